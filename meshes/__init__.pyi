"""The public face of softhand.meshes: what examples and users import."""
from .tube import Tube, tube_mesh
