"""The broad phase of a ``World``, kept across frames: one state object per ``broad_phase`` method.

- "tree": a ``DynamicAABBTree`` over *fat* boxes (Box2D's ``b2_aabbMargin``): each body's AABB grown by
  ``FAT_MARGIN`` × its largest side, and a cache of the pairs of overlapping fat boxes. The pose upload flags
  the bodies whose AABB left its fat box (``BodyStore.escaped``). While none escapes the cached pairs stand;
  when a few escape (at most ``rebuild_threshold``) their leaves are re-fattened and moved and their pairs
  found again by a tree query each (Box2D's move buffer, ``b2UpdatePairs``); when more escape at once the tree
  is rebuilt top-down (``DynamicAABBTree.from_boxes``) and its pairs found by one traversal.
- "sap": an ``IncrementalSAP`` over the AABBs (insertion sort of last frame's order, then the sweep);
- "grid", "octree", "brute": ``find_pairs`` over the AABBs each query (they keep no state).
``candidates(store, bodies, escaped)`` returns pairs (k, 2) of body ids, i < j in each row, no repeat, whose
boxes overlap — fat boxes for the tree (a superset: the narrow phase tests the AABBs first; its rows are not
sorted), the AABBs for the others (sorted). Only the moving bodies enter it: static bodies and grounds never do.
``swept(store, bodies, moved, lo, hi)`` asks the same kept structure for the pairs whose *swept* boxes ``lo``,
``hi`` may overlap (``World.time_of_impact``): the bodies ``moved`` were given fat boxes around their swept boxes
(``fatten_around``, Box2D's ``b2MoveProxy`` with a displacement), so the tree's cached fat pairs cover them; the
SAP sorts the swept boxes from its kept order; the others sweep them afresh.

Static bodies (level geometry) are kept apart, as Jolt keeps its static tree apart from the dynamic one and Box2D
queries its static tree with the moved proxies only: ``StaticPairs`` holds a tree of their AABBs, built when the
static set changes, and the candidate pairs of each moving body against it, found again only when the body
leaves its fat box. So a static level costs nothing per frame beyond the pairs it makes, and two static bodies
are never paired. The fat boxes are the world's (``fatten``: each body's AABB grown by ``FAT_MARGIN`` × its
largest side when it escapes), shared by the tree broad phase and the static pairs.
"""
from __future__ import annotations

import numpy as np

from engine.broadphase import DynamicAABBTree, IncrementalSAP, canonical_pairs, find_pairs

__all__ = ["FAT_MARGIN", "REBUILD_THRESHOLD", "TreeBroadPhase", "SAPBroadPhase", "RebuildBroadPhase",
           "StaticPairs", "make_broad_phase", "fatten", "fatten_around", "boxes_overlap"]

#: the tree's fat boxes: the AABB grown on each side by this fraction of its largest side (bodies jittering by
#: 2 % of their size per frame then leave their fat box once every ~400 frames: a few tree queries per frame)
FAT_MARGIN = 0.5
#: the tree is rebuilt when more bodies than this left their fat boxes since the last query
REBUILD_THRESHOLD = 64


def _canonical(pairs: np.ndarray) -> np.ndarray:
    if pairs.shape[0] == 0:
        return np.empty((0, 2), np.int64)
    return canonical_pairs(pairs)


def _drop_rows_of(pairs: np.ndarray, bodies, capacity: int) -> np.ndarray:
    """The rows of ``pairs`` that involve none of ``bodies``."""
    gone = np.zeros(capacity, np.bool_)
    gone[bodies] = True
    return pairs[~(gone[pairs[:, 0]] | gone[pairs[:, 1]])]


def fatten(store, bodies) -> None:
    """Give ``bodies`` new fat boxes: their AABB grown on each side by FAT_MARGIN × its largest side."""
    fatten_around(store, bodies, store.lo[bodies], store.hi[bodies])


def fatten_around(store, bodies, lo, hi) -> None:
    """Give ``bodies`` new fat boxes around the boxes ``lo``, ``hi`` (m, 3) — each containing its body's AABB —:
    grown on each side by FAT_MARGIN × the largest side."""
    grow = FAT_MARGIN * (hi - lo).max(axis=1, keepdims=True)
    store.fat_lo[bodies] = lo - grow
    store.fat_hi[bodies] = hi + grow
    store.escaped[bodies] = False


