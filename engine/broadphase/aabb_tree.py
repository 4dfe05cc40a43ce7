"""Dynamic AABB tree: the hierarchy ("un arbre") used by Box2D, Bullet (btDbvt) and FCL, stored as index arrays.

Chapter slides "Phase Large : Subdivision spatiale" (non uniforme: "une hiérarchie ! un « arbre »"); Ericson,
*Real-Time Collision Detection* 6.1–6.2 (bounding volume hierarchies, top-down build), 6.5 (tree traversal);
Box2D's ``b2DynamicTree`` for the incremental operations:

- ``insert``: a leaf holding a *fattened* box (the object's box grown by a margin) goes down the tree along the
  cheapest branch (the increase of the summed box sides, a perimeter cost as in Box2D) and becomes the sibling
  of the node where the descent stops; the boxes of its ancestors are refitted on the way back up;
- ``remove``: the leaf's sibling takes its parent's place;
- ``move``: while the object's box stays inside its fat box nothing changes; otherwise remove + insert;
- ``pairs``: every object descends the nodes whose (fat) boxes overlap its own box; at a leaf the two *exact*
  boxes are compared, so the pairs are exactly the overlapping boxes whatever the margins;
- ``rebuild``: a batch top-down build (median-of-extent split on the widest axis of the centres, 6.2.1).

There are no tree rotations: a long sequence of moves can unbalance the tree; ``rebuild()`` restores it.
"""
from __future__ import annotations

from collections import namedtuple
from typing import Literal, overload

import numpy as np
from numpy.typing import ArrayLike

import engine.broadphase.pairs as pair_buffer
from engine._config import njit
from engine._validate import as_choice, as_float_array, as_nonnegative
from engine.bounding.aabb import enclose_aabbs
from engine.broadphase.incremental import IncrementalBroadPhase
from engine.broadphase.pairs import (
    as_boxes,
    as_boxes_3d,
    as_one_box,
    as_threads,
    boxes_overlap,
    empty_pairs,
    with_tests,
)

__all__ = ["DynamicAABBTree", "TreeArrays", "tree_pairs", "tree_leaf_pairs", "tree_query_boxes"]

#: a tree's arrays for compiled traversals (``DynamicAABBTree.arrays``)
TreeArrays = namedtuple("TreeArrays", "root node_lo node_hi child1 child2 obj_of")


@njit
def _refit_upwards(index, node_lo, node_hi, parent, child1, child2, height):
    """Walk from ``index`` to the root, refitting each node's box and height to its two children."""
    while index != -1:
        a = child1[index]
        b = child2[index]
        for k in range(3):
            node_lo[index, k] = min(node_lo[a, k], node_lo[b, k])
            node_hi[index, k] = max(node_hi[a, k], node_hi[b, k])
        height[index] = 1 + max(height[a], height[b])
        index = parent[index]


@njit
def _sides(lo0, lo1, lo2, hi0, hi1, hi2):
    return (hi0 - lo0) + (hi1 - lo1) + (hi2 - lo2)


@njit
def _union_cost(node_lo, node_hi, a, b):
    """Sum of the sides of the union of node boxes a and b (the perimeter cost of Box2D, in 1-3 D)."""
    return _sides(min(node_lo[a, 0], node_lo[b, 0]), min(node_lo[a, 1], node_lo[b, 1]),
                  min(node_lo[a, 2], node_lo[b, 2]), max(node_hi[a, 0], node_hi[b, 0]),
                  max(node_hi[a, 1], node_hi[b, 1]), max(node_hi[a, 2], node_hi[b, 2]))


@njit
def _own_cost(node_lo, node_hi, a):
    return _sides(node_lo[a, 0], node_lo[a, 1], node_lo[a, 2], node_hi[a, 0], node_hi[a, 1], node_hi[a, 2])


@njit
def _insert_leaf_kernel(leaf, new_parent, root, node_lo, node_hi, parent, child1, child2, height):
    # Box2D b2DynamicTree::InsertLeaf: descend along the cheapest branch, then pair the leaf with the sibling.
    # With P(box) the sum of its sides and U = P(node ∪ leaf): stopping at an inner node costs 2U; going into a
    # child c costs P(c ∪ leaf) + 2(U − P(node)), minus P(c) when c is an inner node (only its growth counts).
    # Stop when stopping is strictly cheaper than both children; otherwise go to child1 on a tie.
    if root == -1:
        parent[leaf] = -1
        return leaf
    index = root
    while child1[index] != -1:
        a = child1[index]
        b = child2[index]
        area = _own_cost(node_lo, node_hi, index)
        combined = _union_cost(node_lo, node_hi, index, leaf)
        cost = 2.0 * combined
        inheritance = 2.0 * (combined - area)
        cost_a = _union_cost(node_lo, node_hi, a, leaf) + inheritance
        if child1[a] != -1:
            cost_a -= _own_cost(node_lo, node_hi, a)
        cost_b = _union_cost(node_lo, node_hi, b, leaf) + inheritance
        if child1[b] != -1:
            cost_b -= _own_cost(node_lo, node_hi, b)
        if cost < cost_a and cost < cost_b:
            break
        index = a if cost_a <= cost_b else b
    sibling = index
    old_parent = parent[sibling]
    parent[new_parent] = old_parent
    child1[new_parent] = sibling
    child2[new_parent] = leaf
    parent[sibling] = new_parent
    parent[leaf] = new_parent
    if old_parent != -1:
        if child1[old_parent] == sibling:
            child1[old_parent] = new_parent
        else:
            child2[old_parent] = new_parent
    else:
        root = new_parent
    _refit_upwards(new_parent, node_lo, node_hi, parent, child1, child2, height)
    return root


