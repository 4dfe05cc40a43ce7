"""The broad phase's public helpers, called directly: ``default_cell_size`` (the uniform grid's default cell
side) and ``build_octree`` (the loose octree as index arrays). ``find_pairs`` reaches their kernels without
them, so the pair properties cannot see a helper that mis-passes its arguments or drops a case; these state
the helpers' documented contracts against independent computations (numpy)."""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import example, given
from hypothesis import strategies as st

from engine.broadphase import build_octree
from engine.broadphase.uniform_grid import default_cell_size


def scene(seed, n, d, side_scale, flat_axes):
    """n boxes (n, d) in [-10, 10]^d, sides up to 2 × side_scale (0: points); the axes in flat_axes are flat."""
    rng = np.random.default_rng(seed)
    lo = rng.uniform(-10.0, 10.0, (n, d))
    hi = lo + rng.uniform(0.0, 2.0, (n, d)) * side_scale
    for k in flat_axes:
        if k < d:
            lo[:, k] = hi[:, k] = 1.5
    return lo, hi


def expected_cell_size(lo, hi):
    """The documented formula, in numpy: max(2 × mean largest side, (V / n)^(1/k)), or 1.0 when that is 0."""
    n = lo.shape[0]
    twice_mean_side = 2.0 * float(np.mean(np.max(hi - lo, axis=1)))
    extent = hi.max(axis=0) - lo.min(axis=0)
    positive = extent[extent > 0.0]
    spacing = float(np.prod(positive) / n) ** (1.0 / positive.size) if positive.size else 0.0
    size = max(twice_mean_side, spacing)
    return size if size > 0.0 else 1.0


@example(0, 5, 3, 0.0, ())  # points: the spacing (V / n)^(1/3) decides
@example(1, 10, 2, 1e-3, (1, 2))  # nearly points, one axis extended (k = 1)
@example(2, 30, 3, 1.0, ())  # boxes: twice the mean side decides
@given(st.integers(0, 2**32 - 1), st.integers(1, 50), st.integers(1, 3), st.sampled_from([0.0, 1e-3, 1.0, 5.0]),
       st.sampled_from([(), (0,), (1, 2), (0, 1, 2)]))
def test_default_cell_size_is_the_documented_formula(seed, n, d, side_scale, flat_axes):
    lo, hi = scene(seed, n, d, side_scale, flat_axes)
    lo_before, hi_before = lo.copy(), hi.copy()
    got = default_cell_size(lo, hi)
    assert isinstance(got, float) and got > 0.0
    assert math.isclose(got, expected_cell_size(lo, hi), rel_tol=1e-12)
    np.testing.assert_array_equal(lo, lo_before)  # the caller's arrays are not modified
    np.testing.assert_array_equal(hi, hi_before)


def test_default_cell_size_of_small_scenes():
    assert default_cell_size(np.zeros((0, 3)), np.zeros((0, 3))) == 1.0
    assert default_cell_size([[0.0, 0.0]], [[3.0, 1.0]]) == 6.0  # one box: twice its largest side
    # 8 points at the corners of a 2-cube: one point per 1-cube on average (the point-like fallback)
    corners = np.array([[x, y, z] for x in (0.0, 2.0) for y in (0.0, 2.0) for z in (0.0, 2.0)])
    assert math.isclose(default_cell_size(corners, corners), 1.0, rel_tol=1e-12)
    # 4 points on a segment of length 12 (k = 1): 3 per point
    points = np.array([[0.0, 5.0], [4.0, 5.0], [8.0, 5.0], [12.0, 5.0]])
    assert math.isclose(default_cell_size(points, points), 3.0, rel_tol=1e-12)
    assert default_cell_size(np.ones((5, 3)), np.ones((5, 3))) == 1.0  # one point five times: no size at all
    with pytest.raises(ValueError):
        default_cell_size([[1.0, 0.0, 0.0]], [[0.0, 0.0, 0.0]])


def octree_scene(seed, n, d, duplicates):
    rng = np.random.default_rng(seed)
    lo = rng.uniform(-10.0, 10.0, (n, d))
    hi = lo + rng.uniform(0.0, 3.0, (n, d))
    if duplicates:  # several boxes with the same centre: a leaf that cannot be cut
        same = rng.random(n) < 0.5
        lo[same], hi[same] = lo[0], hi[0]
    return lo, hi


@given(st.integers(0, 2**32 - 1), st.integers(1, 80), st.integers(1, 3), st.integers(1, 8), st.booleans())
def test_build_octree_is_the_documented_loose_octree(seed, n, d, leaf_size, duplicates):
    lo, hi = octree_scene(seed, n, d, duplicates)
    lo3 = np.zeros((n, 3))
    hi3 = np.zeros((n, 3))
    lo3[:, :d], hi3[:, :d] = lo, hi
    centre = 0.5 * lo3 + 0.5 * hi3
    perm, node_lo, node_hi, first, last, child0, n_children = build_octree(lo, hi, leaf_size)
    n_nodes = node_lo.shape[0]
    assert node_lo.shape == node_hi.shape == (n_nodes, 3)
    assert sorted(perm.tolist()) == list(range(n))
    assert n_nodes < 2 * n or n_nodes == 1

    def objects(node):
        """The objects below ``node``, from its leaves (each leaf holds perm[first:last])."""
        if n_children[node] == 0:
            return perm[first[node]:last[node]].tolist()
        return [o for t in range(n_children[node]) for o in objects(child0[node] + t)]

    in_leaves = []
    reached = set()
    stack = [0]
    while stack:
        node = stack.pop()
        reached.add(node)
        below = objects(node)
        # loose bounds: exactly the union of the full boxes of the objects below the node
        np.testing.assert_array_equal(node_lo[node], lo3[below].min(axis=0))
        np.testing.assert_array_equal(node_hi[node], hi3[below].max(axis=0))
        if n_children[node] == 0:
            assert child0[node] == -1  # documented mark of a leaf
            in_leaves += below
            # a leaf holds at most leaf_size objects, unless all their centres coincide (no cut separates them)
            assert len(below) <= leaf_size or np.all(centre[below] == centre[below[0]])
            continue
        assert len(below) > leaf_size
        assert 2 <= n_children[node] <= 8  # a cut separates the objects: at least two non-empty octants
        # each object is in the octant of its centre, around the midpoint of the node's centres
        c = centre[below]
        mid = 0.5 * c.min(axis=0) + 0.5 * c.max(axis=0)
        cut = (c.min(axis=0) < mid) & (mid <= c.max(axis=0))
        octants = []
        for t in range(n_children[node]):
            child = child0[node] + t
            codes = {tuple(bool(v) for v in (centre[o] >= mid) & cut) for o in objects(child)}
            assert len(codes) == 1  # one octant per child
            octants += codes
            stack.append(child)
        assert len(set(octants)) == len(octants)  # distinct octants
    assert sorted(in_leaves) == list(range(n))  # every object in exactly one leaf
    assert reached == set(range(n_nodes))  # every node is reachable from the root (node 0)


def test_build_octree_refuses_what_it_cannot_build():
    with pytest.raises(ValueError, match="leaf_size"):
        build_octree(np.zeros((2, 3)), np.ones((2, 3)), 0)
    with pytest.raises(ValueError, match="at least one box"):
        build_octree(np.zeros((0, 3)), np.zeros((0, 3)))
