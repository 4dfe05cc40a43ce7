"""Uniform grid: the chapter's *absolute* (uniform) spatial subdivision.

Chapter slides "Phase Large : Subdivision (découpage) spatiale" — space is cut into cells and only objects that
share a cell are compared ("deux objets éloignés l'un de l'autre ne peuvent vraisemblablement pas être en
collision"); the uniform cut is the "absolue" one. Ericson, *Real-Time Collision Detection* 7.1.

- Cell size: by default twice the mean largest side of the boxes, or the mean spacing (V/n)^(1/k) if larger (an
  empty or point-like scene gets one cell per object on average; ``default_cell_size``); the cells are stored
  densely, enlarged if needed so the grid has at most about 8·n cells.
- Far-apart clusters would then share coarse cells, one cluster per cell: the quadratic cliff. So when the
  spacing exceeds ``SPARSE_SPACING_RATIO`` × twice the mean largest side (boxes that fill a small part of their
  bounding volume), or when the cap on the cell count would enlarge the cells, only the occupied cells are
  stored (sorted 64-bit cell keys, up to 2^21 cells per axis) and the cells keep their size.
- A box is entered in every cell its box covers. A pair is reported only in the cell holding the lower corner
  (max lo_i, max lo_j) of the two boxes, which both cover — so exactly once, no duplicate.
- Boxes covering more than 64 cells (one huge box among tiny ones) are kept out of the grid and tested against
  every box, so the grid stays linear in size.
- Cells are numbered from the scene's lowest corner, so negative coordinates need nothing special; the cells are
  stored densely and filled by a counting sort on the cell number (count, then fill; two radix passes so the
  counters stay in cache).
"""
from __future__ import annotations

from typing import Literal, overload

import numpy as np
from numpy.typing import ArrayLike

import engine.broadphase.pairs as pair_buffer
from engine._config import njit
from engine._validate import as_positive
from engine.broadphase.counting_sort import cell_of, grid_dims, radix_sort_pairs, radix_split, sort_within_buckets
from engine.broadphase.pairs import as_boxes_3d, as_threads, boxes_overlap, empty_pairs, with_tests

__all__ = ["grid_pairs", "default_cell_size"]

_MAX_CELLS_PER_BOX = 64
#: with the default cell size, when the spacing term exceeds this many times 2 × the mean largest side (the
#: boxes fill a small part of their bounding volume: clusters far apart), the cells are 2 × the mean largest side
#: and only the occupied ones are stored
SPARSE_SPACING_RATIO = 8.0


@njit
def _cell_range(lo, hi, i, origin, inv, dims):
    """First and last cell along x, y, z of box i."""
    return (cell_of(lo[i, 0], origin[0], inv, dims[0]), cell_of(hi[i, 0], origin[0], inv, dims[0]),
            cell_of(lo[i, 1], origin[1], inv, dims[1]), cell_of(hi[i, 1], origin[1], inv, dims[1]),
            cell_of(lo[i, 2], origin[2], inv, dims[2]), cell_of(hi[i, 2], origin[2], inv, dims[2]))


@njit
def _grid_layout(lo, hi, cell_size):
    """(origin (3,), 1/side, dims (3,) int64, dense): cells from the scene's lowest corner. Dense: at most ~8n
    cells, stored as a table. When that cap would coarsen the cells (far-apart clusters), the cells keep their
    size (up to 2^21 per axis, so that a 64-bit key numbers them) and only the occupied ones are stored (sparse:
    sorted cell keys)."""
    origin = np.empty(3)
    top = np.empty(3)
    for k in range(3):
        origin[k] = lo[:, k].min()
        top[k] = hi[:, k].max()
    max_cells = max(8.0 * lo.shape[0], 64.0)
    size, nx, ny, nz = grid_dims(origin, top, cell_size, max_cells, max_cells)
    if size > cell_size:
        # at most 2^21 cells per axis: the key (cx · ny + cy) · nz + cz stays below 2^63
        sparse_size, sx, sy, sz = grid_dims(origin, top, cell_size, 2.0 ** 63, float(1 << 21))
        if sparse_size < size:
            return origin, 1.0 / sparse_size, np.array([sx, sy, sz]), False
    return origin, 1.0 / size, np.array([nx, ny, nz]), True


