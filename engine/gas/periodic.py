"""The periodic box [−L/2, L/2)³: the minimum image of a separation and the wrap of a coordinate.

Both gas methods use the minimum-image convention (Allen & Tildesley, *Computer Simulation of Liquids*, 1.5.2):
of all the periodic images of sphere j, sphere i meets the nearest one, r_ij − L round(r_ij / L).
"""
from __future__ import annotations

import math

import numpy as np

from engine.gas.kernels import state_kernel

__all__ = ["minimum_image", "wrap_coordinate", "wrapped_into_box"]


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
