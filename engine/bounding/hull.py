"""Convex hull and convexity (chapter slides "Enveloppe convexe" — the smallest convex surface/volume holding
the object — and "Objet convexe" — a line meets a convex shape in at most two points).

- 3-D: quickhull (Barber, Dobkin & Huhdanpaa 1996; Ericson, *Real-Time Collision Detection*, 12.4.2): start from
  a tetrahedron of extreme points, give every outside point to one face (its conflict list), then repeatedly
  take the farthest point of a face, find the faces it sees (depth-first over face neighbours), replace them
  by a cone of new faces on the horizon, and hand the visible faces' points to the new faces.
- 2-D: Andrew's monotone chain (Andrew 1979): sort by x then y, build the lower and upper chains, popping
  every point that does not make a strict left turn.

``convex_hull(points)`` never returns a wrong hull and never refuses a full-dimensional one. Every visibility
decision of quickhull is the exact sign of orient3d (engine.bounding.predicates, Shewchuk 1997), so the mesh stays
exactly convex and every horizon is one loop, whatever the round-off. Points within MERGE_TOL s of a face (s = the
largest absolute coordinate) are not outside it (quickhull's thick planes), and faces within MERGE_TOL of each other's
planes are one facet (Qhull's merge of coplanar facets): a vertex on one or two facets (inside a flat region, on
an edge) is not a corner, and the hull is rebuilt from the corners. The result is certified — a closed
triangulated sphere, every input point (past FULL_CERTIFY_WORK point-face pairs: every removed non-corner) at
most CERTIFY_TOL s above every face plane — or else rebuilt with exact tests only (every point exactly inside).
Every input point lies at most HULL_TOL s (2^-46 s, 1.4e-14 s) above the exact plane through each face's
corners, and face normals come from cross products accurate to a few ulps, sliver faces included. Duplicates are
fine; input within MERGE_TOL s of a point, a line or a plane (lower-dimensional to round-off; fewer than d + 1
points) raises ValueError saying which.

``is_convex`` is the slide's criterion in its practical form: every vertex lies on the inner side of every
face (edge) plane.
"""
from __future__ import annotations

import math
from collections import namedtuple

import numpy as np

from .._config import njit
from .._validate import as_nonnegative, unit_scale_exponent
from .aabb import as_points
from .horizon import link_neighbours, stitch_cone, visible_faces_and_horizon_exact
from .predicates import accurate_cross, orient3d

__all__ = ["ConvexHull", "convex_hull", "is_convex", "monotone_chain", "HULL_EPS", "HULL_TOL"]

#: 2-D: an area below HULL_EPS × extent × scale counts as zero (the monotone chain's collinearity test)
HULL_EPS = 1e-12
#: 3-D, relative to s = the largest absolute coordinate: quickhull's thick planes and the merge of coplanar faces (a
#: point within MERGE_TOL s of a face's plane is not outside it; faces whose far vertices are that close to each
#: other's planes are one facet) — 64 ulps of 1, the order of Qhull's own premerge tolerance (a few times its
#: DISTround ~ 10 ε max|x|), so that round-off-flat vertices (lattices after a decimal scaling) are not corners
MERGE_TOL = 2.0 ** -47
#: the certificate: every input point at most CERTIFY_TOL s above every face plane, in floating point (MERGE_TOL
#: plus 32 ulps for the float distance's own error, which is below 26 ε s: see HULL_TOL)
CERTIFY_TOL = MERGE_TOL + 2.0 ** -48
#: the documented bound: every input point lies at most HULL_TOL s above the exact plane through every hull
#: face's three (float) corners — CERTIFY_TOL plus the float distance's error (normal within ~4 ε of the
#: exact one's direction, |p − a| <= 2√3 s; the dot products and the centroid offset: ~12 ε s), rounded up to
#: 128 ulps of 1 (1.4e-14). A hull that fails the certificate is rebuilt exactly: then the bound is 0.
HULL_TOL = 2.0 ** -46
#: incident face normals closer than this (radians) to a common line count as flat (the 2-D chain's turns)
FLAT_ANGLE = 1e-10
#: up to this many point-face pairs, every input point is checked against every hull face
FULL_CERTIFY_WORK = 50_000_000

_DEGENERATE_3D = {
    1: "all points coincide (a 0-dimensional set, to MERGE_TOL)",
    2: "all points are collinear (a 1-dimensional set, to MERGE_TOL)",
    3: "all points are coplanar (a 2-dimensional set, to MERGE_TOL); project them to 2-D and use a 2-D hull",
}


