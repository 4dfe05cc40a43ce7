"""Convex bodies against a static triangle surface (engine.narrowphase.triangle_mesh: a ``TriangleMesh`` or a
``HeightField``), batched over the (body, surface) pairs of one surface: the World's four questions — overlap,
contact, distance, time of impact — as compiled loops (``mesh_overlap_rows``, ``mesh_contact_rows``,
``mesh_distance_rows``, ``mesh_impact_times``). Every kernel takes its scratch (``mesh_work``): thread-safe.

Per pair, the body's AABB selects the candidate triangles (``candidate_triangles``: the BVH or the grid), then a
per-triangle kernel answers each one by the body's shape (``BODY_ROUND``: a sphere's point or a capsule's
segment, engine.narrowphase.triangle_contact.round_core_triangle; ``BODY_BOX``, ``BODY_HULL``: GJK/EPA on the
body's corners against the triangle as a 3-point core, ``convex_triangle``, with an exact SAT over a superset of
the Minkowski difference's face normals where EPA gives up on round-off), written into a ``TriangleContact``.

- Active edges (Jolt's ``ActiveEdges::FixNormal``): when the triangle feature that touches is an inactive edge,
  or a corner whose two edges in that triangle (``VERTEX_EDGES``) are both inactive, the normal becomes the
  triangle's face normal, turned into the hemisphere of the computed normal; the separation stays the exact one.
- Merge (contact): the pair touches iff some triangle has separation <= 0; its separation is the minimum over
  the candidates, its normal and features the deepest triangle's (ties: the lowest triangle id); its points are
  every touching triangle's points, reduced to ``contacts.MAX_POINTS`` by ``contacts.reduce_manifold`` (the
  deepest first). Overlap stops at the first touching triangle.
- Point ids: the body's feature key (the kernels' numbering) with the surface's key in its global numbering:
  face t is triangle t, edge e of triangle t is 3t + e (the two triangles of a shared edge number it apart),
  corner v of triangle t is its vertex index ``triangles[t, v]``. A key's index keeps its low 20 bits
  (contacts.feature_key): past 2^20 triangles (or 2^20 / 3 for edges, 2^20 vertices) two features of the surface
  may share an index; two points of one pair never share an id (reduce_manifold bumps a repeat).
- Distance: the candidates under the body's box first (a touching triangle must meet it): if one touches, the
  contact's separation; else every triangle in order of its box's distance to the body's box, until that lower
  bound passes the nearest distance found (the closest triangle, exactly). Witness points: the triangle kernel's
  closest points (a round core: its point halfway ∓ separation / 2 · normal; a box or hull: GJK's / EPA's); the
  normal is the computed one (no active-edge fix: point_b − point_a = distance · normal).
- Impact: conservative advancement (engine.narrowphase.time_of_impact.toi_kernel) of the translating body against
  each triangle under its swept box, the static triangle a 3-point core; the earliest time wins.

The body (the kernel's A: its kind code is below the surfaces') and the surface are oriented by ``flip`` (the
pair's first shape is the surface): normals are stored from the pair's first shape to its second.
"""
from __future__ import annotations

import math
from collections import namedtuple

import numpy as np

from .._config import njit
from .contact_manifold import FEATURE_TOL, contact_points, feature_scratch
from .contacts import (
    APART,
    EDGE,
    FACE,
    TOUCHING,
    VERTEX,
    feature_key,
    kernel_scratch,
    point_id,
    reduce_manifold,
    swap_point_id,
    write_pair,
)
from .epa import epa_polytope
from .gjk import MAX_ITERATIONS, gjk_scratch
from .penetration import penetration_kernel
from .signed_distance import SMALLEST_GAP
from .status import OVERLAP, SEPARATED
from .time_of_impact import toi_kernel
from .touching_normal import unit_vector
from .triangle_contact import MAX_TRIANGLE_POINTS, round_core_triangle, triangle_contact
from .triangle_mesh import VERTEX_EDGES, candidate_triangles

__all__ = ["BODY_ROUND", "BODY_BOX", "BODY_HULL", "MeshWork", "mesh_work", "convex_triangle", "fix_normal",
           "surface_key", "triangle_answer", "mesh_overlap_rows", "mesh_contact_rows", "mesh_distance_rows",
           "mesh_impact_times", "IMPACT_TOL", "IMPACT_ITERATIONS"]

