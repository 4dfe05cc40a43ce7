"""EPA: penetration depth and normal of two overlapping convex hulls (the narrow phase's "how deep").

When GJK finds the origin inside the Minkowski difference M = A − B, the penetration depth is the distance from
the origin to the boundary of M, and the normal is the outward normal of M's face that realises it. The
Expanding Polytope Algorithm grows a polytope P ⊂ M that contains the origin until its face closest to the
origin is a face of M:

    P <- the tetrahedron of GJK's last simplex (origin inside)
    loop:
        f <- face of P closest to the origin, at distance d along its outward unit normal n
        w <- s_M(n) = s_A(n) − s_B(−n)
        if n·w − d <= eps: return (d, n)          (f lies on the boundary of M)
        remove every face of P that sees w, and join w to the horizon (the silhouette) edges

Where round-off folds the polytope (many coplanar support points, e.g. boxes sharing axes; about 1 pair in
10^4 of such adversarial inputs), the public functions fall back on the exact answer from Qhull on the
Minkowski difference (scipy), so no wrong depth and no error escapes for small shapes.

Van den Bergen, *Collision Detection in Interactive 3D Environments*, section 4.3.3; Ericson, *Real-Time
Collision Detection*, section 9.5 (remarks on penetration depth). Moving B by ``depth * normal`` (or A by
``-depth * normal``) brings the hulls into touching contact: the normal points from A towards B.
"""
from __future__ import annotations

import math

import numpy as np

from .._config import njit
from .._validate import as_float_array, as_max_iterations, check_offsets, check_pairs
from .gjk import (
    _NOT_CONVERGED,
    _OVERLAP,
    MAX_ITERATIONS,
    GJKNotConverged,
    _gjk,
    _support,
    rescale_unit,
)

__all__ = ["EPANotConverged", "epa_penetration", "epa_penetration_pairs", "EPA_TOL"]

#: EPA stops when the support point beyond the closest face is within EPA_TOL × size(M) of it
EPA_TOL = 1e-10
#: room for the expanding polytope (vertices, faces); exceeding it is reported as non-convergence
_MAX_VERTS = 256
_MAX_FACES = 1024

_EPA_OK = 0
_EPA_NOT_CONVERGED = 3
_EPA_SEPARATED = 4


class EPANotConverged(RuntimeError):
    """EPA reached its iteration cap (or its polytope storage) before its stopping test."""


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
        # chosen as the closest face, and removed as soon as the flood fill reaches it
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


@njit
def _support_m(pa, pb, dx, dy, dz, V, VA, VB, nv):
    ia = _support(pa, dx, dy, dz)
    ib = _support(pb, -dx, -dy, -dz)
    V[nv, 0] = pa[ia, 0] - pb[ib, 0]
    V[nv, 1] = pa[ia, 1] - pb[ib, 1]
    V[nv, 2] = pa[ia, 2] - pb[ib, 2]
    VA[nv] = ia
    VB[nv] = ib


#: the normal-cone search (``_normal_cone_direction``) costs (n + m)³: beyond this many points it is skipped
MAX_CONE_POINTS = 200