class ConvexHull:
    """The convex hull of a point set in 2-D or 3-D (``convex_hull``'s answer); its arrays are read-only.

    Attributes
    ----------
    points : numpy.ndarray, shape (n, d), float64
        A read-only copy of the input, d = 2 or 3.
    dim : int
        d.
    vertices : numpy.ndarray, shape (v,), int64
        Indices into ``points`` of the hull's vertices, one per distinct position: counter-clockwise in 2-D,
        ascending in 3-D.
    faces : numpy.ndarray, shape (m, d), int64
        Outward-oriented triangles (counter-clockwise seen from outside) in 3-D; the counter-clockwise edges in 2-D.
    normals : numpy.ndarray, shape (m, d), float64
        Unit outward normals of the faces.
    offsets : numpy.ndarray, shape (m,), float64
        A point x is inside iff ``normals @ x <= offsets`` for every face.
    volume : float
        The enclosed volume (the area in 2-D); inf when it exceeds the float range (~1.8e308).
    area : float
        The surface area (the perimeter in 2-D); inf likewise.
    """

    __slots__ = ("points", "dim", "vertices", "faces", "normals", "offsets", "volume", "area")

    def __init__(self, points, vertices, faces, normals, offsets, volume, area):
        self.points = points
        self.dim = points.shape[1]
        self.vertices = vertices
        self.faces = faces
        self.normals = normals
        self.offsets = offsets
        self.volume = float(volume)
        self.area = float(area)
        for arr in (points, vertices, faces, normals, offsets):
            arr.setflags(write=False)

    def __repr__(self) -> str:
        return (f"ConvexHull(dim={self.dim}, vertices={len(self.vertices)}, faces={len(self.faces)}, "
                f"volume={self.volume!r})")


# ---------------------------------------------------------------------------------------------------------
# 2-D: Andrew's monotone chain
# ---------------------------------------------------------------------------------------------------------
@njit
def _not_left_turn(o, a, b):
    """True unless o -> a -> b turns left by more than FLAT_ANGLE (sine of the turn; exact 0 for repeats)."""
    ux = a[0] - o[0]
    uy = a[1] - o[1]
    vx = b[0] - o[0]
    vy = b[1] - o[1]
    cross = ux * vy - uy * vx
    if cross <= 0.0:
        return True
    return cross * cross <= FLAT_ANGLE * FLAT_ANGLE * ((ux * ux + uy * uy) * (vx * vx + vy * vy))


@njit
def monotone_chain(points, order):
    """Indices (int64) of the 2-D hull vertices of ``points`` (n, >= 2) float64, counter-clockwise, from the
    points visited in lexicographic (x, then y) ``order`` (n,) int64.

    Andrew's algorithm: lower chain left to right, upper chain right to left; a point is popped while the last
    two chain points and the new point do not turn strictly left (cross <= 0, or a turn below FLAT_ANGLE), so
    collinear points and duplicates are dropped.
    """
    n = order.shape[0]
    hull = np.empty(2 * n + 1, dtype=np.int64)
    k = 0
    for t in range(n):  # lower chain
        i = order[t]
        while k >= 2 and _not_left_turn(points[hull[k - 2]], points[hull[k - 1]], points[i]):
            k -= 1
        hull[k] = i
        k += 1
    lower = k + 1
    for t in range(n - 2, -1, -1):  # upper chain
        i = order[t]
        while k >= lower and _not_left_turn(points[hull[k - 2]], points[hull[k - 1]], points[i]):
            k -= 1
        hull[k] = i
        k += 1
    return hull[: max(k - 1, 1)]  # the last point repeats the first


def _hull_2d(pts: np.ndarray) -> ConvexHull:
    n = pts.shape[0]
    if n < 3:
        raise ValueError(f"points: a 2-D hull needs at least 3 points, got {n}")
    order = np.argsort(pts[:, 0])  # lexicographic (x, then y) order; ties in x need the second key
    if (np.diff(pts[order, 0]) == 0).any():
        order = np.lexsort((pts[:, 1], pts[:, 0]))
    order = order.astype(np.int64)
    verts = monotone_chain(pts, order)
    if verts.shape[0] < 3:
        what = "coincide" if np.ptp(pts, axis=0).max() == 0 else "are collinear"
        raise ValueError(f"points: all points {what}; a 2-D hull needs 3 non-collinear points")
    v = pts[verts]
    nxt = np.roll(v, -1, axis=0)
    rel, rel_next = v - v[0], nxt - v[0]  # shoelace about a vertex: no cancellation far from the origin
    area2 = float(np.sum(rel[:, 0] * rel_next[:, 1] - rel_next[:, 0] * rel[:, 1]))
    extent = float(np.ptp(pts, axis=0).max())
    scale = float(np.abs(pts).max() + extent)
    if area2 <= HULL_EPS * extent * scale:  # round-off of a cross product: ~ machine epsilon * |x| * extent
        raise ValueError("points: all points are (numerically) collinear; a 2-D hull needs 3 non-collinear points")
    edges = nxt - v
    lengths = np.hypot(edges[:, 0], edges[:, 1])
    normals = np.column_stack([edges[:, 1], -edges[:, 0]]) / lengths[:, None]  # right of a ccw edge = outside
    offsets = np.einsum("ij,ij->i", normals, v)
    faces = np.column_stack([verts, np.roll(verts, -1)]).astype(np.int64)
    return ConvexHull(pts, verts.astype(np.int64), faces, normals, offsets, area2 / 2.0, lengths.sum())


