"""Convex bodies against a static triangle surface (engine.narrowphase.triangle_mesh: a ``TriangleMesh`` or a
``HeightField``), batched over the (body, surface) pairs of one surface: the World's four questions — overlap,
contact, distance, time of impact — as compiled loops (``mesh_overlap_rows``, ``mesh_contact_rows``,
``mesh_distance_rows``, ``mesh_impact_times``). Every kernel takes its scratch (``mesh_work``): thread-safe.

Per pair, the body's AABB selects the candidate triangles (``candidate_triangles``: the BVH or the grid), then a
per-triangle kernel answers each one by the body's shape (``BODY_ROUND``: a sphere's point or a capsule's
segment, engine.narrowphase.triangle_contact.round_core_triangle; ``BODY_BOX``: the 13-axis SAT and clipped
manifold of engine.narrowphase.box_triangle; ``BODY_HULL``: GJK/EPA on the hull's vertices against the triangle
as a 3-point core, ``convex_triangle``, with an exact SAT over a superset of the Minkowski difference's face
normals where EPA gives up on round-off), written into a ``TriangleContact``. The kernels read the triangle's
corners and the core's ends as 3-tuples of scalars (``_triangle_of``, ``_round_of``).

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
  contact's separation; else the nearest triangle among those whose AABBs meet the body's box grown by a reach
  that doubles (from the body's size) until it passes the nearest distance found plus the body's radius: every
  triangle outside is then farther (its box distance, a lower bound, exceeds the reach); a triangle whose box
  distance already exceeds that bound is skipped unanswered. Apart, a box's answer is GJK's exact distance (its
  SAT gives only a lower bound). Ties: the lowest triangle id (whatever order the BVH or grid gives). Witness
  points: a round core's (or a touching box's deepest manifold point's) halfway point ∓ separation / 2 · normal;
  a box apart or a hull: GJK's / EPA's; the normal is the computed one (no active-edge fix: point_b − point_a =
  distance · normal).
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
from .box_triangle import box_triangle
from .contact_manifold import FEATURE_TOL, contact_points, feature_scratch
from .contacts import (
    APART,
    EDGE,
    FACE,
    TOUCHING,
    VERTEX,
    feature_key,
    kernel_scratch,
    key_kind,
    point_id,
    reduce_manifold,
    swap_point_id,
    write_pair,
)
from .convex_cores import nearest_support_vertex
from .epa import epa_polytope
from .gjk import MAX_ITERATIONS, gjk_scratch
from .penetration import penetration_kernel
from .signed_distance import SMALLEST_GAP
from .status import OVERLAP, SEPARATED
from .time_of_impact import toi_kernel
from .touching_normal import unit_vector
from .triangle_contact import MAX_TRIANGLE_POINTS, round_core_answer, round_core_triangle, triangle_contact
from .triangle_mesh import VERTEX_EDGES, candidate_triangles

__all__ = ["BODY_ROUND", "BODY_BOX", "BODY_HULL", "MeshWork", "mesh_work", "convex_triangle", "sat_hull_triangle",
           "fix_normal", "surface_key", "triangle_answer", "triangle_distance", "mesh_overlap_rows",
           "mesh_contact_rows", "mesh_distance_rows", "mesh_impact_times", "IMPACT_TOL", "IMPACT_ITERATIONS"]

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
#: the impact's ``poses`` (2, m, 3), ``toi`` (4,); the distance's ``wit`` (2, 3) the witnesses of the last
#: triangle
MeshWork = namedtuple("MeshWork", "stack cand tri pts deep ids scratch gjk poly g res feat corners cpts poses toi "
                                  "wit")


def mesh_work(mesh, m: int) -> MeshWork:
    """Scratch for the kernels over the surface ``mesh`` (MeshArrays) and bodies of at most m core points."""
    m = max(int(m), 3)
    nodes = mesh.node_lo.shape[0]
    n_pts = 16 * MAX_TRIANGLE_POINTS
    return MeshWork(np.empty(nodes + 1, np.int64), np.empty(64, np.int64), triangle_contact(),
                    np.empty((n_pts, 3)), np.empty(n_pts), np.empty(n_pts, np.int64), kernel_scratch(m),
                    gjk_scratch(m), epa_polytope(), np.empty(7), np.empty(10), feature_scratch(m), np.empty((3, 3)),
                    np.empty((2 * m + 8, 3)), np.empty((2, m, 3)), np.empty(4), np.empty((2, 3)))


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
def sat_hull_triangle(pa, tri, n_face, best):
    """The penetration depth and unit normal (body towards triangle) of hull(pa) ((n, 3)) and the triangle ``tri``
    (3, 3) of unit normal ``n_face`` (3,) into best (4,), by SAT over a superset of the Minkowski difference's face
    normals (Ericson 5.2.1, 4.4.1): the triangle's normal, every body point pair × triangle edge, the plane of every
    triple of body points (its faces among them). The exact answer where EPA gave up on round-off (many coplanar
    support points); apart, best[0] is minus the largest gap over those axes (a lower bound of the distance)."""
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
def _convex_separation(pa, radius, a, b, c, n_face, work):
    """The penetration chain of hull(pa) ((n, 3) core points, swept by ``radius``) against the triangle (a, b, c)
    as a 3-point core (engine.narrowphase.penetration: GJK's distance apart, EPA's depth overlapping; SAT where EPA
    gives up): its answer in work.res (distance, normal, the two witnesses of the cores), the corners in
    work.corners, the witnesses of the shapes in work.wit; returns the separation."""
    tri = work.corners
    for k in range(3):
        tri[0, k], tri[1, k], tri[2, k] = a[k], b[k], c[k]
    res = work.res
    status = penetration_kernel(pa, tri, np.int64(MAX_ITERATIONS), work.gjk, work.poly, work.g, res)
    if status != SEPARATED and status != OVERLAP:
        sat_hull_triangle(pa, tri, n_face, work.toi)
        res[0], nx, ny, nz = -work.toi[0], work.toi[1], work.toi[2], work.toi[3]
        res[1], res[2], res[3] = nx, ny, nz
        top = -np.inf
        for v in range(pa.shape[0]):
            top = max(top, pa[v, 0] * nx + pa[v, 1] * ny + pa[v, 2] * nz)
        for k in range(3):  # a support point of each side: what contact_points falls back on
            res[4 + k] = pa[nearest_support_vertex(pa, pa.shape[0], nx, ny, nz, 1.0, 0.0, pa[0]), k]
            res[7 + k] = tri[nearest_support_vertex(tri, tri.shape[0], nx, ny, nz, -1.0, 0.0, tri[0]), k]
    separation = res[0] - radius
    nx, ny, nz = res[1], res[2], res[3]
    work.wit[0, 0], work.wit[0, 1], work.wit[0, 2] = res[4] + radius * nx, res[5] + radius * ny, res[6] + radius * nz
    work.wit[1, 0], work.wit[1, 1], work.wit[1, 2] = res[7], res[8], res[9]
    return separation


@njit
def convex_triangle(pa, radius, a, b, c, n_face, out, work):
    """The GJK/EPA answer of hull(pa) ((n, 3) core points, swept by ``radius``) against the triangle (a, b, c) as
    a 3-point core, into the TriangleContact ``out``: the penetration chain (``_convex_separation``), then the
    contact features and points of engine.narrowphase.contact_manifold (the body's feature per point at its
    nearest support vertex, as engine.narrowphase.convex_cores). Returns the separation."""
    separation = _convex_separation(pa, radius, a, b, c, n_face, work)
    tri, res = work.corners, work.res
    nx, ny, nz = res[1], res[2], res[3]
    out.separation[0] = separation
    out.normal[0], out.normal[1], out.normal[2] = nx, ny, nz
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
        vertex = nearest_support_vertex(pa, pa.shape[0], nx, ny, nz, 1.0, tol, work.cpts[q])
        out.body_keys[q] = feature_key(ka, vertex)
        out.tri_keys[q] = feature_key(ft, fi)
    return separation


@njit(inline="always")
def _corner_of(vertices, triangles, t, j):
    """Corner j of triangle t as a 3-tuple (no array view per triangle)."""
    i = triangles[t, j]
    return vertices[i, 0], vertices[i, 1], vertices[i, 2]


@njit(inline="always")
def _triangle_of(vertices, triangles, normals, t):
    """Triangle t's corners and unit normal, 3-tuples of scalars."""
    return (_corner_of(vertices, triangles, t, 0), _corner_of(vertices, triangles, t, 1),
            _corner_of(vertices, triangles, t, 2), (normals[t, 0], normals[t, 1], normals[t, 2]))


