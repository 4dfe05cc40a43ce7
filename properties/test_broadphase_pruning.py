"""What the broad phases are for: pruning. The pairs are exact whatever the pruning (the other properties check
that); here, the deterministic count of box tests (``find_pairs(..., return_tests=True)``: work is
measured by counts, never by time) on scenes where the answer is known:

- on a sparse line of disjoint boxes (along x, y or z) every method but brute force tests fewer pairs than
  brute force's (n² − n)/2: a tree or octree traversal that stopped rejecting nodes along one axis, or a sweep
  that stopped using one of its column axes, would test everything against everything;
- ``sap_pairs`` sweeps by default along the axis where the box centres spread most (its documented default;
  oracle: numpy's variance), so its work equals the work with that axis given explicitly;
- the sweep's columns are a grid over the two other axes, built the same way along both: exchanging those two
  axes' coordinates changes neither the pairs nor the number of tests; and the columns do prune: the sweep
  tests fewer pairs than all those overlapping along the sweep axis.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st

from engine.broadphase import BROAD_PHASES, find_pairs, sap_pairs


def sparse_line(seed, n, axis):
    """n disjoint boxes along ``axis`` (one every 3 units, at most 1.5 long), all overlapping across it."""
    rng = np.random.default_rng(seed)
    lo = rng.uniform(0.0, 1.0, (n, 3))
    lo[:, axis] = 3.0 * rng.permutation(n) + rng.uniform(0.0, 1.0, n)
    return lo, lo + rng.uniform(0.1, 1.5, (n, 3))


@pytest.mark.parametrize("axis", [0, 1, 2])
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(100, 160))
def test_every_broad_phase_prunes_a_sparse_line(axis, seed, n):
    lo, hi = sparse_line(seed, n, axis)
    all_pairs = n * (n - 1) // 2
    for method in BROAD_PHASES:
        pairs, tests = find_pairs(lo, hi, method, return_tests=True)
        assert pairs.shape == (0, 2)  # disjoint along the line
        if method == "brute":
            assert tests == all_pairs
        else:
            assert tests < all_pairs, (method, tests, all_pairs)


def spread_scene(seed, n):
    """Boxes whose centres spread differently along each axis, around different offsets."""
    rng = np.random.default_rng(seed)
    spread = rng.uniform(0.5, 20.0, 3)
    offset = rng.uniform(-50.0, 50.0, 3)
    lo = offset + spread * rng.uniform(0.0, 1.0, (n, 3))
    return lo, lo + rng.uniform(0.0, 3.0, (n, 3))


@given(st.integers(0, 2**32 - 1), st.integers(3, 60))
def test_sap_sweeps_by_default_along_the_widest_spread_of_the_centres(seed, n):
    lo, hi = spread_scene(seed, n)
    variance = np.var(0.5 * lo + 0.5 * hi, axis=0)
    ranked = np.sort(variance)
    assume(ranked[2] > 1.01 * ranked[1])  # a clear widest axis
    widest = int(np.argmax(variance))
    default_pairs, default_tests = sap_pairs(lo, hi, return_tests=True)
    given_pairs, given_tests = sap_pairs(lo, hi, axis=widest, return_tests=True)
    np.testing.assert_array_equal(default_pairs, given_pairs)
    assert default_tests == given_tests


def mixed_scene(seed, n):
    """Many small boxes in a cube of side 100 and 5 % of boxes spanning it whole: the columns first sized for the
    small ones hold too many entries (> 4 per box), so the sweep coarsens its column grid."""
    rng = np.random.default_rng(seed)
    lo = rng.uniform(0.0, 100.0, (n, 3))
    hi = lo + rng.uniform(0.0, 0.02, (n, 3))
    huge = rng.random(n) < 0.05
    lo[huge] = rng.uniform(-1.0, 0.0, (int(huge.sum()), 3))
    hi[huge] = rng.uniform(100.0, 101.0, (int(huge.sum()), 3))
    return lo, hi


@pytest.mark.parametrize("axis", [0, 1, 2])
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(2, 80), mixed=st.booleans())
def test_sap_work_does_not_depend_on_the_order_of_the_two_other_axes(axis, seed, n, mixed):
    lo, hi = mixed_scene(seed, 10 * n) if mixed else spread_scene(seed, n)
    a1, a2 = (axis + 1) % 3, (axis + 2) % 3
    swap = np.arange(3)
    swap[[a1, a2]] = [a2, a1]
    pairs, tests = sap_pairs(lo, hi, axis=axis, return_tests=True)
    swapped_pairs, swapped_tests = sap_pairs(lo[:, swap], hi[:, swap], axis=axis, return_tests=True)
    np.testing.assert_array_equal(pairs, swapped_pairs)
    assert tests == swapped_tests


@given(st.integers(0, 2**32 - 1), st.integers(200, 400))
def test_sap_columns_prune_pairs_that_overlap_only_along_the_sweep_axis(seed, n):
    """Small boxes spread through a cube: the sweep runs per column of a grid over the two other axes, so it
    tests fewer pairs than a plain one-axis sweep would (every pair overlapping along the sweep axis)."""
    rng = np.random.default_rng(seed)
    lo = rng.uniform(0.0, 50.0, (n, 3))
    hi = lo + rng.uniform(0.0, 1.0, (n, 3))
    axis = int(np.argmax(np.var(0.5 * lo + 0.5 * hi, axis=0)))
    overlap = (lo[:, None, axis] <= hi[None, :, axis]) & (lo[None, :, axis] <= hi[:, None, axis])
    along_axis = int(np.count_nonzero(np.triu(overlap, 1)))
    pairs, tests = sap_pairs(lo, hi, return_tests=True)
    assert tests < along_axis