# ---------------------------------------------------------------------------------------------------------
# 3-D: quickhull
# ---------------------------------------------------------------------------------------------------------
@njit
def _plane(points, a, b, c, normal):
    """Unit normal of the triangle (a, b, c) (right-hand rule) written in ``normal``; returns its offset. The
    cross product is accurate to a few ulps per component (predicates.accurate_cross), sliver triangles included:
    the normal is within a few ulps of the exact plane's, whatever the triangle's shape."""
    accurate_cross(points, a, b, c, normal)
    nx, ny, nz = normal[0], normal[1], normal[2]
    length = math.sqrt(nx * nx + ny * ny + nz * nz)
    if length == 0.0:
        length = 1.0
    normal[0] = nx / length
    normal[1] = ny / length
    normal[2] = nz / length
    # offset through the centroid (less round-off than through one vertex)
    offset = 0.0
    for m in range(3):
        offset += normal[m] * (points[a, m] + points[b, m] + points[c, m]) / 3.0
    return offset


@njit
def _distance(points, i, normal, offset):
    return normal[0] * points[i, 0] + normal[1] * points[i, 1] + normal[2] * points[i, 2] - offset


@njit
def _assign_outside_point(points, i, candidates, n_candidates, fv, fn, fd, delta, head, nxt, far, far_d):
    """Quickhull's conflict lists: put point i on the list of the candidate face it lies farthest outside of,
    and keep each face's farthest point; a point outside no candidate is dropped. Outside means exactly above the
    face's plane (orient3d > 0) and more than ``delta`` above it in floating point (``delta`` = -inf: exactly
    above is enough); the float distance only ranks the faces."""
    best = -np.inf
    bf = -1
    for t in range(n_candidates):
        f = candidates[t]
        d = _distance(points, i, fn[f], fd[f])
        if d > best and d > delta and orient3d(points, fv[f, 0], fv[f, 1], fv[f, 2], i) > 0.0:
            best = d
            bf = f
    if bf >= 0:
        if head[bf] == -1 or best > far_d[bf]:
            far_d[bf] = best
            far[bf] = i
        nxt[i] = head[bf]
        head[bf] = i


@njit
def _initial_simplex(points, eps):
    """Four affinely independent extreme points, or a status 1/2/3 when the input is 0/1/2-dimensional."""
    n = points.shape[0]
    simplex = np.zeros(4, dtype=np.int64)
    # farthest pair among the 6 axis extremes
    extremes = np.zeros(6, dtype=np.int64)
    for k in range(3):
        for i in range(n):
            if points[i, k] < points[extremes[2 * k], k]:
                extremes[2 * k] = i
            if points[i, k] > points[extremes[2 * k + 1], k]:
                extremes[2 * k + 1] = i
    best = -1.0
    for s in range(6):
        for t in range(s + 1, 6):
            d2 = 0.0
            for m in range(3):
                d2 += (points[extremes[s], m] - points[extremes[t], m]) ** 2
            if d2 > best:
                best = d2
                simplex[0] = extremes[s]
                simplex[1] = extremes[t]
    if math.sqrt(best) <= eps:
        return simplex, 1
    # farthest from the line (p0, p1)
    a = points[simplex[0]]
    u = points[simplex[1]] - a
    u = u / math.sqrt(u[0] ** 2 + u[1] ** 2 + u[2] ** 2)
    best = -1.0
    for i in range(n):
        w = points[i] - a
        t = w[0] * u[0] + w[1] * u[1] + w[2] * u[2]
        d2 = (w[0] - t * u[0]) ** 2 + (w[1] - t * u[1]) ** 2 + (w[2] - t * u[2]) ** 2
        if d2 > best:
            best = d2
            simplex[2] = i
    if math.sqrt(best) <= eps:
        return simplex, 2
    # farthest from the plane (p0, p1, p2)
    normal = np.empty(3)
    offset = _plane(points, simplex[0], simplex[1], simplex[2], normal)
    best = -1.0
    for i in range(n):
        d = abs(_distance(points, i, normal, offset))
        if d > best:
            best = d
            simplex[3] = i
    if best <= eps:
        return simplex, 3
    return simplex, 0


@njit
def _grown(arr, size, fill):
    """A copy of ``arr`` (1-D or 2-D) with ``size`` rows, the new rows set to ``fill``."""
    shape = (size,) + arr.shape[1:]
    out = np.full(shape, fill, dtype=arr.dtype)
    out[: arr.shape[0]] = arr
    return out


#: quickhull's per-face arrays (one row per face slot; the mesh layout of engine.bounding.horizon) and its search
#: scratch: ``alive``, the conflict lists (``head``: first outside point, ``far`` / ``far_d``: the farthest one and
#: its distance), ``visible``, ``stack``, ``horizon`` (3 × capacity rows), ``new_faces``
QuickhullMesh = namedtuple("QuickhullMesh", ["fv", "fadj", "fn", "fd", "alive", "head", "far", "far_d", "stamp",
                                             "visible", "stack", "horizon", "new_faces"])


