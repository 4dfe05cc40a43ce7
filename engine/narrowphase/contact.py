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
from .._validate import as_float_array, as_nonnegative, as_positive
from .epa import epa_penetration
from .gjk import MAX_ITERATIONS, _as_max_iterations, _check_offsets, _gjk, check_pairs, gjk_distance

__all__ = ["Contact", "contact_feature", "time_of_impact", "time_of_impact_pairs", "TOINotConverged",
           "FEATURE_TOL"]

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

def _plane_basis(n: np.ndarray):
    """Two unit vectors u, v with (u, v, n) orthonormal."""
    k = int(np.argmin(np.abs(n)))
    e = np.zeros(3)
    e[k] = 1.0
    u = np.cross(n, e)
    u /= np.linalg.norm(u)
    return u, np.cross(n, u)


def _feature_polygon(points2d: np.ndarray, tol: float):
    """The support set projected on the contact plane, reduced to its shape: (1, 2) a vertex, (2, 2) an edge
    (its two extreme points), or (k, 2) a convex polygon in counter-clockwise order."""
    from ..bounding.hull import convex_hull

    pts = points2d
    spread = pts - pts[0]
    if np.abs(spread).max() <= tol:
        return pts[:1]
    # principal direction: extreme points along it
    _, s, vt = np.linalg.svd(pts - pts.mean(axis=0), full_matrices=False)
    along = (pts - pts.mean(axis=0)) @ vt[0]
    across = np.abs((pts - pts.mean(axis=0)) @ vt[1]) if vt.shape[0] > 1 else np.zeros(len(pts))
    if pts.shape[0] == 2 or across.max() <= tol:
        return pts[[int(np.argmin(along)), int(np.argmax(along))]]
    try:
        hull = convex_hull(pts)
    except ValueError:  # collinear to round-off: the support set is an edge
        return pts[[int(np.argmin(along)), int(np.argmax(along))]]
    return pts[hull.vertices]  # the monotone chain gives 2-D hull vertices counter-clockwise


def _cross2(a, b):
    return a[0] * b[1] - a[1] * b[0]


def _clip_polygon(subject: np.ndarray, clip: np.ndarray) -> np.ndarray:
    """Sutherland–Hodgman: the part of polygon ``subject`` (k, 2) inside the convex CCW polygon ``clip`` (m, 2)."""
    out = subject
    m = clip.shape[0]
    for e in range(m):
        a = clip[e]
        b = clip[(e + 1) % m]
        edge = b - a
        inp = out
        if inp.shape[0] == 0:
            break
        res = []
        for i in range(inp.shape[0]):
            p = inp[i]
            q = inp[(i + 1) % inp.shape[0]]
            sp = _cross2(edge, p - a)
            sq = _cross2(edge, q - a)
            if sp >= 0.0:
                res.append(p)
            if (sp >= 0.0) != (sq >= 0.0):
                t = sp / (sp - sq)
                res.append(p + t * (q - p))
        out = np.array(res).reshape(-1, 2)
    return out


def _clip_segment(p: np.ndarray, q: np.ndarray, clip: np.ndarray):
    """Cyrus–Beck: the part of segment [p, q] inside the convex CCW polygon ``clip``; None if empty."""
    t0, t1 = 0.0, 1.0
    d = q - p
    m = clip.shape[0]
    for e in range(m):
        a = clip[e]
        edge = clip[(e + 1) % m] - a
        num = _cross2(edge, p - a)  # >= 0 inside
        den = _cross2(edge, d)
        if den == 0.0:
            if num < 0.0:
                return None
            continue
        t = -num / den
        if den > 0.0:
            t0 = max(t0, t)
        else:
            t1 = min(t1, t)
        if t0 > t1:
            return None
    return np.array([p + t0 * d, p + t1 * d])


def _closest_segments_2d(p1, q1, p2, q2, tol):
    """Contact points of two projected edges: their crossing, or the overlap of parallel edges (Ericson 5.1.9)."""
    d1 = q1 - p1
    d2 = q2 - p2
    den = _cross2(d1, d2)
    scale = max(np.linalg.norm(d1) * np.linalg.norm(d2), 1e-300)
    if abs(den) > 1e-9 * scale:
        s = _cross2(p2 - p1, d2) / den
        return (p1 + np.clip(s, 0.0, 1.0) * d1)[None, :]
    # parallel: the overlap of the two intervals along d1
    u = d1 / max(np.linalg.norm(d1), 1e-300)
    a0, a1 = 0.0, float(d1 @ u)
    b0, b1 = sorted((float((p2 - p1) @ u), float((q2 - p1) @ u)))
    lo, hi = max(a0, b0), min(a1, b1)
    if lo > hi:  # should not happen for facing features; keep the nearest end
        lo = hi = (a1 if b0 > a1 else a0)
    if hi - lo <= tol:
        return (p1 + 0.5 * (lo + hi) * u)[None, :]
    return np.array([p1 + lo * u, p1 + hi * u])