#: the body's shape, as the kernels dispatch on it: a round core (sphere, capsule), a box, a hull
BODY_ROUND, BODY_BOX, BODY_HULL = 0, 1, 2
#: conservative advancement's contact distance and step cap (the ADVANCEMENT rows' defaults)
IMPACT_TOL = 1e-9
IMPACT_ITERATIONS = 256
_INDEX_MASK = (1 << 20) - 1

#: the kernels' scratch, one per thread (``mesh_work``): ``stack`` (nodes + 1,) int64 for the BVH descent,
#: ``cand`` (c,) int64 candidate triangles (grown when full), ``tri`` a TriangleContact; the merged points
#: ``pts`` (P, 3), ``deep`` (P,), ``ids`` (P,) int64 and ``scratch`` (contacts.kernel_scratch) of
#: reduce_manifold; the GJK/EPA fallback's ``gjk`` (gjk_scratch), ``poly`` (epa_polytope), ``g`` (7,), ``res``
#: (10,), ``feat`` (feature_scratch), ``corners`` (3, 3) the triangle, ``cpts`` (2 m + 8, 3) its contact points;
#: the impact's ``poses`` (2, m, 3), ``toi`` (4,); the distance's ``lower`` (nt,) box distances, ``wit`` (2, 3)
#: the witnesses of the last triangle
MeshWork = namedtuple("MeshWork", "stack cand tri pts deep ids scratch gjk poly g res feat corners cpts poses toi "
                                  "lower wit")


def mesh_work(mesh, m: int) -> MeshWork:
    """Scratch for the kernels over the surface ``mesh`` (MeshArrays) and bodies of at most m core points."""
    m = max(int(m), 3)
    nodes = mesh.node_lo.shape[0]
    n_pts = 16 * MAX_TRIANGLE_POINTS
    return MeshWork(np.empty(nodes + 1, np.int64), np.empty(64, np.int64), triangle_contact(),
                    np.empty((n_pts, 3)), np.empty(n_pts), np.empty(n_pts, np.int64), kernel_scratch(m),
                    gjk_scratch(m), epa_polytope(), np.empty(7), np.empty(10), feature_scratch(m), np.empty((3, 3)),
                    np.empty((2 * m + 8, 3)), np.empty((2, m, 3)), np.empty(4), np.empty(mesh.triangles.shape[0]),
                    np.empty((2, 3)))


# -- one body against one triangle ----------------------------------------------------------------------------
@njit
def _axis_depth(pa, tri, ux, uy, uz, best):
    """SAT along the axis u (any length): (depth, unit normal) of the smaller of the two overlaps — translating
    the triangle along +u or −u — when below ``best[0]``, written into best (4,)."""
    ux, uy, uz, ok = unit_vector(ux, uy, uz)
    if not ok:
        return
    top_a, bot_a = -np.inf, np.inf
    for v in range(pa.shape[0]):
        h = pa[v, 0] * ux + pa[v, 1] * uy + pa[v, 2] * uz
        top_a, bot_a = max(top_a, h), min(bot_a, h)
    top_t, bot_t = -np.inf, np.inf
    for v in range(3):
        h = tri[v, 0] * ux + tri[v, 1] * uy + tri[v, 2] * uz
        top_t, bot_t = max(top_t, h), min(bot_t, h)
    if top_a - bot_t < best[0]:
        best[0], best[1], best[2], best[3] = top_a - bot_t, ux, uy, uz
    if top_t - bot_a < best[0]:
        best[0], best[1], best[2], best[3] = top_t - bot_a, -ux, -uy, -uz


@njit
def _sat_depth(pa, tri, n_face, best):
    """The penetration depth and normal (body towards triangle) of hull(pa) and the triangle ``tri`` (3, 3) into
    best (4,), by SAT over a superset of the Minkowski difference's face normals (Ericson 5.2.1, 4.4.1): the
    triangle's normal, every body point pair × triangle edge, the plane of every triple of body points (its faces
    among them). The exact answer where EPA gave up on round-off (many coplanar support points)."""
    n = pa.shape[0]
    best[0] = np.inf
    _axis_depth(pa, tri, n_face[0], n_face[1], n_face[2], best)
    for i in range(n):
        for j in range(i + 1, n):
            dx, dy, dz = pa[j, 0] - pa[i, 0], pa[j, 1] - pa[i, 1], pa[j, 2] - pa[i, 2]
            for e in range(3):
                e0, e1 = tri[e], tri[(e + 1) % 3]
                ux, uy, uz = _cross(dx, dy, dz, e1[0] - e0[0], e1[1] - e0[1], e1[2] - e0[2])
                _axis_depth(pa, tri, ux, uy, uz, best)
            for k in range(j + 1, n):
                ux, uy, uz = _cross(dx, dy, dz, pa[k, 0] - pa[i, 0], pa[k, 1] - pa[i, 1], pa[k, 2] - pa[i, 2])
                _axis_depth(pa, tri, ux, uy, uz, best)