@njit
def _new_mesh(capacity):
    return QuickhullMesh(np.zeros((capacity, 3), dtype=np.int64), np.full((capacity, 3), -1, dtype=np.int64),
                         np.zeros((capacity, 3)), np.zeros(capacity), np.zeros(capacity, dtype=np.bool_),
                         np.full(capacity, -1, dtype=np.int64), np.full(capacity, -1, dtype=np.int64),
                         np.zeros(capacity), np.full(capacity, -1, dtype=np.int64), np.empty(capacity, dtype=np.int64),
                         np.empty(capacity, dtype=np.int64), np.empty((3 * capacity, 3), dtype=np.int64),
                         np.empty(capacity, dtype=np.int64))


@njit
def _grown_mesh(m, capacity):
    """Every per-face array of ``m`` with ``capacity`` rows (amortised doubling)."""
    return QuickhullMesh(_grown(m.fv, capacity, 0), _grown(m.fadj, capacity, -1), _grown(m.fn, capacity, 0.0),
                         _grown(m.fd, capacity, 0.0), _grown(m.alive, capacity, False),
                         _grown(m.head, capacity, -1), _grown(m.far, capacity, -1), _grown(m.far_d, capacity, 0.0),
                         _grown(m.stamp, capacity, -1), _grown(m.visible, capacity, 0),
                         _grown(m.stack, capacity, 0), _grown(m.horizon, 3 * capacity, 0),
                         _grown(m.new_faces, capacity, 0))
@njit
def _initial_tetrahedron(points, simplex, m, nxt, delta):
    """Faces 0..3 of the mesh: the tetrahedron ``simplex`` (not coplanar), each face oriented away from the
    opposite vertex (exact orient3d) and linked to its neighbours; every other point goes to the conflict list of
    the face it lies farthest outside of."""
    tri = np.array([[0, 1, 2], [0, 3, 1], [1, 3, 2], [2, 3, 0]], dtype=np.int64)
    opposite = np.array([3, 2, 0, 1], dtype=np.int64)
    for f in range(4):
        a = simplex[tri[f, 0]]
        b = simplex[tri[f, 1]]
        c = simplex[tri[f, 2]]
        if orient3d(points, a, b, c, simplex[opposite[f]]) > 0.0:
            b, c = c, b
        m.fd[f] = _plane(points, a, b, c, m.fn[f])
        m.fv[f, 0] = a
        m.fv[f, 1] = b
        m.fv[f, 2] = c
        m.alive[f] = True
    link_neighbours(m.fv, 4, m.fadj)
    first_faces = np.arange(4)
    fv, fn, fd, head, far, far_d = m.fv, m.fn, m.fd, m.head, m.far, m.far_d  # locals: see above _quickhull_kernel
    for i in range(points.shape[0]):
        if i == simplex[0] or i == simplex[1] or i == simplex[2] or i == simplex[3]:
            continue
        _assign_outside_point(points, i, first_faces, 4, fv, fn, fd, delta, head, nxt, far, far_d)


@njit
def _alive_faces(fv, alive, n_faces):
    """The vertex rows (k, 3) of the faces still alive among the first ``n_faces`` slots."""
    faces = np.empty((alive[:n_faces].sum(), 3), dtype=np.int64)
    count = 0
    for g in range(n_faces):
        if alive[g]:
            faces[count] = fv[g]
            count += 1
    return faces


# The mesh arrays are locals of the loop below, never read through the QuickhullMesh tuple inside it, and no
# tuple of them is built or passed after it: either makes numba keep reference counts in the loop (atomic
# increments and decrements of the arrays' counts on every iteration; bench/test_bench_bounding.py, the convex
# hull group's 10,000 points on a sphere, times the loop).
@njit
def _quickhull_kernel(points, simplex, delta, capacity):
    """Quickhull in 3-D (Ericson 12.4.2) from the tetrahedron ``simplex`` (4,) int64 of points not coplanar.
    Returns (faces (m, 3), ok); ok is False only if the simplex is coplanar. ``capacity``: the first number of
    face slots. A point is outside a face when exactly above its plane and more than ``delta`` above it in
    floating point (quickhull's thick planes; ``delta`` = -inf: exactly above).

        the tetrahedron; every other point on the conflict list of a face it is outside
        for each face f with a non-empty conflict list:
            p <- the farthest point of f's list
            replace the faces p sees (exact orient3d) by the cone of new faces on their horizon
            hand the dead faces' points over to the new faces

    Every visibility decision is exact, so each step makes the exact hull of the polytope and p: the mesh stays
    exactly convex, its horizons are simple loops, and a point dropped with ``delta`` = -inf is exactly inside.
    """
    n = points.shape[0]
    if orient3d(points, simplex[0], simplex[1], simplex[2], simplex[3]) == 0.0:
        return np.zeros((0, 3), dtype=np.int64), False
    m = _new_mesh(capacity)
    nxt = np.full(n, -1, dtype=np.int64)  # next point in the same conflict list
    start_face = np.full(n, -1, dtype=np.int64)  # stitch_cone's scratch
    end_face = np.full(n, -1, dtype=np.int64)
    _initial_tetrahedron(points, simplex, m, nxt, delta)
    fv, fadj, fn, fd, alive, head, far, far_d, stamp, visible, stack, horizon, new_faces = m
    n_faces = 4
    f = 0
    while f < n_faces:
        if not alive[f] or head[f] == -1:
            f += 1
            continue
        p = far[f]
        n_visible, n_horizon = visible_faces_and_horizon_exact(f, p, points, fv, fadj, stamp, f, stack, visible,
                                                               horizon)  # mark: f
        if n_faces + n_horizon > fv.shape[0]:
            fv, fadj, fn, fd, alive, head, far, far_d, stamp, visible, stack, horizon, new_faces = _grown_mesh(
                QuickhullMesh(fv, fadj, fn, fd, alive, head, far, far_d, stamp, visible, stack, horizon, new_faces),
                2 * (n_faces + n_horizon))
        if not stitch_cone(p, horizon, n_horizon, fv, fadj, stamp, n_faces, start_face, end_face, new_faces):
            return np.zeros((0, 3), dtype=np.int64), False  # not a simple loop: only if the mesh were not convex
        for nf in range(n_faces, n_faces + n_horizon):  # the cone's planes, with empty conflict lists
            fd[nf] = _plane(points, fv[nf, 0], fv[nf, 1], p, fn[nf])
            alive[nf] = True
            head[nf] = -1
            far[nf] = -1
            far_d[nf] = 0.0
        n_faces += n_horizon
        for v in range(n_visible):  # the visible faces die; their points (but p) go to the new faces or are dropped
            g = visible[v]
            alive[g] = False
            i = head[g]
            while i != -1:
                following = nxt[i]
                if i != p:
                    _assign_outside_point(points, i, new_faces, n_horizon, fv, fn, fd, delta, head, nxt, far, far_d)
                i = following
            head[g] = -1
        f += 1
    return _alive_faces(fv, alive, n_faces), True


