"""The cell list of the event-driven gas: a uniform grid of cubic cells, each a doubly linked list of spheres.

Ericson, *Real-Time Collision Detection* 7.1.5 (grids as linked lists of objects); Rapaport, *The Art of
Molecular Dynamics Simulation* 14.3. Cells are at least one largest diameter wide, so a sphere can only touch
the spheres of its own and of the 26 neighbouring cells; the cells tile [−L/2, L/2)³ exactly, so with periodic
boundaries the neighbours of an edge cell are the cells of the opposite face, met through an image shifted by ±L.
Removing a sphere from its cell is O(1) (the ``prev`` links), which the cell crossings of the gas need.

Each sphere's links and cell coordinates are one 16-byte record (``LINK``), so that following a list touches
one small array, which stays in the processor's cache.

The gas's searches size their cells at least 2 r_max (1 + ``CELL_MARGIN``) wide: the relative margin keeps a cell
wider than a diameter once the cell width L/ncell and the centres carry their round-off.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from engine.gas.kernels import state_kernel

__all__ = ["LINK", "CellList", "new_cell_list", "cell_fill", "cell_of", "cell_insert", "cell_remove", "cell_step",
           "neighbour_cell", "CELL_MARGIN"]

#: the relative margin over one largest diameter of the narrowest cell the searches make (see the docstring)
CELL_MARGIN = 1e-12

#: a sphere's place in the cell lists: the next and previous sphere of its cell (−1: none), its cell coordinates
LINK = np.dtype([("next", np.int32), ("prev", np.int32), ("cell", np.int16, (3,))], align=True)


class CellList(NamedTuple):
    """links: (n,) LINK records; head: (ncell³,) int32 the first sphere of each cell (−1: empty); half = L/2,
    box = L, width = L/ncell (float); ncell: cells per axis (int, at most 2^10); periodic (bool)."""

    links: np.ndarray
    head: np.ndarray
    half: float
    box: float
    width: float
    ncell: int
    periodic: bool


def new_cell_list(n: int, box: float, ncell: int, periodic: bool) -> CellList:
    """Empty lists for n < 2^31 spheres in ncell³ cells of side box/ncell (filled by ``cell_fill``)."""
    if not 1 <= ncell <= 1024:
        raise ValueError(f"ncell must lie in [1, 1024], got {ncell}")
    links = np.zeros(n, dtype=LINK)
    links["next"] = -1
    links["prev"] = -1
    return CellList(links, np.full(ncell**3, -1, dtype=np.int32), box / 2.0, box, box / ncell, int(ncell),
                    bool(periodic))


@state_kernel
def cell_of(cells, i):
    """Flat index (cx · ncell + cy) · ncell + cz of sphere i's cell."""
    n = cells.ncell
    c = cells.links[i]["cell"]
    return (np.int64(c[0]) * n + c[1]) * n + c[2]


@state_kernel
def cell_insert(cells, i):
    """Push sphere i at the head of the list of its cell (``links[i]["cell"]``)."""
    links = cells.links
    c = cell_of(cells, i)
    h = cells.head[c]
    links[i]["next"] = h
    links[i]["prev"] = -1
    if h >= 0:
        links[h]["prev"] = i
    cells.head[c] = i


@state_kernel
def cell_remove(cells, i):
    """Unlink sphere i from the list of its cell (``links[i]["cell"]``)."""
    links = cells.links
    nxt, prv = links[i]["next"], links[i]["prev"]
    if prv >= 0:
        links[prv]["next"] = nxt
    else:
        cells.head[cell_of(cells, i)] = nxt
    if nxt >= 0:
        links[nxt]["prev"] = prv


@state_kernel
def cell_fill(cells, positions):
    """Put every sphere in the cell that contains its centre (positions: (n, ≥3) float64, x, y, z in the first
    three columns); centres on the outer faces go to the edge cells."""
    cells.head[:] = -1
    for i in range(positions.shape[0]):
        for k in range(3):
            c = int(math.floor((positions[i, k] + cells.half) / cells.width))
            cells.links[i]["cell"][k] = min(cells.ncell - 1, max(0, c))
        cell_insert(cells, i)


@state_kernel
def cell_step(cells, i, axis, up):
    """Move sphere i to the next cell along ``axis`` (up: +1 side, else −1). Returns the shift (0, −L or +L) its
    coordinate takes when it leaves through a periodic face and enters the opposite cell."""
    cell, ncell, box = cells.links[i]["cell"], cells.ncell, cells.box
    cell_remove(cells, i)
    c = cell[axis] + (1 if up else -1)
    shift = 0.0
    if c >= ncell:
        c = 0
        shift = -box
    elif c < 0:
        c = ncell - 1
        shift = box
    cell[axis] = c
    cell_insert(cells, i)
    return shift


@state_kernel
def neighbour_cell(c, d, ncell, box, periodic):
    """Along one axis, the coordinate of the cell at offset d from cell coordinate c (|d| <= 2 < ncell + 1), and
    the shift (0, ±L) of the image its spheres are met through; (−1, 0.0) when that cell lies beyond a wall."""
    c += d
    if c < 0:
        if not periodic:
            return -1, 0.0
        return c + ncell, -box
    if c >= ncell:
        if not periodic:
            return -1, 0.0
        return c - ncell, box
    return c, 0.0
