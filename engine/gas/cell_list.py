"""The cell list of the event-driven gas: a uniform grid of cubic cells, each a doubly linked list of spheres.

Ericson, *Real-Time Collision Detection* 7.1.5 (grids as linked lists of objects); Rapaport, *The Art of
Molecular Dynamics Simulation* 14.3. Cells are at least one largest diameter wide, so a sphere can only touch
the spheres of its own and of the 26 neighbouring cells; the cells tile [−L/2, L/2)³ exactly, so with periodic
boundaries the neighbours of an edge cell are the cells of the opposite face, met through an image shifted by ±L.
Removing a sphere from its cell is O(1) (the ``prev`` links), which the cell crossings of the gas need.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from engine._config import njit

__all__ = ["CellList", "new_cell_list", "cell_fill", "cell_of", "cell_insert", "cell_remove", "cell_step",
           "neighbour_cell"]


class CellList(NamedTuple):
    """cell: (n, 3) int64 each sphere's cell coordinates; head: (ncell³,) int64 first sphere of each cell (−1:
    empty); next, prev: (n,) int64 the links of the cell lists (−1: none); half = L/2, box = L, width = L/ncell
    (float); ncell: cells per axis (int); periodic (bool)."""

    cell: np.ndarray
    head: np.ndarray
    next: np.ndarray
    prev: np.ndarray
    half: float
    box: float
    width: float
    ncell: int
    periodic: bool


def new_cell_list(n: int, box: float, ncell: int, periodic: bool) -> CellList:
    """Empty lists for n spheres in ncell³ cells of side box/ncell (filled by ``cell_fill``)."""
    return CellList(np.zeros((n, 3), dtype=np.int64), np.empty(ncell**3, dtype=np.int64),
                    -np.ones(n, dtype=np.int64), -np.ones(n, dtype=np.int64), box / 2.0, box, box / ncell,
                    int(ncell), bool(periodic))


@njit(error_model="numpy")
def cell_of(cells, i):
    """Flat index (cx · ncell + cy) · ncell + cz of sphere i's cell."""
    n = cells.ncell
    return (cells.cell[i, 0] * n + cells.cell[i, 1]) * n + cells.cell[i, 2]


@njit(error_model="numpy")
def cell_insert(cells, i):
    """Push sphere i at the head of the list of its cell (``cells.cell[i]``)."""
    c = cell_of(cells, i)
    h = cells.head[c]
    cells.next[i] = h
    cells.prev[i] = -1
    if h >= 0:
        cells.prev[h] = i
    cells.head[c] = i


@njit(error_model="numpy")
def cell_remove(cells, i):
    """Unlink sphere i from the list of its cell (``cells.cell[i]``)."""
    nxt, prv = cells.next, cells.prev
    c = cell_of(cells, i)
    if prv[i] >= 0:
        nxt[prv[i]] = nxt[i]
    else:
        cells.head[c] = nxt[i]
    if nxt[i] >= 0:
        prv[nxt[i]] = prv[i]


@njit(error_model="numpy")
def cell_fill(cells, positions):
    """Put every sphere in the cell that contains its centre (positions: (n, ≥3) float64, x, y, z in the first
    three columns); centres on the outer faces go to the edge cells."""
    cells.head[:] = -1
    for i in range(positions.shape[0]):
        for k in range(3):
            c = int(math.floor((positions[i, k] + cells.half) / cells.width))
            cells.cell[i, k] = min(cells.ncell - 1, max(0, c))
        cell_insert(cells, i)


@njit(error_model="numpy")
def cell_step(cells, i, axis, up):
    """Move sphere i to the next cell along ``axis`` (up: +1 side, else −1). Returns the shift (0, −L or +L) its
    coordinate takes when it leaves through a periodic face and enters the opposite cell."""
    cell, ncell, box = cells.cell, cells.ncell, cells.box
    cell_remove(cells, i)
    c = cell[i, axis] + (1 if up else -1)
    shift = 0.0
    if c >= ncell:
        c = 0
        shift = -box
    elif c < 0:
        c = ncell - 1
        shift = box
    cell[i, axis] = c
    cell_insert(cells, i)
    return shift


@njit(error_model="numpy")
def neighbour_cell(c, d, ncell, box, periodic):
    """Along one axis, the coordinate of the cell at offset d (−1, 0, 1) from cell coordinate c, and the shift
    (0, ±L) of the image its spheres are met through; (−1, 0.0) when that cell lies beyond a wall."""
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
