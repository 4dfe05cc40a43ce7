"""Canonical pair arrays and the pair buffer, the common output of every broad phase.

"pairs" is always an int64 array of shape (k, 2) with ``i < j`` in every row, rows in lexicographic order and
no duplicate row.  Every broad-phase kernel gathers its candidate pairs in a *pair buffer* — an int64 (capacity, 2)
array and a row count — in whatever order its traversal meets them: :func:`new_pair_buffer` makes one,
:func:`push_pair` appends a row (doubling the buffer when it is full). The two hottest sweeps (sap's columns and
the sphere columns) record branch-free instead — the *two-try record*: write the row while there is room, add the
test's outcome to the count, and sweep again with a buffer of that count (:func:`work_pair_buffer`) if it was
short; it is written out in them, since any helper call that takes the buffer costs an atomic reference-count
increment and decrement per candidate, on a loop that otherwise does a few compares and one store per candidate
(bench/test_bench_broadphase.py, the W1 boxes and W2 spheres groups, time those sweeps). The kernel hands the
buffer to :func:`canonicalise_pairs`, which puts the rows in that one form in O(k): one integer key per pair, a
radix sort, repeats dropped. :func:`canonical_pairs` is the same operation at the public boundary (validated);
:func:`canonicalise_buffer` runs it with the keys in this thread's reusable work arrays (:func:`work_array`,
which the sweeps also use for their sorted data). A kernel may record each pair as one integer key
min · 2^s + max instead (:func:`pair_key_shift`; half the bytes of a row): :func:`canonicalise_key_buffer` sorts
and decodes such keys.
:func:`split_work` and :func:`run_split` share a kernel's work among threads and merge their buffers.

This module also holds the checks shared by the broad phases: :func:`as_boxes` validates ``lo``/``hi`` box
arrays at the public boundary, and :func:`as_boxes_3d` pads 1-D and 2-D boxes to 3-D with a zero-width extra
axis (which every box then overlaps), so each kernel is written once, in 3-D.
"""
from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, DTypeLike

from engine._config import MAX_THREADS, njit
from engine._validate import as_count, as_float_array
from engine.broadphase.counting_sort import radix_sort_pairs
from engine.broadphase.pair_merge import merge_pair_parts, row_keys
from engine.broadphase.thread_pool import run_parts

__all__ = ["canonical_pairs", "empty_pairs", "as_boxes", "as_boxes_3d", "as_one_box", "as_live_id", "boxes_overlap",
           "with_tests",
           "new_pair_buffer", "grow_pair_buffer", "push_pair", "canonicalise_pairs", "canonicalise_pairs_with",
           "canonicalise_buffer", "pair_key_shift", "canonicalise_pair_keys_with", "canonicalise_key_buffer",
           "as_threads", "split_work", "split_even", "run_split", "work_pair_buffer", "work_array", "keep_work_array"]


def empty_pairs() -> np.ndarray:
    """The empty pair array, shape (0, 2), int64."""
    return np.zeros((0, 2), dtype=np.int64)


def with_tests(pairs: np.ndarray, tests: int, return_tests: bool) -> Any:
    """What a broad phase returns: ``pairs`` ((k, 2) int64), or ``(pairs, tests)`` when the caller asked for the
    work count (``tests`` as a Python int)."""
    return (pairs, int(tests)) if return_tests else pairs


@njit
def new_pair_buffer(expected):
    """An empty pair buffer: int64 (max(expected, 16), 2), to be filled from row 0 by :func:`push_pair`."""
    return np.empty((max(expected, 16), 2), dtype=np.int64)


@njit
def grow_pair_buffer(buffer, needed):
    """A copy of the pair buffer ``buffer`` (int64 (capacity, 2)) with room for at least ``needed`` rows
    (the capacity at least doubles, so n pushes cost O(n) copies in all)."""
    capacity = max(2 * buffer.shape[0], needed, 16)
    out = np.empty((capacity, 2), dtype=np.int64)
    for r in range(buffer.shape[0]):  # row by row: no shape check (and no compiled error message) to make
        out[r, 0] = buffer[r, 0]
        out[r, 1] = buffer[r, 1]
    return out


