"""Brute force, the chapter's exhaustive search: the reference every other broad phase is tested against.

Chapter slide "Phase Large : la méthode de force brute": compare the bounding boxes of every pair of objects,
(n² − n)/2 tests — no self-test (i, i), and (A, B) is never tested again as (B, A). Kept forever as the oracle,
like Jolt's ``BroadPhaseBruteForce`` ("can be used as a reference implementation").
"""
from __future__ import annotations

import numpy as np

from engine._config import njit
from engine.broadphase.pairs import as_boxes_3d, boxes_overlap, empty_pairs, with_tests

__all__ = ["brute_force_pairs"]


@njit
def _brute_force_kernel(lo, hi):
    # Chapter, "force brute": for i < j (no self-test, no (B, A) after (A, B)) test the boxes i, j.
    # Two passes (count, then fill) so the output is allocated once; rows come out already canonical.
    n = lo.shape[0]
    count = 0
    for i in range(n):
        for j in range(i + 1, n):
            if boxes_overlap(lo, hi, i, j):
                count += 1
    out = np.empty((count, 2), dtype=np.int64)
    tests = n * (n - 1) // 2  # the chapter's (n² − n)/2 box tests, by construction
    k = 0
    for i in range(n):
        for j in range(i + 1, n):
            if boxes_overlap(lo, hi, i, j):
                out[k, 0] = i
                out[k, 1] = j
                k += 1
    return out, tests


def brute_force_pairs(lo, hi, *, return_tests: bool = False):
    """All pairs of overlapping closed boxes by the exhaustive (n² − n)/2 test.

    lo, hi: (n, d) with d in {1, 2, 3} and lo <= hi. Returns canonical pairs, int64 (k, 2); with
    ``return_tests=True``, ``(pairs, tests)`` where tests counts the box–box overlap tests made.
    """
    lo3, hi3 = as_boxes_3d(lo, hi)
    if lo3.shape[0] < 2:
        return with_tests(empty_pairs(), 0, return_tests)
    pairs, tests = _brute_force_kernel(lo3, hi3)
    return with_tests(pairs, tests, return_tests)
