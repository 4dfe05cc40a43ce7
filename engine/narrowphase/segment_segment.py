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

When the cores meet (d <= ``MEET`` × their largest |coordinate|, where c_B − c_A is round-off), n is the
common perpendicular of the two segments (d_A × d_B), or any direction
perpendicular to the one segment, or +x for two points; the depth is then r_A + r_B − d.

Features (``engine.narrowphase.contacts``): a core point is the shape's vertex 0 (sphere; a capsule's end
0 or 1, "sphere" for a rounded shape), a segment's interior its edge 0 ("cylinder").
"""
from __future__ import annotations

import math

from .._config import njit
from .._validate import as_float_array, as_nonnegative
from .contacts import (
    EDGE,
    VERTEX,
    contact_of_one_pair,
    feature_key,
    key_kind,
    write_pair,
    write_point,
)
from .touching_normal import unit_vector

__all__ = ["PARALLEL_SIN2", "SHORT2", "MEET", "closest_segment_parameters", "contact_round_cores",
           "contact_segments_pair"]

#: segments whose sin² of angle is at most this are parallel (their contact is the overlap of the two)
PARALLEL_SIN2 = 1e-12
#: a segment whose squared length is at most this × the other's is taken as its first point (it is shorter than
#: 1e-12 × the other: the error is below the round-off of the other's length, and a·e cannot underflow)
SHORT2 = 1e-24
#: cores closer than this × their largest |coordinate| meet (their closest points' difference is round-off)
MEET = 1e-14


@njit(inline="always")
def _clamp01(x):
    return min(max(x, 0.0), 1.0)


@njit
def closest_segment_parameters(p1, q1, p2, q2):
    """Ericson 5.1.9 ClosestPtSegmentSegment: (s, t, parallel) with p1 + s (q1 − p1) and p2 + t (q2 − p2) the
    closest points of the segments [p1, q1], [p2, q2] ((3,) each; a segment of length 0, or shorter than 1e-12 ×
    the other, is its first point);
    ``parallel``: both have a length and sin² of their angle <= PARALLEL_SIN2."""
    d1x, d1y, d1z = q1[0] - p1[0], q1[1] - p1[1], q1[2] - p1[2]
    d2x, d2y, d2z = q2[0] - p2[0], q2[1] - p2[1], q2[2] - p2[2]
    rx, ry, rz = p1[0] - p2[0], p1[1] - p2[1], p1[2] - p2[2]
    a = d1x * d1x + d1y * d1y + d1z * d1z
    e = d2x * d2x + d2y * d2y + d2z * d2z
    f = d2x * rx + d2y * ry + d2z * rz
    if a <= SHORT2 * e:  # the first segment is a point (or so short that a·e would underflow)
        a = 0.0
    if e <= SHORT2 * a:
        e = 0.0
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
    segment, else (two point cores, spheres) o itself, +x if o = 0; turned to make a non-negative angle with o
    (B's midpoint − A's)."""
    nx, ny, nz = _cross(d1x, d1y, d1z, d2x, d2y, d2z)
    if nx == 0.0 and ny == 0.0 and nz == 0.0:
        dx, dy, dz = (d1x, d1y, d1z) if d1x != 0.0 or d1y != 0.0 or d1z != 0.0 else (d2x, d2y, d2z)
        if dx == 0.0 and dy == 0.0 and dz == 0.0:  # centres a round-off apart: their offset is B's side
            nx, ny, nz, _ = unit_vector(ox, oy, oz)
            return nx, ny, nz
        if abs(dx) <= abs(dy) and abs(dx) <= abs(dz):  # d × e_x: perpendicular to d
            nx, ny, nz = 0.0, dz, -dy
        elif abs(dy) <= abs(dz):
            nx, ny, nz = -dz, 0.0, dx
        else:
            nx, ny, nz = dy, -dx, 0.0
    nx, ny, nz, _ = unit_vector(nx, ny, nz)
    sign = -1.0 if nx * ox + ny * oy + nz * oz < 0.0 else 1.0
    return sign * nx, sign * ny, sign * nz


@njit(inline="always")
def _magnitude(a0, a1, b0, b1):
    """The largest |coordinate| of the four ends: the scale of the round-off of c2 − c1."""
    big = 0.0
    for c in range(3):
        big = max(big, abs(a0[c]), abs(a1[c]), abs(b0[c]), abs(b1[c]))
    return big


