"""Box against box: the separating axis test with the penetration depth, then the contact manifold by clipping
(Ericson 4.4.1 ``TestOBBOBB``; the manifold as ODE's ``dBoxBox`` and Box2D's ``b2CollidePolygons`` build it).

1. SAT on the 15 axes — the 3 face normals of A, the 3 of B, the 9 cross products A_i × B_j of their edges —
   in A's frame (R_ij = A_i·B_j, t = B's centre in A's frame). On each axis L the projections overlap by
   r_A + r_B − |t·L| (divided by |L| for a cross product); a negative overlap on any axis separates the boxes.
   The overlap tests of the cross products add ``PARALLEL_EPS`` × the extents, as Ericson adds ε to |R|: for
   (nearly) parallel edges L is (nearly) zero and every term is round-off, which must never separate two boxes
   that touch. Otherwise the smallest overlap is the exact penetration depth (for two convex polyhedra the
   minimum over face normals and edge–edge cross products is the minimum translation distance), reported with
   its axis as the normal (the face's own normal when the face ties it to round-off, ``ROUND_OFF``); a cross
   product shorter than ``EDGE_AXIS_MIN`` is not a candidate normal (its parallel edges are covered by the
   faces). The feature pair that gives the points is a face — among the faces a later one replaces an earlier
   one only when it is smaller by more than ``TIE`` × the boxes' size (faces of A, then of B) — unless the best
   edge axis beats it by more than that margin over |A_i × B_j| *and* lies farther than arccos(``FACE_KEEP_COS``)
   from the face normal (``prefer_face``): nearly flush boxes keep their face manifold even where an edge axis
   between the two face normals has the least overlap (its depth and normal are still the ones reported).
2. A face axis: that face is the *reference* face, the most anti-parallel face of the other box the *incident*
   face. The incident quad is clipped by the four side planes of the reference face (Sutherland–Hodgman,
   Ericson 8.3.4), its points below the reference face are kept (at most 8), reduced to 4 (deepest first, then
   the largest area: ``contacts.reduce_manifold``), and each is placed halfway between itself and the
   reference face. An edge axis: the closest points of the two edges (Ericson 5.1.9), one point halfway.

Feature kinds (``feature_a``, ``feature_b``: the feature of each side that touches): a face axis reports the
reference box's FACE and, for the incident box, the feature its kept points span — 1 point a VERTEX (a corner
pressed into the face), 2 an EDGE (a box resting on one of its edges: "face-edge"), 3 or 4 a FACE; an edge axis
reports EDGE on both sides ("edge-edge").

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
from .._validate import as_float_array, as_half_extents
from ..bounding.aabb import as_rotation_matrix
from .contacts import (
    EDGE,
    FACE,
    VERTEX,
    contact_of_one_pair,
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

__all__ = ["EDGE_AXIS_MIN", "TIE", "FACE_SLOP", "ROUND_OFF", "FACE_KEEP_COS", "prefer_face", "sat_box_box",
           "contact_box_box", "overlap_box_box", "contact_box_box_pair"]

#: cross products of edges shorter than this (sin of the edges' angle) are not candidate contact normals
EDGE_AXIS_MIN = 1e-7
#: relative margin (× the sum of the half extents) by which a later SAT axis must be smaller to be chosen
TIE = 1e-12
#: relative round-off (× the magnitude of the boxes' coordinates: the largest |centre coordinate| of each box plus
#: all half extents) within which a clipped point on the reference face's plane counts as below it
FACE_SLOP = 1e-14
#: relative round-off of an overlap (× the magnitude of its terms: half extents and |centre offset|): two overlaps
#: that close are equal, and the face's normal is reported for both
ROUND_OFF = 64.0 * np.finfo(np.float64).eps
#: a face's manifold is kept over an edge axis of smaller overlap within this cosine of the face normal (the edge
#: axis at most arccos(1 / 1.05) = 17.8° from it: ODE's ``fudge_factor``, see ``prefer_face``)
FACE_KEEP_COS = 1.0 / 1.05


@njit(inline="always")
def _edge_axis(R, a, b, tl, length):
    """The unit edge axis A_a × B_b in A's frame (R_ij = A_i·B_j, ``length`` = |A_a × B_b| > 0), turned so that
    the projection ``tl`` of B's centre on it is >= 0: L[a] = 0, L[a1] = −R[a2, b], L[a2] = R[a1, b]."""
    a1, a2 = (a + 1) % 3, (a + 2) % 3
    s = (1.0 if tl >= 0.0 else -1.0) / length
    return (0.0 if a == 0 else (-s * R[a2, b] if a1 == 0 else s * R[a1, b]),
            0.0 if a == 1 else (-s * R[a2, b] if a1 == 1 else s * R[a1, b]),
            0.0 if a == 2 else (-s * R[a2, b] if a1 == 2 else s * R[a1, b]))


