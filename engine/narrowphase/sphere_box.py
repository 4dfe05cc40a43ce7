"""Sphere against an oriented box: the closest point of an OBB (Ericson 5.1.3, ``ClosestPtPointOBB``).

In the box's frame (centre c, axes u_k = the columns of its rotation, half extents e_k) the sphere's centre has
coordinates d_k = (p − c)·u_k; the closest point of the box clamps each to [−e_k, e_k]. The number of clamped
coordinates says which feature of the box is nearest — 1 a face, 2 an edge, 3 a vertex (its Voronoi region) —
and gives the contact:

- a face (axis k, side σ = sign d_k): the normal is exactly that face's normal: from the sphere to the box
  n = −σ u_k, separation = |d_k| − e_k − r — a sphere resting on a face gets that face's normal, to the bit;
- an edge or a vertex: n = (q − p)/|q − p| with q − p rotated from its box-frame coordinates, separation
  = |q − p| − r;
- the centre inside the box: the nearest face (smallest e_k − |d_k|) is where the sphere gets out: n = −σ u_k,
  separation = −(r + e_k − |d_k|).

The contact point lies halfway between the sphere's deepest point p + r n and the box's surface along n.
Features: the sphere is its vertex 0 ("sphere"); the box's vertex / edge / face number as in
``engine.narrowphase.contacts``.
"""
from __future__ import annotations

import math

import numpy as np

from .._config import njit
from .._validate import as_float_array, as_half_extents, as_positive
from ..bounding.aabb import as_rotation_matrix
from .contacts import (
    EDGE,
    FACE,
    VERTEX,
    contact_of_one_pair,
    feature_key,
    write_pair,
    write_point,
)
from .touching_normal import unit_vector

__all__ = ["contact_sphere_box", "contact_sphere_box_pair", "box_feature_key"]


@njit(inline="always")
def box_feature_key(region, sx, sy, sz):
    """The key of a box feature from its clamp signs per axis (+1, −1, or 0: inside along that axis):
    ``region`` = the number of non-zero signs (1 face, 2 edge, 3 vertex)."""
    if region == 3:
        return feature_key(VERTEX, 4 * (sx > 0) + 2 * (sy > 0) + (sz > 0))
    if region == 1:
        axis = 0 if sx != 0 else (1 if sy != 0 else 2)
        side = sx + sy + sz
        return feature_key(FACE, 2 * axis + (side > 0))
    # an edge along the axis whose sign is 0, at the signs of the two others (in axis order)
    if sx == 0:
        return feature_key(EDGE, 0 + 2 * (sy > 0) + (sz > 0))
    if sy == 0:
        return feature_key(EDGE, 4 + 2 * (sx > 0) + (sz > 0))
    return feature_key(EDGE, 8 + 2 * (sx > 0) + (sy > 0))


@njit(inline="always")
def contact_sphere_box(centers, radii, rotations, halves, i, j, rows, p_row, flip, scratch):
    """Sphere i (centre centers[i], radius radii[i]) against box j (centre centers[j], rotation rotations[j]
    whose columns are its axes, half extents halves[j]) into row ``p_row`` of ``rows``; ``flip``: the pair's
    first shape is the box; ``scratch`` a contacts.Scratch. Returns the separation."""
    r = radii[i]
    dx, dy, dz = centers[i, 0] - centers[j, 0], centers[i, 1] - centers[j, 1], centers[i, 2] - centers[j, 2]
    d, q, sign = scratch.vec, scratch.vec[3:], scratch.ivec
    clamped = 0
    for k in range(3):
        e = halves[j, k]
        d[k] = dx * rotations[j, 0, k] + dy * rotations[j, 1, k] + dz * rotations[j, 2, k]
        q[k] = min(max(d[k], -e), e)
        sign[k] = 1 if d[k] > e else (-1 if d[k] < -e else 0)
        clamped += sign[k] != 0
    px, py, pz = centers[i, 0], centers[i, 1], centers[i, 2]
    if clamped <= 1:  # a face region, or inside: the face normal exactly
        if clamped == 1:
            k = 0 if sign[0] != 0 else (1 if sign[1] != 0 else 2)
        else:  # inside: the face nearest to the centre
            k = 0
            for m in range(1, 3):
                if halves[j, m] - abs(d[m]) < halves[j, k] - abs(d[k]):
                    k = m
            sign[k] = 1 if d[k] >= 0.0 else -1
        gap = abs(d[k]) - halves[j, k]  # the centre's height above the face (< 0: below it)
        s = float(sign[k])
        nx, ny, nz = -s * rotations[j, 0, k], -s * rotations[j, 1, k], -s * rotations[j, 2, k]
        separation = gap - r
        lift = 0.5 * (gap + r)  # from the centre to halfway between the sphere's deepest point and the face
        key = box_feature_key(1, sign[0] if k == 0 else 0, sign[1] if k == 1 else 0, sign[2] if k == 2 else 0)
        write_point(rows, p_row, 0, px + lift * nx, py + lift * ny, pz + lift * nz, feature_key(VERTEX, 0), key,
                    flip)
        write_pair(rows, p_row, separation, nx, ny, nz, VERTEX, FACE, 1, flip)
        return separation
    # an edge or a vertex: q − p from its box-frame coordinates
    vx = vy = vz = 0.0
    for k in range(3):
        delta = q[k] - d[k]
        vx += delta * rotations[j, 0, k]
        vy += delta * rotations[j, 1, k]
        vz += delta * rotations[j, 2, k]
    dist = math.sqrt(vx * vx + vy * vy + vz * vz)
    nx, ny, nz, _ = unit_vector(vx, vy, vz)
    separation = dist - r
    lift = 0.5 * (dist + r)
    key = box_feature_key(clamped, sign[0], sign[1], sign[2])
    write_point(rows, p_row, 0, px + lift * nx, py + lift * ny, pz + lift * nz, feature_key(VERTEX, 0), key, flip)
    write_pair(rows, p_row, separation, nx, ny, nz, VERTEX, EDGE if clamped == 2 else VERTEX, 1, flip)
    return separation


def contact_sphere_box_pair(center, radius, box_center, box_rotation, half_extents):
    """The contact of a sphere (centre (3,), radius > 0) and a box (centre (3,), rotation (3, 3) whose columns
    are its axes or a unit quaternion (w, x, y, z), half extents (3,) > 0): a ContactSet of one pair (sphere
    first; separation > 0 when apart)."""
    centers = np.stack([as_float_array(center, "center", shape=(3,)),
                        as_float_array(box_center, "box_center", shape=(3,))])
    r = as_positive(radius, "radius")
    rotations = np.stack([np.eye(3), as_rotation_matrix(box_rotation, "box_rotation")])
    e = as_half_extents(half_extents, "half_extents")
    return contact_of_one_pair(contact_sphere_box, (centers, np.array([r, 0.0]), rotations,
                                                    np.stack([np.zeros(3), e]), 0, 1), radius_a=r)
