"""The normal of two convex hulls that touch at a common point p (depth 0): a unit n along which the Minkowski
difference M = A − B does not extend, max over M of m·n <= tol — the normal of a plane through p that separates
the hulls, a direction of M's normal cone at the origin. GJK and EPA meet this case when GJK ends on a single
support point, or at distance exactly 0 without a full simplex.

The normal cone of M at the origin is the polar of the cone spanned by the generators g (every a − p and p − b);
its edges are orthogonal to two generators (Rockafellar, *Convex Analysis*, section 14: polar cones).
"""
from __future__ import annotations

import math

import numpy as np

from .._config import njit
from .support import support_minkowski

__all__ = ["MAX_CONE_POINTS", "SMALL_DISTANCE", "pair_size", "unit_vector", "touching_normal_at_vertex",
           "normal_cone_direction", "separated_normal_at_contact"]


#: the normal-cone search (``normal_cone_direction``) costs (n + m)³: beyond this many points it is skipped
MAX_CONE_POINTS = 200


@njit
def normal_cone_direction(pa, pb, px, py, pz, tol):
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
            cx, cy, cz, nonzero = unit_vector(G[i, 1] * G[k, 2] - G[i, 2] * G[k, 1],
                                              G[i, 2] * G[k, 0] - G[i, 0] * G[k, 2],
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
        return unit_vector(sx, sy, sz)
    mx = 0.0
    my = 0.0
    mz = 0.0
    for j in range(n):
        gx, gy, gz, nonzero = unit_vector(G[j, 0], G[j, 1], G[j, 2])
        if nonzero:
            mx -= gx
            my -= gy
            mz -= gz
    if _unit_within(G, mx, my, mz, tol):
        return unit_vector(mx, my, mz)
    if found:
        return fx, fy, fz, True
    return 1.0, 0.0, 0.0, False


@njit
def unit_vector(x, y, z):
    """``(ux, uy, uz, nonzero)``: (x, y, z) / |(x, y, z)| and True, scaled by its largest component first (no
    underflow of the squares for tiny vectors, no overflow for huge ones); (1, 0, 0, False) for the zero vector."""
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
    nx, ny, nz, ok = unit_vector(x, y, z)
    if not ok:
        return False
    for j in range(G.shape[0]):
        if nx * G[j, 0] + ny * G[j, 1] + nz * G[j, 2] > tol:
            return False
    return True


@njit
def pair_size(pa, pb):
    """The size of two point sets pa (n, 3), pb (m, 3) that the touching tolerances are relative to: the largest
    coordinate difference of any of their points from pa[0]."""
    scale = 0.0
    for i in range(pa.shape[0]):
        for c in range(3):
            scale = max(scale, abs(pa[i, c] - pa[0, c]))
    for i in range(pb.shape[0]):
        for c in range(3):
            scale = max(scale, abs(pb[i, c] - pa[0, c]))
    return scale


@njit
def touching_normal_at_vertex(pa, pb, rel_tol, px, py, pz):
    """The origin is on the boundary of M = A − B, at the common point p of the two hulls (depth 0): a unit
    direction n along which M does not extend, max over M of m·n <= tol (a normal of the touching plane).
    Candidates: the direction from A's centroid to B's, then the six axis directions, then the normal cone of M
    at the origin (``normal_cone_direction``, for up to MAX_CONE_POINTS points); returns (nx, ny, nz, found).
    ``rel_tol`` is relative to the shapes' size."""
    scale = pair_size(pa, pb)
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
        # rescaled first: a tiny (1e-162) direction's squares underflow
        dx, dy, dz, nonzero = unit_vector(dx, dy, dz)
        if not nonzero:
            continue
        _, _, wx, wy, wz = support_minkowski(pa, pb, dx, dy, dz)
        h = wx * dx + wy * dy + wz * dz
        if h <= tol:
            return dx, dy, dz, True
    if pa.shape[0] + pb.shape[0] <= MAX_CONE_POINTS:
        return normal_cone_direction(pa, pb, px, py, pz, tol)
    return 1.0, 0.0, 0.0, False


#: a separated pair's normal is checked against M (``separated_normal_at_contact``) when its distance d is below
#: this fraction of the shapes' size: the closest points' difference carries a round-off of 2^-52 × size, so its
#: direction errs by about 2^-52 size / d and the shapes' projections on it by 2^-52 size² / d, more than the
#: tolerance 1e-10 × size when d < 2^-52 / 1e-10 × size = 2.2e-6 size
SMALL_DISTANCE = 1e-5


@njit
def separated_normal_at_contact(pa, pb, nx, ny, nz, d, rel_tol, px, py, pz):
    """The normal (A towards B, unit) of hulls separated by a tiny distance d, given the candidate (nx, ny, nz)
    from their closest points (p on A). The exact normal n minimises h(n) = max over M of m·n, to h = −d: the
    candidate is kept when h <= −d + tol (tol = rel_tol × the shapes' size, as in ``touching_normal_at_vertex``);
    else, the hulls being within round-off of touching at p, a direction of M's normal cone there
    (``touching_normal_at_vertex``) is taken if its h is lower. Returns (nx, ny, nz)."""
    scale = pair_size(pa, pb)
    if d > SMALL_DISTANCE * scale:
        return nx, ny, nz
    _, _, wx, wy, wz = support_minkowski(pa, pb, nx, ny, nz)
    h = wx * nx + wy * ny + wz * nz
    if h <= -d + rel_tol * max(scale, 1e-300):
        return nx, ny, nz
    cx, cy, cz, found = touching_normal_at_vertex(pa, pb, rel_tol, px, py, pz)
    _, _, wx, wy, wz = support_minkowski(pa, pb, cx, cy, cz)
    if found and wx * cx + wy * cy + wz * cz < h:
        return cx, cy, cz
    return nx, ny, nz