@njit
def prefer_face(face_overlap, edge_overlap, cos_angle, tie):
    """Whether the contact points come from a face axis (its clipped manifold) rather than from an edge–edge axis
    whose overlap is smaller: True when the edge's ``edge_overlap`` does not beat ``face_overlap`` by more than
    ``tie`` (their round-off, >= 0, a length), or when the two unit axes make an angle whose cosine
    ``cos_angle`` (either sign) is at least ``FACE_KEEP_COS``. Only the points and feature kinds follow this
    choice: the caller still reports the least overlap and its axis as the depth and the normal. Shared with
    every kernel whose separating axes are faces and edge cross products (box–box, box–triangle).

    The face's manifold measures depths along the face normal n_f; the least translation is d_e along the edge
    axis L, at angle φ from n_f. A wedge of depth d_e along L is d_e / cos φ deep along n_f: the face's
    manifold overstates it by the factor 1 / cos φ. ODE's ``dBoxBox`` (and Bullet's ``btBoxBoxDetector``, its
    port) keep a face unless an edge's overlap is smaller by more than its ``fudge_factor`` 1.05, a 5 %
    overstatement; Box2D's ``b2CollidePolygons`` likewise keeps the first reference face within 0.1
    ``b2_linearSlop``. Here the 5 % bounds 1 / cos φ: cos φ >= 1 / 1.05 (φ <= 17.8°). The test is on the angle,
    not on the overlaps (ODE's form), because a face's overlap also counts the corners that hang past the other
    box's face: nearly flush boxes (φ ~ their tilt) have face overlaps above the edge's by up to tilt × overhang,
    any multiple of the depth, and would lose their face."""
    return edge_overlap >= face_overlap - tie or abs(cos_angle) >= FACE_KEEP_COS