@njit
def _max_outside_kernel(points, rows, normals, offsets):
    """The largest signed distance of the points ``rows`` above any face plane (<= 0 for an exact hull)."""
    worst = -np.inf
    for i in rows:
        for f in range(normals.shape[0]):
            d = normals[f, 0] * points[i, 0] + normals[f, 1] * points[i, 1] + normals[f, 2] * points[i, 2]
            d -= offsets[f]
            if d > worst:
                worst = d
    return worst


@njit
def _face_planes(points, faces):
    """Unit outward normals (F, 3), offsets (F,) (through each face's centroid) and twice the areas (F,) of the
    faces, from cross products accurate to a few ulps (predicates.accurate_cross)."""
    m = faces.shape[0]
    normals = np.empty((m, 3))
    offsets = np.empty(m)
    twice_area = np.empty(m)
    for f in range(m):
        offsets[f] = _plane(points, faces[f, 0], faces[f, 1], faces[f, 2], normals[f])
        cross = accurate_cross(points, faces[f, 0], faces[f, 1], faces[f, 2], np.empty(3))
        twice_area[f] = math.sqrt(cross[0] ** 2 + cross[1] ** 2 + cross[2] ** 2)
    return normals, offsets, twice_area


def _edge_pairs(faces, n):
    """The two faces of every edge of a closed, consistently oriented triangle mesh over n points, and the far
    vertex of each: four (E,) int64 arrays (f, g, far vertex of f, far vertex of g); None when some edge is not
    traversed exactly once in each direction."""
    m = faces.shape[0]
    start = faces.ravel()
    end = np.roll(faces, -1, axis=1).ravel()
    far = np.roll(faces, -2, axis=1).ravel()
    face = np.repeat(np.arange(m), 3)
    key = np.minimum(start, end) * n + np.maximum(start, end)
    order = np.argsort(key, kind="stable")
    first, second = order[0::2], order[1::2]
    if (key[first] != key[second]).any() or (np.diff(key[first]) <= 0).any() or (start[first] != end[second]).any():
        return None
    return face[first], face[second], far[first], far[second]


@njit
def _root(parent, a):
    while parent[a] != a:
        parent[a] = parent[parent[a]]
        a = parent[a]
    return a


@njit
def _facet_labels(points, faces, f, g, far_f, far_g, normals, offsets, delta):
    """Qhull's merge of coplanar neighbours (Barber et al. 1996, section 4): faces f[k], g[k] across an edge join
    one facet when each one's far vertex is within ``delta`` of the other's plane (``delta`` <= 0: when the four
    points are exactly coplanar, orient3d = 0). Returns each face's facet label (union-find roots), (F,) int64."""
    parent = np.arange(faces.shape[0])
    for k in range(f.shape[0]):
        a, b = f[k], g[k]
        if delta > 0.0:
            coplanar = (_distance(points, far_g[k], normals[a], offsets[a]) >= -delta
                        and _distance(points, far_f[k], normals[b], offsets[b]) >= -delta)
        else:
            coplanar = orient3d(points, faces[a, 0], faces[a, 1], faces[a, 2], far_g[k]) == 0.0
        if coplanar:
            ra, rb = _root(parent, a), _root(parent, b)
            parent[max(ra, rb)] = min(ra, rb)
    for h in range(faces.shape[0]):
        parent[h] = _root(parent, h)
    return parent