def boxes_overlap(lo, hi, a, b) -> np.ndarray:
    """Whether the closed boxes a[k] and b[k] of ``lo``, ``hi`` (n, 3) overlap, for index arrays a, b (k,)."""
    return ((lo[a] <= hi[b]) & (lo[b] <= hi[a])).all(axis=1)


def _local_rows(pairs: np.ndarray, bodies: np.ndarray, capacity: int) -> np.ndarray:
    """Pairs of body ids (k, 2), both among ``bodies`` (m,), as rows of ``bodies``."""
    position = np.full(capacity + 1, -1, np.int64)  # a free slot's −1 reads the last entry: −1
    position[bodies] = np.arange(bodies.shape[0])
    return position[pairs]


class RebuildBroadPhase:
    """``find_pairs(lo, hi, method)`` over the live bodies' AABBs at each query, on ``threads`` threads."""

    def __init__(self, method: str, threads: int = 1):
        self.method = method
        self.threads = threads

    def add(self, store, body: int) -> None:
        pass

    def remove(self, store, body: int) -> None:
        pass

    def candidates(self, store, bodies: np.ndarray, escaped: np.ndarray) -> np.ndarray:
        if bodies.shape[0] < 2:
            return np.empty((0, 2), np.int64)
        rows = find_pairs(store.lo[bodies], store.hi[bodies], self.method, threads=self.threads)
        return bodies[rows]  # bodies ascending: rows i < j stay canonical

    def swept(self, store, bodies, moved, lo, hi) -> np.ndarray:
        """Rows of ``bodies`` (k, 2) whose swept boxes ``lo``, ``hi`` (m, 3) overlap."""
        if bodies.shape[0] < 2:
            return np.empty((0, 2), np.int64)
        return find_pairs(lo, hi, self.method, threads=self.threads)


class SAPBroadPhase:
    """An ``IncrementalSAP`` whose object ids map to body ids; its sorted order survives from frame to frame.
    Bodies added since the last query are inserted then — one by one if they are few, else by building the
    SAP again over every body at once. Its sweep runs on ``threads`` threads."""

    def __init__(self, rebuild_threshold: int = REBUILD_THRESHOLD, threads: int = 1):
        self.threads = threads
        self.sap = IncrementalSAP(dim=3)
        self.body_of = np.full(16, -1, np.int64)
        self.slot_of: dict[int, int] = {}
        self.pending: list[int] = []
        self.rebuild_threshold = rebuild_threshold

    def add(self, store, body: int) -> None:
        self.pending.append(body)

    def remove(self, store, body: int) -> None:
        if body in self.slot_of:
            self.sap.remove(self.slot_of.pop(body))
        else:
            self.pending.remove(body)

    def _insert_pending(self, store, bodies) -> None:
        if len(self.pending) > self.rebuild_threshold:
            self.sap = IncrementalSAP(store.lo[bodies], store.hi[bodies])
            self.body_of = np.concatenate([bodies, np.full(16, -1, np.int64)])
            self.slot_of = dict(zip(bodies.tolist(), range(bodies.shape[0])))
        else:
            for body in self.pending:
                slot = self.sap.add(store.lo[body], store.hi[body])
                if slot >= self.body_of.shape[0]:
                    self.body_of = np.concatenate([self.body_of, np.full(slot + 1, -1, np.int64)])
                self.body_of[slot] = body
                self.slot_of[body] = slot
        self.pending = []

    def candidates(self, store, bodies: np.ndarray, escaped: np.ndarray) -> np.ndarray:
        if self.pending:
            self._insert_pending(store, bodies)
        slots = self.sap.ids()
        if slots.shape[0] < 2:
            return np.empty((0, 2), np.int64)
        owner = self.body_of[slots]
        return _canonical(self.body_of[self.sap.update(store.lo[owner], store.hi[owner], threads=self.threads)])

    def swept(self, store, bodies, moved, lo, hi) -> np.ndarray:
        """Rows of ``bodies`` (k, 2) whose swept boxes ``lo``, ``hi`` (m, 3) overlap: the kept order sorted again
        over the swept boxes (the next frame sorts the AABBs back from it)."""
        if self.pending:
            self._insert_pending(store, bodies)
        slots = self.sap.ids()
        if slots.shape[0] < 2:
            return np.empty((0, 2), np.int64)
        row = _local_rows(self.body_of, bodies, store.capacity)  # slot -> row of bodies (free slots: unread)
        live = row[slots]
        return _canonical(row[self.sap.update(lo[live], hi[live], threads=self.threads)])


