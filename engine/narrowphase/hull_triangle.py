"""A convex polytope (the hull of its world vertices) against one triangle of a static surface: GJK distance when
apart, EPA depth when they overlap (engine.narrowphase.penetration's chain, the triangle a 3-point core of radius
0: the Minkowski difference of a hull with volume and a flat triangle has volume), then the contact manifold as
the engine's hull–hull contact builds it (engine.narrowphase.contact_manifold.contact_points: each side's support
set along the normal reduced to a vertex, an edge or a face, the two intersected in the contact plane —
Sutherland–Hodgman for a face on a face, Ericson 8.3.4 — and lifted to the mid-plane between the two support
planes).

Accuracy: apart, the separation is GJK's distance (relative error about ``gjk.REL_TOL`` = 1e-12 of the pair's
size); overlapping, EPA's depth (within ``epa.EPA_TOL`` = 1e-10 of the size); touching without a full simplex,
0 and a normal of the Minkowski difference's normal cone. Where GJK or EPA does not converge (round-off on many
coplanar support points), the answer is the exact separating-axis one instead (``sat_hull_triangle``: every
plane through three hull vertices, the triangle's normal, every segment of two hull vertices crossed with every
triangle edge — a superset of the Minkowski difference's face normals, so the least overlap is the exact depth;
O(m⁴) for m vertices, run only then). The contact points lie on the mid-plane, within ``FEATURE_TOL`` × the size
of both support planes: each point's depth is the pair's depth.

Feature keys: the hull's key of a point is (its feature kind, the support vertex nearest to it in the contact
plane), as ``convex_cores.feature_point_ids`` gives the hull–hull contacts; the triangle's key is the triangle's
supporting feature (local numbering: corner v, edge e joining corners e and (e + 1) % 3, face 0), which is also
``tri_feature``; ``body_feature`` is the hull's feature kind.
"""
from __future__ import annotations

import math
from collections import namedtuple

import numpy as np

from .._config import njit
from .box_box import EDGE_AXIS_MIN
from .contact_manifold import FEATURE_TOL, contact_points, feature_scratch
from .contacts import EDGE, FACE, VERTEX, Scratch, feature_key, kernel_scratch, reduce_manifold
from .epa import epa_polytope
from .gjk import MAX_ITERATIONS, gjk_scratch
from .penetration import penetration_kernel
from .status import OVERLAP, SEPARATED
from .triangle_contact import MAX_TRIANGLE_POINTS

__all__ = ["HullTriangleScratch", "hull_triangle_scratch", "hull_triangle", "sat_hull_triangle"]

#: ``hull_triangle``'s work space, allocated once (``hull_triangle_scratch``): every field of contacts.Scratch
#: (so ``box_triangle`` takes it too), then ``gjk`` (gjk.GJKScratch), ``epa`` (epa.Polytope), ``g`` (7,) and
#: ``chain`` (10,) (penetration_kernel's outputs), ``tri`` (3, 3) the triangle's corners, ``feature``
#: (contact_manifold.FeatureScratch) and ``found`` (m + 4, 3) the contact points before reduction
HullTriangleScratch = namedtuple("HullTriangleScratch", Scratch._fields + ("gjk", "epa", "g", "chain", "tri",
                                                                           "feature", "found"))


def hull_triangle_scratch(m: int) -> HullTriangleScratch:
    """The work space of ``hull_triangle`` for hulls of at most m vertices."""
    m = max(int(m), 3)
    return HullTriangleScratch(*kernel_scratch(m + 4), gjk_scratch(m), epa_polytope(), np.empty(7), np.empty(10),
                               np.empty((3, 3)), feature_scratch(m), np.empty((m + 4, 3)))


@njit(inline="always")
def _overlap_along(pa, tri, lx, ly, lz):
    """(overlap, sign) of the hull's and the triangle's projections on L (not unit): min(top_A − low_T,
    top_T − low_A), sign +1 when the first (the triangle on L's side) is the smaller."""
    lo_a, hi_a, lo_t, hi_t = np.inf, -np.inf, np.inf, -np.inf
    for i in range(pa.shape[0]):
        p = pa[i, 0] * lx + pa[i, 1] * ly + pa[i, 2] * lz
        lo_a, hi_a = min(lo_a, p), max(hi_a, p)
    for i in range(3):
        p = tri[i, 0] * lx + tri[i, 1] * ly + tri[i, 2] * lz
        lo_t, hi_t = min(lo_t, p), max(hi_t, p)
    up, down = hi_a - lo_t, hi_t - lo_a
    return (up, 1.0) if up <= down else (down, -1.0)


@njit(inline="always")
def _length(x, y, z):
    return math.sqrt(x * x + y * y + z * z)