@njit
def _remove_leaf_kernel(leaf, root, node_lo, node_hi, parent, child1, child2, height):
    """Box2D b2DynamicTree::RemoveLeaf; returns (new root, freed inner node or −1)."""
    if leaf == root:
        return -1, -1
    p = parent[leaf]
    grand = parent[p]
    sibling = child2[p] if child1[p] == leaf else child1[p]
    if grand != -1:
        if child1[grand] == p:
            child1[grand] = sibling
        else:
            child2[grand] = sibling
        parent[sibling] = grand
        _refit_upwards(grand, node_lo, node_hi, parent, child1, child2, height)
        return root, p
    parent[sibling] = -1
    return sibling, p


@njit
def _fit_node(items, s, e, box_lo, box_hi, node_lo, node_hi, node):
    """Fit node ``node`` to the objects items[s:e]; (centres' lowest corner, highest corner, widest axis)."""
    cmin = np.empty(3)
    cmax = np.empty(3)
    enclose_aabbs(box_lo, box_hi, items[s:e], node_lo[node], node_hi[node], cmin, cmax)
    axis = 0
    for k in range(1, 3):
        if cmax[k] - cmin[k] > cmax[axis] - cmin[axis]:
            axis = k
    return cmin, cmax, axis


@njit
def _split_items(items, s, e, box_lo, box_hi, node_lo, node_hi, node):
    """Fit node ``node`` to the objects items[s:e] and choose where they split (Ericson 6.2.1): the midpoint of
    their centres along the widest axis of the centres, items[s:e] partitioned so that centres < mid come first;
    at half the count if every centre coincides. Returns the split index."""
    cmin, cmax, axis = _fit_node(items, s, e, box_lo, box_hi, node_lo, node_hi, node)
    mid = 0.5 * cmin[axis] + 0.5 * cmax[axis]
    if not (cmin[axis] < mid and mid <= cmax[axis]):
        return (s + e) // 2
    split = s
    for p in range(s, e):  # partition: centres < mid first
        t = items[p]
        if 0.5 * box_lo[t, axis] + 0.5 * box_hi[t, axis] < mid:
            items[p] = items[split]
            items[split] = t
            split += 1
    return split


#: how ``from_boxes`` splits a node's objects
SPLITS = ("midpoint", "sah")
#: bins of the surface-area split (``from_boxes(..., split="sah")``)
SAH_BINS = 16


@njit
def _half_area(lo0, lo1, lo2, hi0, hi1, hi2):
    dx, dy, dz = hi0 - lo0, hi1 - lo1, hi2 - lo2
    return dx * dy + dy * dz + dz * dx


@njit
def _split_items_sah(items, s, e, box_lo, box_hi, node_lo, node_hi, node):
    """As ``_split_items``, with the split that minimises the surface area heuristic over SAH_BINS bins of the
    centres along their widest axis (Wald 2007, binned SAH; Ericson 6.2.1): area(left)·count(left) +
    area(right)·count(right). A ray meets a box with a chance proportional to its area, so this tree is the one
    rays walk fastest."""
    cmin, cmax, axis = _fit_node(items, s, e, box_lo, box_hi, node_lo, node_hi, node)
    width = cmax[axis] - cmin[axis]
    if not width > 0.0:
        return (s + e) // 2
    count = np.zeros(SAH_BINS, np.int64)
    blo = np.full((SAH_BINS, 3), np.inf)
    bhi = np.full((SAH_BINS, 3), -np.inf)
    for p in range(s, e):
        t = items[p]
        c = min(int((0.5 * box_lo[t, axis] + 0.5 * box_hi[t, axis] - cmin[axis]) / width * SAH_BINS), SAH_BINS - 1)
        count[c] += 1
        for k in range(3):
            blo[c, k] = min(blo[c, k], box_lo[t, k])
            bhi[c, k] = max(bhi[c, k], box_hi[t, k])
    right_cost = np.zeros(SAH_BINS)  # right_cost[b]: area × count of bins b .. end
    lo = np.full(3, np.inf)
    hi = np.full(3, -np.inf)
    n = 0
    for b in range(SAH_BINS - 1, 0, -1):
        n += count[b]
        for k in range(3):
            lo[k], hi[k] = min(lo[k], blo[b, k]), max(hi[k], bhi[b, k])
        right_cost[b] = _half_area(lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]) * n if n else 0.0
    lo[:], hi[:], n = np.inf, -np.inf, 0
    best, best_bin = np.inf, -1
    for b in range(SAH_BINS - 1):  # split between bins b and b + 1
        n += count[b]
        for k in range(3):
            lo[k], hi[k] = min(lo[k], blo[b, k]), max(hi[k], bhi[b, k])
        if n == 0 or n == e - s:
            continue
        cost = _half_area(lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]) * n + right_cost[b + 1]
        if cost < best:
            best, best_bin = cost, b
    if best_bin < 0:
        return (s + e) // 2
    split = s
    for p in range(s, e):  # partition: the bins up to best_bin first
        t = items[p]
        c = min(int((0.5 * box_lo[t, axis] + 0.5 * box_hi[t, axis] - cmin[axis]) / width * SAH_BINS), SAH_BINS - 1)
        if c <= best_bin:
            items[p] = items[split]
            items[split] = t
            split += 1
    return split


