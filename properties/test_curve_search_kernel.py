"""The compiled curve search ``_search_jit`` (engine/narrowphase/primitives.py), called directly, in both modes.

The public curve functions take ``_search_jit`` only for a numba dispatcher f (``_is_jitted``); with
``NUMBA_DISABLE_JIT=1`` (the mutation run) ``numba.njit`` returns the Python function, so that path is never taken
through the public API (test_curve_jitted_errors.py checks it compiled, in CI). Called directly with
``numba.njit(f)``, ``_search_jit`` runs compiled with a dispatcher f, or interpreted with the Python f when the JIT
is off, so its documented contract is checked in both modes:

- it returns 0 and the same minimiser and minimum per interval as the Python-f search (``_minimize_on_intervals``
  with a plain Python f), for both objectives (the maximum of f, the squared distance from a point to the graph);
- when f returns a non-finite value (here: finite on the sample grid, +inf at every refinement point) it returns 1
  with the first bad abscissa and value in ``bad_x[0:2]`` (``_evaluate_jit``: "the first bad (x, f(x)) goes to
  bad[0:2]"), the values the Python path names in its error.
"""
from __future__ import annotations

import numba
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from engine.narrowphase.primitives import _DISTANCE, _MAXIMIZE, GOLDEN_ITERATIONS, _minimize_on_intervals, _search_jit


def _bumpy(x):
    """A smooth curve with several local maxima on [-3, 3] (a polynomial: the same bits compiled and interpreted)."""
    return 0.5 - 0.3 * x * x + 0.05 * x * x * x * x - 0.002 * x * x * x * x * x * x + 0.1 * x


_bumpy_jit = numba.njit(_bumpy)


@numba.njit
def _finite_on_the_grid_only(x):
    """0 at the grid abscissae 0 and 1 of ``samples=2`` on [0, 1], +inf strictly between (the refinement)."""
    out = np.empty_like(x)
    for i in range(x.shape[0]):
        out[i] = 0.0 if x[i] == 0.0 or x[i] == 1.0 else np.inf
    return out


def _search(f, mode, lo, hi, px, py, samples):
    n = lo.shape[0]
    x_out, v_out, bad = np.full(n, np.nan), np.full(n, np.nan), np.full(2, np.nan)
    code = _search_jit(f, mode, lo, hi, np.linspace(0.0, 1.0, samples), px, py, GOLDEN_ITERATIONS, x_out, v_out,
                       bad)
    return code, x_out, v_out, bad


intervals = st.lists(st.tuples(st.floats(-3.0, 3.0), st.floats(0.0, 2.0), st.floats(-3.0, 3.0),
                               st.floats(-2.0, 2.0)), min_size=1, max_size=4)


@given(intervals, st.sampled_from([_MAXIMIZE, _DISTANCE]), st.integers(2, 40))
def test_search_kernel_matches_the_python_search(rows, mode, samples):
    lo = np.array([r[0] for r in rows])
    hi = lo + np.array([r[1] for r in rows])
    px, py = np.array([r[2] for r in rows]), np.array([r[3] for r in rows])
    code, x_out, v_out, bad = _search(_bumpy_jit, mode, lo, hi, px, py, samples)
    x_py, v_py = _minimize_on_intervals(_bumpy, mode, lo, hi, px, py, samples)
    assert code == 0 and np.isnan(bad).all(), (code, bad)
    assert np.allclose(x_out, x_py, rtol=0.0, atol=1e-12) and np.allclose(v_out, v_py, rtol=0.0, atol=1e-12), (
        x_out, x_py, v_out, v_py)
    assert ((lo <= x_out) & (x_out <= hi)).all(), (lo, x_out, hi)


@pytest.mark.filterwarnings("ignore:invalid value encountered:RuntimeWarning")  # inf - inf, interpreted
@given(st.integers(1, 5), st.sampled_from([_MAXIMIZE, _DISTANCE]))
def test_search_kernel_reports_the_first_non_finite_value(n, mode):
    lo, hi = np.zeros(n), np.ones(n)
    px, py = np.full(n, 0.5), np.zeros(n)
    code, _, _, bad = _search(_finite_on_the_grid_only, mode, lo, hi, px, py, 2)
    assert code == 1, code
    # the Python path's error names the same value and abscissa: the first refinement point c = 1 - φ
    with pytest.raises(ValueError, match="non-finite") as info:
        _minimize_on_intervals(lambda x: _finite_on_the_grid_only(x), mode, lo, hi, px, py, 2)
    assert str(info.value) == f"f returned a non-finite value {float(bad[1])!r} at x = {float(bad[0])!r}", (
        str(info.value), bad)
    assert bad[1] == np.inf and 0.0 < bad[0] < 1.0, bad
