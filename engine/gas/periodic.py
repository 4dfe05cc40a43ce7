"""The periodic box [−L/2, L/2)³: the minimum image of a separation and the wrap of a coordinate.

Both gas methods use the minimum-image convention (Allen & Tildesley, *Computer Simulation of Liquids*, 1.5.2):
of all the periodic images of sphere j, sphere i meets the nearest one, r_ij − L round(r_ij / L).
"""
from __future__ import annotations

import math

from engine.gas.kernels import state_kernel

__all__ = ["minimum_image", "wrap_coordinate"]


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