@njit
def _normal_cone_direction(pa, pb, px, py, pz, tol):
    """A unit n with n·(a − p) <= tol for every row a of A and n·(p − b) <= tol for every row b of B, where p is a
    point common to the two hulls: then max over A of n·a = n·p = min over B of n·b, so n is the normal of a plane
    through p that separates the hulls — a direction of the normal cone of M = A − B at the origin. That cone is
    the polar of the cone spanned by the generators g (every a − p and p − b); its edges are orthogonal to two
    generators, so every ±g_i × g_k is tried and the normalised sum of those that qualify (a direction inside the
    cone) is returned, with found; when they cancel (a cone holding a whole line), −Σ ĝ, else one qualifying edge.
    O((n + m)³)."""
    na = pa.shape[0]
    n = na + pb.shape[0]
    G = np.empty((n, 3))
    for i in range(na):
        G[i, 0], G[i, 1], G[i, 2] = pa[i, 0] - px, pa[i, 1] - py, pa[i, 2] - pz
    for j in range(pb.shape[0]):
        G[na + j, 0], G[na + j, 1], G[na + j, 2] = px - pb[j, 0], py - pb[j, 1], pz - pb[j, 2]
    sx = 0.0
    sy = 0.0
    sz = 0.0
    fx, fy, fz = 1.0, 0.0, 0.0  # the first qualifying edge
    found = False
    for i in range(n):
        for k in range(i + 1, n):
            cx, cy, cz, nonzero = _unit(G[i, 1] * G[k, 2] - G[i, 2] * G[k, 1], G[i, 2] * G[k, 0] - G[i, 0] * G[k, 2],
                                        G[i, 0] * G[k, 1] - G[i, 1] * G[k, 0])
            if not nonzero:
                continue
            for sgn in (1.0, -1.0):
                ok = True
                for j in range(n):
                    if sgn * (cx * G[j, 0] + cy * G[j, 1] + cz * G[j, 2]) > tol:
                        ok = False
                        break
                if ok:
                    sx += sgn * cx
                    sy += sgn * cy
                    sz += sgn * cz
                    if not found:
                        fx, fy, fz = sgn * cx, sgn * cy, sgn * cz
                    found = True
    # the sum of the qualifying edges lies inside the cone, unless they cancel (a cone that holds a whole line,
    # e.g. for two segments: then its edges are ±g_i × g_k and the inside is around −(ĝ_i + ĝ_k))
    if found and _unit_within(G, sx, sy, sz, tol):
        return _unit(sx, sy, sz)
    mx = 0.0
    my = 0.0
    mz = 0.0
    for j in range(n):
        gx, gy, gz, nonzero = _unit(G[j, 0], G[j, 1], G[j, 2])
        if nonzero:
            mx -= gx
            my -= gy
            mz -= gz
    if _unit_within(G, mx, my, mz, tol):
        return _unit(mx, my, mz)
    if found:
        return fx, fy, fz, True
    return 1.0, 0.0, 0.0, False


@njit
def _unit(x, y, z):
    """(x, y, z) / |(x, y, z)|, rescaled before squaring; (1, 0, 0, False) for the zero vector."""
    big = max(abs(x), abs(y), abs(z))
    if big == 0.0:
        return 1.0, 0.0, 0.0, False
    x /= big
    y /= big
    z /= big
    length = math.sqrt(x * x + y * y + z * z)
    return x / length, y / length, z / length, True


@njit
def _unit_within(G, x, y, z, tol):
    """Whether the unit direction of (x, y, z) exists and has n·g <= tol for every row g of G."""
    nx, ny, nz, ok = _unit(x, y, z)
    if not ok:
        return False
    for j in range(G.shape[0]):
        if nx * G[j, 0] + ny * G[j, 1] + nz * G[j, 2] > tol:
            return False
    return True


