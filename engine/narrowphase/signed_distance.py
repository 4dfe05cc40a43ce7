"""Signed distance of two shapes and its witness points, batched over pairs: the World's "distance" question.

One answer per pair p (``DistanceRows``): ``distance[p]`` > 0 the gap when apart, 0 touching, −depth when they
overlap; ``point_a[p]``, ``point_b[p]`` on the surfaces of the pair's first and second shape — the closest points
when apart, the deepest points when overlapping — with ``point_b − point_a = distance · normal`` and ``normal[p]``
a unit vector from the first shape towards the second (the contact kernels' convention: moving the second shape
by depth · normal separates an overlapping pair).

- ``witnesses_from_contact``: a contact row whose point 0 lies halfway between the two surfaces along the normal
  (the closed forms of sphere–sphere, sphere–capsule, capsule–capsule: Ericson 5.1.9; sphere–box: Ericson 5.1.3;
  a body on a ``HeightCurve``) gives both witnesses: point 0 ∓ distance / 2 · normal;
- ``distance_plane``: a body's core points swept by r against a plane: the lowest core point minus r along the
  plane's normal (the chapter's "sol plat"), exact;
- ``convex_distance_rows``: convex cores swept by balls with no closed form, GJK distance when the cores are apart,
  EPA depth when they overlap (engine.narrowphase.penetration, the chain with its exact fallback), the radii added
  along the normal (Ericson 4.5: a swept core's distance is its core's minus the radii);
- ``curve_distance_rows``: a body against a curved ground y <= f(x) (z-extruded): when it overlaps, the contact of
  engine.narrowphase.curve_ground (its depth); when apart, the distance of the core to the vertical lines through
  points (x, f(x)) of the curve, sampled, then refined by golden-section search (a bump of f narrower than the
  sample spacing can be missed, as in ``ground_gap``).

A pair's sign always follows the overlap test of its cell (``sign_like_overlap``): distance <= 0 exactly when
the overlap question says touching, so ``World.pairs_within(0)`` and ``World.pairs()`` agree to the bit.
"""
from __future__ import annotations

from collections import namedtuple

import numpy as np

from .._config import njit
from .contacts import contact_rows
from .convex_cores import pack_cores
from .curve_ground import GOLDEN_STEPS, curve_contact_rows, curve_overlap, ground_gap, lower_boundary
from .gjk import MAX_ITERATIONS, gjk_distance_pairs
from .penetration import penetration_pairs

__all__ = ["DistanceRows", "distance_rows", "witnesses_from_contact", "distance_plane", "convex_distance_rows",
           "sign_like_overlap", "curve_distance_rows", "SMALLEST_GAP"]

#: the per-pair answer of the distance question: ``distance`` (k,), ``normal``, ``point_a``, ``point_b`` (k, 3)
DistanceRows = namedtuple("DistanceRows", "distance normal point_a point_b")

#: the distance given to a pair that its overlap test finds apart while the distance computation rounds to 0
SMALLEST_GAP = float(np.nextafter(0.0, 1.0))


def distance_rows(k: int) -> DistanceRows:
    """Fresh DistanceRows for k pairs (distance inf, NaN points: rows no kernel wrote stand out)."""
    return DistanceRows(np.full(k, np.inf), np.full((k, 3), np.nan), np.full((k, 3), np.nan),
                        np.full((k, 3), np.nan))


@njit
def witnesses_from_contact(rows, sel, out):
    """Rows ``sel`` of ``out`` from the same rows of the ContactRows ``rows``, whose point 0 is halfway between
    the two surfaces along the normal: distance = separation, point_a / point_b = point 0 ∓ separation / 2 ·
    normal (the normal runs from the pair's first shape to its second)."""
    for p in sel:
        s = rows.separation[p]
        out.distance[p] = s
        for c in range(3):
            n = rows.normal[p, c]
            out.normal[p, c] = n
            out.point_a[p, c] = rows.points[p, 0, c] - 0.5 * s * n
            out.point_b[p, c] = rows.points[p, 0, c] + 0.5 * s * n


