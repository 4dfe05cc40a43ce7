"""Box against box: the separating axis test with the penetration depth, then the contact manifold by clipping
(Ericson 4.4.1 ``TestOBBOBB``; the manifold as ODE's ``dBoxBox`` and Box2D's ``b2CollidePolygons`` build it).

1. SAT on the 15 axes — the 3 face normals of A, the 3 of B, the 9 cross products A_i × B_j of their edges —
   in A's frame (R_ij = A_i·B_j, t = B's centre in A's frame). On each axis L the projections overlap by
   r_A + r_B − |t·L| (divided by |L| for a cross product); a negative overlap on any axis separates the boxes.
   The overlap tests of the cross products add ``PARALLEL_EPS`` × the extents, as Ericson adds ε to |R|: for
   (nearly) parallel edges L is (nearly) zero and every term is round-off, which must never separate two boxes
   that touch. Otherwise the smallest overlap is the exact penetration depth (for two convex polyhedra the
   minimum over face normals and edge–edge cross products is the minimum translation distance); a cross product
   shorter than ``EDGE_AXIS_MIN`` is not a candidate normal (its parallel edges are covered by the faces), and a
   later axis replaces an earlier one only when it is smaller by more than ``TIE`` × the boxes' size (faces of
   A, then of B, then edges: the order breaks round-off ties).
2. A face axis: that face is the *reference* face, the most anti-parallel face of the other box the *incident*
   face. The incident quad is clipped by the four side planes of the reference face (Sutherland–Hodgman,
   Ericson 8.3.4), its points below the reference face are kept (at most 8), reduced to 4 (deepest first, then
   the largest area: ``contacts.reduce_manifold``), and each is placed halfway between itself and the
   reference face. An edge axis: the closest points of the two edges (Ericson 5.1.9), one point halfway.

Point ids (Box2D's ``b2ContactFeature``): a vertex of the incident face inside the reference face is (reference
face, incident vertex); a crossing of an incident edge with a side of the reference face is (the reference edge
on that side, incident edge); a corner of the reference face inside the incident face is (reference vertex,
incident face); edge–edge is (edge of A, edge of B). They do not depend on which box is the reference, so a
contact whose reference face switches between the two boxes keeps its ids.
"""
from __future__ import annotations

import math

import numpy as np

from .._config import njit
from .._validate import as_float_array
from ..bounding.aabb import as_rotation_matrix
from .contacts import (
    EDGE,
    FACE,
    VERTEX,
    contact_rows,
    contact_set_from_rows,
    feature_key,
    key_kind,
    point_id,
    reduce_manifold,
    swap_point_id,
    write_pair,
    write_point,
)
from .sat import PARALLEL_EPS
from .segment_segment import closest_segment_parameters
from .sphere_box import box_feature_key

__all__ = ["EDGE_AXIS_MIN", "TIE", "sat_box_box", "contact_box_box", "overlap_box_box", "contact_box_box_pair"]

#: cross products of edges shorter than this (sin of the edges' angle) are not candidate contact normals
EDGE_AXIS_MIN = 1e-7
#: relative margin (× the sum of the half extents) by which a later SAT axis must be smaller to be chosen
TIE = 1e-12