@njit
def _touching_normal_at_vertex(pa, pb, rel_tol, px, py, pz):
    """The origin is on the boundary of M = A − B, at the common point p of the two hulls (depth 0): a unit
    direction n along which M does not extend, max over M of m·n <= tol (a normal of the touching plane).
    Candidates: the direction from A's centroid to B's, then the six axis directions, then the normal cone of M
    at the origin (``_normal_cone_direction``, for up to MAX_CONE_POINTS points); returns (nx, ny, nz, found).
    ``rel_tol`` is relative to the shapes' size."""
    scale = 0.0
    for i in range(pa.shape[0]):
        for c in range(3):
            scale = max(scale, abs(pa[i, c] - pa[0, c]))
    for i in range(pb.shape[0]):
        for c in range(3):
            scale = max(scale, abs(pb[i, c] - pa[0, c]))
    tol = rel_tol * max(scale, 1e-300)
    cx = 0.0
    cy = 0.0
    cz = 0.0
    for i in range(pb.shape[0]):
        cx += pb[i, 0] / pb.shape[0]
        cy += pb[i, 1] / pb.shape[0]
        cz += pb[i, 2] / pb.shape[0]
    for i in range(pa.shape[0]):
        cx -= pa[i, 0] / pa.shape[0]
        cy -= pa[i, 1] / pa.shape[0]
        cz -= pa[i, 2] / pa.shape[0]
    for k in range(7):
        if k == 0:
            dx, dy, dz = cx, cy, cz
        else:
            dx, dy, dz = 0.0, 0.0, 0.0
            sign = 1.0 if k % 2 == 1 else -1.0
            axis = (k - 1) // 2
            if axis == 0:
                dx = sign
            elif axis == 1:
                dy = sign
            else:
                dz = sign
        dx, dy, dz, nonzero = _unit(dx, dy, dz)  # rescaled first: a tiny (1e-162) direction's squares underflow
        if not nonzero:
            continue
        ia = _support(pa, dx, dy, dz)
        ib = _support(pb, -dx, -dy, -dz)
        h = (pa[ia, 0] - pb[ib, 0]) * dx + (pa[ia, 1] - pb[ib, 1]) * dy + (pa[ia, 2] - pb[ib, 2]) * dz
        if h <= tol:
            return dx, dy, dz, True
    if pa.shape[0] + pb.shape[0] <= MAX_CONE_POINTS:
        return _normal_cone_direction(pa, pb, px, py, pz, tol)
    return 1.0, 0.0, 0.0, False