@njit
def _enter_boxes(lo, hi, origin, inv, dims, large):
    """The (cell, box) entries: every cell each box covers, in box order — (keys, ids), int64 (entries,) each.
    Boxes covering more than _MAX_CELLS_PER_BOX cells are marked in ``large`` instead and enter no cell."""
    n = lo.shape[0]
    entries = 0
    for i in range(n):  # the cell ranges are recomputed in the second pass rather than stored
        x0, x1, y0, y1, z0, z1 = _cell_range(lo, hi, i, origin, inv, dims)
        cells = (x1 - x0 + 1) * (y1 - y0 + 1) * (z1 - z0 + 1)
        if cells > _MAX_CELLS_PER_BOX:
            large[i] = True
        else:
            entries += cells
    keys = np.empty(entries, dtype=np.int64)
    ids = np.empty(entries, dtype=np.int64)
    t = 0
    for i in range(n):
        if large[i]:
            continue
        x0, x1, y0, y1, z0, z1 = _cell_range(lo, hi, i, origin, inv, dims)
        for cx in range(x0, x1 + 1):
            for cy in range(y0, y1 + 1):
                for cz in range(z0, z1 + 1):
                    keys[t] = (cx * dims[1] + cy) * dims[2] + cz
                    ids[t] = i
                    t += 1
    return keys, ids


@njit
def _sort_entries(lo, hi, keys, ids, n_cells):
    """The entries sorted by cell: (start (n_cells + 1,), member, elo, ehi); cell c holds entries start[c] ..
    start[c + 1] − 1, member[t] is the box of entry t and elo, ehi (entries, 3) its box, contiguous by cell.

    Counting sort in two passes (MSD radix) so that the counters of each pass stay in cache: first on the high
    bits of the cell number (<= 2048 buckets), then each bucket on its low bits; stable, so box order is kept.
    """
    entries = keys.shape[0]
    shift, n_buckets = radix_split(n_cells)
    bucket_start = np.zeros(n_buckets + 1, dtype=np.int64)
    for t in range(entries):
        bucket_start[(keys[t] >> shift) + 1] += 1
    for b in range(n_buckets):
        bucket_start[b + 1] += bucket_start[b]
    fill = bucket_start[:-1].copy()
    b_key = np.empty(entries, dtype=np.int64)
    b_id = np.empty(entries, dtype=np.int64)
    for t in range(entries):
        q = fill[keys[t] >> shift]
        fill[keys[t] >> shift] = q + 1
        b_key[q] = keys[t]
        b_id[q] = ids[t]
    start = np.empty(n_cells + 1, dtype=np.int64)
    dest = sort_within_buckets(b_key, bucket_start, shift, n_cells, start)
    member = np.empty(entries, dtype=np.int64)
    elo = np.empty((entries, 3))
    ehi = np.empty((entries, 3))
    for t in range(entries):
        q = dest[t]
        member[q] = b_id[t]
        for k in range(3):
            elo[q, k] = lo[b_id[t], k]
            ehi[q, k] = hi[b_id[t], k]
    start[n_cells] = entries
    return start, member, elo, ehi


@njit
def _sort_entries_sparse(lo, hi, keys, ids):
    """The entries sorted by cell key (one radix sort; only the occupied cells): (cell keys (c,), start
    (c + 1,), member, elo, ehi) as in ``_sort_entries``, cell i being the run start[i] .. start[i + 1] − 1."""
    entries = keys.shape[0]
    skeys, member = radix_sort_pairs(keys, ids, np.empty(entries, dtype=np.int64), np.empty(entries, dtype=np.int64),
                                     entries)
    cell_key = np.empty(entries, dtype=np.int64)
    start = np.empty(entries + 1, dtype=np.int64)
    cells = 0
    for t in range(entries):
        if t == 0 or skeys[t] != skeys[t - 1]:
            cell_key[cells] = skeys[t]
            start[cells] = t
            cells += 1
    start[cells] = entries
    elo = np.empty((entries, 3))
    ehi = np.empty((entries, 3))
    for t in range(entries):
        for k in range(3):
            elo[t, k] = lo[member[t], k]
            ehi[t, k] = hi[member[t], k]
    return cell_key[:cells].copy(), start[: cells + 1].copy(), member.copy(), elo, ehi