@njit
def distance_plane(points, counts, radii, i, origin, up, out, p, flip):
    """Body i — core ``points[i, :counts[i]]`` swept by ``radii[i]`` — against the ground through ``origin`` of
    outward unit normal ``up`` into row p of ``out`` (``flip``: the pair's first shape is the ground). The depth
    is the one of engine.narrowphase.plane.contact_points_plane, computed the same way (max over the core points
    of (o − v)·u + r): its lowest point v gives the body's witness v − r u, and the ground's is that point moved
    by the depth along u (onto the plane). Returns the distance."""
    radius = radii[i]
    depth = -np.inf
    low = 0
    for v in range(counts[i]):
        h = ((origin[0] - points[i, v, 0]) * up[0] + (origin[1] - points[i, v, 1]) * up[1]
             + (origin[2] - points[i, v, 2]) * up[2]) + radius
        if h > depth:
            depth, low = h, v
    sign = 1.0 if flip else -1.0  # from the pair's first shape to its second: −u from the body to the ground
    body, ground = (out.point_b, out.point_a) if flip else (out.point_a, out.point_b)
    out.distance[p] = -depth
    for c in range(3):
        out.normal[p, c] = sign * up[c]
        body[p, c] = points[i, low, c] - radius * up[c]
        ground[p, c] = body[p, c] + depth * up[c]
    return -depth


def sign_like_overlap(out, sel, touching) -> None:
    """Make rows ``sel`` of ``out`` agree with the overlap test's verdict ``touching`` (bool, one per row): a
    touching pair's distance is at most 0, an apart pair's at least ``SMALLEST_GAP`` (the two computations differ
    only by round-off near contact)."""
    d = out.distance[sel]
    out.distance[sel] = np.where(touching, np.minimum(d, 0.0), np.maximum(d, SMALLEST_GAP))


def convex_distance_rows(cores, pairs, sel, out) -> np.ndarray:
    """Rows ``sel`` of ``out`` for the pairs ``pairs[sel]`` of convex cores (engine.narrowphase.convex_cores.
    Cores): the penetration chain on the cores (GJK distance apart, EPA depth overlapping, Qhull where EPA
    folds), then the radii: distance = core distance − r_a − r_b, point_a = core point + r_a n, point_b = core
    point − r_b n. Returns the cores' GJK distance (0 when they overlap), what the overlap test reads."""
    pr = pairs[sel]
    if pr.shape[0] == 0:
        return np.empty(0)
    points, offsets, local, radii = pack_cores(cores, pr)
    signed, normal, ca, cb = penetration_pairs(points, offsets, local, MAX_ITERATIONS)[:4]
    ra, rb = radii[local[:, 0]], radii[local[:, 1]]
    out.distance[sel] = signed - ra - rb
    out.normal[sel] = normal
    out.point_a[sel] = ca + ra[:, None] * normal
    out.point_b[sel] = cb - rb[:, None] * normal
    return np.maximum(signed, 0.0)


def _vertical_line_distances(core, z_lo, z_hi, rows, x, height):
    """GJK distance of each body's core ``core[rows]`` ((q, M, 3) points) to the vertical segment through
    (x, height(x)) spanning [z_lo, z_hi] of that body: (distance (q,), core point (q, 3), segment point (q, 3))."""
    q, m = rows.shape[0], core.shape[1]
    y = height(x)
    seg = np.empty((q, 2, 3))
    seg[:, :, 0], seg[:, :, 1] = x[:, None], y[:, None]
    seg[:, 0, 2], seg[:, 1, 2] = z_lo[rows], z_hi[rows]
    points = np.concatenate([core[rows].reshape(-1, 3), seg.reshape(-1, 3)])
    offsets = np.concatenate([np.arange(q + 1) * m, q * m + 2 * np.arange(1, q + 1)]).astype(np.int64)
    pairs = np.stack([np.arange(q), q + np.arange(q)], axis=1).astype(np.int64)
    return gjk_distance_pairs(points, offsets, pairs)


