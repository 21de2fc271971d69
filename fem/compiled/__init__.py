"""Compiled element kernels (numba): the finger's hot loops, one pass per element or facet.

The NumPy kernels elsewhere in :mod:`softhand.fem` evaluate each step for all elements at once;
their batched products are fast, but the (elements, points, nodes) intermediates between them
are not. On the finger's default mesh that memory traffic made a tangent cost more than its
factorisation. Here one compiled function does all an element (:mod:`.rubber`) or a cavity
facet (:mod:`.cavity`) needs while its data sit in the cache, and adds the result straight
into the residual and the CSR data of the fixed pattern. The NumPy kernels stay: for the other
laws, where numba is missing, and as the reference the compiled ones are tested against
(tests/fem/test_compiled.py).

The kernels are compiled on first use and cached on disk beside this package (numba's
``cache=True``): a few seconds once per machine, then a fraction of a second per process.
"""
from __future__ import annotations

try:  # a core dependency; without it the NumPy kernels serve
    from numba import njit
except ImportError:  # pragma: no cover
    njit = None


def available() -> bool:
    """True when numba is installed (the compiled kernels can run)."""
    return njit is not None


def compiled(function):
    """``function`` compiled (no GIL, cached on disk), or as it is without numba."""
    return function if njit is None else njit(nogil=True, cache=True, error_model="numpy")(function)
