"""Closest points of two segments (Ericson 5.1.9), and the contacts of the shapes whose cores are points or
segments swept by a ball: sphere–sphere, sphere–capsule, capsule–capsule.

A sphere is a point core swept by its radius, a capsule a segment core; two such shapes touch where their
cores' closest points c_A, c_B are at most r_A + r_B apart (Ericson 4.5, "sphere swept volumes"). With
d = |c_B − c_A|: separation = d − r_A − r_B, normal n = (c_B − c_A) / d, and the contact point lies halfway
between the two surfaces along n: (c_A + r_A n + c_B − r_B n) / 2. Exact to round-off:

- sphere–sphere: c_A, c_B are the centres;
- sphere–capsule: the centre and its closest point on the segment;
- capsule–capsule: ``closest_segment_parameters`` (Ericson 5.1.9 ``ClosestPtSegmentSegment``); when the two
  segments are parallel (sin² of their angle <= ``PARALLEL_SIN2``) and their projections overlap, the contact
  is the overlap: two points, at its ends, and n is exactly perpendicular to the common direction (d is then
  the distance of the two lines).

When the cores meet (d = 0), n is the common perpendicular of the two segments (d_A × d_B), or any direction
perpendicular to the one segment, or +x for two points; the depth is then r_A + r_B.

Features (``engine.narrowphase.contacts``): a core point is the shape's vertex 0 (sphere; a capsule's end
0 or 1, "sphere" for a rounded shape), a segment's interior its edge 0 ("cylinder").
"""
from __future__ import annotations

import math

import numpy as np

from .._config import njit
from .._validate import as_float_array, as_nonnegative
from .contacts import (
    EDGE,
    VERTEX,
    contact_rows,
    contact_set_from_rows,
    feature_key,
    key_kind,
    write_pair,
    write_point,
)

__all__ = ["PARALLEL_SIN2", "closest_segment_parameters", "contact_round_cores", "contact_segments_pair"]

#: segments whose sin² of angle is at most this are parallel (their contact is the overlap of the two)
PARALLEL_SIN2 = 1e-12


@njit(inline="always")
def _clamp01(x):
    return min(max(x, 0.0), 1.0)


@njit
def closest_segment_parameters(p1, q1, p2, q2):
    """Ericson 5.1.9 ClosestPtSegmentSegment: (s, t, parallel) with p1 + s (q1 − p1) and p2 + t (q2 − p2) the
    closest points of the segments [p1, q1], [p2, q2] ((3,) each; a segment of length 0 is its point);
    ``parallel``: both have a length and sin² of their angle <= PARALLEL_SIN2."""
    d1x, d1y, d1z = q1[0] - p1[0], q1[1] - p1[1], q1[2] - p1[2]
    d2x, d2y, d2z = q2[0] - p2[0], q2[1] - p2[1], q2[2] - p2[2]
    rx, ry, rz = p1[0] - p2[0], p1[1] - p2[1], p1[2] - p2[2]
    a = d1x * d1x + d1y * d1y + d1z * d1z
    e = d2x * d2x + d2y * d2y + d2z * d2z
    f = d2x * rx + d2y * ry + d2z * rz
    if a == 0.0 and e == 0.0:  # two points
        return 0.0, 0.0, False
    if a == 0.0:  # the first segment is a point
        return 0.0, _clamp01(f / e), False
    c = d1x * rx + d1y * ry + d1z * rz
    if e == 0.0:  # the second segment is a point
        return _clamp01(-c / a), 0.0, False
    b = d1x * d2x + d1y * d2y + d1z * d2z
    denom = a * e - b * b  # = |d1 × d2|² >= 0
    parallel = denom <= PARALLEL_SIN2 * a * e
    s = 0.0 if parallel else _clamp01((b * f - c * e) / denom)
    t = (b * s + f) / e
    if t < 0.0:
        t = 0.0
        s = _clamp01(-c / a)
    elif t > 1.0:
        t = 1.0
        s = _clamp01((b - c) / a)
    return s, t, parallel


@njit(inline="always")
def _end_key(u, is_point):
    """The feature of a core point at parameter u: a vertex (end 0 or 1; a point core's only point) or the edge."""
    if is_point or u == 0.0:
        return feature_key(VERTEX, 0)
    if u == 1.0:
        return feature_key(VERTEX, 1)
    return feature_key(EDGE, 0)


@njit
def _fallback_normal(d1x, d1y, d1z, d2x, d2y, d2z, ox, oy, oz):
    """A unit normal for cores that meet: the common perpendicular d1 × d2, else a perpendicular of the one
    segment, else +x; turned to make a non-negative angle with o (B's midpoint − A's)."""
    nx, ny, nz = d1y * d2z - d1z * d2y, d1z * d2x - d1x * d2z, d1x * d2y - d1y * d2x
    length = math.sqrt(nx * nx + ny * ny + nz * nz)
    if length == 0.0:
        dx, dy, dz = (d1x, d1y, d1z) if d1x != 0.0 or d1y != 0.0 or d1z != 0.0 else (d2x, d2y, d2z)
        if dx == 0.0 and dy == 0.0 and dz == 0.0:
            return 1.0, 0.0, 0.0
        if abs(dx) <= abs(dy) and abs(dx) <= abs(dz):  # d × e_x: perpendicular to d
            nx, ny, nz = 0.0, dz, -dy
        elif abs(dy) <= abs(dz):
            nx, ny, nz = -dz, 0.0, dx
        else:
            nx, ny, nz = dy, -dx, 0.0
        length = math.sqrt(nx * nx + ny * ny + nz * nz)
    sign = -1.0 if nx * ox + ny * oy + nz * oz < 0.0 else 1.0
    return sign * nx / length, sign * ny / length, sign * nz / length


