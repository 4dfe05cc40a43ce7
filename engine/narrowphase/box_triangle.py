"""A box against one triangle of a static surface: the separating axis test with the exact penetration depth, then
the contact manifold by clipping (Ericson 5.2.9 ``TestTriangleAABB``, with depths; the manifold as
engine.narrowphase.box_box builds it, after ODE's ``dBoxBox`` and Box2D's ``b2CollidePolygons``).

Everything is computed in the box's frame (the triangle's corners V_i = Rᵀ (p_i − c)), where the box is
[−h, h]. The 13 axes, in this order: 0 the triangle's normal (the cross product of two edges, computed as the
edge axes are, not the rounded unit normal given), 1–3 the box's faces e_k, 4 + 3a + j the cross
products e_a × f_j of a box axis and the triangle's edge f_j = V_{j+1} − V_j (edge j joins corners j and j + 1).
On an axis L the box projects on [−r, r], r = Σ h_m |L_m|, the triangle on [p_min, p_max]; their overlap is
min(r − p_min, p_max + r) (translating the triangle by that much along +L, resp. −L, separates them), divided by
|L|. A negative overlap separates (touching counts as overlap); the edge axes add ``PARALLEL_EPS`` × |f_j| × the
pair's size to that test, as box_box does, since for (nearly) parallel edges L is (nearly) zero and every term
is round-off. Overlapping: the smallest overlap is the exact penetration depth (the faces of the Minkowski
difference of two polyhedra have these normals; a triangle is a flat polyhedron with faces ±n); a cross product
with sin(e_a, f_j) <= ``EDGE_AXIS_MIN`` is no candidate normal; a later axis wins only when smaller by more than
``TIE`` × the size (an edge axis: divided by its sine), so faces — the triangle's normal first — win ties. Apart:
the largest gap over the separating axes (a lower bound of the distance). The normal runs from the box towards
the triangle.

The manifold (at most ``MAX_TRIANGLE_POINTS`` points, each with its depth along the normal, in [0, depth]):

- the triangle's normal: the box's face most aligned with the normal (the incident face) is clipped by the
  triangle's three side planes (Sutherland–Hodgman, Ericson 8.3.4); its points past the triangle's plane are
  kept, each moved halfway back towards that plane;
- a box face: the triangle is clipped by that face's four side planes; its points below the face are kept, each
  moved halfway out towards the face;
- an edge axis: the closest points of the box's edge farthest along the normal and the triangle's edge j
  (Ericson 5.1.9), one point halfway between them.

If clipping keeps nothing (the incident face misses the triangle's prism, or round-off), the points are the
vertices of the triangle clipped by the box's six planes (they lie in both shapes), and failing that (shapes
touching to round-off) the box or triangle corner lying deepest in both.

Feature keys (engine.narrowphase.contacts): box keys in the box's numbering (``sphere_box.box_feature_key``);
triangle keys local: corner v, edge e, face 0. A point inside the reference face is (that face, the incident
vertex); an incident edge crossing a side is (the side's edge, the incident edge); two sides crossing inside the
incident face is (their corner, the incident face) — the same ids whichever shape is the reference, as in
box_box. ``tri_feature`` / ``body_feature``: the triangle's face and the box's feature reaching deepest along the
normal (its support vertices: 1 a vertex, 2 an edge, 4 a face) for the triangle's normal; the box's face and the
triangle's deepest feature (1 corner, 2 an edge, 3 the face) for a box face; the two edges for an edge axis.
"""
from __future__ import annotations

import math

import numpy as np

from .._config import njit
from .box_box import EDGE_AXIS_MIN, FACE_SLOP, TIE
from .contact_manifold import FEATURE_TOL
from .contacts import EDGE, FACE, VERTEX, feature_key
from .sat import PARALLEL_EPS
from .segment_segment import closest_segment_parameters
from .sphere_box import box_feature_key
from .triangle_contact import MAX_TRIANGLE_POINTS

