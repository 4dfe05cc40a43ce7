"""Sweep-and-prune (SAP): the chapter's 1-D sweep on intervals, its 3-D box form, and an incremental variant.

Chapter slides "Phase Large : Sweep and Prune (SAP)" ("Algorithmes de balayage et de tri"):

- one list of all b_i and e_i sorted from the smallest value to the largest;
- the list is swept in increasing order keeping a list of *active* intervals, initially empty;
- meeting b_i, interval i enters the list; meeting e_i, it leaves;
- two intervals that are in the active list together overlap.

Closed intervals: touching counts, so at a tied value every b is met before any e.

In 2-D and 3-D each box has one interval per axis. :func:`sap_pairs` sorts the boxes once on one axis (by
default the axis along which the box centres spread most, Ericson *Real-Time Collision Detection* 7.5.2), sweeps
that axis and tests the other axes of each candidate ("box pruning": the active list of the slide is the run of
boxes whose b lies between b_i and e_i, read straight from the sorted arrays). :class:`IncrementalSAP` keeps the
sorted order between frames and repairs it by insertion sort (temporal coherence: objects move little, so the
list is nearly sorted and the repair is close to linear).
"""
from __future__ import annotations

from collections import namedtuple
from collections.abc import Sequence
from typing import Literal, overload

import numpy as np
from numpy.typing import ArrayLike

import engine.broadphase.pairs as pair_buffer
from engine._config import njit
from engine._validate import as_float_array
from engine.broadphase.counting_sort import bucket_offsets, cell_of, radix_sort_pairs
from engine.broadphase.incremental import IncrementalBroadPhase
from engine.broadphase.pairs import as_boxes, as_boxes_3d, as_one_box, as_threads, empty_pairs, with_tests
from engine.broadphase.thread_pool import run_parts

__all__ = ["sweep_intervals", "sap_pairs", "sap_example_trace", "IncrementalSAP", "SLIDE_EXAMPLE"]

#: the slide's worked example: interval i (numbered from 1 on the slide) is [b_i, e_i]
SLIDE_EXAMPLE = {
    1: (3.0, 7.0),
    2: (7.7, 18.0),
    3: (1.0, 8.0),
    4: (8.9, 11.2),
    5: (7.5, 11.0),
    6: (2.0, 6.0),
}


# ---------------------------------------------------------------------------------------------------------
# 1-D: the slide's algorithm, literally
# ---------------------------------------------------------------------------------------------------------
@njit
def _sorted_events(begin, end):
    """The slide's list of all b_i and e_i, sorted; at equal values every b comes before every e.

    Returns (interval, is_end) of the 2n events in sweep order.
    """
    n = begin.shape[0]
    values = np.empty(2 * n)
    values[:n] = begin
    values[n:] = end
    order = np.argsort(values, kind="mergesort")  # stable: the b's (first half) win ties
    interval = np.empty(2 * n, dtype=np.int64)
    is_end = np.empty(2 * n, dtype=np.bool_)
    for t in range(2 * n):
        e = order[t]
        interval[t] = e if e < n else e - n
        is_end[t] = e >= n
    return interval, is_end


@njit
def _sweep_intervals_kernel(begin, end):
    # Chapter, "Algorithmes de balayage et de tri": sweep the sorted list of b_i, e_i keeping the active list;
    # at b_i, i overlaps every active interval, then enters; at e_i, i leaves (swap-remove, O(1)).
    n = begin.shape[0]
    interval, is_end = _sorted_events(begin, end)
    active = np.empty(n, dtype=np.int64)
    slot = np.empty(n, dtype=np.int64)
    n_active = 0
    out = pair_buffer.new_pair_buffer(n)
    count = 0
    for t in range(2 * n):
        i = interval[t]
        if not is_end[t]:
            for a in range(n_active):
                out, count = pair_buffer.push_pair(out, count, active[a], i)
            active[n_active] = i
            slot[i] = n_active
            n_active += 1
        else:
            s = slot[i]
            n_active -= 1
            last = active[n_active]
            active[s] = last
            slot[last] = s
    return pair_buffer.canonicalise_pairs(out, count, n)


def _as_intervals(begin: ArrayLike | None, end: ArrayLike | None) -> tuple[np.ndarray, np.ndarray]:
    b = as_float_array(begin, "begin", ndim=1)
    e = as_float_array(end, "end", ndim=1)
    if b.shape != e.shape:
        raise ValueError(f"begin and end must have the same shape, got {b.shape} and {e.shape}")
    inverted = np.flatnonzero(b > e)
    if inverted.size:
        i = int(inverted[0])
        raise ValueError(f"begin must not exceed end: begin[{i}] = {float(b[i])!r} > end[{i}] = {float(e[i])!r}")
    return b, e


