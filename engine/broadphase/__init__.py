"""Broad phase: every method of the chapter's "Phase Large", one contract.

``find_pairs(lo, hi, method)`` returns all pairs of overlapping closed boxes [lo_i, hi_i] (touching counts) as
canonical pairs — int64 (k, 2), i < j per row, rows sorted, no duplicate — identical for every method in
``BROAD_PHASES``; "brute" (the chapter's exhaustive search) is the oracle the others are tested against.
"""
from __future__ import annotations

from engine._validate import as_choice
from engine.broadphase.aabb_tree import DynamicAABBTree, tree_pairs
from engine.broadphase.brute_force import brute_force_pairs
from engine.broadphase.kinematic import cull_separating_box_pairs, cull_separating_sphere_pairs, front_faces
from engine.broadphase.octree import build_octree, octree_pairs
from engine.broadphase.pairs import canonical_pairs
from engine.broadphase.spheres import sphere_pairs, spheres_overlap_pairs
from engine.broadphase.sweep_and_prune import IncrementalSAP, sap_example_trace, sap_pairs, sweep_intervals
from engine.broadphase.uniform_grid import grid_pairs

__all__ = [
    "BROAD_PHASES",
    "find_pairs",
    "sweep_intervals",
    "sphere_pairs",
    "spheres_overlap_pairs",
    "sap_example_trace",
    "IncrementalSAP",
    "DynamicAABBTree",
    "canonical_pairs",
    "cull_separating_sphere_pairs",
    "cull_separating_box_pairs",
    "front_faces",
    "brute_force_pairs",
    "sap_pairs",
    "grid_pairs",
    "octree_pairs",
    "tree_pairs",
    "build_octree",
]

_METHODS = {
    "brute": brute_force_pairs,
    "sap": sap_pairs,
    "grid": grid_pairs,
    "octree": octree_pairs,
    "tree": tree_pairs,
}

#: the names accepted by find_pairs (and sphere_pairs)
BROAD_PHASES = tuple(_METHODS)


def find_pairs(lo, hi, method: str = "sap", *, return_tests: bool = False, threads: int = 1):
    """All pairs of overlapping closed boxes [lo_i, hi_i]; the same canonical pairs whatever the method.

    lo, hi: (n, d) with d in {1, 2, 3} and lo <= hi. method: one of ``BROAD_PHASES`` — "brute" (exhaustive
    (n² − n)/2 tests, the oracle), "sap" (sweep-and-prune), "grid" (uniform grid), "octree" (loose octree),
    "tree" (AABB tree built top-down). Returns int64 (k, 2), i < j per row, rows sorted, no duplicate.

    With ``return_tests=True`` returns ``(pairs, tests)``: ``tests`` counts the box–box overlap tests between
    objects that the method made — (n² − n)/2 for brute force — the deterministic measure of how much each
    method prunes (the CI gate bounds it).

    ``threads`` (1 to 256): how many threads may share the work (each method splits its sweep or its queries
    into contiguous ranges, one per thread, when there is enough work); the answer is the same, bit for bit.
    """
    as_choice(method, "method", _METHODS)
    return _METHODS[method](lo, hi, return_tests=return_tests, threads=threads)