@njit(inline="always")
def push_pair(buffer, count, i, j):
    """Append the row (i, j) to the pair buffer holding ``count`` rows; returns (buffer, count + 1).

    ``buffer`` is int64 (capacity, 2); when it is full a grown copy is returned, so callers always write
    ``buffer, count = push_pair(buffer, count, i, j)``.
    """
    if count == buffer.shape[0]:
        buffer = grow_pair_buffer(buffer, count + 1)
    buffer[count, 0] = i
    buffer[count, 1] = j
    return buffer, count + 1


@njit
def canonicalise_pairs(candidates, count, n):
    """Canonical pairs (int64 (k, 2), a new array) of the first ``count`` rows of the pair buffer ``candidates``
    (int64 (capacity, 2); objects numbered 0..n-1).

    Each row (a, b) with a != b becomes the integer key min(a, b) · 2^s + max(a, b) (2^s > n − 1); the keys are
    radix-sorted (``counting_sort.radix_sort_pairs``: a few linear passes, no comparison sort), repeats dropped
    and the rows decoded. Rows with a == b (a self-test, which the chapter excludes) are dropped.
    """
    return canonicalise_pairs_with(candidates, count, n, np.empty(count, dtype=np.int64),
                                   np.empty(count, dtype=np.int64))


@njit
def canonicalise_pairs_with(candidates, count, n, keys, keys_tmp):
    """:func:`canonicalise_pairs` with the keys sorted in the given work arrays (int64, at least ``count``
    each; overwritten)."""
    shift = pair_key_shift(n)
    k = row_keys(candidates, count, shift, keys, np.int64(0))  # int64: radix_sort_pairs is compiled for one count type
    no_values = np.empty(0, dtype=np.int64)
    keys, _ = radix_sort_pairs(keys, no_values, keys_tmp, no_values, k)
    rows = 0
    for t in range(k):
        rows += t == 0 or keys[t] != keys[t - 1]
    out = np.empty((rows, 2), dtype=np.int64)
    rows = 0
    low = (1 << shift) - 1
    for t in range(k):
        if t == 0 or keys[t] != keys[t - 1]:
            out[rows, 0] = keys[t] >> shift
            out[rows, 1] = keys[t] & low
            rows += 1
    return out


@njit
def pair_key_shift(n):
    """The smallest s with 2^s >= n (at least 1): the pair (i, j), i < j < n, is the integer key i · 2^s + j."""
    shift = 1
    while (1 << shift) < n:
        shift += 1
    return shift


@njit
def canonicalise_pair_keys_with(keys, count, n, keys_tmp):
    """Canonical pairs (int64 (k, 2), a new array) of the first ``count`` pair keys ``keys`` (int64, each
    min(a, b) · 2^s + max(a, b) of a pair of objects a, b < n, s = ``pair_key_shift(n)``; overwritten), sorted with
    the work array ``keys_tmp`` (int64, at least ``count``).

    The form a kernel writes when it records its pairs as keys (one 8-byte word a pair instead of two): the
    keys are radix-sorted as in :func:`canonicalise_pairs`, then decoded in one pass, repeats and keys with
    a == b dropped.
    """
    shift = pair_key_shift(n)
    no_values = np.empty(0, dtype=np.int64)
    keys, _ = radix_sort_pairs(keys, no_values, keys_tmp, no_values, count)
    out = np.empty((count, 2), dtype=np.int64)
    low = (1 << shift) - 1
    rows = 0
    previous = -1
    for t in range(count):
        key = keys[t]
        i = key >> shift
        j = key & low
        if key != previous and i != j:
            out[rows, 0] = i
            out[rows, 1] = j
            rows += 1
        previous = key
    return out if rows == count else out[:rows].copy()


def canonicalise_key_buffer(keys: np.ndarray, count: int, n: int) -> np.ndarray:
    """:func:`canonicalise_pair_keys_with` of the first ``count`` pair keys of ``keys`` (overwritten), sorted in
    this thread's reusable work array."""
    return canonicalise_pair_keys_with(keys, count, n, work_array("canonical_keys_tmp", count, np.int64))


def canonicalise_buffer(buffer: np.ndarray, count: int, n: int) -> np.ndarray:
    """:func:`canonicalise_pairs` of the pair buffer's first ``count`` rows, its keys sorted in this thread's
    reusable work arrays (fresh ones would cost a page fault every 512 pairs)."""
    keys = work_array("canonical_keys", count, np.int64)
    keys_tmp = work_array("canonical_keys_tmp", count, np.int64)
    return canonicalise_pairs_with(buffer, count, n, keys, keys_tmp)


