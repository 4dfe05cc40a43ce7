"""The broad phase of a ``World``, kept across frames: one state object per ``broad_phase`` method.

- "tree": a ``DynamicAABBTree`` over *fat* boxes (Box2D's ``b2_aabbMargin``): each body's AABB grown by
  ``FAT_MARGIN`` × its largest side, and a cache of the pairs of overlapping fat boxes. The pose upload flags
  the bodies whose AABB left its fat box (``BodyStore.escaped``). While none escapes the cached pairs stand;
  when a few escape (at most ``rebuild_threshold``) their leaves are re-fattened and moved and their pairs
  found again by a tree query each (Box2D's move buffer, ``b2UpdatePairs``); when more escape at once the tree
  is rebuilt top-down (``DynamicAABBTree.from_boxes``) and its pairs found by one traversal.
- "sap": an ``IncrementalSAP`` over the AABBs (insertion sort of last frame's order, then the sweep);
- "grid", "octree", "brute": ``find_pairs`` over the AABBs each query (they keep no state).
``candidates(store, bodies)`` returns pairs (k, 2) of body ids, i < j in each row, no repeat, whose boxes
overlap — fat boxes for the tree (a superset: the narrow phase tests the AABBs first; its rows are not sorted),
the AABBs for the others (sorted). Grounds never enter it.
"""
from __future__ import annotations

import numpy as np

from engine.broadphase import DynamicAABBTree, IncrementalSAP, canonical_pairs, find_pairs

__all__ = ["FAT_MARGIN", "REBUILD_THRESHOLD", "TreeBroadPhase", "SAPBroadPhase", "RebuildBroadPhase",
           "make_broad_phase"]

#: the tree's fat boxes: the AABB grown on each side by this fraction of its largest side (bodies jittering by
#: 2 % of their size per frame then leave their fat box once every ~400 frames: a few tree queries per frame)
FAT_MARGIN = 0.5
#: the tree is rebuilt when more bodies than this left their fat boxes since the last query
REBUILD_THRESHOLD = 64


def _canonical(pairs: np.ndarray) -> np.ndarray:
    if pairs.shape[0] == 0:
        return np.empty((0, 2), np.int64)
    return canonical_pairs(pairs)


class RebuildBroadPhase:
    """``find_pairs(lo, hi, method)`` over the live bodies' AABBs at each query."""

    def __init__(self, method: str):
        self.method = method

    def add(self, store, body: int) -> None:
        pass

    def remove(self, store, body: int) -> None:
        pass

    def candidates(self, store, bodies: np.ndarray) -> np.ndarray:
        if bodies.shape[0] < 2:
            return np.empty((0, 2), np.int64)
        rows = find_pairs(store.lo[bodies], store.hi[bodies], self.method)
        return bodies[rows]  # bodies ascending: rows i < j stay canonical


class SAPBroadPhase:
    """An ``IncrementalSAP`` whose object ids map to body ids; its sorted order survives from frame to frame.
    Bodies added since the last query are inserted then — one by one if they are few, else by building the
    SAP again over every body at once."""

    def __init__(self, rebuild_threshold: int = REBUILD_THRESHOLD):
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

    def candidates(self, store, bodies: np.ndarray) -> np.ndarray:
        if self.pending:
            self._insert_pending(store, bodies)
        slots = self.sap.ids()
        if slots.shape[0] < 2:
            return np.empty((0, 2), np.int64)
        owner = self.body_of[slots]
        return _canonical(self.body_of[self.sap.update(store.lo[owner], store.hi[owner])])


class TreeBroadPhase:
    """A ``DynamicAABBTree`` of fat boxes (see the module docstring); ``rebuild_threshold`` bounds the leaves
    moved (or inserted: a body added since the last query has no leaf yet and counts as escaped) one by one per
    query."""

    def __init__(self, rebuild_threshold: int = REBUILD_THRESHOLD):
        self.tree = DynamicAABBTree(dim=3, margin=0.0)
        self.leaf_of: dict[int, int] = {}
        self.body_of = np.full(16, -1, np.int64)
        self.cached: np.ndarray | None = None
        self.rebuild_threshold = rebuild_threshold
        self.rebuilds = 0
        self.removed: list[int] = []  # bodies removed since the last query: their cached pairs are dropped then

    @staticmethod
    def _fatten(store, bodies) -> None:
        grow = FAT_MARGIN * (store.hi[bodies] - store.lo[bodies]).max(axis=1, keepdims=True)
        store.fat_lo[bodies] = store.lo[bodies] - grow
        store.fat_hi[bodies] = store.hi[bodies] + grow
        store.escaped[bodies] = False

    def add(self, store, body: int) -> None:
        """Nothing until the next query: the body's fat box is empty, so the upload flags it as escaped."""
        store.fat_lo[body], store.fat_hi[body] = np.inf, -np.inf
        store.escaped[body] = True

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
            gone = np.zeros(store.capacity, np.bool_)
            gone[self.removed] = True
            self.cached = self.cached[~(gone[self.cached[:, 0]] | gone[self.cached[:, 1]])]
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

    def candidates(self, store, bodies: np.ndarray) -> np.ndarray:
        if self.removed:
            self._drop_removed(store)
        escaped = bodies[store.escaped[bodies]]
        if escaped.shape[0]:
            self._fatten(store, escaped)
            if escaped.shape[0] > self.rebuild_threshold or self.cached is None:
                self._rebuild(store, bodies)
                self.cached = None
            else:
                self._requery(store, escaped)
        if self.cached is None:
            self.cached = _canonical(self.body_of[self.tree.pairs()]) if bodies.shape[0] > 1 else \
                np.empty((0, 2), np.int64)
        return self.cached


def make_broad_phase(method: str):
    """The broad-phase state for ``World(broad_phase=method)``."""
    if method == "tree":
        return TreeBroadPhase()
    if method == "sap":
        return SAPBroadPhase()
    return RebuildBroadPhase(method)
