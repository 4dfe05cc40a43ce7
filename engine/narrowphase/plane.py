"""A convex body against a plane ground: the chapter's "sol plat" (y <= altitude is solid), for every body whose
core is a point set swept by a ball — sphere (1 point), capsule (2), box (8 corners), convex hull (its
vertices).

The ground is the half-space (x − o)·u <= 0, with o a point of its surface and u its outward unit normal. Each
core point v of the body (radius r) reaches below the surface by h_v = (o − v)·u + r; the body touches the
ground when the largest h_v is >= 0, and that is the exact penetration depth (the lowest point of a convex body
is one of its core points, minus r along u). Every core point with h_v >= 0 is a contact point, placed halfway
between the body's surface point v − r u and the ground: v + (h_v / 2 − r) u; more than ``MAX_POINTS`` are
reduced to 4 (``contacts.reduce_manifold``: the deepest, then the largest area). So a box on the ground gets
its 4 bottom corners, exactly on the ground's normal; a sphere its lowest point; a capsule lying flat both ends.

Features: the body's point set gives a vertex (1 point), an edge (2) or a face (3 or more: "sphere", "cylinder",
"face" when rounded), each point the body's vertex number; the ground is its face 0.
"""
from __future__ import annotations

import numpy as np

from .._config import njit
from .._validate import as_float_array, as_nonnegative
from .contacts import (
    EDGE,
    FACE,
    VERTEX,
    contact_of_one_pair,
    feature_key,
    point_id,
    reduce_manifold,
    swap_point_id,
    write_pair,
)

__all__ = ["contact_points_plane", "contact_points_plane_pair", "impact_time_plane"]


@njit
def contact_points_plane(points, counts, radii, i, origin, up, rows, p, flip, scratch):
    """Body i — core ``points[i, :counts[i]]`` (points (n, m, 3)) swept by ``radii[i]`` — against the ground
    through ``origin`` (3,) of outward unit normal ``up`` (3,), into row p of ``rows`` (the kernel's A is the
    body, B the ground; ``flip``: the pair's first shape is the ground); ``scratch`` a contacts.Scratch with
    room for m points. Returns the separation (minus the depth)."""
    radius = radii[i]
    pts, deep, ids = scratch.pts, scratch.deep, scratch.ids
    depth = -np.inf
    n = np.int64(0)  # typed int64 from the start: reduce_manifold is compiled for one count type
    for v in range(counts[i]):
        h = ((origin[0] - points[i, v, 0]) * up[0] + (origin[1] - points[i, v, 1]) * up[1]
             + (origin[2] - points[i, v, 2]) * up[2]) + radius
        depth = max(depth, h)
        if h >= 0.0:
            lift = 0.5 * h - radius
            for c in range(3):
                pts[n, c] = points[i, v, c] + lift * up[c]
            deep[n] = h
            ids[n] = point_id(feature_key(VERTEX, v), feature_key(FACE, 0))
            n += 1
    # from the body (A) to the ground (B): the ground moves down along −up to separate
    if n == 0:
        write_pair(rows, p, -depth, -up[0], -up[1], -up[2], VERTEX, FACE, 0, flip)
        return -depth
    kind = VERTEX if n == 1 else (EDGE if n == 2 else FACE)
    n = reduce_manifold(pts, deep, ids, n, up[0], up[1], up[2], scratch)
    for v in range(n):
        for c in range(3):
            rows.points[p, v, c] = pts[v, c]
        rows.ids[p, v] = swap_point_id(ids[v]) if flip else ids[v]
    write_pair(rows, p, -depth, -up[0], -up[1], -up[2], kind, FACE, n, flip)
    return -depth


@njit
def impact_time_plane(points, counts, radii, velocity, i, origin, up, dt):
    """First t in [0, dt] at which body i (core ``points[i, :counts[i]]`` swept by ``radii[i]``, translating with
    ``velocity`` (3,)) touches the ground through ``origin`` of outward normal ``up``: its lowest point moves
    linearly, so t = gap / (−v·u); 0 when it already touches, inf when it does not within dt."""
    low = np.inf
    for v in range(counts[i]):
        low = min(low, (points[i, v, 0] - origin[0]) * up[0] + (points[i, v, 1] - origin[1]) * up[1]
                  + (points[i, v, 2] - origin[2]) * up[2])
    gap = low - radii[i]
    if gap <= 0.0:
        return 0.0
    rate = velocity[0] * up[0] + velocity[1] * up[1] + velocity[2] * up[2]
    if rate >= 0.0:
        return np.inf
    t = gap / -rate
    return t if t <= dt else np.inf


def contact_points_plane_pair(points, radius, altitude):
    """The contact of the body whose core is ``points`` (m, 3) swept by ``radius`` >= 0 with the ground
    ``Plane(altitude)`` (solid below y = altitude): a ContactSet of one pair (body first; separation > 0 when
    the body is above)."""
    pts = as_float_array(points, "points", shape=(None, 3), min_rows=1)
    r = as_nonnegative(radius, "radius")
    a = as_float_array([0.0, altitude, 0.0], "altitude", shape=(3,))
    m = pts.shape[0]
    return contact_of_one_pair(contact_points_plane, (pts[None], np.array([m]), np.array([r]), 0, a,
                                                      np.array([0.0, 1.0, 0.0])), radius_a=r, scratch_points=m)