def canonical_pairs(pairs: ArrayLike, n: int | None = None) -> np.ndarray:
    """Put index pairs in canonical form: int64 (k, 2), ``i < j`` in every row, rows sorted, no duplicate.

    Rows (i, j) and (j, i) are the same pair; rows (i, i) are dropped. The sort is a radix sort on one integer
    key per pair, O(m).

    Parameters
    ----------
    pairs : array_like of int, shape (m, 2)
        Index pairs in any order, with repeats allowed; an empty array of any shape (even float, as
        ``np.array([])``) means no pairs.
    n : int, optional
        The number of objects; every index must then lie in [0, n). By default, one more than the largest index.

    Returns
    -------
    numpy.ndarray, shape (k, 2), int64
        A new array; never a view of ``pairs``.

    Raises
    ------
    TypeError
        When ``pairs`` is not an integer array (and not empty), or ``n`` is not an int.
    ValueError
        When ``pairs`` does not have shape (m, 2), holds a negative index, or an index >= ``n`` (the message
        names the first such row), or when ``n < 0``.

    Examples
    --------
    >>> from engine.broadphase import canonical_pairs
    >>> canonical_pairs([[3, 1], [0, 2], [1, 3], [2, 2]])
    array([[0, 2],
           [1, 3]])
    """
    if n is not None:
        n = as_count(n, "n", 0)
    arr = np.asarray(pairs)
    if arr.dtype.kind not in "iu":
        if arr.size == 0 and arr.dtype.kind == "f":  # np.array([]) and np.empty((0, 2)) mean "no pairs"
            arr = arr.astype(np.int64)
        else:
            raise TypeError(f"pairs must be an integer array, got dtype {arr.dtype}")
    if arr.ndim != 2 or arr.shape[1] != 2:
        if arr.size == 0:
            return empty_pairs()
        raise ValueError(f"pairs must have shape (m, 2), got {arr.shape}")
    if arr.shape[0] == 0:
        return empty_pairs()
    arr = np.ascontiguousarray(arr, dtype=np.int64)
    negative = np.flatnonzero((arr < 0).any(axis=1))
    if negative.size:
        raise ValueError(f"pairs must hold non-negative indices: pairs[{negative[0]}] = {arr[negative[0]].tolist()}")
    top = int(arr.max()) + 1
    if n is None:
        n = top
    if top > n:
        bad = int(np.flatnonzero((arr >= n).any(axis=1))[0])
        raise ValueError(f"pairs[{bad}] = {arr[bad].tolist()} indexes past n = {n}")
    return canonicalise_pairs(arr, arr.shape[0], int(n))


def as_boxes(lo: ArrayLike | None, hi: ArrayLike | None) -> tuple[np.ndarray, np.ndarray]:
    """Validate axis-aligned boxes [lo_i, hi_i]: float64 copies of shape (n, d), d in {1, 2, 3}, lo <= hi.

    ValueError (naming ``lo``/``hi`` and the first offending entry) for NaN, inf, mismatched shapes, another d
    or lo > hi; TypeError for non-numeric arrays (None included).
    """
    lo_arr = as_float_array(lo, "lo", ndim=2)
    hi_arr = as_float_array(hi, "hi", ndim=2)
    if lo_arr.shape != hi_arr.shape:
        raise ValueError(f"lo and hi must have the same shape, got {lo_arr.shape} and {hi_arr.shape}")
    if lo_arr.shape[1] not in (1, 2, 3):
        raise ValueError(f"lo and hi must have shape (n, d) with d = 1, 2 or 3, got d = {lo_arr.shape[1]}")
    inverted = lo_arr > hi_arr
    if inverted.any():
        i, k = (int(v) for v in np.argwhere(inverted)[0])
        raise ValueError(f"lo must not exceed hi: lo[{i}, {k}] = {float(lo_arr[i, k])!r} > "
                         f"hi[{i}, {k}] = {float(hi_arr[i, k])!r}")
    return lo_arr, hi_arr