@njit(inline="always")
def _cross(ax, ay, az, bx, by, bz):
    return ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx


@njit
def _support_vertex(points, nx, ny, nz, sign, tol, x):
    """The row of ``points`` in the support set along sign·n (within tol of its plane) nearest to x across n."""
    top = -np.inf
    for v in range(points.shape[0]):
        top = max(top, sign * (points[v, 0] * nx + points[v, 1] * ny + points[v, 2] * nz))
    best, pick = np.inf, 0
    for v in range(points.shape[0]):
        if sign * (points[v, 0] * nx + points[v, 1] * ny + points[v, 2] * nz) >= top - tol:
            dx, dy, dz = x[0] - points[v, 0], x[1] - points[v, 1], x[2] - points[v, 2]
            along = dx * nx + dy * ny + dz * nz
            off = (dx - along * nx) ** 2 + (dy - along * ny) ** 2 + (dz - along * nz) ** 2
            if off < best:
                best, pick = off, v
    return pick


@njit
def _triangle_feature(tri, nx, ny, nz, tol):
    """The triangle's supporting feature along −n: its corners within tol of min corner·n — one corner (VERTEX v),
    two (EDGE e, joining corners e and (e + 1) % 3) or three (FACE 0)."""
    h0 = tri[0, 0] * nx + tri[0, 1] * ny + tri[0, 2] * nz
    h1 = tri[1, 0] * nx + tri[1, 1] * ny + tri[1, 2] * nz
    h2 = tri[2, 0] * nx + tri[2, 1] * ny + tri[2, 2] * nz
    low = min(h0, min(h1, h2))
    in0, in1, in2 = h0 <= low + tol, h1 <= low + tol, h2 <= low + tol
    if in0 and in1 and in2:
        return FACE, 0
    if in0 and in1:
        return EDGE, 0
    if in1 and in2:
        return EDGE, 1
    if in0 and in2:
        return EDGE, 2
    return VERTEX, 0 if in0 else (1 if in1 else 2)


@njit
def convex_triangle(pa, radius, a, b, c, n_face, out, work):
    """The GJK/EPA answer of hull(pa) ((n, 3) core points, swept by ``radius``) against the triangle (a, b, c) as
    a 3-point core, into the TriangleContact ``out``: the penetration chain (engine.narrowphase.penetration; SAT
    where EPA gives up), then the contact features and points of engine.narrowphase.contact_manifold (the body's
    feature per point at its nearest support vertex, as engine.narrowphase.convex_cores). Returns the
    separation."""
    tri = work.corners
    for k in range(3):
        tri[0, k], tri[1, k], tri[2, k] = a[k], b[k], c[k]
    res = work.res
    status = penetration_kernel(pa, tri, np.int64(MAX_ITERATIONS), work.gjk, work.poly, work.g, res)
    if status != SEPARATED and status != OVERLAP:
        _sat_depth(pa, tri, n_face, work.toi)
        res[0], nx, ny, nz = -work.toi[0], work.toi[1], work.toi[2], work.toi[3]
        res[1], res[2], res[3] = nx, ny, nz
        top = -np.inf
        for v in range(pa.shape[0]):
            top = max(top, pa[v, 0] * nx + pa[v, 1] * ny + pa[v, 2] * nz)
        for k in range(3):  # a support point of each side: what contact_points falls back on
            res[4 + k] = pa[_support_vertex(pa, nx, ny, nz, 1.0, 0.0, pa[0]), k]
            res[7 + k] = tri[_support_vertex(tri, nx, ny, nz, -1.0, 0.0, tri[0]), k]
    separation = res[0] - radius
    nx, ny, nz = res[1], res[2], res[3]
    out.separation[0] = separation
    out.normal[0], out.normal[1], out.normal[2] = nx, ny, nz
    work.wit[0, 0], work.wit[0, 1], work.wit[0, 2] = res[4] + radius * nx, res[5] + radius * ny, res[6] + radius * nz
    work.wit[1, 0], work.wit[1, 1], work.wit[1, 2] = res[7], res[8], res[9]
    ka, kb, count = contact_points(pa, tri, radius, 0.0, res[1:4], res[4:7], res[7:10], FEATURE_TOL, work.feat,
                                   work.cpts, 0)
    size = 0.0
    for k in range(3):
        lo, hi = np.inf, -np.inf
        for v in range(pa.shape[0]):
            lo, hi = min(lo, pa[v, k]), max(hi, pa[v, k])
        for v in range(3):
            lo, hi = min(lo, tri[v, k]), max(hi, tri[v, k])
        size = max(size, hi - lo)
    tol = FEATURE_TOL * max(size, radius, 1e-300)
    ft, fi = _triangle_feature(tri, nx, ny, nz, tol)
    out.tri_feature[0], out.tri_feature[1] = ft, fi
    out.body_feature[0] = ka
    count = min(count, MAX_TRIANGLE_POINTS)
    out.count[0] = count
    for q in range(count):
        for k in range(3):
            out.points[q, k] = work.cpts[q, k]
        out.depths[q] = max(-separation, 0.0)
        out.body_keys[q] = feature_key(ka, _support_vertex(pa, nx, ny, nz, 1.0, tol, work.cpts[q]))
        out.tri_keys[q] = feature_key(ft, fi)
    return separation