def _contact_points(fa: np.ndarray, fb: np.ndarray, tol: float) -> np.ndarray:
    """Intersection of two projected features (vertex (1, 2), edge (2, 2), polygon (k, 2))."""
    na, nb = fa.shape[0], fb.shape[0]
    if na == 1:
        return fa.copy()
    if nb == 1:
        return fb.copy()
    if na == 2 and nb == 2:
        return _closest_segments_2d(fa[0], fa[1], fb[0], fb[1], tol)
    if na == 2:
        seg = _clip_segment(fa[0], fa[1], fb)
        return seg if seg is not None else np.empty((0, 2))
    if nb == 2:
        seg = _clip_segment(fb[0], fb[1], fa)
        return seg if seg is not None else np.empty((0, 2))
    return _clip_polygon(fa, fb)


def _dedupe(points: np.ndarray, tol: float) -> np.ndarray:
    keep = []
    for p in points:
        if all(np.linalg.norm(p - q) > tol for q in keep):
            keep.append(p)
    return np.array(keep).reshape(-1, points.shape[1])


def contact_feature(points_a, points_b, *, radius_a: float = 0.0, radius_b: float = 0.0,
                    feature_tol: float = FEATURE_TOL) -> Contact:
    """Contact normal, features and contact point(s) of two convex shapes.

    Shape A is the convex hull of ``points_a`` (n, 3) swept by a ball of ``radius_a`` >= 0 (0: a polyhedron; a
    single point with radius r: a sphere; two points: a capsule); likewise B. Works whether the shapes are apart
    (the features that face each other across the gap), touching, or overlapping (the features along EPA's
    normal). Returns a ``Contact``.
    """
    pa = as_float_array(points_a, "points_a", shape=(None, 3), min_rows=1)
    pb = as_float_array(points_b, "points_b", shape=(None, 3), min_rows=1)
    ra = as_nonnegative(radius_a, "radius_a")
    rb = as_nonnegative(radius_b, "radius_b")
    ftol = as_positive(feature_tol, "feature_tol")
    d, ca, cb = gjk_distance(pa, pb)
    if d > 0.0:
        n = (cb - ca) / d
        separation = d - ra - rb
    else:
        depth, n, ca, cb = epa_penetration(pa, pb, witnesses=True)
        separation = -depth - ra - rb
        if depth == 0.0 and pa.shape[0] == 1 and pb.shape[0] == 1:
            n = np.array([1.0, 0.0, 0.0])  # two coincident points: any direction
    size = max(np.ptp(np.concatenate([pa, pb]), axis=0).max(), ra + rb, 1e-300)
    tol = ftol * size
    ha = pa @ n
    hb = pb @ n
    top_a = ha.max()
    bot_b = hb.min()
    sa = pa[ha >= top_a - tol]
    sb = pb[hb <= bot_b + tol]
    u, v = _plane_basis(n)
    basis = np.stack([u, v], axis=1)
    fa = _feature_polygon(sa @ basis, tol)
    fb = _feature_polygon(sb @ basis, tol)
    pts2 = _contact_points(fa, fb, tol)
    if pts2.shape[0] == 0:  # round-off left no overlap: fall back on the closest points
        pts2 = (0.5 * (ca + cb) @ basis)[None, :]
    pts2 = _dedupe(pts2, tol)
    mid = 0.5 * ((top_a + ra) + (bot_b - rb))
    points = pts2 @ basis.T + mid * n
    names_a = _ROUND_NAMES if ra > 0 else _NAMES
    names_b = _ROUND_NAMES if rb > 0 else _NAMES
    feature_a = names_a[min(fa.shape[0], 3)]
    feature_b = names_b[min(fb.shape[0], 3)]
    return Contact(separation=float(separation), normal=n, feature_a=feature_a, feature_b=feature_b,
                   kind=f"{feature_a}-{feature_b}", points=points, closest_a=ca + ra * n, closest_b=cb - rb * n)


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
    max_iter = _as_max_iterations(max_iterations)
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
    off = _check_offsets(offsets, pts.shape[0])
    s = off.shape[0] - 1
    vel = as_float_array(velocities, "velocities", shape=(s, 3))
    spin = np.zeros((s, 3)) if angular_velocities is None else as_float_array(angular_velocities,
                                                                              "angular_velocities", shape=(s, 3))
    if centers is None:
        cen = np.add.reduceat(pts, off[:-1], axis=0) / np.diff(off)[:, None] if s else np.empty((0, 3))
    else:
        cen = as_float_array(centers, "centers", shape=(s, 3))
    rad = np.zeros(s) if radii is None else as_float_array(radii, "radii", shape=(s,))
    if (rad < 0).any():
        i = int(np.argmax(rad < 0))
        raise ValueError(f"radii must be >= 0: radii[{i}] = {rad[i]!r}")
    pr = check_pairs(pairs, s)
    tm = as_nonnegative(t_max, "t_max")
    tol = as_positive(tol, "tol")
    max_iter = _as_max_iterations(max_iterations)
    times = np.empty(pr.shape[0])
    status = np.empty(pr.shape[0], np.int64)
    if pr.shape[0]:
        _toi_pairs(pts, off, cen, vel, spin, rad, pr, tm, tol, max_iter, times, status)
        bad = np.flatnonzero(status >= 2)
        if bad.size:
            raise TOINotConverged(f"conservative advancement did not converge for pairs[{bad[0]}]")
    return times