@njit
def _on_at_most_two_facets(faces, labels, n):
    """Boolean (n,): the mesh vertices on one facet (inside a flat region) or two (on the edge between two flat
    regions) — not corners of the polytope, whose corners meet three facets or more."""
    first = np.full(n, -1, dtype=np.int64)
    second = np.full(n, -1, dtype=np.int64)
    seen = np.zeros(n, dtype=np.bool_)
    many = np.zeros(n, dtype=np.bool_)
    for f in range(faces.shape[0]):
        label = labels[f]
        for k in range(3):
            v = faces[f, k]
            seen[v] = True
            if first[v] == -1 or first[v] == label:
                first[v] = label
            elif second[v] == -1 or second[v] == label:
                second[v] = label
            else:
                many[v] = True
    return seen & ~many


def _corner_hull(pts, simplex, delta):
    """Quickhull with thick planes ``delta`` (-inf: exact), then the rebuild from the polytope's corners until
    every vertex is a corner (ties and near-ties make quickhull keep points inside facets or on their edges; the
    facets are merged as in ``_facet_labels``). Returns (faces (F, 3) into ``pts``, the rows removed as not
    corners), or None when a rebuild finds the corners (numerically) flat."""
    index = np.arange(pts.shape[0])
    work = pts
    removed = []
    while True:
        faces, ok = _quickhull_kernel(work, simplex, delta, 256)  # per-face arrays grow as needed
        pairs = _edge_pairs(faces, work.shape[0]) if ok else None
        if pairs is None:
            return None
        normals, offsets, _ = _face_planes(work, faces)
        labels = _facet_labels(work, faces, *pairs, normals, offsets, delta)
        flat = _on_at_most_two_facets(faces, labels, work.shape[0])
        if not flat.any():
            return index[faces], np.concatenate(removed or [np.zeros(0, dtype=np.int64)])
        removed.append(index[flat])
        keep = np.setdiff1d(np.unique(faces), np.flatnonzero(flat))
        index, work = index[keep], work[keep]
        simplex, status = _initial_simplex(work, max(delta, 0.0))
        if status != 0:
            return None


def _volume_from_a_vertex(pts: np.ndarray, faces: np.ndarray) -> float:
    """Volume of the closed outward-oriented triangle mesh ``faces`` (F, 3) int64 over ``pts`` (n, 3) float64: the
    sum of the tetrahedra (r, a, b, c) / 6 (divergence theorem) from r = the hull vertex on the most faces.

    From a point of a convex hull every tetrahedron is >= 0 (no cancellation between terms). Each term is
    (a − r) · ((b − a) × (c − a)) in differences of the input coordinates, whose round-off is about
    2^-53 |a − r| |b − a| |c − a|: each face is turned cyclically (its orientation kept) to the start a making
    that product least — 0 for the faces through r, which then add exactly 0; a sliver face starts at an end of
    its short edge. Summed from the vertex centroid instead, a sliver pyramid 1.4e6 from its apex lost 1.3e-9 of
    its volume (its condition number is 8.8e5)."""
    r = int(np.bincount(faces.ravel()).argmax())
    return float(_volume_terms_kernel(pts, faces, r).sum() / 6.0)  # numpy's pairwise sum of the F terms


@njit
def _volume_terms_kernel(pts, faces, r):
    """The F terms (a − r) · ((b − a) × (c − a)) of _volume_from_a_vertex, each face started at the corner a
    (first of the least) that makes |a − r| |b − a| |c − a| least."""
    terms = np.empty(faces.shape[0])
    for f in range(faces.shape[0]):
        best = 0
        best_cost = np.inf
        for k in range(3):
            a, b, c = faces[f, k], faces[f, (k + 1) % 3], faces[f, (k + 2) % 3]
            cost = math.sqrt(_dist2(pts, a, r)) * math.sqrt(_dist2(pts, b, a)) * math.sqrt(_dist2(pts, c, a))
            if cost < best_cost:
                best_cost = cost
                best = k
        a, b, c = faces[f, best], faces[f, (best + 1) % 3], faces[f, (best + 2) % 3]
        ux, uy, uz = pts[b, 0] - pts[a, 0], pts[b, 1] - pts[a, 1], pts[b, 2] - pts[a, 2]
        vx, vy, vz = pts[c, 0] - pts[a, 0], pts[c, 1] - pts[a, 1], pts[c, 2] - pts[a, 2]
        terms[f] = ((pts[a, 0] - pts[r, 0]) * (uy * vz - uz * vy) + (pts[a, 1] - pts[r, 1]) * (uz * vx - ux * vz)
                    + (pts[a, 2] - pts[r, 2]) * (ux * vy - uy * vx))
    return terms


@njit
def _dist2(pts, i, j):
    return (pts[i, 0] - pts[j, 0]) ** 2 + (pts[i, 1] - pts[j, 1]) ** 2 + (pts[i, 2] - pts[j, 2]) ** 2