@njit
def _cell_pairs(cell_key, start, member, elo, ehi, origin, inv, dims, first, last, out):
    """Boxes sharing a cell, each pair reported only in the cell of the lower corner of its overlap, for the
    cells first .. last − 1 (cell i has key cell_key[i] = (cx · ny + cy) · nz + cz and entries start[i] ..
    start[i + 1] − 1); returns the pair buffer (out, count) and the tests made."""
    count = 0
    tests = 0
    for c in range(first, last):
        if start[c + 1] - start[c] < 2:
            continue
        key = cell_key[c]
        cz = key % dims[2]
        cy = (key // dims[2]) % dims[1]
        cx = key // (dims[1] * dims[2])
        for p in range(start[c], start[c + 1]):
            for q in range(p + 1, start[c + 1]):
                tests += 1
                if boxes_overlap(elo, ehi, p, q):
                    if (cell_of(max(elo[p, 0], elo[q, 0]), origin[0], inv, dims[0]) == cx
                            and cell_of(max(elo[p, 1], elo[q, 1]), origin[1], inv, dims[1]) == cy
                            and cell_of(max(elo[p, 2], elo[q, 2]), origin[2], inv, dims[2]) == cz):
                        out, count = pair_buffer.push_pair(out, count, member[p], member[q])
    return out, count, tests


@njit
def _large_box_pairs(lo, hi, large, out):
    """The boxes too large for the grid against every box (once per pair of large boxes); returns the pair
    buffer (out, count) and the tests made."""
    count = 0
    tests = 0
    for i in range(lo.shape[0]):
        if not large[i]:
            continue
        for j in range(lo.shape[0]):
            if j == i or (large[j] and j < i):
                continue
            tests += 1
            if boxes_overlap(lo, hi, i, j):
                out, count = pair_buffer.push_pair(out, count, i, j)
    return out, count, tests


@njit
def _prepare_grid(lo, hi, cell_size):
    # Ericson 7.1.3-7.1.6: each box goes into every cell it overlaps; boxes sharing a cell are tested.
    origin, inv, dims, dense = _grid_layout(lo, hi, cell_size)
    large = np.zeros(lo.shape[0], dtype=np.bool_)
    keys, ids = _enter_boxes(lo, hi, origin, inv, dims, large)
    if dense:
        n_cells = dims[0] * dims[1] * dims[2]
        start, member, elo, ehi = _sort_entries(lo, hi, keys, ids, n_cells)
        return origin, inv, dims, large, np.arange(n_cells), start, member, elo, ehi
    cell_key, start, member, elo, ehi = _sort_entries_sparse(lo, hi, keys, ids)
    return origin, inv, dims, large, cell_key, start, member, elo, ehi


#: a thread tests the boxes of at least this many (box, cell) entries
MIN_ENTRIES_PER_THREAD = 4096


@njit
def _mean_largest_side(lo, hi):
    mean_side = 0.0
    for i in range(lo.shape[0]):
        side = 0.0
        for k in range(3):
            side = max(side, hi[i, k] - lo[i, k])
        mean_side += side
    return mean_side / lo.shape[0]


@njit
def _default_cell_size(lo, hi):
    n = lo.shape[0]
    mean_side = _mean_largest_side(lo, hi)
    # a fallback for point-like scenes: the side of a cell holding one object on average
    volume = 1.0
    dims = 0
    for k in range(3):
        extent = hi[:, k].max() - lo[:, k].min()
        if extent > 0.0:
            volume *= extent
            dims += 1
    spacing = volume ** (1.0 / dims) / n ** (1.0 / dims) if dims > 0 else 0.0
    size = max(2.0 * mean_side, spacing)
    return size if size > 0.0 else 1.0


def default_cell_size(lo: ArrayLike, hi: ArrayLike) -> float:
    """The grid's default cell side for the given boxes.

    max(2 × the mean over the boxes of their largest side, (V / n)^(1/k)), where the scene's extent (largest hi
    minus smallest lo) is positive along k of the axes and V is the product of those extents (the side of a
    cell holding one object on average: the fallback of point-like scenes; 0 when k = 0); 1.0 if that is 0.
    When the spacing term exceeds ``SPARSE_SPACING_RATIO`` times 2 × the mean largest side (far-apart
    clusters), ``grid_pairs`` uses cells of 2 × the mean largest side instead, storing only the occupied ones.

    Parameters
    ----------
    lo, hi : array_like, shape (n, d)
        The boxes, d = 1, 2 or 3, ``lo <= hi``, finite.

    Returns
    -------
    float
        > 0; 1.0 for n = 0.

    Raises
    ------
    ValueError, TypeError
        For invalid boxes, as :func:`find_pairs`.
    """
    lo3, hi3 = as_boxes_3d(lo, hi)
    if lo3.shape[0] == 0:
        return 1.0
    return float(_default_cell_size(lo3, hi3))


@overload
def grid_pairs(lo: ArrayLike, hi: ArrayLike, cell_size: float | None = ..., *, return_tests: Literal[False] = ...,
               threads: int = ...) -> np.ndarray: ...
@overload
def grid_pairs(lo: ArrayLike, hi: ArrayLike, cell_size: float | None = ..., *, return_tests: Literal[True],
               threads: int = ...) -> tuple[np.ndarray, int]: ...
def grid_pairs(lo: ArrayLike, hi: ArrayLike, cell_size: float | None = None, *, return_tests: bool = False,
               threads: int = 1) -> np.ndarray | tuple[np.ndarray, int]:
    """All pairs of overlapping closed boxes with a uniform grid: ``find_pairs(method="grid")``.

    Each box enters every cell it covers and the boxes sharing a cell are tested; a pair is reported only in
    the cell of the lower corner of the two boxes' overlap, so once. Boxes covering more than 64 cells are
    tested against every box instead. The threads share the cells. ``lo``, ``hi``, ``return_tests``,
    ``threads`` and the result are those of every box method (:ref:`broadphase-boxes`, :ref:`broadphase-options`).

    Parameters
    ----------
    cell_size : float, optional
        The cell side, > 0. Default: :func:`default_cell_size` (from the box sizes and the mean spacing). When a
        table of every cell would need more than max(8·n, 64) cells, only the occupied cells are stored (the
        cells keep their side, enlarged only past 2^21 cells per axis).

    Returns
    -------
    pairs : numpy.ndarray, shape (k, 2), int64
        :ref:`broadphase-pairs`; ``(pairs, tests)`` with ``return_tests=True``, ``tests`` counting the box–box
        tests made: boxes sharing a cell, and the too-large boxes' tests.

    Raises
    ------
    ValueError
        When ``cell_size`` is not > 0 and finite (and for invalid boxes or ``threads``, as every box method).
    TypeError
        When ``cell_size`` is not a real number (and for non-numeric boxes).
    """
    threads = as_threads(threads)
    lo3, hi3 = as_boxes_3d(lo, hi)
    size = None if cell_size is None else as_positive(cell_size, "cell_size")
    if lo3.shape[0] < 2:
        return with_tests(empty_pairs(), 0, return_tests)
    if size is None:
        size = float(_default_cell_size(lo3, hi3))
        fine = 2.0 * float(_mean_largest_side(lo3, hi3))
        if 0.0 < SPARSE_SPACING_RATIO * fine < size:
            size = fine  # far-apart clusters: the spacing term would put a cluster in a cell; store occupied cells
    n = lo3.shape[0]
    origin, inv, dims, large, cell_key, start, member, elo, ehi = _prepare_grid(lo3, hi3, size)
    ranges = pair_buffer.split_work(start, threads, MIN_ENTRIES_PER_THREAD)
    large_pairs = _large_box_pairs(lo3, hi3, large, pair_buffer.new_pair_buffer(16))
    pairs, tests = pair_buffer.run_split(
        lambda first, last: _cell_pairs(cell_key, start, member, elo, ehi, origin, inv, dims, first, last,
                                        pair_buffer.new_pair_buffer(n)), ranges, n, extra=large_pairs)
    return with_tests(pairs, tests, return_tests)