@njit
def sat_box_box(centers, rotations, halves, i, j, R, t):
    """Ericson 4.4.1 with depths: box i against box j of the arrays ``centers`` (n, 3), ``rotations`` (n, 3, 3)
    (columns = the box axes), ``halves`` (n, 3); R (3, 3), t (>= 3,) scratch. Returns (overlap, axis,
    penetration, nx, ny, nz, fx, fy, fz). Overlapping: penetration >= 0 is the least overlap over the axes and
    n (world, unit, from i towards j) that axis, so translating j by penetration · n separates the boxes;
    ``axis`` is the feature pair that gives the contact points — 0-2 a face of i, 3-5 of j, 6 + 3 a + b the
    edge pair A_a × B_b — and f its unit axis from i towards j (a face is kept over an edge by ``prefer_face``).
    Apart: the first separating axis found, penetration = minus the gap along it (a lower bound of the
    distance), f = n."""
    Ra, Rb, ea, eb = rotations[i], rotations[j], halves[i], halves[j]
    for a in range(3):
        for b in range(3):
            R[a, b] = Ra[0, a] * Rb[0, b] + Ra[1, a] * Rb[1, b] + Ra[2, a] * Rb[2, b]
    dx, dy, dz = centers[j, 0] - centers[i, 0], centers[j, 1] - centers[i, 1], centers[j, 2] - centers[i, 2]
    for a in range(3):
        t[a] = dx * Ra[0, a] + dy * Ra[1, a] + dz * Ra[2, a]
    tie = TIE * (ea[0] + ea[1] + ea[2] + eb[0] + eb[1] + eb[2])
    # the round-off of an overlap: ROUND_OFF × the magnitude of its terms (/ |A_a × B_b| for an edge axis)
    round_off = ROUND_OFF * (ea[0] + ea[1] + ea[2] + eb[0] + eb[1] + eb[2] + abs(t[0]) + abs(t[1]) + abs(t[2]))
    least_round = round_off
    least = face = edge = np.inf  # the least overlap; the face and the edge axes kept (ties: the first)
    face_axis = edge_axis = -1
    edge_tie = 0.0
    ux = uy = uz = fx = fy = fz = lx = ly = lz = 0.0  # their unit axes in i's frame, from i to j
    for m in range(6):  # faces of A (m = a), then of B (m = 3 + b)
        b = m - 3
        if m < 3:
            tl = t[m]
            overlap = ea[m] + eb[0] * abs(R[m, 0]) + eb[1] * abs(R[m, 1]) + eb[2] * abs(R[m, 2]) - abs(tl)
        else:
            tl = t[0] * R[0, b] + t[1] * R[1, b] + t[2] * R[2, b]
            overlap = ea[0] * abs(R[0, b]) + ea[1] * abs(R[1, b]) + ea[2] * abs(R[2, b]) + eb[b] - abs(tl)
        s = 1.0 if tl >= 0.0 else -1.0
        vx, vy, vz = (s * (m == 0), s * (m == 1), s * (m == 2)) if m < 3 else (s * R[0, b], s * R[1, b], s * R[2, b])
        if overlap < 0.0:
            wx, wy, wz = _world(Ra, vx, vy, vz)
            return False, m, overlap, wx, wy, wz, wx, wy, wz
        if overlap < least:
            least, least_round, ux, uy, uz = overlap, round_off, vx, vy, vz
        if overlap < face - tie:
            face, face_axis, fx, fy, fz = overlap, m, vx, vy, vz
    for a in range(3):  # edges: L = A_a × B_b (``_edge_axis``)
        a1, a2 = (a + 1) % 3, (a + 2) % 3
        for b in range(3):
            b1, b2 = (b + 1) % 3, (b + 2) % 3
            tl = t[a2] * R[a1, b] - t[a1] * R[a2, b]
            reach = (ea[a1] * abs(R[a2, b]) + ea[a2] * abs(R[a1, b]) + eb[b1] * abs(R[a, b2])
                     + eb[b2] * abs(R[a, b1]))
            slack = PARALLEL_EPS * (ea[a1] + ea[a2] + eb[b1] + eb[b2])
            length = math.sqrt(R[a1, b] * R[a1, b] + R[a2, b] * R[a2, b])
            if abs(tl) > reach + slack:  # then length > 0: tl and reach both vanish with it
                vx, vy, vz = _edge_axis(R, a, b, tl, length)
                vx, vy, vz = _world(Ra, vx, vy, vz)
                return False, 6 + 3 * a + b, (reach - abs(tl)) / length, vx, vy, vz, vx, vy, vz
            if length > EDGE_AXIS_MIN:
                overlap = max(reach - abs(tl), 0.0) / length
                vx, vy, vz = _edge_axis(R, a, b, tl, length)
                if overlap < least:
                    least, least_round, ux, uy, uz = overlap, round_off / length, vx, vy, vz
                # reach − |tl| carries the round-off of the face tests (a few u × the sizes); the division by
                # |A_a × B_b| magnifies it by 1 / length, and so is the margin an edge must win by
                if overlap < edge - edge_tie:
                    edge, edge_axis, edge_tie, lx, ly, lz = overlap, 6 + 3 * a + b, tie / length, vx, vy, vz
    if face <= least + least_round + round_off:  # the face ties the least overlap: its normal, exact
        ux, uy, uz = fx, fy, fz
    if not prefer_face(face, edge, fx * lx + fy * ly + fz * lz, edge_tie):
        face_axis, fx, fy, fz = edge_axis, lx, ly, lz
    nx, ny, nz = _world(Ra, ux, uy, uz)
    fx, fy, fz = _world(Ra, fx, fy, fz)
    return True, face_axis, least, nx, ny, nz, fx, fy, fz


@njit(inline="always")
def _world(Ra, lx, ly, lz):
    """The vector of components (lx, ly, lz) in the frame of the columns of Ra, in world coordinates."""
    return (lx * Ra[0, 0] + ly * Ra[0, 1] + lz * Ra[0, 2], lx * Ra[1, 0] + ly * Ra[1, 1] + lz * Ra[1, 2],
            lx * Ra[2, 0] + ly * Ra[2, 1] + lz * Ra[2, 2])


@njit
def overlap_box_box(centers, rotations, halves, i, j, scratch):
    """True when boxes i and j overlap (touching counts): the SAT of ``sat_box_box``."""
    return sat_box_box(centers, rotations, halves, i, j, scratch.mat, scratch.vec)[0]


@njit(inline="always")
def _signs_key(region, s0, s1, s2):
    return box_feature_key(region, s0, s1, s2)