# What the per-triangle kernels read of body i, by its shape: a round core's ends (3-tuples) and radius; a box's
# centre, rotation, half extents and corners; a hull's points and radius.
@njit(inline="always")
def _round_of(bodies, i):
    m = bodies.count[i] - 1
    p = bodies.points
    return (p[i, 0, 0], p[i, 0, 1], p[i, 0, 2]), (p[i, m, 0], p[i, m, 1], p[i, m, 2]), bodies.radius[i]


@njit(inline="always")
def _box_of(bodies, i):
    return bodies.center[i], bodies.rotation[i], bodies.half[i], bodies.points[i, :bodies.count[i]]


@njit(inline="always")
def _hull_of(bodies, i):
    return bodies.points[i, :bodies.count[i]], bodies.radius[i]


@njit(inline="always")
def _convex_answer(shape, box, hull, vertices, triangles, normals, t, out, work):
    """A box's (box_triangle) or a hull's (convex_triangle) answer against triangle t, into ``out``."""
    a, b, c, n = _triangle_of(vertices, triangles, normals, t)
    if shape == BODY_BOX:
        return box_triangle(box[0], box[1], box[2], a, b, c, n, out, work.scratch)
    return convex_triangle(hull[0], hull[1], a, b, c, n, out, work)


@njit(inline="always")
def _halfway_witnesses(s, out, wit):
    """The witnesses of an answer by points halfway between the surfaces (a round core's one point, a touching
    box's deepest manifold point): that point ∓ s / 2 · normal, into wit (2, 3)."""
    deepest = 0
    for v in range(1, out.count[0]):
        if out.depths[v] > out.depths[deepest]:
            deepest = v
    for k in range(3):
        wit[0, k] = out.points[deepest, k] - 0.5 * s * out.normal[k]
        wit[1, k] = out.points[deepest, k] + 0.5 * s * out.normal[k]