@njit(inline="always")
def _core(bodies, body):
    return bodies.points[body, :bodies.count[body]]


@njit
def triangle_answer(bodies, shape, body, mesh, t, out, work):
    """Body ``body`` of the store ``bodies`` (engine.world.bodies.BodyArrays; ``shape`` BODY_ROUND / BOX / HULL)
    against triangle t of ``mesh``, into the TriangleContact ``out`` (before the active-edge fix); returns the
    separation. The body's witness is work.wit[0], the triangle's work.wit[1]."""
    v = mesh.vertices
    ia, ib, ic = mesh.triangles[t, 0], mesh.triangles[t, 1], mesh.triangles[t, 2]
    a, b, c, n = v[ia], v[ib], v[ic], mesh.normals[t]
    r = bodies.radius[body]
    if shape == BODY_ROUND:
        s = round_core_triangle(bodies.points[body, 0], bodies.points[body, bodies.count[body] - 1], r, a, b, c, n,
                                out)
        for k in range(3):
            work.wit[0, k] = out.points[0, k] - 0.5 * s * out.normal[k]
            work.wit[1, k] = out.points[0, k] + 0.5 * s * out.normal[k]
        return s
    return convex_triangle(_core(bodies, body), r, a, b, c, n, out, work)


@njit(inline="always")
def _edge_inactive(mesh, t, ft, fi):
    if ft == EDGE:
        return not mesh.active[t, fi]
    if ft == VERTEX:
        return not mesh.active[t, VERTEX_EDGES[fi, 0]] and not mesh.active[t, VERTEX_EDGES[fi, 1]]
    return False


@njit
def fix_normal(mesh, t, out):
    """Jolt's ActiveEdges::FixNormal on triangle t's answer ``out``: an inactive edge, or a corner whose two edges
    are inactive, takes the face normal in the hemisphere of the computed one (+ the face normal when they are
    perpendicular)."""
    if _edge_inactive(mesh, t, out.tri_feature[0], out.tri_feature[1]):
        nx, ny, nz = mesh.normals[t, 0], mesh.normals[t, 1], mesh.normals[t, 2]
        sign = -1.0 if nx * out.normal[0] + ny * out.normal[1] + nz * out.normal[2] < 0.0 else 1.0
        out.normal[0], out.normal[1], out.normal[2] = sign * nx, sign * ny, sign * nz


@njit(inline="always")
def surface_key(mesh, t, key):
    """Triangle t's local feature key in the surface's numbering (module docstring)."""
    kind = key >> 20
    local = key & _INDEX_MASK
    if kind == FACE:
        index = np.int64(t)
    elif kind == EDGE:
        index = 3 * np.int64(t) + local
    else:
        index = mesh.triangles[t, local]
    return feature_key(kind, index & _INDEX_MASK)


@njit(inline="always")
def _candidates(mesh, bodies, body, work, cand):
    return candidate_triangles(mesh, bodies.lo[body], bodies.hi[body], work.stack, cand)


