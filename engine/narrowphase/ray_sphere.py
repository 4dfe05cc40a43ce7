"""Ray against a solid sphere (Ericson, *Real-Time Collision Detection*, 5.3.2 "Intersecting ray or segment
against sphere"), in the cancellation-free form of Haines, Günther and Akenine-Möller, "Precision Improvements
for Ray/Sphere Intersection" (*Ray Tracing Gems*, chapter 7).

With m = o − c and a unit direction d, the points o + t d of the sphere solve t² + 2 b t + c' = 0, b = m·d,
c' = m·m − r². The textbook discriminant b² − c' subtracts two large, nearly equal numbers when the sphere is
small and far away; it equals r² − |m − b d|² (|m − b d| is the distance from the centre to the ray's line),
which is computed here instead. The near root −b − √discr cancels when b < 0 and discr ≈ b², so it is taken as
c' / q with q = −b + √discr (Vieta: the product of the roots is c'), the numerically stable quadratic.

Ray conventions (shared by every ``ray_*`` kernel): ``o``, ``d`` 3-tuples of float64, d of unit length; the
answer ``(t, nx, ny, nz)`` is the first t in [0, tmax] where the ray meets the closed solid and the outward unit
normal there; an origin inside or on the surface gives (0, −d); a miss gives (inf, nan, nan, nan).
"""
from __future__ import annotations

import math

from .._config import njit

__all__ = ["ray_sphere"]


@njit
def ray_sphere(o, d, tmax, c, r):
    """First hit of the ray o + t d, 0 <= t <= tmax, with the solid sphere of centre ``c`` and radius ``r``.

    Parameters
    ----------
    o, d : tuple of 3 float
        Origin and unit direction of the ray.
    tmax : float
        Largest t looked at, >= 0 (may be inf).
    c : tuple of 3 float
        Centre of the sphere.
    r : float
        Radius, >= 0.

    Returns
    -------
    tuple of 4 float
        ``(t, nx, ny, nz)``: the distance to the hit and the outward unit normal there; (0, −d) for an origin
        in the closed ball; (inf, nan, nan, nan) for a miss.
    """
    mx, my, mz = o[0] - c[0], o[1] - c[1], o[2] - c[2]
    dx, dy, dz = d[0], d[1], d[2]
    cc = (mx * mx + my * my + mz * mz) - r * r  # > 0 iff the origin is outside
    if cc <= 0.0:
        return 0.0, -dx, -dy, -dz
    b = mx * dx + my * dy + mz * dz
    if b >= 0.0:  # outside and not moving towards the centre
        return math.inf, math.nan, math.nan, math.nan
    # the centre's offset from its foot on the line: |q|² is the squared distance to the line, without b² − m·m
    qx, qy, qz = mx - b * dx, my - b * dy, mz - b * dz
    discr = r * r - (qx * qx + qy * qy + qz * qz)
    if discr < 0.0:  # tangent (discr == 0) hits: the ball is closed
        return math.inf, math.nan, math.nan, math.nan
    root = math.sqrt(discr)
    t = cc / (root - b)  # the near root c'/q, q = −b + √discr > 0
    if t > tmax:
        return math.inf, math.nan, math.nan, math.nan
    # the hit point's offset from the centre, m + t d = q + (t + b) d = q − √discr d: no cancellation, and its
    # component along d is <= 0 (the normal faces the ray); a ray through a point (r = 0) gets −d
    nx, ny, nz = qx - root * dx, qy - root * dy, qz - root * dz
    length = math.sqrt(nx * nx + ny * ny + nz * nz)
    if length == 0.0:
        return t, -dx, -dy, -dz
    return t, nx / length, ny / length, nz / length