@njit
def _distance_answer(shape, core, box, hull, vertices, triangles, normals, t, out, work):
    """The distance question's answer against triangle t: the contact answer, witnesses in work.wit (the body's,
    the triangle's), and apart the exact distance (a box: GJK's, its SAT giving only a lower bound)."""
    a, b, c, n = _triangle_of(vertices, triangles, normals, t)
    if shape == BODY_ROUND:
        s = round_core_triangle(core[0], core[1], core[2], a, b, c, n, out)
    else:
        s = _convex_answer(shape, box, hull, vertices, triangles, normals, t, out, work)
        if shape == BODY_HULL:
            return s  # convex_triangle wrote GJK's / EPA's witnesses
        if s > 0.0:
            return max(_convex_separation(box[3], 0.0, a, b, c, n, work), SMALLEST_GAP)
    _halfway_witnesses(s, out, work.wit)
    return s


@njit
def triangle_answer(bodies, shape, body, mesh, t, out, work):
    """Body ``body`` of the store ``bodies`` (engine.world.bodies.BodyArrays; ``shape`` BODY_ROUND / BOX / HULL)
    against triangle t of ``mesh``, into the TriangleContact ``out`` (before the active-edge fix); returns the
    separation: a round core's closed form (round_core_triangle), a box's 13-axis SAT and clipped manifold
    (engine.narrowphase.box_triangle: apart, a lower bound of the distance), a hull's GJK/EPA
    (``convex_triangle``)."""
    v, tr, nr = mesh.vertices, mesh.triangles, mesh.normals
    if shape == BODY_ROUND:
        core = _round_of(bodies, body)
        a, b, c, n = _triangle_of(v, tr, nr, t)
        return round_core_triangle(core[0], core[1], core[2], a, b, c, n, out)
    return _convex_answer(shape, _box_of(bodies, body), _hull_of(bodies, body), v, tr, nr, t, out, work)


