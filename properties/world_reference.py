"""The reference path of the World properties: every pair of live ids, two static ones excepted, answered through
the overlap table of the dispatch (``engine.world.dispatch.answer``) — no broad phase, no filter."""
from __future__ import annotations

import numpy as np

from engine.narrowphase.contacts import TOUCHING, kernel_scratch
from engine.world import TABLE
from engine.world.dispatch import NarrowContext, answer

__all__ = ["every_pair", "reference_pairs"]


def every_pair(world) -> np.ndarray:
    """Every pair of live ids (i < j, lexicographic order) that a query may ask: not two static bodies."""
    ids = world.ids()
    static = world.bodies().static
    return np.array([(i, j) for x, i in enumerate(ids) for j in ids[x + 1:] if not (static[i] and static[j])],
                    dtype=np.int64).reshape(-1, 2)


def reference_pairs(world) -> np.ndarray:
    """The pairs of ``every_pair`` whose shapes overlap, by the overlap table: canonical (k, 2)."""
    allp = every_pair(world)
    store = world._store.view()
    shapes = {g: world.shape(g) for g in world.ids().tolist()}  # the kernels of grounds and surfaces read them
    result = answer(TABLE, "overlap", NarrowContext(store, shapes, kernel_scratch(store.points.shape[1]), 0.0, True),
                    allp)
    return np.unique(allp[result.origin[result.out.status == TOUCHING]], axis=0).reshape(-1, 2)