# -- the batched questions ----------------------------------------------------------------------------------------
@njit
def mesh_overlap_rows(mesh, bodies, shape, body, at, flip, rows, work):
    """The overlap question for the pairs at rows ``at`` (k,) of ``rows`` (ContactRows), body ``body[q]`` (k,) of
    shape ``shape[q]`` against this surface: TOUCHING at the first candidate triangle at separation <= 0."""
    cand = work.cand
    for q in range(at.shape[0]):
        p, i = at[q], body[q]
        cand, count = _candidates(mesh, bodies, i, work, cand)
        rows.status[p] = APART
        for x in range(count):
            if triangle_answer(bodies, shape[q], i, mesh, cand[x], work.tri, work) <= 0.0:
                rows.status[p] = TOUCHING
                break


@njit
def _merge_contact(mesh, bodies, shape, i, cand, count, work, pts, deep, ids):
    """The merged contact of body i over the candidate triangles cand[:count] (module docstring): (separation,
    normal, body feature, triangle feature type, points count, the deepest triangle or −1); the points in pts,
    deep, ids."""
    tri = work.tri
    best, best_t, n = np.inf, np.int64(-1), np.int64(0)
    nx = ny = nz = 0.0
    fa = fb = np.int64(0)
    for x in range(count):
        t = cand[x]
        s = triangle_answer(bodies, shape, i, mesh, t, tri, work)
        fix_normal(mesh, t, tri)
        if s < best:
            best, best_t = s, t
            nx, ny, nz = tri.normal[0], tri.normal[1], tri.normal[2]
            fa, fb = tri.body_feature[0], tri.tri_feature[0]
        if s <= 0.0:
            for v in range(tri.count[0]):
                for k in range(3):
                    pts[n, k] = tri.points[v, k]
                deep[n] = tri.depths[v]
                ids[n] = point_id(tri.body_keys[v], surface_key(mesh, t, tri.tri_keys[v]))
                n += 1
    return best, nx, ny, nz, fa, fb, n, best_t


@njit
def _sort_deepest_first(pts, deep, ids, n):
    """Insertion sort of the n points by depth, deepest first (stable: the triangle order breaks ties)."""
    for i in range(1, n):
        j = i
        while j > 0 and deep[j] > deep[j - 1]:
            for k in range(3):
                pts[j, k], pts[j - 1, k] = pts[j - 1, k], pts[j, k]
            deep[j], deep[j - 1] = deep[j - 1], deep[j]
            ids[j], ids[j - 1] = ids[j - 1], ids[j]
            j -= 1


@njit
def mesh_contact_rows(mesh, bodies, shape, body, at, flip, rows, work):
    """The contact question for the pairs at rows ``at`` (k,) of ``rows`` (ContactRows), body ``body[q]`` of
    shape ``shape[q]`` against this surface, ``flip[q]``: the pair's first shape is the surface (module
    docstring: the merge)."""
    cand, pts, deep, ids = work.cand, work.pts, work.deep, work.ids
    for q in range(at.shape[0]):
        p, i = at[q], body[q]
        cand, count = _candidates(mesh, bodies, i, work, cand)
        if count * MAX_TRIANGLE_POINTS > pts.shape[0]:
            size = 2 * count * MAX_TRIANGLE_POINTS
            pts, deep, ids = np.empty((size, 3)), np.empty(size), np.empty(size, np.int64)
        best, nx, ny, nz, fa, fb, n, _ = _merge_contact(mesh, bodies, shape[q], i, cand, count, work, pts, deep,
                                                        ids)
        _sort_deepest_first(pts, deep, ids, n)
        n = reduce_manifold(pts, deep, ids, n, nx, ny, nz, work.scratch)
        write_pair(rows, p, best, nx, ny, nz, fa, fb, n, flip[q])
        for v in range(n):
            for k in range(3):
                rows.points[p, v, k] = pts[v, k]
            rows.ids[p, v] = swap_point_id(ids[v]) if flip[q] else ids[v]


@njit(inline="always")
def _box_gap(lo, hi, mesh, t):
    """The distance from the box [lo, hi] to triangle t's AABB (0 when they meet): a lower bound of the distance
    from anything in the box to the triangle."""
    g2 = 0.0
    for k in range(3):
        x0 = mesh.vertices[mesh.triangles[t, 0], k]
        x1 = mesh.vertices[mesh.triangles[t, 1], k]
        x2 = mesh.vertices[mesh.triangles[t, 2], k]
        gap = max(min(x0, min(x1, x2)) - hi[k], lo[k] - max(x0, max(x1, x2)), 0.0)
        g2 += gap * gap
    return math.sqrt(g2)