def _hull_3d(pts: np.ndarray) -> ConvexHull:
    """Quickhull on ``pts`` (n, 3), |coordinates| < 1: with thick planes of MERGE_TOL s (s = the largest
    absolute coordinate) and certified (every point at most CERTIFY_TOL s above every face plane in floating point, so
    at most HULL_TOL s exactly); when the certificate fails, the exact hull of the points' corners."""
    n = pts.shape[0]
    if n < 4:
        raise ValueError(f"points: a 3-D hull needs at least 4 points that are not coplanar, got {n} point(s)")
    s = max(float(np.abs(pts).max()), np.finfo(float).tiny)
    simplex, status = _initial_simplex(pts, MERGE_TOL * s)
    if status != 0:
        raise ValueError(f"points: {_DEGENERATE_3D[status]}")
    built = _corner_hull(pts, simplex, MERGE_TOL * s)
    if built is None or not _certified(pts, built[0], built[1], CERTIFY_TOL * s):
        built = _corner_hull(pts, simplex, -np.inf)  # exact: every point exactly inside every face plane
    faces = built[0]
    normals, offsets, twice_area = _face_planes(pts, faces)
    vertices = np.unique(faces)
    volume = _volume_from_a_vertex(pts, faces)
    return ConvexHull(pts, vertices.astype(np.int64), faces, normals, offsets, volume, twice_area.sum() / 2.0)


def _certified(pts, faces, removed, tol) -> bool:
    """A closed triangulated sphere (F = 2V - 4) with every input point (the removed non-corners only, past
    FULL_CERTIFY_WORK point-face pairs) at most ``tol`` above every face plane in floating point."""
    if faces.shape[0] != 2 * np.unique(faces).shape[0] - 4:
        return False
    normals, offsets, _ = _face_planes(pts, faces)
    rows = np.arange(pts.shape[0]) if pts.shape[0] * faces.shape[0] <= FULL_CERTIFY_WORK else removed
    return rows.shape[0] == 0 or _max_outside_kernel(pts, rows, normals, offsets) <= tol


def convex_hull(points) -> ConvexHull:
    """The convex hull of a point set: Andrew's monotone chain in 2-D, quickhull in 3-D.

    Quickhull (Barber, Dobkin, Huhdanpaa 1996; Ericson 12.4.2): start from a simplex of extreme points, then
    repeatedly take the point farthest outside a face, remove the faces it sees and join their horizon to it.
    Collinear and coplanar points on the boundary are not vertices. The hull scales exactly: for points scaled
    by a power of two 2^k (coordinates kept normal floats) the vertices, faces and normals are the same and the
    offsets, area and volume are scaled by 2^k, 2^(k(d-1)) and 2^(kd), bit for bit, at every magnitude.

    Parameters
    ----------
    points : array_like, shape (n, d), float64
        d = 2 or 3, n >= d + 1, finite; duplicates and interior points are allowed.

    Returns
    -------
    ConvexHull
        Its vertices, faces, normals, offsets, volume and area.

    Raises
    ------
    ValueError
        For fewer than d + 1 points, NaN or ±inf, or input of lower dimension (all points equal, collinear, or
        coplanar in 3-D; in 3-D to MERGE_TOL × the largest absolute coordinate): such input has no d-dimensional hull.

    Examples
    --------
    The unit cube's corners and its centre:

    >>> import numpy as np
    >>> import engine
    >>> cube = np.array([[x, y, z] for x in (0.0, 1.0) for y in (0.0, 1.0) for z in (0.0, 1.0)])
    >>> hull = engine.convex_hull(np.vstack([cube, [[0.5, 0.5, 0.5]]]))
    >>> hull.vertices, hull.faces.shape, hull.volume, hull.area
    (array([0, 1, 2, 3, 4, 5, 6, 7]), (12, 3), 1.0, 6.0)
    """
    pts = as_points(points)
    d = pts.shape[1]
    # on the cloud scaled by an exact power of two (|coordinates| < 1): cross products and squared lengths
    # neither underflow for a tiny cloud nor overflow for a huge one, and the hull scales exactly
    e = int(unit_scale_exponent(pts))
    unit = np.ldexp(pts, -e)
    hull = _hull_2d(unit) if d == 2 else _hull_3d(unit)
    with np.errstate(over="ignore"):  # a volume beyond the float range is inf (documented)
        volume, area = np.ldexp(hull.volume, d * e), np.ldexp(hull.area, (d - 1) * e)
    return ConvexHull(pts, hull.vertices, hull.faces, hull.normals, np.ldexp(hull.offsets, e), volume, area)


# ---------------------------------------------------------------------------------------------------------
# convexity
# ---------------------------------------------------------------------------------------------------------
@njit
def _polygon_convex_kernel(poly, tol):
    """Slide "Objet convexe", practical form: every vertex on the inner side of every edge line, and the
    boundary turns once around (total turning 2 pi), which rules out a convex polygon traversed twice."""
    n = poly.shape[0]
    area2 = 0.0
    for i in range(n):
        j = (i + 1) % n
        area2 += poly[i, 0] * poly[j, 1] - poly[j, 0] * poly[i, 1]
    if area2 == 0.0:
        return False
    sign = 1.0 if area2 > 0.0 else -1.0
    turning = 0.0
    for i in range(n):
        j = (i + 1) % n
        ex = poly[j, 0] - poly[i, 0]
        ey = poly[j, 1] - poly[i, 1]
        length = math.sqrt(ex * ex + ey * ey)
        for k in range(n):
            side = sign * (ex * (poly[k, 1] - poly[i, 1]) - ey * (poly[k, 0] - poly[i, 0]))
            if side < -tol * length:
                return False
        nx = poly[(j + 1) % n, 0] - poly[j, 0]
        ny = poly[(j + 1) % n, 1] - poly[j, 1]
        if length > 0.0 and (nx != 0.0 or ny != 0.0):
            turning += math.atan2(ex * ny - ey * nx, ex * nx + ey * ny)
    return abs(abs(turning) - 2.0 * math.pi) < 1e-6


