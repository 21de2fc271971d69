"""The public face of softhand.fem: what examples and users import."""
from .assembly import Restriction
from .hand.finger import FingerModel
from .hand.finger_options import FingerOptions
from .hand.grasp import GraspModel, GraspOptions
from .hand.reservoir import SheetModel, inflate
from .linsolve import make_solver
from .loads import FollowerPressure
from .materials import NeoHookean
from .newton import NewtonOptions
from .newton_path import PathOptions, solve_path
from .mixed import MixedNewton
from .solid import Solid
