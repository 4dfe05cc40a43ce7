"""One convex body against one triangle of a static surface (engine.narrowphase.triangle_mesh): what every
per-triangle kernel writes (``TriangleContact``), the bundle the mesh's pair kernels read back and merge.
"""
from __future__ import annotations

import math
from collections import namedtuple

import numpy as np

from .._config import njit
from .contacts import EDGE, FACE, VERTEX, feature_key, key_kind
from .segment_segment import closest_segment_parameters
from .touching_normal import unit_vector

__all__ = ["TriangleContact", "triangle_contact", "MAX_TRIANGLE_POINTS", "closest_on_triangle",
           "round_core_answer", "round_core_triangle", "MEET"]

#: the most candidate points one body–triangle contact writes (a box face clipped by a triangle: up to 7)
MAX_TRIANGLE_POINTS = 8

#: one body against one triangle, reused from triangle to triangle (no allocation per triangle):
#: ``separation`` (1,) the signed distance (< 0: penetration depth; > 0 apart: the distance, or a lower bound of it
#: for the SAT kernels); ``normal`` (3,) unit, from the body towards the triangle (translating the triangle by
#: depth · normal separates them), before the active-edge fix; ``tri_feature`` (2,) int64: the triangle's feature
#: that touches, (type, local index) — type contacts.VERTEX (corner v), EDGE (edge e joins corners e and
#: (e + 1) % 3) or FACE (index 0); ``body_feature`` (1,) int64: the body's feature code (contacts.VERTEX, EDGE,
#: FACE); ``count`` (1,) int64 points; ``points`` (MAX_TRIANGLE_POINTS, 3) contact points, ``depths`` (…,) their
#: penetration along the normal (>= 0), ``body_keys`` (…,) int64 the body's feature key of each point
#: (contacts.feature_key), ``tri_keys`` (…,) int64 the triangle's, with the local index (the pair kernel turns it
#: into the surface's numbering)
TriangleContact = namedtuple("TriangleContact", "separation normal tri_feature body_feature count points depths "
                                                "body_keys tri_keys")


def triangle_contact() -> TriangleContact:
    """A fresh, empty ``TriangleContact``."""
    m = MAX_TRIANGLE_POINTS
    return TriangleContact(np.full(1, np.inf), np.zeros(3), np.zeros(2, np.int64), np.zeros(1, np.int64),
                           np.zeros(1, np.int64), np.zeros((m, 3)), np.zeros(m), np.zeros(m, np.int64),
                           np.zeros(m, np.int64))


# -- round cores (a sphere: one point; a capsule: a segment) against one triangle --------------------------------
#
# The core C (a point or the segment p0–p1) swept by r touches triangle T where their closest points c ∈ C,
# q ∈ T are at most r apart (Ericson 4.5). With d = |q − c|: separation = d − r, normal n = (q − c) / d (from the
# body towards the triangle), one point halfway between the two surfaces, c + (r + d) / 2 · n, of depth −separation.
#
# When the core meets the triangle (d = 0, or a round-off of the coordinates' size: ``MEET``) q − c has no
# direction. The answer is then the triangle's face normal n_f, turned away from the side of the core's midpoint m
# (s = sign((m − a)·n_f), +1 when m lies on the plane): n = −s n_f; the core must move along −n by
# h = max(0, max over its ends of −s (p_k − a)·n_f) to clear the triangle's plane, so separation = −(r + h), the
# body feature is the deepest end (h > 0) or the meeting point, the triangle's feature its face. Translating the
# triangle by (r + h) n separates the two (an upper bound of the depth; the limit of d − r as d → 0 from the
# face's side, where h = 0).

#: cores closer than this × their largest |coordinate| meet (engine.narrowphase.segment_segment.MEET)
MEET = 1e-14


@njit(inline="always")
def _dot(ax, ay, az, bx, by, bz):
    return ax * bx + ay * by + az * bz


@njit(inline="always")
def _cross3(ax, ay, az, bx, by, bz):
    return ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx


@njit(inline="always")
def _off_line(px, py, pz, e0, e1):
    """q − p for q the foot of p on the line e0–e1: −(the part of p − e0 perpendicular to e = e1 − e0), computed as
    −e × ((p − e0) × e) / |e|² (no round-off along e, unlike e0 + t e − p)."""
    ex, ey, ez = e1[0] - e0[0], e1[1] - e0[1], e1[2] - e0[2]
    wx, wy, wz = _cross3(px - e0[0], py - e0[1], pz - e0[2], ex, ey, ez)
    ux, uy, uz = _cross3(ex, ey, ez, wx, wy, wz)
    ee = _dot(ex, ey, ez, ex, ey, ez)
    return -ux / ee, -uy / ee, -uz / ee