def as_one_box(lo_i: ArrayLike, hi_i: ArrayLike, d: int,
               names: tuple[str, str] = ("lo_i", "hi_i")) -> tuple[np.ndarray, np.ndarray]:
    """Validate one box [lo_i, hi_i]: float64 copies of shape (d,) each, lo_i <= hi_i; ``names`` are the
    argument names the errors quote."""
    lo_name, hi_name = names
    lo_arr = as_float_array(lo_i, lo_name, shape=(d,))
    hi_arr = as_float_array(hi_i, hi_name, shape=(d,))
    bad = np.flatnonzero(lo_arr > hi_arr)
    if bad.size:
        k = int(bad[0])
        raise ValueError(f"{lo_name} must not exceed {hi_name}: {lo_name}[{k}] = {float(lo_arr[k])!r} > "
                         f"{hi_name}[{k}] = {float(hi_arr[k])!r}")
    return lo_arr, hi_arr


def as_live_id(obj_id: Any, is_live: Callable[[int], bool]) -> int:
    """``obj_id`` as an int after checking it: TypeError unless an int, ValueError unless ``is_live(obj_id)``
    (the id of a live object of an incremental broad phase)."""
    if isinstance(obj_id, bool) or not isinstance(obj_id, int | np.integer):
        raise TypeError(f"id must be an int, got {type(obj_id).__name__}")
    if not is_live(int(obj_id)):
        raise ValueError(f"id {obj_id} is not a live object")
    return int(obj_id)