@njit
def _consider(pa, tri, lx, ly, lz, scale, best):
    """best (4,) = (signed separation, unit axis): updated with axis L when its gap (> 0 apart) or minus its
    overlap is larger, i.e. the SAT answer max over the axes of −overlap. L is skipped when it is no longer than
    ``EDGE_AXIS_MIN`` × ``scale`` (the product of the lengths it is the cross product of): (nearly) parallel
    vectors, whose normal is round-off; a face keeps a better conditioned triple, parallel edges are covered by
    the faces."""
    length = math.sqrt(lx * lx + ly * ly + lz * lz)
    if not length > EDGE_AXIS_MIN * scale:
        return
    over, s = _overlap_along(pa, tri, lx, ly, lz)
    if -over / length > best[0]:
        best[0], best[1], best[2], best[3] = -over / length, s * lx / length, s * ly / length, s * lz / length


@njit
def sat_hull_triangle(pa, tri, best):
    """The exact separating-axis answer for hull(pa) ((m, 3)) and the triangle tri (3, 3) into best (4,):
    (separation, unit normal from the hull towards the triangle) — −depth when they overlap, else the largest
    gap over the axes (a lower bound of the distance). Axes: the triangle's normal, the normal of every plane
    through three hull vertices, every hull segment × triangle edge (Ericson 5.2.1's candidates, over all the
    vertex sets since the hull's faces are not given)."""
    m = pa.shape[0]
    best[0] = -np.inf
    ux, uy, uz = tri[1, 0] - tri[0, 0], tri[1, 1] - tri[0, 1], tri[1, 2] - tri[0, 2]
    wx, wy, wz = tri[2, 0] - tri[0, 0], tri[2, 1] - tri[0, 1], tri[2, 2] - tri[0, 2]
    _consider(pa, tri, uy * wz - uz * wy, uz * wx - ux * wz, ux * wy - uy * wx, _length(ux, uy, uz)
              * _length(wx, wy, wz), best)
    for i in range(m):
        for j in range(i + 1, m):
            dx, dy, dz = pa[j, 0] - pa[i, 0], pa[j, 1] - pa[i, 1], pa[j, 2] - pa[i, 2]
            for e in range(3):
                fx, fy, fz = (tri[(e + 1) % 3, 0] - tri[e, 0], tri[(e + 1) % 3, 1] - tri[e, 1],
                              tri[(e + 1) % 3, 2] - tri[e, 2])
                _consider(pa, tri, dy * fz - dz * fy, dz * fx - dx * fz, dx * fy - dy * fx,
                          _length(dx, dy, dz) * _length(fx, fy, fz), best)
            for k in range(j + 1, m):
                ex, ey, ez = pa[k, 0] - pa[i, 0], pa[k, 1] - pa[i, 1], pa[k, 2] - pa[i, 2]
                _consider(pa, tri, dy * ez - dz * ey, dz * ex - dx * ez, dx * ey - dy * ex,
                          _length(dx, dy, dz) * _length(ex, ey, ez), best)


@njit
def _support_points(pa, tri, nx, ny, nz, chain):
    """chain[4:7] a vertex of the hull farthest along n, chain[7:10] a corner of the triangle farthest along −n."""
    top, ia = -np.inf, 0
    for i in range(pa.shape[0]):
        p = pa[i, 0] * nx + pa[i, 1] * ny + pa[i, 2] * nz
        if p > top:
            top, ia = p, i
    low, it = np.inf, 0
    for i in range(3):
        p = tri[i, 0] * nx + tri[i, 1] * ny + tri[i, 2] * nz
        if p < low:
            low, it = p, i
    for c in range(3):
        chain[4 + c], chain[7 + c] = pa[ia, c], tri[it, c]


@njit
def _triangle_feature(tri, nx, ny, nz, tol):
    """The triangle's support feature along −n (its corners within tol of the lowest): (kind, local index)."""
    p0 = tri[0, 0] * nx + tri[0, 1] * ny + tri[0, 2] * nz
    p1 = tri[1, 0] * nx + tri[1, 1] * ny + tri[1, 2] * nz
    p2 = tri[2, 0] * nx + tri[2, 1] * ny + tri[2, 2] * nz
    low = min(p0, p1, p2)
    d0, d1, d2 = p0 <= low + tol, p1 <= low + tol, p2 <= low + tol
    deep = d0 + d1 + d2
    if deep == 3:
        return FACE, 0
    if deep == 2:  # edge 0 joins corners 0 and 1, edge 1 corners 1 and 2, edge 2 corners 2 and 0
        return EDGE, (0 if not d2 else (1 if not d0 else 2))
    return VERTEX, (0 if d0 else (1 if d1 else 2))


