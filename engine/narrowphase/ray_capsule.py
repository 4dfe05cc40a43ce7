"""Ray against a solid capsule, the segment p0–p1 swept by a ball of radius r: the lateral surface of its
cylinder (Ericson, *Real-Time Collision Detection*, 5.3.7 "Intersecting ray or segment against cylinder") and
its two end spheres (5.3.2, ``ray_sphere``).

The capsule is the union of the finite cylinder and the two balls, all convex: the first point of the union on
the ray is the earliest of their first points. The cylinder's flat caps lie inside the balls, so only its
lateral surface counts: the first point of the infinite cylinder, kept when its foot on the axis falls within
the segment.

Infinite cylinder: with a = p1 − p0, m = o − p0 and the components m⊥, d⊥ orthogonal to a, the ray projected
on the plane orthogonal to a is m⊥ + λ u, u = d⊥ / |d⊥|, λ = t |d⊥|: the sphere's problem in that plane, solved
the same cancellation-free way (b = m⊥·u, discriminant r² − |m⊥ − b u|², near root c'/(−b + √discr) with
c' = |m⊥|² − r²), then t = λ / |d⊥|. A ray parallel to the axis (d⊥ = 0) never meets the lateral surface.

A degenerate segment (p0 == p1, or shorter than 1.5e-154) is a sphere at p0. Ray conventions as in ``ray_sphere``.
"""
from __future__ import annotations

import math

from .._config import njit
from .ray_sphere import ray_sphere

__all__ = ["ray_capsule"]

#: the smallest normal float64: a segment with |p1 − p0|² below it is taken as the point p0
TINY = 2.2250738585072014e-308


@njit(inline="always")
def _perp(x, y, z, ax, ay, az, len2):
    """The component of (x, y, z) orthogonal to the axis a (|a|² given)."""
    s = (x * ax + y * ay + z * az) / len2  # one rounding, not two of a reciprocal
    return x - s * ax, y - s * ay, z - s * az


@njit
def _ray_cylinder_side(o, d, tmax, p0, p1, r):
    """First hit (t, normal) of the ray with the lateral surface of the cylinder p0–p1 of radius r from outside
    (an origin inside the infinite cylinder gives a miss: the capsule test decides those); |p1 − p0|² normal."""
    ax, ay, az = p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]
    len2 = ax * ax + ay * ay + az * az
    mx, my, mz = o[0] - p0[0], o[1] - p0[1], o[2] - p0[2]
    px, py, pz = _perp(mx, my, mz, ax, ay, az, len2)
    qx, qy, qz = _perp(d[0], d[1], d[2], ax, ay, az, len2)
    # the projected ray runs along the unit u = d⊥ / |d⊥| at speed |d⊥| (|d⊥| found without under- or overflow)
    big = max(abs(qx), abs(qy), abs(qz))
    if big == 0.0:  # parallel to the axis: never crosses the lateral surface
        return math.inf, math.nan, math.nan, math.nan
    qx, qy, qz = qx / big, qy / big, qz / big
    w = math.sqrt(qx * qx + qy * qy + qz * qz)
    ux, uy, uz, speed = qx / w, qy / w, qz / w, big * w
    cc = (px * px + py * py + pz * pz) - r * r
    b = px * ux + py * uy + pz * uz
    if cc <= 0.0 or b >= 0.0:  # inside the infinite cylinder, or not closing in on its axis
        return math.inf, math.nan, math.nan, math.nan
    fx, fy, fz = px - b * ux, py - b * uy, pz - b * uz  # the axis' foot on the projected line
    discr = r * r - (fx * fx + fy * fy + fz * fz)
    if discr < 0.0:
        return math.inf, math.nan, math.nan, math.nan
    root = math.sqrt(discr)
    lam = cc / (root - b)  # the near root, as for the sphere, in distance along u
    t = lam / speed
    if t > tmax or t == math.inf:
        return math.inf, math.nan, math.nan, math.nan
    s = ((mx + t * d[0]) * ax + (my + t * d[1]) * ay + (mz + t * d[2]) * az) / len2
    if s < 0.0 or s > 1.0:  # past an end: the end spheres answer there
        return math.inf, math.nan, math.nan, math.nan
    nx, ny, nz = fx - root * ux, fy - root * uy, fz - root * uz  # m⊥ + λ u without cancellation, as for the sphere
    length = math.sqrt(nx * nx + ny * ny + nz * nz)
    if length == 0.0:  # r == 0: the ray crosses the segment itself
        return t, -d[0], -d[1], -d[2]
    return t, nx / length, ny / length, nz / length


@njit
def ray_capsule(o, d, tmax, p0, p1, r):
    """First hit of the ray o + t d, 0 <= t <= tmax, with the solid capsule of segment p0–p1 and radius r.

    Parameters
    ----------
    o, d : tuple of 3 float
        Origin and unit direction of the ray.
    tmax : float
        Largest t looked at, >= 0 (may be inf).
    p0, p1 : tuple of 3 float
        Ends of the capsule's segment (equal: a sphere).
    r : float
        Radius, >= 0.

    Returns
    -------
    tuple of 4 float
        ``(t, nx, ny, nz)``: the distance to the hit and the outward unit normal there; (0, −d) for an origin
        in the closed capsule; (inf, nan, nan, nan) for a miss.
    """
    ax, ay, az = p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]
    len2 = ax * ax + ay * ay + az * az
    if len2 < TINY:  # p0 == p1 (or |a| < 1.5e-154, whose |a|² is not a normal float): a sphere
        return ray_sphere(o, d, tmax, p0, r)
    mx, my, mz = o[0] - p0[0], o[1] - p0[1], o[2] - p0[2]
    s = (mx * ax + my * ay + mz * az) / len2  # the origin's foot on the axis, in units of the segment
    if 0.0 <= s <= 1.0:
        px, py, pz = _perp(mx, my, mz, ax, ay, az, len2)
        if px * px + py * py + pz * pz <= r * r:  # the origin is in the cylinder part
            return 0.0, -d[0], -d[1], -d[2]
    best = _ray_cylinder_side(o, d, tmax, p0, p1, r)
    for end in (ray_sphere(o, d, tmax, p0, r), ray_sphere(o, d, tmax, p1, r)):
        if end[0] < best[0]:
            best = end
    return best
