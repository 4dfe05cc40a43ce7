"""EPA: penetration depth and normal of two overlapping convex hulls (the narrow phase's "how deep").

When GJK finds the origin inside the Minkowski difference M = A − B, the penetration depth is the distance from
the origin to the boundary of M, and the normal is the outward normal of M's face that realises it. The
Expanding Polytope Algorithm grows a polytope P ⊂ M that contains the origin until its face closest to the
origin is a face of M:

    P <- the tetrahedron of GJK's last simplex (origin inside)       (_initial_polytope)
    loop:                                                            (_expand_polytope)
        f <- face of P closest to the origin, at distance d along its outward unit normal n
        w <- s_M(n) = s_A(n) − s_B(−n)
        if n·w − d <= eps: return (d, n)          (f lies on the boundary of M)
        remove every face of P that sees w, and join w to the horizon (the silhouette) edges
                                                  (engine.bounding.horizon, shared with quickhull)
    witness points: the origin's projection on f, in barycentric coordinates applied to A and B  (_face_witnesses)

Van den Bergen, *Collision Detection in Interactive 3D Environments*, section 4.3.3; Ericson, *Real-Time
Collision Detection*, section 9.5 (remarks on penetration depth). Moving B by ``depth * normal`` (or A by
``-depth * normal``) brings the hulls into touching contact: the normal points from A towards B.

Kernels (public within the package): ``epa_polytope`` (the one allocation of EPA's storage, ``Polytope``) and
``epa_kernel``. The public functions ``epa_penetration`` / ``epa_penetration_pairs`` (GJK, then this, with the
exact fallback and the rescaling) are in engine.narrowphase.penetration. ``trace_epa`` records the polytope of
every iteration (``EPAStep``), for pictures of EPA converging.
"""
from __future__ import annotations

import math
from collections import namedtuple

import numpy as np

from .._config import njit
from .._validate import as_float_array, as_max_iterations
from ..bounding.horizon import link_neighbours, stitch_cone, visible_faces_and_horizon
from .gjk import MAX_ITERATIONS, gjk_kernel, gjk_scratch
from .rescale import largest_coordinate, rescale_unit
from .status import EPA_NOT_CONVERGED, OVERLAP, raise_for_status
from .support import support_minkowski
from .touching_normal import touching_normal_at_vertex, unit_vector

__all__ = ["EPA_TOL", "MAX_VERTS", "MAX_FACES", "Polytope", "epa_polytope", "epa_kernel", "EPAStep", "trace_epa"]

#: EPA stops when the support point beyond the closest face is within EPA_TOL × size(M) of it
EPA_TOL = 1e-10
#: room for the expanding polytope (vertices, faces); exceeding it is reported as non-convergence
MAX_VERTS = 256
MAX_FACES = 1024

#: EPA's polytope (see ``epa_polytope``)
Polytope = namedtuple("Polytope", ["V", "VA", "VB", "F", "fadj", "N", "D", "alive", "stamp", "stack", "visible",
                                   "horizon", "new_faces", "start_face", "end_face"])


@njit
def epa_polytope():
    """EPA's storage, allocated here and nowhere else (reusable from one pair to the next): vertices ``V``
    (MAX_VERTS, 3) float64 (points of M) with their rows ``VA``, ``VB`` (MAX_VERTS,) int64 in A and B; faces in
    the mesh layout of engine.bounding.horizon — ``F`` (MAX_FACES, 3) int64, ``fadj`` (MAX_FACES, 3) int64, unit
    normals ``N`` (MAX_FACES, 3), offsets ``D`` (MAX_FACES,), ``alive`` (MAX_FACES,) bool, ``stamp`` — and the
    flood fill's scratch (``stack``, ``visible``, ``horizon`` (3 MAX_FACES, 3), ``new_faces``, ``start_face``,
    ``end_face``)."""
    return Polytope(np.empty((MAX_VERTS, 3)), np.empty(MAX_VERTS, np.int64), np.empty(MAX_VERTS, np.int64),
                    np.empty((MAX_FACES, 3), np.int64), np.empty((MAX_FACES, 3), np.int64),
                    np.empty((MAX_FACES, 3)), np.empty(MAX_FACES), np.zeros(MAX_FACES, np.bool_),
                    np.full(MAX_FACES, -1, np.int64), np.empty(MAX_FACES, np.int64), np.empty(MAX_FACES, np.int64),
                    np.empty((3 * MAX_FACES, 3), np.int64), np.empty(MAX_FACES, np.int64),
                    np.full(MAX_VERTS, -1, np.int64), np.full(MAX_VERTS, -1, np.int64))