@njit
def triangle_distance(bodies, shape, body, mesh, t, out, work):
    """``triangle_answer`` as the distance question takes it: apart, the exact distance (a box's by GJK);
    witnesses in work.wit[0] (the body's) and work.wit[1] (the triangle's)."""
    return _distance_answer(shape, _round_of(bodies, body), _box_of(bodies, body), _hull_of(bodies, body),
                            mesh.vertices, mesh.triangles, mesh.normals, t, out, work)


@njit(inline="always")
def _edge_inactive(active, t, ft, fi):
    if ft == EDGE:
        return not active[t, fi]
    if ft == VERTEX:
        return not active[t, VERTEX_EDGES[fi, 0]] and not active[t, VERTEX_EDGES[fi, 1]]
    return False


@njit(inline="always")
def _fixed_normal(active, normals, t, ft, fi, nx, ny, nz):
    """Jolt's ActiveEdges::FixNormal: the normal n of triangle t's answer touching at feature (ft, fi) — the face
    normal in n's hemisphere (+ the face normal when they are perpendicular) where that feature is an inactive
    edge or a corner whose two edges are inactive, else n."""
    if not _edge_inactive(active, t, ft, fi):
        return nx, ny, nz
    fx, fy, fz = normals[t, 0], normals[t, 1], normals[t, 2]
    sign = -1.0 if fx * nx + fy * ny + fz * nz < 0.0 else 1.0
    return sign * fx, sign * fy, sign * fz


@njit
def fix_normal(mesh, t, out):
    """``_fixed_normal`` (Jolt's ActiveEdges::FixNormal) on triangle t's answer ``out``."""
    out.normal[0], out.normal[1], out.normal[2] = _fixed_normal(mesh.active, mesh.normals, t, out.tri_feature[0],
                                                                out.tri_feature[1], out.normal[0], out.normal[1],
                                                                out.normal[2])


@njit(inline="always")
def _surface_key(triangles, t, key):
    kind = key >> 20
    local = key & _INDEX_MASK
    if kind == FACE:
        index = np.int64(t)
    elif kind == EDGE:
        index = 3 * np.int64(t) + local
    else:
        index = triangles[t, local]
    return feature_key(kind, index & _INDEX_MASK)


@njit
def surface_key(mesh, t, key):
    """Triangle t's local feature key in the surface's numbering (module docstring)."""
    return _surface_key(mesh.triangles, t, key)


@njit(inline="always")
def _candidates(mesh, bodies, body, work, cand):
    return candidate_triangles(mesh, bodies.lo[body], bodies.hi[body], work.stack, cand)


# -- the batched questions ----------------------------------------------------------------------------------------
@njit
def _round_touches(vertices, triangles, normals, core, cand, count):
    """Whether the round core (``_round_of``) touches some candidate triangle cand[:count]."""
    for x in range(count):
        a, b, c, n = _triangle_of(vertices, triangles, normals, cand[x])
        if round_core_answer(core[0], core[1], core[2], a, b, c, n)[0] <= 0.0:
            return True
    return False


@njit
def _convex_touches(shape, box, hull, vertices, triangles, normals, cand, count, out, work):
    """Whether the box or hull touches some candidate triangle cand[:count]."""
    for x in range(count):
        if _convex_answer(shape, box, hull, vertices, triangles, normals, cand[x], out, work) <= 0.0:
            return True
    return False