@njit
def sat_box_box(ca, Ra, ea, cb, Rb, eb):
    """Ericson 4.4.1 with depths: boxes (centre (3,), rotation (3, 3) whose columns are the axes, half extents
    (3,)). Returns (overlap, axis, penetration, nx, ny, nz): axis 0-2 a face of A, 3-5 of B, 6 + 3 i + j the
    edge pair A_i × B_j; n the unit axis from A towards B (world); penetration >= 0 when they overlap, else
    minus the gap along the separating axis found (a lower bound of their distance)."""
    R = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            R[i, j] = Ra[0, i] * Rb[0, j] + Ra[1, i] * Rb[1, j] + Ra[2, i] * Rb[2, j]
    dx, dy, dz = cb[0] - ca[0], cb[1] - ca[1], cb[2] - ca[2]
    t = np.empty(3)
    for i in range(3):
        t[i] = dx * Ra[0, i] + dy * Ra[1, i] + dz * Ra[2, i]
    tie = TIE * (ea[0] + ea[1] + ea[2] + eb[0] + eb[1] + eb[2])
    best = np.inf
    axis = -1
    lx = ly = lz = 0.0  # the best axis in A's frame, oriented from A to B
    for i in range(3):  # faces of A
        tl = t[i]
        overlap = ea[i] + eb[0] * abs(R[i, 0]) + eb[1] * abs(R[i, 1]) + eb[2] * abs(R[i, 2]) - abs(tl)
        if overlap < 0.0:
            return False, i, overlap, 0.0, 0.0, 0.0
        if overlap < best - tie:
            best, axis = overlap, i
            s = 1.0 if tl >= 0.0 else -1.0
            lx, ly, lz = s * (i == 0), s * (i == 1), s * (i == 2)
    for j in range(3):  # faces of B
        tl = t[0] * R[0, j] + t[1] * R[1, j] + t[2] * R[2, j]
        overlap = ea[0] * abs(R[0, j]) + ea[1] * abs(R[1, j]) + ea[2] * abs(R[2, j]) + eb[j] - abs(tl)
        if overlap < 0.0:
            return False, 3 + j, overlap, 0.0, 0.0, 0.0
        if overlap < best - tie:
            best, axis = overlap, 3 + j
            s = 1.0 if tl >= 0.0 else -1.0
            lx, ly, lz = s * R[0, j], s * R[1, j], s * R[2, j]
    for i in range(3):  # edges: L = A_i × B_j, in A's frame L[i] = 0, L[i1] = −R[i2, j], L[i2] = R[i1, j]
        i1, i2 = (i + 1) % 3, (i + 2) % 3
        for j in range(3):
            j1, j2 = (j + 1) % 3, (j + 2) % 3
            tl = t[i2] * R[i1, j] - t[i1] * R[i2, j]
            reach = (ea[i1] * abs(R[i2, j]) + ea[i2] * abs(R[i1, j]) + eb[j1] * abs(R[i, j2])
                     + eb[j2] * abs(R[i, j1]))
            slack = PARALLEL_EPS * (ea[i1] + ea[i2] + eb[j1] + eb[j2])
            if abs(tl) > reach + slack:
                return False, 6 + 3 * i + j, reach - abs(tl), 0.0, 0.0, 0.0
            length = math.sqrt(R[i1, j] * R[i1, j] + R[i2, j] * R[i2, j])
            if length > EDGE_AXIS_MIN:
                overlap = max(reach - abs(tl), 0.0) / length
                if overlap < best - tie:
                    best, axis = overlap, 6 + 3 * i + j
                    s = (1.0 if tl >= 0.0 else -1.0) / length
                    v = np.zeros(3)
                    v[i1] = -s * R[i2, j]
                    v[i2] = s * R[i1, j]
                    lx, ly, lz = v[0], v[1], v[2]
    nx = lx * Ra[0, 0] + ly * Ra[0, 1] + lz * Ra[0, 2]
    ny = lx * Ra[1, 0] + ly * Ra[1, 1] + lz * Ra[1, 2]
    nz = lx * Ra[2, 0] + ly * Ra[2, 1] + lz * Ra[2, 2]
    return True, axis, best, nx, ny, nz


@njit
def overlap_box_box(ca, Ra, ea, cb, Rb, eb):
    """True when the two boxes overlap (touching counts): the SAT of ``sat_box_box``."""
    return sat_box_box(ca, Ra, ea, cb, Rb, eb)[0]


@njit(inline="always")
def _signs_key(region, signs):
    return box_feature_key(region, signs[0], signs[1], signs[2])