@njit
def _face_plane(V, F, N, D, f, ox, oy, oz, orient):
    """Unit normal and offset of face f = (V[F[f,0]], V[F[f,1]], V[F[f,2]]).

    With ``orient`` the winding is flipped if needed so that the normal points away from the interior point o
    (the initial polytope); faces made from the horizon keep the winding of the faces they replace, which keeps
    the mesh consistent even where round-off would tilt the normal.
    """
    a = F[f, 0]
    b = F[f, 1]
    c = F[f, 2]
    e1x, e1y, e1z = V[b, 0] - V[a, 0], V[b, 1] - V[a, 1], V[b, 2] - V[a, 2]
    e2x, e2y, e2z = V[c, 0] - V[a, 0], V[c, 1] - V[a, 1], V[c, 2] - V[a, 2]
    nx = e1y * e2z - e1z * e2y
    ny = e1z * e2x - e1x * e2z
    nz = e1x * e2y - e1y * e2x
    length = math.sqrt(nx * nx + ny * ny + nz * nz)
    e1 = math.sqrt(e1x * e1x + e1y * e1y + e1z * e1z)
    e2 = math.sqrt(e2x * e2x + e2y * e2y + e2z * e2z)
    if not length > 1e-12 * e1 * e2:
        # a zero-area sliver (w collinear with a horizon edge): kept in the mesh so that it stays closed, never
        # chosen as the closest face (offset +inf), and removed as soon as the flood fill reaches it
        N[f, 0] = 0.0
        N[f, 1] = 0.0
        N[f, 2] = 0.0
        D[f] = np.inf
        return False
    nx /= length
    ny /= length
    nz /= length
    if orient and (V[a, 0] - ox) * nx + (V[a, 1] - oy) * ny + (V[a, 2] - oz) * nz < 0.0:
        # flip the winding so that the normal points away from the interior point o
        F[f, 1] = c
        F[f, 2] = b
        nx, ny, nz = -nx, -ny, -nz
    N[f, 0] = nx
    N[f, 1] = ny
    N[f, 2] = nz
    D[f] = V[a, 0] * nx + V[a, 1] * ny + V[a, 2] * nz
    return True


@njit(inline="always")  # five stores, at sites with constant slots: no kernel of its own per constant
def _put_vertex(V, VA, VB, k, ia, ib, wx, wy, wz):
    V[k, 0] = wx
    V[k, 1] = wy
    V[k, 2] = wz
    VA[k] = ia
    VB[k] = ib


@njit
def _blow_up_segment(pa, pb, V, VA, VB, size2):
    """The origin lies on the segment V[0]V[1]: add the support point of M farther along ±d, d a unit direction
    orthogonal to the segment (crossed with the coordinate axis least aligned with it). Returns (nv, d): nv = 3,
    or −2 when M has no extent along d on either side (touching; d is the touching plane's normal)."""
    sx, sy, sz = V[1, 0] - V[0, 0], V[1, 1] - V[0, 1], V[1, 2] - V[0, 2]
    if abs(sx) <= abs(sy) and abs(sx) <= abs(sz):
        dx, dy, dz = 0.0, -sz, sy
    elif abs(sy) <= abs(sz):
        dx, dy, dz = sz, 0.0, -sx
    else:
        dx, dy, dz = -sy, sx, 0.0
    # a unit d (rescaled before squaring): best = max ±w·d below is then a length, comparable with EPA_TOL · size
    # at any scale; with |d| ~ |segment| it would scale as a length squared (an area), which for tiny shapes falls
    # below EPA_TOL · size and would call a solid M flat
    dx, dy, dz, _ = unit_vector(dx, dy, dz)
    best = -1.0
    for sgn in (1.0, -1.0):
        ia, ib, wx, wy, wz = support_minkowski(pa, pb, sgn * dx, sgn * dy, sgn * dz)
        h = sgn * (wx * dx + wy * dy + wz * dz)
        if h > best:
            best = h
            _put_vertex(V, VA, VB, 2, ia, ib, wx, wy, wz)
    if best <= EPA_TOL * math.sqrt(size2):
        return -2, dx, dy, dz
    return 3, dx, dy, dz