__all__ = ["box_triangle", "sat_box_triangle", "TRIANGLE_NORMAL_AXIS", "FIRST_EDGE_AXIS"]

#: axis numbers of ``sat_box_triangle``: 0 the triangle's normal, 1 + k box face k, FIRST_EDGE_AXIS + 3 a + j
#: the cross product of box axis a and triangle edge j
TRIANGLE_NORMAL_AXIS = 0
FIRST_EDGE_AXIS = 4

# reference tags of a clipped point (column 0 of the tags): inside the reference face, on a side s (SIDE + s),
# at the corner of sides s and t (CORNER + 10 s + t)
_INSIDE, _SIDE, _CORNER = -1, 100, 200


@njit(inline="always")
def _overlap_on(h, V, lx, ly, lz):
    """(overlap, sign) of the box [−h, h] and the triangle V (3, 3) on the axis L (not unit): min(r − p_min,
    p_max + r) with sign +1 when the first (the triangle is on L's side) is the smaller."""
    r = h[0] * abs(lx) + h[1] * abs(ly) + h[2] * abs(lz)
    p0 = V[0, 0] * lx + V[0, 1] * ly + V[0, 2] * lz
    p1 = V[1, 0] * lx + V[1, 1] * ly + V[1, 2] * lz
    p2 = V[2, 0] * lx + V[2, 1] * ly + V[2, 2] * lz
    up, down = r - min(p0, p1, p2), max(p0, p1, p2) + r
    return (up, 1.0) if up <= down else (down, -1.0)


@njit(inline="always")
def _pair_size(h, V):
    """The pair's size in the box's frame: the half extents plus the largest corner coordinate."""
    big = 0.0
    for i in range(3):
        for c in range(3):
            big = max(big, abs(V[i, c]))
    return h[0] + h[1] + h[2] + big


@njit(inline="always")
def _edge_axis(V, a, j):
    """e_a × f_j (not unit) and |f_j|: the axis of box axis a and triangle edge j."""
    fx, fy, fz = V[(j + 1) % 3, 0] - V[j, 0], V[(j + 1) % 3, 1] - V[j, 1], V[(j + 1) % 3, 2] - V[j, 2]
    # e_a × f: (0, −f_z, f_y), (f_z, 0, −f_x), (−f_y, f_x, 0)
    lx = 0.0 if a == 0 else (fz if a == 1 else -fy)
    ly = -fz if a == 0 else (0.0 if a == 1 else fx)
    lz = fy if a == 0 else (-fx if a == 1 else 0.0)
    return lx, ly, lz, math.sqrt(fx * fx + fy * fy + fz * fz)