@njit
def _incident_quad(cr, Rr, er, i, nrx, nry, nrz, ci, Ri, ei, poly, tags):
    """The incident face of box (ci, Ri, ei) against the reference face of (cr, Rr, er) with axis i and outward
    normal nr: its 4 corners into ``poly`` (rows x, y in the reference face's frame, world x, y, z, depth below
    the reference face) and ``tags`` (rows: reference key, incident key, out-edge kind (0 incident edge, 1
    reference side), out-edge key or side). Returns the incident face's key."""
    best = -1.0
    a = 0
    for m in range(3):
        dot = abs(Ri[0, m] * nrx + Ri[1, m] * nry + Ri[2, m] * nrz)
        if dot > best:
            best, a = dot, m
    tau = -1 if Ri[0, a] * nrx + Ri[1, a] * nry + Ri[2, a] * nrz > 0.0 else 1
    b1, b2 = (a + 1) % 3, (a + 2) % 3
    if b1 > b2:
        b1, b2 = b2, b1
    j, k = (i + 1) % 3, (i + 2) % 3
    if j > k:
        j, k = k, j
    ref_face = _ref_face_key(Rr, i, nrx, nry, nrz)
    signs = np.zeros(3, np.int64)
    for m in range(4):
        s1 = -1 if m == 0 or m == 3 else 1
        s2 = -1 if m <= 1 else 1
        signs[a], signs[b1], signs[b2] = tau, s1, s2
        wx = ci[0] + tau * ei[a] * Ri[0, a] + s1 * ei[b1] * Ri[0, b1] + s2 * ei[b2] * Ri[0, b2]
        wy = ci[1] + tau * ei[a] * Ri[1, a] + s1 * ei[b1] * Ri[1, b1] + s2 * ei[b2] * Ri[1, b2]
        wz = ci[2] + tau * ei[a] * Ri[2, a] + s1 * ei[b1] * Ri[2, b1] + s2 * ei[b2] * Ri[2, b2]
        rx, ry, rz = wx - cr[0], wy - cr[1], wz - cr[2]
        poly[m, 0] = rx * Rr[0, j] + ry * Rr[1, j] + rz * Rr[2, j]
        poly[m, 1] = rx * Rr[0, k] + ry * Rr[1, k] + rz * Rr[2, k]
        poly[m, 2], poly[m, 3], poly[m, 4] = wx, wy, wz
        poly[m, 5] = er[i] - (rx * nrx + ry * nry + rz * nrz)
        tags[m, 0] = ref_face
        tags[m, 1] = _signs_key(3, signs)
        # the edge to the next corner runs along b1 (m = 0, 2) or b2 (m = 1, 3)
        signs[b1 if m % 2 == 0 else b2] = 0
        tags[m, 2] = 0
        tags[m, 3] = _signs_key(2, signs)
    signs[:] = 0
    signs[a] = tau
    return _signs_key(1, signs)


@njit(inline="always")
def _ref_face_key(Rr, i, nrx, nry, nrz):
    side = 1 if Rr[0, i] * nrx + Rr[1, i] * nry + Rr[2, i] * nrz > 0.0 else 0
    return feature_key(FACE, 2 * i + side)


