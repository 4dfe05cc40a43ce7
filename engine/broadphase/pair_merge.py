"""The canonical merge of the pair buffers of several threads: canonical pairs without a serial pass.

When a broad phase shares its sweep among threads, each thread fills a pair buffer of its own. The canonical
pairs of their union (int64 (k, 2), i < j, rows sorted, no repeat: ``engine.broadphase.pairs``) are made in
two parallel stages, each part on its own thread (``thread_pool.run_parts``):

1. *sort*: each buffer is turned into pair keys min · 2^s + max (2^s >= n; rows with i == j dropped), written
   into its own segment of one key array, and radix-sorted there;
2. *merge*: the key range is cut at splitters — keys of the largest segment at equal ranks — and each output
   range is the k-way merge of the sub-segments of every segment falling in it (each found by binary search),
   repeats dropped. A key falls in exactly one output range, so repeats (the same pair met by two threads)
   always meet in one merge and the ranges hold disjoint, increasing sets of keys. A prefix sum of the ranges'
   sizes gives each its first output row, where it writes its pairs decoded (when a pair was met twice the
   ranges leave gaps, closed by one copy at the end).

This is the parallel form of the sample sort / multiway merge (Sanders and Winkel, "Super Scalar Sample Sort",
ESA 2004; Knuth, TAOCP vol. 3, 5.4.1 for the k-way merge): the output depends only on the set of keys, not on how
the work was cut or which thread finished first, so any thread count gives the same array, bit for bit.
"""
from __future__ import annotations

import numpy as np

from engine._config import njit
from engine.broadphase.thread_pool import run_parts

__all__ = ["merge_pair_parts", "row_keys", "first_at_or_after"]


@njit
def row_keys(buf, count, shift, keys, first):
    """keys[first:] = the key min · 2^shift + max of each row (a, b) of the pair buffer buf[:count] (int64
    (capacity, 2)) with a != b; returns how many keys were written."""
    k = first
    for t in range(count):
        a = buf[t, 0]
        b = buf[t, 1]
        if a != b:
            keys[k] = (min(a, b) << shift) | max(a, b)
            k += 1
    return k - first


@njit
def _sort_keys_into(src, count, dst, tmp, in_place):
    """dst[:count] = the keys src[:count] (non-negative int64) sorted: a stable LSD radix sort (Knuth, TAOCP vol.
    3, 5.2.5) whose first pass reads src and whose last pass writes dst, so no copy is made (tmp: scratch of at
    least ``count``; ``in_place``: src is dst, copied to tmp first when an odd number of passes would make the
    first one write over what it reads). Digits of at most 10 bits, the histograms of all digits counted in one read
    pass, a digit on which every key agrees skipped."""
    top = 0
    for t in range(count):
        top = max(top, src[t])
    bits = 0
    while (top >> bits) > 0:
        bits += 1
    passes = (bits + 9) // 10
    width = (bits + passes - 1) // passes if passes > 0 else 1
    mask = (1 << width) - 1
    hist = np.zeros((max(passes, 1), mask + 1), dtype=np.int64)
    for t in range(count):
        k = src[t]
        for d in range(passes):
            hist[d, (k >> (d * width)) & mask] += 1
    left = 0  # the passes to run: the one with an even number left after it writes dst
    for d in range(passes):
        left += hist[d, (src[0] >> (d * width)) & mask] != count
    if left == 0:
        for t in range(count):  # copies by loops: a slice assignment compiles numba's shape-error path
            dst[t] = src[t]
        return
    a = src
    if in_place and left % 2 == 1:
        for t in range(count):
            tmp[t] = src[t]
        a = tmp
    for d in range(passes):
        if hist[d, (src[0] >> (d * width)) & mask] == count:
            continue
        left -= 1
        b = dst if left % 2 == 0 else tmp
        total = 0
        for v in range(mask + 1):
            c = hist[d, v]
            hist[d, v] = total
            total += c
        shift = d * width
        for t in range(count):
            k = a[t]
            v = (k >> shift) & mask
            p = hist[d, v]  # read once: b and hist could alias for the compiler
            hist[d, v] = p + 1
            b[p] = k
        a = b


@njit
def first_at_or_after(keys, lo, hi, key):
    """The first position p in [lo, hi) of the sorted keys with keys[p] >= key (hi if none): binary search."""
    while lo < hi:
        mid = (lo + hi) >> 1
        if keys[mid] < key:
            lo = mid + 1
        else:
            hi = mid
    return lo


