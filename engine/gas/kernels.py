"""How the gas's state kernels are compiled: ``state_kernel``, numba's ``njit`` with the engine's flags plus two.

The event loop and the frame loop call many small kernels that take the gas's state bundles (namedtuples of arrays,
engine/gas/events.py, engine/gas/stepped.py). These kernels allocate nothing, so they are compiled without numba's
reference counting (``_nrt=False``): otherwise every call increments and decrements, atomically, the count of each
array of each bundle it receives: two atomic read-modify-writes per array per call, which for a bundle of several
arrays is of the order of the whole work of a small kernel (a few dozen floating-point operations), on the event
loop's hottest path (bench/test_bench_gas.py measures its collisions per second). A kernel that tries to allocate
fails to compile, so the option cannot hide a leak. ``error_model="numpy"``: no division in these kernels can be by
zero (each is noted where it occurs), and without Python's zero-division checks they have no exception path.
``fastmath`` stays off, as everywhere in the engine.

The gas's structured records (``LINK``, ``ENTRY``, ``BOOK``) are read and written as ``rec["field"]``: numba
compiles that form exactly as ``rec.field`` (the same machine code), and it also works on numpy's ``numpy.void``
rows, which have no attribute access. So every kernel also runs interpreted (``NUMBA_DISABLE_JIT=1``, as the
mutation run does), with the same results bit for bit (properties/test_gas_without_jit.py).
"""
from __future__ import annotations

from engine._config import njit

__all__ = ["state_kernel"]


def state_kernel(function):
    """Compile ``function`` (a kernel that allocates no array) with the options above."""
    return njit(error_model="numpy", _nrt=False)(function)