def _curve_gaps(curve, core, radius):
    """For bodies apart from the curve (core points (k, M, 3) swept by ``radius`` (k,)): the core's distance to
    the ground and the two closest points (k, 3) each, body first. The closest ground point lies within the
    core's vertical gap (an upper bound of the distance) of its x-range: that window is sampled, then the lowest
    sample refined by golden-section search over its two neighbouring intervals."""
    k = core.shape[0]
    gap = ground_gap(curve, lower_boundary(core, radius, curve.samples))[0]
    reach = np.maximum(gap, 0.0) + radius
    x0, x1 = core[:, :, 0].min(axis=1) - reach, core[:, :, 0].max(axis=1) + reach
    z_lo, z_hi = core[:, :, 2].min(axis=1) - 1.0, core[:, :, 2].max(axis=1) + 1.0
    n = max(curve.samples, 16)
    xs = x0[:, None] + np.linspace(0.0, 1.0, n)[None, :] * (x1 - x0)[:, None]
    r = np.arange(k)
    rows = np.repeat(r, n)
    d = _vertical_line_distances(core, z_lo, z_hi, rows, xs.ravel(), curve.height)[0].reshape(k, n)
    i = np.argmin(d, axis=1)
    best_d, best_x = d[r, i], xs[r, i]
    a, b = xs[r, np.maximum(i - 1, 0)], xs[r, np.minimum(i + 1, n - 1)]
    phi = (np.sqrt(5.0) - 1.0) / 2.0
    for _ in range(GOLDEN_STEPS):
        c = b - phi * (b - a)
        e = a + phi * (b - a)
        dc, de = np.split(_vertical_line_distances(core, z_lo, z_hi, np.concatenate([r, r]), np.concatenate([c, e]),
                                                   curve.height)[0], 2)
        for xq, dq in ((c, dc), (e, de)):  # keep the nearest point seen
            better = dq < best_d
            best_d, best_x = np.where(better, dq, best_d), np.where(better, xq, best_x)
        left = dc <= de
        b, a = np.where(left, e, b), np.where(left, a, c)
    return _vertical_line_distances(core, z_lo, z_hi, r, best_x, curve.height)


def curve_distance_rows(curve, points, radius, centers, is_sphere, ground_first, out, sel) -> None:
    """Rows ``sel`` (k,) of ``out`` for k bodies (core points (k, M, 3), rows past a body's count repeating its
    first point, swept by ``radius`` (k,), centres (k, 3), ``is_sphere`` (k,)) against the curve;
    ``ground_first`` (k,): the pair's first shape is the curve. Touching (``curve_overlap``, the overlap
    question's test): the contact of ``curve_contact_rows`` (distance −depth, witnesses about its point);
    apart: the core's distance to the ground minus the radius, its closest points moved out by the radius."""
    if sel.size == 0:
        return
    hit = curve_overlap(curve, points, radius, centers, is_sphere)
    if hit.any():
        rows = contact_rows(int(hit.sum()))
        at = np.arange(rows.status.shape[0])
        curve_contact_rows(curve, points[hit], radius[hit], centers[hit], ground_first[hit], rows, at)
        sub = distance_rows(at.shape[0])
        witnesses_from_contact(rows, at, sub)
        for name in DistanceRows._fields:
            getattr(out, name)[sel[hit]] = getattr(sub, name)
    apart = ~hit
    if apart.any():
        core, r, first = points[apart], radius[apart], ground_first[apart]
        d, on_body, on_ground = _curve_gaps(curve, core, r)
        normal = on_ground - on_body
        length = np.linalg.norm(normal, axis=1)
        normal = normal / np.where(length > 0.0, length, 1.0)[:, None]
        surface = on_body + r[:, None] * normal
        rows_of = sel[apart]
        out.distance[rows_of] = np.maximum(d - r, SMALLEST_GAP)  # the overlap test found it apart
        out.normal[rows_of] = np.where(first[:, None], -normal, normal)
        out.point_a[rows_of] = np.where(first[:, None], on_ground, surface)
        out.point_b[rows_of] = np.where(first[:, None], surface, on_ground)