@njit
def _write_distance(out, p, flip, s, nx, ny, nz, wit):
    sign = -1.0 if flip else 1.0
    first, second = (1, 0) if flip else (0, 1)
    out.distance[p] = s
    for k in range(3):
        out.normal[p, k] = sign * (nx if k == 0 else (ny if k == 1 else nz))
        out.point_a[p, k] = wit[first, k]
        out.point_b[p, k] = wit[second, k]


@njit
def mesh_distance_rows(mesh, bodies, shape, body, at, flip, out, work):
    """The distance question (DistanceRows ``out``, rows ``at``) for body ``body[q]`` against this surface: the
    signed distance to the nearest triangle and its witnesses (module docstring)."""
    cand, tri, lower = work.cand, work.tri, work.lower
    nt = mesh.triangles.shape[0]
    order = np.empty(nt, np.int64)
    best_w = np.empty((2, 3))
    for q in range(at.shape[0]):
        p, i = at[q], body[q]
        cand, count = _candidates(mesh, bodies, i, work, cand)
        best, bx, by, bz = np.inf, 1.0, 0.0, 0.0
        for x in range(count):  # a touching triangle meets the body's box
            s = triangle_answer(bodies, shape[q], i, mesh, cand[x], tri, work)
            if s < best:
                best, bx, by, bz = s, tri.normal[0], tri.normal[1], tri.normal[2]
                best_w[:] = work.wit
        if not best <= 0.0:  # apart: the nearest triangle, by increasing box distance
            best = np.inf
            for t in range(nt):
                lower[t] = _box_gap(bodies.lo[i], bodies.hi[i], mesh, t)
            order[:] = np.argsort(lower, kind="mergesort")
            for x in range(nt):
                t = order[x]
                if lower[t] > best + bodies.radius[i]:  # the core is radius inside the box: d − r >= gap − r
                    break
                s = triangle_answer(bodies, shape[q], i, mesh, t, tri, work)
                if s < best:
                    best, bx, by, bz = s, tri.normal[0], tri.normal[1], tri.normal[2]
                    best_w[:] = work.wit
            best = max(best, SMALLEST_GAP)  # no candidate touches: apart, as the overlap question says
        _write_distance(out, p, flip[q], best, bx, by, bz, best_w)


@njit
def mesh_impact_times(mesh, bodies, body, dt, times, at, status):
    """The impact question: for body ``body[q]`` translating by its velocity over [0, dt], the earliest time of
    contact with a triangle under its swept box (times[at[q]], inf for none), by conservative advancement against
    each one; status[q] the worst toi status (TOI_NOT_CONVERGED stops the search)."""
    work_cand = np.empty(64, np.int64)
    lo, hi = np.empty(3), np.empty(3)
    stack = np.empty(mesh.node_lo.shape[0] + 1, np.int64)
    tri = np.empty((3, 3))
    zero = np.zeros(3)
    n_max = np.int64(3)
    for q in range(body.shape[0]):
        n_max = max(n_max, bodies.count[body[q]])
    scratch = gjk_scratch(n_max)
    poses = np.empty((2, n_max, 3))
    g = np.empty(7)
    res = np.empty(4)
    for q in range(at.shape[0]):
        i = body[q]
        for k in range(3):
            step = bodies.velocity[i, k] * dt
            lo[k] = bodies.lo[i, k] + min(step, 0.0)
            hi[k] = bodies.hi[i, k] + max(step, 0.0)
        work_cand, count = candidate_triangles(mesh, lo, hi, stack, work_cand)
        pa = _core(bodies, i)
        center = bodies.center[i]
        earliest = np.inf
        status[q] = SEPARATED
        for x in range(count):
            t = work_cand[x]
            for v in range(3):
                for k in range(3):
                    tri[v, k] = mesh.vertices[mesh.triangles[t, v], k]
            st = toi_kernel(pa, center, bodies.velocity[i], zero, bodies.radius[i], tri, tri[0], zero, zero, 0.0,
                            dt, IMPACT_TOL, IMPACT_ITERATIONS, scratch, poses, g, res)
            if st != OVERLAP and st != SEPARATED:
                status[q] = st
                break
            if st == OVERLAP and res[0] < earliest:
                earliest = res[0]
        times[at[q]] = earliest
