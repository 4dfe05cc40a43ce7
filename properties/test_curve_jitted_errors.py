"""Curved ground with a numba-jitted f (engine/narrowphase/primitives.py, ``_search_jit``): when f returns a
non-finite value during the golden-section refinement (finite on the sample grid, infinite between), the error
names the value and the abscissa exactly as the Python-f path does (no NaN or garbage escapes into the message).

With NUMBA_DISABLE_JIT=1 (the mutation run) ``numba.njit`` returns the Python function and both calls take the
Python path; compiled (CI), the first call runs the one compiled search.
"""
from __future__ import annotations

import numba
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from engine.narrowphase import max_on_intervals, min_distance_to_curve


@numba.njit
def _finite_on_the_grid_only(x):
    """0 at the grid abscissae 0 and 1 of ``samples=2`` on [0, 1], +inf strictly between (where the golden
    section evaluates f)."""
    out = np.empty_like(x)
    for i in range(x.shape[0]):
        out[i] = 0.0 if x[i] == 0.0 or x[i] == 1.0 else np.inf
    return out


def _python_f(x):
    return _finite_on_the_grid_only(x)


def _message(call):
    with pytest.raises(ValueError, match="non-finite") as info:
        call()
    return str(info.value)


@given(st.integers(1, 5))
def test_non_finite_value_in_the_refinement_is_reported_as_in_python(n):
    lo, hi = np.zeros(n), np.ones(n)
    jitted = _message(lambda: max_on_intervals(_finite_on_the_grid_only, lo, hi, samples=2))
    python = _message(lambda: max_on_intervals(_python_f, lo, hi, samples=2))
    assert jitted == python
    assert "inf" in jitted
    points = np.c_[np.full(n, 0.5), np.zeros(n)]
    jitted = _message(lambda: min_distance_to_curve(points, _finite_on_the_grid_only, 0.5, samples=2))
    python = _message(lambda: min_distance_to_curve(points, _python_f, 0.5, samples=2))
    assert jitted == python and "inf" in jitted
