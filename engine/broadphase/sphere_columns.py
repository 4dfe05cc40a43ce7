"""Sphere pairs by sorted columns: the grid of ``sphere_pairs`` (one sort, then short sweeps).

Ericson, *Real-Time Collision Detection* 7.1 (a uniform grid, each sphere stored once, in the cell of its centre)
swept like Terdiman's box pruning (7.5.2): space is cut along y and z into *columns* of side h >= the largest
diameter (plus a round-off margin), and each column is sorted along x. Two touching spheres then lie in the same
or in adjacent columns, less than h apart along x. Each sphere is compared with the spheres after it in its own
column up to h ahead, and with the spheres of the four columns (iy, iz + 1), (iy + 1, iz − 1), (iy + 1, iz),
(iy + 1, iz + 1) up to h on either side; the other four neighbours meet it from their own side, so every pair is
met once. About one candidate per sphere at packing fraction 0.05 (a 3 × 3 × 3 cell stencil tests 4 to 5).

Data-oriented passes:

1. one integer key per sphere, ``column · nxf + fx``, where fx = floor((x − x0) / w) counts steps of
   w = h / X_STEPS along x: 32-bit when the grid is small (*dense*: a table gives each column's first sphere),
   64-bit otherwise (*sparse*: columns looked up by binary search, so far-apart clusters cost nothing);
2. one stable radix sort of the keys (``counting_sort.radix_sort_pairs``) and one gather of the coordinates into
   sorted float arrays (structure of arrays);
3. the sweeps, on integer keys: a touching pair's fx differ by at most X_STEPS + 1 (the layout's reach). Each
   column's keys stay more than a reach below the next column's and a sentinel key ends the array, so no sweep
   needs a bounds check; pairs are recorded branch-free (the two-try record of ``pairs``).
"""
from __future__ import annotations

import math
from collections import namedtuple

import numpy as np

from engine._config import njit
from engine.broadphase.counting_sort import cell_of, radix_sort_pairs
from engine.broadphase.pair_merge import first_at_or_after

__all__ = ["X_STEPS", "ColumnLayout", "column_layout", "sort_into_columns", "sweep_columns", "pair_hit",
           "touching_at_scale", "TINY_REACH"]

#: steps of the x key per column side (fewer in a very long scene; a touching pair's x keys then differ by at
#: most steps + 1, the layout's reach)
X_STEPS = 16
#: the largest dense key (32-bit keys, one below the sentinel)
_DENSE_LIMIT = (1 << 31) - 2

#: the grid: its origin, 1/h and 1/w, fx steps per column (nfx) and per key row (nxf), columns along y and z,
#: and whether keys are dense (32-bit, column starts in a table) or sparse (64-bit, binary search)
ColumnLayout = namedtuple("ColumnLayout", ["x0", "y0", "z0", "inv_h", "inv_w", "reach", "nfx", "nxf", "ny", "nz",
                                           "dense"])