@njit(inline="always")
def _with(a, value, s0, s1, s2):
    """(s0, s1, s2) with component a set to value."""
    return (value if a == 0 else s0), (value if a == 1 else s1), (value if a == 2 else s2)


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
    b1, b2 = min((a + 1) % 3, (a + 2) % 3), max((a + 1) % 3, (a + 2) % 3)
    j, k = min((i + 1) % 3, (i + 2) % 3), max((i + 1) % 3, (i + 2) % 3)
    ref_face = _ref_face_key(Rr, i, nrx, nry, nrz)
    for m in range(4):
        s1 = -1 if m == 0 or m == 3 else 1
        s2 = -1 if m <= 1 else 1
        g0, g1, g2 = _with(b2, s2, 0, 0, 0)
        g0, g1, g2 = _with(b1, s1, g0, g1, g2)
        g0, g1, g2 = _with(a, tau, g0, g1, g2)
        wx = ci[0] + tau * ei[a] * Ri[0, a] + s1 * ei[b1] * Ri[0, b1] + s2 * ei[b2] * Ri[0, b2]
        wy = ci[1] + tau * ei[a] * Ri[1, a] + s1 * ei[b1] * Ri[1, b1] + s2 * ei[b2] * Ri[1, b2]
        wz = ci[2] + tau * ei[a] * Ri[2, a] + s1 * ei[b1] * Ri[2, b1] + s2 * ei[b2] * Ri[2, b2]
        rx, ry, rz = wx - cr[0], wy - cr[1], wz - cr[2]
        poly[m, 0] = rx * Rr[0, j] + ry * Rr[1, j] + rz * Rr[2, j]
        poly[m, 1] = rx * Rr[0, k] + ry * Rr[1, k] + rz * Rr[2, k]
        poly[m, 2], poly[m, 3], poly[m, 4] = wx, wy, wz
        poly[m, 5] = er[i] - (rx * nrx + ry * nry + rz * nrz)
        tags[m, 0] = ref_face
        tags[m, 1] = _signs_key(3, g0, g1, g2)
        # the edge to the next corner runs along b1 (m = 0, 2) or b2 (m = 1, 3): that sign is free
        tags[m, 2] = 0
        e0, e1, e2 = _with(b1 if m % 2 == 0 else b2, 0, g0, g1, g2)
        tags[m, 3] = _signs_key(2, e0, e1, e2)
    f0, f1, f2 = _with(a, tau, 0, 0, 0)
    return _signs_key(1, f0, f1, f2)


@njit(inline="always")
def _ref_face_key(Rr, i, nrx, nry, nrz):
    side = 1 if Rr[0, i] * nrx + Rr[1, i] * nry + Rr[2, i] * nrz > 0.0 else 0
    return feature_key(FACE, 2 * i + side)


@njit
def _clip_side(poly, tags, n, side, bound, j, k, face_axis, face_sign, inc_face, out, out_tags):
    """Sutherland–Hodgman step: the part of the polygon poly[:n] with sign·coordinate <= bound (side 0: x <=
    e_j, 1: x >= −e_j, 2: y <= e_k, 3: y >= −e_k; j, k the reference box's axes along x and y, its face on axis
    ``face_axis`` at side ``face_sign``), into out[:m]; returns m. A new point gets its id: an incident edge
    crossing the side is (the reference edge on that side, incident edge); a reference side crossing it is a
    corner of the reference face (reference vertex, incident face)."""
    c = side // 2
    sign = 1 if side % 2 == 0 else -1
    m = 0
    for v in range(n):
        w = (v + 1) % n
        pin = sign * poly[v, c] <= bound
        qin = sign * poly[w, c] <= bound
        if pin:
            for col in range(6):
                out[m, col] = poly[v, col]
            for col in range(4):
                out_tags[m, col] = tags[v, col]
            m += 1
        if pin != qin:
            u = (bound - sign * poly[v, c]) / (sign * poly[w, c] - sign * poly[v, c])
            for col in range(6):
                out[m, col] = poly[v, col] + u * (poly[w, col] - poly[v, col])
            out[m, c] = sign * bound
            s0, s1, s2 = _with(face_axis, face_sign, 0, 0, 0)
            s0, s1, s2 = _with(j if c == 0 else k, sign, s0, s1, s2)
            if tags[v, 2] == 0:  # an incident edge crosses this side
                out_tags[m, 0] = _signs_key(2, s0, s1, s2)
                out_tags[m, 1] = tags[v, 3]
            elif tags[v, 3] // 2 != c:  # an earlier side crosses this one: a corner of the reference face
                other = 1 if tags[v, 3] % 2 == 0 else -1
                v0, v1, v2 = _with(j if c == 1 else k, other, s0, s1, s2)
                out_tags[m, 0] = _signs_key(3, v0, v1, v2)
                out_tags[m, 1] = inc_face
            else:  # (round-off) a side parallel to this one
                out_tags[m, 0] = _signs_key(2, s0, s1, s2)
                out_tags[m, 1] = inc_face
            # from here the polygon runs along this side (leaving) or on along the crossed edge (entering)
            out_tags[m, 2] = 1 if pin else tags[v, 2]
            out_tags[m, 3] = side if pin else tags[v, 3]
            m += 1
    return m


