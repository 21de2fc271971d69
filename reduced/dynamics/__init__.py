"""The hand in time: the plant, the angle and pressure controllers, Table II."""

import lazy_loader

# the room's modules as attributes, imported on first use (softhand.reduced's face names them)
__getattr__, __dir__, __all__ = lazy_loader.attach(__name__, submodules=["control","controllers","plant"])
