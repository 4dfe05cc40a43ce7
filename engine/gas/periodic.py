"""The periodic box [−L/2, L/2)³: the boxes allowed, the minimum image of a separation and the wrap of a coordinate.

Both gas methods use the minimum-image convention (Allen & Tildesley, *Computer Simulation of Liquids*, 1.5.2):
of all the periodic images of sphere j, sphere i meets the nearest one, r_ij − L round(r_ij / L).

The periodic-box rule, checked by ``check_periodic_box`` for ``simulate_gas``, for the validation of a gas state
(both methods) and for the event-driven cell list: L >= 3 · 2 r_max (1 + ``CELL_MARGIN``), a box at least 3 largest
diameters wide. The event-driven cell list needs 3 cells per axis, each at least one largest diameter wide with the
cell list's round-off margin, so that the 27 cells around a cell are distinct (with 2 cells per axis, or 1, the
cells at offsets −1 and +1 are the same cell). Such a box also keeps the minimum image unique: two spheres touch at
a distance σ <= L/3 < L/2, so through one image only. The stepped method follows the same rule, so that both methods
accept the same states. (The neighbour-list search asks more: 3 cells of (1 + α) diameters per axis,
``list_cells_per_axis`` in engine/gas/neighbour_list.py.)
"""
from __future__ import annotations

import math

import numpy as np

from engine.gas.cell_list import CELL_MARGIN
from engine.gas.kernels import state_kernel

__all__ = ["check_periodic_box", "minimum_image", "wrap_coordinate", "wrapped_into_box"]


def check_periodic_box(box: float, rmax: float, name: str) -> None:
    """Refuse a periodic box narrower than 3 largest diameters: L >= 3 · 2 r_max (1 + ``CELL_MARGIN``).

    ``box`` is L, ``rmax`` the largest radius and ``name`` the caller's argument that gave the radii ("radius",
    "radii"), which the ValueError names first.
    """
    if box < 3.0 * 2.0 * rmax * (1.0 + CELL_MARGIN):
        raise ValueError(f"{name} too large for the periodic box: a periodic box must be at least 3 diameters wide "
                         f"(box >= 6 r (1 + {CELL_MARGIN!r})): largest radius {rmax!r}, box {box!r}")


@state_kernel
def minimum_image(rx, ry, rz, box):
    """The separation (rx, ry, rz) of two centres reduced to its nearest periodic image (box side L = ``box``)."""
    rx -= box * round(rx / box)
    ry -= box * round(ry / box)
    rz -= box * round(rz / box)
    return rx, ry, rz


@state_kernel
def wrap_coordinate(x, half):
    """A coordinate x wrapped into [−L/2, L/2) (L = 2 half); round-off of the wrap that lands on L/2 goes to −L/2."""
    box = 2.0 * half
    x -= box * math.floor((x + half) / box)
    if x >= half:
        x -= box
    return x


@state_kernel
def _wrap_all(p, out, half):
    for i in range(p.shape[0]):
        for k in range(3):
            out[i, k] = wrap_coordinate(p[i, k], half)


def wrapped_into_box(positions: np.ndarray, box: float) -> np.ndarray:
    """Centres (n, 3) float64 wrapped into [−L/2, L/2)³ (``wrap_coordinate`` on each), as a new array."""
    out = np.empty((positions.shape[0], 3))
    _wrap_all(positions, out, 0.5 * float(box))
    return out