@njit
def _epa(pa, pb, W, IA, IB, n_simplex, max_iter, out):
    """EPA from GJK's final simplex. Writes depth, normal (3), point on A (3), point on B (3) into ``out``."""
    V = np.empty((_MAX_VERTS, 3))
    VA = np.empty(_MAX_VERTS, np.int64)
    VB = np.empty(_MAX_VERTS, np.int64)
    F = np.empty((_MAX_FACES, 3), np.int64)
    N = np.empty((_MAX_FACES, 3))
    D = np.empty(_MAX_FACES)
    alive = np.zeros(_MAX_FACES, np.bool_)
    size2 = 0.0
    for k in range(n_simplex):
        V[k, 0] = W[k, 0]
        V[k, 1] = W[k, 1]
        V[k, 2] = W[k, 2]
        VA[k] = IA[k]
        VB[k] = IB[k]
        size2 = max(size2, W[k, 0] ** 2 + W[k, 1] ** 2 + W[k, 2] ** 2)
    nv = n_simplex
    dx, dy, dz = 0.0, 0.0, 0.0  # the flat direction of a segment simplex (set below)
    # --- blow a lower-dimensional simplex up into a tetrahedron (the origin lies on the simplex) ---------------
    if nv == 1:
        # the origin is a support point of M, hence on its boundary: touching, depth 0
        nv = 1
    if nv == 2:
        # a direction orthogonal to the segment: cross with the coordinate axis least aligned with it
        sx, sy, sz = V[1, 0] - V[0, 0], V[1, 1] - V[0, 1], V[1, 2] - V[0, 2]
        ax = abs(sx)
        ay = abs(sy)
        az = abs(sz)
        if ax <= ay and ax <= az:
            dx, dy, dz = 0.0, -sz, sy
        elif ay <= az:
            dx, dy, dz = sz, 0.0, -sx
        else:
            dx, dy, dz = -sy, sx, 0.0
        # a unit d (rescaled before squaring): best below is then a length, comparable with EPA_TOL · size at any
        # scale (with |d| ~ |segment| it was an area, and tiny shapes passed for flat)
        dx, dy, dz, _ = _unit(dx, dy, dz)
        best = -1.0
        for sgn in (1.0, -1.0):
            _support_m(pa, pb, sgn * dx, sgn * dy, sgn * dz, V, VA, VB, 2)
            h = sgn * (V[2, 0] * dx + V[2, 1] * dy + V[2, 2] * dz)
            if h > best:
                best = h
                VA[3] = VA[2]
                VB[3] = VB[2]
                V[3, 0], V[3, 1], V[3, 2] = V[2, 0], V[2, 1], V[2, 2]
        V[2, 0], V[2, 1], V[2, 2] = V[3, 0], V[3, 1], V[3, 2]
        VA[2] = VA[3]
        VB[2] = VB[3]
        nv = 3
        if best <= EPA_TOL * math.sqrt(size2):
            nv = -2  # M has no extent along d (either sign): touching, and d is the touching plane's normal
    if nv == 3:
        e1x, e1y, e1z = V[1, 0] - V[0, 0], V[1, 1] - V[0, 1], V[1, 2] - V[0, 2]
        e2x, e2y, e2z = V[2, 0] - V[0, 0], V[2, 1] - V[0, 1], V[2, 2] - V[0, 2]
        nx = e1y * e2z - e1z * e2y
        ny = e1z * e2x - e1x * e2z
        nz = e1x * e2y - e1y * e2x
        # the origin lies in the triangle: if M does not extend beyond its plane on one side, it is on the boundary
        _support_m(pa, pb, nx, ny, nz, V, VA, VB, 3)
        _support_m(pa, pb, -nx, -ny, -nz, V, VA, VB, 4)
        length = math.sqrt(nx * nx + ny * ny + nz * nz)
        h_up = (V[3, 0] * nx + V[3, 1] * ny + V[3, 2] * nz) / max(length, 1e-300)
        h_down = -(V[4, 0] * nx + V[4, 1] * ny + V[4, 2] * nz) / max(length, 1e-300)
        tol = EPA_TOL * math.sqrt(size2)
        if length == 0.0 or h_up <= tol or h_down <= tol:
            nv = -1  # the origin is on M's boundary (or M is flat): touching
        else:
            # M extends on both sides: the tetrahedron (triangle, upper apex) holds the origin on its base; EPA
            # copes with the origin on the boundary (that face has distance 0 and is expanded first). A bipyramid
            # would hold it inside, but is not convex when the apexes are offset.
            nv = 4
    if nv == 4:
        tris = ((0, 1, 2), (0, 3, 1), (0, 2, 3), (1, 3, 2))
        for f in range(4):
            F[f, 0] = tris[f][0]
            F[f, 1] = tris[f][1]
            F[f, 2] = tris[f][2]
    if nv <= 1:
        # touching: depth 0, the normal from the simplex (any unit vector if it is a single point)
        out[0] = 0.0
        out[1], out[2], out[3] = 1.0, 0.0, 0.0
        if nv == 1:
            # the origin is a vertex of M (GJK's one-point simplex): any direction of M's normal cone there
            nx1, ny1, nz1, found = _touching_normal_at_vertex(pa, pb, EPA_TOL, pa[VA[0], 0], pa[VA[0], 1],
                                                                pa[VA[0], 2])
            if found:
                out[1], out[2], out[3] = nx1, ny1, nz1
        if nv == -2:
            # M lies in a plane (or on a line) containing the segment and orthogonal to d: moving along d by any
            # amount separates the cores, so d — not a direction inside M — is the minimum translation
            length = math.sqrt(dx * dx + dy * dy + dz * dz)
            if length > 0.0:
                out[1], out[2], out[3] = dx / length, dy / length, dz / length
        if nv == -1:
            # the touching plane's normal: the lower-dimensional case above found a flat direction
            e1x, e1y, e1z = V[1, 0] - V[0, 0], V[1, 1] - V[0, 1], V[1, 2] - V[0, 2]
            e2x, e2y, e2z = V[2, 0] - V[0, 0], V[2, 1] - V[0, 1], V[2, 2] - V[0, 2]
            nx = e1y * e2z - e1z * e2y
            ny = e1z * e2x - e1x * e2z
            nz = e1x * e2y - e1y * e2x
            length = math.sqrt(nx * nx + ny * ny + nz * nz)
            if length > 0.0:
                # choose the side on which M does not extend
                ia = _support(pa, nx, ny, nz)
                ib = _support(pb, -nx, -ny, -nz)
                h = ((pa[ia, 0] - pb[ib, 0]) * nx + (pa[ia, 1] - pb[ib, 1]) * ny + (pa[ia, 2] - pb[ib, 2]) * nz)
                s = 1.0 if h <= EPA_TOL * math.sqrt(size2) * length else -1.0
                out[1], out[2], out[3] = s * nx / length, s * ny / length, s * nz / length
        for c in range(3):
            out[4 + c] = pa[VA[0], c]
            out[7 + c] = pa[VA[0], c]
        return _EPA_OK
    # an interior point of the initial polytope, to orient its faces outwards
    cx = 0.0
    cy = 0.0
    cz = 0.0
    for k in range(nv):
        cx += V[k, 0] / nv
        cy += V[k, 1] / nv
        cz += V[k, 2] / nv
    n_faces = 4
    for f in range(n_faces):
        _face_plane(V, F, N, D, f, cx, cy, cz, True)
        alive[f] = True
    for k in range(nv):
        size2 = max(size2, V[k, 0] ** 2 + V[k, 1] ** 2 + V[k, 2] ** 2)
    tol = EPA_TOL * math.sqrt(size2)
    stack = np.empty(_MAX_FACES, np.int64)
    horizon = np.empty((_MAX_FACES, 2), np.int64)
    status = _EPA_NOT_CONVERGED
    best = -1
    for _ in range(max_iter):
        # the face of P closest to the origin
        best = -1
        best_d = np.inf
        for f in range(n_faces):
            if alive[f] and D[f] < best_d:
                best_d = D[f]
                best = f
        if best < 0 or nv >= _MAX_VERTS or best_d < -tol:
            break  # out of room, or round-off has folded the polytope (an inward face): give up
        _support_m(pa, pb, N[best, 0], N[best, 1], N[best, 2], V, VA, VB, nv)
        wx, wy, wz = V[nv, 0], V[nv, 1], V[nv, 2]
        h = wx * N[best, 0] + wy * N[best, 1] + wz * N[best, 2]
        if h - best_d <= tol:
            status = _EPA_OK
            break
        # remove the faces seen from w, flood-filling from the closest face so the hole stays connected,
        # and record the horizon edges (in the winding of the removed faces) to join to w
        n_h = 0
        top = 0
        stack[top] = best
        top += 1
        alive[best] = False
        while top > 0:
            top -= 1
            f = stack[top]
            for e in range(3):
                i = F[f, e]
                j = F[f, (e + 1) % 3]
                # the neighbour across edge (i, j) carries the edge (j, i)
                g = -1
                for q in range(n_faces):
                    if alive[q] and ((F[q, 0] == j and F[q, 1] == i) or (F[q, 1] == j and F[q, 2] == i)
                                     or (F[q, 2] == j and F[q, 0] == i)):
                        g = q
                        break
                if g < 0:
                    # the neighbour was removed already, unless this edge borders the hole: look it up there
                    on_horizon = True
                    for q in range(n_faces):
                        if (not alive[q]) and q != f and ((F[q, 0] == j and F[q, 1] == i)
                                                          or (F[q, 1] == j and F[q, 2] == i)
                                                          or (F[q, 2] == j and F[q, 0] == i)):
                            on_horizon = False
                            break
                    if on_horizon:
                        return _EPA_NOT_CONVERGED  # broken mesh: give up rather than return nonsense
                    continue
                seen = (wx - V[F[g, 0], 0]) * N[g, 0] + (wy - V[F[g, 0], 1]) * N[g, 1] \
                    + (wz - V[F[g, 0], 2]) * N[g, 2]
                if seen > 0.0 or D[g] == np.inf:
                    alive[g] = False
                    stack[top] = g
                    top += 1
                else:
                    horizon[n_h, 0] = i
                    horizon[n_h, 1] = j
                    n_h += 1
        if n_faces + n_h > _MAX_FACES:
            break
        new_v = nv
        nv += 1
        for e in range(n_h):
            F[n_faces, 0] = horizon[e, 0]
            F[n_faces, 1] = horizon[e, 1]
            F[n_faces, 2] = new_v
            _face_plane(V, F, N, D, n_faces, cx, cy, cz, False)
            alive[n_faces] = True
            n_faces += 1
    if status != _EPA_OK:
        return _EPA_NOT_CONVERGED
    out[0] = max(D[best], 0.0)
    out[1], out[2], out[3] = N[best, 0], N[best, 1], N[best, 2]
    # witness points: barycentric coordinates of the origin's projection on the face, applied to A and B
    a = F[best, 0]
    b = F[best, 1]
    c = F[best, 2]
    px, py, pz = D[best] * N[best, 0], D[best] * N[best, 1], D[best] * N[best, 2]
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
    la = 1.0 - lb - lc
    for k in range(3):
        out[4 + k] = la * pa[VA[a], k] + lb * pa[VA[b], k] + lc * pa[VA[c], k]
        out[7 + k] = la * pb[VB[a], k] + lb * pb[VB[b], k] + lc * pb[VB[c], k]
    return _EPA_OK


