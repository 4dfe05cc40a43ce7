"""The contact record of a ``World`` frame, assembled by compiled kernels from the narrow phase's rows.

``contact_record`` turns the contact rows of the tested pairs of parts (engine.narrowphase.contacts.ContactRows,
one row per pair of store rows) into the arrays of one ``ContactSet``: the touching rows in lexicographic order
of (i, j, part_a, part_b) — (i, j) the candidate pair of bodies each row came from —, their points packed in that
order, and whether each point persists from the previous record. A point is keyed by its pair of (body, part),
each packed as ``body << PART_BITS | part``, and its id; the previous record's points are kept sorted by (key of
the first side, key of the second, id), which the binary search of ``mark_persisting`` reads, and the kernel
returns this record's points in that order for the next frame.

The order is a total order (a pair of parts is tested once, and ``reduce_manifold`` makes the ids of one pair
distinct), so the record does not depend on the order the rows were computed in.
"""
from __future__ import annotations

import numpy as np

from engine._config import njit
from engine.narrowphase.contacts import TOUCHING, mark_persisting

from . import split

__all__ = ["PART_BITS", "contact_record"]

#: bits of a part number in the keys that tell the parts of one compound apart (contact persistence)
PART_BITS = 20


@njit
def _order_by_two(first, second):
    """Indices sorting the rows by (first, second), ties kept in row order: a bottom-up merge sort of the
    indices (merging runs of width 1, 2, 4, ...), O(n log n)."""
    n = first.shape[0]
    order = np.arange(n)
    work = np.empty(n, np.int64)
    width = 1
    while width < n:
        for lo in range(0, n, 2 * width):
            mid, hi = min(lo + width, n), min(lo + 2 * width, n)
            a, b = lo, mid
            for out in range(lo, hi):
                take_b = a >= mid
                if a < mid and b < hi:
                    x, y = order[a], order[b]
                    take_b = first[y] < first[x] or (first[y] == first[x] and second[y] < second[x])
                if take_b:
                    work[out] = order[b]
                    b += 1
                else:
                    work[out] = order[a]
                    a += 1
        order, work = work, order
        width *= 2
    return order


@njit(inline="always")
def _touching_order(status, cand, origin, tested, part):
    """The touching rows (status TOUCHING) in the order of (i, j, part_a, part_b)."""
    rows = np.empty(status.shape[0], np.int64)
    k = 0
    for r in range(status.shape[0]):
        if status[r] == TOUCHING:
            rows[k] = r
            k += 1
    rows = rows[:k]
    span = np.int64(1)
    for p in range(cand.shape[0]):
        span = max(span, cand[p, 1] + 1)
    pair_key = np.empty(rows.shape[0], np.int64)
    part_key = np.empty(rows.shape[0], np.int64)
    for t in range(rows.shape[0]):
        r = rows[t]
        c = origin[r]
        pair_key[t] = cand[c, 0] * span + cand[c, 1]  # ids < span: (i, j) as one number, in the same order
        part_key[t] = part[tested[r, 0]] << PART_BITS | part[tested[r, 1]]
    return rows[_order_by_two(pair_key, part_key)]


@njit
def _start(rows, cand, origin, tested, part):
    """The touching rows in order (``_touching_order``), their point offsets (k + 1,) and the record's arrays,
    unwritten: pairs, separation, depth, normal, feature_a, feature_b, points, point_ids, persists, radius_a,
    radius_b, part_a, part_b and the rows' keys (k, 2)."""
    keep = _touching_order(rows.status, cand, origin, tested, part)
    k = keep.shape[0]
    offsets = np.zeros(k + 1, np.int64)
    for t in range(k):
        offsets[t + 1] = offsets[t] + rows.count[keep[t]]
    m = offsets[-1]
    out = (np.empty((k, 2), np.int64), np.empty(k), np.empty(k), np.empty((k, 3)), np.empty(k, np.int8),
           np.empty(k, np.int8), np.empty((m, 3)), np.empty(m, np.int64), np.zeros(m, np.bool_), np.empty(k),
           np.empty(k), np.empty(k, np.int64), np.empty(k, np.int64), np.empty((k, 2), np.int64))
    return keep, offsets, out


