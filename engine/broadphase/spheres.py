"""Sphere pairs: broad phase + exact sphere test, the fast path of the confined-gas simulation.

``sphere_pairs(centers, radii)`` returns exactly the pairs with ``|c_i − c_j| <= r_i + r_j``, computed as
``dx² + dy² + dz² <= (r_i + r_j)²`` in IEEE double precision (touching counts), together with
``|dx|, |dy|, |dz| <= r_i + r_j`` so that squares underflowing to zero (coordinates below ~1e-154) cannot make
distinct points touch.

The default method, "grid", is a uniform grid specialised to spheres (Ericson, *Real-Time Collision Detection*
7.1, and the chapter's "absolue" spatial subdivision): each sphere is stored once, in the cell of its centre,
cells at least one largest diameter wide (plus a round-off margin), so that two touching spheres lie in the same
or adjacent cells. When the scene is dense enough (at most ``sphere_cells.MAX_CELLS_PER_SPHERE`` cells per
sphere) the cells form a padded grid whose forward half stencil is five contiguous ranges of sorted spheres
(``engine.broadphase.sphere_cells``: one radix sort of cell keys, sorted coordinate arrays, a table of cell
ends, one flat loop per sphere). Sparser scenes use columns along x, sorted and swept like box pruning
(``engine.broadphase.sphere_columns``): columns are also at least ``SPACING_FACTOR`` × the mean spacing
(V/n)^(1/3) wide, so a sparse scene does not pay for empty columns, and far-apart clusters keep fine columns
(the keys become 64-bit and columns are found by binary search instead of a table), so they cost no more than
each cluster alone. Spheres much larger than the typical one (radius > 4 × median) are kept out of the grid and
tested against every sphere. ``threads`` > 1 sweeps disjoint ranges of spheres (cells) or of columns on that many
threads (the pairs are the same: they are put in canonical form).

Any other method of ``BROAD_PHASES`` runs that broad phase on the spheres' bounding boxes (widened by a
round-off margin so no touching pair is lost) and then applies the same exact test.
"""
from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

import engine.broadphase.pairs as pair_buffer
from engine._config import njit
from engine._validate import MAX_MAGNITUDE, as_choice, as_float_array, as_radii
from engine.bounding.sphere import spheres_touch
from engine.broadphase.counting_sort import bucket_offsets, radix_split
from engine.broadphase.pairs import as_threads, canonical_pairs, empty_pairs
from engine.broadphase.sphere_cells import (
    CellLayout,
    cell_ends,
    cell_layout,
    cell_words,
    place_in_cells,
    scatter_spheres,
    sort_into_cells,
    sweep_cells,
)
from engine.broadphase.sphere_columns import column_layout, home_columns, sort_into_columns, sweep_columns
from engine.broadphase.thread_pool import run_parts

__all__ = ["sphere_pairs", "spheres_overlap_pairs"]

_EPS = np.finfo(np.float64).eps
#: columns are at least this fraction of the mean spacing (V/n)^(1/3) wide
SPACING_FACTOR = 0.0
#: a thread sweeps at least this many spheres (below that, starting threads costs more than it saves)
MIN_SPHERES_PER_THREAD = 4096


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
                out, count = pair_buffer.push_pair(out, count, i, j)
    return out, count



