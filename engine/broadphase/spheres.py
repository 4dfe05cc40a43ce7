"""Sphere pairs: broad phase + exact sphere test, the fast path of the confined-gas simulation.

``sphere_pairs(centers, radii)`` returns exactly the pairs with |c_i − c_j| <= r_i + r_j, computed as
``dx² + dy² + dz² <= (r_i + r_j)²`` in IEEE double precision (touching counts), together with
``|dx|, |dy|, |dz| <= r_i + r_j`` so that squares underflowing to zero (coordinates below ~1e-154) cannot make
distinct points touch.

The default method, "grid", is a uniform grid specialised to spheres (Ericson, *Real-Time Collision Detection*
7.1.2–7.1.6, and the chapter's "absolue" spatial subdivision): each sphere is stored once, in the cell of its
centre; cells are at least one largest diameter wide (plus a round-off margin), so two touching spheres are in
the same or in adjacent cells, and each cell is compared with itself and with 13 of its 26 neighbours (the half
that comes after it), so every pair is met once. The cells are numbered linearly and filled by a counting sort
(count, prefix sum, fill) into contiguous sorted arrays — no lists grow inside the kernel. Cells are also at
least 0.7 × the mean spacing (V/n)^(1/3) wide (about 0.3 spheres per cell), so a sparse scene does not pay for
empty cells; measured best on the W2 workload between 0.5 and 1 × spacing. Spheres much larger
than the typical one (radius > 4 × median) are kept out of the grid and tested against every sphere.

Any other method of ``BROAD_PHASES`` runs that broad phase on the spheres' bounding boxes (widened by a
round-off margin so no touching pair is lost) and then applies the same exact test.
"""
from __future__ import annotations

import threading

import numpy as np

from engine._config import njit
from engine._validate import as_choice, as_float_array, as_nonnegative
from engine.bounding.sphere import spheres_touch
from engine.broadphase.counting_sort import cell_of, grid_dims, radix_split, sort_within_buckets
from engine.broadphase.pairs import canonical_pairs, canonicalise_pairs, empty_pairs, push_pair

__all__ = ["sphere_pairs", "spheres_overlap_pairs"]

_EPS = np.finfo(np.float64).eps
#: cells are at least this fraction of the mean spacing (V/n)^(1/3) wide (about 0.3 spheres per cell)
_SPACING_FACTOR = 0.7
#: up to this many cells the spheres are counting-sorted in one pass; beyond, in two radix passes
_DIRECT_SORT_CELLS = 1 << 19


@njit
def _spheres_touch(c, r, i, j):
    """Spheres i and j of (c (n, 3), r (n,)) touch or overlap: the engine's one sphere test (bounding.sphere)."""
    return spheres_touch(c[i], r[i], c[j], r[j])


@njit
def _point_bounds(c):
    """(lowest, highest) coordinate of the points c (n, 3) along each axis, (3,) each."""
    lo = np.full(3, np.inf)
    hi = np.full(3, -np.inf)
    for i in range(c.shape[0]):
        for k in range(3):
            v = c[i, k]
            if v < lo[k]:
                lo[k] = v
            if v > hi[k]:
                hi[k] = v
    return lo, hi


@njit
def _sphere_grid_shape(c, cell_size):
    """(origin (3,), 1/side, nx, ny, nz) of the grid over the centres c (n, 3), at most ~32n cells (about 3n at
    the default cell size)."""
    origin, top = _point_bounds(c)
    size, nx, ny, nz = grid_dims(origin, top, cell_size, max(32.0 * c.shape[0], 64.0))
    return origin, 1.0 / size, nx, ny, nz


@njit
def _sphere_cells(c, large, origin, inv, nx, ny, nz, cell):
    """cell[i] = the number of the cell of centre i, x varying fastest (−1 for the spheres kept out of the
    grid); returns how many spheres are in the grid."""
    n_small = 0
    for i in range(c.shape[0]):
        if large[i]:
            cell[i] = -1
            continue
        ix = cell_of(c[i, 0], origin[0], inv, nx)
        iy = cell_of(c[i, 1], origin[1], inv, ny)
        iz = cell_of(c[i, 2], origin[2], inv, nz)
        cell[i] = (iy * nz + iz) * nx + ix
        n_small += 1
    return n_small


