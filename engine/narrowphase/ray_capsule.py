"""Ray against a solid capsule, the segment p0–p1 swept by a ball of radius r: the lateral surface of its
cylinder (Ericson, *Real-Time Collision Detection*, 5.3.7 "Intersecting ray or segment against cylinder") and
its two end spheres (5.3.2, ``ray_sphere``).

The capsule is the union of the finite cylinder and the two balls, all convex: the first point of the union on
the ray is the earliest of their first points. The cylinder's flat caps lie inside the balls, so only its
lateral surface counts: the first point of the infinite cylinder, kept when its foot on the axis falls within
the segment.

Infinite cylinder: with a = p1 − p0, m = o − p0 and the components m⊥, d⊥ orthogonal to a, the ray is inside
for |m⊥ + t d⊥|² <= r², i.e. A t² + 2 B t + C <= 0 with A = d⊥·d⊥, B = m⊥·d⊥, C = m⊥·m⊥ − r². As for the
sphere the discriminant B² − A C is taken as A (r² − |m⊥ − (B/A) d⊥|²) (r² minus the squared distance from the
axis to the ray's projected line) and the near root as C / (−B + √(B² − A C)), both free of cancellation.

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
def _perp(x, y, z, ax, ay, az, inv_len2):
    """The component of (x, y, z) orthogonal to the axis a (1 / |a|² given)."""
    s = (x * ax + y * ay + z * az) * inv_len2
    return x - s * ax, y - s * ay, z - s * az


@njit
def _ray_cylinder_side(o, d, tmax, p0, p1, r):
    """First hit (t, normal) of the ray with the lateral surface of the cylinder p0–p1 of radius r from outside
    (an origin inside the infinite cylinder gives a miss: the capsule test decides those); p0 != p1."""
    ax, ay, az = p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]
    inv = 1.0 / (ax * ax + ay * ay + az * az)
    mx, my, mz = o[0] - p0[0], o[1] - p0[1], o[2] - p0[2]
    px, py, pz = _perp(mx, my, mz, ax, ay, az, inv)
    qx, qy, qz = _perp(d[0], d[1], d[2], ax, ay, az, inv)
    cc = (px * px + py * py + pz * pz) - r * r
    A = qx * qx + qy * qy + qz * qz
    B = px * qx + py * qy + pz * qz
    if cc <= 0.0 or B >= 0.0:  # inside the infinite cylinder, or not closing in on its axis (A == 0 included)
        return math.inf, math.nan, math.nan, math.nan
    k = B / A  # the foot of the axis on the projected line is m⊥ − k d⊥
    fx, fy, fz = px - k * qx, py - k * qy, pz - k * qz
    discr = r * r - (fx * fx + fy * fy + fz * fz)
    if discr < 0.0:
        return math.inf, math.nan, math.nan, math.nan
    t = cc / (math.sqrt(A * discr) - B)
    s = ((mx + t * d[0]) * ax + (my + t * d[1]) * ay + (mz + t * d[2]) * az) * inv
    if t > tmax or s < 0.0 or s > 1.0:  # beyond tmax, or past an end (the end spheres answer there)
        return math.inf, math.nan, math.nan, math.nan
    nx, ny, nz = px + t * qx, py + t * qy, pz + t * qz
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
    if len2 < TINY:  # p0 == p1 (or |a| < 1.5e-154, whose 1 / |a|² overflows): a sphere
        return ray_sphere(o, d, tmax, p0, r)
    inv = 1.0 / len2
    mx, my, mz = o[0] - p0[0], o[1] - p0[1], o[2] - p0[2]
    s = (mx * ax + my * ay + mz * az) * inv  # the origin's foot on the axis, in units of the segment
    if 0.0 <= s <= 1.0:
        px, py, pz = mx - s * ax, my - s * ay, mz - s * az
        if px * px + py * py + pz * pz <= r * r:  # the origin is in the cylinder part
            return 0.0, -d[0], -d[1], -d[2]
    best = _ray_cylinder_side(o, d, tmax, p0, p1, r)
    for end in (ray_sphere(o, d, tmax, p0, r), ray_sphere(o, d, tmax, p1, r)):
        if end[0] < best[0]:
            best = end
    return best
