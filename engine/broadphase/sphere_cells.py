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
word), sorted by cell, the coordinates gathered into sorted float arrays (structure of arrays), the table of cell
ends, then the sweep. On one thread: one stable radix sort of the words (``sort_into_cells``,
``counting_sort.radix_sort_packed``), then the table (``cell_ends``: a histogram of the sorted cells and its
running sum). On several, the same order by ``counting_sort``'s two counting passes (Ericson 7.1.6), each split
among the threads: the words scattered by bucket (a high part of the cell number) by chunks of spheres, each with
its own histogram of buckets (``cell_words``, ``counting_sort.bucket_offsets``, ``scatter_spheres``: the order
is the same for any split; the centres travel with their words, read in index order), then each range of buckets
sorted by cell with its counters in cache, writing its cell ends (``place_in_cells``). The sweep is split by
ranges of sorted spheres.
The table has one entry per cell, so the grid is used only when there are at most ``MAX_CELLS_PER_SPHERE`` cells
per sphere (``cell_layout`` says so); sparser scenes use the sorted columns of ``sphere_columns``.
"""
from __future__ import annotations

from collections import namedtuple

import numpy as np

from engine._config import njit
from engine.broadphase.counting_sort import cell_of, radix_sort_packed
from engine.broadphase.sphere_columns import pair_hit

__all__ = ["MAX_CELLS_PER_SPHERE", "ID_MASK", "CellLayout", "cell_layout", "sort_into_cells", "cell_ends",
           "cell_words", "scatter_spheres", "place_in_cells", "sweep_cells"]

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
def _cell_keys(c, large, layout, order):
    """order[m] = (padded cell number of sphere i) · 2^32 + i for each sphere i in the grid; returns m."""
    m = 0
    for i in range(c.shape[0]):
        if large[i]:
            continue
        iy = cell_of(c[i, 1], layout.y0, layout.inv_h, layout.ny)
        ix = cell_of(c[i, 0], layout.x0, layout.inv_h, layout.nx) + 1
        iz = cell_of(c[i, 2], layout.z0, layout.inv_h, layout.nz) + 1
        order[m] = (np.int64((iy * layout.row_x + ix) * layout.row_z + iz) << 32) | i
        m += 1
    return m


#: from this many spheres on, the sort's digits are 8 bits (its arrays no longer fit in the L2 cache)
_SMALL_DIGITS_FROM = 1 << 17


@njit
def sort_into_cells(c, r, large, equal, layout, order, order_tmp, sx, sy, sz, sr):
    """Sort the spheres of the grid by cell: returns (m, order) with order[:m] (int64, one of the two buffers
    given) the sorted words cell · 2^32 + sphere id, and fills sx, sy, sz, sr[:m] (the sorted centres and radii,
    float64; ``equal``: every radius is r[0], which is then not gathered). order, order_tmp: int64 work arrays
    of at least n entries."""
    m = _cell_keys(c, large, layout, order)
    bits = 0
    while ((layout.n_cells - 1) >> bits) > 0:
        bits += 1
    order = radix_sort_packed(order, order_tmp, m, 32, bits, 8 if m >= _SMALL_DIGITS_FROM else 11)
    for p in range(m):  # the one random-access pass: each sphere's centre read once, written in cell order
        i = order[p] & ID_MASK
        sx[p] = c[i, 0]
        sy[p] = c[i, 1]
        sz[p] = c[i, 2]
    if equal:  # r may then be r[0] alone (a select would load r[i] all the same)
        sr[:m] = r[0]
    else:
        for p in range(m):
            sr[p] = r[order[p] & ID_MASK]
    return m, order


@njit
def cell_ends(order, m, n_cells, ends):
    """Fill ends[:n_cells] (int32) with ends[k] = the number of sorted spheres in cells <= k (order: the sorted
    words of ``sort_into_cells``), so that cell k holds the sorted spheres ends[k − 1] .. ends[k] − 1: a
    histogram of the cells, then its running sum (no branch per cell)."""
    ends[:n_cells] = 0
    for p in range(m):
        ends[order[p] >> 32] += 1
    total = 0
    for k in range(n_cells):
        total += ends[k]
        ends[k] = total


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
def scatter_spheres(words, first, count, shift, offsets, c, r, equal, grouped, gr):
    """The first pass's scatter, for the words words[first:first + count] of one chunk (``cell_words``): each
    word to its slot q in its bucket (word >> shift), offsets (B,) being this chunk's row of
    ``counting_sort.bucket_offsets`` (advanced), stable. The sphere's centre goes with it: grouped[q] (float64
    (n, 4)) is the record (word, as int64 bits; x; y; z), one stream of writes per bucket, and gr[q] its radius
    (only when not ``equal``). The centres are read in index order here, so that no later pass reads them at
    random."""
    bits = grouped.reshape(grouped.size).view(np.int64)
    for t in range(first, first + count):
        word = words[t]
        b = word >> shift
        q = offsets[b]
        offsets[b] = q + 1
        i = word & ID_MASK
        bits[4 * q] = word
        grouped[q, 1] = c[i, 0]
        grouped[q, 2] = c[i, 1]
        grouped[q, 3] = c[i, 2]
        if not equal:
            gr[q] = r[i]


@njit
def place_in_cells(grouped, gr, bucket_start, first, last, shift, n_cells, r, equal, order, ends, sx, sy, sz, sr):
    """The second pass of the sort by cell, for the buckets first .. last − 1 (bucket b: the cells b · 2^shift ..
    (b + 1) · 2^shift − 1, its records grouped[bucket_start[b]:bucket_start[b + 1]] (word, x, y, z) in index
    order and their radii gr at the same slots — ``scatter_spheres`` put them there).

    A counting sort of each bucket by cell (its counters in cache): writes ends[k] (int32) = the number of
    sorted spheres in cells <= k for each of the buckets' cells, each word at its sorted slot p of ``order``
    (int64; in a cell, by index) and its sphere's centre and radius at sx, sy, sz, sr[p] (float64; ``equal``:
    every radius is r[0]). Every access is in sequence or within one bucket's slots.
    """
    bits = grouped.reshape(grouped.size).view(np.int64)
    width = 1 << shift
    local = np.zeros(width, dtype=np.int32)  # slots relative to the bucket's first: 4 bytes, in the L1 cache
    for b in range(first, last):
        first_cell = b << shift
        cells = min(n_cells, first_cell + width) - first_cell
        lo, hi = bucket_start[b], bucket_start[b + 1]
        local[:cells] = 0
        for t in range(lo, hi):
            local[(bits[4 * t] >> 32) - first_cell] += 1
        total = 0
        for u in range(cells):  # local[u]: the first slot of cell u (a running sum held in a register)
            count = local[u]
            local[u] = total
            total += count
            ends[first_cell + u] = lo + total
        for t in range(lo, hi):
            word = bits[4 * t]
            u = (word >> 32) - first_cell
            p = lo + local[u]
            local[u] += 1
            order[p] = word
            sx[p] = grouped[t, 1]
            sy[p] = grouped[t, 2]
            sz[p] = grouped[t, 3]
            if not equal:
                sr[p] = gr[t]
        if equal:
            sr[lo:hi] = r[0]


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