@njit
def closest_on_triangle(px, py, pz, a, b, c, n_face):
    """Ericson 5.1.5 ClosestPtPointTriangle: the offset q − p (3 floats) from p to its closest point q of triangle
    (a, b, c) ((3,) each; unit normal ``n_face``) and q's feature (type, local index): contacts.VERTEX v, EDGE e
    (joining corners e and (e + 1) % 3) or FACE 0, decided by the barycentric region tests. The offset is computed
    from the feature (face: −((p − a)·n) n; edge: the perpendicular part of p − e0; vertex: corner − p): exact in
    direction up to round-off of the feature itself."""
    abx, aby, abz = b[0] - a[0], b[1] - a[1], b[2] - a[2]
    acx, acy, acz = c[0] - a[0], c[1] - a[1], c[2] - a[2]
    d1 = _dot(abx, aby, abz, px - a[0], py - a[1], pz - a[2])
    d2 = _dot(acx, acy, acz, px - a[0], py - a[1], pz - a[2])
    if d1 <= 0.0 and d2 <= 0.0:  # vertex region a
        return a[0] - px, a[1] - py, a[2] - pz, VERTEX, 0
    d3 = _dot(abx, aby, abz, px - b[0], py - b[1], pz - b[2])
    d4 = _dot(acx, acy, acz, px - b[0], py - b[1], pz - b[2])
    if d3 >= 0.0 and d4 <= d3:  # vertex region b
        return b[0] - px, b[1] - py, b[2] - pz, VERTEX, 1
    vc = d1 * d4 - d3 * d2
    if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:  # edge region ab (edge 0)
        x, y, z = _off_line(px, py, pz, a, b)
        return x, y, z, EDGE, 0
    d5 = _dot(abx, aby, abz, px - c[0], py - c[1], pz - c[2])
    d6 = _dot(acx, acy, acz, px - c[0], py - c[1], pz - c[2])
    if d6 >= 0.0 and d5 <= d6:  # vertex region c
        return c[0] - px, c[1] - py, c[2] - pz, VERTEX, 2
    vb = d5 * d2 - d1 * d6
    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:  # edge region ca (edge 2)
        x, y, z = _off_line(px, py, pz, c, a)
        return x, y, z, EDGE, 2
    va = d3 * d6 - d5 * d4
    if va <= 0.0 and d4 - d3 >= 0.0 and d5 - d6 >= 0.0:  # edge region bc (edge 1)
        x, y, z = _off_line(px, py, pz, b, c)
        return x, y, z, EDGE, 1
    h = _dot(px - a[0], py - a[1], pz - a[2], n_face[0], n_face[1], n_face[2])  # face region
    return -h * n_face[0], -h * n_face[1], -h * n_face[2], FACE, 0


@njit(inline="always")
def _corner(a, b, c, k):
    if k == 0:
        return a
    if k == 1:
        return b
    return c


@njit
def _crosses_triangle(p0, p1, a, b, c, n_face):
    """Whether the segment p0–p1 crosses (or touches) the interior of the triangle: its ends on either side of the
    plane, the crossing point on the inner side of the three edges (Ericson 5.3.6, by the plane first)."""
    dp = _dot(p0[0] - a[0], p0[1] - a[1], p0[2] - a[2], n_face[0], n_face[1], n_face[2])
    dq = _dot(p1[0] - a[0], p1[1] - a[1], p1[2] - a[2], n_face[0], n_face[1], n_face[2])
    if dp == dq or (dp > 0.0 and dq > 0.0) or (dp < 0.0 and dq < 0.0):
        return False
    u = dp / (dp - dq)
    x, y, z = p0[0] + u * (p1[0] - p0[0]), p0[1] + u * (p1[1] - p0[1]), p0[2] + u * (p1[2] - p0[2])
    for k in range(3):
        e0 = _corner(a, b, c, k)
        e1 = _corner(a, b, c, (k + 1) % 3)
        cx, cy, cz = _cross3(e1[0] - e0[0], e1[1] - e0[1], e1[2] - e0[2], x - e0[0], y - e0[1], z - e0[2])
        if _dot(cx, cy, cz, n_face[0], n_face[1], n_face[2]) < 0.0:
            return False
    return True


@njit
def _closest_core_triangle(p0, p1, a, b, c, n_face):
    """The closest points of the core p0–p1 (p0 == p1: a point) and the triangle (Ericson 5.1.10): the ends
    against the triangle (5.1.5), then the segment against the three edges (5.1.9). Returns (s, the offset
    q − c (3 floats), the triangle feature (type, index)) with c = p0 + s (p1 − p0) the core's point."""
    vx, vy, vz, ft, fi = closest_on_triangle(p0[0], p0[1], p0[2], a, b, c, n_face)
    s = 0.0
    best = _dot(vx, vy, vz, vx, vy, vz)
    dx, dy, dz = p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]
    if dx == 0.0 and dy == 0.0 and dz == 0.0:
        return s, vx, vy, vz, ft, fi
    wx, wy, wz, gt, gi = closest_on_triangle(p1[0], p1[1], p1[2], a, b, c, n_face)
    if _dot(wx, wy, wz, wx, wy, wz) < best:
        s, vx, vy, vz, ft, fi = 1.0, wx, wy, wz, gt, gi
        best = _dot(wx, wy, wz, wx, wy, wz)
    for k in range(3):
        e0 = _corner(a, b, c, k)
        e1 = _corner(a, b, c, (k + 1) % 3)
        u, t, _ = closest_segment_parameters(p0, p1, e0, e1)
        ex, ey, ez = e1[0] - e0[0], e1[1] - e0[1], e1[2] - e0[2]
        cx, cy, cz = p0[0] + u * dx, p0[1] + u * dy, p0[2] + u * dz
        qx, qy, qz = e0[0] + t * ex, e0[1] + t * ey, e0[2] + t * ez
        if t == 0.0:
            qx, qy, qz = e0[0], e0[1], e0[2]
        elif t == 1.0:
            qx, qy, qz = e1[0], e1[1], e1[2]
        ox, oy, oz = qx - cx, qy - cy, qz - cz
        if _dot(ox, oy, oz, ox, oy, oz) < best:
            best = _dot(ox, oy, oz, ox, oy, oz)
            s, vx, vy, vz = u, ox, oy, oz
            if t == 0.0:
                ft, fi = VERTEX, k
            elif t == 1.0:
                ft, fi = VERTEX, (k + 1) % 3
            else:
                ft, fi = EDGE, k
    if best > 0.0 and _crosses_triangle(p0, p1, a, b, c, n_face):
        return s, 0.0, 0.0, 0.0, FACE, 0
    return s, vx, vy, vz, ft, fi