def sweep_intervals(begin: ArrayLike, end: ArrayLike) -> np.ndarray:
    """The chapter's 1-D sweep-and-prune: all pairs (i, j) whose closed intervals [b_i, e_i], [b_j, e_j] meet.

    The slide's algorithm, literally: the 2n ends sorted (at a tied value every b before any e, so touching
    intervals meet), swept while keeping the list of active intervals.

    Parameters
    ----------
    begin, end : array_like, shape (n,)
        The intervals' ends b_i and e_i, ``begin <= end``, finite.

    Returns
    -------
    numpy.ndarray, shape (k, 2), int64
        Canonical pairs of 0-based indices: ``i < j`` in every row, rows sorted, no duplicate.

    Raises
    ------
    ValueError
        When ``begin`` or ``end`` is not 1-D, holds NaN or ±inf, when their shapes differ, or when
        ``begin[i] > end[i]`` (the message names the first such i).
    TypeError
        When ``begin`` or ``end`` is not a real numeric array.

    See Also
    --------
    sap_example_trace : the same sweep, step by step, as text.

    Examples
    --------
    The first three intervals of the slide's example, [3, 7], [7.7, 18] and [1, 8]:

    >>> from engine.broadphase import sweep_intervals
    >>> sweep_intervals([3, 7.7, 1], [7, 18, 8])
    array([[0, 2],
           [1, 2]])
    """
    b, e = _as_intervals(begin, end)
    if b.shape[0] < 2:
        return empty_pairs()
    return _sweep_intervals_kernel(b, e)


def sap_example_trace(begin: ArrayLike | None = None, end: ArrayLike | None = None,
                      labels: Sequence[object] | None = None) -> str:
    """The step-by-step 1-D sweep (event, active list, pairs reported) as text, by default on the slide's example.

    The events and pairs are those of :func:`sweep_intervals`; ``colldet sap-example`` prints this table.

    Parameters
    ----------
    begin, end : array_like, shape (n,), optional
        The intervals, ``begin <= end``. Default: the slide's six intervals (``SLIDE_EXAMPLE``), labelled 1..6
        as on the slide.
    labels : sequence of n objects, optional
        The names of the intervals in the text (default 1..n).

    Returns
    -------
    str
        One line per event, then the list of overlapping pairs.

    Raises
    ------
    ValueError
        For invalid intervals (as :func:`sweep_intervals`), or when ``labels`` does not have n entries.
    """
    if begin is None and end is None:
        keys = sorted(SLIDE_EXAMPLE)
        begin = [SLIDE_EXAMPLE[k][0] for k in keys]
        end = [SLIDE_EXAMPLE[k][1] for k in keys]
        labels = keys if labels is None else labels
    b, e = _as_intervals(begin, end)
    n = b.shape[0]
    labels = list(range(1, n + 1)) if labels is None else list(labels)
    if len(labels) != n:
        raise ValueError(f"labels must have {n} entries, got {len(labels)}")
    interval, is_end = _sorted_events(b, e)
    lines = ["Sweep-and-prune (1-D): events sorted, b before e at equal values", ""]
    header = f"{'event':<14}{'active list':<28}pairs reported"
    lines += [header, "-" * len(header)]
    active: list[int] = []
    reported = []
    for i, ending in zip(interval.tolist(), is_end.tolist()):
        value = e[i] if ending else b[i]
        event = f"{'e' if ending else 'b'}{labels[i]}={value:g}"
        new = []
        if ending:
            active.remove(i)
        else:
            new = [(labels[a], labels[i]) for a in active]
            active.append(i)
        reported += new
        act = "{" + ", ".join(str(labels[a]) for a in active) + "}"
        lines.append(f"{event:<14}{act:<28}" + (", ".join(f"({p}, {q})" for p, q in new) or "-"))
    ordered = sorted((min(p, q), max(p, q)) for p, q in reported)
    lines += ["", f"{len(reported)} overlapping pairs: " + ", ".join(f"({p}, {q})" for p, q in ordered)]
    return "\n".join(lines)


# ---------------------------------------------------------------------------------------------------------
# 3-D: sort on one axis, sweep it, prune on the others
# ---------------------------------------------------------------------------------------------------------
#: below this many boxes the columns are always a table (small scenes: at most m/8 columns, one below 32 boxes)
SPARSE_MIN_BOXES = 256
#: the coarse grid of columns over the two axes a1, a2 other than the sweep axis: for each, the origin (o1, o2),
#: 1 / the column size (inv1, inv2; 0.0 for a single column) and the number of columns (k1, k2)
ColumnGrid = namedtuple("ColumnGrid", ["o1", "inv1", "k1", "o2", "inv2", "k2"])

#: the fields of a box record (one row of 8 float64, one cache line), the boxes' bounds gathered once in sweep
#: order (Terdiman's sorted min/max arrays, one row per box since the sweep reads every bound of each candidate):
#: b, e on the sweep axis, on a1, on a2, then the tag 4 · box + home flags, an int64 kept in the row's bits (read
#: through an int64 view of the same memory), and a spare slot
B0, E0, B1, E1, B2, E2, TAG = range(7)
ENTRY_WIDTH = 8


