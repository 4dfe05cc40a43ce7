"""A convex body against a curved ground (slide "Sol courbe": y <= f(x), extruded along z), vectorised over the
bodies with numpy (f is a Python callable, evaluated on arrays).

The ground is any object with ``f`` (vectorised y = f(x)), ``samples`` (an int), ``height(x)`` (f checked
finite) and ``slope(x)``: engine.world's ``HeightCurve``. The bodies come as arrays: their world core points
(k, M, 3) (rows past a body's own count repeating its first point), radii (k,), centres (k, 3).

- candidates: the bodies' AABBs against the curve (engine.narrowphase.overlap_aabb_curve);
- overlap of a sphere: ``overlap_circle_curve`` in the x–y plane (exact for a z-extruded ground: the sphere's
  widest section is the disc at its centre's z);
- overlap of another body: the lowest value of y − f(x) over the body's lower boundary in the x–y plane
  (``lower_boundary``: the support points of ``samples`` directions pointing down, so every vertex of a
  polytope whose normal cone is wider than π/samples is hit exactly, and 4 points on each chord between them),
  minimised by ``ground_gap`` (a bump of f narrower than the sample spacing can be missed — raise ``samples``);
- contact: the deepest point of that lower boundary under f: normal (−f'(x), 1) (towards the body), depth
  −gap · n_y, one point halfway;
- time of impact: the sampled gap at ``steps`` times brackets the first sign change, then Algorithme 3
  (bisection), vectorised over the bodies.
"""
from __future__ import annotations

import numpy as np

from .contacts import FACE, TOUCHING, VERTEX, feature_key, point_id
from .primitives import overlap_aabb_curve, overlap_circle_curve

__all__ = ["lower_boundary", "ground_gap", "GOLDEN_STEPS", "curve_candidates", "curve_overlap",
           "curve_contact_rows", "curve_impact_times"]


def lower_boundary(points, radius, samples: int) -> np.ndarray:
    """Points (k, S, 2) on the lower boundary (x–y plane) of each body, from its world core points (k, M, 3)
    (rows past a body's count repeating its first point) swept by ``radius`` (k,): supports in ``samples``
    directions pointing down, plus 4 points on each chord between consecutive supports."""
    theta = np.linspace(np.pi, 2 * np.pi, samples)
    d = np.stack([np.cos(theta), np.sin(theta)], axis=1)  # (K, 2)
    wp = points[:, :, :2]  # (k, M, 2)
    best = np.argmax(np.einsum("kmc,dc->kdm", wp, d), axis=2)  # (k, K)
    sup = np.take_along_axis(wp, best[:, :, None], axis=1) + radius[:, None, None] * d[None]
    s = np.linspace(0.0, 1.0, 5)[:-1]
    chords = sup[:, :-1, None, :] + s[None, None, :, None] * (sup[:, 1:, None, :] - sup[:, :-1, None, :])
    return np.concatenate([chords.reshape(points.shape[0], -1, 2), sup[:, -1:, :]], axis=1)


#: golden-section steps refining the lowest point of a body's lower boundary over a curve (0.618^40 ≈ 4e-9 of
#: the two sample intervals around it)
GOLDEN_STEPS = 40


def _chord_heights(bx, by):
    """The heights L(rows, x) on the chords through each row's boundary points: ``bx``, ``by`` (k, S) increasing
    in x per row; the returned function takes ``rows`` (q,) and ``x`` (q,). One np.interp for every row: row r's
    abscissae are mapped to u = 2r + (x − x_first) / width (rows then occupy disjoint, increasing stretches of u)."""
    k = bx.shape[0]
    x0 = bx[:, 0]
    width = bx[:, -1] - x0
    span = np.where(width > 0, width, 1.0)
    u_nodes = (2.0 * np.arange(k)[:, None] + (bx - x0[:, None]) / span[:, None]).ravel()
    y_nodes = by.ravel()

    def heights(rows, x):
        return np.interp(2.0 * rows + (x - x0[rows]) / span[rows], u_nodes, y_nodes)
    return heights


def ground_gap(curve, boundary) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """min of L(x) − f(x) over each body's lower boundary L, and where: ``(gap (k,), x (k,), y (k,))``.

    ``boundary`` (k, S, 2) holds points of each body's lower boundary in increasing x (``lower_boundary``); L is
    the broken line through them (exact for polytopes, inside a rounded shape by at most its chords' sagitta).
    L − f is sampled at S abscissae evenly spaced over the body's width plus the boundary points themselves (its
    kinks), then the lowest sample is refined by golden-section search over its two neighbouring intervals — a
    sampled gap alone missed a crest of f between two corners of a long bottom face.
    """
    k, n_pts, _ = boundary.shape
    if k == 0:  # no body: no gap (np.interp refuses an empty table)
        return np.empty(0), np.empty(0), np.empty(0)
    bx = np.maximum.accumulate(boundary[:, :, 0], axis=1)  # increasing (round-off of the supports aside)
    by = boundary[:, :, 1]
    x0, x1 = bx[:, 0], bx[:, -1]
    t = np.linspace(0.0, 1.0, n_pts)
    xs = np.sort(np.concatenate([x0[:, None] + t[None, :] * (x1 - x0)[:, None], bx], axis=1), axis=1)
    xs = np.clip(xs, x0[:, None], x1[:, None])
    chord = _chord_heights(bx, by)
    rows = np.repeat(np.arange(k), xs.shape[1])
    g = (chord(rows, xs.ravel()) - curve.height(xs.ravel())).reshape(k, -1)
    i = np.argmin(g, axis=1)
    r = np.arange(k)
    best_g, best_x = g[r, i], xs[r, i]
    a = xs[r, np.maximum(i - 1, 0)]
    b = xs[r, np.minimum(i + 1, xs.shape[1] - 1)]
    phi = (np.sqrt(5.0) - 1.0) / 2.0
    for _ in range(GOLDEN_STEPS):
        c = b - phi * (b - a)
        d = a + phi * (b - a)
        both = np.concatenate([c, d])
        gc, gd = np.split(chord(np.concatenate([r, r]), both) - curve.height(both), 2)
        for xq, gq in ((c, gc), (d, gd)):  # keep the lowest point seen (the search may only improve it)
            better = gq < best_g
            best_g = np.where(better, gq, best_g)
            best_x = np.where(better, xq, best_x)
        left = gc <= gd
        b = np.where(left, d, b)
        a = np.where(left, a, c)
    return best_g, best_x, chord(r, best_x)