@njit(inline="always")
def _core_key(s, is_point):
    """The body's feature key of the core point at parameter s (engine.narrowphase.segment_segment's numbering:
    a sphere's point and a capsule's end 0 are vertex 0, its end 1 vertex 1, the segment's interior edge 0)."""
    if is_point or s == 0.0:
        return feature_key(VERTEX, 0)
    if s == 1.0:
        return feature_key(VERTEX, 1)
    return feature_key(EDGE, 0)


@njit(inline="always")
def _magnitude(p0, p1, a, b, c):
    big = 0.0
    for k in range(3):
        big = max(big, abs(p0[k]), abs(p1[k]), abs(a[k]), abs(b[k]), abs(c[k]))
    return big


@njit
def round_core_answer(p0, p1, radius, a, b, c, n_face):
    """One round core — the segment p0–p1 ((3,) arrays or 3-tuples; p0 == p1 for a sphere) swept by ``radius`` —
    against the triangle (a, b, c) of unit normal ``n_face`` (see the comment above: the closest points, or the
    meeting answer): (separation, normal (3 floats), the triangle's feature (type, index), the body's feature key,
    the contact point (3 floats))."""
    is_point = p0[0] == p1[0] and p0[1] == p1[1] and p0[2] == p1[2]
    s, vx, vy, vz, ft, fi = _closest_core_triangle(p0, p1, a, b, c, n_face)
    cx, cy, cz = p0[0] + s * (p1[0] - p0[0]), p0[1] + s * (p1[1] - p0[1]), p0[2] + s * (p1[2] - p0[2])
    if s == 1.0:
        cx, cy, cz = p1[0], p1[1], p1[2]
    d = math.sqrt(vx * vx + vy * vy + vz * vz)
    key = _core_key(s, is_point)
    if d > MEET * _magnitude(p0, p1, a, b, c):
        nx, ny, nz, _ = unit_vector(vx, vy, vz)
        separation = d - radius
    else:  # the core meets the triangle: the face normal, away from the midpoint's side
        mid = _dot(0.5 * (p0[0] + p1[0]) - a[0], 0.5 * (p0[1] + p1[1]) - a[1], 0.5 * (p0[2] + p1[2]) - a[2],
                   n_face[0], n_face[1], n_face[2])
        side = -1.0 if mid < 0.0 else 1.0
        nx, ny, nz = -side * n_face[0], -side * n_face[1], -side * n_face[2]
        h = 0.0
        for k in range(1 if is_point else 2):
            e = p0 if k == 0 else p1
            below = -side * _dot(e[0] - a[0], e[1] - a[1], e[2] - a[2], n_face[0], n_face[1], n_face[2])
            if below > h:
                h = below
                cx, cy, cz = e[0], e[1], e[2]
                key = _core_key(float(k), is_point)
        separation = -(radius + h)
        ft, fi = FACE, 0
    lift = radius + 0.5 * separation  # from the core point to halfway between the surfaces
    return separation, nx, ny, nz, ft, fi, key, cx + lift * nx, cy + lift * ny, cz + lift * nz


@njit
def round_core_triangle(p0, p1, radius, a, b, c, n_face, out):
    """``round_core_answer`` into the ``TriangleContact`` ``out`` (one point). Returns the separation."""
    separation, nx, ny, nz, ft, fi, key, px, py, pz = round_core_answer(p0, p1, radius, a, b, c, n_face)
    out.separation[0] = separation
    out.normal[0], out.normal[1], out.normal[2] = nx, ny, nz
    out.tri_feature[0], out.tri_feature[1] = ft, fi
    out.body_feature[0] = key_kind(key)
    out.count[0] = 1
    out.points[0, 0], out.points[0, 1], out.points[0, 2] = px, py, pz
    out.depths[0] = max(-separation, 0.0)
    out.body_keys[0] = key
    out.tri_keys[0] = feature_key(ft, fi)
    return separation
