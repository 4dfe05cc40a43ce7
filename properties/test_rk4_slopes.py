"""How ``rk4_step`` reads the slopes f returns: as float64 arrays of y's shape, whatever f hands back, and a slope
of the wrong shape is reported with the stage (k1 .. k4) at which it came.

Oracles: the same step with f's answer converted to float64 by the caller (bit for bit); the stage is known from
the number of calls made before f misbehaves.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from engine.dynamics.rk4 import rk4_step

finite = st.floats(-10.0, 10.0, allow_nan=False)


@given(hnp.arrays(np.float64, st.integers(1, 6), elements=finite), st.floats(-1.0, 1.0),
       st.floats(1e-3, 0.5), st.sampled_from([np.float32, np.float16, np.int64, "list"]), st.data())
def test_slopes_are_read_as_float64_whatever_f_returns(y, t, dt, kind, data):
    """f(t, y) = A y + b t returned as float32, float16, int64 or a list: the step equals the one whose f returns
    the same values already converted to float64 (so no stage is computed in a narrower type). |A| <= 1 keeps
    every stage's slope below 1e3, inside float16's range (65504): a slope that overflows to inf is refused by
    the step, rightly, and is not what this property is about."""
    n = y.shape[0]
    a = data.draw(hnp.arrays(np.float64, (n, n), elements=st.floats(-1.0, 1.0)))
    b = data.draw(hnp.arrays(np.float64, n, elements=finite))

    def narrow(ti, yi):
        k = a @ yi + b * ti
        return k.tolist() if kind == "list" else k.astype(kind)

    def wide(ti, yi):
        return np.asarray(narrow(ti, yi), dtype=np.float64)

    got = rk4_step(narrow, t, y, dt)
    assert got.dtype == np.float64
    np.testing.assert_array_equal(got, rk4_step(wide, t, y, dt))


@given(st.integers(1, 4), st.integers(1, 5), st.sampled_from(["longer", "shorter", "matrix"]))
def test_a_slope_of_the_wrong_shape_names_its_stage(stage, n, how):
    calls = []

    def f(t, y):
        calls.append(t)
        if len(calls) == stage:
            return {"longer": np.zeros(n + 1), "shorter": np.zeros(max(n - 1, 0)), "matrix": np.zeros((n, 1))}[how]
        return -y

    with pytest.raises(ValueError, match=rf"at stage k{stage};") as info:
        rk4_step(f, 0.0, np.ones(n), 0.1)
    assert str(info.value).startswith("f returned shape")
    assert len(calls) == stage  # the step stops at the stage that failed
