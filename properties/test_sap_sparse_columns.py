"""SAP's sparse column grid (engine/broadphase/sweep_and_prune.py, ``_choose_columns`` / ``_fill_columns_sparse``):
from SPARSE_MIN_BOXES boxes on, clusters far apart over the two axes other than the sweep axis keep columns of
about twice the mean box size and store only the occupied ones. The boxes here span several columns along both
of those axes (rods across the clusters, boxes of a few mean sizes), so the (box, column) entries away from a box's
first column, and a pair reported only in its home column, are exercised; the pairs must be brute force's.
"""
from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from engine.broadphase import brute_force_pairs, sap_pairs
from engine.broadphase.sweep_and_prune import SPARSE_MIN_BOXES


def clustered_boxes(seed, axis, n):
    """n boxes in 4 clusters 1e4 apart over the two axes other than ``axis``: unit-sized boxes, one in 8 of them
    3 to 12 times longer along one of those axes, one in 16 touching its neighbour exactly (shared faces)."""
    rng = np.random.default_rng(seed)
    others = [a for a in range(3) if a != axis]
    corners = np.array([[0.0, 0.0], [1e4, 0.0], [0.0, 1e4], [1e4, 1e4]])
    lo = rng.uniform(0.0, 30.0, (n, 3))
    lo[:, others] += corners[rng.integers(0, 4, n)]
    size = rng.uniform(0.5, 1.5, (n, 3))
    long = rng.random(n) < 0.125
    size[long, rng.choice(others, size=long.sum())] *= rng.uniform(3.0, 12.0, long.sum())
    for t in np.nonzero(rng.random(n - 1) < 0.0625)[0]:  # box t + 1 moved onto box t: lo of one = hi of the other
        lo[t + 1] = lo[t] + rng.uniform(0.0, 0.4, 3)
        lo[t + 1, others[1]] = lo[t, others[1]] + size[t, others[1]]
    return lo, lo + size


@settings(max_examples=10, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), axis=st.integers(0, 2), extra=st.integers(0, 200))
def test_sap_sparse_columns_equal_brute_force(seed, axis, extra):
    lo, hi = clustered_boxes(seed, axis, SPARSE_MIN_BOXES + extra)
    np.testing.assert_array_equal(sap_pairs(lo, hi, axis=axis), brute_force_pairs(lo, hi))
