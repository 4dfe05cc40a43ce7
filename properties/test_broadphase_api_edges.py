"""Edges of the broad phase's public API that the pair-equality properties do not reach: defaults of the
direct entry points (``find_pairs`` always passes them explicitly), scenes with fewer than two boxes, malformed
inputs to ``canonical_pairs`` / ``sap_pairs`` / ``IncrementalSAP`` (errors name the argument), and
``IncrementalSAP`` in 1-D and 2-D (boxes padded to 3-D inside). Oracle: numpy all-pairs."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from engine.broadphase import (
    BROAD_PHASES,
    DynamicAABBTree,
    IncrementalSAP,
    find_pairs,
    grid_pairs,
    octree_pairs,
    sap_pairs,
    sphere_pairs,
    sweep_intervals,
    tree_pairs,
)
from engine.broadphase.kinematic import cull_separating_sphere_pairs
from engine.broadphase.pairs import canonical_pairs


def brute_box_pairs(lo, hi):
    overlap = np.all((lo[:, None, :] <= hi[None, :, :]) & (lo[None, :, :] <= hi[:, None, :]), axis=2)
    i, j = np.nonzero(np.triu(overlap, 1))
    return np.stack([i, j], axis=1).astype(np.int64)


def random_boxes(seed, n, d):
    rng = np.random.default_rng(seed)
    lo = rng.uniform(-4.0, 4.0, (n, d))
    return lo, lo + rng.uniform(0.0, 2.5, (n, d))


@given(st.integers(0, 2**32 - 1), st.integers(2, 30), st.integers(1, 3))
def test_direct_entry_points_return_only_the_pairs_by_default(seed, n, d):
    lo, hi = random_boxes(seed, n, d)
    expected = brute_box_pairs(lo, hi)
    for method in (sap_pairs, grid_pairs, octree_pairs, tree_pairs):
        got = method(lo, hi)
        assert isinstance(got, np.ndarray)  # not a (pairs, tests) tuple: return_tests defaults to False
        np.testing.assert_array_equal(got, expected)


@pytest.mark.parametrize("method", BROAD_PHASES)
@pytest.mark.parametrize("n", [0, 1])
@pytest.mark.parametrize("d", [1, 3])
def test_fewer_than_two_boxes_cost_no_test(method, n, d):
    """No pair can exist, so no method tests anything (brute force's (n² − n)/2 is 0 too)."""
    lo = np.zeros((n, d))
    pairs, tests = find_pairs(lo, lo + 1.0, method, return_tests=True)
    assert pairs.shape == (0, 2) and pairs.dtype == np.int64
    assert tests == 0


def test_canonical_pairs_refuses_rows_that_are_not_pairs():
    for bad in (np.array([[1, 2, 3]]), np.array([1, 2]), np.zeros((2, 2, 2), dtype=np.int64)):
        with pytest.raises(ValueError, match="pairs"):
            canonical_pairs(bad)
    for empty in (np.array([], dtype=np.int64), np.zeros((0, 3), dtype=np.int64), np.zeros((0, 2), dtype=np.int64)):
        got = canonical_pairs(empty)
        assert got.shape == (0, 2) and got.dtype == np.int64


def test_sap_axis_must_be_an_int():
    lo, hi = random_boxes(0, 5, 3)
    for bad in (1.0, True, "1"):
        with pytest.raises(TypeError, match="axis"):
            sap_pairs(lo, hi, axis=bad)
    for bad in (-1, 3):
        with pytest.raises(ValueError, match="axis"):
            sap_pairs(lo, hi, axis=bad)


def test_incremental_sap_refuses_dead_ids_and_mismatched_boxes():
    sap = IncrementalSAP(dim=2)
    a = sap.add([0.0, 0.0], [1.0, 1.0])
    b = sap.add([0.5, 0.5], [2.0, 2.0])
    sap.remove(a)
    for dead in (a, b + 1, 100):
        with pytest.raises(ValueError, match="not a live object"):
            sap.remove(dead)
        with pytest.raises(ValueError, match="not a live object"):
            sap.move(dead, [0.0, 0.0], [1.0, 1.0])
    with pytest.raises(ValueError, match="hi_i"):
        sap.add([0.0, 0.0], [1.0, 1.0, 1.0])
    with pytest.raises(ValueError, match="lo_i"):
        sap.add([0.0], [1.0, 1.0])
    assert sap.pairs().shape == (0, 2)


@given(st.integers(0, 2**32 - 1), st.integers(2, 25), st.integers(1, 2), st.data())
def test_incremental_sap_in_one_and_two_dimensions_equals_brute_force(seed, n, d, data):
    """Boxes added one by one (ids reused after removals) in 1-D or 2-D: the pairs of the live boxes."""
    lo, hi = random_boxes(seed, n, d)
    sap = IncrementalSAP(dim=d)
    ids = [sap.add(lo[i], hi[i]) for i in range(n)]
    assert ids == list(range(n))
    gone = data.draw(st.lists(st.integers(0, n - 1), unique=True, max_size=n // 2))
    for i in gone:
        sap.remove(i)
    live_lo, live_hi = lo.copy(), hi.copy()
    for i in gone:  # boxes added again, shifted: they take the freed ids
        new_id = sap.add(lo[i] + 0.5, hi[i] + 0.5)
        assert new_id in gone
        live_lo[new_id], live_hi[new_id] = lo[i] + 0.5, hi[i] + 0.5
    np.testing.assert_array_equal(sap.pairs(), brute_box_pairs(live_lo, live_hi))


@pytest.mark.parametrize("call, message", [
    (lambda: find_pairs(np.array([[0.0, 3.5]]), np.array([[1.0, -1.0]]), "brute"),
     "lo must not exceed hi: lo[0, 1] = 3.5 > hi[0, 1] = -1.0"),
    (lambda: sweep_intervals([0.0, 2.0], [1.0, 1.5]), "begin must not exceed end: begin[1] = 2.0 > end[1] = 1.5"),
    (lambda: IncrementalSAP(np.zeros((1, 3)), np.ones((1, 3))).add([0.0, 2.0, 0.0], [1.0, 1.0, 1.0]),
     "lo_i must not exceed hi_i: lo_i[1] = 2.0 > hi_i[1] = 1.0"),
    (lambda: DynamicAABBTree().insert([0.0, 2.0, 0.0], [1.0, 1.0, 1.0]),
     "lo_i must not exceed hi_i: lo_i[1] = 2.0 > hi_i[1] = 1.0"),
    (lambda: sphere_pairs(np.zeros((3, 3)), [1.0, -1.0, 1.0]), "radii must be >= 0: radii[1] = -1.0"),
    (lambda: cull_separating_sphere_pairs([[0, 1]], np.zeros((2, 3)), [1.0, -0.5], np.zeros((2, 3))),
     "radii must be >= 0: radii[1] = -0.5"),
])
def test_offending_values_are_printed_as_plain_numbers(call, message):
    """The whole message: the argument, the first bad index, and the value as Python prints a float (not numpy's
    ``np.float64(-1.0)``)."""
    with pytest.raises(ValueError) as info:
        call()
    assert str(info.value) == message


@given(n=st.integers(1, 8), data=st.data())
def test_sap_example_trace_names_given_intervals_1_to_n_by_default(n, data):
    """``sap_example_trace(begin, end)`` without labels names the intervals 1..n (its documented default): each
    interval's begin and end events appear once, as b{i}= and e{i}=, i = 1..n, and no other label."""
    from engine.broadphase import sap_example_trace

    begin = np.array(data.draw(st.lists(st.integers(-5, 5), min_size=n, max_size=n)), dtype=float)
    end = begin + np.array(data.draw(st.lists(st.integers(0, 4), min_size=n, max_size=n)))
    text = sap_example_trace(begin, end)
    tokens = text.split()
    for i in range(1, n + 1):
        assert sum(t.startswith(f"b{i}=") for t in tokens) == 1 and sum(t.startswith(f"e{i}=") for t in tokens) == 1
    assert not any(t.startswith((f"b{n + 1}=", f"e{n + 1}=", "b0=", "e0=")) for t in tokens)


@given(seed=st.integers(0, 2**32 - 1), n=st.integers(2, 12))
def test_incremental_sap_built_by_add_is_the_one_built_from_arrays(seed, n):
    """An IncrementalSAP filled box by box with ``add`` holds the same sorted order as one built from the arrays
    (boxes of equal lo on the sweep axis in the order of their ids: a stable sort), so after the same moves both
    report the same pairs and the same number of insertion-sort swaps (``last_swaps``). Integer boxes: many ties."""
    rng = np.random.default_rng(seed)
    lo = rng.integers(0, 3, (n, 3)).astype(float)
    hi = lo + rng.integers(0, 2, (n, 3))
    built = IncrementalSAP(lo, hi, axis=0)
    added = IncrementalSAP(dim=3, axis=0)
    for i in range(n):
        assert added.add(lo[i], hi[i]) == i
    for _ in range(3):
        np.testing.assert_array_equal(added.pairs(), built.pairs())
        assert added.last_swaps == built.last_swaps
        moved = rng.integers(0, n)
        step = rng.integers(-2, 1, 3).astype(float)
        for sap in (built, added):
            sap.move(moved, lo[moved] + step, hi[moved] + step)
        lo[moved] += step
        hi[moved] += step
