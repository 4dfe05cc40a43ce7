"""Ray against one triangle, watertight: Woop, Benthin and Wald, "Watertight Ray/Triangle Intersection", Journal
of Computer Graphics Techniques 2(1), 2013.

The triangle is moved into the ray's frame: translated by −o, its axes permuted so that kz is the axis of the
largest |d_k| (kx, ky the next two in cyclic order, swapped when d_kz < 0 so that the frame keeps its handedness),
then sheared so that the ray becomes the +z axis: x' = x_kx − (d_kx / d_kz) z, y' = y_ky − (d_ky / d_kz) z. There
the ray meets the triangle iff the origin of the (x', y') plane lies in its projection, which the three 2-D edge
functions decide:

    U = C'x·B'y − C'y·B'x,   V = A'x·C'y − A'y·C'x,   W = B'x·A'y − B'y·A'x.

The ray misses when their signs are mixed (some < 0 and some > 0); a zero is on an edge and accepted by either
sign, so a hit on an edge or a vertex counts for every triangle that shares it. Watertightness: each edge function
reads only its edge's two transformed vertices, which depend on the vertex and the ray and not on the triangle, and
a triangle on the other side of the edge computes exactly its negation (products commute, a − b = −(b − a) in
IEEE arithmetic): the two triangles see the ray on the same side of their edge, and no ray slips between them.

An edge function that evaluates to exactly 0 is evaluated again exactly (the paper recomputes in double what it
computed in single precision; here the arithmetic is already double, so the second evaluation is exact instead):
fl(p − q) = 0 means p = q, and then the exact value of c·b − d·a is e_p − e_q, the rounding errors of the two
products (Dekker's TwoProduct by Veltkamp's split: exact for |products| below about 1e300 and above the
subnormal range), whose sign fl(e_p − e_q) keeps. The recomputed value is again exactly minus its neighbour's.

With det = U + V + W (0: the ray runs in the triangle's plane or the triangle projects to a segment — a miss),
the distance is t = (U·A'z + V·B'z + W·C'z) / det with z' = z_kz / d_kz; both signs of det are accepted (the
triangle is two-sided) and a hit needs 0 <= t <= t_max (an origin on the triangle: t = 0), compared on the t
returned (not on T against t_max·det, whose rounding could let a t just beyond t_max through: a surface's walk
passes its best t so far as t_max, and needs the exact comparison to keep the lowest t). The sign of det tells
the side the ray comes from: det > 0 when it meets the face against its right-hand normal n = (b − a) × (c − a)
(n·d < 0), det < 0 when it meets its back; the normal returned is the one facing the ray, −sign(n·d)·n.
"""
from __future__ import annotations

import math

from .._config import njit

__all__ = ["ray_triangle", "ray_triangle_side"]

#: Veltkamp's splitting factor for float64: 2^27 + 1
_SPLIT = 134217729.0


@njit(inline="always")
def _product_error(a, b, p):
    """The rounding error a·b − p of p = fl(a·b), exactly (Dekker's TwoProduct with Veltkamp's split)."""
    ca = _SPLIT * a
    a_hi = ca - (ca - a)
    a_lo = a - a_hi
    cb = _SPLIT * b
    b_hi = cb - (cb - b)
    b_lo = b - b_hi
    return ((a_hi * b_hi - p) + a_hi * b_lo + a_lo * b_hi) + a_lo * b_lo


@njit(inline="always")
def _edge(ax, ay, bx, by):
    """ax·by − ay·bx with the right sign: exact when it rounds to 0 (the module docstring)."""
    p = ax * by
    q = ay * bx
    e = p - q
    if e == 0.0:
        return _product_error(ax, by, p) - _product_error(ay, bx, q)
    return e


@njit(inline="always")
def _axes(d):
    """(kx, ky, kz): kz the axis of the largest |d_k|, (kx, ky) the next two, swapped when d_kz < 0."""
    ax, ay, az = abs(d[0]), abs(d[1]), abs(d[2])
    kz = 0 if ax >= ay and ax >= az else (1 if ay >= az else 2)
    kx = (kz + 1) % 3
    ky = (kx + 1) % 3
    if d[kz] < 0.0:
        kx, ky = ky, kx
    return kx, ky, kz


@njit(inline="always")
def _sheared(p, o, kx, ky, kz, sx, sy):
    """Corner p in the ray's frame: (x', y', z_kz − o_kz), before the scale of z."""
    x, y, z = p[kx] - o[kx], p[ky] - o[ky], p[kz] - o[kz]
    return x - sx * z, y - sy * z, z


@njit
def ray_triangle_side(o, d, t_max, a, b, c):
    """The hit of the ray o + t·d (3-tuples, d non-zero) with the two-sided triangle (a, b, c) (3-tuples), t in
    [0, t_max]: ``(t, side)`` with side = +1.0 when the ray meets the face of the right-hand normal
    (b − a) × (c − a) against it, −1.0 when it meets the back; (inf, 0.0) for a miss (the module docstring)."""
    kx, ky, kz = _axes(d)
    sz = 1.0 / d[kz]
    sx, sy = d[kx] * sz, d[ky] * sz
    ax, ay, az = _sheared(a, o, kx, ky, kz, sx, sy)
    bx, by, bz = _sheared(b, o, kx, ky, kz, sx, sy)
    cx, cy, cz = _sheared(c, o, kx, ky, kz, sx, sy)
    u = _edge(cx, cy, bx, by)
    v = _edge(ax, ay, cx, cy)
    w = _edge(bx, by, ax, ay)
    if (u < 0.0 or v < 0.0 or w < 0.0) and (u > 0.0 or v > 0.0 or w > 0.0):
        return math.inf, 0.0
    det = u + v + w
    if det == 0.0:
        return math.inf, 0.0
    big_t = u * (sz * az) + v * (sz * bz) + w * (sz * cz)
    side = 1.0
    if det < 0.0:  # the back face: both signs flipped, so that one comparison serves
        big_t, det, side = -big_t, -det, -1.0
    t = big_t / det
    if big_t < 0.0 or t > t_max:
        return math.inf, 0.0
    return t, side


@njit
def ray_triangle(o, d, t_max, a, b, c):
    """The first hit (t, nx, ny, nz) of the ray o + t·d (3-tuples, d unit, t in [0, t_max]) with the two-sided
    triangle (a, b, c): the unit face normal turned against the ray; (inf, nan, nan, nan) for a miss (the module
    docstring)."""
    t, side = ray_triangle_side(o, d, t_max, a, b, c)
    if t == math.inf:
        return math.inf, math.nan, math.nan, math.nan
    e1 = (b[0] - a[0], b[1] - a[1], b[2] - a[2])
    e2 = (c[0] - a[0], c[1] - a[1], c[2] - a[2])
    nx = e1[1] * e2[2] - e1[2] * e2[1]
    ny = e1[2] * e2[0] - e1[0] * e2[2]
    nz = e1[0] * e2[1] - e1[1] * e2[0]
    length = math.sqrt(nx * nx + ny * ny + nz * nz)
    return t, side * nx / length, side * ny / length, side * nz / length