@njit
def _blow_up_triangle(pa, pb, V, VA, VB, size2):
    """The origin lies in the triangle V[0]V[1]V[2]. If M does not extend beyond its plane on one side, the origin
    is on M's boundary: returns −1 (touching). Else adds the support point along the triangle's normal n as apex
    V[3] and returns 4: the tetrahedron holds the origin on its base, which EPA copes with (that face has
    distance 0 and is expanded first; a bipyramid would hold it inside, but is not convex when the apexes are
    offset)."""
    e1x, e1y, e1z = V[1, 0] - V[0, 0], V[1, 1] - V[0, 1], V[1, 2] - V[0, 2]
    e2x, e2y, e2z = V[2, 0] - V[0, 0], V[2, 1] - V[0, 1], V[2, 2] - V[0, 2]
    nx = e1y * e2z - e1z * e2y
    ny = e1z * e2x - e1x * e2z
    nz = e1x * e2y - e1y * e2x
    ia, ib, ux, uy, uz = support_minkowski(pa, pb, nx, ny, nz)
    _, _, lx, ly, lz = support_minkowski(pa, pb, -nx, -ny, -nz)
    length = math.sqrt(nx * nx + ny * ny + nz * nz)
    h_up = (ux * nx + uy * ny + uz * nz) / max(length, 1e-300)
    h_down = -(lx * nx + ly * ny + lz * nz) / max(length, 1e-300)
    tol = EPA_TOL * math.sqrt(size2)
    if length == 0.0 or h_up <= tol or h_down <= tol:
        return -1
    _put_vertex(V, VA, VB, 3, ia, ib, ux, uy, uz)
    return 4


@njit
def _initial_polytope(pa, pb, W, IA, IB, n_simplex, V, VA, VB, F):
    """GJK's final simplex (W (4, 3), rows IA, IB (4,), n_simplex points, the origin on or in it) blown up into a
    tetrahedron of points of M. Returns (nv, size², d): nv = 4 (faces 0–3 set), or a touching case — 1 (the origin
    is a vertex of M), −1 (on a flat triangle's plane), −2 (M flat across a segment, d its normal)."""
    size2 = 0.0
    for k in range(n_simplex):
        _put_vertex(V, VA, VB, k, IA[k], IB[k], W[k, 0], W[k, 1], W[k, 2])
        size2 = max(size2, W[k, 0] ** 2 + W[k, 1] ** 2 + W[k, 2] ** 2)
    nv = n_simplex
    dx, dy, dz = 0.0, 0.0, 0.0
    if nv == 2:
        nv, dx, dy, dz = _blow_up_segment(pa, pb, V, VA, VB, size2)
    if nv == 3:
        nv = _blow_up_triangle(pa, pb, V, VA, VB, size2)
    if nv == 4:
        tris = ((0, 1, 2), (0, 3, 1), (0, 2, 3), (1, 3, 2))
        for f in range(4):
            F[f, 0] = tris[f][0]
            F[f, 1] = tris[f][1]
            F[f, 2] = tris[f][2]
    return nv, size2, dx, dy, dz