def as_boxes_3d(lo: ArrayLike, hi: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Validated boxes (as :func:`as_boxes`) padded to 3-D: (n, 3) float64 lo and hi; the padded axes are
    [0, 0], which every box overlaps, so the pairs are those of the d-D boxes."""
    lo_arr, hi_arr = as_boxes(lo, hi)
    d = lo_arr.shape[1]
    if d == 3:
        return lo_arr, hi_arr
    lo3 = np.zeros((lo_arr.shape[0], 3))
    hi3 = np.zeros((lo_arr.shape[0], 3))
    lo3[:, :d] = lo_arr
    hi3[:, :d] = hi_arr
    return lo3, hi3


@njit
def boxes_overlap(lo, hi, i, j):
    """Closed-box overlap test of boxes i and j of (n, 3) arrays: touching counts (Ericson 4.2.1)."""
    for k in range(3):
        if lo[i, k] > hi[j, k] or lo[j, k] > hi[i, k]:
            return False
    return True


_WORK = threading.local()  # per-thread pair buffers of the two-try sweeps and work arrays, reused between calls


def work_pair_buffer(rows: int) -> np.ndarray:
    """This thread's reusable pair buffer, int64 (at least ``rows``, 2) (grown by 25 %, never shrunk): a sweep
    that records into it keeps the size its last call needed, so it seldom sweeps twice, and fresh pages are not
    faulted in at every call. Its rows are overwritten by the next sweep on this thread: copy what you keep."""
    buf = getattr(_WORK, "pairs", None)
    if buf is None or buf.shape[0] < rows:
        buf = np.empty((max(16, rows + rows // 4), 2), dtype=np.int64)
        _WORK.pairs = buf
    return buf


def work_array(name: str, size: int, dtype: DTypeLike) -> np.ndarray:
    """This thread's reusable 1-D work array ``name`` of at least ``size`` elements of ``dtype`` (grown by 25 %,
    never shrunk): reusing it saves the page faults of fresh allocations, a large share of a sweep's time from
    1e5 objects on. Its contents are overwritten by the next call on this thread that uses ``name``."""
    arr = getattr(_WORK, name, None)
    if arr is None or arr.shape[0] < size or arr.dtype != dtype:
        arr = np.empty(max(16, size + size // 4), dtype=dtype)
        setattr(_WORK, name, arr)
    return arr


def as_threads(threads: Any) -> int:
    """The checked ``threads`` argument of a broad phase: an int in [1, MAX_THREADS]."""
    return as_count(threads, "threads", minimum=1, maximum=MAX_THREADS)


def split_work(work: np.ndarray | int, threads: int, min_work: int) -> list[tuple[int, int]]:
    """Cut the items 0..m−1, whose cumulative work is ``work`` ((m + 1,) non-decreasing, work[0] = 0), into at
    most ``threads`` contiguous ranges (first, last) of about equal work, each of at least ``min_work`` (one
    range when there is too little work to share). ``work`` an int m: m items of equal work (:func:`split_even`)."""
    if isinstance(work, int | np.integer):
        return split_even(int(work), threads, min_work)
    m = len(work) - 1
    parts = min(threads, max(1, int(work[-1]) // max(min_work, 1)))
    if parts <= 1 or m <= 1:
        return [(0, m)]
    cuts = np.searchsorted(work, [work[-1] * t / parts for t in range(1, parts)])
    bounds = sorted({0, m, *(int(c) for c in cuts)})
    return list(zip(bounds[:-1], bounds[1:]))


def split_even(m: int, threads: int, min_work: int) -> list[tuple[int, int]]:
    """:func:`split_work` of m items of equal work (cumulative work 0, 1, .., m) without making that array: the
    cut targets m · t / parts rounded up, as the binary search of split_work finds them."""
    parts = min(threads, max(1, m // max(min_work, 1)))
    if parts <= 1 or m <= 1:
        return [(0, m)]
    bounds = sorted({0, m, *(-(-m * t // parts) for t in range(1, parts))})
    return list(zip(bounds[:-1], bounds[1:]))


def run_split(sweep: Callable[[int, int], tuple[np.ndarray, int, int]], ranges: list[tuple[int, int]], n: int,
              extra: tuple[np.ndarray, int, int] | None = None,
              canonicalise: Callable[[np.ndarray, int, int], np.ndarray] = canonicalise_buffer,
              ) -> tuple[np.ndarray, int]:
    """Run ``sweep(first, last) -> (buffer, count, tests)`` over the item ranges, one thread per range (the
    kernels release the GIL), and merge them (and ``extra``, one more (buffer, count, tests) if given):
    ``(canonical pairs of the n objects, total tests)``. The result is the same, bit for bit, as one call over
    all the items: one range is put in canonical form by ``canonicalise(buffer, count, n)``
    (:func:`canonicalise_buffer` for pair buffers, (capacity, 2) rows, the default; :func:`canonicalise_key_buffer`
    for buffers of pair keys), several by the parallel canonical merge of ``engine.broadphase.pair_merge`` (each
    thread sorts its own buffer, then the threads merge disjoint key ranges)."""
    if extra is not None and extra[1] == 0:
        tests_extra = int(extra[2])
        pairs, tests = run_split(sweep, ranges, n, canonicalise=canonicalise)  # nothing to merge but the tests
        return pairs, tests + tests_extra
    if len(ranges) == 1:
        buf, count, tests = sweep(*ranges[0])
        if extra is None:
            return canonicalise(buf, count, n), int(tests)
        merged = np.concatenate([_as_rows(buf[:count], n), extra[0][: extra[1]]])
        return canonicalise_buffer(merged, merged.shape[0], n), int(tests) + int(extra[2])
    parts = run_parts(lambda r: sweep(*r), ranges)
    tests = sum(int(t) for _, _, t in parts)
    buffers = [(buf, int(count)) for buf, count, _ in parts]
    if extra is not None:
        buffers.append((extra[0], int(extra[1])))
        tests += int(extra[2])
    total = sum(count for _, count in buffers)
    keys = work_array("merge_keys", total, np.int64)
    keys_tmp = work_array("merge_keys_tmp", total, np.int64)
    return merge_pair_parts(buffers, n, int(pair_key_shift(n)), keys, keys_tmp, len(ranges)), tests


def _as_rows(buf: np.ndarray, n: int) -> np.ndarray:
    """A pair buffer's rows: ``buf`` itself when it holds rows ((k, 2)), else its pair keys decoded."""
    if buf.ndim == 2:
        return buf
    shift = int(pair_key_shift(n))
    return np.stack([buf >> shift, buf & ((1 << shift) - 1)], axis=1)


def keep_work_array(name: str, arr: np.ndarray) -> None:
    """Make ``arr`` this thread's work array ``name`` (see :func:`work_array`) when it is larger than the one
    held: a part that outgrew the buffer it was given hands the larger one back for the next call."""
    held = getattr(_WORK, name, None)
    if held is None or held.shape[0] < arr.shape[0]:
        setattr(_WORK, name, arr)