def curve_candidates(curve, lo, hi) -> np.ndarray:
    """bool (n,): the AABBs [lo, hi] ((n, 3) each) that may touch the curve."""
    return overlap_aabb_curve(lo, hi, curve.f, samples=curve.samples)


def curve_overlap(curve, points, radius, centers, is_sphere) -> np.ndarray:
    """bool (k,): whether each body touches the curve — a sphere (``is_sphere``, centre ``centers`` (k, 3)) by
    its disc in the x–y plane (``overlap_circle_curve``), another body by the lowest y − f(x) over its lower
    boundary (core points ``points`` (k, M, 3) swept by ``radius`` (k,)) being <= 0."""
    hit = np.zeros(points.shape[0], np.bool_)
    if is_sphere.any():
        hit[is_sphere] = overlap_circle_curve(centers[is_sphere, :2], radius[is_sphere], curve.f,
                                              samples=curve.samples)
    rest = ~is_sphere
    if rest.any():
        gap = ground_gap(curve, lower_boundary(points[rest], radius[rest], curve.samples))[0]
        hit[rest] = gap <= 0.0
    return hit


def curve_contact_rows(curve, points, radius, centers, ground_first, rows, sel) -> None:
    """Rows ``sel`` (k,) of ``rows`` for k touching bodies (core points (k, M, 3) swept by ``radius`` (k,),
    centres (k, 3)) against the curve; ``ground_first`` (k,) bool: the pair's first shape is the curve. Normal
    ±(−f'(x), 1, 0) / norm at the deepest point of the lower boundary (from the pair's first shape to its
    second), depth −gap · n_y, one point halfway between the body and the curve; ids (body vertex 0, ground
    face 0)."""
    if sel.size == 0:
        return
    gap, x, y = ground_gap(curve, lower_boundary(points, radius, curve.samples))
    slope = curve.slope(x)
    norm = np.sqrt(1 + slope ** 2)
    n2 = np.stack([-slope / norm, 1.0 / norm], axis=1)
    depth = np.maximum(-gap * n2[:, 1], 0.0)
    sign = np.where(ground_first, 1.0, -1.0)[:, None]
    rows.status[sel] = TOUCHING
    rows.separation[sel] = -depth
    rows.normal[sel] = np.concatenate([n2, np.zeros((sel.size, 1))], axis=1) * sign
    rows.feature_a[sel] = np.where(ground_first, FACE, VERTEX)
    rows.feature_b[sel] = np.where(ground_first, VERTEX, FACE)
    rows.count[sel] = 1
    rows.points[sel, 0] = np.stack([x + 0.5 * depth * n2[:, 0], y + 0.5 * depth * n2[:, 1], centers[:, 2]],
                                   axis=1)
    body_key, ground_key = feature_key(VERTEX, 0), feature_key(FACE, 0)  # body vertex 0, ground face 0
    rows.ids[sel, 0] = np.where(ground_first, point_id(ground_key, body_key), point_id(body_key, ground_key))


def curve_impact_times(curve, points, radius, velocity, dt, steps: int = 32, iterations: int = 60) -> np.ndarray:
    """First t in [0, dt] at which each body (core points (k, M, 3) swept by ``radius`` (k,), translating with
    ``velocity`` (k, 3)) touches the curve; inf if none. The sampled gap at ``steps`` times brackets the first
    sign change, then Algorithme 3 (bisection)."""
    v = velocity
    bnd = lower_boundary(points, radius, curve.samples)  # (k, S, 2)
    k = points.shape[0]
    t_hit = np.full(k, np.inf)
    t_hit[ground_gap(curve, bnd)[0] <= 0] = 0.0
    lo_t = np.zeros(k)
    hi_t = np.full(k, np.nan)
    for s in range(1, steps + 1):
        pending = np.flatnonzero(np.isinf(t_hit) & np.isnan(hi_t))
        if not pending.size:
            break
        t = dt * s / steps
        crossed = pending[ground_gap(curve, bnd[pending] + t * v[pending, None, :2])[0] <= 0]
        hi_t[crossed] = t
        lo_t[crossed] = dt * (s - 1) / steps
    todo = np.flatnonzero(~np.isnan(hi_t))
    a, b = lo_t[todo], hi_t[todo]
    sub, vs = bnd[todo], v[todo]
    for _ in range(iterations):  # Algorithme 3: keep the half whose ends have opposite signs
        m = 0.5 * (a + b)
        inside = ground_gap(curve, sub + m[:, None, None] * vs[:, None, :2])[0] <= 0
        b = np.where(inside, m, b)
        a = np.where(inside, a, m)
    t_hit[todo] = b
    return t_hit
