"""The narrow-phase dispatch table: (shape kind, shape kind) -> one batched exact test, in ONE place.

As in Box2D (``b2_registers`` in ``contact.c``), parry (``DefaultQueryDispatcher``) and Jolt
(``CollisionDispatch``): the candidate pairs of the broad phase are grouped by the kinds of their two shapes and
each group is answered by a single call of a batched test of engine.narrowphase — no per-pair Python loop. Adding
a shape kind is one row per kind it can meet.

Rows are keyed (kind_a, kind_b) with kind_a <= kind_b (codes of engine/world/shapes.py); a row function receives
the ``Geometry`` of the world and the body ids ``ia``, ``ib`` (k,) of the group (``ia`` of kind_a) and returns a
bool (k,) array: do the two shapes overlap (closed: touching counts)?

- sphere–sphere, sphere–box (OBB), sphere–capsule, box–box (SAT, Ericson 4.4.1): the exact primitive tests;
- every other pair of bodies: GJK distance between the cores (Ericson 9.5) <= r_a + r_b (the radii of the swept
  cores: sphere and capsule radius, 0 for boxes and hulls);
- a body against ``Plane``: its lowest point (support in −y) is not above the altitude (slide "sol plat");
- a sphere against ``HeightCurve``: ``overlap_circle_curve`` in the x–y plane (exact for a z-extruded ground:
  the sphere's widest section is the disc at its centre's z);
- another body against ``HeightCurve``: the lowest value of y − f(x) over the body's lower boundary in the x–y
  plane, sampled at the support points of ``samples`` directions pointing down (every vertex of a polytope whose
  normal cone is wider than π/samples is hit exactly) and at 4 points on each chord between them (slide
  "Sol courbe"; a bump of f narrower than the sample spacing can be missed — raise ``samples``).
"""
from __future__ import annotations

import numpy as np

from engine.narrowphase import (
    gjk_distance_pairs,
    overlap_circle_curve,
    overlap_obb_obb_batch,
    overlap_sphere_capsule_batch,
    overlap_sphere_obb_batch,
    overlap_sphere_sphere_batch,
)

from .shapes import BOX, CAPSULE, CURVE, HULL, PLANE, SPHERE

__all__ = ["NARROW_TESTS", "overlap_groups", "lower_boundary", "ground_gap"]


# ---------------------------------------------------------------------------------------------------------------
# body-body rows
# ---------------------------------------------------------------------------------------------------------------

def overlap_sphere_sphere_rows(geo, ia, ib):
    return overlap_sphere_sphere_batch(geo.center, geo.radius, geo.center, geo.radius, ia, ib)


def overlap_sphere_box_rows(geo, ia, ib):
    # engine's OBB convention: rows are the axes, so pass rotation^T
    return overlap_sphere_obb_batch(geo.center, geo.radius, geo.center, geo.axes_rows, geo.half, ia, ib)


def overlap_sphere_capsule_rows(geo, ia, ib):
    p0, p1 = geo.segment_ends
    return overlap_sphere_capsule_batch(geo.center, geo.radius, p0, p1, geo.radius, ia, ib)


def overlap_box_box_rows(geo, ia, ib):
    return overlap_obb_obb_batch(geo.center, geo.axes_rows, geo.half, geo.center, geo.axes_rows, geo.half, ia, ib)


def overlap_gjk_rows(geo, ia, ib):
    dist, _, _ = gjk_distance_pairs(geo.points, geo.offsets, np.stack([ia, ib], axis=1))
    return dist <= geo.radius[ia] + geo.radius[ib]


# ---------------------------------------------------------------------------------------------------------------
# body-ground rows (ib holds ground ids; grouped per ground, a handful of calls)
# ---------------------------------------------------------------------------------------------------------------

def _per_ground(geo, ia, ib, test):
    out = np.zeros(ia.shape[0], np.bool_)
    for g in np.unique(ib).tolist():
        rows = np.flatnonzero(ib == g)
        out[rows] = test(geo.grounds[g], ia[rows])
    return out


def overlap_body_plane_rows(geo, ia, ib):
    return _per_ground(geo, ia, ib, lambda plane, bodies: geo.lowest_y(bodies) <= plane.altitude)