@njit
def _merge_bounds(keys, seg_start, seg_end, ranges):
    """The cut of the sorted segments keys[seg_start[p]:seg_end[p]] into ``ranges`` output ranges: bounds (k,
    ranges + 1) int64, range j of segment p being keys[bounds[p, j]:bounds[p, j + 1]]. The splitters are the keys
    of the longest segment at ranks len · j / ranges (j = 1 .. ranges − 1); a key equal to a splitter goes to
    the range that starts at it, in every segment."""
    k = seg_start.shape[0]
    longest = 0
    for p in range(k):
        if seg_end[p] - seg_start[p] > seg_end[longest] - seg_start[longest]:
            longest = p
    size = seg_end[longest] - seg_start[longest]
    bounds = np.empty((k, ranges + 1), dtype=np.int64)
    for p in range(k):
        bounds[p, 0] = seg_start[p]
        bounds[p, ranges] = seg_end[p]
        for j in range(1, ranges):
            splitter = keys[seg_start[longest] + size * j // ranges]
            bounds[p, j] = first_at_or_after(keys, bounds[p, j - 1], seg_end[p], splitter)
    return bounds


@njit(inline="always")
def _put_row(out, row, key, shift):
    """out[row] = the pair (i, j) of the key i · 2^shift + j."""
    out[row, 0] = key >> shift
    out[row, 1] = key & ((1 << shift) - 1)


@njit
def _merge_range(keys, heads, ends, shift, out, row):
    """Merge the sorted runs keys[heads[p]:ends[p]] (p < k) into the pair rows out[row:] (decoded), repeats
    dropped (k-way merge: the smallest head at each step, a scan of the k heads); returns the number of rows
    written. heads is overwritten."""
    k = heads.shape[0]
    written = 0
    previous = -1
    while True:
        best = -1
        for p in range(k):
            if heads[p] < ends[p] and (best < 0 or keys[heads[p]] < keys[heads[best]]):
                best = p
        if best < 0:
            return written
        key = keys[heads[best]]
        heads[best] += 1
        if key != previous:
            _put_row(out, row + written, key, shift)
            written += 1
            previous = key


@njit
def _merge_two(keys, a, a_end, b, b_end, shift, out, row):
    """``_merge_range`` of two runs (the usual case: two threads), one compare per key."""
    written = 0
    previous = -1
    while a < a_end or b < b_end:
        take_a = b >= b_end or (a < a_end and keys[a] <= keys[b])
        key = keys[a] if take_a else keys[b]
        a += take_a
        b += not take_a
        if key != previous:
            _put_row(out, row + written, key, shift)
            written += 1
            previous = key
    return written


def _merge(keys: np.ndarray, bounds: np.ndarray, j: int, shift: int, out: np.ndarray, row: int) -> int:
    """Output range j of the cut ``bounds``: its merged pairs without repeats in out[row:]; their number."""
    if bounds.shape[0] == 2:
        return int(_merge_two(keys, bounds[0, j], bounds[0, j + 1], bounds[1, j], bounds[1, j + 1], shift, out, row))
    return int(_merge_range(keys, bounds[:, j].copy(), bounds[:, j + 1].copy(), shift, out, row))


def merge_pair_parts(parts: list[tuple[np.ndarray, int]], n: int, shift: int, keys: np.ndarray, tmp: np.ndarray,
                     threads: int) -> np.ndarray:
    """Canonical pairs (int64 (k, 2), a new array) of the union of the pair buffers ``parts`` = [(buffer, count)],
    on ``threads`` threads (see the module's description; parts past the threads-th are sorted by the last thread).

    A buffer is either rows (int64 (capacity, 2): pairs (a, b) of objects < n, any order, a == b dropped) or pair
    keys (int64 (capacity,): min · 2^shift + max, ``pairs.pair_key_shift(n)``). keys and tmp: int64 work arrays
    of at least the sum of the counts (overwritten).
    """
    counts = np.array([count for _, count in parts], dtype=np.int64)
    seg_start = np.zeros(len(parts), dtype=np.int64)
    seg_start[1:] = np.cumsum(counts)[:-1]
    seg_end = seg_start.copy()

    def sort(group: list[int]) -> None:
        for p in group:
            sort_one(p)

    def sort_one(p: int) -> None:
        buf, count = parts[p]
        first = int(seg_start[p])
        if buf.ndim == 2:  # rows: their keys, then sorted where they are
            written = row_keys(buf, count, shift, keys, first)
            segment = keys[first:first + written]
            _sort_keys_into(segment, written, segment, tmp[first:first + written], True)
        else:  # pair keys: sorted from the buffer into the segment
            written = count
            _sort_keys_into(buf, count, keys[first:first + count], tmp[first:first + count], False)
        seg_end[p] = first + written

    groups = [[t] for t in range(min(threads, len(parts)))]
    groups[-1] += range(len(groups), len(parts))
    run_parts(sort, groups)
    ranges = len(groups)
    bounds = _merge_bounds(keys, seg_start, seg_end, ranges)
    first = np.zeros(ranges + 1, dtype=np.int64)  # range j starts at row first[j] (the keys before it)
    first[1:] = np.cumsum((bounds[:, 1:] - bounds[:, :-1]).sum(axis=0))
    out = np.empty((int(first[-1]), 2), dtype=np.int64)
    sizes = run_parts(lambda j: _merge(keys, bounds, j, shift, out, int(first[j])), range(ranges))
    if sum(sizes) == out.shape[0]:  # no pair met twice: the ranges fill the rows
        return out
    return np.concatenate([out[first[j]:first[j] + sizes[j]] for j in range(ranges)])
