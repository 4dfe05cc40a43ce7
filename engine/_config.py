"""Numerical settings shared by every module: dtype, tolerances and numba flags, in one place.

``fastmath`` stays off everywhere: the invariants the properties check (closed-interval overlap, exact
agreement between broad phases, conservation to round-off) need exact IEEE-754 arithmetic.
"""
from __future__ import annotations

import hashlib
import os
from pathlib import Path

import numba
import numpy as np
from numba import njit as _numba_njit

FLOAT = np.float64
INDEX = np.int64

#: keyword arguments of every compiled kernel of the engine
NJIT_OPTIONS = {"cache": True, "fastmath": False, "nogil": True}

#: absolute tolerance, in seconds, of the bisection that locates an impact time tc (Algorithme 3's epsilon)
DEFAULT_TIME_TOL = 1e-10


def _source_fingerprint() -> str:
    """A hash of every source file of the package (and numba's version).

    numba's ``cache=True`` checks only the timestamp of the file that defines a kernel, not of the kernels it
    calls in other files: after an edit of a callee it can serve stale machine code. Keying the cache directory
    on the whole package's sources makes any edit recompile every kernel once.
    """
    root = Path(__file__).resolve().parent
    digest = hashlib.sha256(numba.__version__.encode())
    for path in sorted(root.rglob("*.py")):
        digest.update(str(path.relative_to(root)).encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()[:16]


def _cache_base() -> str:
    if os.environ.get("NUMBA_CACHE_DIR"):
        return os.environ["NUMBA_CACHE_DIR"]
    xdg = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return os.path.join(xdg, "engine-numba")


#: where compiled kernels are cached: <NUMBA_CACHE_DIR or ~/.cache/engine-numba>/<fingerprint of the sources>
CACHE_DIR = os.path.join(_cache_base(), _source_fingerprint())
numba.config.CACHE_DIR = CACHE_DIR  # read by numba when each kernel below is decorated


def njit(*args, **kwargs):
    """``numba.njit`` with the engine's flags (cache on, fastmath off); usable bare or with arguments."""
    options = {**NJIT_OPTIONS, **kwargs}
    if len(args) == 1 and callable(args[0]) and not kwargs:
        return _numba_njit(**options)(args[0])
    return _numba_njit(*args, **options)