@njit
def _touching_answer(pa, pb, V, VA, VB, nv, size2, dx, dy, dz, out):
    """Depth 0 for the touching cases of ``_initial_polytope``, with the touching plane's normal, and the common
    point of the simplex, on A and on B (``_touching_witnesses``) as the witnesses."""
    out[0] = 0.0
    out[1], out[2], out[3] = 1.0, 0.0, 0.0
    if nv == 1:
        # the origin is a vertex of M (GJK's one-point simplex): any direction of M's normal cone there
        nx1, ny1, nz1, found = touching_normal_at_vertex(pa, pb, EPA_TOL, pa[VA[0], 0], pa[VA[0], 1], pa[VA[0], 2])
        if found:
            out[1], out[2], out[3] = nx1, ny1, nz1
    if nv == -2:
        # M lies in a plane (or on a line) containing the segment and orthogonal to d: moving along d by any
        # amount separates the cores, so d — not a direction inside M — is the minimum translation
        length = math.sqrt(dx * dx + dy * dy + dz * dz)
        if length > 0.0:
            out[1], out[2], out[3] = dx / length, dy / length, dz / length
    if nv == -1:
        # the triangle's plane: on the side along which M does not extend
        e1x, e1y, e1z = V[1, 0] - V[0, 0], V[1, 1] - V[0, 1], V[1, 2] - V[0, 2]
        e2x, e2y, e2z = V[2, 0] - V[0, 0], V[2, 1] - V[0, 1], V[2, 2] - V[0, 2]
        nx = e1y * e2z - e1z * e2y
        ny = e1z * e2x - e1x * e2z
        nz = e1x * e2y - e1y * e2x
        length = math.sqrt(nx * nx + ny * ny + nz * nz)
        if length > 0.0:
            _, _, wx, wy, wz = support_minkowski(pa, pb, nx, ny, nz)
            h = wx * nx + wy * ny + wz * nz
            s = 1.0 if h <= EPA_TOL * math.sqrt(size2) * length else -1.0
            out[1], out[2], out[3] = s * nx / length, s * ny / length, s * nz / length
    _touching_witnesses(pa, pb, V, VA, VB, 1 if nv == 1 else (2 if nv == -2 else 3), out)


@njit
def _touching_witnesses(pa, pb, V, VA, VB, m, out):
    """The witnesses of a touching case: the origin's barycentric weights μ in the simplex V[0:m] (m = 1, 2, 3;
    Ericson 5.1.2 and 5.1.5 for its projection on the segment or the triangle, weights clamped to [0, 1]) applied
    to A's vertices VA and to B's vertices VB: out[4:7] = Σ μ_k a_k lies on A, out[7:10] = Σ μ_k b_k on B, and
    their difference Σ μ_k V_k is the origin's distance to the simplex (0 to round-off)."""
    mu1, mu2 = 0.0, 0.0
    if m == 2:
        ex, ey, ez = V[1, 0] - V[0, 0], V[1, 1] - V[0, 1], V[1, 2] - V[0, 2]
        ee = ex * ex + ey * ey + ez * ez
        if ee > 0.0:
            mu1 = min(max(-(V[0, 0] * ex + V[0, 1] * ey + V[0, 2] * ez) / ee, 0.0), 1.0)
    if m == 3:
        # normal equations of min |V0 + μ1 e1 + μ2 e2|: [e1·e1 e1·e2; e1·e2 e2·e2] μ = −[e1·V0; e2·V0]
        e1 = (V[1, 0] - V[0, 0], V[1, 1] - V[0, 1], V[1, 2] - V[0, 2])
        e2 = (V[2, 0] - V[0, 0], V[2, 1] - V[0, 1], V[2, 2] - V[0, 2])
        g11 = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]
        g12 = e1[0] * e2[0] + e1[1] * e2[1] + e1[2] * e2[2]
        g22 = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2]
        r1 = -(e1[0] * V[0, 0] + e1[1] * V[0, 1] + e1[2] * V[0, 2])
        r2 = -(e2[0] * V[0, 0] + e2[1] * V[0, 1] + e2[2] * V[0, 2])
        det = g11 * g22 - g12 * g12
        if det > 0.0:
            mu1 = min(max((r1 * g22 - r2 * g12) / det, 0.0), 1.0)
            mu2 = min(max((r2 * g11 - r1 * g12) / det, 0.0), 1.0 - mu1)
    mu = (1.0 - mu1 - mu2, mu1, mu2)
    for c in range(3):
        out[4 + c] = 0.0
        out[7 + c] = 0.0
        for k in range(m):  # only the m vertices set: VA[k], VB[k] beyond them are stale
            out[4 + c] += mu[k] * pa[VA[k], c]
            out[7 + c] += mu[k] * pb[VB[k], c]


