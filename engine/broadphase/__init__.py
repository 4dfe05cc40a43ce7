"""Broad phase: every method of the chapter's "Phase Large", one contract.

``find_pairs(lo, hi, method)`` returns all pairs of overlapping closed boxes ``[lo_i, hi_i]`` (touching counts)
as canonical pairs — an int64 array of shape (k, 2) with ``i < j`` in every row, rows in lexicographic order, no
duplicate — identical for every method in ``BROAD_PHASES``; "brute" (the chapter's exhaustive search) is the
oracle the others are tested against. ``sphere_pairs`` is the same for spheres (broad phase and exact test),
``IncrementalSAP`` and ``DynamicAABBTree`` keep their structure between frames, and the kinematic culls drop
candidate pairs that move apart.
"""
from __future__ import annotations

from collections.abc import Callable
from typing import Any, Literal, overload

import numpy as np
from numpy.typing import ArrayLike

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

_METHODS: dict[str, Callable[..., Any]] = {
    "brute": brute_force_pairs,
    "sap": sap_pairs,
    "grid": grid_pairs,
    "octree": octree_pairs,
    "tree": tree_pairs,
}

#: the method names accepted by ``find_pairs`` and ``sphere_pairs``: "brute", "sap", "grid", "octree", "tree"
BROAD_PHASES = tuple(_METHODS)


@overload
def find_pairs(lo: ArrayLike, hi: ArrayLike, method: str = ..., *, return_tests: Literal[False] = ...,
               threads: int = ...) -> np.ndarray: ...
@overload
def find_pairs(lo: ArrayLike, hi: ArrayLike, method: str = ..., *, return_tests: Literal[True],
               threads: int = ...) -> tuple[np.ndarray, int]: ...
def find_pairs(lo: ArrayLike, hi: ArrayLike, method: str = "sap", *, return_tests: bool = False,
               threads: int = 1) -> np.ndarray | tuple[np.ndarray, int]:
    """All pairs of overlapping closed boxes ``[lo_i, hi_i]``; the same canonical pairs whatever the method.

    Parameters
    ----------
    lo, hi : array_like, shape (n, d)
        The boxes' lower and upper corners, d = 1, 2 or 3, ``lo <= hi``; finite, converted to float64. Boxes are
        closed: two boxes that touch overlap.
    method : str, optional
        One of ``BROAD_PHASES``: "brute" (the exhaustive (n² − n)/2 tests, the oracle), "sap"
        (sweep-and-prune, the default), "grid" (uniform grid), "octree" (loose octree), "tree" (AABB tree built
        top-down).
    return_tests : bool, optional
        Also return how many box–box overlap tests between objects the method made: (n² − n)/2 for brute
        force, the deterministic measure of how much each method prunes.
    threads : int, optional
        How many threads may share the work, 1 to 256 (each method splits its sweep or its queries into
        contiguous ranges, one per thread, when there is enough work); the answer is the same, bit for bit.

    Returns
    -------
    pairs : numpy.ndarray, shape (k, 2), int64
        The overlapping pairs (i, j) of row indices: ``i < j`` in every row, rows sorted, no duplicate.
    tests : int
        Only with ``return_tests=True``: the number of box–box tests made.

    Raises
    ------
    ValueError
        When ``lo`` or ``hi`` holds NaN, ±inf or a magnitude above 1e150, when their shapes differ or d is not
        1, 2 or 3, when ``lo > hi`` somewhere (the message names the first such entry), when ``method`` is
        unknown, or when ``threads`` is out of range.
    TypeError
        When ``lo`` or ``hi`` is not a real numeric array, ``method`` is not a string or ``threads`` not an int.

    See Also
    --------
    sphere_pairs : the same contract for spheres.
    IncrementalSAP, DynamicAABBTree : broad phases that keep their structure between frames.

    Examples
    --------
    >>> import numpy as np
    >>> from engine.broadphase import find_pairs
    >>> lo = np.array([[0.0, 0.0], [1.0, 0.0], [5.0, 5.0]])
    >>> find_pairs(lo, lo + 1.0)  # boxes 0 and 1 touch along x = 1
    array([[0, 1]])
    >>> find_pairs(lo, lo + 1.0, "brute", return_tests=True)
    (array([[0, 1]]), 3)
    """
    as_choice(method, "method", _METHODS)
    return _METHODS[method](lo, hi, return_tests=return_tests, threads=threads)