@njit
def contact_round_cores(a0, a1, ra, b0, b1, rb, rows, p, flip):
    """Contact of A = segment [a0, a1] swept by ra and B = [b0, b1] swept by rb ((3,) each; a0 == a1 for a
    sphere) into row p of ``rows`` (engine.narrowphase.contacts.ContactRows); ``flip``: the pair's first shape
    is B. Returns the separation."""
    s, t, parallel = closest_segment_parameters(a0, a1, b0, b1)
    d1x, d1y, d1z = a1[0] - a0[0], a1[1] - a0[1], a1[2] - a0[2]
    d2x, d2y, d2z = b1[0] - b0[0], b1[1] - b0[1], b1[2] - b0[2]
    if parallel and _parallel_overlap(a0, a1, ra, b0, b1, rb, rows, p, flip):
        return rows.separation[p]
    c1x, c1y, c1z = a0[0] + s * d1x, a0[1] + s * d1y, a0[2] + s * d1z
    c2x, c2y, c2z = b0[0] + t * d2x, b0[1] + t * d2y, b0[2] + t * d2z
    vx, vy, vz = c2x - c1x, c2y - c1y, c2z - c1z
    d = math.sqrt(vx * vx + vy * vy + vz * vz)
    if d > 0.0:
        nx, ny, nz = vx / d, vy / d, vz / d
    else:
        nx, ny, nz = _fallback_normal(d1x, d1y, d1z, d2x, d2y, d2z, 0.5 * (b0[0] + b1[0] - a0[0] - a1[0]),
                                      0.5 * (b0[1] + b1[1] - a0[1] - a1[1]), 0.5 * (b0[2] + b1[2] - a0[2] - a1[2]))
    separation = d - ra - rb
    key_a = _end_key(s, d1x == 0.0 and d1y == 0.0 and d1z == 0.0)
    key_b = _end_key(t, d2x == 0.0 and d2y == 0.0 and d2z == 0.0)
    half = 0.5 * (ra - rb)
    write_point(rows, p, 0, 0.5 * (c1x + c2x) + half * nx, 0.5 * (c1y + c2y) + half * ny,
                0.5 * (c1z + c2z) + half * nz, key_a, key_b, flip)
    write_pair(rows, p, separation, nx, ny, nz, key_kind(key_a), key_kind(key_b), 1, flip)
    return separation


@njit
def _parallel_overlap(a0, a1, ra, b0, b1, rb, rows, p, flip):
    """Parallel segments: if B's projection on A's line overlaps A over a positive length, write the two-point
    contact at the ends of the overlap (normal exactly perpendicular to A) and return True."""
    ux, uy, uz = a1[0] - a0[0], a1[1] - a0[1], a1[2] - a0[2]
    la = math.sqrt(ux * ux + uy * uy + uz * uz)
    ux, uy, uz = ux / la, uy / la, uz / la
    w0x, w0y, w0z = b0[0] - a0[0], b0[1] - a0[1], b0[2] - a0[2]
    t0 = w0x * ux + w0y * uy + w0z * uz
    t1 = (b1[0] - a0[0]) * ux + (b1[1] - a0[1]) * uy + (b1[2] - a0[2]) * uz
    lo = max(0.0, min(t0, t1))
    hi = min(la, max(t0, t1))
    if not hi > lo:
        return False
    # B's line offset from A's line: the component of b0 − a0 perpendicular to u
    wx, wy, wz = w0x - t0 * ux, w0y - t0 * uy, w0z - t0 * uz
    d = math.sqrt(wx * wx + wy * wy + wz * wz)
    if d > 0.0:
        nx, ny, nz = wx / d, wy / d, wz / d
    else:
        nx, ny, nz = _fallback_normal(ux, uy, uz, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    lift = ra + 0.5 * (d - ra - rb)  # from A's line to the middle of the two surfaces
    b_first = 0 if t0 <= t1 else 1
    for slot in range(2):
        at = lo if slot == 0 else hi
        if at == (0.0 if slot == 0 else la):  # the overlap ends at an end of A
            key_a, key_b = feature_key(VERTEX, slot), feature_key(EDGE, 0)
        else:  # ... else at an end of B
            key_a, key_b = feature_key(EDGE, 0), feature_key(VERTEX, b_first if slot == 0 else 1 - b_first)
        write_point(rows, p, slot, a0[0] + at * ux + lift * nx, a0[1] + at * uy + lift * ny,
                    a0[2] + at * uz + lift * nz, key_a, key_b, flip)
    write_pair(rows, p, d - ra - rb, nx, ny, nz, EDGE, EDGE, 2, flip)
    return True


def contact_segments_pair(a0, a1, radius_a, b0, b1, radius_b):
    """The contact of two shapes whose cores are segments [a0, a1], [b0, b1] ((3,) each; a0 == a1: a sphere)
    swept by radius_a, radius_b >= 0: a ContactSet of one pair (its separation > 0 when they are apart)."""
    ends = [as_float_array(v, name, shape=(3,)) for v, name in ((a0, "a0"), (a1, "a1"), (b0, "b0"), (b1, "b1"))]
    ra = as_nonnegative(radius_a, "radius_a")
    rb = as_nonnegative(radius_b, "radius_b")
    rows = contact_rows(1)
    contact_round_cores(ends[0], ends[1], ra, ends[2], ends[3], rb, rows, 0, False)
    return contact_set_from_rows(rows, np.array([[0, 1]], np.int64), np.array([ra]), np.array([rb]),
                                 keep_apart=True)
