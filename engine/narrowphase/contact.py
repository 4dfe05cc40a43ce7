"""Contact: the pipeline's last stage — "l'instant et le lieu précis (vertex, côtés, faces) de contact".

Where: ``contact_feature`` finds, for two convex shapes (convex hulls of point sets, optionally swept by a ball
of radius r: spheres, capsules, rounded boxes), the contact normal n (from A towards B; GJK's closest points when
they are apart, EPA's normal when they overlap) and the supporting feature of each shape along it: the vertices
of A within ``feature_tol`` of A's support plane max a·n, and of B within it of min b·n. One vertex is a
*vertex*, two (or collinear ones) an *edge*, three or more a *face*; the pair names the contact (vertex–face,
edge–edge, face–face, edge–face ...). The contact points are the intersection of the two features projected on
the plane orthogonal to n (Sutherland–Hodgman clipping for face–face, Ericson 8.3.4 / Box2D's
``b2ClipPolygons``; segment clipping for edge–face; closest points of two segments for edge–edge, Ericson
5.1.9), placed on the mid-plane between the two support planes.

When: ``time_of_impact`` advances two convex shapes moving with constant linear and angular velocities by
conservative advancement on the GJK distance (Mirtich 1996; Zhang, Lee, Kim 2006): with d the distance and n the
direction of the closest points, no contact can happen before d / μ where μ = (v_A − v_B)·n + |ω_A| ρ_A + |ω_B|
ρ_B bounds the closing speed (ρ = farthest vertex from the rotation centre). The step t += d / μ never
overshoots; it stops when d <= tol.

The contact polygon of a face is the 2-D convex hull (the engine's monotone chain, engine.bounding.hull) of the
support set projected on the contact plane.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._config import njit
from .._validate import (
    as_float_array,
    as_max_iterations,
    as_nonnegative,
    as_positive,
    as_radii,
    check_offsets,
    check_pairs,
)
from ..bounding.hull import HULL_EPS, monotone_chain
from .epa import (
    _EPA_OK,
    EPA_TOL,
    EPANotConverged,
    _epa,
    _largest_coordinate,
    _minkowski_fallback,
    _touching_normal_at_vertex,
)
from .gjk import (
    _NOT_CONVERGED,
    _OVERLAP,
    MAX_ITERATIONS,
    GJKNotConverged,
    _gjk,
    rescale_unit,
)

__all__ = ["Contact", "ContactBatch", "contact_feature", "contact_feature_pairs", "time_of_impact",
           "time_of_impact_pairs", "TOINotConverged", "FEATURE_TOL"]

#: relative tolerance (× the size of the shapes) of the support-plane test that groups vertices into a feature
FEATURE_TOL = 1e-7

_NAMES = {1: "vertex", 2: "edge", 3: "face"}
_ROUND_NAMES = {1: "sphere", 2: "cylinder", 3: "face"}


class TOINotConverged(RuntimeError):
    """Conservative advancement hit its iteration cap before reaching the contact distance."""


@dataclass(frozen=True)
class Contact:
    """The answer to "whether and where".

    - ``separation``: signed distance between the shapes (> 0 apart, 0 touching, < 0 penetration depth);
    - ``normal`` (3,): unit vector from A towards B;
    - ``feature_a``, ``feature_b``: "vertex", "edge" or "face" (rounded shapes: "sphere" or "cylinder");
    - ``kind``: e.g. "vertex-face" (A's feature first);
    - ``points`` (k, 3): contact point(s) on the mid-plane between the two support planes (k = 1 for a vertex or
      crossing edges, 2 for an edge on a face or parallel edges, up to the polygon's size for face–face);
    - ``closest_a``, ``closest_b`` (3,): GJK's closest (or EPA's deepest) points of A and B.
    """

    separation: float
    normal: np.ndarray
    feature_a: str
    feature_b: str
    kind: str
    points: np.ndarray
    closest_a: np.ndarray
    closest_b: np.ndarray

    @property
    def touching(self) -> bool:
        return self.separation <= 0.0


# ---------------------------------------------------------------------------------------------------------------
# where: features and contact points
# ---------------------------------------------------------------------------------------------------------------

# --- the kernels, one pair at a time; _contact_pairs runs them over a batch in one compiled call ------------------

_OK = 0
_GJK_FAILED = 2
_EPA_FAILED = 3


@njit
def _plane_basis(nx, ny, nz, basis):
    """Two unit vectors u = basis[0], v = basis[1] with (u, v, n) orthonormal: u = n × e_k, e_k the coordinate
    axis least aligned with n, v = n × u."""
    ax, ay, az = abs(nx), abs(ny), abs(nz)
    if ax <= ay and ax <= az:  # e_x: n × e_x = (0, nz, -ny)
        ux, uy, uz = 0.0, nz, -ny
    elif ay <= az:  # e_y: n × e_y = (-nz, 0, nx)
        ux, uy, uz = -nz, 0.0, nx
    else:  # e_z: n × e_z = (ny, -nx, 0)
        ux, uy, uz = ny, -nx, 0.0
    length = math.sqrt(ux * ux + uy * uy + uz * uz)
    ux, uy, uz = ux / length, uy / length, uz / length
    basis[0, 0], basis[0, 1], basis[0, 2] = ux, uy, uz
    basis[1, 0] = ny * uz - nz * uy
    basis[1, 1] = nz * ux - nx * uz
    basis[1, 2] = nx * uy - ny * ux


@njit
def _feature_polygon(P, m, tol, F):
    """The support set P[:m] (projected on the contact plane) reduced to its shape, written into F: returns 1 (a
    vertex), 2 (an edge: its two extreme points along the set's principal direction) or k >= 3 (a convex polygon,
    counter-clockwise: the engine's monotone chain, engine.bounding.hull)."""
    x0 = P[0, 0]
    y0 = P[0, 1]
    spread = 0.0
    for i in range(m):
        spread = max(spread, abs(P[i, 0] - x0), abs(P[i, 1] - y0))
    if spread <= tol:
        F[0, 0] = x0
        F[0, 1] = y0
        return 1
    # principal direction (u_x, u_y) of the centred set: the covariance's main axis, ½ atan2(2 sxy, sxx − syy)
    mx = 0.0
    my = 0.0
    for i in range(m):
        mx += P[i, 0]
        my += P[i, 1]
    mx /= m
    my /= m
    sxx = 0.0
    sxy = 0.0
    syy = 0.0
    for i in range(m):
        dx = P[i, 0] - mx
        dy = P[i, 1] - my
        sxx += dx * dx
        sxy += dx * dy
        syy += dy * dy
    theta = 0.5 * math.atan2(2.0 * sxy, sxx - syy)
    ux = math.cos(theta)
    uy = math.sin(theta)
    i_min = 0
    i_max = 0
    lo = np.inf
    hi = -np.inf
    across = 0.0
    for i in range(m):
        dx = P[i, 0] - mx
        dy = P[i, 1] - my
        t = dx * ux + dy * uy
        if t < lo:
            lo = t
            i_min = i
        if t > hi:
            hi = t
            i_max = i
        across = max(across, abs(-dx * uy + dy * ux))
    if m == 2 or across <= tol:
        F[0, 0], F[0, 1] = P[i_min, 0], P[i_min, 1]
        F[1, 0], F[1, 1] = P[i_max, 0], P[i_max, 1]
        return 2
    # Andrew's monotone chain on the points in lexicographic (x, then y) order
    pts = P[:m]
    by_y = np.argsort(pts[:, 1].copy(), kind="mergesort")
    order = by_y[np.argsort(pts[by_y, 0].copy(), kind="mergesort")]
    verts = monotone_chain(pts, order)
    k = verts.shape[0]
    area2 = 0.0
    ext_x = 0.0
    ext_y = 0.0
    big = 0.0
    for i in range(m):
        ext_x = max(ext_x, abs(pts[i, 0] - x0))
        ext_y = max(ext_y, abs(pts[i, 1] - y0))
        big = max(big, abs(pts[i, 0]), abs(pts[i, 1]))
    if k >= 3:
        vx = pts[verts[0], 0]
        vy = pts[verts[0], 1]
        for i in range(k):
            a = verts[i]
            b = verts[(i + 1) % k]
            area2 += (pts[a, 0] - vx) * (pts[b, 1] - vy) - (pts[b, 0] - vx) * (pts[a, 1] - vy)
    # the extent (the largest ptp) as engine.bounding.hull measures it for its collinearity test
    xmin = np.inf
    xmax = -np.inf
    ymin = np.inf
    ymax = -np.inf
    for i in range(m):
        xmin = min(xmin, pts[i, 0])
        xmax = max(xmax, pts[i, 0])
        ymin = min(ymin, pts[i, 1])
        ymax = max(ymax, pts[i, 1])
    extent = max(xmax - xmin, ymax - ymin)
    if k < 3 or area2 <= HULL_EPS * extent * (big + extent):  # collinear to round-off: the support set is an edge
        F[0, 0], F[0, 1] = P[i_min, 0], P[i_min, 1]
        F[1, 0], F[1, 1] = P[i_max, 0], P[i_max, 1]
        return 2
    for i in range(k):
        F[i, 0] = pts[verts[i], 0]
        F[i, 1] = pts[verts[i], 1]
    return k


@njit
def _clip_polygon(S, ns, C, nc, buf):
    """Sutherland–Hodgman (Ericson 8.3.4, Box2D's b2ClipPolygons): the part of the polygon S[:ns] inside the
    convex counter-clockwise polygon C[:nc]. Works in the two halves of buf (2, cap, 2); returns (half, count)."""
    cur = 0
    n = ns
    for i in range(ns):
        buf[0, i, 0] = S[i, 0]
        buf[0, i, 1] = S[i, 1]
    for e in range(nc):
        if n == 0:
            break
        ax = C[e, 0]
        ay = C[e, 1]
        ex = C[(e + 1) % nc, 0] - ax
        ey = C[(e + 1) % nc, 1] - ay
        nxt = 1 - cur
        m = 0
        for i in range(n):
            px, py = buf[cur, i, 0], buf[cur, i, 1]
            qx, qy = buf[cur, (i + 1) % n, 0], buf[cur, (i + 1) % n, 1]
            sp = ex * (py - ay) - ey * (px - ax)  # >= 0: p is inside the edge's half-plane
            sq = ex * (qy - ay) - ey * (qx - ax)
            if sp >= 0.0:
                buf[nxt, m, 0] = px
                buf[nxt, m, 1] = py
                m += 1
            if (sp >= 0.0) != (sq >= 0.0):
                t = sp / (sp - sq)
                buf[nxt, m, 0] = px + t * (qx - px)
                buf[nxt, m, 1] = py + t * (qy - py)
                m += 1
        cur = nxt
        n = m
    return cur, n


@njit
def _clip_segment(px, py, qx, qy, C, nc, out):
    """Cyrus–Beck: the part of segment [p, q] inside the convex counter-clockwise polygon C[:nc] into out[:2];
    returns 2, or 0 when it is empty."""
    t0 = 0.0
    t1 = 1.0
    dx = qx - px
    dy = qy - py
    for e in range(nc):
        ax = C[e, 0]
        ay = C[e, 1]
        ex = C[(e + 1) % nc, 0] - ax
        ey = C[(e + 1) % nc, 1] - ay
        num = ex * (py - ay) - ey * (px - ax)  # >= 0 inside
        den = ex * dy - ey * dx
        if den == 0.0:
            if num < 0.0:
                return 0
            continue
        t = -num / den
        if den > 0.0:
            t0 = max(t0, t)
        else:
            t1 = min(t1, t)
        if t0 > t1:
            return 0
    out[0, 0] = px + t0 * dx
    out[0, 1] = py + t0 * dy
    out[1, 0] = px + t1 * dx
    out[1, 1] = py + t1 * dy
    return 2


@njit
def _closest_segments_2d(A, B, tol, out):
    """Contact points of two projected edges A[:2], B[:2]: their crossing, or the overlap of parallel edges
    (Ericson 5.1.9). Writes out[:count]; returns count (1 or 2)."""
    p1x, p1y = A[0, 0], A[0, 1]
    d1x, d1y = A[1, 0] - p1x, A[1, 1] - p1y
    p2x, p2y = B[0, 0], B[0, 1]
    d2x, d2y = B[1, 0] - p2x, B[1, 1] - p2y
    den = d1x * d2y - d1y * d2x
    len1 = math.sqrt(d1x * d1x + d1y * d1y)
    scale = max(len1 * math.sqrt(d2x * d2x + d2y * d2y), 1e-300)
    if abs(den) > 1e-9 * scale:
        s = ((p2x - p1x) * d2y - (p2y - p1y) * d2x) / den
        s = min(max(s, 0.0), 1.0)
        out[0, 0] = p1x + s * d1x
        out[0, 1] = p1y + s * d1y
        return 1
    # parallel: the overlap of the two intervals along d1
    length = max(len1, 1e-300)
    ux = d1x / length
    uy = d1y / length
    a0 = 0.0
    a1 = d1x * ux + d1y * uy
    b0 = (p2x - p1x) * ux + (p2y - p1y) * uy
    b1 = (B[1, 0] - p1x) * ux + (B[1, 1] - p1y) * uy
    if b1 < b0:
        b0, b1 = b1, b0
    lo = max(a0, b0)
    hi = min(a1, b1)
    if lo > hi:  # should not happen for facing features; keep the nearest end
        lo = a1 if b0 > a1 else a0
        hi = lo
    if hi - lo <= tol:
        mid = 0.5 * (lo + hi)
        out[0, 0] = p1x + mid * ux
        out[0, 1] = p1y + mid * uy
        return 1
    out[0, 0] = p1x + lo * ux
    out[0, 1] = p1y + lo * uy
    out[1, 0] = p1x + hi * ux
    out[1, 1] = p1y + hi * uy
    return 2


@njit
def _drop_flat_vertices(S, count, tol):
    """Remove from the convex polygon S[:count] every vertex within tol of the line through its two neighbours
    (clipping a face on a face that shares an edge leaves such points: they add nothing to the contact patch).
    Returns the new count."""
    while count >= 3:
        dropped = False
        for i in range(count):
            a = (i - 1) % count
            b = (i + 1) % count
            ex = S[b, 0] - S[a, 0]
            ey = S[b, 1] - S[a, 1]
            length = math.sqrt(ex * ex + ey * ey)
            dx = S[i, 0] - S[a, 0]
            dy = S[i, 1] - S[a, 1]
            off = abs(ex * dy - ey * dx) / length if length > 0.0 else math.sqrt(dx * dx + dy * dy)
            if off <= tol:
                for j in range(i, count - 1):
                    S[j, 0] = S[j + 1, 0]
                    S[j, 1] = S[j + 1, 1]
                count -= 1
                dropped = True
                break
        if not dropped:
            break
    return count


@njit
def _features(pa, pb, ra, rb, n, ca, cb, ftol, S, FA, FB, buf, out_points, start):
    """The "where" of one pair, given the contact normal n (A towards B) and the closest (or deepest) points
    ca, cb: the support sets of A (vertices within tol of max a·n) and of B (within tol of min b·n), projected on
    the plane ⊥ n and reduced to features, their intersection (clipping), deduplicated (and polygon vertices flat
    between their neighbours dropped), lifted to the mid-plane between the two support planes. Writes the points
    into out_points[start:]; returns (kind_a, kind_b, count) with kind 1 vertex, 2 edge, 3 face. S, FA, FB, buf
    are scratch arrays."""
    size = 0.0
    for c in range(3):
        lo = np.inf
        hi = -np.inf
        for i in range(pa.shape[0]):
            lo = min(lo, pa[i, c])
            hi = max(hi, pa[i, c])
        for i in range(pb.shape[0]):
            lo = min(lo, pb[i, c])
            hi = max(hi, pb[i, c])
        size = max(size, hi - lo)
    size = max(size, ra + rb, 1e-300)
    tol = ftol * size
    nx, ny, nz = n[0], n[1], n[2]
    top_a = -np.inf
    for i in range(pa.shape[0]):
        top_a = max(top_a, pa[i, 0] * nx + pa[i, 1] * ny + pa[i, 2] * nz)
    bot_b = np.inf
    for i in range(pb.shape[0]):
        bot_b = min(bot_b, pb[i, 0] * nx + pb[i, 1] * ny + pb[i, 2] * nz)
    basis = np.empty((2, 3))
    _plane_basis(nx, ny, nz, basis)
    # A's support set, projected, then its feature
    m = 0
    for i in range(pa.shape[0]):
        if pa[i, 0] * nx + pa[i, 1] * ny + pa[i, 2] * nz >= top_a - tol:
            S[m, 0] = pa[i, 0] * basis[0, 0] + pa[i, 1] * basis[0, 1] + pa[i, 2] * basis[0, 2]
            S[m, 1] = pa[i, 0] * basis[1, 0] + pa[i, 1] * basis[1, 1] + pa[i, 2] * basis[1, 2]
            m += 1
    na = _feature_polygon(S, m, tol, FA)
    m = 0
    for i in range(pb.shape[0]):
        if pb[i, 0] * nx + pb[i, 1] * ny + pb[i, 2] * nz <= bot_b + tol:
            S[m, 0] = pb[i, 0] * basis[0, 0] + pb[i, 1] * basis[0, 1] + pb[i, 2] * basis[0, 2]
            S[m, 1] = pb[i, 0] * basis[1, 0] + pb[i, 1] * basis[1, 1] + pb[i, 2] * basis[1, 2]
            m += 1
    nb = _feature_polygon(S, m, tol, FB)
    # their intersection in the plane (into S)
    if na == 1:
        S[0, 0], S[0, 1] = FA[0, 0], FA[0, 1]
        count = 1
    elif nb == 1:
        S[0, 0], S[0, 1] = FB[0, 0], FB[0, 1]
        count = 1
    elif na == 2 and nb == 2:
        count = _closest_segments_2d(FA, FB, tol, S)
    elif na == 2:
        count = _clip_segment(FA[0, 0], FA[0, 1], FA[1, 0], FA[1, 1], FB, nb, S)
    elif nb == 2:
        count = _clip_segment(FB[0, 0], FB[0, 1], FB[1, 0], FB[1, 1], FA, na, S)
    else:
        half, count = _clip_polygon(FA, na, FB, nb, buf)
        for i in range(count):
            S[i, 0] = buf[half, i, 0]
            S[i, 1] = buf[half, i, 1]
    if count == 0:  # round-off left no overlap: fall back on the closest points
        for r in range(2):
            S[0, r] = 0.5 * ((ca[0] + cb[0]) * basis[r, 0] + (ca[1] + cb[1]) * basis[r, 1]
                             + (ca[2] + cb[2]) * basis[r, 2])
        count = 1
    # drop repeated points (greedy, first kept), then lift to the mid-plane
    kept = 0
    for i in range(count):
        fresh = True
        for j in range(kept):
            dx = S[i, 0] - S[j, 0]
            dy = S[i, 1] - S[j, 1]
            if not math.sqrt(dx * dx + dy * dy) > tol:
                fresh = False
                break
        if fresh:
            S[kept, 0] = S[i, 0]
            S[kept, 1] = S[i, 1]
            kept += 1
    kept = _drop_flat_vertices(S, kept, tol)
    mid = 0.5 * ((top_a + ra) + (bot_b - rb))
    for i in range(kept):
        for c in range(3):
            out_points[start + i, c] = S[i, 0] * basis[0, c] + S[i, 1] * basis[1, c] + mid * n[c]
    return min(na, 3), min(nb, 3), kept


@njit
def _normal_and_depth(pa, pb, max_iter, out, W, IA, IB, lam, g, work_i, work_f):
    """GJK (Ericson 9.5), then EPA (van den Bergen 4.3.3) when the hulls overlap: out = signed distance of the
    hulls (> 0 apart, −depth overlapping), normal (3, A towards B), closest/deepest point of A (3) and of B (3).
    Returns _OK, _GJK_FAILED or _EPA_FAILED (the caller then takes Qhull's exact answer). ``_contact_pairs``, its
    caller, hands it tiny or huge pairs already scaled into range (``rescale_unit``)."""
    status, n_simplex = _gjk(pa, pb, max_iter, W, IA, IB, lam, g, work_i, work_f)
    if status == _NOT_CONVERGED:
        return _GJK_FAILED
    d = g[6]
    if d > 0.0:
        out[0] = d
        # the unit direction of closest_b − closest_a, rescaled first (d may be so small, 1e-162, that its square
        # underflows and d itself is inexact)
        big = max(abs(g[3] - g[0]), abs(g[4] - g[1]), abs(g[5] - g[2]))
        length = math.sqrt(((g[3] - g[0]) / big) ** 2 + ((g[4] - g[1]) / big) ** 2 + ((g[5] - g[2]) / big) ** 2)
        for c in range(3):
            out[1 + c] = (g[3 + c] - g[c]) / big / length
            out[4 + c] = g[c]
            out[7 + c] = g[3 + c]
        return _OK
    if status != _OVERLAP:  # touching at distance exactly 0 without a full simplex: depth 0, a touching normal
        out[0] = 0.0
        nx, ny, nz, _ = _touching_normal_at_vertex(pa, pb, EPA_TOL, g[0], g[1], g[2])
        out[1], out[2], out[3] = nx, ny, nz
        for c in range(3):
            out[4 + c] = g[c]
            out[7 + c] = g[3 + c]
        return _OK
    epa = np.empty(10)
    if _epa(pa, pb, W, IA, IB, n_simplex, max_iter, epa) != _EPA_OK:
        return _EPA_FAILED
    out[0] = -epa[0]
    for c in range(1, 10):
        out[c] = epa[c]
    if epa[0] == 0.0 and pa.shape[0] == 1 and pb.shape[0] == 1:
        out[1], out[2], out[3] = 1.0, 0.0, 0.0  # two coincident points: any direction
    return _OK


@njit
def _contact_pairs(points, offsets, pairs, radii, ftol, max_iter, todo, geometry, separation, normal, closest_a,
                   closest_b, kind_a, kind_b, out_points, point_start, point_count, status):
    """contact_feature over the pairs p with todo[p]: GJK/EPA (unless ``geometry`` is False: then separation,
    normal and closest points are given, e.g. by the exact fallback), then the features and contact points.
    Pair p writes its points at out_points[point_start[p]:], room for size(A) + size(B) + 1."""
    W = np.empty((4, 3))
    IA = np.empty(4, np.int64)
    IB = np.empty(4, np.int64)
    lam = np.empty(4)
    g = np.empty(7)
    work_i = np.empty(12, np.int64)
    work_f = np.empty(13)
    out = np.empty(10)
    big = 1
    for s in range(offsets.shape[0] - 1):
        big = max(big, offsets[s + 1] - offsets[s])
    S = np.empty((2 * big + 2, 2))
    FA = np.empty((big + 1, 2))
    FB = np.empty((big + 1, 2))
    buf = np.empty((2, 2 * big + 2, 2))
    for p in range(pairs.shape[0]):
        if not todo[p]:
            continue
        i = pairs[p, 0]
        j = pairs[p, 1]
        pa = points[offsets[i]:offsets[i + 1]]
        pb = points[offsets[j]:offsets[j + 1]]
        ra = radii[i]
        rb = radii[j]
        # tiny or huge pairs are solved on copies scaled by a power of two (exact), lengths scaled back at the end
        unit = rescale_unit(max(_largest_coordinate(pa, pb), ra, rb))
        if unit != 1.0:
            pa = pa * unit
            pb = pb * unit
            ra *= unit
            rb *= unit
            if not geometry:  # the given closest points are in the shapes' own units
                for c in range(3):
                    closest_a[p, c] *= unit
                    closest_b[p, c] *= unit
        if geometry:
            st = _normal_and_depth(pa, pb, max_iter, out, W, IA, IB, lam, g, work_i, work_f)
            status[p] = st
            if st != _OK:
                point_count[p] = 0
                continue
            for c in range(3):
                normal[p, c] = out[1 + c]
                closest_a[p, c] = out[4 + c]
                closest_b[p, c] = out[7 + c]
            separation[p] = out[0] - ra - rb
        ka, kb, cnt = _features(pa, pb, ra, rb, normal[p], closest_a[p], closest_b[p], ftol, S, FA, FB, buf,
                                out_points, point_start[p])
        kind_a[p] = ka
        kind_b[p] = kb
        point_count[p] = cnt
        for c in range(3):
            closest_a[p, c] += ra * normal[p, c]
            closest_b[p, c] -= rb * normal[p, c]
        if unit != 1.0:
            if geometry:
                separation[p] /= unit
            for c in range(3):
                closest_a[p, c] /= unit
                closest_b[p, c] /= unit
                for q in range(point_start[p], point_start[p] + cnt):
                    out_points[q, c] /= unit


@dataclass(frozen=True)
class ContactBatch:
    """``contact_feature`` over k pairs, as arrays (see ``contact_feature_pairs``).

    - ``separation`` (k,): signed distance (> 0 apart, 0 touching, < 0 penetration depth);
    - ``normal`` (k, 3): unit vectors from A towards B;
    - ``feature_a``, ``feature_b`` (k,) int8: 1 vertex, 2 edge, 3 face (for a rounded shape, radius > 0: sphere,
      cylinder, face; ``names_a``, ``names_b`` and ``kind`` give the strings);
    - ``points`` (M, 3), ``point_offsets`` (k + 1,): the contact points of pair p are
      ``points[point_offsets[p]:point_offsets[p + 1]]`` (at least one per pair);
    - ``closest_a``, ``closest_b`` (k, 3): GJK's closest (or EPA's deepest) points of A and B;
    - ``radius_a``, ``radius_b`` (k,): the radii of the two shapes of every pair;
    - ``exact_fallback`` (k,) bool: pairs whose depth came from Qhull on the Minkowski difference (EPA broke
      down on round-off; see ``engine.narrowphase.epa``).
    ``len(batch)`` is k and ``batch[p]`` the ``Contact`` of pair p.
    """

    separation: np.ndarray
    normal: np.ndarray
    feature_a: np.ndarray
    feature_b: np.ndarray
    points: np.ndarray
    point_offsets: np.ndarray
    closest_a: np.ndarray
    closest_b: np.ndarray
    radius_a: np.ndarray
    radius_b: np.ndarray
    exact_fallback: np.ndarray

    def __len__(self) -> int:
        return int(self.separation.shape[0])

    @staticmethod
    def _names(codes, radii) -> list:
        return [(_ROUND_NAMES if r > 0 else _NAMES)[int(c)] for c, r in zip(codes, radii)]

    @property
    def names_a(self) -> list:
        """A's feature of every pair: "vertex", "edge", "face" (rounded: "sphere", "cylinder", "face")."""
        return self._names(self.feature_a, self.radius_a)

    @property
    def names_b(self) -> list:
        return self._names(self.feature_b, self.radius_b)

    @property
    def kind(self) -> list:
        """"vertex-face", "edge-edge" ... for every pair (A's feature first)."""
        return [f"{a}-{b}" for a, b in zip(self.names_a, self.names_b)]

    def __getitem__(self, p) -> Contact:
        if isinstance(p, bool) or not isinstance(p, int | np.integer):
            raise TypeError(f"p must be an int, got {type(p).__name__}")
        k = len(self)
        if not -k <= p < k:
            raise IndexError(f"pair {p} outside a batch of {k}")
        p = int(p) % k
        fa = (_ROUND_NAMES if self.radius_a[p] > 0 else _NAMES)[int(self.feature_a[p])]
        fb = (_ROUND_NAMES if self.radius_b[p] > 0 else _NAMES)[int(self.feature_b[p])]
        return Contact(separation=float(self.separation[p]), normal=self.normal[p].copy(), feature_a=fa,
                       feature_b=fb, kind=f"{fa}-{fb}",
                       points=self.points[self.point_offsets[p]:self.point_offsets[p + 1]].copy(),
                       closest_a=self.closest_a[p].copy(), closest_b=self.closest_b[p].copy())


def _contact_batch(pts, off, pr, rad, ftol, max_iter) -> ContactBatch:
    """contact_feature_pairs on validated arrays."""
    k = pr.shape[0]
    sizes = np.diff(off)
    room = sizes[pr[:, 0]] + sizes[pr[:, 1]] + 1 if k else np.zeros(0, np.int64)
    start = np.zeros(k + 1, np.int64)
    np.cumsum(room, out=start[1:])
    separation = np.empty(k)
    normal = np.empty((k, 3))
    ca = np.empty((k, 3))
    cb = np.empty((k, 3))
    kind_a = np.zeros(k, np.int8)
    kind_b = np.zeros(k, np.int8)
    raw = np.empty((int(start[-1]), 3))
    count = np.zeros(k, np.int64)
    status = np.zeros(k, np.int64)
    fallback = np.zeros(k, np.bool_)
    if k:
        _contact_pairs(pts, off, pr, rad, ftol, max_iter, np.ones(k, np.bool_), True, separation, normal, ca, cb,
                       kind_a, kind_b, raw, start, count, status)
        bad = np.flatnonzero(status == _GJK_FAILED)
        if bad.size:
            raise GJKNotConverged(f"GJK did not converge in max_iterations={max_iter} iterations for pairs[{bad[0]}]")
        fallback = status == _EPA_FAILED
        for p in np.flatnonzero(fallback):  # rare: EPA folded on round-off; Qhull's exact answer instead
            i, j = pr[p]
            pa, pb = pts[off[i]:off[i + 1]], pts[off[j]:off[j + 1]]
            exact = _minkowski_fallback(pa, pb)
            if exact is None:
                raise EPANotConverged(f"EPA did not converge in max_iterations={max_iter} iterations for pairs[{p}]")
            depth, n, wa, wb = exact
            if depth == 0.0 and pa.shape[0] == 1 and pb.shape[0] == 1:
                n = np.array([1.0, 0.0, 0.0])
            separation[p] = -depth - rad[i] - rad[j]
            normal[p], ca[p], cb[p] = n, wa, wb
        if fallback.any():
            _contact_pairs(pts, off, pr, rad, ftol, max_iter, fallback, False, separation, normal, ca, cb,
                           kind_a, kind_b, raw, start, count, status)
    point_offsets = np.zeros(k + 1, np.int64)
    np.cumsum(count, out=point_offsets[1:])
    # the rows of the points actually written: pair p's count rows from start[p]
    take = np.arange(point_offsets[-1]) + np.repeat(start[:-1] - point_offsets[:-1], count)
    return ContactBatch(separation=separation, normal=normal, feature_a=kind_a, feature_b=kind_b,
                        points=raw[take], point_offsets=point_offsets, closest_a=ca, closest_b=cb,
                        radius_a=rad[pr[:, 0]], radius_b=rad[pr[:, 1]], exact_fallback=fallback)


def contact_feature_pairs(points, offsets, pairs, *, radii=None, feature_tol: float = FEATURE_TOL) -> ContactBatch:
    """``contact_feature`` over k pairs of packed convex shapes in one compiled call.

    ``points`` (N, 3) / ``offsets`` (S + 1,) as in ``gjk_distance_pairs`` (shape s is the convex hull of
    ``points[offsets[s]:offsets[s + 1]]``), swept by a ball of ``radii[s]`` ((S,) >= 0, default 0); ``pairs``
    (k, 2) int: (shape A, shape B) per row, repeats allowed. GJK, EPA for overlapping pairs, the support sets,
    the features and their clipping all run in one compiled loop (chapter: "l'instant et le lieu précis (vertex,
    côtés, faces) de contact"; Ericson 9.5, 8.3.4, 5.1.9). Returns a ``ContactBatch``; ``batch[p]`` equals
    ``contact_feature`` on pair p. Where EPA folds on round-off (rare, see ``engine.narrowphase.epa``) the depth
    and normal of that pair come from Qhull (Python), flagged in ``exact_fallback``.
    """
    pts = as_float_array(points, "points", shape=(None, 3))
    off = check_offsets(offsets, pts.shape[0])
    s = off.shape[0] - 1
    rad = np.zeros(s) if radii is None else as_radii(radii, "radii", s, scalar=False)
    pr = check_pairs(pairs, s)
    ftol = as_positive(feature_tol, "feature_tol")
    return _contact_batch(pts, off, pr, rad, ftol, MAX_ITERATIONS)


def contact_feature(points_a, points_b, *, radius_a: float = 0.0, radius_b: float = 0.0,
                    feature_tol: float = FEATURE_TOL) -> Contact:
    """Contact normal, features and contact point(s) of two convex shapes.

    Shape A is the convex hull of ``points_a`` (n, 3) swept by a ball of ``radius_a`` >= 0 (0: a polyhedron; a
    single point with radius r: a sphere; two points: a capsule); likewise B. Works whether the shapes are apart
    (the features that face each other across the gap), touching, or overlapping (the features along EPA's
    normal). Returns a ``Contact``: ``contact_feature_pairs`` on this one pair.
    """
    pa = as_float_array(points_a, "points_a", shape=(None, 3), min_rows=1)
    pb = as_float_array(points_b, "points_b", shape=(None, 3), min_rows=1)
    ra = as_nonnegative(radius_a, "radius_a")
    rb = as_nonnegative(radius_b, "radius_b")
    ftol = as_positive(feature_tol, "feature_tol")
    off = np.array([0, pa.shape[0], pa.shape[0] + pb.shape[0]], np.int64)
    batch = _contact_batch(np.concatenate([pa, pb]), off, _ONE_PAIR, np.array([ra, rb]), ftol, MAX_ITERATIONS)
    return batch[0]


_ONE_PAIR = np.array([[0, 1]], np.int64)


# ---------------------------------------------------------------------------------------------------------------
# when: conservative advancement
# ---------------------------------------------------------------------------------------------------------------

@njit
def _pose(p0, center, v, w, t, out):
    """Vertices at time t: x(t) = c + v t + R(ω t)(x0 − c), R by Rodrigues' formula."""
    wn = math.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
    theta = wn * t
    if wn > 0.0:
        kx, ky, kz = w[0] / wn, w[1] / wn, w[2] / wn
    else:
        kx, ky, kz = 0.0, 0.0, 1.0
    cs = math.cos(theta)
    sn = math.sin(theta)
    for i in range(p0.shape[0]):
        x = p0[i, 0] - center[0]
        y = p0[i, 1] - center[1]
        z = p0[i, 2] - center[2]
        kdx = kx * x + ky * y + kz * z
        cx = ky * z - kz * y
        cy = kz * x - kx * z
        cz = kx * y - ky * x
        out[i, 0] = center[0] + v[0] * t + x * cs + cx * sn + kx * kdx * (1.0 - cs)
        out[i, 1] = center[1] + v[1] * t + y * cs + cy * sn + ky * kdx * (1.0 - cs)
        out[i, 2] = center[2] + v[2] * t + z * cs + cz * sn + kz * kdx * (1.0 - cs)


@njit
def _toi(pa, ca, va, wa, ra, pb, cb, vb, wb, rb, t_max, tol, max_iter, out):
    """Conservative advancement (Mirtich 1996). Returns a status (0 hit, 1 no hit in [0, t_max], 2 not converged,
    3 GJK failure); out[0] = t, out[1:4] = normal at t."""
    xa = np.empty_like(pa)
    xb = np.empty_like(pb)
    W = np.empty((4, 3))
    IA = np.empty(4, np.int64)
    IB = np.empty(4, np.int64)
    lam = np.empty(4)
    g = np.empty(7)
    work_i = np.empty(12, np.int64)
    work_f = np.empty(13)
    rho_a = 0.0
    for i in range(pa.shape[0]):
        rho_a = max(rho_a, math.sqrt((pa[i, 0] - ca[0]) ** 2 + (pa[i, 1] - ca[1]) ** 2 + (pa[i, 2] - ca[2]) ** 2))
    rho_b = 0.0
    for i in range(pb.shape[0]):
        rho_b = max(rho_b, math.sqrt((pb[i, 0] - cb[0]) ** 2 + (pb[i, 1] - cb[1]) ** 2 + (pb[i, 2] - cb[2]) ** 2))
    spin = math.sqrt(wa[0] ** 2 + wa[1] ** 2 + wa[2] ** 2) * rho_a + math.sqrt(wb[0] ** 2 + wb[1] ** 2
                                                                                 + wb[2] ** 2) * rho_b
    t = 0.0
    for _ in range(max_iter):
        _pose(pa, ca, va, wa, t, xa)
        _pose(pb, cb, vb, wb, t, xb)
        status, _ = _gjk(xa, xb, MAX_ITERATIONS, W, IA, IB, lam, g, work_i, work_f)
        if status == 2:
            return 3
        gap = g[6] - ra - rb
        if g[6] > 0.0:
            for c in range(3):
                out[1 + c] = (g[3 + c] - g[c]) / g[6]
        else:
            for c in range(3):
                out[1 + c] = 0.0
        if gap <= tol:
            out[0] = t
            return 0
        closing = spin
        for c in range(3):
            closing += (va[c] - vb[c]) * out[1 + c]
        if closing <= 0.0:
            out[0] = np.inf
            return 1
        t += gap / closing
        if t > t_max:
            out[0] = np.inf
            return 1
    out[0] = t
    return 2


@njit
def _toi_pairs(points, offsets, centers, velocities, spins, radii, pairs, t_max, tol, max_iter, times, status):
    out = np.empty(4)
    for p in range(pairs.shape[0]):
        i = pairs[p, 0]
        j = pairs[p, 1]
        st = _toi(points[offsets[i]:offsets[i + 1]], centers[i], velocities[i], spins[i], radii[i],
                  points[offsets[j]:offsets[j + 1]], centers[j], velocities[j], spins[j], radii[j],
                  t_max, tol, max_iter, out)
        status[p] = st
        times[p] = out[0]


def _vec(value, name):
    return as_float_array(np.zeros(3) if value is None else value, name, shape=(3,))


def time_of_impact(points_a, velocity_a, points_b, velocity_b, *, t_max: float = 1.0,
                   angular_velocity_a=None, angular_velocity_b=None, center_a=None, center_b=None,
                   radius_a: float = 0.0, radius_b: float = 0.0, tol: float | None = None,
                   max_iterations: int = 256):
    """First time t in [0, t_max] at which two moving convex shapes touch, or None.

    Shape A: convex hull of ``points_a`` (n, 3) at t = 0, swept by a ball of ``radius_a``, moving with constant
    ``velocity_a`` (3,) and spinning with ``angular_velocity_a`` (3,) (rad per unit time) about ``center_a``
    (default: the mean of its points); likewise B. Returns t (a float, within ``tol`` distance of contact — the
    shapes are at most ``tol`` apart at t and not touching before, up to that tolerance), or None when they do
    not meet before ``t_max``. ``tol`` defaults to 1e-9 × the size of the shapes. Raises ``TOINotConverged``
    after ``max_iterations`` advancement steps.
    """
    pa = as_float_array(points_a, "points_a", shape=(None, 3), min_rows=1)
    pb = as_float_array(points_b, "points_b", shape=(None, 3), min_rows=1)
    va = _vec(velocity_a, "velocity_a")
    vb = _vec(velocity_b, "velocity_b")
    wa = _vec(angular_velocity_a, "angular_velocity_a")
    wb = _vec(angular_velocity_b, "angular_velocity_b")
    ca = pa.mean(axis=0) if center_a is None else _vec(center_a, "center_a")
    cb = pb.mean(axis=0) if center_b is None else _vec(center_b, "center_b")
    ra = as_nonnegative(radius_a, "radius_a")
    rb = as_nonnegative(radius_b, "radius_b")
    tm = as_nonnegative(t_max, "t_max")
    max_iter = as_max_iterations(max_iterations)
    if tol is None:
        size = max(np.ptp(pa, axis=0).max(), np.ptp(pb, axis=0).max(), ra, rb, 1e-300)
        tol = 1e-9 * size
    tol = as_positive(tol, "tol")
    out = np.empty(4)
    status = _toi(pa, ca, va, wa, ra, pb, cb, vb, wb, rb, tm, tol, max_iter, out)
    if status == 3:
        raise RuntimeError("GJK did not converge during time_of_impact")
    if status == 2:
        raise TOINotConverged(f"conservative advancement did not reach contact in max_iterations={max_iter} steps "
                              f"(t = {out[0]!r}); raise max_iterations or tol")
    return None if status == 1 else float(out[0])


def time_of_impact_pairs(points, offsets, velocities, pairs, *, t_max: float = 1.0, angular_velocities=None,
                         centers=None, radii=None, tol: float = 1e-9, max_iterations: int = 256):
    """Conservative advancement over k pairs of packed shapes in one compiled call.

    ``points`` (N, 3) / ``offsets`` (S + 1,) as in ``gjk_distance_pairs``; ``velocities`` (S, 3), optional
    ``angular_velocities`` (S, 3), ``centers`` (S, 3) (default: each shape's mean point), ``radii`` (S,);
    ``pairs`` (k, 2). Returns times (k,), ``inf`` where the pair does not meet before ``t_max``.
    """
    pts = as_float_array(points, "points", shape=(None, 3))
    off = check_offsets(offsets, pts.shape[0])
    s = off.shape[0] - 1
    vel = as_float_array(velocities, "velocities", shape=(s, 3))
    spin = np.zeros((s, 3)) if angular_velocities is None else as_float_array(angular_velocities,
                                                                              "angular_velocities", shape=(s, 3))
    if centers is None:
        cen = np.add.reduceat(pts, off[:-1], axis=0) / np.diff(off)[:, None] if s else np.empty((0, 3))
    else:
        cen = as_float_array(centers, "centers", shape=(s, 3))
    rad = np.zeros(s) if radii is None else as_radii(radii, "radii", s, scalar=False)
    pr = check_pairs(pairs, s)
    tm = as_nonnegative(t_max, "t_max")
    tol = as_positive(tol, "tol")
    max_iter = as_max_iterations(max_iterations)
    times = np.empty(pr.shape[0])
    status = np.empty(pr.shape[0], np.int64)
    if pr.shape[0]:
        _toi_pairs(pts, off, cen, vel, spin, rad, pr, tm, tol, max_iter, times, status)
        bad = np.flatnonzero(status >= 2)
        if bad.size:
            raise TOINotConverged(f"conservative advancement did not converge for pairs[{bad[0]}]")
    return times