@njit
def _expand_polytope(pa, pb, poly, nv, size2, max_iter):
    """EPA's loop (van den Bergen 4.3.3) on the tetrahedron V[0:4], faces 0–3. Returns (status, closest face,
    number of faces):
    OVERLAP when the closest face lies on M's boundary, else EPA_NOT_CONVERGED (iteration cap, storage, a face
    folded inwards or a horizon that is not one loop: round-off has broken the polytope)."""
    V, VA, VB, F, fadj, N, D, alive, stamp = poly[:9]
    cx = 0.0  # an interior point, to orient the first faces outwards
    cy = 0.0
    cz = 0.0
    for k in range(nv):
        cx += V[k, 0] / nv
        cy += V[k, 1] / nv
        cz += V[k, 2] / nv
    for f in range(4):
        _face_plane(V, F, N, D, f, cx, cy, cz, True)
        alive[f] = True
        stamp[f] = -1
    link_neighbours(F, 4, fadj)
    closed = True  # every edge has its reversed twin: the orientation above made one consistent mesh
    for k in range(4):
        size2 = max(size2, V[k, 0] ** 2 + V[k, 1] ** 2 + V[k, 2] ** 2)
        closed &= fadj[k, 0] >= 0 and fadj[k, 1] >= 0 and fadj[k, 2] >= 0
    tol = EPA_TOL * math.sqrt(size2)
    n_faces = 4
    for it in range(max_iter):
        best, best_d = -1, np.inf  # the live face of P closest to the origin
        for f in range(n_faces):
            if alive[f] and D[f] < best_d:
                best, best_d = f, D[f]
        if best < 0 or nv >= MAX_VERTS or best_d < -tol:
            break  # out of room, or round-off has folded the polytope (an inward face): give up
        ia, ib, wx, wy, wz = support_minkowski(pa, pb, N[best, 0], N[best, 1], N[best, 2])
        V[nv, 0], V[nv, 1], V[nv, 2], VA[nv], VB[nv] = wx, wy, wz, ia, ib
        if wx * N[best, 0] + wy * N[best, 1] + wz * N[best, 2] - best_d <= tol:
            return OVERLAP, best, n_faces
        if not closed:
            break  # round-off oriented the first faces inconsistently: no horizon to follow
        n_visible, n_horizon = visible_faces_and_horizon(best, wx, wy, wz, 0.0, F, fadj, N, D, stamp, it, poly.stack,
                                                         poly.visible, poly.horizon)
        if n_faces + n_horizon > MAX_FACES:
            break
        for v in range(n_visible):
            alive[poly.visible[v]] = False
        if not stitch_cone(nv, poly.horizon, n_horizon, F, fadj, stamp, n_faces, poly.start_face, poly.end_face,
                           poly.new_faces):
            break
        for f in range(n_faces, n_faces + n_horizon):
            _face_plane(V, F, N, D, f, cx, cy, cz, False)
            alive[f] = True
        n_faces += n_horizon
        nv += 1
    return EPA_NOT_CONVERGED, -1, n_faces


