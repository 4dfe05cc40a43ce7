"""The dynamic AABB tree (Box2D's dynamic tree, Ericson 6.2/6.5) at the edges of its API: a fattening margin
given to ``from_boxes``, ``move`` reporting whether the leaf was re-inserted, ids one past the last, and a
query that finds more objects than its first result buffer holds. Oracle: brute force (numpy all-pairs)."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from engine.broadphase import DynamicAABBTree, find_pairs


def boxes(seed, n, spread):
    rng = np.random.default_rng(seed)
    lo = rng.uniform(-spread, spread, (n, 3))
    return lo, lo + rng.uniform(0.0, 2.0, (n, 3))


@given(st.integers(0, 2**32 - 1), st.integers(2, 40), st.floats(0.01, 3.0, allow_nan=False))
def test_from_boxes_with_a_margin_finds_exactly_the_overlapping_pairs(seed, n, margin):
    lo, hi = boxes(seed, n, 6.0)
    tree = DynamicAABBTree.from_boxes(lo, hi, margin=margin)
    np.testing.assert_array_equal(tree.pairs(), find_pairs(lo, hi, "brute"))
    tree.check_structure()


@given(st.integers(0, 2**32 - 1), st.integers(1, 30), st.floats(0.05, 1.0, allow_nan=False))
def test_move_inside_the_fat_box_is_not_a_reinsertion_and_a_far_move_is(seed, n, margin):
    lo, hi = boxes(seed, n, 6.0)
    tree = DynamicAABBTree.from_boxes(lo, hi, margin=margin)
    i = int(np.random.default_rng(seed).integers(n))
    assert tree.move(i, lo[i], hi[i]) is False  # the same box: inside its fat box
    far = 1e3 + 10.0 * i
    assert tree.move(i, lo[i] + far, hi[i] + far) is True
    lo2, hi2 = lo.copy(), hi.copy()
    lo2[i] += far
    hi2[i] += far
    np.testing.assert_array_equal(tree.pairs(), find_pairs(lo2, hi2, "brute"))


@given(st.integers(1, 40))
def test_ids_past_the_last_are_refused(n):
    lo, hi = boxes(n, n, 5.0)
    tree = DynamicAABBTree.from_boxes(lo, hi)
    for bad in (n, n + 1, -1):
        with pytest.raises(ValueError, match="not a live object"):
            tree.remove(bad)


@given(st.integers(17, 120), st.integers(0, 2**32 - 1))
def test_query_returning_more_ids_than_its_first_buffer(n, seed):
    """More than 16 hits: the result buffer of the query kernel grows; all the ids still come back."""
    lo, hi = boxes(seed, n, 3.0)
    tree = DynamicAABBTree.from_boxes(lo, hi)
    q_lo, q_hi = np.full(3, -10.0), np.full(3, 10.0)
    np.testing.assert_array_equal(tree.query(q_lo, q_hi), np.arange(n))
    inside = np.flatnonzero(np.all(lo <= 1.0, axis=1) & np.all(hi >= 0.0, axis=1))
    np.testing.assert_array_equal(tree.query(np.zeros(3), np.ones(3)), inside)


@given(st.integers(0, 2**32 - 1), st.integers(1, 30), st.floats(0.05, 1.0, allow_nan=False),
       st.floats(-0.9, 0.9, allow_nan=False))
def test_a_move_smaller_than_the_margin_keeps_the_leaf(seed, n, margin, fraction):
    """Inserted one by one, each leaf's fat box is its box grown by the margin on every side: a shift by less
    than the margin, up or down, stays inside it (no re-insertion), and the pairs follow the moved box."""
    lo, hi = boxes(seed, n, 6.0)
    tree = DynamicAABBTree(dim=3, margin=margin)
    assert [tree.insert(lo[k], hi[k]) for k in range(n)] == list(range(n))
    i = int(np.random.default_rng(seed).integers(n))
    shift = fraction * margin
    assert tree.move(i, lo[i] + shift, hi[i] + shift) is False
    lo2, hi2 = lo.copy(), hi.copy()
    lo2[i] += shift
    hi2[i] += shift
    np.testing.assert_array_equal(tree.pairs(), find_pairs(lo2, hi2, "brute"))


@settings(max_examples=40)
@given(st.integers(1, 40), st.integers(0, 2**16), st.integers(1, 3))
def test_node_boxes_are_the_tree(n, seed, d):
    """node_boxes lists every node depth first: its leaves are the objects' fat boxes, every node encloses the
    nodes of its subtree (those that follow it, deeper, until the depth comes back up), the deepest is the
    tree's height."""
    rng = np.random.default_rng(seed)
    lo = rng.uniform(0, 10, (n, d))
    tree = DynamicAABBTree.from_boxes(lo, lo + rng.uniform(0, 2, (n, d)))
    if n > 2:
        tree.remove(int(rng.integers(n)))
    nlo, nhi, depth, leaf = tree.node_boxes()
    assert depth[0] == 0 and depth.max() == tree.height and leaf.sum() == len(tree)
    assert len(depth) == 2 * len(tree) - 1
    fat = sorted(tuple(np.concatenate(tree.fat_box(i))) for i in tree.ids())
    assert sorted(tuple(np.concatenate([a, b])) for a, b in zip(nlo[leaf], nhi[leaf])) == fat
    for i in range(len(depth)):
        j = i + 1
        while j < len(depth) and depth[j] > depth[i]:
            assert (nlo[i] <= nlo[j]).all() and (nhi[j] <= nhi[i]).all()
            j += 1
        assert leaf[i] == (j == i + 1)