@njit(inline="always")
def _build_nodes(box_lo, box_hi, node_lo, node_hi, parent, child1, child2, height, leaf_of, obj_of, split_items):
    # Ericson 6.2.1, top-down: split the objects at the midpoint of their centres along the widest axis
    # (at half the count if every centre coincides: split_items = _split_items), or by the binned surface-area
    # heuristic (_split_items_sah); inlined into each kernel below, which compiles only its own split. Nodes
    # 0..2m-2, root 0; leaf_of[t] is object t's leaf.
    m = box_lo.shape[0]
    items = np.arange(m)
    n_nodes = 1
    stack = np.empty((2 * m, 3), dtype=np.int64)  # (node, first item, end item) of the nodes still to build
    stack[0, 0] = 0
    stack[0, 1] = 0
    stack[0, 2] = m
    parent[0] = -1
    top = 1
    while top > 0:
        top -= 1
        node, s, e = stack[top, 0], stack[top, 1], stack[top, 2]
        if e - s == 1:
            for k in range(3):
                node_lo[node, k] = box_lo[items[s], k]
                node_hi[node, k] = box_hi[items[s], k]
            child1[node] = -1
            child2[node] = -1
            height[node] = 0
            leaf_of[items[s]] = node
            obj_of[node] = items[s]
            continue
        split = split_items(items, s, e, box_lo, box_hi, node_lo, node_hi, node)
        a = n_nodes
        b = n_nodes + 1
        n_nodes += 2
        child1[node] = a
        child2[node] = b
        parent[a] = node
        parent[b] = node
        obj_of[node] = -1
        stack[top, 0], stack[top, 1], stack[top, 2] = a, s, split
        stack[top + 1, 0], stack[top + 1, 1], stack[top + 1, 2] = b, split, e
        top += 2
    # heights, bottom-up (children always have larger indices than their parent)
    for node in range(n_nodes - 1, -1, -1):
        if child1[node] != -1:
            height[node] = 1 + max(height[child1[node]], height[child2[node]])
    return n_nodes


@njit
def _build_kernel(box_lo, box_hi, node_lo, node_hi, parent, child1, child2, height, leaf_of, obj_of):
    # the top-down build, split at the midpoint of the centres
    return _build_nodes(box_lo, box_hi, node_lo, node_hi, parent, child1, child2, height, leaf_of, obj_of,
                        _split_items)


@njit
def _build_sah_kernel(box_lo, box_hi, node_lo, node_hi, parent, child1, child2, height, leaf_of, obj_of):
    # the top-down build, split by the binned surface-area heuristic
    return _build_nodes(box_lo, box_hi, node_lo, node_hi, parent, child1, child2, height, leaf_of, obj_of,
                        _split_items_sah)


@njit
def _leaf_range_pairs(root, node_lo, node_hi, child1, child2, obj_of, obj_lo, obj_hi, obj_node, n_objects, first,
                      last, out):
    # Ericson 6.5 / Box2D b2DynamicTree::Query: each object descends the nodes whose fat box overlaps its exact
    # box; at a leaf holding object j > i the exact boxes are compared. The objects of the node slots first ..
    # last − 1, in node order (leaves of a subtree are close: consecutive queries share branches).
    count = 0
    tests = 0
    stack = np.empty(node_lo.shape[0] + 1, dtype=np.int64)
    for leaf in range(first, last):
        if child1[leaf] != -1:
            continue
        i = obj_of[leaf]
        if i < 0 or i >= n_objects or obj_node[i] != leaf:
            continue  # a free slot, not a live leaf
        top = 1
        stack[0] = root
        while top > 0:
            top -= 1
            node = stack[top]
            tests += 1  # the object's box against the node's box
            if (obj_lo[i, 0] > node_hi[node, 0] or node_lo[node, 0] > obj_hi[i, 0]
                    or obj_lo[i, 1] > node_hi[node, 1] or node_lo[node, 1] > obj_hi[i, 1]
                    or obj_lo[i, 2] > node_hi[node, 2] or node_lo[node, 2] > obj_hi[i, 2]):
                continue
            if child1[node] == -1:
                j = obj_of[node]
                if j > i and boxes_overlap(obj_lo, obj_hi, i, j):
                    out, count = pair_buffer.push_pair(out, count, i, j)
            else:
                stack[top] = child1[node]
                stack[top + 1] = child2[node]
                top += 2
    return out, count, tests


@njit
def tree_leaf_pairs(root, node_lo, node_hi, child1, child2, obj_of, obj_lo, obj_hi, obj_node, n_objects):
    """All pairs of objects of a tree stored as index arrays whose exact boxes overlap: (pairs, tests).

    Nodes: node_lo, node_hi (m, 3) float64 boxes; child1, child2 (m,) int64 (−1 at a leaf); obj_of (m,) int64
    the object of a leaf; root the root node (−1: empty). Objects: obj_lo, obj_hi (n, 3) float64 exact boxes,
    obj_node (n,) int64 the leaf of each object, ids 0..n_objects−1. A node slot is a live leaf only if it is a
    leaf whose object points back to it: free slots are skipped whatever they hold. Returns canonical pairs
    (int64 (k, 2)) and the number of box tests of the traversal.
    """
    if root == -1:
        return pair_buffer.new_pair_buffer(np.int64(0))[:0].copy(), 0
    out, count, tests = _leaf_range_pairs(root, node_lo, node_hi, child1, child2, obj_of, obj_lo, obj_hi, obj_node,
                                          n_objects, np.int64(0), node_lo.shape[0],
                                          pair_buffer.new_pair_buffer(n_objects))
    return pair_buffer.canonicalise_pairs(out, count, n_objects), tests


@njit
def _descend_query(root, node_lo, node_hi, child1, child2, obj_of, obj_lo, obj_hi, q_lo, q_hi, row, stack, out,
                   count):
    """Push (row, j) for every object j whose exact box overlaps the query box [q_lo, q_hi] ((3,) each): descend
    the nodes the query box overlaps (Ericson 6.5, Box2D ``b2DynamicTree_Query``). Returns (out, count)."""
    top = 1
    stack[0] = root
    while top > 0:
        top -= 1
        node = stack[top]
        hit = True
        for k in range(3):
            if q_lo[k] > node_hi[node, k] or node_lo[node, k] > q_hi[k]:
                hit = False
        if not hit:
            continue
        if child1[node] == -1:
            j = obj_of[node]
            for k in range(3):
                if q_lo[k] > obj_hi[j, k] or obj_lo[j, k] > q_hi[k]:
                    hit = False
            if hit:
                out, count = pair_buffer.push_pair(out, count, row, j)
        else:
            stack[top] = child1[node]
            stack[top + 1] = child2[node]
            top += 2
    return out, count