@njit
def _barycentric(V, F, f, px, py, pz):
    """Barycentric weights (la, lb, lc) of the projection of p on the plane of face f (Ericson 3.4)."""
    a, b, c = F[f, 0], F[f, 1], F[f, 2]
    v0 = (V[b, 0] - V[a, 0], V[b, 1] - V[a, 1], V[b, 2] - V[a, 2])
    v1 = (V[c, 0] - V[a, 0], V[c, 1] - V[a, 1], V[c, 2] - V[a, 2])
    v2 = (px - V[a, 0], py - V[a, 1], pz - V[a, 2])
    d00 = v0[0] * v0[0] + v0[1] * v0[1] + v0[2] * v0[2]
    d01 = v0[0] * v1[0] + v0[1] * v1[1] + v0[2] * v1[2]
    d11 = v1[0] * v1[0] + v1[1] * v1[1] + v1[2] * v1[2]
    d20 = v2[0] * v0[0] + v2[1] * v0[1] + v2[2] * v0[2]
    d21 = v2[0] * v1[0] + v2[1] * v1[1] + v2[2] * v1[2]
    den = d00 * d11 - d01 * d01
    if den > 0.0:
        lb = (d11 * d20 - d01 * d21) / den
        lc = (d00 * d21 - d01 * d20) / den
    else:
        lb = 0.0
        lc = 0.0
    return 1.0 - lb - lc, lb, lc


@njit
def _face_witnesses(pa, pb, V, VA, VB, F, N, D, alive, n_faces, best, out):
    """Depth, normal and witness points of the closest face ``best``: the origin's projection p = D n on it, in
    barycentric coordinates of the three vertices of the face that holds p, applied to their rows of A and B.

    p lies on P's boundary (the ball of radius D about the origin is inside P and touches its plane at p), so some
    live face in best's plane holds it; when several triangles share that plane, p may lie outside ``best`` itself
    (weights < 0: extrapolated witnesses, outside A and B), hence the face of that plane whose smallest weight is
    the largest."""
    out[0] = max(D[best], 0.0)
    out[1], out[2], out[3] = N[best, 0], N[best, 1], N[best, 2]
    px, py, pz = D[best] * N[best, 0], D[best] * N[best, 1], D[best] * N[best, 2]
    face = best
    la, lb, lc = _barycentric(V, F, best, px, py, pz)
    if min(la, lb, lc) < 0.0:
        reach = 0.0  # the size of best's vertices: the scale of the coplanarity test
        for k in range(3):
            reach = max(reach, abs(V[F[best, k], 0]), abs(V[F[best, k], 1]), abs(V[F[best, k], 2]))
        for f in range(n_faces):
            if not alive[f] or f == best or abs(N[f, 0] * px + N[f, 1] * py + N[f, 2] * pz - D[f]) > EPA_TOL * reach:
                continue
            ma, mb, mc = _barycentric(V, F, f, px, py, pz)
            if min(ma, mb, mc) > min(la, lb, lc):
                face, la, lb, lc = f, ma, mb, mc
    a, b, c = F[face, 0], F[face, 1], F[face, 2]
    for k in range(3):
        out[4 + k] = la * pa[VA[a], k] + lb * pa[VA[b], k] + lc * pa[VA[c], k]
        out[7 + k] = la * pb[VB[a], k] + lb * pb[VB[b], k] + lc * pb[VB[c], k]


@njit
def epa_kernel(pa, pb, W, IA, IB, n_simplex, max_iter, poly, out):
    """EPA between hull(pa) and hull(pb), (n, 3) and (m, 3) float64, from GJK's final simplex (W (4, 3), rows IA,
    IB (4,) int64, ``n_simplex`` points: ``gjk_kernel``'s scratch after an OVERLAP), with ``poly`` from
    ``epa_polytope``. Writes ``out`` (10,): depth, unit normal (A towards B), witness point on A, on B. Returns
    OVERLAP (depth found; 0 for touching hulls) or EPA_NOT_CONVERGED."""
    nv, size2, dx, dy, dz = _initial_polytope(pa, pb, W, IA, IB, n_simplex, poly.V, poly.VA, poly.VB, poly.F)
    if nv <= 1:
        _touching_answer(pa, pb, poly.V, poly.VA, poly.VB, nv, size2, dx, dy, dz, out)
        return OVERLAP
    status, best, n_faces = _expand_polytope(pa, pb, poly, nv, size2, max_iter)
    if status != OVERLAP:
        return EPA_NOT_CONVERGED
    _face_witnesses(pa, pb, poly.V, poly.VA, poly.VB, poly.F, poly.N, poly.D, poly.alive, n_faces, best, out)
    return OVERLAP