@njit
def sorted_records(order, lo, hi, axis, rec):
    """Gather the boxes (n, 3) ``order`` (sweep order) into the box records ``rec`` ((m, ENTRY_WIDTH) float64,
    row p = box order[p], home flags 0): the one pass that reads lo and hi out of order; every later pass reads
    the records in sequence."""
    a1 = (axis + 1) % 3
    a2 = (axis + 2) % 3
    bits = rec.reshape(rec.size).view(np.int64)
    for p in range(order.shape[0]):
        o = order[p]
        rec[p, B0] = lo[o, axis]
        rec[p, E0] = hi[o, axis]
        rec[p, B1] = lo[o, a1]
        rec[p, E1] = hi[o, a1]
        rec[p, B2] = lo[o, a2]
        rec[p, E2] = hi[o, a2]
        bits[p * ENTRY_WIDTH + TAG] = 4 * o
        bits[p * ENTRY_WIDTH + TAG + 1] = 0


@njit
def _box_bounds(box):
    """(smallest b, largest e, sum of the extents e − b) of the box records ``box`` along the sweep axis, a1 and a2,
    (3,) each, in one pass."""
    origin = np.full(3, np.inf)
    top = np.full(3, -np.inf)
    extent = np.zeros(3)
    for p in range(box.shape[0]):
        for a in range(3):
            b = box[p, 2 * a]
            e = box[p, 2 * a + 1]
            origin[a] = min(origin[a], b)
            top[a] = max(top[a], e)
            extent[a] += e - b
    return origin, top, extent


@njit
def _column_count(span, extent_sum, m, kmax):
    """Columns along one axis: about span / (2 × the mean box extent), within [1, kmax]; a span so small that
    span / kmax underflows to 0 (denormal coordinates) keeps one column."""
    size = max(2.0 * extent_sum / m, span / kmax)
    if span > 0.0 and size > 0.0:
        return int(min(kmax, max(1.0, span / size)))
    return 1