class TreeBroadPhase:
    """A ``DynamicAABBTree`` of fat boxes (see the module docstring); ``rebuild_threshold`` bounds the leaves
    moved (or inserted: a body added since the last query has no leaf yet and counts as escaped) one by one per
    query."""

    def __init__(self, rebuild_threshold: int = REBUILD_THRESHOLD, threads: int = 1):
        self.threads = threads
        self.tree = DynamicAABBTree(dim=3, margin=0.0)
        self.leaf_of: dict[int, int] = {}
        self.body_of = np.full(16, -1, np.int64)
        self.cached: np.ndarray | None = None
        self.rebuild_threshold = rebuild_threshold
        self.rebuilds = 0
        self.removed: list[int] = []  # bodies removed since the last query: their cached pairs are dropped then

    def add(self, store, body: int) -> None:
        """Nothing until the next query: the world gives the body an empty fat box, so it counts as escaped."""

    def remove(self, store, body: int) -> None:
        leaf = self.leaf_of.pop(body, None)
        if leaf is not None:
            self.tree.remove(leaf)
            self.body_of[leaf] = -1
        self.removed.append(body)

    def _drop_removed(self, store) -> None:
        """Drop the cached pairs of the bodies removed since the last query (one pass for all of them; an id
        reused by a body added since is dropped too, and that body, escaped, is queried afresh)."""
        if self.cached is not None:
            self.cached = _drop_rows_of(self.cached, self.removed, store.capacity)
        self.removed = []

    def _rebuild(self, store, bodies) -> None:
        self.tree = DynamicAABBTree.from_boxes(store.fat_lo[bodies], store.fat_hi[bodies], margin=0.0)
        self.body_of = np.full(max(16, bodies.shape[0]), -1, np.int64)
        self.body_of[: bodies.shape[0]] = bodies
        self.leaf_of = dict(zip(bodies.tolist(), range(bodies.shape[0])))
        self.rebuilds += 1

    def _requery(self, store, escaped) -> None:
        """Move (or insert) the leaves of the escaped bodies and replace their cached pairs by what the tree now
        finds."""
        cached = self.cached
        assert cached is not None  # candidates() rebuilds instead when nothing is cached
        moved = np.zeros(store.capacity, np.bool_)
        moved[escaped] = True
        keep = ~(moved[cached[:, 0]] | moved[cached[:, 1]])
        for body in escaped.tolist():  # a few leaves: Box2D's move buffer
            if body in self.leaf_of:
                self.tree.move(self.leaf_of[body], store.fat_lo[body], store.fat_hi[body])
            else:
                leaf = self.tree.insert(store.fat_lo[body], store.fat_hi[body])
                if leaf >= self.body_of.shape[0]:
                    self.body_of = np.concatenate([self.body_of, np.full(leaf + 1, -1, np.int64)])
                self.body_of[leaf] = body
                self.leaf_of[body] = leaf
        found = []
        for body in escaped.tolist():
            others = self.body_of[self.tree.query(store.fat_lo[body], store.fat_hi[body])]
            others = others[others != body]
            found.append(np.stack([np.minimum(others, body), np.maximum(others, body)], axis=1))
        # the kept rows involve no escaped body, the found ones all do: only the found ones can repeat
        self.cached = np.concatenate([cached[keep], _canonical(np.concatenate(found))])

    def candidates(self, store, bodies: np.ndarray, escaped: np.ndarray) -> np.ndarray:
        """``escaped``: the bodies given new fat boxes since the last query (``fatten``)."""
        if self.removed:
            self._drop_removed(store)
        if escaped.shape[0]:
            if escaped.shape[0] > self.rebuild_threshold or self.cached is None:
                self._rebuild(store, bodies)
                self.cached = None
            else:
                self._requery(store, escaped)
        if self.cached is None:
            self.cached = _canonical(self.body_of[self.tree.pairs(threads=self.threads)]) if bodies.shape[0] > 1 else \
                np.empty((0, 2), np.int64)
        return self.cached

    def swept(self, store, bodies, moved, lo, hi) -> np.ndarray:
        """Rows of ``bodies`` (k, 2) whose swept boxes ``lo``, ``hi`` (m, 3) overlap: the fat pairs (every swept
        box lies in its fat box: ``moved`` were fattened around theirs), kept where the swept boxes overlap."""
        rows = _local_rows(self.candidates(store, bodies, moved), bodies, store.capacity)
        return rows[boxes_overlap(lo, hi, rows[:, 0], rows[:, 1])]