@njit
def _direct_sort(c, r, cell, n_cells, start, sx, sy, sz, sr, sid):
    """One counting sort of the spheres by cell straight into the sorted arrays (the counters fit in cache)."""
    start[: n_cells + 1] = 0
    for i in range(c.shape[0]):
        if cell[i] >= 0:
            start[cell[i] + 1] += 1
    for t in range(n_cells):
        start[t + 1] += start[t]
    fill = start[:n_cells].copy()
    for i in range(c.shape[0]):
        key = cell[i]
        if key >= 0:
            p = fill[key]
            fill[key] = p + 1
            sx[p] = c[i, 0]
            sy[p] = c[i, 1]
            sz[p] = c[i, 2]
            sr[p] = r[i]
            sid[p] = i


@njit
def _radix_sort(c, r, cell, n_cells, n_small, start, sx, sy, sz, sr, sid, b_cell, b_x, b_y, b_z, b_r, b_id):
    """Two-pass (MSD radix) counting sort, so that the counters of each pass stay in cache: first on the high
    bits of the cell number (at most 2048 buckets) moving every payload (cell, x, y, z, r, index) to its bucket
    (sequential reads, one write stream per bucket and array), then each bucket on its low bits."""
    shift, n_buckets = radix_split(n_cells)
    bucket_start = np.zeros(n_buckets + 1, dtype=np.int64)
    for i in range(c.shape[0]):
        if cell[i] >= 0:
            bucket_start[(cell[i] >> shift) + 1] += 1
    for b in range(n_buckets):
        bucket_start[b + 1] += bucket_start[b]
    fill_bucket = bucket_start[:-1].copy()
    for i in range(c.shape[0]):
        if cell[i] >= 0:
            b = cell[i] >> shift
            q = fill_bucket[b]
            fill_bucket[b] = q + 1
            b_cell[q] = cell[i]
            b_x[q] = c[i, 0]
            b_y[q] = c[i, 1]
            b_z[q] = c[i, 2]
            b_r[q] = r[i]
            b_id[q] = i
    dest = sort_within_buckets(b_cell[:n_small], bucket_start, shift, n_cells, start)
    for t in range(n_small):
        p = dest[t]
        sx[p] = b_x[t]
        sy[p] = b_y[t]
        sz[p] = b_z[t]
        sr[p] = b_r[t]
        sid[p] = b_id[t]
    start[n_cells] = n_small


@njit
def _sphere_grid_sort(c, r, large, origin, inv, nx, ny, nz, cell, start, sx, sy, sz, sr, sid,
                      b_cell, b_x, b_y, b_z, b_r, b_id):
    # Ericson 7.1.2: one cell per sphere (its centre); cell side >= largest diameter, so a touching pair lies
    # in the same or an adjacent cell. Counting sort of the spheres by cell number, x varying fastest, into a
    # sorted structure of arrays (sx, sy, sz, sr, sid); a column (iy, iz) of cells is then one contiguous run
    # ordered by ix, and start[cell] .. start[cell + 1] are the spheres of a cell. All arrays are work arrays
    # given by the caller (reused between calls); returns the number of spheres placed in the grid.
    n_small = _sphere_cells(c, large, origin, inv, nx, ny, nz, cell)
    n_cells = nx * ny * nz
    if n_cells <= _DIRECT_SORT_CELLS:
        _direct_sort(c, r, cell, n_cells, start, sx, sy, sz, sr, sid)
    else:
        _radix_sort(c, r, cell, n_cells, n_small, start, sx, sy, sz, sr, sid, b_cell, b_x, b_y, b_z, b_r, b_id)
    return n_small