@njit(inline="always")
def _within(pts, k, x, y, z, tol):
    """Whether (x, y, z) is within tol of pts[k] in every coordinate. A vertex of the incident face lying on a
    side of the reference face comes out of Sutherland–Hodgman twice (kept, then as the crossing at u ≈ 0): one
    contact point, not two."""
    return abs(pts[k, 0] - x) <= tol and abs(pts[k, 1] - y) <= tol and abs(pts[k, 2] - z) <= tol


@njit(inline="always")
def _outside(px, py, pz, c, R, e):
    """How far (px, py, pz) lies outside box (c, R, e), in its largest axis (<= 0 inside)."""
    rx, ry, rz = px - c[0], py - c[1], pz - c[2]
    out = -np.inf
    for m in range(3):
        out = max(out, abs(rx * R[0, m] + ry * R[1, m] + rz * R[2, m]) - e[m])
    return out


@njit
def _touching_point(cr, Rr, er, i, nrx, nry, nrz, face_sign, ci, Ri, ei, poly, tags, pts):
    """The point of boxes touching to round-off, when clipping left nothing: of the incident face's 4 corners and
    the reference face's 4 corners, the one lying deepest in both boxes (least max of its distances outside
    each), into pts[0]. The boxes touch at a corner of one of those faces (a corner on a face, an edge or a
    corner of the other box), and a clamp of the incident corner onto the reference face would leave it on the
    reference box only."""
    _incident_quad(cr, Rr, er, i, nrx, nry, nrz, ci, Ri, ei, poly, tags)
    j, k = min((i + 1) % 3, (i + 2) % 3), max((i + 1) % 3, (i + 2) % 3)
    best = np.inf
    for m in range(8):
        if m < 4:
            px, py, pz = poly[m, 2], poly[m, 3], poly[m, 4]
        else:
            s1 = -1.0 if m == 4 or m == 7 else 1.0
            s2 = -1.0 if m <= 5 else 1.0
            px = cr[0] + er[i] * face_sign * Rr[0, i] + s1 * er[j] * Rr[0, j] + s2 * er[k] * Rr[0, k]
            py = cr[1] + er[i] * face_sign * Rr[1, i] + s1 * er[j] * Rr[1, j] + s2 * er[k] * Rr[1, k]
            pz = cr[2] + er[i] * face_sign * Rr[2, i] + s1 * er[j] * Rr[2, j] + s2 * er[k] * Rr[2, k]
        miss = max(_outside(px, py, pz, cr, Rr, er), _outside(px, py, pz, ci, Ri, ei))
        if miss < best:
            best = miss
            pts[0, 0], pts[0, 1], pts[0, 2] = px, py, pz


