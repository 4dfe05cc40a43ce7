"""Brute force, the chapter's exhaustive search: the reference every other broad phase is tested against.

Chapter slide "Phase Large : la méthode de force brute": compare the bounding boxes of every pair of objects,
(n² − n)/2 tests — no self-test (i, i), and (A, B) is never tested again as (B, A). Kept forever as the oracle,
like Jolt's ``BroadPhaseBruteForce`` ("can be used as a reference implementation").
"""
from __future__ import annotations

from typing import Literal, overload

import numpy as np
from numpy.typing import ArrayLike

import engine.broadphase.pairs as pair_buffer
from engine._config import njit
from engine.broadphase.pairs import as_boxes_3d, as_threads, boxes_overlap, empty_pairs, with_tests

__all__ = ["brute_force_pairs"]


@njit
def _brute_force_kernel(lo, hi, first, last):
    # Chapter, "force brute": for i < j (no self-test, no (B, A) after (A, B)) test the boxes i, j, for the rows
    # i = first .. last − 1. Two passes (count, then fill) so the output is allocated once; rows come out already
    # canonical. Returns (pairs, count, tests).
    n = lo.shape[0]
    count = 0
    for i in range(first, last):
        for j in range(i + 1, n):
            if boxes_overlap(lo, hi, i, j):
                count += 1
    out = np.empty((count, 2), dtype=np.int64)
    k = 0
    for i in range(first, last):
        for j in range(i + 1, n):
            if boxes_overlap(lo, hi, i, j):
                out[k, 0] = i
                out[k, 1] = j
                k += 1
    tests = 0  # the chapter's (n² − n)/2 box tests over all rows, by construction
    for i in range(first, last):
        tests += n - 1 - i
    return out, count, tests


#: a thread makes at least this many box tests
MIN_TESTS_PER_THREAD = 1 << 20


@overload
def brute_force_pairs(lo: ArrayLike, hi: ArrayLike, *, return_tests: Literal[False] = ...,
                      threads: int = ...) -> np.ndarray: ...
@overload
def brute_force_pairs(lo: ArrayLike, hi: ArrayLike, *, return_tests: Literal[True],
                      threads: int = ...) -> tuple[np.ndarray, int]: ...
def brute_force_pairs(lo: ArrayLike, hi: ArrayLike, *, return_tests: bool = False,
                      threads: int = 1) -> np.ndarray | tuple[np.ndarray, int]:
    """All pairs of overlapping closed boxes by the exhaustive (n² − n)/2 tests: ``find_pairs(method="brute")``.

    The threads share the rows i of the tests (i, j > i). ``lo``, ``hi``, ``return_tests``, ``threads``, the result
    and the errors are those of every box method (:ref:`broadphase-boxes`, :ref:`broadphase-options`).

    Returns
    -------
    pairs : numpy.ndarray, shape (k, 2), int64
        :ref:`broadphase-pairs`; ``(pairs, tests)`` with ``return_tests=True``, ``tests`` always (n² − n)/2.
    """
    threads = as_threads(threads)
    lo3, hi3 = as_boxes_3d(lo, hi)
    n = lo3.shape[0]
    if n < 2:
        return with_tests(empty_pairs(), 0, return_tests)
    work = np.concatenate([[0], np.cumsum(np.arange(n - 1, -1, -1))])  # tests of the rows before each row
    ranges = pair_buffer.split_work(work, threads, MIN_TESTS_PER_THREAD)
    pairs, tests = pair_buffer.run_split(lambda first, last: _brute_force_kernel(lo3, hi3, first, last), ranges, n)
    return with_tests(pairs, tests, return_tests)
