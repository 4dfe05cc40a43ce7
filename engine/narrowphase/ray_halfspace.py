"""Ray against a solid half-space {x : n·(x − p) <= 0} (Ericson, *Real-Time Collision Detection*, 5.3.1
"Intersecting segment against plane"), the engine's ground ``Plane`` being the case n = +y.

The signed height of the ray's point is s(t) = n·(o − p) + t n·d. An origin with s(0) <= 0 is in the closed
solid; otherwise the ray reaches the surface at t = s(0) / (−n·d) when it goes down (n·d < 0), and never when
it runs parallel to the surface or rises.

Ray conventions as in ``ray_sphere``.
"""
from __future__ import annotations

import math

from .._config import njit

__all__ = ["ray_halfspace"]


@njit
def ray_halfspace(o, d, tmax, p, n):
    """First hit of the ray o + t d, 0 <= t <= tmax, with the solid half-space n·(x − p) <= 0.

    Parameters
    ----------
    o, d : tuple of 3 float
        Origin and unit direction of the ray.
    tmax : float
        Largest t looked at, >= 0 (may be inf).
    p : tuple of 3 float
        A point of the boundary plane.
    n : tuple of 3 float
        Outward unit normal of the boundary.

    Returns
    -------
    tuple of 4 float
        ``(t, nx, ny, nz)``: the distance to the hit and n; (0, −d) for an origin in the closed half-space;
        (inf, nan, nan, nan) for a miss.
    """
    height = n[0] * (o[0] - p[0]) + n[1] * (o[1] - p[1]) + n[2] * (o[2] - p[2])
    if height <= 0.0:
        return 0.0, -d[0], -d[1], -d[2]
    rate = n[0] * d[0] + n[1] * d[1] + n[2] * d[2]
    if rate >= 0.0:  # parallel or rising: the height never drops
        return math.inf, math.nan, math.nan, math.nan
    t = height / -rate
    if t > tmax or t == math.inf:  # beyond tmax, or beyond the float range
        return math.inf, math.nan, math.nan, math.nan
    return t, n[0], n[1], n[2]
