"""Octree: the chapter's *non-uniform* spatial subdivision — "une hiérarchie ! un « arbre »".

Chapter slides "Phase Large : Subdivision (découpage) spatiale" (absolue / non uniforme); Ericson, *Real-Time
Collision Detection* 7.3 (octrees), 7.3.6 (loose octrees).

Construction (top-down, stored as index arrays): a node holding more than ``leaf_size`` objects is cut in eight
octants at the midpoint of its objects' centres, and each object goes to the octant holding its *centre*
(an axis whose centres all coincide is not cut, so every cut separates objects and the tree has < 2n nodes).

Objects that straddle the cutting planes are handled the *loose octree* way: every object lives in exactly one
leaf (the one of its centre), and each node's bounds are loosened to the union of the full boxes of the objects
below it — so a straddler is neither split nor copied, and no straddler list is needed. All pairs: each object
descends from the root into the nodes whose loose bounds overlap its box and is tested against the objects of
the leaves it reaches that have a larger index, so every pair is found once.
"""
from __future__ import annotations

from typing import Literal, overload

import numpy as np
from numpy.typing import ArrayLike

import engine.broadphase.pairs as pair_buffer
from engine._config import njit
from engine.bounding.aabb import enclose_aabbs
from engine.broadphase.pairs import as_boxes_3d, as_threads, boxes_overlap, empty_pairs, with_tests

__all__ = ["octree_pairs", "build_octree"]


@njit
def _sort_by_octant(lo, hi, perm, s, e, mid, cut, counts):
    """Counting sort of perm[s:e] by the octant of each object's centre (bit k set when the centre is >= mid[k]
    on a cut axis k); counts (9,) receives the first slot of each octant (relative to s) and the end."""
    octant_of = np.empty(e - s, dtype=np.int64)
    counts[:] = 0
    for p in range(s, e):
        o = perm[p]
        octant = 0
        for k in range(3):
            if cut[k] and 0.5 * lo[o, k] + 0.5 * hi[o, k] >= mid[k]:
                octant |= 1 << k
        octant_of[p - s] = octant
        counts[octant + 1] += 1
    for t in range(8):
        counts[t + 1] += counts[t]
    bucket = counts[:8].copy()
    moved = np.empty(e - s, dtype=np.int64)
    for p in range(s, e):
        moved[bucket[octant_of[p - s]]] = perm[p]
        bucket[octant_of[p - s]] += 1
    perm[s:e] = moved


@njit
def _build_octree_kernel(lo, hi, leaf_size):
    # Ericson 7.3.1 (top-down octree build), with loose bounds (7.3.6): nodes as index arrays.
    n = lo.shape[0]
    perm = np.arange(n)
    capacity = 2 * n + 1
    node_lo = np.empty((capacity, 3))
    node_hi = np.empty((capacity, 3))
    first = np.empty(capacity, dtype=np.int64)   # range [first, last) of perm for a leaf
    last = np.empty(capacity, dtype=np.int64)
    child0 = np.full(capacity, -1, dtype=np.int64)  # children are the nodes child0..child0 + n_children - 1
    n_children = np.zeros(capacity, dtype=np.int64)
    n_nodes = 1
    first[0] = 0
    last[0] = n
    stack = np.empty(capacity, dtype=np.int64)
    stack[0] = 0
    top = 1
    cmin = np.empty(3)
    cmax = np.empty(3)
    mid = np.empty(3)
    cut = np.zeros(3, dtype=np.bool_)
    counts = np.zeros(9, dtype=np.int64)
    while top > 0:
        top -= 1
        node = stack[top]
        s = first[node]
        e = last[node]
        # loose bounds: the union of the boxes of the objects below the node
        enclose_aabbs(lo, hi, perm[s:e], node_lo[node], node_hi[node], cmin, cmax)
        if e - s <= leaf_size:
            continue
        # cut at the midpoint of the centres; an axis is cut only if the midpoint separates its centres
        for k in range(3):
            mid[k] = 0.5 * cmin[k] + 0.5 * cmax[k]
            cut[k] = cmin[k] < mid[k] and mid[k] <= cmax[k]
        if not (cut[0] or cut[1] or cut[2]):
            continue  # all centres coincide: a leaf, whatever its size
        _sort_by_octant(lo, hi, perm, s, e, mid, cut, counts)
        child0[node] = n_nodes
        for t in range(8):
            if counts[t + 1] > counts[t]:
                child = n_nodes
                n_nodes += 1
                first[child] = s + counts[t]
                last[child] = s + counts[t + 1]
                n_children[node] += 1
                stack[top] = child
                top += 1
    return (perm, node_lo[:n_nodes].copy(), node_hi[:n_nodes].copy(), first[:n_nodes].copy(),
            last[:n_nodes].copy(), child0[:n_nodes].copy(), n_children[:n_nodes].copy())


