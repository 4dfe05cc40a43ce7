"""Numerical settings shared by every module: tolerances and numba flags, in one place.

``fastmath`` stays off everywhere: the invariants the properties check (closed-interval overlap, exact
agreement between broad phases, conservation to round-off) need exact IEEE-754 arithmetic.
"""
from __future__ import annotations

import contextlib
import hashlib
import os
import sys
from pathlib import Path

import numba
import numba.core.event
from numba import njit as _numba_njit

#: keyword arguments of every compiled kernel of the engine
NJIT_OPTIONS = {"cache": True, "fastmath": False, "nogil": True}

#: the most threads a call may ask for with ``threads=`` (every broad phase, the narrow-phase batches)
MAX_THREADS = 256

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


@contextlib.contextmanager
def _engine_cache_dir():
    """numba picks a kernel's cache folder from ``numba.config.CACHE_DIR`` when the kernel is decorated: the
    engine's folder is set for the decoration only, then the user's setting is put back (other packages'
    ``cache=True`` functions keep theirs)."""
    saved = numba.config.CACHE_DIR
    numba.config.CACHE_DIR = CACHE_DIR
    try:
        yield
    finally:
        numba.config.CACHE_DIR = saved


def njit(*args, **kwargs):
    """``numba.njit`` with the engine's flags (cache on, fastmath off); usable bare or with arguments."""
    options = {**NJIT_OPTIONS, **kwargs}
    decorate = _numba_njit(**options) if len(args) == 1 and callable(args[0]) and not kwargs else None
    if decorate is not None:
        with _engine_cache_dir():
            return decorate(args[0])
    inner = _numba_njit(*args, **options)

    def decorator(func):
        with _engine_cache_dir():
            return inner(func)

    return decorator


class _CompileNotice(numba.core.event.Listener):
    """Says once per process, on stderr, that the engine is compiling its kernels — only when a kernel of the
    engine really compiles (a kernel loaded from the cache says nothing). ``COLLDET_COMPILE_NOTICE=0`` silences it."""

    told = False

    def on_start(self, event):
        dispatcher = event.data["dispatcher"]
        if self.told or not getattr(dispatcher.py_func, "__module__", "").startswith("engine."):
            return
        type(self).told = True
        sys.stderr.write("colldet: compiling the engine's kernels for this machine (once: the machine code is "
                         f"cached in {CACHE_DIR}; `colldet warmup` compiles them all ahead of time)\n")
        sys.stderr.flush()

    def on_end(self, event):
        pass


if os.environ.get("COLLDET_COMPILE_NOTICE", "1") != "0":
    numba.core.event.register("numba:compile", _CompileNotice())