def overlap_sphere_curve_rows(geo, ia, ib):
    return _per_ground(geo, ia, ib, lambda curve, bodies: overlap_circle_curve(
        geo.center[bodies, :2], geo.radius[bodies], curve.f, samples=curve.samples))


def lower_boundary(geo, bodies, samples: int) -> np.ndarray:
    """Points (k, S, 2) on the lower boundary (x–y plane) of each body: supports in ``samples`` directions
    pointing down, plus 4 points on each chord between consecutive supports."""
    theta = np.linspace(np.pi, 2 * np.pi, samples)
    d = np.stack([np.cos(theta), np.sin(theta)], axis=1)  # (K, 2)
    wp = geo.padded_points[bodies][:, :, :2]  # (k, M, 2)
    best = np.argmax(np.einsum("kmc,dc->kdm", wp, d), axis=2)  # (k, K)
    sup = np.take_along_axis(wp, best[:, :, None], axis=1) + geo.radius[bodies][:, None, None] * d[None]
    s = np.linspace(0.0, 1.0, 5)[:-1]
    chords = sup[:, :-1, None, :] + s[None, None, :, None] * (sup[:, 1:, None, :] - sup[:, :-1, None, :])
    return np.concatenate([chords.reshape(len(bodies), -1, 2), sup[:, -1:, :]], axis=1)


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


def overlap_body_curve_rows(geo, ia, ib):
    def test(curve, bodies):
        gap = ground_gap(curve, lower_boundary(geo, bodies, curve.samples))[0]
        return gap <= 0.0
    return _per_ground(geo, ia, ib, test)


#: (kind_a, kind_b) with kind_a <= kind_b -> batched test; ground-ground pairs are never tested
NARROW_TESTS = {
    (SPHERE, SPHERE): overlap_sphere_sphere_rows,
    (SPHERE, BOX): overlap_sphere_box_rows,
    (SPHERE, CAPSULE): overlap_sphere_capsule_rows,
    (SPHERE, HULL): overlap_gjk_rows,
    (BOX, BOX): overlap_box_box_rows,
    (BOX, CAPSULE): overlap_gjk_rows,
    (BOX, HULL): overlap_gjk_rows,
    (CAPSULE, CAPSULE): overlap_gjk_rows,
    (CAPSULE, HULL): overlap_gjk_rows,
    (HULL, HULL): overlap_gjk_rows,
    (SPHERE, PLANE): overlap_body_plane_rows,
    (BOX, PLANE): overlap_body_plane_rows,
    (CAPSULE, PLANE): overlap_body_plane_rows,
    (HULL, PLANE): overlap_body_plane_rows,
    (SPHERE, CURVE): overlap_sphere_curve_rows,
    (BOX, CURVE): overlap_body_curve_rows,
    (CAPSULE, CURVE): overlap_body_curve_rows,
    (HULL, CURVE): overlap_body_curve_rows,
}


def overlap_groups(geo, pairs: np.ndarray, table=None):
    """Exact overlap of candidate pairs (k, 2) of ids: group by kind pair, one batched call per group.

    Returns ``(mask (k,), groups)`` with ``groups`` a dict {(kind_a, kind_b): number of pairs tested}.
    """
    table = NARROW_TESTS if table is None else table
    k = pairs.shape[0]
    mask = np.zeros(k, np.bool_)
    groups: dict = {}
    if k == 0:
        return mask, groups
    ka = geo.kind[pairs[:, 0]].astype(np.int64)
    kb = geo.kind[pairs[:, 1]].astype(np.int64)
    swap = ka > kb
    first = np.where(swap, pairs[:, 1], pairs[:, 0])
    second = np.where(swap, pairs[:, 0], pairs[:, 1])
    code = np.minimum(ka, kb) * 8 + np.maximum(ka, kb)
    order = np.argsort(code, kind="stable")
    codes, starts = np.unique(code[order], return_index=True)
    bounds = np.append(starts, k)
    for c, s, e in zip(codes.tolist(), bounds[:-1].tolist(), bounds[1:].tolist()):
        rows = order[s:e]
        key = (c // 8, c % 8)
        if key not in table:
            raise KeyError(f"no narrow test for the shape kinds {key}")
        mask[rows] = table[key](geo, first[rows], second[rows])
        groups[key] = e - s
    return mask, groups