@njit
def _clip_side(poly, tags, n, side, bound, axes, ref_signs, inc_face, out, out_tags):
    """Sutherland–Hodgman step: the part of the polygon poly[:n] with sign·coordinate <= bound (side 0: x <=
    e_j, 1: x >= −e_j, 2: y <= e_k, 3: y >= −e_k; ``axes`` = (j, k) the reference box's axes along x and y),
    into out[:m]; returns m. A new point gets its id: an incident edge crossing the side is (the reference edge
    on that side, incident edge); a reference side crossing it is a corner of the reference face (reference
    vertex, incident face)."""
    c = side // 2
    sign = 1 if side % 2 == 0 else -1
    m = 0
    for v in range(n):
        w = (v + 1) % n
        pin = sign * poly[v, c] <= bound
        qin = sign * poly[w, c] <= bound
        if pin:
            out[m] = poly[v]
            out_tags[m] = tags[v]
            m += 1
        if pin != qin:
            u = (bound - sign * poly[v, c]) / (sign * poly[w, c] - sign * poly[v, c])
            for col in range(6):
                out[m, col] = poly[v, col] + u * (poly[w, col] - poly[v, col])
            out[m, c] = sign * bound
            signs = ref_signs.copy()
            signs[axes[c]] = sign
            if tags[v, 2] == 0:  # an incident edge crosses this side
                out_tags[m, 0] = _signs_key(2, signs)
                out_tags[m, 1] = tags[v, 3]
            elif tags[v, 3] // 2 != c:  # an earlier side crosses this one: a corner of the reference face
                signs[axes[tags[v, 3] // 2]] = 1 if tags[v, 3] % 2 == 0 else -1
                out_tags[m, 0] = _signs_key(3, signs)
                out_tags[m, 1] = inc_face
            else:  # (round-off) a side parallel to this one
                out_tags[m, 0] = _signs_key(2, signs)
                out_tags[m, 1] = inc_face
            # from here the polygon runs along this side (leaving) or on along the crossed edge (entering)
            out_tags[m, 2] = 1 if pin else tags[v, 2]
            out_tags[m, 3] = side if pin else tags[v, 3]
            m += 1
    return m


@njit
def _face_contact(cr, Rr, er, i, nrx, nry, nrz, ci, Ri, ei, ref_is_a, rows, p, flip, depth):
    """The manifold of a face axis: reference face i of box r (outward normal nr, towards box i), incident face
    of box i clipped by its side planes. Writes row p (``ref_is_a``: the reference box is the kernel's A)."""
    poly = np.empty((9, 6))
    work = np.empty((9, 6))
    tags = np.zeros((9, 4), np.int64)
    work_tags = np.zeros((9, 4), np.int64)
    inc_face = _incident_quad(cr, Rr, er, i, nrx, nry, nrz, ci, Ri, ei, poly, tags)
    j, k = (i + 1) % 3, (i + 2) % 3
    if j > k:
        j, k = k, j
    axes = np.array([j, k])
    ref_signs = np.zeros(3, np.int64)
    ref_signs[i] = 1 if Rr[0, i] * nrx + Rr[1, i] * nry + Rr[2, i] * nrz > 0.0 else -1
    n = 4
    for side in range(4):
        bound = er[j] if side < 2 else er[k]
        n = _clip_side(poly, tags, n, side, bound, axes, ref_signs, inc_face, work, work_tags)
        poly, work = work, poly
        tags, work_tags = work_tags, tags
        if n == 0:
            break
    pts = np.empty((9, 3))
    deep = np.empty(9)
    ids = np.empty(9, np.int64)
    count = 0
    for v in range(n):  # the points below the reference face
        if poly[v, 5] >= 0.0:
            pts[count, 0], pts[count, 1], pts[count, 2] = poly[v, 2], poly[v, 3], poly[v, 4]
            deep[count] = poly[v, 5]
            ids[count] = point_id(tags[v, 0], tags[v, 1]) if ref_is_a else point_id(tags[v, 1], tags[v, 0])
            count += 1
    if count == 0:  # round-off clipped everything: the reference face's centre, at the SAT depth
        count = 1
        for c in range(3):
            pts[0, c] = cr[c] + er[i] * ref_signs[i] * Rr[c, i] - depth * (nrx, nry, nrz)[c]
        deep[0] = depth
        ids[0] = point_id(tags[0, 0], inc_face) if ref_is_a else point_id(inc_face, tags[0, 0])
    nr = np.array([nrx, nry, nrz])
    count = reduce_manifold(pts, deep, ids, count, nr)
    for v in range(count):
        h = 0.5 * deep[v]
        rows.points[p, v, 0] = pts[v, 0] + h * nrx
        rows.points[p, v, 1] = pts[v, 1] + h * nry
        rows.points[p, v, 2] = pts[v, 2] + h * nrz
        rows.ids[p, v] = swap_point_id(ids[v]) if flip else ids[v]
    inc_kind = VERTEX if count == 1 else (EDGE if count == 2 else FACE)
    sign = 1.0 if ref_is_a else -1.0  # the kernel's normal runs from A to B
    write_pair(rows, p, -depth, sign * nrx, sign * nry, sign * nrz, FACE if ref_is_a else inc_kind,
               inc_kind if ref_is_a else FACE, count, flip)


@njit
def _edge_contact(ca, Ra, ea, cb, Rb, eb, i, j, nx, ny, nz, rows, p, flip, depth):
    """The contact of an edge–edge axis A_i × B_j: the closest points of A's edge along A_i that is farthest
    along n and B's edge along B_j farthest along −n (Ericson 5.1.9); one point halfway between them."""
    sa = np.zeros(3, np.int64)
    sb = np.zeros(3, np.int64)
    a0 = ca.copy()
    b0 = cb.copy()
    for m in range(3):
        da = Ra[0, m] * nx + Ra[1, m] * ny + Ra[2, m] * nz
        db = Rb[0, m] * nx + Rb[1, m] * ny + Rb[2, m] * nz
        if m != i:
            sa[m] = 1 if da >= 0.0 else -1
            a0 += sa[m] * ea[m] * Ra[:, m]
        if m != j:
            sb[m] = -1 if db > 0.0 else 1
            b0 += sb[m] * eb[m] * Rb[:, m]
    a1 = a0 + ea[i] * Ra[:, i]
    a0 = a0 - ea[i] * Ra[:, i]
    b1 = b0 + eb[j] * Rb[:, j]
    b0 = b0 - eb[j] * Rb[:, j]
    s, t, _ = closest_segment_parameters(a0, a1, b0, b1)
    key_a = _signs_key(2, sa)
    key_b = _signs_key(2, sb)
    mid = 0.5 * (a0 + s * (a1 - a0) + b0 + t * (b1 - b0))
    write_point(rows, p, 0, mid[0], mid[1], mid[2], key_a, key_b, flip)
    write_pair(rows, p, -depth, nx, ny, nz, key_kind(key_a), key_kind(key_b), 1, flip)


@njit
def contact_box_box(ca, Ra, ea, cb, Rb, eb, rows, p, flip):
    """Box A (centre (3,), rotation (3, 3), columns the axes, half extents (3,)) against box B into row p of
    ``rows``; ``flip``: the pair's first shape is B. Returns the separation (apart: minus the SAT overlap on
    the separating axis found, a lower bound of the distance)."""
    overlap, axis, depth, nx, ny, nz = sat_box_box(ca, Ra, ea, cb, Rb, eb)
    if not overlap:
        write_pair(rows, p, -depth, nx, ny, nz, 0, 0, 0, flip)
        return -depth
    if axis < 3:
        _face_contact(ca, Ra, ea, axis, nx, ny, nz, cb, Rb, eb, True, rows, p, flip, depth)
    elif axis < 6:
        _face_contact(cb, Rb, eb, axis - 3, -nx, -ny, -nz, ca, Ra, ea, False, rows, p, flip, depth)
    else:
        _edge_contact(ca, Ra, ea, cb, Rb, eb, (axis - 6) // 3, (axis - 6) % 3, nx, ny, nz, rows, p, flip, depth)
    return -depth


def contact_box_box_pair(center_a, rotation_a, half_extents_a, center_b, rotation_b, half_extents_b):
    """The contact of two boxes (centre (3,), rotation (3, 3) whose columns are the axes or a unit quaternion
    (w, x, y, z), half extents (3,) > 0): a ContactSet of one pair (separation > 0 when apart: a lower bound of
    the distance, the gap along a separating axis)."""
    boxes = []
    for tag, (c, r, e) in (("a", (center_a, rotation_a, half_extents_a)), ("b", (center_b, rotation_b,
                                                                                 half_extents_b))):
        c = as_float_array(c, f"center_{tag}", shape=(3,))
        r = np.ascontiguousarray(as_rotation_matrix(r, f"rotation_{tag}"))
        e = as_float_array(e, f"half_extents_{tag}", shape=(3,))
        if (e <= 0).any():
            k = int(np.argmax(e <= 0))
            raise ValueError(f"half_extents_{tag} must be > 0: half_extents_{tag}[{k}] = {e[k]!r}")
        boxes += [c, r, e]
    rows = contact_rows(1)
    contact_box_box(*boxes, rows, 0, False)
    return contact_set_from_rows(rows, np.array([[0, 1]], np.int64), np.zeros(1), np.zeros(1), keep_apart=True)