@njit
def mesh_overlap_rows(mesh, bodies, shape, body, at, flip, rows, work):
    """The overlap question for the pairs at rows ``at`` (k,) of ``rows`` (ContactRows), body ``body[q]`` (k,) of
    shape ``shape[q]`` against this surface: TOUCHING at the first candidate triangle at separation <= 0."""
    cand = work.cand
    v, tr, nr = mesh.vertices, mesh.triangles, mesh.normals
    for q in range(at.shape[0]):
        p, i = at[q], body[q]
        cand, count = _candidates(mesh, bodies, i, work, cand)
        if shape[q] == BODY_ROUND:
            hit = _round_touches(v, tr, nr, _round_of(bodies, i), cand, count)
        else:
            hit = _convex_touches(shape[q], _box_of(bodies, i), _hull_of(bodies, i), v, tr, nr, cand, count,
                                  work.tri, work)
        rows.status[p] = TOUCHING if hit else APART


@njit(inline="always")
def _insert_point(pts, deep, ids, n, x, y, z, d, key):
    """Insert the point (x, y, z) of depth d and id key among the n points sorted deepest first (after its equals:
    the triangle order breaks ties)."""
    j = n
    while j > 0 and d > deep[j - 1]:
        pts[j, 0], pts[j, 1], pts[j, 2] = pts[j - 1, 0], pts[j - 1, 1], pts[j - 1, 2]
        deep[j], ids[j] = deep[j - 1], ids[j - 1]
        j -= 1
    pts[j, 0], pts[j, 1], pts[j, 2] = x, y, z
    deep[j], ids[j] = d, key


@njit
def _merge_round(vertices, triangles, normals, active, core, cand, count, pts, deep, ids):
    """The merged contact of the round core (``_round_of``) over the candidate triangles cand[:count] (module
    docstring): (separation, normal, body feature, triangle feature type, points count); the points in pts, deep,
    ids, deepest first."""
    best, n = np.inf, np.int64(0)
    nx = ny = nz = 0.0
    fa = fb = np.int64(0)
    for x in range(count):
        t = cand[x]
        a, b, c, nf = _triangle_of(vertices, triangles, normals, t)
        s, mx, my, mz, ft, fi, key, px, py, pz = round_core_answer(core[0], core[1], core[2], a, b, c, nf)
        if s < best:
            best = s
            nx, ny, nz = _fixed_normal(active, normals, t, ft, fi, mx, my, mz)
            fa, fb = key_kind(key), ft
        if s <= 0.0:
            _insert_point(pts, deep, ids, n, px, py, pz, max(-s, 0.0),
                          point_id(key, _surface_key(triangles, t, feature_key(ft, fi))))
            n += 1
    return best, nx, ny, nz, fa, fb, n


@njit(inline="always")
def _take_answer(s, t, tri, triangles, normals, active, best, nx, ny, nz, fa, fb, n, pts, deep, ids):
    """Merge triangle t's answer ``tri`` (separation s) into the pair's: the deepest triangle's normal (active-edge
    fixed) and features, every touching triangle's points (``_merge_round``)."""
    if s < best:
        best = s
        nx, ny, nz = _fixed_normal(active, normals, t, tri.tri_feature[0], tri.tri_feature[1], tri.normal[0],
                                   tri.normal[1], tri.normal[2])
        fa, fb = tri.body_feature[0], tri.tri_feature[0]
    if s <= 0.0:
        for v in range(tri.count[0]):
            _insert_point(pts, deep, ids, n, tri.points[v, 0], tri.points[v, 1], tri.points[v, 2], tri.depths[v],
                          point_id(tri.body_keys[v], _surface_key(triangles, t, tri.tri_keys[v])))
            n += 1
    return best, nx, ny, nz, fa, fb, n


