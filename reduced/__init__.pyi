"""The public face of softhand.reduced: what examples and users import."""
from . import contact, control, finger, grasp, hand, kinematics, reservoir
from .design import HandDesign, design_from_dict, load_design
from .errors import InputError
