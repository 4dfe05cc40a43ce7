"""Numerical settings shared by every module: dtype, tolerances and numba flags, in one place.

``fastmath`` stays off everywhere: the invariants the properties check (closed-interval overlap, exact
agreement between broad phases, conservation to round-off) need exact IEEE-754 arithmetic.
"""
from __future__ import annotations

import numpy as np
from numba import njit as _numba_njit

FLOAT = np.float64
INDEX = np.int64

#: keyword arguments of every compiled kernel of the engine
NJIT_OPTIONS = {"cache": True, "fastmath": False, "nogil": True}

#: absolute tolerance, in seconds, of the bisection that locates an impact time tc (Algorithme 3's epsilon)
DEFAULT_TIME_TOL = 1e-10


def njit(*args, **kwargs):
    """``numba.njit`` with the engine's flags (cache on, fastmath off); usable bare or with arguments."""
    options = {**NJIT_OPTIONS, **kwargs}
    if len(args) == 1 and callable(args[0]) and not kwargs:
        return _numba_njit(**options)(args[0])
    return _numba_njit(*args, **options)