@njit
def _largest_coordinate(pa, pb):
    big = 0.0
    for i in range(pa.shape[0]):
        big = max(big, abs(pa[i, 0]), abs(pa[i, 1]), abs(pa[i, 2]))
    for i in range(pb.shape[0]):
        big = max(big, abs(pb[i, 0]), abs(pb[i, 1]), abs(pb[i, 2]))
    return big


@njit
def _penetration(pa, pb, max_iter, out):
    """GJK then EPA on one pair; out = depth, normal (3), witness on A (3), witness on B (3). Tiny or huge shapes
    (``rescale_unit``) are solved on copies scaled by a power of two (``rescale_unit``: exact), so that no
    squared length or cross product turns subnormal, and the lengths scaled back."""
    unit = rescale_unit(_largest_coordinate(pa, pb))
    if unit == 1.0:
        return _penetration_at_scale(pa, pb, max_iter, out)
    status = _penetration_at_scale(pa * unit, pb * unit, max_iter, out)
    out[0] /= unit
    for c in range(4, 10):
        out[c] /= unit
    return status


@njit
def _penetration_at_scale(pa, pb, max_iter, out):
    W = np.empty((4, 3))
    IA = np.empty(4, np.int64)
    IB = np.empty(4, np.int64)
    lam = np.empty(4)
    g = np.empty(7)
    status, n = _gjk(pa, pb, max_iter, W, IA, IB, lam, g, np.empty(12, np.int64), np.empty(13))
    if status == _NOT_CONVERGED:
        return _NOT_CONVERGED
    if status != _OVERLAP:
        # separated: no penetration; report the separating direction (A towards B) with depth 0
        out[0] = 0.0
        d = g[6]
        for c in range(3):
            out[1 + c] = (g[3 + c] - g[c]) / d if d > 0.0 else (1.0 if c == 0 else 0.0)
            out[4 + c] = g[c]
            out[7 + c] = g[3 + c]
        if d == 0.0:  # touching without a full simplex: a direction of M's normal cone at the common point
            out[1], out[2], out[3], _ = _touching_normal_at_vertex(pa, pb, EPA_TOL, g[0], g[1], g[2])
        return _EPA_SEPARATED
    return _epa(pa, pb, W, IA, IB, n, max_iter, out)