def _sphere_grid_pairs(c: np.ndarray, r: np.ndarray, large: np.ndarray, bounds: tuple, cell_size: float,
                       equal_radii: bool, threads: int) -> np.ndarray:
    """Grid broad phase + exact test of spheres (n, 3), radii (n,), centres within bounds = (lo, hi): the
    padded cells of engine.broadphase.sphere_cells when there are few enough cells, the sorted columns of
    engine.broadphase.sphere_columns otherwise; canonical pairs. ``threads`` > 1 shares the sort by cell, then
    the sweep (disjoint ranges of spheres or of columns), then the canonical merge of the threads' pairs."""
    n = c.shape[0]
    cells = cell_layout(*bounds, cell_size, n)
    if cells.n_cells > 0:
        grid, items, work = _cell_grid(c, r, large, equal_radii, cells, threads)
        sweep = sweep_cells
    else:
        grid, items, work = _column_grid(c, r, large, bounds, cell_size)
        sweep = sweep_columns
    chunks = pair_buffer.split_work(work, threads, MIN_SPHERES_PER_THREAD)
    extra = None
    if not equal_radii:
        buf, count = _large_sphere_pairs(c, r, large, pair_buffer.new_pair_buffer(16), 0)
        extra = (buf, count, 0)
    if len(chunks) == 1:
        buf, count = _sweep_chunk(sweep, grid, chunks[0], pair_buffer.work_pair_buffer(max(16, n)))
        if extra is not None and extra[1] > 0:
            buf = np.concatenate([buf[:count], extra[0][: extra[1]]])
            count = buf.shape[0]
        return pair_buffer.canonicalise_buffer(buf, count, n)
    # each chunk records into a buffer of its own, held by this thread between calls (see sap's _sweep_sorted)
    names = [f"sphere_pairs_{t}" for t in range(len(chunks))]
    buffers = {chunk: _rows(pair_buffer.work_array(name, 2 * (n // len(chunks) + 16), np.int64))
               for name, chunk in zip(names, chunks)}

    def sweep_part(first: int, last: int) -> tuple[np.ndarray, int, int]:
        buf, count = _sweep_chunk(sweep, grid, (first, last), buffers[first, last])
        buffers[first, last] = buf
        return buf, count, 0

    pairs, _ = pair_buffer.run_split(sweep_part, chunks, n, extra=extra)
    for name, chunk in zip(names, chunks):  # the grown buffers serve the next call
        pair_buffer.keep_work_array(name, buffers[chunk].reshape(-1))
    return pairs


def _rows(flat: np.ndarray) -> np.ndarray:
    """A pair buffer (int64 (k, 2)) over the even-length start of the flat work array ``flat``."""
    return flat[: flat.shape[0] // 2 * 2].reshape(-1, 2)


def _cell_grid(c: np.ndarray, r: np.ndarray, large: np.ndarray, equal_radii: bool, layout: CellLayout,
               threads: int) -> tuple:
    """The spheres sorted by cell and the table of cell ends (engine.broadphase.sphere_cells), the passes shared
    by ``threads`` threads: (grid arguments of sweep_cells, its number m of sweep items (spheres), their work for
    split_work: m, as they are of about equal work)."""
    n = c.shape[0]
    chunks = pair_buffer.split_even(n, threads, MIN_SPHERES_PER_THREAD)
    if len(chunks) == 1:  # one thread: one radix sort, then the table (fewer passes than the two counting ones)
        return _cell_grid_one_thread(c, r, large, equal_radii, layout)
    shift, n_buckets = (int(v) for v in radix_split(layout.n_cells))
    words, order = (pair_buffer.work_array(name, n, np.int64) for name in ("cell_words", "cell_order"))
    grouped = pair_buffer.work_array("cell_grouped", 4 * n, np.float64)[: 4 * n].reshape(n, 4)
    grouped_radii = pair_buffer.work_array("cell_grouped_radii", n, np.float64)
    sorted_arrays = [pair_buffer.work_array(name, n, np.float64) for name in ("sx", "sy", "sz", "sr")]
    hist = np.zeros((len(chunks), n_buckets), dtype=np.int64)
    counts = run_parts(lambda t: cell_words(c, large, layout, *chunks[t], words, shift + 32, hist[t]),
                       range(len(chunks)))
    offsets, bucket_start = bucket_offsets(hist)
    run_parts(lambda t: scatter_spheres(words, chunks[t][0], counts[t], shift + 32, offsets[t], c, r, equal_radii,
                                        grouped, grouped_radii), range(len(chunks)))
    ends = pair_buffer.work_array("cell_ends", layout.n_cells, np.int32)
    # the second pass costs about one unit per sphere and one per 4 cells of its buckets
    work = bucket_start + (np.minimum(np.arange(n_buckets + 1) << shift, layout.n_cells) >> 2)
    run_parts(lambda part: place_in_cells(grouped, grouped_radii, bucket_start, *part, shift, layout.n_cells, r,
                                          equal_radii, order, ends, *sorted_arrays),
              pair_buffer.split_work(work, threads, MIN_SPHERES_PER_THREAD))
    m = int(bucket_start[-1])
    return (layout, order, ends, *sorted_arrays), m, m


def _cell_grid_one_thread(c: np.ndarray, r: np.ndarray, large: np.ndarray, equal_radii: bool,
                          layout: CellLayout) -> tuple:
    """``_cell_grid`` on this thread alone: the radix sort of sphere_cells.sort_into_cells, then cell_ends."""
    n = c.shape[0]
    order, order_tmp = (pair_buffer.work_array(name, n, np.int64) for name in ("cell_order", "cell_order_tmp"))
    sorted_arrays = [pair_buffer.work_array(name, n, np.float64) for name in ("sx", "sy", "sz", "sr")]
    m, order = sort_into_cells(c, r, large, equal_radii, layout, order, order_tmp, *sorted_arrays)
    ends = pair_buffer.work_array("cell_ends", layout.n_cells, np.int32)
    cell_ends(order, m, layout.n_cells, ends)
    return (layout, order, ends, *sorted_arrays), m, m


def _column_grid(c: np.ndarray, r: np.ndarray, large: np.ndarray, bounds: tuple, cell_size: float) -> tuple:
    """The sorted columns of engine.broadphase.sphere_columns: (grid arguments of sweep_columns, its number of
    sweep items (home columns), their cumulative work (spheres) for split_work)."""
    n = c.shape[0]
    if r.shape[0] != n:  # one radius for all (sphere_pairs' compact form): the columns gather n of them
        r = np.full(n, r[0])
    layout = column_layout(*bounds, cell_size, n)
    key_type = np.int32 if layout.dense else np.int64
    keys, keys_tmp = (pair_buffer.work_array(f"{name}_{key_type.__name__}", n + 1, key_type)
                      for name in ("keys", "keys_tmp"))
    index, index_tmp = (pair_buffer.work_array(name, n, np.int64) for name in ("index", "index_tmp"))
    sorted_arrays = [pair_buffer.work_array(name, n, np.float64) for name in ("sx", "sy", "sz", "sr")]
    m, skeys, sid = sort_into_columns(c, r, large, layout, keys, index, keys_tmp, index_tmp, *sorted_arrays,
                                      np.iinfo(key_type).max)
    col_ids, col_start = home_columns(skeys, m, layout)
    return (layout, skeys, m, *sorted_arrays, sid, col_ids, col_start), col_ids.shape[0], col_start


def _sweep_chunk(sweep, grid: tuple, chunk: tuple[int, int], buf: np.ndarray) -> tuple[np.ndarray, int]:
    """The sweeps of the items chunk = (first, last) of grid; returns (buffer, pair count), with a buffer grown
    to the count and swept again when the one given was too small."""
    count = sweep(*grid, chunk[0], chunk[1], buf, 0)
    if count > buf.shape[0]:
        buf = np.empty((count, 2), dtype=np.int64)
        count = sweep(*grid, chunk[0], chunk[1], buf, 0)
    return buf, count


@njit
def _exact_filter_kernel(candidates, c, r):
    """The candidate pairs (canonical, (m, 2)) whose spheres touch, in the same order."""
    keep = np.empty(candidates.shape[0], dtype=np.bool_)
    for t in range(candidates.shape[0]):
        keep[t] = _spheres_touch(c, r, candidates[t, 0], candidates[t, 1])
    return candidates[keep]


@njit
def _bounds_within(a, limit):
    """(whether every |a[i, k]| <= limit (False on a NaN), the lowest and the highest coordinate along each axis
    (3,) each) of a (n, 3): the finiteness check of as_float_array and the centres' bounds in one pass, without a
    copy (the bounds are meaningful only when the check passes). Scalar accumulators and selects, no early
    exit: the loop has no branch, and it reads the centres once where a check and a bounds pass would read them
    twice (bench/test_bench_broadphase.py, the W2 spheres group, times it within ``sphere_pairs``)."""
    lo_x = lo_y = lo_z = np.inf
    hi_x = hi_y = hi_z = -np.inf
    within = True
    for i in range(a.shape[0]):
        x, y, z = a[i, 0], a[i, 1], a[i, 2]
        within &= (abs(x) <= limit) & (abs(y) <= limit) & (abs(z) <= limit)
        lo_x, hi_x = (x if x < lo_x else lo_x), (x if x > hi_x else hi_x)
        lo_y, hi_y = (y if y < lo_y else lo_y), (y if y > hi_y else hi_y)
        lo_z, hi_z = (z if z < lo_z else lo_z), (z if z > hi_z else hi_z)
    return within, np.array([lo_x, lo_y, lo_z]), np.array([hi_x, hi_y, hi_z])


def _as_centres(centers: ArrayLike) -> tuple[np.ndarray, tuple | None]:
    """The checked centres and, when known already, their bounds (lo, hi): a caller's C-contiguous float64
    (n, 3) array of finite values is used as it is (no kernel writes to it), its bounds found by the same pass
    as the check; anything else gets as_float_array's copy and checks (and its error messages), and no bounds."""
    if (isinstance(centers, np.ndarray) and centers.dtype == np.float64 and centers.ndim == 2
            and centers.shape[1] == 3 and centers.flags.c_contiguous):
        within, lo, hi = _bounds_within(centers, MAX_MAGNITUDE)
        if within:
            return centers, (lo, hi)
    return as_float_array(centers, "centers", ndim=2), None


def _as_spheres(centers: ArrayLike, radii: ArrayLike, compact: bool = False,
                ) -> tuple[np.ndarray, np.ndarray, bool, tuple]:
    """(centres (n, 3), radii (n,), whether the radii were one scalar, the centres' bounds (lo, hi)); with
    ``compact``, one scalar radius is returned as a (1,) array rather than n copies of it."""
    c, bounds = _as_centres(centers)
    if c.shape[1] not in (1, 2, 3):
        raise ValueError(f"centers must have shape (n, d) with d = 1, 2 or 3, got {c.shape}")
    n = c.shape[0]
    equal = np.ndim(radii) == 0
    r = as_radii(radii, "radii", 1 if equal and compact else n)
    if c.shape[1] < 3:
        c3 = np.zeros((n, 3))
        c3[:, : c.shape[1]] = c
        c = c3
    return c, r, equal, bounds if bounds is not None else _point_bounds(c)


@njit
def _scene_stats(n, r, large, lo, hi):
    """(largest |coordinate| + largest radius, largest radius outside ``large``, mean spacing (V/n)^(1/k)) of
    the n spheres of radii r (or of the one radius r[0] of them all, r (1,)) whose centres lie within the bounds
    lo, hi ((3,) each)."""
    r_all = 0.0
    r_small = 0.0
    for i in range(r.shape[0]):
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


def sphere_pairs(centers: ArrayLike, radii: ArrayLike, method: str = "grid", *, threads: int = 1) -> np.ndarray:
    """All pairs of spheres with ``|c_i − c_j| <= r_i + r_j`` (touching counts): broad phase, then the exact test.

    The test is ``dx² + dy² + dz² <= (r_i + r_j)²`` in IEEE double precision (made on rescaled values when the
    squares would underflow), so the pairs are exactly those of the brute-force test, whatever the method.

    Parameters
    ----------
    centers : array_like, shape (n, d)
        The centres, d = 1, 2 or 3, finite (converted to float64; a C-contiguous float64 (n, 3) array is read
        without a copy and never written).
    radii : float or array_like, shape (n,)
        The radii, >= 0; a scalar for equal spheres.
    method : str, optional
        "grid" (the default and the fastest: sorted columns of a uniform grid specialised to spheres), or any
        other name of ``BROAD_PHASES``, run on the spheres' bounding boxes.
    threads : int, optional
        How many threads may share the work, 1 to 256 (the same answer, bit for bit).

    Returns
    -------
    numpy.ndarray, shape (k, 2), int64
        Canonical pairs: ``i < j`` in every row, rows sorted, no duplicate.

    Raises
    ------
    ValueError
        For NaN, ±inf or magnitudes above 1e150, a shape other than (n, d) with d in {1, 2, 3} for ``centers``
        or (n,) for ``radii``, a negative radius (the message names its index), an unknown ``method`` or
        ``threads`` out of range.
    TypeError
        For non-numeric arrays, a ``method`` that is not a string, or ``threads`` that is not an int.

    See Also
    --------
    find_pairs : the same contract for boxes.
    spheres_overlap_pairs : the exact test alone, on given candidate pairs.

    Examples
    --------
    >>> from engine.broadphase import sphere_pairs
    >>> sphere_pairs([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [3.0, 0.0, 0.0]], 0.5)  # spheres 0 and 1 touch
    array([[0, 1]])
    """
    from engine.broadphase import BROAD_PHASES, find_pairs

    method = as_choice(method, "method", BROAD_PHASES)
    threads = as_threads(threads)
    c, r, equal, (lo, hi) = _as_spheres(centers, radii, compact=method == "grid")
    n = c.shape[0]
    if n < 2:
        return empty_pairs()
    if equal:
        large = np.zeros(n, dtype=np.bool_)
    else:
        large = r > 4.0 * float(np.median(r))
        if large.all():
            large[:] = False
    scale, r_cell, spacing = _scene_stats(n, r, large, lo, hi)
    margin = 16.0 * _EPS * scale  # covers the rounding of coordinate differences and radius sums
    if method == "grid":
        cell = max(2.0 * r_cell * (1.0 + 1e-9) + margin, SPACING_FACTOR * spacing)
        return _sphere_grid_pairs(c, r, large, (lo, hi), cell if cell > 0.0 else 1.0, equal, threads)
    widen = r + margin
    candidates = find_pairs(c - widen[:, None], c + widen[:, None], method=method, threads=threads)
    return _exact_filter_kernel(candidates, c, r)


def spheres_overlap_pairs(centers: ArrayLike, radii: ArrayLike, pairs: ArrayLike) -> np.ndarray:
    """The candidate pairs whose spheres touch or overlap: the exact test of :func:`sphere_pairs` alone.

    Parameters
    ----------
    centers : array_like, shape (n, d)
        The centres, d = 1, 2 or 3, finite.
    radii : float or array_like, shape (n,)
        The radii, >= 0; a scalar for equal spheres.
    pairs : array_like of int, shape (m, 2)
        Candidate pairs of indices in [0, n), in any order (they are put in canonical form first).

    Returns
    -------
    numpy.ndarray, shape (k, 2), int64
        The canonical pairs with ``|c_i − c_j| <= r_i + r_j``: a subset of ``pairs``.

    Raises
    ------
    ValueError
        For invalid spheres (as :func:`sphere_pairs`), or an index of ``pairs`` outside [0, n).
    TypeError
        For non-numeric arrays, or ``pairs`` that are not integers.
    """
    c, r, _, _ = _as_spheres(centers, radii)
    candidates = canonical_pairs(pairs, n=c.shape[0])
    return _exact_filter_kernel(candidates, c, r)
