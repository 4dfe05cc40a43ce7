"""engine — collision detection for game physics: whether, where and when two objects collide.

Every public name of DESIGN.md section 3 is importable from here; see engine/ARCHITECTURE.md for the map from
modules to the chapter's slides, their oracles and their property files.
"""
from __future__ import annotations

from .dynamics.bisection import BisectionResult, bisect
from .dynamics.rk4 import rk4_step, split_state, state_vector
from .dynamics.scenes import CubeDrop, FallResult, Impact, drop_cube, drop_particle

__version__ = "0.1.0"

__all__ = [
    # dynamics: falling bodies, RK4, Algorithme 3
    "rk4_step",
    "state_vector",
    "split_state",
    "bisect",
    "BisectionResult",
    "drop_particle",
    "drop_cube",
    "FallResult",
    "CubeDrop",
    "Impact",
]
