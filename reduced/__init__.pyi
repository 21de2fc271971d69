"""The public face of softhand.reduced: what examples and users import."""
from .dynamics import control
from .equations import contact, finger, grasp, hand, kinematics, reservoir
from .vocabulary.design import HandDesign
from .vocabulary.design_files import design_from_dict, load_design
from .vocabulary.errors import InputError