@njit
def _face_contact(cr, Rr, er, i, nrx, nry, nrz, ci, Ri, ei, ref_is_a, rows, p, flip, depth, normal, scratch):
    """The manifold of a face axis: reference face i of box r (outward normal nr, towards box i), incident face
    of box i clipped by its side planes. Writes row p (``ref_is_a``: the reference box is the kernel's A) with
    the pair's ``depth`` and ``normal`` (3-tuple, from the kernel's A to B: the least-overlap axis)."""
    poly, work, tags, work_tags = scratch.poly, scratch.work, scratch.tags, scratch.work_tags
    inc_face = _incident_quad(cr, Rr, er, i, nrx, nry, nrz, ci, Ri, ei, poly, tags)
    j, k = min((i + 1) % 3, (i + 2) % 3), max((i + 1) % 3, (i + 2) % 3)
    face_sign = 1 if Rr[0, i] * nrx + Rr[1, i] * nry + Rr[2, i] * nrz > 0.0 else -1
    n = np.int64(4)  # the incident quad's corners, an int64 from the start: _clip_side is compiled once
    for side in range(4):
        bound = er[j] if side < 2 else er[k]
        n = _clip_side(poly, tags, n, side, bound, j, k, i, face_sign, inc_face, work, work_tags)
        poly, work = work, poly
        tags, work_tags = work_tags, tags
        if n == 0:
            break
    pts, deep, ids = scratch.pts, scratch.deep, scratch.ids
    # below the reference face up to the round-off of the points' depths, relative to the coordinates' magnitude
    slop = FACE_SLOP * (max(abs(cr[0]), abs(cr[1]), abs(cr[2])) + max(abs(ci[0]), abs(ci[1]), abs(ci[2]))
                        + er[0] + er[1] + er[2] + ei[0] + ei[1] + ei[2])
    count = np.int64(0)  # typed int64 from the start: reduce_manifold is compiled for one count type
    for v in range(n):  # the points below the reference face, each once
        if poly[v, 5] >= -slop and not (count > 0 and _within(pts, count - 1, poly[v, 2], poly[v, 3], poly[v, 4],
                                                              slop)):
            pts[count, 0], pts[count, 1], pts[count, 2] = poly[v, 2], poly[v, 3], poly[v, 4]
            deep[count] = poly[v, 5]
            ids[count] = point_id(tags[v, 0], tags[v, 1]) if ref_is_a else point_id(tags[v, 1], tags[v, 0])
            count += 1
    if count > 1 and _within(pts, 0, pts[count - 1, 0], pts[count - 1, 1], pts[count - 1, 2], slop):
        count -= 1  # the polygon closes on its first point
    if count == 0:  # round-off clipped everything (e.g. corners touching): one point, on both boxes
        count = 1
        ref_face = _ref_face_key(Rr, i, nrx, nry, nrz)
        _touching_point(cr, Rr, er, i, nrx, nry, nrz, face_sign, ci, Ri, ei, scratch.poly, scratch.tags, pts)
        pts[0, 0] -= 0.5 * depth * nrx  # the row adds half the depth back: the point is the candidate itself
        pts[0, 1] -= 0.5 * depth * nry
        pts[0, 2] -= 0.5 * depth * nrz
        deep[0] = depth
        ids[0] = point_id(ref_face, inc_face) if ref_is_a else point_id(inc_face, ref_face)
    count = reduce_manifold(pts, deep, ids, count, nrx, nry, nrz, scratch)
    for v in range(count):
        h = 0.5 * deep[v]
        rows.points[p, v, 0] = pts[v, 0] + h * nrx
        rows.points[p, v, 1] = pts[v, 1] + h * nry
        rows.points[p, v, 2] = pts[v, 2] + h * nrz
        rows.ids[p, v] = swap_point_id(ids[v]) if flip else ids[v]
    inc_kind = VERTEX if count == 1 else (EDGE if count == 2 else FACE)
    write_pair(rows, p, -depth, normal[0], normal[1], normal[2], FACE if ref_is_a else inc_kind,
               inc_kind if ref_is_a else FACE, count, flip)


@njit
def _edge_point(c, R, e, axis, nx, ny, nz, sign, end):
    """An end (end = ±1) of the box's edge along ``axis`` that is farthest along sign·n."""
    px = c[0] + end * e[axis] * R[0, axis]
    py = c[1] + end * e[axis] * R[1, axis]
    pz = c[2] + end * e[axis] * R[2, axis]
    for m in range(3):
        if m != axis:
            s = 1.0 if sign * (R[0, m] * nx + R[1, m] * ny + R[2, m] * nz) >= 0.0 else -1.0
            px += s * e[m] * R[0, m]
            py += s * e[m] * R[1, m]
            pz += s * e[m] * R[2, m]
    return px, py, pz


@njit
def _edge_key(R, axis, nx, ny, nz, sign):
    """The key of the box's edge along ``axis`` farthest along sign·n."""
    s0, s1, s2 = 0, 0, 0
    for m in range(3):
        if m != axis:
            s0, s1, s2 = _with(m, 1 if sign * (R[0, m] * nx + R[1, m] * ny + R[2, m] * nz) >= 0.0 else -1, s0, s1,
                               s2)
    return _signs_key(2, s0, s1, s2)