@njit
def _penetration_pairs(points, offsets, pairs, max_iter, depth, normal, status):
    out = np.empty(10)
    for p in range(pairs.shape[0]):
        i = pairs[p, 0]
        j = pairs[p, 1]
        st = _penetration(points[offsets[i]:offsets[i + 1]], points[offsets[j]:offsets[j + 1]], max_iter, out)
        status[p] = st
        depth[p] = out[0]
        for c in range(3):
            normal[p, c] = out[1 + c]


def _raise(status, where: str, max_iter: int):
    if status == _NOT_CONVERGED:
        raise GJKNotConverged(f"GJK did not converge in max_iterations={max_iter} iterations{where}")
    if status == _EPA_NOT_CONVERGED:
        raise EPANotConverged(f"EPA did not converge in max_iterations={max_iter} iterations{where}")


def _minkowski_fallback(pa: np.ndarray, pb: np.ndarray):
    """Exact depth and normal from Qhull on the Minkowski difference {a − b} (scipy.spatial.ConvexHull).

    Used only where the expanding polytope breaks down on round-off (many coplanar support points, e.g. boxes
    sharing axes); O(n m) points, so meant for the small shapes of a narrow phase. Returns
    (depth, normal, point_a, point_b) or None when there are too many points.
    """
    from scipy.spatial import ConvexHull, QhullError

    if pa.shape[0] * pb.shape[0] > 200_000:
        return None
    md = (pa[:, None, :] - pb[None, :, :]).reshape(-1, 3)
    try:
        hull = ConvexHull(md)
    except (QhullError, ValueError):
        # M is flat: the origin lies on its boundary; depth 0 along the normal of its plane
        _, _, vt = np.linalg.svd(md - md.mean(axis=0))
        normal = vt[-1]
        return 0.0, normal, pa[int(np.argmax(pa @ normal))], pb[int(np.argmin(pb @ normal))]
    distances = -hull.equations[:, 3]
    k = int(np.argmin(distances))
    normal = hull.equations[k, :3].copy()
    depth = max(float(distances[k]), 0.0)
    return depth, normal, pa[int(np.argmax(pa @ normal))], pb[int(np.argmin(pb @ normal))]