@njit
def _query_box_kernel(root, node_lo, node_hi, child1, child2, obj_of, obj_lo, obj_hi, q_lo, q_hi):
    """Ids of the objects whose exact box overlaps the query box [q_lo, q_hi] ((3,) each), ascending."""
    if root == -1:
        return np.empty(0, dtype=np.int64)
    stack = np.empty(node_lo.shape[0] + 1, dtype=np.int64)
    zero = np.int64(0)  # an int64, not a literal: one specialisation of the callees for every caller
    out, count = _descend_query(root, node_lo, node_hi, child1, child2, obj_of, obj_lo, obj_hi, q_lo, q_hi, zero,
                                stack, pair_buffer.new_pair_buffer(np.int64(16)), zero)
    return np.sort(out[:count, 1])


@njit
def tree_query_boxes(root, node_lo, node_hi, child1, child2, obj_of, obj_lo, obj_hi, q_lo, q_hi):
    """Every (query row r, object j) whose boxes overlap, for the query boxes [q_lo[r], q_hi[r]] ((m, 3) each),
    in the order of the rows (objects unordered within a row): int64 (k, 2). The tree as in
    ``tree_leaf_pairs``."""
    out = pair_buffer.new_pair_buffer(q_lo.shape[0])
    count = np.int64(0)  # an int64 from the start: _descend_query is compiled for one count type
    if root == -1:
        return out[:0].copy()
    stack = np.empty(node_lo.shape[0] + 1, dtype=np.int64)
    for r in range(q_lo.shape[0]):
        out, count = _descend_query(root, node_lo, node_hi, child1, child2, obj_of, obj_lo, obj_hi, q_lo[r],
                                    q_hi[r], r, stack, out, count)
    return out[:count].copy()


@njit
def _refit_kernel(root, node_lo, node_hi, child1, child2, obj_of, obj_lo, obj_hi):
    """Every leaf's box set to its object's box, then every inner node's to the union of its children's — children
    before parents: the reverse of a depth-first preorder. Returns the summed box sides of the inner nodes over
    the root's (the tree's quality: it grows as the objects move away from where the tree was built)."""
    order = np.empty(node_lo.shape[0], np.int64)
    stack = np.empty(node_lo.shape[0] + 1, np.int64)
    stack[0], top, count = root, 1, 0
    while top > 0:
        top -= 1
        node = stack[top]
        order[count] = node
        count += 1
        if child1[node] != -1:
            stack[top], stack[top + 1] = child1[node], child2[node]
            top += 2
    inner = 0.0
    for q in range(count - 1, -1, -1):
        node = order[q]
        a, b = child1[node], child2[node]
        for k in range(3):
            if a == -1:
                node_lo[node, k], node_hi[node, k] = obj_lo[obj_of[node], k], obj_hi[obj_of[node], k]
            else:
                node_lo[node, k] = min(node_lo[a, k], node_lo[b, k])
                node_hi[node, k] = max(node_hi[a, k], node_hi[b, k])
        if a != -1:
            inner += _sides(node_lo[node, 0], node_lo[node, 1], node_lo[node, 2], node_hi[node, 0],
                            node_hi[node, 1], node_hi[node, 2])
    top_sides = _sides(node_lo[root, 0], node_lo[root, 1], node_lo[root, 2], node_hi[root, 0], node_hi[root, 1],
                       node_hi[root, 2])
    return inner / top_sides if top_sides > 0.0 else 0.0