class StaticPairs:
    """The candidate pairs of the moving bodies against the static ones (see the module docstring): a
    ``DynamicAABBTree`` of the static bodies' AABBs, and the cached pairs (moving id, static id) canonicalised."""

    def __init__(self):
        self.static: set[int] = set()
        self.tree: DynamicAABBTree | None = None
        self.static_of = np.empty(0, np.int64)  # tree object -> static body id
        self.cached: np.ndarray | None = None
        self.removed: list[int] = []  # moving bodies removed since the last query
        self.dirty = False

    def add(self, body: int) -> None:
        self.static.add(body)
        self.dirty = True

    def remove(self, store, body: int) -> None:
        """A body leaves the world: a static one changes the static set, a moving one loses its cached pairs."""
        if body in self.static:
            self.static.discard(body)
            self.dirty = True
        else:
            self.removed.append(body)

    def _build(self, store) -> None:
        self.static_of = np.array(sorted(self.static), np.int64)
        self.tree = (DynamicAABBTree.from_boxes(store.lo[self.static_of], store.hi[self.static_of], margin=0.0,
                                                split="sah")
                     if self.static_of.size else None)
        self.dirty = False

    def tree_arrays(self, store):
        """(TreeArrays, static ids by tree object) of the static tree, built first if the static set changed;
        an empty tree (root −1) when there is no static body."""
        if self.dirty:
            self._build(store)
        tree = self.tree if self.tree is not None else DynamicAABBTree(dim=3, margin=0.0)
        return tree.arrays(), self.static_of

    def query(self, store, bodies, lo, hi) -> np.ndarray:
        """Canonical pairs (body, static body) whose boxes overlap, for ``bodies`` (m,) with the boxes ``lo``,
        ``hi`` (m, 3); uncached."""
        if self.dirty:
            self._build(store)
        if self.tree is None or bodies.shape[0] == 0:
            return np.empty((0, 2), np.int64)
        found = self.tree.query_boxes(lo, hi)
        a, b = bodies[found[:, 0]], self.static_of[found[:, 1]]
        return np.stack([np.minimum(a, b), np.maximum(a, b)], axis=1)

    def candidates(self, store, bodies: np.ndarray, escaped: np.ndarray) -> np.ndarray:
        """The pairs of the moving ``bodies`` with the static ones, through their fat boxes; ``escaped``: the bodies
        given new fat boxes since the last query, whose pairs are found again."""
        if self.dirty or self.cached is None:
            self.removed = []
            self.cached = self.query(store, bodies, store.fat_lo[bodies], store.fat_hi[bodies])
            return self.cached
        if self.removed:
            self.cached = _drop_rows_of(self.cached, self.removed, store.capacity)
            self.removed = []
        if escaped.shape[0]:
            kept = _drop_rows_of(self.cached, escaped, store.capacity)
            self.cached = np.concatenate([kept, self.query(store, escaped, store.fat_lo[escaped],
                                                           store.fat_hi[escaped])])
        return self.cached

    def swept(self, store, bodies, moved, lo, hi) -> np.ndarray:
        """The cached pairs (body, static body) whose swept box (``lo``, ``hi`` (m, 3), by row of ``bodies``) meets
        the static body's AABB; ``moved``: the bodies given fat boxes around their swept boxes."""
        pairs = self.candidates(store, bodies, moved)
        side = _local_rows(pairs, bodies, store.capacity)
        first = side[:, 0] >= 0  # the moving body's column
        mover = np.where(first, side[:, 0], side[:, 1])
        fixed = np.where(first, pairs[:, 1], pairs[:, 0])
        meet = ((lo[mover] <= store.hi[fixed]) & (store.lo[fixed] <= hi[mover])).all(axis=1)
        return pairs[meet]


def make_broad_phase(method: str, threads: int = 1):
    """The broad-phase state for ``World(broad_phase=method, threads=threads)``."""
    if method == "tree":
        return TreeBroadPhase(threads=threads)
    if method == "sap":
        return SAPBroadPhase(threads=threads)
    return RebuildBroadPhase(method, threads)