@njit
def _octree_pairs_kernel(lo, hi, perm, node_lo, node_hi, first, last, child0, n_children, t0, t1, out):
    # Ericson 7.3.3 / 6.5: each object descends the nodes whose (loose) bounds overlap its box; at a leaf it is
    # tested against the objects with a larger index (each pair is found once). Objects perm[t0:t1]; returns
    # the pair buffer (out, count) and the tests made.
    count = 0
    tests = 0
    stack = np.empty(node_lo.shape[0] + 1, dtype=np.int64)
    for t in range(t0, t1):
        i = perm[t]  # leaf order: consecutive queries walk the same branches (cache-friendly)
        top = 1
        stack[0] = 0
        while top > 0:
            top -= 1
            node = stack[top]
            tests += 1  # the object's box against the node's loose bounds
            if (lo[i, 0] > node_hi[node, 0] or node_lo[node, 0] > hi[i, 0]
                    or lo[i, 1] > node_hi[node, 1] or node_lo[node, 1] > hi[i, 1]
                    or lo[i, 2] > node_hi[node, 2] or node_lo[node, 2] > hi[i, 2]):
                continue
            if n_children[node] == 0:
                for p in range(first[node], last[node]):
                    j = perm[p]
                    if j <= i:
                        continue
                    tests += 1
                    if boxes_overlap(lo, hi, i, j):
                        out, count = pair_buffer.push_pair(out, count, i, j)
            else:
                for c in range(n_children[node]):
                    stack[top] = child0[node] + c
                    top += 1
    return out, count, tests


def build_octree(lo: ArrayLike, hi: ArrayLike, leaf_size: int = 8) -> tuple[np.ndarray, ...]:
    """The loose octree of the given boxes, as index arrays (what a drawing of the tree needs).

    Parameters
    ----------
    lo, hi : array_like, shape (n, d)
        The boxes, n >= 1, d = 1, 2 or 3, ``lo <= hi``, finite.
    leaf_size : int, optional
        A node holding more than this many objects is cut in eight octants; >= 1.

    Returns
    -------
    perm : numpy.ndarray, shape (n,), int64
        The objects in leaf order: leaf k holds the objects ``perm[first[k]:last[k]]``.
    node_lo, node_hi : numpy.ndarray, shape (m, 3), float64
        Each node's loose bounds: the union of the boxes of the objects below it (1-D and 2-D boxes are padded
        with zero-width axes).
    first, last : numpy.ndarray, shape (m,), int64
        The range of ``perm`` below each node.
    child0, n_children : numpy.ndarray, shape (m,), int64
        An inner node's children are the nodes ``child0[k] .. child0[k] + n_children[k] − 1``; a leaf has
        ``n_children[k] == 0`` and ``child0[k] == −1``. Node 0 is the root.

    Raises
    ------
    ValueError
        For invalid boxes (as :func:`find_pairs`), no box at all, or ``leaf_size`` < 1 or not an int.
    TypeError
        For non-numeric boxes.
    """
    if isinstance(leaf_size, bool) or not isinstance(leaf_size, int | np.integer) or leaf_size < 1:
        raise ValueError(f"leaf_size must be an int >= 1, got {leaf_size!r}")
    lo3, hi3 = as_boxes_3d(lo, hi)
    if lo3.shape[0] == 0:
        raise ValueError("lo must hold at least one box to build an octree")
    return _build_octree_kernel(lo3, hi3, int(leaf_size))


#: a thread makes the queries of at least this many objects
MIN_OBJECTS_PER_THREAD = 2048


@overload
def octree_pairs(lo: ArrayLike, hi: ArrayLike, leaf_size: int = ..., *, return_tests: Literal[False] = ...,
                 threads: int = ...) -> np.ndarray: ...
@overload
def octree_pairs(lo: ArrayLike, hi: ArrayLike, leaf_size: int = ..., *, return_tests: Literal[True],
                 threads: int = ...) -> tuple[np.ndarray, int]: ...
def octree_pairs(lo: ArrayLike, hi: ArrayLike, leaf_size: int = 8, *, return_tests: bool = False,
                 threads: int = 1) -> np.ndarray | tuple[np.ndarray, int]:
    """All pairs of overlapping closed boxes with a loose octree: ``find_pairs(method="octree")``.

    Each object lives in the leaf of its centre and descends the nodes whose loose bounds overlap its box (see
    the module's description); the threads share these queries. ``lo``, ``hi``, ``return_tests``, ``threads``
    and the result are those of every box method (:ref:`broadphase-boxes`, :ref:`broadphase-options`).

    Parameters
    ----------
    leaf_size : int, optional
        Objects per leaf before a cut, >= 1.

    Returns
    -------
    pairs : numpy.ndarray, shape (k, 2), int64
        :ref:`broadphase-pairs`; ``(pairs, tests)`` with ``return_tests=True``, ``tests`` counting the box–box
        tests of the traversal: the object against each node's loose bounds, and against the objects of the
        leaves it reaches.

    Raises
    ------
    ValueError
        When ``leaf_size`` is < 1 or not an int (and for invalid boxes or ``threads``, as every box method).
    """
    threads = as_threads(threads)
    if isinstance(leaf_size, bool) or not isinstance(leaf_size, int | np.integer) or leaf_size < 1:
        raise ValueError(f"leaf_size must be an int >= 1, got {leaf_size!r}")
    lo3, hi3 = as_boxes_3d(lo, hi)
    if lo3.shape[0] < 2:
        return with_tests(empty_pairs(), 0, return_tests)
    tree = _build_octree_kernel(lo3, hi3, int(leaf_size))
    n = lo3.shape[0]
    ranges = pair_buffer.split_work(np.arange(n + 1), threads, MIN_OBJECTS_PER_THREAD)
    pairs, tests = pair_buffer.run_split(
        lambda t0, t1: _octree_pairs_kernel(lo3, hi3, *tree, t0, t1, pair_buffer.new_pair_buffer(n)), ranges, n)
    return with_tests(pairs, tests, return_tests)
