"""The paper's equations: kinematics, finger, reservoir, grasp, contact and the free hand."""

import lazy_loader

# the room's modules as attributes, imported on first use (softhand.reduced's face names them)
__getattr__, __dir__, __all__ = lazy_loader.attach(__name__, submodules=["contact","finger","grasp","hand","kinematics","reservoir"])
