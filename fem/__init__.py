"""Hyperelastic FEM on scikit-fem: materials, forms, loads, constraints, contact, Newton, I/O.

Its public face, imported on first use: the building blocks of a model of one's own
(:class:`~softhand.fem.materials.NeoHookean`, :class:`~softhand.fem.solid.Solid`, :class:`~softhand.fem.loads.FollowerPressure`, :func:`~softhand.fem.newton_path.solve_path`, ...) and
the hand's models built from them (:class:`~softhand.fem.hand.finger.FingerModel`, :class:`~softhand.fem.hand.grasp.GraspModel`,
:class:`~softhand.fem.hand.reservoir.SheetModel`).
"""
if __name__ != "softhand.fem":  # the folder on sys.path, imported by its short name
    raise ImportError(f"'{__name__}' is softhand.fem: import softhand.fem (after pip install -e .)")

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