@njit
def _merge_box(box, vertices, triangles, normals, active, cand, count, tri, scratch, pts, deep, ids):
    """``_merge_round`` for a box (``_box_of``): box_triangle's answers, each in tri."""
    best, nx, ny, nz, fa, fb, n = np.inf, 0.0, 0.0, 0.0, np.int64(0), np.int64(0), np.int64(0)
    for x in range(count):
        t = cand[x]
        a, b, c, nf = _triangle_of(vertices, triangles, normals, t)
        s = box_triangle(box[0], box[1], box[2], a, b, c, nf, tri, scratch)
        best, nx, ny, nz, fa, fb, n = _take_answer(s, t, tri, triangles, normals, active, best, nx, ny, nz, fa, fb,
                                                   n, pts, deep, ids)
    return best, nx, ny, nz, fa, fb, n


@njit
def _merge_hull(hull, vertices, triangles, normals, active, cand, count, tri, work, pts, deep, ids):
    """``_merge_round`` for a hull (``_hull_of``): convex_triangle's answers, each in tri."""
    best, nx, ny, nz, fa, fb, n = np.inf, 0.0, 0.0, 0.0, np.int64(0), np.int64(0), np.int64(0)
    for x in range(count):
        t = cand[x]
        a, b, c, nf = _triangle_of(vertices, triangles, normals, t)
        s = convex_triangle(hull[0], hull[1], a, b, c, nf, tri, work)
        best, nx, ny, nz, fa, fb, n = _take_answer(s, t, tri, triangles, normals, active, best, nx, ny, nz, fa, fb,
                                                   n, pts, deep, ids)
    return best, nx, ny, nz, fa, fb, n


@njit
def mesh_contact_rows(mesh, bodies, shape, body, at, flip, rows, work):
    """The contact question for the pairs at rows ``at`` (k,) of ``rows`` (ContactRows), body ``body[q]`` of
    shape ``shape[q]`` against this surface, ``flip[q]``: the pair's first shape is the surface (module
    docstring: the merge)."""
    cand, pts, deep, ids = work.cand, work.pts, work.deep, work.ids
    v, tr, nr, act = mesh.vertices, mesh.triangles, mesh.normals, mesh.active
    for q in range(at.shape[0]):
        p, i = at[q], body[q]
        cand, count = _candidates(mesh, bodies, i, work, cand)
        if count * MAX_TRIANGLE_POINTS > pts.shape[0]:
            size = 2 * count * MAX_TRIANGLE_POINTS
            pts, deep, ids = np.empty((size, 3)), np.empty(size), np.empty(size, np.int64)
        if shape[q] == BODY_ROUND:
            merged = _merge_round(v, tr, nr, act, _round_of(bodies, i), cand, count, pts, deep, ids)
        elif shape[q] == BODY_BOX:
            merged = _merge_box(_box_of(bodies, i), v, tr, nr, act, cand, count, work.tri, work.scratch, pts, deep,
                                ids)
        else:
            merged = _merge_hull(_hull_of(bodies, i), v, tr, nr, act, cand, count, work.tri, work, pts, deep, ids)
        best, nx, ny, nz, fa, fb, n = merged
        n = reduce_manifold(pts, deep, ids, n, nx, ny, nz, work.scratch)
        write_pair(rows, p, best, nx, ny, nz, fa, fb, n, flip[q])
        for m in range(n):
            for k in range(3):
                rows.points[p, m, k] = pts[m, k]
            rows.ids[p, m] = swap_point_id(ids[m]) if flip[q] else ids[m]


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
def _surface_box(mesh):
    """The AABB of the surface's vertices: (lo (3,), hi (3,))."""
    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
    for v in range(mesh.vertices.shape[0]):
        for k in range(3):
            lo[k], hi[k] = min(lo[k], mesh.vertices[v, k]), max(hi[k], mesh.vertices[v, k])
    return lo, hi