def epa_penetration(points_a, points_b, *, max_iterations: int = MAX_ITERATIONS, witnesses: bool = False):
    """Penetration depth and normal of the overlapping convex hulls of ``points_a`` (n, 3) and ``points_b`` (m, 3).

    Returns ``(depth, normal)``: depth >= 0 is the length of the shortest translation that separates the hulls
    (0.0 when they only touch, or do not overlap at all), ``normal`` (3,) a unit vector pointing from A towards
    B, so that moving B by ``depth * normal`` leaves the hulls touching. With ``witnesses=True`` also returns
    the deepest points of A and of B, (3,) each: ``(depth, normal, point_a, point_b)``. For separated hulls
    depth is 0 and the normal is the direction of GJK's closest points (see ``gjk_distance``).
    """
    pa = as_float_array(points_a, "points_a", shape=(None, 3), min_rows=1)
    pb = as_float_array(points_b, "points_b", shape=(None, 3), min_rows=1)
    max_iter = as_max_iterations(max_iterations)
    out = np.empty(10)
    status = _penetration(pa, pb, max_iter, out)
    if status == _EPA_NOT_CONVERGED:
        exact = _minkowski_fallback(pa, pb)
        if exact is not None:
            depth, normal, wa, wb = exact
            return (depth, normal, wa, wb) if witnesses else (depth, normal)
    _raise(status, "", max_iter)
    normal = out[1:4].copy()
    if witnesses:
        return float(out[0]), normal, out[4:7].copy(), out[7:10].copy()
    return float(out[0]), normal


def epa_penetration_pairs(points, offsets, pairs, *, max_iterations: int = MAX_ITERATIONS):
    """EPA over k pairs of packed shapes (see ``gjk_distance_pairs`` for ``points``/``offsets``) in one compiled
    call. Returns ``(depth (k,), normal (k, 3))``; separated pairs get depth 0 and GJK's direction."""
    pts = as_float_array(points, "points", shape=(None, 3))
    off = check_offsets(offsets, pts.shape[0])
    pr = check_pairs(pairs, off.shape[0] - 1)
    max_iter = as_max_iterations(max_iterations)
    k = pr.shape[0]
    depth = np.empty(k)
    normal = np.empty((k, 3))
    status = np.empty(k, np.int64)
    if k:
        _penetration_pairs(pts, off, pr, max_iter, depth, normal, status)
        for p in np.flatnonzero(status == _EPA_NOT_CONVERGED):  # rare: see _minkowski_fallback
            i, j = pr[p]
            exact = _minkowski_fallback(pts[off[i]:off[i + 1]], pts[off[j]:off[j + 1]])
            if exact is not None:
                depth[p], normal[p] = exact[0], exact[1]
                status[p] = _EPA_OK
        bad = np.flatnonzero((status == _NOT_CONVERGED) | (status == _EPA_NOT_CONVERGED))
        if bad.size:
            _raise(int(status[bad[0]]), f" for pairs[{bad[0]}]", max_iter)
    return depth, normal