@njit
def _fill(rows, keep, offsets, cand, origin, tested, part, radius, prev_keys, prev_ids, out, first, last):
    """Rows first .. last − 1 of the record ``out`` (``_start``'s arrays): each row's fields, its points and ids,
    its key, and whether each point persists (``mark_persisting`` against the previous frame's keys and ids)."""
    pairs, separation, depth, normal, feature_a, feature_b, points, ids, persists, radius_a, radius_b, part_a, \
        part_b, keyed = out
    for t in range(first, last):
        r = keep[t]
        a, b = tested[r, 0], tested[r, 1]
        pairs[t, 0], pairs[t, 1] = cand[origin[r], 0], cand[origin[r], 1]
        s = rows.separation[r]
        separation[t] = s
        depth[t] = -s if (-s >= 0.0 or s != s) else 0.0  # max(−s, 0), a NaN kept (as numpy's maximum)
        for c in range(3):
            normal[t, c] = rows.normal[r, c]
        feature_a[t], feature_b[t] = rows.feature_a[r], rows.feature_b[r]
        radius_a[t], radius_b[t] = radius[a], radius[b]
        part_a[t], part_b[t] = part[a], part[b]
        keyed[t, 0] = pairs[t, 0] << PART_BITS | part_a[t]
        keyed[t, 1] = pairs[t, 1] << PART_BITS | part_b[t]
        for slot in range(offsets[t + 1] - offsets[t]):
            q = offsets[t] + slot
            for c in range(3):
                points[q, c] = rows.points[r, slot, c]
            ids[q] = rows.ids[r, slot]
    mark_persisting(prev_keys, prev_ids, keyed[first:last], offsets[first:last + 1], ids, persists)


@njit
def _next_previous(keyed, offsets, ids):
    """This record's points for the next frame's ``mark_persisting``: their keys (M, 2) and ids (M,), sorted by
    (first key, second key, id) — rows by their keys, then the at most 4 points of a row by id."""
    order = _order_by_two(keyed[:, 0].copy(), keyed[:, 1].copy())  # contiguous: one compiled sort
    owners = np.empty((ids.shape[0], 2), np.int64)
    sorted_ids = np.empty(ids.shape[0], np.int64)
    q = 0
    for t in order:
        first = q
        for s in range(offsets[t], offsets[t + 1]):
            v = ids[s]
            at = q
            while at > first and sorted_ids[at - 1] > v:  # insertion among the row's points
                sorted_ids[at] = sorted_ids[at - 1]
                at -= 1
            sorted_ids[at] = v
            owners[q, 0], owners[q, 1] = keyed[t, 0], keyed[t, 1]
            q += 1
    return owners, sorted_ids


def _fields(offsets, out, previous) -> tuple:
    pairs, separation, depth, normal, feature_a, feature_b, points, ids, persists, radius_a, radius_b, part_a, \
        part_b, _ = out
    return (pairs, separation, depth, normal, feature_a, feature_b, points, offsets, radius_a, radius_b, ids,
            persists, part_a, part_b, *previous)


@njit
def _record_one_thread(rows, cand, origin, tested, part, radius, prev_keys, prev_ids):
    keep, offsets, out = _start(rows, cand, origin, tested, part)
    _fill(rows, keep, offsets, cand, origin, tested, part, radius, prev_keys, prev_ids, out, 0, keep.shape[0])
    return offsets, out, _next_previous(out[-1], offsets, out[7])


def contact_record(rows, cand, origin, tested, part, radius, prev_keys, prev_ids, threads: int = 1) -> tuple:
    """The record of a frame (see the module docstring). ``rows``: the ContactRows of the tested pairs of store
    rows ``tested`` (m, 2), each from the candidate pair ``cand[origin[r]]`` of bodies (i < j); ``part``,
    ``radius``: the store's. Returns (pairs, separation, depth, normal, feature_a, feature_b, points, offsets,
    radius_a, radius_b, point_ids, persists, part_a, part_b, keys, ids): the record's arrays, then its points'
    keys and ids for the next frame. ``threads``: the rows are filled in contiguous ranges on that many threads
    when there are enough of them (``split.MIN_RECORD_ROWS_PER_THREAD`` each); the order and the keys of the
    next frame are one thread's work."""
    spans = split.ranges(int(np.count_nonzero(rows.status == TOUCHING)), threads, split.MIN_RECORD_ROWS_PER_THREAD)
    if len(spans) == 1:
        return _fields(*_record_one_thread(rows, cand, origin, tested, part, radius, prev_keys, prev_ids))
    keep, offsets, out = _start(rows, cand, origin, tested, part)
    split.run_ranges(lambda first, last: _fill(rows, keep, offsets, cand, origin, tested, part, radius,
                                               prev_keys, prev_ids, out, first, last), spans)
    return _fields(offsets, out, _next_previous(out[-1], offsets, out[7]))