@njit
def _choose_columns(box, bounds, ranges):
    """The column grid (Terdiman's multi box pruning): columns about twice the mean box size, halved on both
    axes until a box enters 4 columns on average. ``box``: the box records in sweep order; ``ranges`` (4, m)
    int64 receives the first and last column of each box on a1 and a2; returns (grid, number of (box, column)
    entries, sparse).

    At most ~m/8 columns are stored as a table (dense); when the boxes would need more than 4 times the
    ~sqrt(m/8) of that table along an axis (far-apart clusters: fewer columns would put a cluster in one
    column), the columns keep their size, up to 2^30 per axis, and only the occupied ones are stored (sparse:
    sorted 64-bit column keys), from SPARSE_MIN_BOXES boxes on. ``bounds``: the records' ``_box_bounds``.
    """
    m = box.shape[0]
    origin, top, extent = bounds
    o1, t1, ext1 = origin[1], top[1], extent[1]
    o2, t2, ext2 = origin[2], top[2], extent[2]
    span1 = t1 - o1
    span2 = t2 - o2
    kmax = max(1, int(np.sqrt(m / 8.0)))
    k1 = _column_count(span1, ext1, m, 1 << 30)
    k2 = _column_count(span2, ext2, m, 1 << 30)
    sparse = m >= SPARSE_MIN_BOXES and (k1 > 4 * kmax or k2 > 4 * kmax)
    if not sparse:
        k1 = min(k1, kmax)
        k2 = min(k2, kmax)
    while True:  # (one column: inv = 0, every box in column 0, no 0·inf)
        grid = ColumnGrid(o1, k1 / span1 if k1 > 1 else 0.0, k1, o2, k2 / span2 if k2 > 1 else 0.0, k2)
        entries = 0
        for p in range(m):
            ranges[0, p] = cell_of(box[p, B1], grid.o1, grid.inv1, k1)
            ranges[1, p] = cell_of(box[p, E1], grid.o1, grid.inv1, k1)
            ranges[2, p] = cell_of(box[p, B2], grid.o2, grid.inv2, k2)
            ranges[3, p] = cell_of(box[p, E2], grid.o2, grid.inv2, k2)
            entries += (ranges[1, p] - ranges[0, p] + 1) * (ranges[3, p] - ranges[2, p] + 1)
        if entries <= 4 * m or (k1 == 1 and k2 == 1):
            return grid, entries, sparse
        k1 = max(1, k1 // 2)
        k2 = max(1, k2 // 2)


#: the sort keys: b on the sweep axis mapped to integers 0 .. 2^31 − 1 (monotone, Terdiman's integer-mapped keys)
KEY_STEPS = 1 << 31

#: the sweep axis' integer key map: key(v) = cell_of(v, origin, scale, KEY_STEPS) (monotone in v)
SweepKeys = namedtuple("SweepKeys", ["origin", "scale"])


@njit
def sweep_keys(origin, top):
    """The SweepKeys of boxes whose range along the sweep axis is [origin, top]: that range mapped onto
    0 .. KEY_STEPS − 1 (key(origin) = 0, key(top) = KEY_STEPS − 1, linear in between to within a key step), so
    that the radix sort does the sorting and the runs of equal keys stay short."""
    span = top - origin
    return SweepKeys(origin, KEY_STEPS / span if span > 0.0 else 0.0)


@njit(inline="always")
def _write_entry(rec_bits, t, w0, w1, w2, w3, w4, w5, tag, home):
    """Entry record t: a box record (its words w0 .. w5 and tag, as int64 bits: copied bit for bit) in a
    column; ``home`` bit 0 (bit 1): the column is the box's first along a1 (a2)."""
    r = t * ENTRY_WIDTH
    rec_bits[r + B0] = w0
    rec_bits[r + E0] = w1
    rec_bits[r + B1] = w2
    rec_bits[r + E1] = w3
    rec_bits[r + B2] = w4
    rec_bits[r + E2] = w5
    rec_bits[r + TAG] = tag + home
    rec_bits[r + TAG + 1] = 0


@njit
def _column_counts(ranges, k2, first, last, counts):
    """counts[c] += the number of boxes first .. last − 1 entering column c = c1 · k2 + c2 (``ranges``: each
    box's first and last column on a1 and a2, as ``_choose_columns`` fills them)."""
    for p in range(first, last):
        for c1 in range(ranges[0, p], ranges[1, p] + 1):
            for c2 in range(ranges[2, p], ranges[3, p] + 1):
                counts[c1 * k2 + c2] += 1


@njit
def _scatter_columns(box, ranges, k2, first, last, fill, rec):
    """Write the entry records of the boxes first .. last − 1 into their columns: the entry of a box in column c
    at slot fill[c] (advanced), one record per entry, a cache line, so the scatter writes one line per entry
    and the sweep reads one per candidate."""
    box_bits = box.reshape(box.size).view(np.int64)
    rec_bits = rec.reshape(rec.size).view(np.int64)
    for p in range(first, last):
        r = p * ENTRY_WIDTH  # the record read once, then written to each of the box's columns
        w0, w1, w2, w3, w4, w5 = box_bits[r], box_bits[r + 1], box_bits[r + 2], box_bits[r + 3], box_bits[r + 4], \
            box_bits[r + 5]
        tag = box_bits[r + TAG]
        first1, last1, first2, last2 = ranges[0, p], ranges[1, p], ranges[2, p], ranges[3, p]  # (held in registers:
        for c1 in range(first1, last1 + 1):  # the int64 stores below could alias ranges for the compiler)
            for c2 in range(first2, last2 + 1):
                c = c1 * k2 + c2
                t = fill[c]
                fill[c] = t + 1
                _write_entry(rec_bits, t, w0, w1, w2, w3, w4, w5, tag, (c1 == first1) + 2 * (c2 == first2))


def _fill_columns(box: np.ndarray, grid: ColumnGrid, ranges: np.ndarray, rec: np.ndarray, threads: int
                  ) -> np.ndarray:
    """Counting sort of the (box, column) entries by column, keeping the sweep order inside each column (Ericson
    7.1.6), shared by ``threads`` threads: each counts the entries of its chunk of boxes per column, and
    ``counting_sort.bucket_offsets`` gives each chunk its slots (after the earlier chunks' entries of the column),
    so the records are those of one thread.

    Writes the entry records ``rec`` ((entries + columns, ENTRY_WIDTH) float64) and returns start: column c
    holds entries start[c] .. start[c + 1] − 2 and a sentinel at start[c + 1] − 1 (b = +inf: it ends every
    sweep of the column without a bounds check).
    """
    n_cells = grid.k1 * grid.k2
    chunks = pair_buffer.split_work(box.shape[0], threads, MIN_ENTRIES_PER_THREAD)
    counts = np.zeros((len(chunks), n_cells), dtype=np.int64)
    run_parts(lambda t: _column_counts(ranges, grid.k2, *chunks[t], counts[t]), range(len(chunks)))
    fill, column_start = bucket_offsets(counts)
    sentinels_before = np.arange(n_cells + 1)  # one sentinel closes each column
    fill += sentinels_before[:n_cells]
    run_parts(lambda t: _scatter_columns(box, ranges, grid.k2, *chunks[t], fill[t], rec), range(len(chunks)))
    start = column_start + sentinels_before
    rec[start[1:] - 1, B0] = np.inf
    return start


@njit
def _fill_columns_sparse(box, grid, ranges, entries, rec):
    """``_fill_columns`` storing only the occupied columns: the entries' column keys c1 · k2 + c2 radix-sorted
    (stable, so the sweep order is kept inside each column). Fills rec ((2 · entries, ENTRY_WIDTH)) and returns
    start, occupied column i holding entries start[i] .. start[i + 1] − 2 and its sentinel."""
    column_of = np.empty(entries, dtype=np.int64)
    source = np.empty(entries, dtype=np.int64)
    t = 0
    for p in range(box.shape[0]):
        for c1 in range(ranges[0, p], ranges[1, p] + 1):
            for c2 in range(ranges[2, p], ranges[3, p] + 1):
                column_of[t] = c1 * grid.k2 + c2
                source[t] = p
                t += 1
    column_of, source = radix_sort_pairs(column_of, source, np.empty(entries, dtype=np.int64),
                                         np.empty(entries, dtype=np.int64), entries)
    start = np.empty(entries + 1, dtype=np.int64)
    box_bits = box.reshape(box.size).view(np.int64)
    rec_bits = rec.reshape(rec.size).view(np.int64)
    columns = 0
    for t in range(entries):
        if t == 0 or column_of[t] != column_of[t - 1]:
            if columns > 0:
                rec[t + columns - 1, B0] = np.inf  # the sentinel ending the previous column
            start[columns] = t + columns
            columns += 1
        p = source[t]
        c1 = column_of[t] // grid.k2
        c2 = column_of[t] - c1 * grid.k2
        r = p * ENTRY_WIDTH
        _write_entry(rec_bits, t + columns - 1, box_bits[r], box_bits[r + 1], box_bits[r + 2], box_bits[r + 3],
                     box_bits[r + 4], box_bits[r + 5], box_bits[r + TAG],
                     (c1 == ranges[0, p]) + 2 * (c2 == ranges[2, p]))
    rec[entries + columns - 1, B0] = np.inf
    start[columns] = entries + columns
    return start[: columns + 1].copy()


@njit
def _sweep_columns(start, rec, first, last, out, shift):
    # Chapter SAP slide, box-pruning form: in each column, for entry p the entries q after it with b_q <= e_p
    # are exactly those in the active list when p enters (the entries are sorted by b exactly, so every such q
    # overlaps p on the sweep axis: b_p <= b_q <= e_p, no test needed on that axis); test the two other axes,
    # and report the pair only in the column holding the lower corner (max b^1, max b^2) of the two boxes, so
    # exactly once: as the column map is monotone, that column is the first column of p or of q along a1, and
    # along a2 (the home flags). The column's sentinel (b = +inf) stops the run without a bounds check.
    # Columns first .. last − 1; each pair is recorded as its key min · 2^shift + max in out (the two-try record
    # of engine.broadphase.pairs); returns (count, tests), count > len(out) when out was too small, tests = the
    # pairs of entries that overlap on the sweep axis.
    # The records are read through flat views at offsets q · ENTRY_WIDTH + field (a constant stride: no
    # multiplication by a run-time row stride per candidate), the tags through an int64 view (no conversion).
    flat = rec.reshape(rec.size)
    bits = flat.view(np.int64)
    count = 0
    tests = 0
    capacity = out.shape[0]
    for cell in range(first, last):
        for p in range(start[cell], start[cell + 1] - 1):
            rp = p * ENTRY_WIDTH
            end0 = flat[rp + E0]
            lo1 = flat[rp + B1]
            hi1 = flat[rp + E1]
            lo2 = flat[rp + B2]
            hi2 = flat[rp + E2]
            tag_p = bits[rp + TAG]
            box_p = tag_p >> 2
            rq = rp + ENTRY_WIDTH
            while flat[rq + B0] <= end0:
                tag_q = bits[rq + TAG]
                box_q = tag_q >> 2
                keep = ((flat[rq + B1] <= hi1) & (lo1 <= flat[rq + E1]) & (flat[rq + B2] <= hi2)
                        & (lo2 <= flat[rq + E2]) & (((tag_p | tag_q) & 3) == 3))
                if count < capacity:
                    out[count] = (min(box_p, box_q) << shift) | max(box_p, box_q)
                count += np.int64(keep)
                rq += ENTRY_WIDTH
            tests += (rq - rp) // ENTRY_WIDTH - 1
    return count, tests


@njit
def _sort_runs_exactly(order, key_b, lo, axis):
    """Make ``order`` (boxes sorted by their integer keys ``key_b``, ties by index) sorted by lo[:, axis] exactly:
    the key map is monotone but not one to one (values less than a key step apart share a key), so only a run
    of equal keys can be out of order; such a run is sorted by its values (stable: ties stay by index)."""
    n = order.shape[0]
    t = 1
    while t < n:
        if key_b[t] == key_b[t - 1] and lo[order[t], axis] < lo[order[t - 1], axis]:
            first = t - 1
            while first > 0 and key_b[first - 1] == key_b[t]:
                first -= 1
            last = t + 1
            while last < n and key_b[last] == key_b[t]:
                last += 1
            run = order[first:last].copy()
            values = np.empty(last - first)
            for u in range(last - first):
                values[u] = lo[run[u], axis]
            order[first:last] = run[np.argsort(values, kind="mergesort")]
            t = last
        else:
            t += 1


@njit
def sweep_order(lo, hi, axis):
    """The boxes (n, 3) sorted by lo[:, axis] (ties by index): int64 (n,). One radix sort of their 31-bit
    integer keys (Terdiman's integer-mapped keys) instead of a comparison sort of floats, then the runs of
    equal keys put in the exact order of their values (``_sort_runs_exactly``)."""
    n = lo.shape[0]
    everyone = np.arange(n)
    origin = np.inf
    top = -np.inf
    for i in range(n):
        origin = min(origin, lo[i, axis])
        top = max(top, hi[i, axis])
    keys = sweep_keys(origin, top)
    key_b = np.empty(n, dtype=np.int64)
    for i in range(n):
        key_b[i] = cell_of(lo[i, axis], keys.origin, keys.scale, KEY_STEPS)
    key_b, order = radix_sort_pairs(key_b, everyone, np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64), n)
    order = order.copy()
    _sort_runs_exactly(order, key_b, lo, axis)
    return order


#: a thread sweeps at least this many (box, column) entries
MIN_ENTRIES_PER_THREAD = 4096


def _column_entries(order: np.ndarray, lo: np.ndarray, hi: np.ndarray, axis: int, threads: int = 1,
                    ) -> tuple[np.ndarray, np.ndarray]:
    """The swept columns of the boxes in sweep order: (start, entry records), the records gathered and the dense
    columns filled by ``threads`` threads; the records live in this thread's work arrays (reused by the next sweep
    on this thread)."""
    m = order.shape[0]
    box = pair_buffer.work_array("sap_boxes", m * ENTRY_WIDTH, np.float64)[: m * ENTRY_WIDTH]
    box = box.reshape(m, ENTRY_WIDTH)
    chunks = pair_buffer.split_work(m, threads, MIN_ENTRIES_PER_THREAD)  # the gather, by chunks of the order
    run_parts(lambda chunk: sorted_records(order[chunk[0]:chunk[1]], lo, hi, axis, box[chunk[0]:chunk[1]]), chunks)
    ranges = pair_buffer.work_array("sap_ranges", 4 * m, np.int64)[: 4 * m].reshape(4, m)
    grid, entries, sparse = _choose_columns(box, _box_bounds(box), ranges)
    slots = 2 * entries if sparse else entries + grid.k1 * grid.k2
    rec = pair_buffer.work_array("sap_entries", slots * ENTRY_WIDTH, np.float64)[: slots * ENTRY_WIDTH]
    rec = rec.reshape(slots, ENTRY_WIDTH)
    if sparse:
        return _fill_columns_sparse(box, grid, ranges, entries, rec), rec
    return _fill_columns(box, grid, ranges, rec, threads), rec


def _sweep_sorted(order: np.ndarray, lo: np.ndarray, hi: np.ndarray, axis: int, n_objects: int,
                  threads: int = 1) -> tuple[np.ndarray, int]:
    """Sweep-and-prune of the boxes (n, 3) lo, hi in the order ``order`` of lo[:, axis] (exactly sorted) along
    ``axis``: (canonical pairs, tests); ``threads`` > 1 sweeps disjoint ranges of columns on that many
    threads."""
    start, rec = _column_entries(order, lo, hi, axis, threads)
    ranges = pair_buffer.split_work(start, threads, MIN_ENTRIES_PER_THREAD)
    shift = int(pair_buffer.pair_key_shift(n_objects))

    # each range records into a key buffer of its own, held by this (the calling) thread between calls: a range
    # run by a pool thread cannot use that thread's work arrays (it may run two ranges, one after the other)
    names = {r: f"sap_pair_keys_{t}" for t, r in enumerate(ranges)}
    buffers = {r: pair_buffer.work_array(names[r], start[r[1]] - start[r[0]], np.int64) for r in ranges}

    def sweep(first, last):
        out = buffers[first, last]
        count, tests = _sweep_columns(start, rec, first, last, out, shift)
        if count > out.shape[0]:  # too many pairs for the buffer: again, with room for all of them
            out = buffers[first, last] = np.empty(count + count // 4, dtype=np.int64)
            count, tests = _sweep_columns(start, rec, first, last, out, shift)
        return out, count, tests

    result = pair_buffer.run_split(sweep, ranges, n_objects, canonicalise=pair_buffer.canonicalise_key_buffer)
    for r, buf in buffers.items():  # the grown buffers serve the next call
        pair_buffer.keep_work_array(names[r], buf)
    return result


def _widest_axis(lo: np.ndarray, hi: np.ndarray) -> int:
    """The axis along which the box centres spread most (largest variance, Ericson 7.5.2)."""
    if lo.shape[0] == 0:
        return 0
    return int(np.argmax(_centre_variance(lo, hi)))


@njit
def _centre_variance(lo, hi):
    """Variance of the box centres along each axis, (3,)."""
    n = lo.shape[0]
    mean = np.zeros(3)
    for i in range(n):
        for k in range(3):
            mean[k] += 0.5 * lo[i, k] + 0.5 * hi[i, k]
    mean /= n
    var = np.zeros(3)
    for i in range(n):
        for k in range(3):
            dev = 0.5 * lo[i, k] + 0.5 * hi[i, k] - mean[k]
            var[k] += dev * dev
    return var


@overload
def sap_pairs(lo: ArrayLike, hi: ArrayLike, axis: int | None = ..., *, return_tests: Literal[False] = ...,
              threads: int = ...) -> np.ndarray: ...
@overload
def sap_pairs(lo: ArrayLike, hi: ArrayLike, axis: int | None = ..., *, return_tests: Literal[True],
              threads: int = ...) -> tuple[np.ndarray, int]: ...
def sap_pairs(lo: ArrayLike, hi: ArrayLike, axis: int | None = None, *, return_tests: bool = False,
              threads: int = 1) -> np.ndarray | tuple[np.ndarray, int]:
    """All pairs of overlapping closed boxes by sweep-and-prune: ``find_pairs(method="sap")``.

    The boxes are sorted once on the sweep axis and swept per column of a coarse grid over the two other axes
    (box pruning, see the module's description); the threads share the sweep. ``lo``, ``hi``, ``return_tests``,
    ``threads`` and the result are those of every box method (:ref:`broadphase-boxes`,
    :ref:`broadphase-options`).

    Parameters
    ----------
    axis : int, optional
        The sweep axis, in [0, d). Default: the axis along which the box centres spread most (largest variance).

    Returns
    -------
    pairs : numpy.ndarray, shape (k, 2), int64
        :ref:`broadphase-pairs`; ``(pairs, tests)`` with ``return_tests=True``, ``tests`` counting the box tests
        made: the pairs of entries of a column whose intervals overlap on the sweep axis.

    Raises
    ------
    ValueError
        When ``axis`` is outside [0, d) (and for invalid boxes or ``threads``, as every box method).
    TypeError
        When ``axis`` is not an int (and for non-numeric boxes).
    """
    threads = as_threads(threads)
    lo3, hi3 = as_boxes_3d(lo, hi)
    d = np.shape(lo)[1]
    if axis is not None:
        if isinstance(axis, bool) or not isinstance(axis, int | np.integer):
            raise TypeError(f"axis must be an int, got {type(axis).__name__}")
        if not 0 <= axis < d:
            raise ValueError(f"axis must be in [0, {d}), got {axis}")
    n = lo3.shape[0]
    if n < 2:
        return with_tests(empty_pairs(), 0, return_tests)
    axis = _widest_axis(lo3, hi3) if axis is None else int(axis)
    pairs, tests = _sweep_sorted(sweep_order(lo3, hi3, axis), lo3, hi3, axis, n, threads)
    return with_tests(pairs, tests, return_tests)


# ---------------------------------------------------------------------------------------------------------
# incremental SAP: keep the order between frames, repair it by insertion sort
# ---------------------------------------------------------------------------------------------------------
@njit
def _insertion_sort_order(order, lo, axis):
    """Insertion sort of ``order`` by lo[order, axis], in place; returns the number of swaps (0 if sorted).

    Temporal coherence (Ericson 7.5.2, Baraff's incremental SAP): between frames the list is nearly sorted,
    so this costs O(n + swaps).
    """
    swaps = 0
    for p in range(1, order.shape[0]):
        o = order[p]
        v = lo[o, axis]
        q = p - 1
        while q >= 0 and lo[order[q], axis] > v:
            order[q + 1] = order[q]
            q -= 1
            swaps += 1
        order[q + 1] = o
    return swaps


class IncrementalSAP(IncrementalBroadPhase):
    """Sweep-and-prune that keeps its sorted order between frames (temporal coherence).

    Build it from arrays and update all boxes each frame::

        sap = IncrementalSAP(lo, hi)          # (n, d) boxes get ids 0..n-1
        pairs = sap.update(lo_next, hi_next)  # new boxes of every live object (ids ascending) -> pairs

    or manage objects one by one: ``add(lo_i, hi_i) -> id``, ``move(id, lo_i, hi_i)``, ``remove(id)``,
    ``pairs()``. Pairs are canonical pairs of ids, exactly the overlapping closed boxes (the same as
    :func:`find_pairs` on the live boxes). Freed ids are reused. Each query repairs the order by insertion sort,
    O(n + swaps): close to linear when the objects moved little.

    Parameters
    ----------
    lo, hi : array_like, shape (n, d), optional
        The initial boxes, d = 1, 2 or 3, ``lo <= hi``; they get the ids 0..n−1. Omit both to start empty.
    dim : int, optional
        The dimension d (1, 2 or 3); required when no boxes are given, else it must match their d.
    axis : int, optional
        The sweep axis, in [0, d). Default: the axis along which the initial box centres spread most (0 when
        empty).

    Attributes
    ----------
    axis : int
        The sweep axis.
    last_swaps : int
        The number of insertion-sort swaps of the last repair (0 when the order was already sorted).

    Raises
    ------
    ValueError
        For invalid boxes (as :func:`find_pairs`), a missing or wrong ``dim``, or ``axis`` outside [0, d).
    TypeError
        For non-numeric boxes.

    Examples
    --------
    >>> import numpy as np
    >>> from engine.broadphase import IncrementalSAP
    >>> sap = IncrementalSAP(np.array([[0.0], [2.0]]), np.array([[1.0], [3.0]]))
    >>> sap.pairs()
    array([], shape=(0, 2), dtype=int64)
    >>> sap.move(1, [1.0], [2.0])  # object 1 now touches object 0
    >>> sap.pairs()
    array([[0, 1]])
    >>> sap.add([0.5], [0.6])
    2
    >>> sap.pairs()
    array([[0, 1],
           [0, 2]])
    """

    def __init__(self, lo: ArrayLike | None = None, hi: ArrayLike | None = None, *, dim: int | None = None,
                 axis: int | None = None):
        if lo is None and hi is None:
            if dim is None:
                raise ValueError("give the initial boxes lo, hi, or the dimension dim of an empty SAP")
            if isinstance(dim, bool) or not isinstance(dim, int | np.integer) or dim not in (1, 2, 3):
                raise ValueError(f"dim must be 1, 2 or 3, got {dim!r}")
            lo_d = np.zeros((0, int(dim)))
            hi_d = lo_d
        else:
            lo_d, hi_d = as_boxes(lo, hi)
            if dim is not None and dim != lo_d.shape[1]:
                raise ValueError(f"dim = {dim} does not match lo of shape {lo_d.shape}")
        self._d = lo_d.shape[1]
        n = lo_d.shape[0]
        capacity = max(16, n)
        self._lo = np.zeros((capacity, 3))
        self._hi = np.zeros((capacity, 3))
        self._lo[:n, : self._d] = lo_d
        self._hi[:n, : self._d] = hi_d
        self._alive = np.zeros(capacity, dtype=bool)
        self._alive[:n] = True
        self._size = n  # ids in use are < _size
        self._free: list[int] = []
        if axis is None:
            axis = _widest_axis(self._lo[:n], self._hi[:n]) if n else 0
        else:
            if isinstance(axis, bool) or not isinstance(axis, int | np.integer) or not 0 <= axis < self._d:
                raise ValueError(f"axis must be an int in [0, {self._d}), got {axis!r}")
        self.axis = int(axis)
        self._order = np.argsort(self._lo[:n, self.axis], kind="stable").astype(np.int64)
        self.last_swaps = 0

    # -- bookkeeping (documented by IncrementalBroadPhase) ----------------------------------------------
    def __len__(self) -> int:
        return int(self._order.shape[0])

    def ids(self) -> np.ndarray:
        return np.flatnonzero(self._alive[: self._size]).astype(np.int64)

    def _is_live(self, obj_id: int) -> bool:
        return 0 <= obj_id < self._size and bool(self._alive[obj_id])

    # -- objects ----------------------------------------------------------------------------------------
    def add(self, lo_i: ArrayLike, hi_i: ArrayLike) -> int:
        """Insert the box ``lo_i, hi_i`` at its place in the sorted order; returns its id
        (:ref:`broadphase-incremental`)."""
        lo_i, hi_i = as_one_box(lo_i, hi_i, self._d)
        if self._free:
            obj_id = self._free.pop()
        else:
            obj_id = self._size
            if obj_id == self._lo.shape[0]:
                grow = 2 * obj_id
                self._lo = np.concatenate([self._lo, np.zeros((grow - obj_id, 3))])
                self._hi = np.concatenate([self._hi, np.zeros((grow - obj_id, 3))])
                self._alive = np.concatenate([self._alive, np.zeros(grow - obj_id, dtype=bool)])
            self._size += 1
        self._lo[obj_id] = 0.0
        self._hi[obj_id] = 0.0
        self._lo[obj_id, : self._d] = lo_i
        self._hi[obj_id, : self._d] = hi_i
        self._alive[obj_id] = True
        keys = self._lo[self._order, self.axis]
        at = int(np.searchsorted(keys, lo_i[self.axis] if self.axis < self._d else 0.0, side="right"))
        self._order = np.insert(self._order, at, obj_id)
        return obj_id

    def _remove_object(self, obj_id: int) -> None:
        self._alive[obj_id] = False
        self._order = self._order[self._order != obj_id]
        self._free.append(obj_id)

    def move(self, obj_id: int, lo_i: ArrayLike, hi_i: ArrayLike) -> None:
        """Give the live object ``obj_id`` the new box ``lo_i, hi_i`` (:ref:`broadphase-incremental`); the sorted
        order is repaired at the next query."""
        obj_id = self._check_id(obj_id)
        lo_i, hi_i = as_one_box(lo_i, hi_i, self._d)
        self._lo[obj_id, : self._d] = lo_i
        self._hi[obj_id, : self._d] = hi_i

    def _set_boxes(self, ids: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> None:
        self._lo[ids, : self._d] = lo
        self._hi[ids, : self._d] = hi

    def pairs(self, *, threads: int = 1) -> np.ndarray:
        # repair the sorted order by insertion sort, then sweep (the threads share the columns)
        threads = as_threads(threads)
        if self._order.shape[0] < 2:
            return empty_pairs()
        self.last_swaps = int(_insertion_sort_order(self._order, self._lo, self.axis))
        return _sweep_sorted(self._order, self._lo, self._hi, self.axis, self._size, threads)[0]