@njit
def _sphere_grid_sweep(nx, ny, nz, start, sx, sy, sz, sr, sid, out):
    """Each cell against the half of its 26 neighbours that comes after it, and itself (q > p).

    Neighbour cells are read as contiguous runs: in its own column the cell and the next one (ix, ix + 1); in
    the four columns (dy, dz) = (0, 1), (1, −1), (1, 0), (1, 1) the three cells ix − 1 .. ix + 1. The other
    four columns meet this cell from their own side, so every pair is met once.
    Pairs are written to ``out`` while it has room; returns their number (the caller retries if larger).
    """
    capacity = out.shape[0]
    count = 0
    for iy in range(ny):
        for iz in range(nz):
            column = (iy * nz + iz) * nx
            for ix in range(nx):
                h0 = start[column + ix]
                h1 = start[column + ix + 1]
                if h0 == h1:
                    continue
                for side in range(5):
                    if side == 0:
                        jy = iy
                        jz = iz
                    elif side == 1:
                        jy = iy
                        jz = iz + 1
                    else:
                        jy = iy + 1
                        jz = iz + side - 3
                    if jy >= ny or jz < 0 or jz >= nz:
                        continue
                    base = (jy * nz + jz) * nx
                    o1 = start[base + min(ix + 2, nx)]
                    o0 = start[base + max(ix - 1, 0)]
                    for p in range(h0, h1):
                        px = sx[p]
                        py = sy[p]
                        pz = sz[p]
                        pr = sr[p]
                        for q in range(p + 1 if side == 0 else o0, o1):
                            ddx = px - sx[q]
                            ddy = py - sy[q]
                            ddz = pz - sz[q]
                            s = pr + sr[q]
                            if (ddx * ddx + ddy * ddy + ddz * ddz <= s * s
                                    and abs(ddx) <= s and abs(ddy) <= s and abs(ddz) <= s):
                                if count < capacity:
                                    out[count, 0] = sid[p]
                                    out[count, 1] = sid[q]
                                count += 1
    return count


@njit
def _large_sphere_pairs(c, r, large, out, count):
    """Append to ``out`` (from row ``count``) the pairs of the spheres kept out of the grid."""
    n = c.shape[0]
    # spheres too large for the grid: against every sphere (once per pair of large spheres)
    for i in range(n):
        if not large[i]:
            continue
        for j in range(n):
            if j == i or (large[j] and j < i):
                continue
            if _spheres_touch(c, r, i, j):
                out, count = push_pair(out, count, i, j)
    return out, count


_WORK = threading.local()  # per-thread work arrays of the sphere grid, reused between calls