#: one polytope of ``trace_epa``
EPAStep = namedtuple("EPAStep", ["vertices", "faces", "closest_face", "distance", "normal", "support"])


def trace_epa(points_a, points_b, *, max_iterations: int = MAX_ITERATIONS):
    """EPA's polytope, iteration by iteration, for the overlapping hulls of ``points_a`` (n, 3) and ``points_b``
    (m, 3): for pictures of EPA converging (``epa_penetration`` is the function that answers).

    Runs ``gjk_kernel``, then ``epa_kernel`` capped at 0, 1, 2, … expansions on a fresh ``Polytope``: the run
    capped at k expansions stops with the very polytope the uncapped run has after k expansions. Returns
    ``(steps, depth, normal)``: one ``EPAStep`` per polytope, the last being the one EPA stops on —
    ``vertices`` (v, 3) float64 (points of M = A − B), ``faces`` (f, 3) int64 (rows of ``vertices``,
    counter-clockwise seen from outside), ``closest_face`` (the row of ``faces`` closest to the origin),
    ``distance`` (its distance to the origin), ``normal`` (3,) (its outward unit normal), ``support`` (3,) (the
    support point of M along that normal: the next vertex, or, at the last step, a point within EPA's tolerance of
    the face's plane) — and EPA's answer, ``depth`` (the last step's distance) and the unit ``normal`` (3,), the
    same as ``epa_penetration``'s. Raises ValueError when the hulls do not overlap, only touch (no polytope to
    expand) or have coordinates outside [2^-160, 2^160] (EPA then runs on rescaled copies); GJKNotConverged, or
    EPANotConverged when EPA gives up (``max_iterations`` expansions, or a polytope broken by round-off, where
    ``epa_penetration`` falls back on the exact hull of M).
    """
    pa = as_float_array(points_a, "points_a", shape=(None, 3), min_rows=1)
    pb = as_float_array(points_b, "points_b", shape=(None, 3), min_rows=1)
    max_iter = as_max_iterations(max_iterations)
    if rescale_unit(largest_coordinate(pa, pb)) != 1.0:
        raise ValueError("points_a and points_b have coordinates outside [2^-160, 2^160]: EPA runs on rescaled "
                         "copies there, which trace_epa does not show")
    scratch, g = gjk_scratch(max(pa.shape[0], pb.shape[0])), np.empty(7)
    status, n_simplex = gjk_kernel(pa, pb, max_iter, scratch, g)
    raise_for_status(status, max_iter)
    if status != OVERLAP:
        raise ValueError("the hulls of points_a and points_b do not overlap: EPA has no polytope to expand")
    steps: list[EPAStep] = []
    out = np.empty(10)
    for cap in range(max_iter + 1):
        poly = epa_polytope()
        if epa_kernel(pa, pb, scratch.W, scratch.IA, scratch.IB, n_simplex, cap, poly, out) == OVERLAP:
            if not steps:
                raise ValueError("the hulls of points_a and points_b only touch: EPA has no polytope to expand")
            return steps, float(out[0]), out[1:4].copy()
        faces = np.flatnonzero(poly.alive)
        best = faces[np.argmin(poly.D[faces])]  # the kernel's choice: the first face of least offset
        _, _, wx, wy, wz = support_minkowski(pa, pb, poly.N[best, 0], poly.N[best, 1], poly.N[best, 2])
        steps.append(EPAStep(poly.V[:4 + cap].copy(), poly.F[faces].copy(), int(np.flatnonzero(faces == best)[0]),
                             float(poly.D[best]), poly.N[best].copy(), np.array([wx, wy, wz])))
    raise_for_status(np.array([EPA_NOT_CONVERGED]), max_iter)