@njit
def column_layout(lo, hi, h, n):
    """The ColumnLayout over the centres' bounds lo, hi ((3,) each) for columns of side ``h`` and n spheres.

    Keys are dense when there are at most max(8n, 64) columns and every key fits in 31 bits. Otherwise (sparse)
    they must fit in 63 bits: columns along y and z at most 2^21 each, x steps per key row at most 2^21, with
    fewer x steps per column (down to 1) when the scene is very long, and h doubled only past that.
    """
    size = h
    while True:
        nx = int(np.floor((hi[0] - lo[0]) / size)) + 1
        ny = int(np.floor((hi[1] - lo[1]) / size)) + 1
        nz = int(np.floor((hi[2] - lo[2]) / size)) + 1
        steps = min(X_STEPS, ((1 << 21) - 2 * X_STEPS - 2) // nx)
        if ny <= 1 << 21 and nz <= 1 << 21 and steps >= 1:
            break
        size *= 2.0
    nfx = nx * steps
    nxf = nfx + 2 * steps + 2  # each key row ends more than a reach (steps + 1) before the next
    dense = ny * nz <= max(8 * n, 64) and ny * nz * nxf <= _DENSE_LIMIT
    return ColumnLayout(lo[0], lo[1], lo[2], 1.0 / size, steps / size, steps + 1, nfx, nxf, ny, nz, dense)


@njit
def _column_keys(c, large, layout, keys, index):
    """keys[m] = column · nxf + fx and index[m] = i for each sphere i in the grid; returns m."""
    m = 0
    for i in range(c.shape[0]):
        if large[i]:
            continue
        iy = cell_of(c[i, 1], layout.y0, layout.inv_h, layout.ny)
        iz = cell_of(c[i, 2], layout.z0, layout.inv_h, layout.nz)
        fx = cell_of(c[i, 0], layout.x0, layout.inv_w, layout.nfx)
        keys[m] = (iy * layout.nz + iz) * layout.nxf + fx
        index[m] = i
        m += 1
    return m


@njit
def sort_into_columns(c, r, large, layout, keys, index, keys_tmp, index_tmp, sx, sy, sz, sr, sentinel):
    """Sort the spheres of the grid by key: returns (m, sorted keys (m + 1,) ending with the sentinel, sorted
    sphere ids (m,)) and fills sx, sy, sz, sr (the sorted centres and radii, float64). keys, keys_tmp: (n + 1,)
    int32 (dense) or int64 (sparse) work arrays; index, index_tmp: (n,) int64; sentinel: the largest key value."""
    m = _column_keys(c, large, layout, keys, index)
    skeys, sid = radix_sort_pairs(keys, index, keys_tmp, index_tmp, m)
    for p in range(m):
        i = sid[p]
        sx[p] = c[i, 0]
        sy[p] = c[i, 1]
        sz[p] = c[i, 2]
        sr[p] = r[i]
    skeys[m] = sentinel  # stops every sweep
    return m, skeys, sid


@njit
def home_columns(keys, m, layout):
    """The columns to sweep from: (column ids, first sphere of each, and m at the end), int64.

    Dense: every column 0 .. ny·nz − 1 (empty ones included: their starts are the table of column starts).
    Sparse: the occupied columns only, in key order.
    """
    if layout.dense:
        n_cols = layout.ny * layout.nz
        start = np.empty(n_cols + 1, dtype=np.int64)
        p = 0
        for col in range(n_cols + 1):
            threshold = col * layout.nxf
            while p < m and keys[p] < threshold:
                p += 1
            start[col] = p
        return np.arange(n_cols), start
    cols = np.empty(m, dtype=np.int64)
    start = np.empty(m + 1, dtype=np.int64)
    k = 0
    previous = -1
    for p in range(m):
        col = keys[p] // layout.nxf
        if col != previous:
            cols[k] = col
            start[k] = p
            k += 1
            previous = col
    start[k] = m
    return cols[:k].copy(), start[: k + 1].copy()


@njit
def _neighbour_starts(col, layout, keys, m, col_ids, col_start, bases, starts):
    """For the four forward neighbours of column ``col``: the key of their first x step (bases) and their first
    sphere (starts); an absent neighbour gets base −1. Returns the home column's base."""
    iy = col // layout.nz
    iz = col - iy * layout.nz
    for k in range(4):
        jy = iy if k == 0 else iy + 1
        jz = iz + 1 if k == 0 else iz + k - 2
        if jy >= layout.ny or jz < 0 or jz >= layout.nz:
            bases[k] = -1
            continue
        other = jy * layout.nz + jz
        bases[k] = other * layout.nxf
        starts[k] = col_start[other] if layout.dense else first_at_or_after(keys, np.int64(0), m, bases[k])
    return col * layout.nxf


#: below this sum of radii, squared distances underflow (to subnormals or 0) and the test is made at scale
TINY_REACH = 1e-150


@njit(inline="always")
def touching_at_scale(dx, dy, dz, s):
    """|d|² <= s² with d and s divided by the power of two that brings their largest magnitude into [0.5, 1)
    first (exact: a pair of spheres far below 1e-150, whose squared distance would underflow, is decided as at
    unit scale; the same test as engine.bounding.sphere.spheres_touch)."""
    big = max(s, abs(dx), abs(dy), abs(dz))
    if big == 0.0:
        return True
    e = -math.frexp(big)[1]
    x, y, z, t = math.ldexp(dx, e), math.ldexp(dy, e), math.ldexp(dz, e), math.ldexp(s, e)
    return x * x + y * y + z * z <= t * t


@njit(inline="always")
def pair_hit(ddx, ddy, ddz, s):
    """Whether two spheres whose centres differ by (ddx, ddy, ddz) and whose radii sum to s touch: |d|² <= s² and
    |d_k| <= s (so that squares underflowing to 0 cannot make distinct points touch), decided at scale when s is
    tiny whatever the plain test said (subnormal squares round either way: spheres exactly touching at 2^-541
    came out apart). Branch-light: the branch is on the rare tiny s, not on the outcome (which would be
    mispredicted at about every other candidate)."""
    hit = ((ddx * ddx + ddy * ddy + ddz * ddz <= s * s) & (abs(ddx) <= s) & (abs(ddy) <= s) & (abs(ddz) <= s))
    if s < TINY_REACH:  # squares of these magnitudes underflow (rounded up, too): the test at scale decides
        hit = touching_at_scale(ddx, ddy, ddz, s)
    return hit


@njit
def sweep_columns(layout, keys, m, sx, sy, sz, sr, sid, col_ids, col_start, first, last, buf, count):
    """The sweeps from the home columns col_ids[first:last] (see the module's description), and from no other: the
    ranges of a split of 0 .. c record, between them, each pair of the whole sweep exactly once (the threads of
    sphere_pairs share the columns that way).

    The arguments are the layout, the outputs of ``sort_into_columns`` (keys (m + 1,), m, sx, sy, sz, sr (m,)
    float64, sid (m,) int64) and of ``home_columns`` (col_ids (c,), col_start (c + 1,) int64). Records the
    touching pairs (original sphere ids) in ``buf`` (int64 (capacity, 2)) from row ``count`` on (the two-try
    record) and returns the new count, which exceeds ``capacity`` when buf was too small.
    """
    bases = np.empty(5, dtype=np.int64)  # run 0: the home column itself; runs 1-4: its forward neighbours
    starts = np.empty(5, dtype=np.int64)
    reach = layout.reach
    capacity = buf.shape[0]
    for h in range(first, last):
        if col_start[h] == col_start[h + 1]:
            continue
        home = _neighbour_starts(col_ids[h], layout, keys, m, col_ids, col_start, bases[1:], starts[1:])
        for p in range(col_start[h], col_start[h + 1]):
            px = sx[p]
            py = sy[p]
            pz = sz[p]
            pr = sr[p]
            fx = keys[p] - home
            for k in range(5):
                if k == 0:  # the same column: the spheres after p, up to a reach ahead
                    q = p + 1
                    limit = keys[p] + reach
                elif bases[k] < 0:
                    continue
                else:  # a neighbour column: from a reach behind p (a pointer that only moves forward) on
                    low = bases[k] + fx - reach
                    q = starts[k]
                    while keys[q] < low:
                        q += 1
                    starts[k] = q
                    limit = low + 2 * reach
                while keys[q] <= limit:
                    hit = pair_hit(px - sx[q], py - sy[q], pz - sz[q], pr + sr[q])
                    if count < capacity:  # the two-try record of engine.broadphase.pairs
                        buf[count, 0] = sid[p]
                        buf[count, 1] = sid[q]
                    count += np.int64(hit)
                    q += 1
    return count