class DynamicAABBTree(IncrementalBroadPhase):
    """A dynamic AABB tree over objects with ids, as Box2D, Bullet and FCL use (see the module's description).

    ``insert(lo_i, hi_i) -> id``; ``remove(id)``; ``move(id, lo_i, hi_i) -> bool`` (True when the leaf had to
    be re-inserted); ``update(lo, hi) -> pairs`` moves every live object (rows in ascending id order);
    ``pairs()``; ``query(lo_q, hi_q) -> ids``; ``rebuild()``; ``DynamicAABBTree.from_boxes(lo, hi)`` builds in
    batch. Each leaf stores its object's box fattened by ``margin``, so small moves leave the tree unchanged;
    pairs and queries compare the exact boxes, so they are the overlapping closed boxes whatever the margin.

    Parameters
    ----------
    dim : int, optional
        The dimension d of the boxes: 1, 2 or 3 (default 3).
    margin : float or None, optional
        How much a leaf's box is fattened on each side: an absolute length >= 0, or None (the default) for 10 %
        of the largest side of the object's box when its leaf is inserted.

    Attributes
    ----------
    margin : float or None
        As given.

    Raises
    ------
    ValueError
        When ``dim`` is not 1, 2 or 3, or ``margin`` is negative or not finite.
    TypeError
        When ``margin`` is not a real number.

    See Also
    --------
    tree_pairs : the same tree built in batch for a one-off query of all pairs.

    Examples
    --------
    >>> from engine.broadphase import DynamicAABBTree
    >>> tree = DynamicAABBTree(dim=2)
    >>> a = tree.insert([0.0, 0.0], [1.0, 1.0])
    >>> b = tree.insert([0.5, 0.5], [2.0, 2.0])
    >>> tree.pairs()
    array([[0, 1]])
    >>> tree.move(b, [3.0, 3.0], [4.0, 4.0])  # left its fat box: its leaf is re-inserted
    True
    >>> tree.query([2.5, 2.5], [3.5, 3.5])
    array([1])
    """

    def __init__(self, dim: int = 3, margin: float | None = None):
        if isinstance(dim, bool) or not isinstance(dim, int | np.integer) or dim not in (1, 2, 3):
            raise ValueError(f"dim must be 1, 2 or 3, got {dim!r}")
        self._d = int(dim)
        self.margin = None if margin is None else as_nonnegative(margin, "margin")
        self._alloc_nodes(16)
        self._obj_lo = np.zeros((16, 3))
        self._obj_hi = np.zeros((16, 3))
        self._obj_node = np.full(16, -1, dtype=np.int64)
        self._n_ids = 0
        self._free_ids: list[int] = []
        self._root = -1

    # -- storage --------------------------------------------------------------------------------------
    def _alloc_nodes(self, capacity: int) -> None:
        self._node_lo = np.zeros((capacity, 3))
        self._node_hi = np.zeros((capacity, 3))
        self._parent = np.full(capacity, -1, dtype=np.int64)
        self._child1 = np.full(capacity, -1, dtype=np.int64)
        self._child2 = np.full(capacity, -1, dtype=np.int64)
        self._height = np.zeros(capacity, dtype=np.int64)
        self._obj_of = np.full(capacity, -1, dtype=np.int64)
        self._free_nodes = list(range(capacity - 1, -1, -1))

    def _new_node(self) -> int:
        if not self._free_nodes:
            old = self._node_lo.shape[0]
            new = 2 * old
            for name in ("_node_lo", "_node_hi"):
                grown: np.ndarray = np.zeros((new, 3))
                grown[:old] = getattr(self, name)
                setattr(self, name, grown)
            for name, fill in (("_parent", -1), ("_child1", -1), ("_child2", -1), ("_height", 0), ("_obj_of", -1)):
                grown = np.full(new, fill, dtype=np.int64)
                grown[:old] = getattr(self, name)
                setattr(self, name, grown)
            self._free_nodes = list(range(new - 1, old - 1, -1))
        return self._free_nodes.pop()

    def _free_node(self, node: int) -> None:
        self._child1[node] = -1
        self._child2[node] = -1
        self._parent[node] = -1
        self._obj_of[node] = -1
        self._height[node] = 0
        self._free_nodes.append(node)

    def _one_box(self, lo_i: ArrayLike, hi_i: ArrayLike,
                 names: tuple[str, str] = ("lo_i", "hi_i")) -> tuple[np.ndarray, np.ndarray]:
        """The validated box [lo_i, hi_i] ((d,) each) padded to 3-D ((3,) each, unused axes [0, 0])."""
        lo_d, hi_d = as_one_box(lo_i, hi_i, self._d, names)
        lo3 = np.zeros(3)
        hi3 = np.zeros(3)
        lo3[: self._d] = lo_d
        hi3[: self._d] = hi_d
        return lo3, hi3

    def _is_live(self, obj_id: int) -> bool:
        return 0 <= obj_id < self._n_ids and bool(self._obj_node[obj_id] >= 0)

    def _fat(self, lo3: np.ndarray, hi3: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        grow = np.zeros(3)  # along the tree's d axes only: the unused axes stay flat (cost = d-D perimeter)
        grow[: self._d] = 0.1 * float((hi3 - lo3).max()) if self.margin is None else self.margin
        fat_lo = lo3 - grow
        fat_hi = hi3 + grow
        return np.minimum(fat_lo, lo3), np.maximum(fat_hi, hi3)  # round-off never shrinks the fat box

    def _insert_node(self, obj_id: int) -> None:
        leaf = self._new_node()
        fat_lo, fat_hi = self._fat(self._obj_lo[obj_id], self._obj_hi[obj_id])
        self._node_lo[leaf] = fat_lo
        self._node_hi[leaf] = fat_hi
        self._child1[leaf] = -1
        self._child2[leaf] = -1
        self._height[leaf] = 0
        self._obj_of[leaf] = obj_id
        self._obj_node[obj_id] = leaf
        new_parent = self._new_node() if self._root != -1 else -1
        self._root = int(_insert_leaf_kernel(leaf, new_parent, self._root, self._node_lo, self._node_hi,
                                             self._parent, self._child1, self._child2, self._height))

    def _remove_node(self, obj_id: int) -> None:
        leaf = int(self._obj_node[obj_id])
        root, freed = _remove_leaf_kernel(leaf, self._root, self._node_lo, self._node_hi, self._parent,
                                          self._child1, self._child2, self._height)
        self._root = int(root)
        if freed >= 0:
            self._free_node(int(freed))
        self._free_node(leaf)
        self._obj_node[obj_id] = -1

    # -- public operations (dim, len, ids, remove, update, pairs: documented by IncrementalBroadPhase) ------

    @property
    def height(self) -> int:
        """Height of the tree (a single leaf has height 0; an empty tree −1)."""
        return -1 if self._root == -1 else int(self._height[self._root])

    def ids(self) -> np.ndarray:
        return np.flatnonzero(self._obj_node[: self._n_ids] >= 0).astype(np.int64)

    def fat_box(self, obj_id: int) -> tuple[np.ndarray, np.ndarray]:
        """The fattened box that an object's leaf stores.

        It is the object's box grown on each side by ``margin`` (or, with ``margin=None``, by 10 % of the
        largest side of the box it had when its leaf was last inserted); ``move`` keeps the leaf while the
        object's box stays inside it.

        Parameters
        ----------
        obj_id : int
            A live id (:ref:`broadphase-incremental`).

        Returns
        -------
        fat_lo, fat_hi : numpy.ndarray, shape (d,), float64
            Copies of the leaf's corners.
        """
        leaf = self._obj_node[self._check_id(obj_id)]
        return self._node_lo[leaf, : self._d].copy(), self._node_hi[leaf, : self._d].copy()

    def area_ratio(self) -> float:
        """Tree quality: the summed box cost of all the nodes of the tree (leaves and inner nodes) over the root's.

        Box2D's ``b2DynamicTree::GetAreaRatio``, with the cost that ``insert`` uses to choose a leaf's sibling (the
        sum of a box's sides: Box2D's perimeter, in 1-3 D). The expected cost of a query grows with it (the
        surface-area heuristic of Goldsmith and Salmon, 1987, which Box2D's insertion cost follows); the leaves'
        share is fixed by the fat boxes, so two trees over the same leaves differ by their inner nodes.

        Returns
        -------
        float
            >= 1 for a tree with a root box of positive size; 0.0 for an empty tree or a root box of zero size.
        """
        if self._root == -1:
            return 0.0
        total = 0.0
        stack = [self._root]
        while stack:
            node = stack.pop()
            total += float((self._node_hi[node] - self._node_lo[node]).sum())
            if self._child1[node] != -1:
                stack += [int(self._child1[node]), int(self._child2[node])]
        root = float((self._node_hi[self._root] - self._node_lo[self._root]).sum())
        return total / root if root > 0.0 else 0.0

    def arrays(self) -> TreeArrays:
        """The tree's own arrays, for compiled traversals (no copy; valid until the tree next changes).

        Returns
        -------
        TreeArrays
            ``root`` (int, −1 when empty), ``node_lo``, ``node_hi`` (nodes, 3) the nodes' boxes, ``child1``,
            ``child2`` (nodes,) int64 (−1 at a leaf), ``obj_of`` (nodes,) int64 a leaf's object id.
        """
        return TreeArrays(int(self._root), self._node_lo, self._node_hi, self._child1, self._child2, self._obj_of)

    def refit(self, lo: np.ndarray, hi: np.ndarray) -> float:
        """Give every object its new box, keeping the tree's shape: each leaf's box becomes its object's box
        exactly (no margin), each inner node's the union of its children's (Bullet's ``btDbvt`` refit). Fast, and
        exact for queries; the tree's quality decays as the objects move away from where it was built (rebuild
        then).

        Parameters
        ----------
        lo, hi : numpy.ndarray, shape (n, 3), float64
            The new boxes of the objects 0 .. n − 1 (n = the largest id + 1), lo <= hi, finite (unchecked: the
            caller's boxes).

        Returns
        -------
        float
            The summed box sides of the inner nodes over the root's (compare it to its value after the build).
        """
        self._obj_lo[: lo.shape[0]] = lo
        self._obj_hi[: hi.shape[0]] = hi
        if self._root == -1:
            return 0.0
        return float(_refit_kernel(self._root, self._node_lo, self._node_hi, self._child1, self._child2,
                                   self._obj_of, self._obj_lo, self._obj_hi))

    def node_boxes(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Every node of the tree, from the root down (depth first): ``(lo, hi, depth, leaf)``.

        Returns
        -------
        lo, hi : numpy.ndarray, shape (m, d), float64
            The nodes' boxes (a leaf's is its object's fat box; an inner node's encloses its two children).
        depth : numpy.ndarray, shape (m,), int64
            0 for the root.
        leaf : numpy.ndarray, shape (m,), bool
            Whether the node is a leaf (holds one object).
        """
        order, depths = [], []
        stack = [(self._root, 0)] if self._root != -1 else []
        while stack:
            node, depth = stack.pop()
            order.append(node)
            depths.append(depth)
            if self._child1[node] != -1:
                stack += [(int(self._child2[node]), depth + 1), (int(self._child1[node]), depth + 1)]
        nodes = np.array(order, dtype=np.int64)
        d = self._d
        return (self._node_lo[nodes, :d].copy(), self._node_hi[nodes, :d].copy(), np.array(depths, dtype=np.int64),
                self._child1[nodes] == -1)

    def insert(self, lo_i: ArrayLike, hi_i: ArrayLike) -> int:
        """Insert the box ``lo_i, hi_i`` and return its id (:ref:`broadphase-incremental`): its fat leaf descends
        along the cheapest branch (Box2D's perimeter cost)."""
        lo3, hi3 = self._one_box(lo_i, hi_i)
        if self._free_ids:
            obj_id = self._free_ids.pop()
        else:
            obj_id = self._n_ids
            if obj_id == self._obj_lo.shape[0]:
                grow = obj_id
                self._obj_lo = np.concatenate([self._obj_lo, np.zeros((grow, 3))])
                self._obj_hi = np.concatenate([self._obj_hi, np.zeros((grow, 3))])
                self._obj_node = np.concatenate([self._obj_node, np.full(grow, -1, dtype=np.int64)])
            self._n_ids += 1
        self._obj_lo[obj_id] = lo3
        self._obj_hi[obj_id] = hi3
        self._insert_node(obj_id)
        return obj_id

    def _remove_object(self, obj_id: int) -> None:
        # the leaf's sibling takes its parent's place
        self._remove_node(obj_id)
        self._free_ids.append(obj_id)

    def move(self, obj_id: int, lo_i: ArrayLike, hi_i: ArrayLike) -> bool:
        """Give the live object ``obj_id`` the new box ``lo_i, hi_i`` (:ref:`broadphase-incremental`); its leaf
        is re-inserted only if the box left the leaf's fat box, and then ``move`` returns True (False when the tree
        did not change)."""
        obj_id = self._check_id(obj_id)
        lo3, hi3 = self._one_box(lo_i, hi_i)
        self._obj_lo[obj_id] = lo3
        self._obj_hi[obj_id] = hi3
        leaf = self._obj_node[obj_id]
        if np.all(self._node_lo[leaf] <= lo3) and np.all(hi3 <= self._node_hi[leaf]):
            return False
        self._remove_node(obj_id)
        self._insert_node(obj_id)
        return True

    def _set_boxes(self, ids: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> None:
        # as ``move`` for every live object: a leaf is re-inserted only if its box left the fat box
        for row, obj_id in enumerate(ids.tolist()):
            self._obj_lo[obj_id, : self._d] = lo[row]
            self._obj_hi[obj_id, : self._d] = hi[row]
            leaf = self._obj_node[obj_id]
            if not (np.all(self._node_lo[leaf] <= self._obj_lo[obj_id])
                    and np.all(self._obj_hi[obj_id] <= self._node_hi[leaf])):
                self._remove_node(obj_id)
                self._insert_node(obj_id)

    def pairs(self, *, threads: int = 1) -> np.ndarray:
        # each object descends the nodes its box overlaps; at a leaf the exact boxes are compared (the threads
        # share the node slots, as tree_pairs does)
        threads = as_threads(threads)
        if self._root == -1:
            return empty_pairs()
        tree = (self._root, self._node_lo, self._node_hi, self._child1, self._child2, self._obj_of, self._obj_lo,
                self._obj_hi, self._obj_node, self._n_ids)
        ranges = pair_buffer.split_work(self._node_lo.shape[0], threads, MIN_NODES_PER_THREAD)
        return pair_buffer.run_split(
            lambda first, last: _leaf_range_pairs(*tree, first, last, pair_buffer.new_pair_buffer(self._n_ids)),
            ranges, self._n_ids)[0]

    def query(self, lo_q: ArrayLike, hi_q: ArrayLike) -> np.ndarray:
        """The objects whose box overlaps a query box (Ericson 6.5: descend the nodes the query box overlaps).

        Parameters
        ----------
        lo_q, hi_q : array_like, shape (d,)
            The query box's corners, ``lo_q <= hi_q``, finite; closed, so touching counts.

        Returns
        -------
        numpy.ndarray, shape (k,), int64
            Ids, ascending, of the objects whose exact box overlaps the query box.

        Raises
        ------
        ValueError
            When the corners do not have shape (d,), are not finite, or ``lo_q > hi_q`` on some axis.
        TypeError
            For non-numeric corners.
        """
        q_lo, q_hi = self._one_box(lo_q, hi_q, ("lo_q", "hi_q"))
        return _query_box_kernel(self._root, self._node_lo, self._node_hi, self._child1, self._child2,
                                 self._obj_of, self._obj_lo, self._obj_hi, q_lo, q_hi)

    def query_boxes(self, lo_q: ArrayLike, hi_q: ArrayLike) -> np.ndarray:
        """Every (query box, object) pair whose boxes overlap, for m query boxes in one compiled call (Box2D
        queries its static tree with the moved proxies this way).

        Parameters
        ----------
        lo_q, hi_q : array_like, shape (m, d)
            The query boxes' corners, ``lo_q <= hi_q``, finite; closed, so touching counts.

        Returns
        -------
        numpy.ndarray, shape (k, 2), int64
            Rows (query row, object id) in lexicographic order, no repeat.

        Raises
        ------
        ValueError
            When the corners are not (m, d), not finite, or ``lo_q > hi_q`` somewhere (named with the index).
        TypeError
            For non-numeric corners.
        """
        lo_d = as_float_array(lo_q, "lo_q", shape=(None, self._d))
        hi_d = as_float_array(hi_q, "hi_q", shape=lo_d.shape)
        bad = np.argwhere(lo_d > hi_d)
        if bad.size:
            r, k = (int(x) for x in bad[0])
            raise ValueError(f"lo_q must not exceed hi_q: lo_q[{r}, {k}] = {lo_d[r, k]!r} > hi_q[{r}, {k}] = "
                             f"{hi_d[r, k]!r}")
        q_lo, q_hi = np.zeros((lo_d.shape[0], 3)), np.zeros((lo_d.shape[0], 3))
        q_lo[:, : self._d], q_hi[:, : self._d] = lo_d, hi_d
        found = tree_query_boxes(self._root, self._node_lo, self._node_hi, self._child1, self._child2,
                                 self._obj_of, self._obj_lo, self._obj_hi, q_lo, q_hi)
        return found[np.lexsort((found[:, 1], found[:, 0]))]

    def rebuild(self) -> None:
        """Rebuild the whole tree top-down from the live objects' fat boxes (restores balance).

        The ids, the fat boxes and the pairs stay the same; only the inner nodes change (Ericson 6.2.1: split
        at the midpoint of the centres along their widest axis).
        """
        ids = self.ids()
        m = ids.shape[0]
        if m == 0:
            return
        fat_lo = np.empty((m, 3))
        fat_hi = np.empty((m, 3))
        for row, obj_id in enumerate(ids.tolist()):
            fat_lo[row] = self._node_lo[self._obj_node[obj_id]]
            fat_hi[row] = self._node_hi[self._obj_node[obj_id]]
        self._build_from(ids, fat_lo, fat_hi)

    def _build_from(self, ids: np.ndarray, fat_lo: np.ndarray, fat_hi: np.ndarray, sah: bool = False) -> None:
        m = ids.shape[0]
        self._alloc_nodes(max(16, 2 * m))
        leaf_of = np.empty(m, dtype=np.int64)
        obj_of = np.full(self._node_lo.shape[0], -1, dtype=np.int64)
        build = _build_sah_kernel if sah else _build_kernel
        n_nodes = build(fat_lo, fat_hi, self._node_lo, self._node_hi, self._parent, self._child1,
                        self._child2, self._height, leaf_of, obj_of)
        self._obj_of = ids[np.maximum(obj_of, 0)]
        self._obj_of[obj_of < 0] = -1
        self._obj_node[:] = -1
        self._obj_node[ids] = leaf_of
        self._root = 0
        self._free_nodes = list(range(self._node_lo.shape[0] - 1, int(n_nodes) - 1, -1))

    @classmethod
    def from_boxes(cls, lo: ArrayLike, hi: ArrayLike, margin: float | None = None, *,
                   split: str = "midpoint") -> DynamicAABBTree:
        """A tree holding the given boxes, built in batch (top-down) rather than by n insertions.

        Parameters
        ----------
        lo, hi : array_like, shape (n, d)
            The boxes, d = 1, 2 or 3, ``lo <= hi``; they get the ids 0..n−1.
        margin : float or None, optional
            As for the constructor.
        split : {"midpoint", "sah"}, default "midpoint"
            How a node's objects are split: at the midpoint of their centres' widest spread, or by the binned
            surface area heuristic (slower to build, fewer nodes met by a ray).

        Returns
        -------
        DynamicAABBTree
            Of dimension d.

        Raises
        ------
        ValueError, TypeError
            For invalid boxes (as :func:`find_pairs`) or margin (as the constructor).
        """
        lo_d, _ = as_boxes(lo, hi)
        tree = cls(dim=lo_d.shape[1], margin=margin)
        lo3, hi3 = as_boxes_3d(lo, hi)
        n = lo3.shape[0]
        if n == 0:
            return tree
        tree._obj_lo = lo3
        tree._obj_hi = hi3
        tree._obj_node = np.full(n, -1, dtype=np.int64)
        tree._n_ids = n
        if margin == 0.0:
            fat_lo, fat_hi = lo3, hi3
        else:
            grow = np.zeros((n, 3))  # along the d axes only, as in ``_fat``
            grow[:, : tree._d] = (0.1 * (hi3 - lo3).max(axis=1) if margin is None else np.full(n, tree.margin))[:, None]
            fat_lo = np.minimum(lo3 - grow, lo3)
            fat_hi = np.maximum(hi3 + grow, hi3)
        tree._build_from(np.arange(n, dtype=np.int64), fat_lo, fat_hi, as_choice(split, "split", SPLITS) == "sah")
        return tree

    def check_structure(self) -> None:
        """Check the tree's invariants (a debugging aid; the properties call it after every operation).

        Raises
        ------
        AssertionError
            Unless the parent/child links, the heights and the enclosing boxes are consistent, every leaf's
            fat box holds its object's box, and the leaves hold exactly the live objects.
        """
        live = self.ids()
        if self._root == -1:
            assert live.size == 0
            return
        assert self._parent[self._root] == -1
        seen = []
        stack = [self._root]
        while stack:
            node = stack.pop()
            a, b = int(self._child1[node]), int(self._child2[node])
            if a == -1:
                assert b == -1 and self._height[node] == 0
                obj = int(self._obj_of[node])
                assert self._obj_node[obj] == node
                assert np.all(self._node_lo[node] <= self._obj_lo[obj])
                assert np.all(self._obj_hi[obj] <= self._node_hi[node])
                seen.append(obj)
                continue
            for child in (a, b):
                assert self._parent[child] == node
                assert np.all(self._node_lo[node] <= self._node_lo[child])
                assert np.all(self._node_hi[child] <= self._node_hi[node])
                stack.append(child)
            assert self._height[node] == 1 + max(self._height[a], self._height[b])
        assert sorted(seen) == live.tolist()


#: a thread makes the queries of at least this many tree nodes
MIN_NODES_PER_THREAD = 2048


@overload
def tree_pairs(lo: ArrayLike, hi: ArrayLike, *, return_tests: Literal[False] = ...,
               threads: int = ...) -> np.ndarray: ...
@overload
def tree_pairs(lo: ArrayLike, hi: ArrayLike, *, return_tests: Literal[True],
               threads: int = ...) -> tuple[np.ndarray, int]: ...
def tree_pairs(lo: ArrayLike, hi: ArrayLike, *, return_tests: bool = False,
               threads: int = 1) -> np.ndarray | tuple[np.ndarray, int]:
    """All pairs of overlapping closed boxes with an AABB tree built in batch: ``find_pairs(method="tree")``.

    The tree is built top-down over the exact boxes (no margin), then every object descends it; the threads
    share these queries. ``lo``, ``hi``, ``return_tests``, ``threads``, the result and the errors are those of
    every box method (:ref:`broadphase-boxes`, :ref:`broadphase-options`).

    Returns
    -------
    pairs : numpy.ndarray, shape (k, 2), int64
        :ref:`broadphase-pairs`; ``(pairs, tests)`` with ``return_tests=True``, ``tests`` counting the box–box
        tests of the traversal: an object's box against each node box visited (a leaf's box is its object's box).
    """
    threads = as_threads(threads)
    lo3, hi3 = as_boxes_3d(lo, hi)
    n = lo3.shape[0]
    if n < 2:
        return with_tests(empty_pairs(), 0, return_tests)
    capacity = 2 * n - 1  # exactly the nodes of a binary tree with n leaves: no uninitialised slot
    node_lo = np.empty((capacity, 3))
    node_hi = np.empty((capacity, 3))
    parent = np.empty(capacity, dtype=np.int64)
    child1 = np.full(capacity, -1, dtype=np.int64)
    child2 = np.full(capacity, -1, dtype=np.int64)
    height = np.zeros(capacity, dtype=np.int64)
    leaf_of = np.empty(n, dtype=np.int64)
    obj_of = np.full(capacity, -1, dtype=np.int64)
    _build_kernel(lo3, hi3, node_lo, node_hi, parent, child1, child2, height, leaf_of, obj_of)
    tree = (0, node_lo, node_hi, child1, child2, obj_of, lo3, hi3, leaf_of, n)
    ranges = pair_buffer.split_work(capacity, threads, MIN_NODES_PER_THREAD)
    pairs, tests = pair_buffer.run_split(
        lambda first, last: _leaf_range_pairs(*tree, first, last, pair_buffer.new_pair_buffer(n)), ranges, n)
    return with_tests(pairs, tests, return_tests)