@njit
def _edge_contact(centers, rotations, halves, i, j, a, b, nx, ny, nz, rows, p, flip, depth, normal):
    """The contact of an edge–edge axis A_a × B_b (unit n, from A to B): the closest points of A's edge along A_a
    that is farthest along n and B's edge along B_b farthest along −n (Ericson 5.1.9); one point halfway between
    them. Writes row p with the pair's ``depth`` and ``normal`` (3-tuple: the least-overlap axis)."""
    ca, Ra, ea, cb, Rb, eb = centers[i], rotations[i], halves[i], centers[j], rotations[j], halves[j]
    a0 = _edge_point(ca, Ra, ea, a, nx, ny, nz, 1.0, -1.0)
    a1 = _edge_point(ca, Ra, ea, a, nx, ny, nz, 1.0, 1.0)
    b0 = _edge_point(cb, Rb, eb, b, nx, ny, nz, -1.0, -1.0)
    b1 = _edge_point(cb, Rb, eb, b, nx, ny, nz, -1.0, 1.0)
    s, t, _ = closest_segment_parameters(a0, a1, b0, b1)
    key_a = _edge_key(Ra, a, nx, ny, nz, 1.0)
    key_b = _edge_key(Rb, b, nx, ny, nz, -1.0)
    mx = 0.5 * (a0[0] + s * (a1[0] - a0[0]) + b0[0] + t * (b1[0] - b0[0]))
    my = 0.5 * (a0[1] + s * (a1[1] - a0[1]) + b0[1] + t * (b1[1] - b0[1]))
    mz = 0.5 * (a0[2] + s * (a1[2] - a0[2]) + b0[2] + t * (b1[2] - b0[2]))
    write_point(rows, p, 0, mx, my, mz, key_a, key_b, flip)
    write_pair(rows, p, -depth, normal[0], normal[1], normal[2], key_kind(key_a), key_kind(key_b), 1, flip)


@njit
def contact_box_box(centers, rotations, halves, i, j, rows, p, flip, scratch):
    """Box i (the kernel's A) against box j (B) of the arrays ``centers`` (n, 3), ``rotations`` (n, 3, 3),
    ``halves`` (n, 3), into row p of ``rows``; ``flip``: the pair's first shape is B; ``scratch`` a
    contacts.Scratch. Returns the separation (apart: minus the SAT overlap on the separating axis found, a
    lower bound of the distance)."""
    overlap, axis, depth, nx, ny, nz, fx, fy, fz = sat_box_box(centers, rotations, halves, i, j, scratch.mat,
                                                               scratch.vec)
    if not overlap:
        write_pair(rows, p, -depth, nx, ny, nz, 0, 0, 0, flip)
        return -depth
    if axis < 6:
        # one call for both reference boxes, with a run-time ``ref_is_a`` (a literal True / False would compile
        # the clipping kernel twice)
        ref_is_a = axis < 3
        r, o, s = (i, j, 1.0) if ref_is_a else (j, i, -1.0)
        _face_contact(centers[r], rotations[r], halves[r], axis % 3, s * fx, s * fy, s * fz, centers[o],
                      rotations[o], halves[o], ref_is_a, rows, p, flip, depth, (nx, ny, nz), scratch)
    else:
        _edge_contact(centers, rotations, halves, i, j, (axis - 6) // 3, (axis - 6) % 3, fx, fy, fz, rows, p,
                      flip, depth, (nx, ny, nz))
    return -depth


def contact_box_box_pair(center_a, rotation_a, half_extents_a, center_b, rotation_b, half_extents_b):
    """The contact of two boxes (centre (3,), rotation (3, 3) whose columns are the axes or a unit quaternion
    (w, x, y, z), half extents (3,) > 0): a ContactSet of one pair (separation > 0 when apart: a lower bound of
    the distance, the gap along a separating axis)."""
    centers, rotations, halves = np.empty((2, 3)), np.empty((2, 3, 3)), np.empty((2, 3))
    for row, (tag, c, r, e) in enumerate((("a", center_a, rotation_a, half_extents_a),
                                          ("b", center_b, rotation_b, half_extents_b))):
        centers[row] = as_float_array(c, f"center_{tag}", shape=(3,))
        rotations[row] = as_rotation_matrix(r, f"rotation_{tag}")
        halves[row] = as_half_extents(e, f"half_extents_{tag}")
    return contact_of_one_pair(contact_box_box, (centers, rotations, halves, 0, 1))