@njit(inline="always")
def _at(p, q, u, dx, dy, dz):
    """The point p + u (q − p) of a segment, its ends exactly (u = 0 or 1: no round-off in p + (q − p))."""
    if u == 0.0:
        return p[0], p[1], p[2]
    if u == 1.0:
        return q[0], q[1], q[2]
    return p[0] + u * dx, p[1] + u * dy, p[2] + u * dz


@njit(inline="always")
def _cross(ax, ay, az, bx, by, bz):
    return ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx


@njit
def _offset(a0, b0, c1x, c1y, c1z, c2x, c2y, c2z, d1x, d1y, d1z, d2x, d2y, d2z, s, t):
    """c2 − c1, computed so that it is perpendicular to a segment whose interior holds its closest point (as it
    is exactly): the common perpendicular's component of b0 − a0 when both are interior, the part of
    c1 − b0 perpendicular to d2, d2 × ((c1 − b0) × d2) / |d2|², when only c2 is (and symmetrically) — the plain
    difference c2 − c1 would keep a round-off part along the segment, a wrong normal when the cores nearly
    meet."""
    inner_s = 0.0 < s < 1.0
    inner_t = 0.0 < t < 1.0
    if inner_s and inner_t:
        nx, ny, nz = _cross(d1x, d1y, d1z, d2x, d2y, d2z)
        length = math.sqrt(nx * nx + ny * ny + nz * nz)
        if length > 0.0:
            nx, ny, nz = nx / length, ny / length, nz / length
            h = (b0[0] - a0[0]) * nx + (b0[1] - a0[1]) * ny + (b0[2] - a0[2]) * nz
            return h * nx, h * ny, h * nz
    if inner_t:  # from c1 to its foot on B's line
        e = d2x * d2x + d2y * d2y + d2z * d2z
        wx, wy, wz = _cross(c1x - b0[0], c1y - b0[1], c1z - b0[2], d2x, d2y, d2z)
        px, py, pz = _cross(d2x, d2y, d2z, wx, wy, wz)
        return -px / e, -py / e, -pz / e
    if inner_s:  # from c2's foot on A's line to c2
        a = d1x * d1x + d1y * d1y + d1z * d1z
        wx, wy, wz = _cross(c2x - a0[0], c2y - a0[1], c2z - a0[2], d1x, d1y, d1z)
        px, py, pz = _cross(d1x, d1y, d1z, wx, wy, wz)
        return px / a, py / a, pz / a
    return c2x - c1x, c2y - c1y, c2z - c1z


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
    c1x, c1y, c1z = _at(a0, a1, s, d1x, d1y, d1z)
    c2x, c2y, c2z = _at(b0, b1, t, d2x, d2y, d2z)
    vx, vy, vz = _offset(a0, b0, c1x, c1y, c1z, c2x, c2y, c2z, d1x, d1y, d1z, d2x, d2y, d2z, s, t)
    d = math.sqrt(vx * vx + vy * vy + vz * vz)
    if d > MEET * _magnitude(a0, a1, b0, b1):
        nx, ny, nz, _ = unit_vector(vx, vy, vz)
    else:  # the cores meet, or are apart by round-off only: c2 − c1 has no reliable direction
        # o = B's midpoint − A's as a sum of end differences (exact for ends a round-off apart, Sterbenz)
        nx, ny, nz = _fallback_normal(d1x, d1y, d1z, d2x, d2y, d2z, 0.5 * ((b0[0] - a0[0]) + (b1[0] - a1[0])),
                                      0.5 * ((b0[1] - a0[1]) + (b1[1] - a1[1])),
                                      0.5 * ((b0[2] - a0[2]) + (b1[2] - a1[2])))
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
    # B's line offset from A's line: the component of b0 − a0 perpendicular to u, u × ((b0 − a0) × u) (not
    # w0 − t0 u, whose round-off along u would tilt the normal when the lines nearly coincide)
    cx, cy, cz = _cross(w0x, w0y, w0z, ux, uy, uz)
    wx, wy, wz = _cross(ux, uy, uz, cx, cy, cz)
    d = math.sqrt(wx * wx + wy * wy + wz * wz)
    if d > MEET * _magnitude(a0, a1, b0, b1):
        nx, ny, nz, _ = unit_vector(wx, wy, wz)
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
    return contact_of_one_pair(contact_round_cores, (ends[0], ends[1], ra, ends[2], ends[3], rb), radius_a=ra,
                               radius_b=rb, scratch_points=None)
