"""The dynamic AABB tree's quality and fat boxes: what the pairs cannot show.

The tree's pairs are exact whatever its shape and margins (``test_broadphase*.py`` check that); what the shape
and the margins change is the cost of every later query and move. Two observable contracts:

- **Insertion follows Box2D's surface-area rule** (``b2DynamicTree::InsertLeaf``, the cost written in
  ``_insert_leaf_kernel``): a new leaf descends along the cheapest child and becomes the sibling of the node
  where stopping is cheaper. Oracle: the same rule written plainly on Python objects here; after the same
  inserts, both trees must have the same height and the same ``area_ratio`` (Box2D's ``GetAreaRatio``: the
  summed box cost of the nodes over the root's, i.e. the surface-area heuristic of the tree's query cost).
  A different descent (a wrong sign of the inherited cost, a leaf child costed like an inner node, ...) builds a
  different tree, whose pairs are still right but whose area ratio is not the documented one.
- **The fat box** of an object is its box grown on each side by ``margin``, or by 10 % of its largest side with
  the default ``margin=None`` — the same whether the tree is built by ``insert`` or by ``from_boxes``.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from engine.broadphase import DynamicAABBTree


def side_sum(lo, hi):
    """Box2D's perimeter in 1-3 D: the sum of the box's sides (lo, hi: 3 floats each)."""
    return (hi[0] - lo[0]) + (hi[1] - lo[1]) + (hi[2] - lo[2])


def union(lo_a, hi_a, lo_b, hi_b):
    return [min(x, y) for x, y in zip(lo_a, lo_b)], [max(x, y) for x, y in zip(hi_a, hi_b)]


class Node:
    def __init__(self, lo, hi, children=()):
        self.lo, self.hi, self.children, self.parent = lo, hi, list(children), None


class ReferenceTree:
    """Box2D's InsertLeaf on plain Python nodes (no arrays, no removal): the documented descent rule.

    At an inner node with U = P(node ∪ leaf): stopping costs 2U; going into child c costs
    P(c ∪ leaf) + 2(U − P(node)), minus P(c) when c is an inner node. Stop when stopping is strictly cheaper
    than both children, else go to the first child on a tie. The leaf becomes the sibling of where it stops.
    """

    def __init__(self):
        self.root = None

    def insert(self, lo, hi):
        leaf = Node(list(lo), list(hi))
        if self.root is None:
            self.root = leaf
            return
        node = self.root
        while node.children:
            a, b = node.children
            combined = side_sum(*union(node.lo, node.hi, leaf.lo, leaf.hi))
            cost = 2.0 * combined
            inheritance = 2.0 * (combined - side_sum(node.lo, node.hi))
            child_costs = []
            for child in (a, b):
                child_cost = side_sum(*union(child.lo, child.hi, leaf.lo, leaf.hi)) + inheritance
                if child.children:
                    child_cost -= side_sum(child.lo, child.hi)
                child_costs.append(child_cost)
            if cost < child_costs[0] and cost < child_costs[1]:
                break
            node = a if child_costs[0] <= child_costs[1] else b
        old_parent = node.parent
        new_parent = Node(*union(node.lo, node.hi, leaf.lo, leaf.hi), children=(node, leaf))
        node.parent = leaf.parent = new_parent
        new_parent.parent = old_parent
        if old_parent is None:
            self.root = new_parent
        else:
            old_parent.children[old_parent.children.index(node)] = new_parent
        up = old_parent
        while up is not None:  # refit the ancestors
            up.lo, up.hi = union(*[v for c in up.children for v in (c.lo, c.hi)])
            up = up.parent

    def nodes(self):
        stack = [self.root] if self.root is not None else []
        while stack:
            node = stack.pop()
            yield node
            stack.extend(node.children)

    def height(self):
        def h(node):
            return 0 if not node.children else 1 + max(h(c) for c in node.children)
        return -1 if self.root is None else h(self.root)

    def area_ratio(self):
        if self.root is None:
            return 0.0
        root = side_sum(self.root.lo, self.root.hi)
        return sum(side_sum(n.lo, n.hi) for n in self.nodes()) / root if root > 0.0 else 0.0


def random_boxes(seed, n, d, layout):
    """n boxes (n, d): uniform in a cube, clustered around a few centres, or along a line (coherent order)."""
    rng = np.random.default_rng(seed)
    if layout == "uniform":
        lo = rng.uniform(-10.0, 10.0, (n, d))
    elif layout == "clusters":
        centres = rng.uniform(-10.0, 10.0, (3, d))
        lo = centres[rng.integers(0, 3, n)] + rng.normal(0.0, 0.5, (n, d))
    else:
        lo = np.outer(np.arange(n, dtype=float), rng.uniform(0.2, 1.0, d)) + rng.uniform(-0.3, 0.3, (n, d))
    return lo, lo + rng.uniform(0.0, 2.0, (n, d))


def padded(v):
    out = [0.0, 0.0, 0.0]
    out[: len(v)] = [float(x) for x in v]
    return out


@given(st.integers(0, 2**32 - 1), st.integers(2, 40), st.integers(1, 3),
       st.sampled_from(["uniform", "clusters", "line"]), st.sampled_from([None, 0.0, 0.25]))
def test_inserted_tree_is_the_documented_surface_area_descent(seed, n, d, layout, margin):
    lo, hi = random_boxes(seed, n, d, layout)
    tree = DynamicAABBTree(dim=d, margin=margin)
    reference = ReferenceTree()
    for i in range(n):
        obj = tree.insert(lo[i], hi[i])
        fat_lo, fat_hi = tree.fat_box(obj)
        reference.insert(padded(fat_lo), padded(fat_hi))
    tree.check_structure()
    assert tree.height == reference.height()
    assert math.isclose(tree.area_ratio(), reference.area_ratio(), rel_tol=1e-12)


@given(st.integers(0, 2**32 - 1), st.integers(2, 30))
def test_area_ratio_is_box2d_get_area_ratio(seed, n):
    """Leaves + inner nodes over the root, every node's box enclosing its children's: the ratio is at least
    1 + (the leaves' share), since the root is counted too; a batch-built tree reports it as well."""
    lo, hi = random_boxes(seed, n, 3, "uniform")
    tree = DynamicAABBTree.from_boxes(lo, hi, margin=0.0)
    root = side_sum(lo.min(axis=0), hi.max(axis=0))
    leaves = float((hi - lo).sum())
    ratio = tree.area_ratio()
    assert ratio >= 1.0 + leaves / root - 1e-12
    # every inner node's cost is at most the root's: n − 1 inner nodes (root included)
    assert ratio <= (n - 1) + leaves / root + 1e-12


def test_area_ratio_of_small_trees():
    tree = DynamicAABBTree()
    assert tree.area_ratio() == 0.0
    a = tree.insert([0.0, 0.0, 0.0], [1.0, 1.0, 1.0])
    assert tree.area_ratio() == 1.0  # a single leaf is the root
    tree.insert([2.0, 0.0, 0.0], [3.0, 1.0, 1.0])
    # leaves 1.2·3 each (10 % margin of side 1 on both sides), root [-0.1, 3.1] × [-0.1, 1.1]²: 3.2 + 2.4
    assert math.isclose(tree.area_ratio(), (5.6 + 3.6 + 3.6) / 5.6, rel_tol=1e-12)
    tree.remove(a)
    assert tree.area_ratio() == 1.0
    # in 1-D the cost is the length: fat boxes [-0.1, 1.1] and [1.9, 3.1] under a root [-0.1, 3.1], whether built
    # in batch or by inserts (the unused axes are not fattened)
    batch = DynamicAABBTree.from_boxes([[0.0], [2.0]], [[1.0], [3.0]])
    incremental = DynamicAABBTree(dim=1)
    incremental.insert([0.0], [1.0])
    incremental.insert([2.0], [3.0])
    for one_d in (batch, incremental):
        assert math.isclose(one_d.area_ratio(), (3.2 + 1.2 + 1.2) / 3.2, rel_tol=1e-12)
    small = DynamicAABBTree(margin=0.0)
    small.insert([0.0, 0.0, 0.0], [0.1, 0.1, 0.1])
    assert small.area_ratio() == 1.0  # a root smaller than 1 still counts
    point = DynamicAABBTree(margin=0.0)
    point.insert([1.0, 2.0, 3.0], [1.0, 2.0, 3.0])
    assert point.area_ratio() == 0.0  # a root of zero size: no ratio (and no division by zero)


@given(st.integers(0, 2**32 - 1), st.integers(1, 30), st.integers(1, 3),
       st.sampled_from([None, 0.0, 0.5, 3.0]), st.sampled_from([1.0, 1e-3, 1e3]))
def test_fat_box_is_the_box_grown_by_the_documented_margin(seed, n, d, margin, scale):
    rng = np.random.default_rng(seed)
    lo = rng.uniform(-5.0, 5.0, (n, d)) * scale
    hi = lo + rng.uniform(0.0, 2.0, (n, d)) * scale
    grow = 0.1 * (hi - lo).max(axis=1) if margin is None else np.full(n, margin)
    batch = DynamicAABBTree.from_boxes(lo, hi, margin=margin)
    incremental = DynamicAABBTree(dim=d, margin=margin)
    for i in range(n):
        assert incremental.insert(lo[i], hi[i]) == i
    for tree in (batch, incremental):
        for i in range(n):
            fat_lo, fat_hi = tree.fat_box(i)
            assert fat_lo.shape == fat_hi.shape == (d,)
            tol = 1e-12 * scale
            np.testing.assert_allclose(fat_lo, lo[i] - grow[i], rtol=0.0, atol=tol)
            np.testing.assert_allclose(fat_hi, hi[i] + grow[i], rtol=0.0, atol=tol)
            assert np.all(fat_lo <= lo[i]) and np.all(hi[i] <= fat_hi)


def test_fat_box_follows_a_reinsertion_and_is_a_copy():
    tree = DynamicAABBTree(dim=2)
    i = tree.insert([0.0, 0.0], [2.0, 1.0])
    np.testing.assert_allclose(tree.fat_box(i)[0], [-0.2, -0.2])
    assert tree.move(i, [0.1, 0.0], [2.1, 1.0]) is False  # still inside: the fat box stays
    np.testing.assert_allclose(tree.fat_box(i)[1], [2.2, 1.2])
    assert tree.move(i, [10.0, 10.0], [14.0, 11.0]) is True  # re-inserted: grown by 10 % of the new side 4
    fat_lo, fat_hi = tree.fat_box(i)
    np.testing.assert_allclose(fat_lo, [9.6, 9.6])
    np.testing.assert_allclose(fat_hi, [14.4, 11.4])
    fat_lo[:] = 0.0  # a copy: the tree is not changed through it
    np.testing.assert_allclose(tree.fat_box(i)[0], [9.6, 9.6])
    tree.remove(i)
    with pytest.raises(ValueError, match="not a live object"):
        tree.fat_box(i)