@njit
def sat_box_triangle(h, V):
    """The 13-axis SAT of the box [−h, h] (h (3,)) and the triangle V (3, 3), in the box's frame. The triangle's
    normal is the cross product of its edges (as exact as the edge axes, not a rounded unit normal). Returns
    (overlapping, axis, depth, lx, ly, lz): l the unit axis from the box towards the triangle; depth >= 0 the
    penetration when overlapping, else minus the largest gap (a lower bound of the distance)."""
    size = _pair_size(h, V)
    tie = TIE * size
    best, axis, bx, by, bz = np.inf, -1, 0.0, 0.0, 0.0
    gap, gap_axis, gx, gy, gz = -np.inf, -1, 0.0, 0.0, 0.0
    ux, uy, uz = V[1, 0] - V[0, 0], V[1, 1] - V[0, 1], V[1, 2] - V[0, 2]
    wx, wy, wz = V[2, 0] - V[0, 0], V[2, 1] - V[0, 1], V[2, 2] - V[0, 2]
    for k in range(4):  # the triangle's normal, then the box's faces
        if k == 0:
            lx, ly, lz = uy * wz - uz * wy, uz * wx - ux * wz, ux * wy - uy * wx
        else:
            lx, ly, lz = 1.0 * (k == 1), 1.0 * (k == 2), 1.0 * (k == 3)
        length = math.sqrt(lx * lx + ly * ly + lz * lz)
        over, s = _overlap_on(h, V, lx, ly, lz)
        if over < 0.0:
            if -over / length > gap:
                gap, gap_axis, gx, gy, gz = -over / length, k, s * lx / length, s * ly / length, s * lz / length
        elif over / length < best - tie:
            best, axis, bx, by, bz = over / length, k, s * lx / length, s * ly / length, s * lz / length
    for a in range(3):
        for j in range(3):
            lx, ly, lz, f_len = _edge_axis(V, a, j)
            length = math.sqrt(lx * lx + ly * ly + lz * lz)
            over, s = _overlap_on(h, V, lx, ly, lz)
            if over < -PARALLEL_EPS * f_len * size:  # then length > 0: over and the bound vanish with it
                if -over / length > gap:
                    gap, gap_axis = -over / length, FIRST_EDGE_AXIS + 3 * a + j
                    gx, gy, gz = s * lx / length, s * ly / length, s * lz / length
            elif length > EDGE_AXIS_MIN * f_len:
                sine = length / f_len
                if max(over, 0.0) / length < best - tie / sine:
                    best, axis = max(over, 0.0) / length, FIRST_EDGE_AXIS + 3 * a + j
                    bx, by, bz = s * lx / length, s * ly / length, s * lz / length
    if gap_axis >= 0:
        return False, gap_axis, -gap, gx, gy, gz
    return True, axis, best, bx, by, bz


@njit(inline="always")
def _with_axis(m, value, s0, s1, s2):
    """(s0, s1, s2) with component m set to value."""
    return (value if m == 0 else s0), (value if m == 1 else s1), (value if m == 2 else s2)


