"""Sphere pairs by a padded cell grid: the grid of ``sphere_pairs`` when the scene is dense enough.

Ericson, *Real-Time Collision Detection* 7.1 (a uniform grid, each sphere stored once, in the cell of its centre;
7.1.6 the cells' contents sorted so that each cell is one contiguous range): cells of side h >= the largest
diameter (plus a round-off margin), so two touching spheres lie in the same or in adjacent cells (their
coordinates differ by at most the sum of their radii < h along every axis). Each sphere is tested against the
spheres after it in its own cell and the 13 cells of the forward half of its 3 × 3 × 3 neighbourhood; the other
13 meet it from their side, so every pair is met once.

The cells are numbered ``(iy · NX + ix) · NZ + iz`` (z fastest, then x, then y) over a grid padded with empty
cells: one layer before and after along x and z, one row after along y. In that order the forward half stencil
is five contiguous ranges of cells, each read from a table of cell ends with no bounds check and no key
comparison:

- the home cell (the spheres after this one) and the next cell along z (iz + 1);
- the three cells (iy, ix + 1, iz − 1 .. iz + 1);
- for dx = −1, 0, 1 the three cells (iy + 1, ix + dx, iz − 1 .. iz + 1).

Data-oriented passes: one 64-bit word per sphere, its cell · 2^32 + its id (the key and the id move as one
word), sorted by cell in two counting passes whose counters stay in cache (``counting_sort``'s two-pass sort,
Ericson 7.1.6): the words scattered by bucket (a high part of the cell number, ``cell_words`` then
``counting_sort.scatter_to_buckets``), then each bucket sorted by cell (``place_in_cells``), which also writes the
table of cell ends (its counters' running sum) and gathers the coordinates into sorted float arrays (structure of
arrays); then the sweep. Each pass is split among threads — the first by chunks of spheres, each with its own
histogram of buckets (``counting_sort.bucket_offsets`` gives each chunk its slots, so the order is the same for
any split), the second by ranges of buckets, the sweep by ranges of sorted spheres.
The table has one entry per cell, so the grid is used only when there are at most ``MAX_CELLS_PER_SPHERE`` cells
per sphere (``cell_layout`` says so); sparser scenes use the sorted columns of ``sphere_columns``.
"""
from __future__ import annotations

from collections import namedtuple

import numpy as np

from engine._config import njit
from engine.broadphase.counting_sort import cell_of
from engine.broadphase.sphere_columns import pair_hit

__all__ = ["MAX_CELLS_PER_SPHERE", "ID_MASK", "CellLayout", "cell_layout", "cell_words", "place_in_cells",
           "sweep_cells"]

#: the most cells (padding included) per sphere for which the padded grid is used (its table of cell ends is
#: one int32 per cell)
MAX_CELLS_PER_SPHERE = 16
#: the largest cell number (32-bit keys)
_KEY_LIMIT = (1 << 31) - 2
#: the sphere id in the low 32 bits of a sorted word cell · 2^32 + id
ID_MASK = (1 << 32) - 1

#: the grid: its origin, 1/h, the cells along each axis (without padding) and the padded row lengths NX = nx + 2
#: and NZ = nz + 2; n_cells is the padded count (ny + 1) · NX · NZ, or 0 when the grid would be too large
CellLayout = namedtuple("CellLayout", ["x0", "y0", "z0", "inv_h", "nx", "ny", "nz", "row_x", "row_z", "n_cells"])


@njit
def cell_layout(lo, hi, h, n):
    """The CellLayout over the centres' bounds lo, hi ((3,) each) for cells of side ``h`` and n spheres, with
    n_cells = 0 when the padded grid would have more than MAX_CELLS_PER_SPHERE · n + 4096 cells or a cell
    number past 31 bits (the counts are compared as floats first: a tiny h gives counts no int holds)."""
    counts = np.empty(3)
    for k in range(3):
        counts[k] = np.floor((hi[k] - lo[k]) / h) + 1.0
    total = (counts[1] + 1.0) * (counts[0] + 2.0) * (counts[2] + 2.0)
    if not (total <= MAX_CELLS_PER_SPHERE * n + 4096 and total <= _KEY_LIMIT and n <= ID_MASK):
        return CellLayout(lo[0], lo[1], lo[2], 1.0 / h, 1, 1, 1, 3, 3, 0)
    nx, ny, nz = int(counts[0]), int(counts[1]), int(counts[2])
    return CellLayout(lo[0], lo[1], lo[2], 1.0 / h, nx, ny, nz, nx + 2, nz + 2, (ny + 1) * (nx + 2) * (nz + 2))


@njit
def cell_words(c, large, layout, first, last, words, bucket_shift, hist):
    """The words of the spheres first .. last − 1 outside ``large``: words[first + k] = (padded cell number of
    the k-th of them) · 2^32 + its index, and hist[b] += 1 (hist (B,) int64) for its bucket b = word >>
    bucket_shift; returns k (one chunk of the first pass of ``place_in_cells``' sort)."""
    k = first
    for i in range(first, last):
        if large[i]:
            continue
        iy = cell_of(c[i, 1], layout.y0, layout.inv_h, layout.ny)
        ix = cell_of(c[i, 0], layout.x0, layout.inv_h, layout.nx) + 1
        iz = cell_of(c[i, 2], layout.z0, layout.inv_h, layout.nz) + 1
        word = (np.int64((iy * layout.row_x + ix) * layout.row_z + iz) << 32) | i
        words[k] = word
        hist[word >> bucket_shift] += 1
        k += 1
    return k - first