def _work_array(name: str, size: int, dtype) -> np.ndarray:
    """A per-thread work array of at least ``size`` elements (grown by 25 %, never shrunk): reusing it saves
    the page faults of fresh allocations, a large share of the time at 1e5-1e6 spheres."""
    arr = getattr(_WORK, name, None)
    if arr is None or arr.shape[0] < size:
        arr = np.empty(max(16, size + size // 4), dtype=dtype)
        setattr(_WORK, name, arr)
    return arr


def _sphere_grid_pairs(c, r, large, cell_size, equal_radii=False):
    """Grid broad phase + exact test of spheres (n, 3), radii (n,); canonical pairs."""
    n = c.shape[0]
    origin, inv, nx, ny, nz = _sphere_grid_shape(c, cell_size)
    n_cells = nx * ny * nz
    radix = n_cells > _DIRECT_SORT_CELLS
    m = n if radix else 1
    sorted_arrays = [_work_array(name, n, np.float64) for name in ("sx", "sy", "sz", "sr")]
    n_small = _sphere_grid_sort(
        c, r, large, origin, inv, nx, ny, nz, _work_array("cell", n, np.int64),
        _work_array("start", n_cells + 1, np.int64), *sorted_arrays, _work_array("sid", n, np.int64),
        _work_array("b_cell", m, np.int64), *[_work_array(name, m, np.float64) for name in ("bx", "by", "bz", "br")],
        _work_array("b_id", m, np.int64))
    grid = (nx, ny, nz, _WORK.start[: n_cells + 1], *[a[:n_small] for a in sorted_arrays], _WORK.sid[:n_small])
    out = _work_pairs(max(16, n))
    count = _sphere_grid_sweep(*grid, out)
    if count > out.shape[0]:
        out = _work_pairs(count)
        count = _sphere_grid_sweep(*grid, out)
    if not equal_radii:
        out, count = _large_sphere_pairs(c, r, large, out, count)
    return canonicalise_pairs(out, count, n)


def _work_pairs(rows: int) -> np.ndarray:
    """A per-thread (rows, 2) int64 work buffer for candidate pairs."""
    buf = getattr(_WORK, "pairs", None)
    if buf is None or buf.shape[0] < rows:
        buf = np.empty((max(16, rows + rows // 4), 2), dtype=np.int64)
        _WORK.pairs = buf
    return buf


@njit
def _exact_filter_kernel(candidates, c, r):
    """The candidate pairs (canonical, (m, 2)) whose spheres touch, in the same order."""
    keep = np.empty(candidates.shape[0], dtype=np.bool_)
    for t in range(candidates.shape[0]):
        keep[t] = _spheres_touch(c, r, candidates[t, 0], candidates[t, 1])
    return candidates[keep]


def _as_spheres(centers, radii):
    c = as_float_array(centers, "centers", ndim=2)
    if c.shape[1] not in (1, 2, 3):
        raise ValueError(f"centers must have shape (n, d) with d = 1, 2 or 3, got {c.shape}")
    n = c.shape[0]
    if np.ndim(radii) == 0:
        r = np.full(n, as_nonnegative(radii, "radii"))
        equal = True
    else:
        r = as_float_array(radii, "radii", shape=(n,))
        negative = np.flatnonzero(r < 0.0)
        if negative.size:
            raise ValueError(f"radii must be >= 0: radii[{negative[0]}] = {r[negative[0]]!r}")
        equal = False
    if c.shape[1] < 3:
        c3 = np.zeros((n, 3))
        c3[:, : c.shape[1]] = c
        c = c3
    return c, r, equal


@njit
def _scene_stats(c, r, large):
    """(largest |coordinate| + largest radius, largest radius outside ``large``, mean spacing (V/n)^(1/k))."""
    n = c.shape[0]
    lo, hi = _point_bounds(c)
    r_all = 0.0
    r_small = 0.0
    for i in range(n):
        r_all = max(r_all, r[i])
        if not large[i]:
            r_small = max(r_small, r[i])
    scale = 0.0
    volume = 1.0
    used = 0
    for k in range(3):
        scale = max(scale, abs(lo[k]), abs(hi[k]))
        if hi[k] > lo[k]:
            volume *= hi[k] - lo[k]
            used += 1
    spacing = (volume / n) ** (1.0 / used) if used > 0 else 0.0
    return scale + r_all, r_small, spacing


def sphere_pairs(centers, radii, method: str = "grid") -> np.ndarray:
    """All pairs of spheres with |c_i − c_j| <= r_i + r_j (touching counts), broad phase + exact test.

    centers: (n, d), d in {1, 2, 3}; radii: a scalar or (n,), >= 0. method: "grid" (default, the fastest) or
    any name of ``BROAD_PHASES`` (run on the spheres' bounding boxes). Returns canonical pairs, int64 (k, 2).
    """
    from engine.broadphase import BROAD_PHASES, find_pairs

    method = as_choice(method, "method", BROAD_PHASES)
    c, r, equal = _as_spheres(centers, radii)
    n = c.shape[0]
    if n < 2:
        return empty_pairs()
    if equal:
        large = np.zeros(n, dtype=np.bool_)
    else:
        large = r > 4.0 * float(np.median(r))
        if large.all():
            large[:] = False
    scale, r_cell, spacing = _scene_stats(c, r, large)
    margin = 16.0 * _EPS * scale  # covers the rounding of coordinate differences and radius sums
    if method == "grid":
        cell = max(2.0 * r_cell * (1.0 + 1e-9) + margin, _SPACING_FACTOR * spacing)
        return _sphere_grid_pairs(c, r, large, cell if cell > 0.0 else 1.0, equal)
    widen = r + margin
    candidates = find_pairs(c - widen[:, None], c + widen[:, None], method=method)
    return _exact_filter_kernel(candidates, c, r)


def spheres_overlap_pairs(centers, radii, pairs) -> np.ndarray:
    """Keep the rows of canonical ``pairs`` ((m, 2) int64) whose spheres touch (the exact narrow test)."""
    c, r, _ = _as_spheres(centers, radii)
    candidates = canonical_pairs(pairs, n=c.shape[0])
    return _exact_filter_kernel(candidates, c, r)