@njit
def _nearest(mesh, shape, core, box, hull, radius, lo, hi, reach, work, cand, best_w, best, best_t, nx, ny, nz):
    """The nearest triangle to the body (``_round_of``, …; its box [lo, hi]) among those whose
    AABBs meet [lo − reach[0], hi + reach[0]], skipping, once best > 0, any whose box distance exceeds best + radius
    + reach[1] (round-off): it cannot be nearer (its core is that far, or it would touch and meet the box).
    Ties: the lowest triangle id. Returns (best, best_t, normal, cand)."""
    g = reach[0]
    glo = np.empty(3)
    ghi = np.empty(3)
    for k in range(3):
        glo[k], ghi[k] = lo[k] - g, hi[k] + g
    cand, count = candidate_triangles(mesh, glo, ghi, work.stack, cand)
    tri = work.tri
    for x in range(count):
        t = cand[x]
        if t == best_t or (best > 0.0 and _box_gap(lo, hi, mesh, t) > best + radius + reach[1]):
            continue
        s = _distance_answer(shape, core, box, hull, mesh.vertices, mesh.triangles, mesh.normals, t, tri, work)
        if s < best or (s == best and t < best_t):
            best, best_t, nx, ny, nz = s, t, tri.normal[0], tri.normal[1], tri.normal[2]
            best_w[:] = work.wit
    return best, best_t, nx, ny, nz, cand


@njit
def _nearest_triangle(mesh, shape, core, box, hull, radius, lo, hi, s_lo, s_hi, reach, work, cand, best_w):
    """The signed distance of the body (``_round_of``, …; radius, box [lo, hi]) to the surface
    (its box [s_lo, s_hi]; reach (2,) scratch): (distance, normal, candidates); witnesses in best_w."""
    big, size = 0.0, 0.0
    for k in range(3):
        big = max(big, abs(lo[k]), abs(hi[k]), abs(s_lo[k]), abs(s_hi[k]))
        size = max(size, hi[k] - lo[k])
    reach[0], reach[1] = 0.0, 1e-12 * big  # a touching triangle meets the body's box
    best, best_t, bx, by, bz, cand = _nearest(mesh, shape, core, box, hull, radius, lo, hi, reach, work, cand,
                                              best_w, np.inf, np.int64(-1), 1.0, 0.0, 0.0)
    if best <= 0.0:
        return best, bx, by, bz, cand
    reach[0] = max(size, 1e-300)  # apart: the nearest triangle, in boxes grown until they hold every nearer one
    while True:
        best, best_t, bx, by, bz, cand = _nearest(mesh, shape, core, box, hull, radius, lo, hi, reach, work,
                                                  cand, best_w, best, best_t, bx, by, bz)
        whole = True
        for k in range(3):
            whole = whole and lo[k] - reach[0] <= s_lo[k] and hi[k] + reach[0] >= s_hi[k]
        if whole or reach[0] > best + radius + reach[1]:  # a triangle outside is farther than reach
            break
        reach[0] = 2.0 * reach[0] if best == np.inf else max(2.0 * reach[0], best + radius + 2.0 * reach[1])
    return max(best, SMALLEST_GAP), bx, by, bz, cand  # no candidate touches: apart, as the overlap question says


@njit
def mesh_distance_rows(mesh, bodies, shape, body, at, flip, out, work):
    """The distance question (DistanceRows ``out``, rows ``at``) for body ``body[q]`` against this surface: the
    signed distance to the nearest triangle and its witnesses (module docstring)."""
    best_w = np.empty((2, 3))
    cand = work.cand
    s_lo, s_hi = _surface_box(mesh)
    reach = np.zeros(2)
    for q in range(at.shape[0]):
        p, i = at[q], body[q]
        lo, hi, r = bodies.lo[i], bodies.hi[i], bodies.radius[i]
        found = _nearest_triangle(mesh, shape[q], _round_of(bodies, i), _box_of(bodies, i), _hull_of(bodies, i), r,
                                  lo, hi, s_lo, s_hi, reach, work, cand, best_w)
        best, bx, by, bz, cand = found
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
        pa = bodies.points[i, :bodies.count[i]]
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
