"""``engine.narrowphase.curve_ground.ground_gap``: the gap between a body's lower boundary (a broken line through
its points) and a HeightCurve is never more than the gap at any of the boundary's own points (they are among its
samples, and the golden-section refinement only lowers it), and it is found within the boundary's x range.

The boundaries are arbitrary broken lines (increasing x, random heights) over curves with steep slopes and
ripples, so the lowest point is anywhere along them: at the first point, at the last, or in between.
"""
from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from engine import HeightCurve
from engine.narrowphase.curve_ground import ground_gap


@given(k=st.integers(1, 3), s=st.integers(3, 12), seed=st.integers(0, 2**32 - 1),
       slope=st.sampled_from([-100.0, -3.0, 0.0, 3.0, 100.0]), ripple=st.floats(0.0, 2.0))
def test_the_gap_is_at_most_the_gap_at_every_boundary_point(k, s, seed, slope, ripple):
    rng = np.random.default_rng(seed)
    x = np.sort(rng.uniform(-2.0, 2.0, size=(k, s)), axis=1) + np.arange(s) * 1e-3  # strictly increasing
    y = rng.uniform(0.0, 3.0, size=(k, s))
    curve = HeightCurve(lambda u: slope * u + ripple * np.sin(3.0 * u))
    gap, gx, _ = ground_gap(curve, np.stack([x, y], axis=2))
    at_points = (y - curve.height(x.ravel()).reshape(k, s)).min(axis=1)
    assert np.all(gap <= at_points + 1e-12 * (1.0 + np.abs(at_points)))
    assert np.all((x[:, 0] <= gx) & (gx <= x[:, -1]))