@njit
def _nearest_support_vertex(pa, nx, ny, nz, tol, x, y, z):
    """The vertex of the hull within tol of its support plane along n nearest to (x, y, z) in the plane ⊥ n."""
    top = -np.inf
    for v in range(pa.shape[0]):
        top = max(top, pa[v, 0] * nx + pa[v, 1] * ny + pa[v, 2] * nz)
    best, pick = np.inf, 0
    for v in range(pa.shape[0]):
        if pa[v, 0] * nx + pa[v, 1] * ny + pa[v, 2] * nz >= top - tol:
            dx, dy, dz = x - pa[v, 0], y - pa[v, 1], z - pa[v, 2]
            along = dx * nx + dy * ny + dz * nz
            off = (dx - along * nx) ** 2 + (dy - along * ny) ** 2 + (dz - along * nz) ** 2
            if off < best:
                best, pick = off, v
    return pick


@njit
def _separation_and_normal(pa, tri, scratch):
    """The penetration chain (GJK → EPA, rescaled) into scratch.chain: (signed distance, normal hull → triangle,
    deepest or closest points); where it does not converge, the exact SAT answer with support points."""
    chain = scratch.chain
    status = penetration_kernel(pa, tri, MAX_ITERATIONS, scratch.gjk, scratch.epa, scratch.g, chain)
    if status != SEPARATED and status != OVERLAP:
        sat_hull_triangle(pa, tri, scratch.vec)
        for c in range(4):
            chain[c] = scratch.vec[c]
        _support_points(pa, tri, chain[1], chain[2], chain[3], chain)


@njit
def _manifold(pa, tri, depth, size, out, scratch):
    """The contact points of a touching pair (normal in scratch.chain[1:4]) into out, with keys and features."""
    chain, pts, deep, ids = scratch.chain, scratch.pts, scratch.deep, scratch.ids
    nx, ny, nz = chain[1], chain[2], chain[3]
    kind_a, _, kept = contact_points(pa, tri, 0.0, 0.0, chain[1:4], chain[4:7], chain[7:10], FEATURE_TOL,
                                     scratch.feature, scratch.found, 0)
    kept = np.int64(kept)
    for i in range(kept):
        for c in range(3):
            pts[i, c] = scratch.found[i, c]
        deep[i], ids[i] = depth, i
    if kept > MAX_TRIANGLE_POINTS:
        kept = reduce_manifold(pts, deep, ids, kept, nx, ny, nz, scratch)
    tol = FEATURE_TOL * size
    kind_t, index_t = _triangle_feature(tri, nx, ny, nz, tol)
    for i in range(kept):
        for c in range(3):
            out.points[i, c] = pts[i, c]
        out.depths[i] = depth
        vertex = _nearest_support_vertex(pa, nx, ny, nz, tol, pts[i, 0], pts[i, 1], pts[i, 2])
        out.body_keys[i] = feature_key(kind_a, vertex)
        out.tri_keys[i] = feature_key(kind_t, index_t)
    out.count[0] = kept
    out.tri_feature[0], out.tri_feature[1], out.body_feature[0] = kind_t, index_t, kind_a


@njit
def _pair_size(pa, tri):
    """The largest extent over the three axes of the hull's vertices and the triangle's corners together."""
    size = 0.0
    for c in range(3):
        lo, hi = min(tri[0, c], tri[1, c], tri[2, c]), max(tri[0, c], tri[1, c], tri[2, c])
        for i in range(pa.shape[0]):
            lo, hi = min(lo, pa[i, c]), max(hi, pa[i, c])
        size = max(size, hi - lo)
    return max(size, 1e-300)


@njit
def hull_triangle(points, count, a, b, c, n_face, out, scratch):
    """The hull of ``points[:count]`` ((m, 3) world vertices, count >= 1; a polytope with volume) against the
    triangle of corners a, b, c (3-tuples; ``n_face``, its unit normal, is not needed: the chain orients the
    normal itself) into ``out`` (triangle_contact.TriangleContact), with ``scratch`` from
    ``hull_triangle_scratch(m)``. Returns the separation (apart: the GJK distance; touching: −depth). See the
    module's docstring for the accuracy."""
    tri = scratch.tri
    for k in range(3):
        tri[0, k], tri[1, k], tri[2, k] = a[k], b[k], c[k]
    pa = points[:count]
    _separation_and_normal(pa, tri, scratch)
    chain = scratch.chain
    out.separation[0] = chain[0]
    out.normal[0], out.normal[1], out.normal[2] = chain[1], chain[2], chain[3]
    out.count[0] = 0
    out.tri_feature[0], out.tri_feature[1], out.body_feature[0] = 0, 0, 0
    if chain[0] <= 0.0:
        _manifold(pa, tri, -chain[0], _pair_size(pa, tri), out, scratch)
    return chain[0]
