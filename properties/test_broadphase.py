"""Broad phase contract: every method of BROAD_PHASES equals brute force exactly, in canonical form.

Oracle: brute force (the chapter's (n² − n)/2 exhaustive test), itself checked against a plain numpy
all-pairs test; the slide's SAP example against its exact answer.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st

from engine.broadphase import (
    BROAD_PHASES,
    IncrementalSAP,
    canonical_pairs,
    find_pairs,
    sap_example_trace,
    sweep_intervals,
)
from engine.broadphase.sweep_and_prune import sap_pairs
from engine.broadphase.uniform_grid import grid_pairs
from properties.strategies.boxes import box_scenes

METHODS = [m for m in BROAD_PHASES if m != "brute"]


def numpy_pairs(lo, hi):
    """Independent reference: all i < j with closed overlap on every axis, by broadcasting."""
    n = lo.shape[0]
    if n < 2:
        return np.zeros((0, 2), dtype=np.int64)
    ok = np.all((lo[:, None, :] <= hi[None, :, :]) & (lo[None, :, :] <= hi[:, None, :]), axis=2)
    i, j = np.nonzero(np.triu(ok, 1))
    return np.stack([i, j], axis=1).astype(np.int64)


def assert_canonical(pairs):
    assert pairs.dtype == np.int64 and pairs.ndim == 2 and pairs.shape[1] == 2
    if len(pairs):
        assert np.all(pairs[:, 0] < pairs[:, 1])
        keys = pairs[:, 0] * (pairs.max() + 1) + pairs[:, 1]
        assert np.all(np.diff(keys) > 0)  # sorted, no duplicate


# ---------------------------------------------------------------- the slide's example
SLIDE_PAIRS_1_BASED = [(1, 3), (1, 6), (2, 3), (2, 4), (2, 5), (3, 5), (3, 6), (4, 5)]


def test_slide_example_exact_answer():
    # b3=1, b6=2, b1=3, e6=6, e1=7, b5=7.5, b2=7.7, e3=8, b4=8.9, e5=11, e4=11.2, e2=18
    begin = [3, 7.7, 1, 8.9, 7.5, 2]
    end = [7, 18, 8, 11.2, 11, 6]
    got = sweep_intervals(begin, end) + 1
    assert got.tolist() == [list(p) for p in SLIDE_PAIRS_1_BASED]
    lo = np.array(begin)[:, None]
    hi = np.array(end)[:, None]
    for method in BROAD_PHASES:
        assert (find_pairs(lo, hi, method) + 1).tolist() == [list(p) for p in SLIDE_PAIRS_1_BASED]


def test_slide_example_trace():
    text = sap_example_trace()
    events = [line.split()[0] for line in text.splitlines() if line[:1] in ("b", "e") and "=" in line.split()[0]]
    assert events == ["b3=1", "b6=2", "b1=3", "e6=6", "e1=7", "b5=7.5", "b2=7.7", "e3=8", "b4=8.9", "e5=11",
                      "e4=11.2", "e2=18"]
    assert "8 overlapping pairs" in text
    for p, q in SLIDE_PAIRS_1_BASED:
        assert f"({p}, {q})" in text


# ---------------------------------------------------------------- every method equals brute force
@given(box_scenes())
def test_brute_force_equals_numpy_reference(scene):
    lo, hi = scene
    got = find_pairs(lo, hi, "brute")
    assert_canonical(got)
    np.testing.assert_array_equal(got, numpy_pairs(lo, hi))


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("d", [1, 2, 3])
@settings(max_examples=60)
@given(data=st.data())
def test_every_method_equals_brute_force(method, d, data):
    lo, hi = data.draw(box_scenes(d=d))
    lo0, hi0 = lo.copy(), hi.copy()
    got = find_pairs(lo, hi, method)
    assert_canonical(got)
    np.testing.assert_array_equal(got, find_pairs(lo, hi, "brute"))
    np.testing.assert_array_equal(lo, lo0)  # inputs are never modified
    np.testing.assert_array_equal(hi, hi0)


@settings(max_examples=60)
@given(box_scenes(d=1))
def test_sweep_intervals_equals_brute_force(scene):
    lo, hi = scene
    np.testing.assert_array_equal(sweep_intervals(lo[:, 0], hi[:, 0]), find_pairs(lo, hi, "brute"))


@settings(max_examples=40)
@given(box_scenes(d=3, min_n=2), st.integers(0, 2))
def test_sap_any_sweep_axis(scene, axis):
    lo, hi = scene
    np.testing.assert_array_equal(sap_pairs(lo, hi, axis=axis), find_pairs(lo, hi, "brute"))


@settings(max_examples=40)
@given(box_scenes(d=3, min_n=2), st.sampled_from([1e-3, 0.5, 3.0, 1e4]))
def test_grid_any_cell_size(scene, cell):
    lo, hi = scene
    np.testing.assert_array_equal(grid_pairs(lo, hi, cell_size=cell), find_pairs(lo, hi, "brute"))


@settings(max_examples=40)
@example(scene=(np.zeros((2, 3)), np.ones((2, 3))), tiny=70, span=0, axis=2, default_size=False)
@given(scene=box_scenes(d=3, min_n=2, max_n=12, integer=True), tiny=st.integers(20, 1070),
       span=st.integers(-8, 8), axis=st.integers(0, 2), default_size=st.booleans())
def test_grid_cells_far_finer_than_the_scene(scene, tiny, span, axis, default_size):
    """A cluster of boxes scaled by 2^-tiny (down to the denormals) and a point 2^span away: the scene spans
    2^(span + tiny) cells (or up to 2^1078), far more than any int64 counts, and the grid must coarsen its cells
    without the count overflowing. Integers scaled by 2^-tiny (tiny <= 1070) are exact, denormals included."""
    lo, hi = (np.ldexp(v, -tiny) for v in scene)
    far = np.zeros((1, 3))
    far[0, axis] = 2.0 ** span
    lo, hi = np.vstack([lo, far]), np.vstack([hi, far])
    size = None if default_size else 2.0 ** -tiny
    np.testing.assert_array_equal(grid_pairs(lo, hi, cell_size=size), numpy_pairs(lo, hi))


@settings(max_examples=40)
@given(box_scenes(d=3, min_n=2))
def test_incremental_sap_from_arrays_equals_brute_force(scene):
    lo, hi = scene
    np.testing.assert_array_equal(IncrementalSAP(lo, hi).pairs(), find_pairs(lo, hi, "brute"))


# ---------------------------------------------------------------- relabelling, translation
@pytest.mark.parametrize("method", BROAD_PHASES)
@settings(max_examples=40)
@given(data=st.data())
def test_relabelling_relabels_pairs(method, data):
    lo, hi = data.draw(box_scenes())
    n = lo.shape[0]
    perm = np.array(data.draw(st.permutations(range(n))), dtype=np.int64)
    # object k of the permuted scene is object perm[k] of the original
    got = find_pairs(lo[perm], hi[perm], method)
    mapped = canonical_pairs(perm[got], n=n) if len(got) else got
    np.testing.assert_array_equal(mapped, find_pairs(lo, hi, method))


@pytest.mark.parametrize("method", BROAD_PHASES)
@settings(max_examples=40)
@given(box_scenes(integer=True), st.lists(st.integers(-10**6, 10**6), min_size=3, max_size=3))
def test_integer_translation_keeps_pairs(method, scene, shift):
    lo, hi = scene
    t = np.array(shift[: lo.shape[1]], dtype=float)
    np.testing.assert_array_equal(find_pairs(lo + t, hi + t, method), find_pairs(lo, hi, method))


# ---------------------------------------------------------------- canonical_pairs itself
@given(st.lists(st.tuples(st.integers(0, 9), st.integers(0, 9)), max_size=60))
def test_canonical_pairs_is_the_sorted_set(rows):
    got = canonical_pairs(np.array(rows, dtype=np.int64).reshape(-1, 2), n=10)
    expected = sorted({(min(a, b), max(a, b)) for a, b in rows if a != b})
    assert got.tolist() == [list(p) for p in expected]
    assert_canonical(got)


# ---------------------------------------------------------------- validation at the boundary
@pytest.mark.parametrize("method", BROAD_PHASES)
def test_validation(method):
    lo = np.zeros((3, 2))
    hi = np.ones((3, 2))
    bad = hi.copy()
    bad[1, 1] = np.nan
    with pytest.raises(ValueError, match=r"hi\[1, 1\]"):
        find_pairs(lo, bad, method)
    inverted = hi.copy()
    inverted[2, 0] = -1.0
    with pytest.raises(ValueError, match=r"lo\[2, 0\]"):
        find_pairs(lo, inverted, method)
    with pytest.raises(ValueError, match="same shape"):
        find_pairs(lo, hi[:2], method)
    with pytest.raises(ValueError, match="d = 1, 2 or 3"):
        find_pairs(np.zeros((3, 4)), np.ones((3, 4)), method)
    with pytest.raises(TypeError):
        find_pairs(np.array([["a"]]), np.array([["b"]]), method)
    assert find_pairs(np.zeros((0, 3)), np.zeros((0, 3)), method).shape == (0, 2)
    assert find_pairs(np.zeros((1, 3)), np.zeros((1, 3)), method).shape == (0, 2)


def test_unknown_method():
    with pytest.raises(ValueError, match="method"):
        find_pairs(np.zeros((2, 3)), np.ones((2, 3)), "bvh")


def test_sweep_intervals_validation():
    with pytest.raises(ValueError, match=r"begin\[1\]"):
        sweep_intervals([0.0, 2.0], [1.0, 1.0])
    with pytest.raises(ValueError, match="end"):
        sweep_intervals([0.0, 1.0], [1.0, np.inf])


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("d", [1, 3])
@settings(max_examples=40)
@given(data=st.data())
def test_work_counts_are_consistent(method, d, data):
    """The work count of find_pairs(return_tests=True): brute force makes exactly (n² − n)/2 box tests; every
    method tests each pair it reports at least once; in 1-D the sweep (one column) tests exactly the pairs whose
    intervals overlap on its axis — the slide's 1-D sweep counts them independently. (In 3-D a pair sharing
    several columns of the multi-column sweep is tested in each, so no bound by brute force holds there.)"""
    lo, hi = data.draw(box_scenes(d=d))
    n = lo.shape[0]
    pairs, tests = find_pairs(lo, hi, method, return_tests=True)
    np.testing.assert_array_equal(pairs, find_pairs(lo, hi, "brute"))
    assert tests >= len(pairs)
    if method == "brute":
        assert tests == n * (n - 1) // 2
    elif method == "sap" and d == 1:
        assert tests == len(sweep_intervals(lo[:, 0], hi[:, 0]))


@settings(max_examples=60)
@given(box_scenes(d=3), st.integers(0, 2))
def test_single_column_sweep_tests_the_pairs_overlapping_on_its_axis(scene, axis):
    """Below 32 boxes the sweep uses one column: its box tests are exactly the pairs whose intervals overlap on
    the sweep axis, which the slide's 1-D sweep finds independently."""
    lo, hi = scene
    assume(lo.shape[0] < 32)
    pairs, tests = sap_pairs(lo, hi, axis=axis, return_tests=True)
    assert tests == len(sweep_intervals(lo[:, axis], hi[:, axis]))