@njit
def place_in_cells(grouped, bucket_start, first, last, shift, n_cells, c, r, equal, order, ends, sx, sy, sz, sr):
    """The second pass of the sort by cell, for the buckets first .. last − 1 (bucket b: the cells b · 2^shift ..
    (b + 1) · 2^shift − 1, its words grouped[bucket_start[b]:bucket_start[b + 1]], in index order — the first
    pass, ``cell_words`` then ``counting_sort.scatter_to_buckets``, put them there).

    A counting sort of each bucket by cell (its counters in cache): writes ends[k] (int32) = the number of
    sorted spheres in cells <= k for each of the buckets' cells, each word at its sorted slot p of ``order``
    (int64; in a cell, by index), and gathers the sphere's centre and radius into sx, sy, sz, sr[p] (float64;
    ``equal``: every radius is r[0], not gathered) — the one random-access pass over the centres.
    """
    width = 1 << shift
    local = np.zeros(width, dtype=np.int64)
    for b in range(first, last):
        first_cell = b << shift
        cells = min(n_cells, first_cell + width) - first_cell
        lo, hi = bucket_start[b], bucket_start[b + 1]
        local[:cells] = 0
        for t in range(lo, hi):
            local[(grouped[t] >> 32) - first_cell] += 1
        total = lo
        for u in range(cells):  # local[u]: the first slot of cell u (a running sum held in a register)
            count = local[u]
            local[u] = total
            total += count
        for t in range(lo, hi):
            word = grouped[t]
            u = (word >> 32) - first_cell
            p = local[u]
            local[u] = p + 1
            order[p] = word
        ends[first_cell:first_cell + cells] = local[:cells]  # each slot advanced to its cell's end
        for p in range(lo, hi):  # the gather: one random read of each centre, written in sorted order
            i = order[p] & ID_MASK
            sx[p] = c[i, 0]
            sy[p] = c[i, 1]
            sz[p] = c[i, 2]
        if equal:  # a loop of its own: a select would still load r[i], one more random read per sphere
            sr[lo:hi] = r[0]
        else:
            for p in range(lo, hi):
                sr[p] = r[order[p] & ID_MASK]


@njit
def _run_bounds(key, p, nz, row, ends):
    """The five ranges of sorted spheres of sphere p's forward half stencil (p in cell ``key``; cells a .. b are
    the sorted spheres ends[a − 1] .. ends[b] − 1): their first entry a0 and, for the flat loop over their
    concatenation, the lengths before ranges 1-4 (c1-c4), the total and the jumps d1-d4 from the end of one
    range to the start of the next."""
    up = key + row  # the same (ix, iz) one row up along y
    a0, b0 = p + 1, np.int64(ends[key + 1])  # the home cell after p and the next cell along z
    a1, b1 = np.int64(ends[key + nz - 2]), np.int64(ends[key + nz + 1])  # (iy, ix + 1, iz - 1 .. iz + 1)
    a2, b2 = np.int64(ends[up - nz - 2]), np.int64(ends[up - nz + 1])  # (iy + 1, ix - 1, iz - 1 .. iz + 1)
    a3, b3 = np.int64(ends[up - 2]), np.int64(ends[up + 1])  # (iy + 1, ix, iz - 1 .. iz + 1)
    a4, b4 = np.int64(ends[up + nz - 2]), np.int64(ends[up + nz + 1])  # (iy + 1, ix + 1, iz - 1 .. iz + 1)
    c1 = b0 - a0
    c2 = c1 + b1 - a1
    c3 = c2 + b2 - a2
    c4 = c3 + b3 - a3
    return a0, c1, c2, c3, c4, c4 + b4 - a4, a1 - b0, a2 - b1, a3 - b2, a4 - b3


@njit
def sweep_cells(layout, order, ends, sx, sy, sz, sr, first, last, buf, count):
    """The sweeps of the sorted spheres first .. last − 1 against their forward half stencil (see the module's
    description).

    The arguments are the layout, the outputs of ``sort_into_cells`` (order (m,) int64: cell · 2^32 + sphere id;
    sx, sy, sz, sr (m,) float64) and the table of ``cell_ends``. Records the touching pairs (original sphere
    ids) in ``buf`` (int64 (capacity, 2)) from row ``count`` on (the two-try record of ``engine.broadphase.pairs``)
    and returns the new count, which exceeds ``capacity`` when buf was too small.

    The five ranges are walked as one flat loop (t counts the candidates, the jumps between ranges are added
    by selects), so a sphere ends one loop, not five: each loop's exit is a mispredicted branch about as often
    as not. Indices are unsigned, so the loads carry no negative-index wraparound.
    """
    nz = layout.row_z
    row = layout.row_x * nz
    flat = buf.reshape(-1)  # row `count` at 2 · count: no stride multiply per record
    capacity = buf.shape[0]
    for p in range(first, last):
        a0, c1, c2, c3, c4, total, d1, d2, d3, d4 = _run_bounds(order[p] >> 32, p, nz, row, ends)
        px = sx[p]
        py = sy[p]
        pz = sz[p]
        pr = sr[p]
        ip = order[p] & ID_MASK
        for t in range(total):
            q = np.uint64(a0 + t + (d1 if t >= c1 else 0) + (d2 if t >= c2 else 0) + (d3 if t >= c3 else 0)
                          + (d4 if t >= c4 else 0))
            hit = pair_hit(px - sx[q], py - sy[q], pz - sz[q], pr + sr[q])
            if count < capacity:  # the two-try record of engine.broadphase.pairs
                flat[2 * count] = ip
                flat[2 * count + 1] = order[q] & ID_MASK
            count += np.int64(hit)
    return count
