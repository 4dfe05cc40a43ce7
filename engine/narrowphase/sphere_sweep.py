"""The time of impact of two translating spheres (Ericson 5.5.5, "Intersecting moving sphere against sphere").

With d0 = c_b − c_a, w = v_b − v_a and R = r_a + r_b, the spheres touch when |d0 + w t| = R, the quadratic
|w|² t² + 2 (d0·w) t + |d0|² − R² = 0. Its smaller root is taken in the form c / (−b' + √(b'² − a c)), which
never subtracts nearly equal numbers (b' = d0·w < 0 while they approach).
"""
from __future__ import annotations

import math

import numpy as np

from .._config import njit

__all__ = ["impact_time_spheres"]


@njit
def impact_time_spheres(ca, cb, va, vb, reach, dt):
    """First t in [0, dt] at which spheres of centres ``ca``, ``cb`` (3,) moving with ``va``, ``vb`` (3,) are at
    distance ``reach`` = r_a + r_b: 0 when they already touch, inf when they never do within dt."""
    dx, dy, dz = cb[0] - ca[0], cb[1] - ca[1], cb[2] - ca[2]
    wx, wy, wz = vb[0] - va[0], vb[1] - va[1], vb[2] - va[2]
    c0 = dx * dx + dy * dy + dz * dz - reach * reach
    if c0 <= 0.0:
        return 0.0
    half_b = dx * wx + dy * wy + dz * wz
    aa = wx * wx + wy * wy + wz * wz
    disc = half_b * half_b - aa * c0
    if half_b >= 0.0 or disc < 0.0:
        return np.inf  # moving apart, or passing by
    t = c0 / (-half_b + math.sqrt(disc))  # the smaller root, without cancellation
    return t if t <= dt else np.inf