@njit(inline="always")
def _with_face(face, s0, s1, s2):
    """(s0, s1, s2) with the sign of box face ``face`` (axis face // 2, side + when face is odd) set."""
    return _with_axis(face // 2, 1 if face % 2 == 1 else -1, s0, s1, s2)


@njit
def _box_key(tag, ref_face, inside_key):
    """The box's key of a clipped point: the signs of the reference face (``ref_face`` >= 0) and of the box
    faces whose side planes the point lies on (the tag); ``inside_key`` when none."""
    s0, s1, s2 = 0, 0, 0
    if ref_face >= 0:
        s0, s1, s2 = _with_face(ref_face, s0, s1, s2)
    if tag >= _CORNER:
        s0, s1, s2 = _with_face((tag - _CORNER) // 10, s0, s1, s2)
        s0, s1, s2 = _with_face((tag - _CORNER) % 10, s0, s1, s2)
    elif tag >= _SIDE:
        s0, s1, s2 = _with_face(tag - _SIDE, s0, s1, s2)
    region = (s0 != 0) + (s1 != 0) + (s2 != 0)
    return inside_key if region == 0 else box_feature_key(region, s0, s1, s2)


@njit
def _tri_key(tag):
    """The triangle's key of a clipped point: its face, the edge of a side, or the corner two sides share."""
    if tag >= _CORNER:
        s, t = (tag - _CORNER) // 10, (tag - _CORNER) % 10
        if (s + 1) % 3 == t:
            return feature_key(VERTEX, t)
        if (t + 1) % 3 == s:
            return feature_key(VERTEX, s)
        return feature_key(EDGE, t)
    if tag >= _SIDE:
        return feature_key(EDGE, tag - _SIDE)
    return feature_key(FACE, 0)


@njit
def _clip(poly, tags, n, ox, oy, oz, bound, side, inc_face, out, out_tags):
    """Sutherland–Hodgman step (Ericson 8.3.4): the part of the polygon poly[:n] (rows x, y, z) with
    o·p <= bound into out; returns its count. ``tags`` rows: (reference tag, incident key, kind of the edge to
    the next vertex: 0 an incident edge, 1 a side, its key or side). A crossing of an incident edge is (side,
    that edge), of an earlier side (their corner, the incident face ``inc_face``)."""
    m = 0
    for v in range(n):
        w = (v + 1) % n
        dv = ox * poly[v, 0] + oy * poly[v, 1] + oz * poly[v, 2] - bound
        dw = ox * poly[w, 0] + oy * poly[w, 1] + oz * poly[w, 2] - bound
        if dv <= 0.0:
            for col in range(3):
                out[m, col] = poly[v, col]
            for col in range(4):
                out_tags[m, col] = tags[v, col]
            m += 1
        if (dv <= 0.0) != (dw <= 0.0):
            u = dv / (dv - dw)
            for col in range(3):
                out[m, col] = poly[v, col] + u * (poly[w, col] - poly[v, col])
            if tags[v, 2] == 0:
                out_tags[m, 0], out_tags[m, 1] = _SIDE + side, tags[v, 3]
            elif tags[v, 3] != side:
                out_tags[m, 0], out_tags[m, 1] = _CORNER + 10 * tags[v, 3] + side, inc_face
            else:  # (round-off) the side itself
                out_tags[m, 0], out_tags[m, 1] = _SIDE + side, inc_face
            # leaving: the polygon runs on along this side; entering: along the crossed edge
            out_tags[m, 2] = 1 if dv <= 0.0 else tags[v, 2]
            out_tags[m, 3] = side if dv <= 0.0 else tags[v, 3]
            m += 1
    return m


@njit
def _box_face_polygon(h, face, poly, tags):
    """The 4 corners of box face ``face`` in cyclic order into poly (rows x, y, z) and tags (inside, corner key,
    incident edge to the next corner); returns the face's key."""
    k, sigma = face // 2, (1 if face % 2 == 1 else -1)
    b1, b2 = min((k + 1) % 3, (k + 2) % 3), max((k + 1) % 3, (k + 2) % 3)
    for m in range(4):
        g0, g1, g2 = _with_axis(k, sigma, 0, 0, 0)
        g0, g1, g2 = _with_axis(b1, -1 if m == 0 or m == 3 else 1, g0, g1, g2)
        g0, g1, g2 = _with_axis(b2, -1 if m <= 1 else 1, g0, g1, g2)
        poly[m, 0], poly[m, 1], poly[m, 2] = g0 * h[0], g1 * h[1], g2 * h[2]
        tags[m, 0], tags[m, 1], tags[m, 2] = _INSIDE, box_feature_key(3, g0, g1, g2), 0
        # the edge to the next corner runs along b1 (m = 0, 2) or b2 (m = 1, 3)
        e0, e1, e2 = _with_axis(b1 if m % 2 == 0 else b2, 0, g0, g1, g2)
        tags[m, 3] = box_feature_key(2, e0, e1, e2)
    return feature_key(FACE, face)


@njit
def _triangle_polygon(V, poly, tags):
    """The triangle's corners into poly and tags (inside, corner v, edge v to the next corner); returns its
    face's key."""
    for v in range(3):
        for c in range(3):
            poly[v, c] = V[v, c]
        tags[v, 0], tags[v, 1], tags[v, 2], tags[v, 3] = _INSIDE, feature_key(VERTEX, v), 0, feature_key(EDGE, v)
    return feature_key(FACE, 0)


@njit(inline="always")
def _side_plane(V, e, nx, ny, nz):
    """The side plane of triangle edge e (through the edge, along the normal n): (o, bound) with o·p <= bound
    on the triangle's side (o not unit)."""
    i, j, k = e, (e + 1) % 3, (e + 2) % 3
    fx, fy, fz = V[j, 0] - V[i, 0], V[j, 1] - V[i, 1], V[j, 2] - V[i, 2]
    ox, oy, oz = fy * nz - fz * ny, fz * nx - fx * nz, fx * ny - fy * nx
    if ox * (V[k, 0] - V[i, 0]) + oy * (V[k, 1] - V[i, 1]) + oz * (V[k, 2] - V[i, 2]) > 0.0:
        ox, oy, oz = -ox, -oy, -oz
    return ox, oy, oz, ox * V[i, 0] + oy * V[i, 1] + oz * V[i, 2]


@njit(inline="always")
def _emit(out, slot, center, R, x, y, z, depth, body_key, tri_key):
    """Point ``slot`` of ``out``: the box-frame point (x, y, z) in world coordinates, its depth and keys."""
    for c in range(3):
        out.points[slot, c] = center[c] + R[c, 0] * x + R[c, 1] * y + R[c, 2] * z
    out.depths[slot] = depth
    out.body_keys[slot] = body_key
    out.tri_keys[slot] = tri_key


@njit(inline="always")
def _near(x, y, z, px, py, pz, tol):
    """Whether two points agree within tol in every coordinate (a vertex on a side comes out of
    Sutherland–Hodgman twice: kept, then as the crossing at u ≈ 0)."""
    return abs(x - px) <= tol and abs(y - py) <= tol and abs(z - pz) <= tol


@njit
def _keep_points(poly, tags, n, lx, ly, lz, level, sign, slop, depth, ref_is_box, ref_face, inside_key, center, R,
                 out):
    """Write the points of poly[:n] on the penetrating side of the reference plane l·p = level — depth
    d = sign (l·p − level) >= −slop, clamped to [0, depth] — each once, moved halfway towards that plane
    (by −sign d / 2 along l), with their keys (the reference's from the tag, the incident's as carried).
    Returns their count."""
    count = np.int64(0)
    fx = fy = fz = qx = qy = qz = 0.0
    for v in range(n):
        x, y, z = poly[v, 0], poly[v, 1], poly[v, 2]
        d = sign * (lx * x + ly * y + lz * z - level)
        if d < -slop or (count > 0 and _near(x, y, z, qx, qy, qz, slop)) or count == MAX_TRIANGLE_POINTS:
            continue
        d = min(max(d, 0.0), depth)
        shift = 0.5 * sign * d
        if ref_is_box:
            keys = (_box_key(tags[v, 0], ref_face, inside_key), tags[v, 1])
        else:
            keys = (tags[v, 1], _tri_key(tags[v, 0]))
        _emit(out, count, center, R, x - shift * lx, y - shift * ly, z - shift * lz, d, keys[0], keys[1])
        if count == 0:
            fx, fy, fz = x, y, z
        qx, qy, qz = x, y, z
        count += 1
    if count > 1 and _near(qx, qy, qz, fx, fy, fz, slop):
        count -= 1  # the polygon closes on its first point
    return count


@njit
def _triangle_face_contact(h, V, lx, ly, lz, depth, slop, center, R, out, scratch):
    """The triangle's normal: the box face most aligned with l (the incident face) clipped by the triangle's
    three side planes, its points past the triangle's plane."""
    k = 0
    for m in range(1, 3):
        if abs((lx, ly, lz)[m]) > abs((lx, ly, lz)[k]):
            k = m
    face = 2 * k + ((lx, ly, lz)[k] > 0.0)
    poly, work, tags, work_tags = scratch.poly, scratch.work, scratch.tags, scratch.work_tags
    inc_face = _box_face_polygon(h, face, poly, tags)
    n = np.int64(4)
    for e in range(3):
        ox, oy, oz, bound = _side_plane(V, e, lx, ly, lz)
        n = _clip(poly, tags, n, ox, oy, oz, bound, e, inc_face, work, work_tags)
        poly, work = work, poly
        tags, work_tags = work_tags, tags
        if n == 0:
            break
    level = min(V[0, 0] * lx + V[0, 1] * ly + V[0, 2] * lz, V[1, 0] * lx + V[1, 1] * ly + V[1, 2] * lz,
                V[2, 0] * lx + V[2, 1] * ly + V[2, 2] * lz)
    return _keep_points(poly, tags, n, lx, ly, lz, level, 1.0, slop, depth, False, -1, 0, center, R, out)


@njit
def _clipped_triangle(h, V, faces, n_faces, inc_face, scratch):
    """The triangle clipped by the side planes t p_m <= h_m of the box faces ``faces[:n_faces]`` (face
    2 m + [t > 0]); returns (polygon, tags, count)."""
    poly, work, tags, work_tags = scratch.poly, scratch.work, scratch.tags, scratch.work_tags
    _triangle_polygon(V, poly, tags)
    n = np.int64(3)
    for i in range(n_faces):
        side = faces[i]
        m, t = side // 2, (1.0 if side % 2 == 1 else -1.0)
        n = _clip(poly, tags, n, t * (m == 0), t * (m == 1), t * (m == 2), h[m], side, inc_face, work, work_tags)
        poly, work = work, poly
        tags, work_tags = work_tags, tags
        if n == 0:
            break
    return poly, tags, n


@njit
def _box_face_contact(h, V, face, depth, slop, center, R, out, scratch):
    """A box face: the triangle clipped by the face's four side planes, its points below the face."""
    k, sigma = face // 2, (1.0 if face % 2 == 1 else -1.0)
    a1, a2 = (k + 1) % 3, (k + 2) % 3
    sides = (2 * a1, 2 * a1 + 1, 2 * a2, 2 * a2 + 1)
    poly, tags, n = _clipped_triangle(h, V, sides, 4, feature_key(FACE, 0), scratch)
    lx, ly, lz = sigma * (k == 0), sigma * (k == 1), sigma * (k == 2)
    return _keep_points(poly, tags, n, lx, ly, lz, h[k], -1.0, slop, depth, True, face, 0, center, R, out)


@njit
def _box_clipped_triangle(h, V, lx, ly, lz, depth, slop, center, R, out, scratch):
    """Clipping kept nothing: the vertices of the triangle clipped by the box's six planes (points of both
    shapes), each with the box's reach past it along l (clamped to [0, depth])."""
    poly, tags, n = _clipped_triangle(h, V, (0, 1, 2, 3, 4, 5), 6, feature_key(FACE, 0), scratch)
    reach = h[0] * abs(lx) + h[1] * abs(ly) + h[2] * abs(lz)
    k = 0
    for m in range(1, 3):
        if abs((lx, ly, lz)[m]) > abs((lx, ly, lz)[k]):
            k = m
    inside_key = feature_key(FACE, 2 * k + ((lx, ly, lz)[k] > 0.0))
    return _keep_points(poly, tags, n, lx, ly, lz, reach, -1.0, slop, depth, True, -1, inside_key, center, R, out)


@njit
def _outside_triangle(V, nx, ny, nz, x, y, z):
    """How far (x, y, z) lies off the triangle: the largest of its distance to the plane and to the side
    planes (<= 0 within the prism)."""
    miss = abs(nx * (x - V[0, 0]) + ny * (y - V[0, 1]) + nz * (z - V[0, 2]))
    for e in range(3):
        ox, oy, oz, bound = _side_plane(V, e, nx, ny, nz)
        miss = max(miss, (ox * x + oy * y + oz * z - bound) / math.sqrt(ox * ox + oy * oy + oz * oz))
    return miss


@njit
def _touching_point(h, V, nx, ny, nz, lx, ly, lz, depth, center, R, out):
    """Shapes touching to round-off, nothing clipped: of the box's 8 corners and the triangle's 3, the one
    lying deepest in both (least largest distance outside either), as the one point."""
    best, pick = np.inf, 0
    for q in range(11):
        if q < 8:
            x, y, z = (h[0] if q & 4 else -h[0]), (h[1] if q & 2 else -h[1]), (h[2] if q & 1 else -h[2])
        else:
            x, y, z = V[q - 8, 0], V[q - 8, 1], V[q - 8, 2]
        box_miss = max(abs(x) - h[0], abs(y) - h[1], abs(z) - h[2])
        miss = max(box_miss, _outside_triangle(V, nx, ny, nz, x, y, z))
        if miss < best:
            best, pick = miss, q
    if pick < 8:
        x, y, z = (h[0] if pick & 4 else -h[0]), (h[1] if pick & 2 else -h[1]), (h[2] if pick & 1 else -h[2])
        keys = (feature_key(VERTEX, pick), feature_key(FACE, 0))
    else:
        x, y, z = V[pick - 8, 0], V[pick - 8, 1], V[pick - 8, 2]
        k = 0
        for m in range(1, 3):
            if abs((lx, ly, lz)[m]) > abs((lx, ly, lz)[k]):
                k = m
        keys = (feature_key(FACE, 2 * k + ((lx, ly, lz)[k] > 0.0)), feature_key(VERTEX, pick - 8))
    _emit(out, 0, center, R, x, y, z, depth, keys[0], keys[1])
    return np.int64(1)


@njit
def _edge_contact(h, V, a, j, lx, ly, lz, depth, center, R, out):
    """An edge axis e_a × f_j: the closest points of the box's edge along a farthest along l and the
    triangle's edge j (Ericson 5.1.9); one point halfway between them."""
    s0, s1, s2 = (1 if lx >= 0.0 else -1), (1 if ly >= 0.0 else -1), (1 if lz >= 0.0 else -1)
    s0, s1, s2 = _with_axis(a, 0, s0, s1, s2)
    p0 = (s0 * h[0] - h[0] * (a == 0), s1 * h[1] - h[1] * (a == 1), s2 * h[2] - h[2] * (a == 2))
    p1 = (s0 * h[0] + h[0] * (a == 0), s1 * h[1] + h[1] * (a == 1), s2 * h[2] + h[2] * (a == 2))
    i, k = j, (j + 1) % 3
    q0 = (V[i, 0], V[i, 1], V[i, 2])
    q1 = (V[k, 0], V[k, 1], V[k, 2])
    s, t, _ = closest_segment_parameters(p0, p1, q0, q1)
    x = 0.5 * (p0[0] + s * (p1[0] - p0[0]) + q0[0] + t * (q1[0] - q0[0]))
    y = 0.5 * (p0[1] + s * (p1[1] - p0[1]) + q0[1] + t * (q1[1] - q0[1]))
    z = 0.5 * (p0[2] + s * (p1[2] - p0[2]) + q0[2] + t * (q1[2] - q0[2]))
    _emit(out, 0, center, R, x, y, z, depth, box_feature_key(2, s0, s1, s2), feature_key(EDGE, j))
    return np.int64(1)


@njit
def _deepest_features(h, V, axis, lx, ly, lz, size, out):
    """``tri_feature`` and ``body_feature``: the features of the SAT axis, and on the reference side the one
    reaching deepest — the box's support feature along l (1, 2 or 4 corners within ``FEATURE_TOL`` × size),
    the triangle's along −l (1, 2 or 3 corners)."""
    tol = FEATURE_TOL * size
    if axis >= FIRST_EDGE_AXIS:
        out.tri_feature[0], out.tri_feature[1] = EDGE, (axis - FIRST_EDGE_AXIS) % 3
        out.body_feature[0] = EDGE
    elif axis == TRIANGLE_NORMAL_AXIS:
        flat = (h[0] * abs(lx) <= tol) + (h[1] * abs(ly) <= tol) + (h[2] * abs(lz) <= tol)
        out.tri_feature[0], out.tri_feature[1] = FACE, 0
        out.body_feature[0] = VERTEX if flat == 0 else (EDGE if flat == 1 else FACE)
    else:
        p0 = V[0, 0] * lx + V[0, 1] * ly + V[0, 2] * lz
        p1 = V[1, 0] * lx + V[1, 1] * ly + V[1, 2] * lz
        p2 = V[2, 0] * lx + V[2, 1] * ly + V[2, 2] * lz
        low = min(p0, p1, p2)
        d0, d1, d2 = p0 <= low + tol, p1 <= low + tol, p2 <= low + tol
        deep = d0 + d1 + d2
        out.body_feature[0] = FACE
        if deep == 3:
            out.tri_feature[0], out.tri_feature[1] = FACE, 0
        elif deep == 2:  # the edge joining the two deepest corners: 0 (corners 0, 1), 1 (1, 2), 2 (2, 0)
            out.tri_feature[0], out.tri_feature[1] = EDGE, (0 if not d2 else (1 if not d0 else 2))
        else:
            out.tri_feature[0], out.tri_feature[1] = VERTEX, (0 if d0 else (1 if d1 else 2))


@njit
def box_triangle(center, rotation, half, a, b, c, n_face, out, scratch):
    """The box (``center`` (3,), ``rotation`` (3, 3) whose columns are its axes, ``half`` (3,) half extents)
    against the triangle of corners a, b, c (3-tuples) and unit face normal ``n_face`` (3-tuple), into ``out``
    (a triangle_contact.TriangleContact); ``scratch`` a contacts.Scratch (kernel_scratch()), or any bundle with
    its fields ``mat``, ``poly``, ``work``, ``tags``, ``work_tags``. Returns the separation (−depth when they
    touch; apart, the largest SAT gap: a lower bound of the distance). See the module's docstring."""
    V, R = scratch.mat, rotation
    for i, p in enumerate((a, b, c)):
        dx, dy, dz = p[0] - center[0], p[1] - center[1], p[2] - center[2]
        for m in range(3):
            V[i, m] = R[0, m] * dx + R[1, m] * dy + R[2, m] * dz
    nx = R[0, 0] * n_face[0] + R[1, 0] * n_face[1] + R[2, 0] * n_face[2]
    ny = R[0, 1] * n_face[0] + R[1, 1] * n_face[1] + R[2, 1] * n_face[2]
    nz = R[0, 2] * n_face[0] + R[1, 2] * n_face[1] + R[2, 2] * n_face[2]
    overlapping, axis, depth, lx, ly, lz = sat_box_triangle(half, V)
    if axis == TRIANGLE_NORMAL_AXIS:  # ± the given normal itself, not its round trip through the box's frame
        s = 1.0 if lx * nx + ly * ny + lz * nz > 0.0 else -1.0
        out.normal[0], out.normal[1], out.normal[2] = s * n_face[0], s * n_face[1], s * n_face[2]
    else:
        for m in range(3):
            out.normal[m] = R[m, 0] * lx + R[m, 1] * ly + R[m, 2] * lz
    out.separation[0] = -depth
    out.count[0] = 0
    out.tri_feature[0], out.tri_feature[1], out.body_feature[0] = 0, 0, 0
    if not overlapping:
        return -depth
    size = _pair_size(half, V)
    slop = FACE_SLOP * (max(abs(center[0]), abs(center[1]), abs(center[2])) + size)
    if axis == TRIANGLE_NORMAL_AXIS:
        count = _triangle_face_contact(half, V, lx, ly, lz, depth, slop, center, R, out, scratch)
    elif axis < FIRST_EDGE_AXIS:
        face = 2 * (axis - 1) + ((lx, ly, lz)[axis - 1] > 0.0)
        count = _box_face_contact(half, V, face, depth, slop, center, R, out, scratch)
    else:
        count = _edge_contact(half, V, (axis - FIRST_EDGE_AXIS) // 3, (axis - FIRST_EDGE_AXIS) % 3, lx, ly, lz,
                              depth, center, R, out)
    if count == 0:
        count = _box_clipped_triangle(half, V, lx, ly, lz, depth, slop, center, R, out, scratch)
    if count == 0:
        count = _touching_point(half, V, nx, ny, nz, lx, ly, lz, depth, center, R, out)
    out.count[0] = count
    _deepest_features(half, V, axis, lx, ly, lz, size, out)
    return -depth