@njit
def _mesh_convex_kernel(vertices, faces, tol):
    """Every vertex on the inner side of every face plane (outward faces; all-inward faces are flipped). Each
    face's normal is its cross product accurate to a few ulps (predicates.accurate_cross), so that a sliver face
    (nearly collinear corners) has its exact plane's direction, not one tilted by ε / (the sine of its angle)."""
    m = faces.shape[0]
    o = vertices[faces[0, 0]]
    volume6 = 0.0  # about a vertex of the surface: no cancellation from the coordinates' magnitude
    for f in range(m):
        a = vertices[faces[f, 0]] - o
        b = vertices[faces[f, 1]] - o
        c = vertices[faces[f, 2]] - o
        volume6 += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                    + a[2] * (b[0] * c[1] - b[1] * c[0]))
    if volume6 == 0.0:
        return False
    sign = 1.0 if volume6 > 0.0 else -1.0
    normal = np.empty(3)
    for f in range(m):
        a = vertices[faces[f, 0]]
        accurate_cross(vertices, faces[f, 0], faces[f, 1], faces[f, 2], normal)
        length = math.sqrt(normal[0] ** 2 + normal[1] ** 2 + normal[2] ** 2)
        if length == 0.0:
            continue  # a degenerate (zero-area) triangle has no plane
        for k in range(vertices.shape[0]):
            w = vertices[k] - a
            if sign * (normal[0] * w[0] + normal[1] * w[1] + normal[2] * w[2]) > tol * length:
                return False
    return True


def is_convex(vertices, faces=None, *, tol: float = 1e-9) -> bool:
    """Whether a polygon or a closed polyhedral surface is convex (slide "Objet convexe").

    Every vertex must lie on the inner side of every face plane (edge line, in 2-D), to ``tol`` times the
    coordinate scale. Degenerate shapes (zero area or volume) are not convex.

    Parameters
    ----------
    vertices : array_like, shape (n, 2) or (n, 3), float64
        2-D: the polygon's vertices in boundary order (either orientation), n >= 3. 3-D: the surface's vertices,
        e.g. a ``ConvexHull``'s ``points``.
    faces : array_like, shape (m, 3), int, optional
        3-D only (required there): triangles, m >= 4, consistently oriented (all outward or all inward); must be
        None in 2-D.
    tol : float, default 1e-9
        Relative tolerance, >= 0.

    Returns
    -------
    bool
        True when no vertex lies outside a face plane by more than the tolerance.

    Raises
    ------
    ValueError
        For ``faces`` given in 2-D or missing in 3-D, a face index out of range (named ``faces[f, e]``), faces not
        of shape (m, 3) with m >= 4, fewer than 3 vertices, NaN or ±inf, or a negative ``tol``.

    Examples
    --------
    >>> import engine
    >>> engine.is_convex([[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]])
    True
    >>> engine.is_convex([[0.0, 0.0], [2.0, 0.0], [1.0, 0.5], [2.0, 2.0], [0.0, 2.0]])
    False
    """
    tol = as_nonnegative(tol, "tol")
    pts = as_points(vertices, "vertices", min_rows=3)
    scale = float(np.abs(pts - pts.mean(axis=0)).max()) or 1.0
    if pts.shape[1] == 2:
        if faces is not None:
            raise ValueError("faces must be None for a 2-D polygon (its vertices are given in boundary order)")
        repeated = (pts == np.roll(pts, 1, axis=0)).all(axis=1)  # a vertex equal to its predecessor adds nothing
        if repeated.all():
            return False
        ring = pts[~repeated]
        if len(ring) < 3:
            return False
        return bool(_polygon_convex_kernel(ring - ring.mean(axis=0), tol * scale))
    if faces is None:
        raise ValueError("faces is required for a 3-D polyhedron: an (m, 3) array of vertex indices")
    tri = np.asarray(faces)
    if tri.dtype.kind not in "iu" or tri.ndim != 2 or tri.shape[1] != 3 or tri.shape[0] < 4:
        raise ValueError(f"faces must be an (m, 3) integer array with m >= 4, got {tri.dtype} {tri.shape}")
    bad = (tri < 0) | (tri >= pts.shape[0])
    if bad.any():
        f, e = (int(i) for i in np.argwhere(bad)[0])
        raise ValueError(f"faces[{f}, {e}] = {tri[f, e]} is not a vertex index in [0, {pts.shape[0]})")
    return bool(_mesh_convex_kernel(pts, tri.astype(np.int64), tol * scale))  # uncentred: no rounding of corners

