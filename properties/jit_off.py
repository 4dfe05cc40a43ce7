"""Running part of the suite with numba's JIT disabled, in a child process, and comparing the answers bit for bit.

The mutation run (properties/MUTATION.md) interprets every kernel (``NUMBA_DISABLE_JIT=1``, read once at import),
so the properties that check "interpreted equals compiled" run a function of theirs in a child process with the
JIT disabled and compare what it returns with the compiled run's.
"""
from __future__ import annotations

import os
import pickle
import subprocess
import sys
from pathlib import Path

import numba
import numpy as np

import engine

#: True when numba's JIT is disabled, as in the mutation run: the kernels are then interpreted, hundreds of times
#: slower, so the longest properties check the same invariant on a smaller case (fewer spheres or examples)
INTERPRETED = bool(numba.config.DISABLE_JIT)

#: the checkout whose ``engine`` this process imported (the child must import the same one)
ROOT = Path(engine.__file__).resolve().parents[1]


def runs_in_child(module: str, function: str, disable_jit: bool = True) -> object:
    """``module.function()`` (no arguments, a picklable result) run in a child process with the JIT disabled
    (or enabled), from this checkout."""
    env = {**os.environ, "NUMBA_DISABLE_JIT": "1" if disable_jit else "0",
           "PYTHONPATH": os.pathsep.join([str(ROOT), *filter(None, [os.environ.get("PYTHONPATH")])])}
    code = (f"import pickle, sys; from {module} import {function}; "
            f"sys.stdout.buffer.write(pickle.dumps({function}()))")
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=env, capture_output=True, timeout=600)
    assert done.returncode == 0, done.stderr.decode(errors="replace")[-3000:]
    return pickle.loads(done.stdout)


def assert_same_bits(a, b, where: str) -> None:
    """a and b are the same value: same type, same float64 bits (NaN included), arrays of the same dtype."""
    assert type(a) is type(b), f"{where}: {type(a).__name__} compiled, {type(b).__name__} interpreted"
    if isinstance(a, dict):
        assert a.keys() == b.keys(), where
        for k in a:
            assert_same_bits(a[k], b[k], f"{where}.{k}")
    elif isinstance(a, np.ndarray):
        assert a.dtype == b.dtype and a.shape == b.shape, where
        assert a.tobytes() == b.tobytes(), f"{where}: first difference at {np.flatnonzero(a.ravel() != b.ravel())[:1]}"
    elif isinstance(a, float):
        assert np.float64(a).tobytes() == np.float64(b).tobytes(), f"{where}: {a!r} compiled, {b!r} interpreted"
    else:
        assert a == b, f"{where}: {a!r} compiled, {b!r} interpreted"
