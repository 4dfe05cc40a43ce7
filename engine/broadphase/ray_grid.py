"""A uniform grid of boxes walked by rays: the 3-D digital differential analyser of Amanatides and Woo (1987).

Chapter slides "Phase Large : Subdivision spatiale" (the uniform cut), asked a ray instead of a box: Ericson,
*Real-Time Collision Detection* 7.4.2 (grid traversal). The ray's parameter t at the next cell boundary along each
axis, ``t_next``, grows by ``t_delta`` = side / abs(d_k) per step; the walk steps along the axis whose boundary comes
first, so it visits exactly the cells the ray crosses, in order of t. A nearest-hit query stops as soon as its
best hit lies before the exit of the current cell: a body further on is met in a later cell, at a larger t.

- ``build_ray_grid(lo, hi)``: cells of side twice the boxes' mean largest side (as ``grid_pairs``), enlarged if
  needed to at most ~8·n cells, over the boxes' bounds; every box is entered in each cell its box, grown by a
  relative 1e-9 of the side (so a cell index rounded at a boundary still finds it), covers — a counting sort on
  the cell number. Boxes covering more than ``MAX_CELLS_PER_BOX`` cells are kept in a list of their own (the
  caller tests them apart).
- ``dda_start`` / ``dda_step``: the walk's state, from the point where the ray enters the grid.
"""
from __future__ import annotations

from collections import namedtuple

import numpy as np

from engine._config import njit
from engine.broadphase.counting_sort import grid_dims

__all__ = ["RayGrid", "MAX_CELLS_PER_BOX", "build_ray_grid", "dda_start", "dda_step"]

#: boxes covering more cells than this stay out of the grid (``RayGrid.large``)
MAX_CELLS_PER_BOX = 64

#: ``origin`` (3,) the grid's lowest corner, ``top`` (3,) its highest, ``side`` the cells' side, ``dims`` (3,)
#: int64 cells per axis, ``start`` (cells + 1,) and ``items`` (entries,): the boxes of cell c are
#: items[start[c]:start[c + 1]] (cell c = (i·ny + j)·nz + k), ``large`` the boxes kept out of the grid — box
#: numbers are rows of the lo, hi given to ``build_ray_grid``
RayGrid = namedtuple("RayGrid", "origin top side dims start items large")


@njit(inline="always")
def _cell(x, origin, side, n):
    c = int(np.floor((x - origin) / side))
    return min(max(c, 0), n - 1)


@njit
def _count_and_fill(lo, hi, origin, side, dims, grow):
    """(start, items, large) of the counting sort of the boxes into the cells they cover."""
    n_cells = dims[0] * dims[1] * dims[2]
    start = np.zeros(n_cells + 1, np.int64)
    large = np.zeros(lo.shape[0], np.bool_)
    for fill in range(2):
        cursor = start[:-1].copy() if fill else start
        items = np.empty(start[-1] if fill else 0, np.int64)
        for b in range(lo.shape[0]):
            r = np.empty(6, np.int64)
            for k in range(3):
                r[2 * k] = _cell(lo[b, k] - grow, origin[k], side, dims[k])
                r[2 * k + 1] = _cell(hi[b, k] + grow, origin[k], side, dims[k])
            if (r[1] - r[0] + 1) * (r[3] - r[2] + 1) * (r[5] - r[4] + 1) > MAX_CELLS_PER_BOX:
                large[b] = True
                continue
            for i in range(r[0], r[1] + 1):
                for j in range(r[2], r[3] + 1):
                    for k in range(r[4], r[5] + 1):
                        c = (i * dims[1] + j) * dims[2] + k
                        if fill:
                            items[cursor[c]] = b
                            cursor[c] += 1
                        else:
                            start[c + 1] += 1
        if not fill:
            for c in range(n_cells):
                start[c + 1] += start[c]
    return start, items, np.flatnonzero(large)


def build_ray_grid(lo: np.ndarray, hi: np.ndarray) -> RayGrid:
    """The grid of the boxes [lo_i, hi_i] ((n, 3) float64 each, finite, n >= 1) for ray walks (module docstring)."""
    origin, top = lo.min(axis=0), hi.max(axis=0)
    side = max(2.0 * float((hi - lo).max(axis=1).mean()), 1e-12 * max(1.0, float(np.abs(top - origin).max())))
    max_cells = max(8.0 * lo.shape[0], 64.0)
    side, nx, ny, nz = grid_dims(origin, top, side, max_cells, max_cells)
    dims = np.array([nx, ny, nz], np.int64)
    start, items, large = _count_and_fill(lo, hi, origin, side, dims, 1e-9 * side)
    return RayGrid(origin, origin + dims * side, float(side), dims, start, items, large)


@njit(inline="always")
def _axis_start(o, d, t, origin, side, n):
    """(cell, step, t_next, t_delta) of one axis for a walk that starts at parameter t."""
    c = _cell(o + t * d, origin, side, n)
    if d > 0.0:
        return c, 1, (origin + (c + 1) * side - o) / d, side / d
    if d < 0.0:
        return c, -1, (origin + c * side - o) / d, -side / d
    return c, 0, np.inf, np.inf


@njit(inline="always")
def dda_start(o, d, t_enter, origin, side, dims):
    """The walk's state where the ray o + t·d (3-tuples) enters the grid at t_enter: (cells (3-tuple), steps,
    t_next, t_delta)."""
    cx, sx, nx, dx = _axis_start(o[0], d[0], t_enter, origin[0], side, dims[0])
    cy, sy, ny, dy = _axis_start(o[1], d[1], t_enter, origin[1], side, dims[1])
    cz, sz, nz, dz = _axis_start(o[2], d[2], t_enter, origin[2], side, dims[2])
    return (cx, cy, cz), (sx, sy, sz), (nx, ny, nz), (dx, dy, dz)


@njit(inline="always")
def dda_step(cells, steps, t_next, t_delta, dims):
    """One step of the walk: (cells, t_next, inside) — the next cell along the axis whose boundary comes first,
    and whether it is still in the grid."""
    cx, cy, cz = cells
    nx, ny, nz = t_next
    if nx <= ny and nx <= nz:
        cx += steps[0]
        nx += t_delta[0]
        inside = 0 <= cx < dims[0]
    elif ny <= nz:
        cy += steps[1]
        ny += t_delta[1]
        inside = 0 <= cy < dims[1]
    else:
        cz += steps[2]
        nz += t_delta[2]
        inside = 0 <= cz < dims[2]
    return (cx, cy, cz), (nx, ny, nz), inside
