"""The paper's analytical virtual-work model and the design vocabulary (NumPy/SciPy only).

Its public face: the design (:class:`~softhand.reduced.vocabulary.design.HandDesign`, :func:`~softhand.reduced.vocabulary.design_files.load_design`), the one input error
(:class:`~softhand.reduced.vocabulary.errors.InputError`), and the model's modules (:mod:`~softhand.reduced.equations.finger`,
:mod:`~softhand.reduced.equations.hand`, :mod:`~softhand.reduced.equations.reservoir`, ...), imported on first use.
"""
if __name__ != "softhand.reduced":  # the folder on sys.path, imported by its short name
    raise ImportError(f"'{__name__}' is softhand.reduced: import softhand.reduced (after pip install -e .)")

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
