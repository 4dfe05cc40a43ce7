"""Batched narrow-phase forms against their single-pair forms and independent oracles.

- ``contact_feature_pairs``: every pair equals ``contact_feature`` on it, and the per-pair numpy reference
  below (the form ``contact_feature`` had before the compiled kernel: numpy, SVD, the engine's 2-D hull); contact
  points on the mid-plane of the two support planes, inside both features' shadows; separation = GJK distance
  (apart) or −EPA depth (overlap);
- ``overlap_convex_sat_pairs``: equals ``overlap_convex_sat``; overlap iff GJK distance 0 (outside a band), and
  coal's collide on the same hulls;
- curved ground: a batch equals one call per shape; a numba-jitted f gives exactly the Python-f path's answer;
- validation of the packed arrays.
"""
from __future__ import annotations

import numba
import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy.spatial import ConvexHull as QhullHull

from engine.bounding.hull import convex_hull
from engine.narrowphase import (
    contact_feature,
    contact_feature_pairs,
    epa_penetration,
    gjk_distance,
    max_on_intervals,
    min_distance_to_curve,
    overlap_aabb_curve,
    overlap_aabb_curve_bottom_middle,
    overlap_circle_curve,
    overlap_convex_sat,
    overlap_convex_sat_pairs,
    pack_point_sets,
)
from engine.narrowphase.box_box import FACE_KEEP_COS
from engine.narrowphase.contact_manifold import FEATURE_TOL
from properties.strategies.narrow import box_corners, hull_signed_distance, point_clouds, rotations, sizes

_NAMES = {1: "vertex", 2: "edge", 3: "face"}
_ROUND_NAMES = {1: "sphere", 2: "cylinder", 3: "face"}

# ---------------------------------------------------------------------------------------------------------------
# the reference: contact_feature as it was, per pair in numpy (helpers prefixed _ref)
# ---------------------------------------------------------------------------------------------------------------

def _ref_plane_basis(n: np.ndarray):
    """Two unit vectors u, v with (u, v, n) orthonormal."""
    k = int(np.argmin(np.abs(n)))
    e = np.zeros(3)
    e[k] = 1.0
    u = np.cross(n, e)
    u /= np.linalg.norm(u)
    return u, np.cross(n, u)


def _ref_feature_polygon(points2d: np.ndarray, tol: float):
    """The support set projected on the contact plane, reduced to its shape: (1, 2) a vertex, (2, 2) an edge
    (its two extreme points), or (k, 2) a convex polygon in counter-clockwise order."""
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


def _ref_cross2(a, b):
    return a[0] * b[1] - a[1] * b[0]


def _ref_clip_polygon(subject: np.ndarray, clip: np.ndarray) -> np.ndarray:
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
            sp = _ref_cross2(edge, p - a)
            sq = _ref_cross2(edge, q - a)
            if sp >= 0.0:
                res.append(p)
            if (sp >= 0.0) != (sq >= 0.0):
                t = sp / (sp - sq)
                res.append(p + t * (q - p))
        out = np.array(res).reshape(-1, 2)
    return out


def _ref_clip_segment(p: np.ndarray, q: np.ndarray, clip: np.ndarray):
    """Cyrus–Beck: the part of segment [p, q] inside the convex CCW polygon ``clip``; None if empty."""
    t0, t1 = 0.0, 1.0
    d = q - p
    m = clip.shape[0]
    for e in range(m):
        a = clip[e]
        edge = clip[(e + 1) % m] - a
        num = _ref_cross2(edge, p - a)  # >= 0 inside
        den = _ref_cross2(edge, d)
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


def _ref_closest_segments_2d(p1, q1, p2, q2, tol):
    """Contact points of two projected edges: their crossing, or the overlap of parallel edges (Ericson 5.1.9)."""
    d1 = q1 - p1
    d2 = q2 - p2
    den = _ref_cross2(d1, d2)
    scale = max(np.linalg.norm(d1) * np.linalg.norm(d2), 1e-300)
    if abs(den) > 1e-9 * scale:
        s = _ref_cross2(p2 - p1, d2) / den
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


def _ref_contact_points(fa: np.ndarray, fb: np.ndarray, tol: float) -> np.ndarray:
    """Intersection of two projected features (vertex (1, 2), edge (2, 2), polygon (k, 2))."""
    na, nb = fa.shape[0], fb.shape[0]
    if na == 1:
        return fa.copy()
    if nb == 1:
        return fb.copy()
    if na == 2 and nb == 2:
        return _ref_closest_segments_2d(fa[0], fa[1], fb[0], fb[1], tol)
    if na == 2:
        seg = _ref_clip_segment(fa[0], fa[1], fb)
        return seg if seg is not None else np.empty((0, 2))
    if nb == 2:
        seg = _ref_clip_segment(fb[0], fb[1], fa)
        return seg if seg is not None else np.empty((0, 2))
    return _ref_clip_polygon(fa, fb)


def _ref_dedupe(points: np.ndarray, tol: float) -> np.ndarray:
    keep = []
    for p in points:
        if all(np.linalg.norm(p - q) > tol for q in keep):
            keep.append(p)
    return np.array(keep).reshape(-1, points.shape[1])


def _face_cosines(pts, n):
    """The cosines of pts' hull face normals (outward) with n; none for a set without volume."""
    try:
        hull = QhullHull(pts)
    except Exception:  # flat or too few points: no face of a solid
        return np.zeros(0)
    return hull.equations[:, :3] @ n


def _flush_faces(pa, pb, n):
    """Whether A has a face within arccos(FACE_KEEP_COS) of n or B one within it of −n (with a margin): a superset
    of the face manifold's case (contact_manifold's face preference needs both, found by its own face search)."""
    return (_face_cosines(pa, n) >= FACE_KEEP_COS - 1e-6).any() or \
        (_face_cosines(pb, -n) >= FACE_KEEP_COS - 1e-6).any()


def _ref_contact_feature(pa, pb, ra=0.0, rb=0.0, ftol=FEATURE_TOL):
    """The per-pair numpy form that contact_feature had before the batch kernel (the reference it must match):
    returns (separation, normal, kind, points)."""
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
    u, v = _ref_plane_basis(n)
    basis = np.stack([u, v], axis=1)
    fa = _ref_feature_polygon(sa @ basis, tol)
    fb = _ref_feature_polygon(sb @ basis, tol)
    pts2 = _ref_contact_points(fa, fb, tol)
    if pts2.shape[0] == 0:  # round-off left no overlap: fall back on the closest points
        pts2 = (0.5 * (ca + cb) @ basis)[None, :]
    pts2 = _ref_dedupe(pts2, tol)
    mid = 0.5 * ((top_a + ra) + (bot_b - rb))
    points = pts2 @ basis.T + mid * n
    names_a = _ROUND_NAMES if ra > 0 else _NAMES
    names_b = _ROUND_NAMES if rb > 0 else _NAMES
    feature_a = names_a[min(fa.shape[0], 3)]
    feature_b = names_b[min(fb.shape[0], 3)]
    return float(separation), n, f"{feature_a}-{feature_b}", points


# ---------------------------------------------------------------------------------------------------------------
# strategies: mixed batches of shapes (apart, touching, overlapping, rounded)
# ---------------------------------------------------------------------------------------------------------------

@st.composite
def _shape(draw, previous):
    """One convex shape (points (n, 3), radius): a box (axis-aligned, rotated, or stacked exactly on top of a
    previous box: touching face to face), a point cloud, a point or a segment (sphere / capsule with a radius)."""
    kind = draw(st.integers(0, 5))
    rounded = draw(st.booleans())
    radius = draw(st.floats(0.05, 0.8)) if rounded else 0.0
    centre = np.array(draw(st.tuples(*[st.floats(-2.0, 2.0)] * 3)))
    if kind == 0 and previous:  # stacked on a previous axis-aligned box, touching (gap 0) or overlapping
        lo, hi = previous[draw(st.integers(0, len(previous) - 1))]
        axis = draw(st.integers(0, 2))
        size = np.array(draw(st.tuples(sizes, sizes, sizes)))
        new_lo = lo + (hi - lo) * np.array(draw(st.tuples(*[st.floats(-0.5, 0.9)] * 3)))
        new_lo[axis] = hi[axis] - draw(st.sampled_from([0.0, 0.0, 0.1, 0.3]))
        return box_corners(new_lo, new_lo + size), 0.0
    if kind <= 1:
        size = np.array(draw(st.tuples(sizes, sizes, sizes)))
        previous.append((centre - size / 2, centre + size / 2))
        return box_corners(centre - size / 2, centre + size / 2), radius if kind == 1 else 0.0
    if kind == 2:
        half = np.array(draw(st.tuples(sizes, sizes, sizes))) / 2
        corners = box_corners(-half, half) @ draw(rotations()).T + centre
        return corners, radius
    if kind == 3:
        return draw(point_clouds(spread=2.0)), radius
    if kind == 4:
        return centre[None, :], draw(st.floats(0.05, 1.0))
    end = centre + np.array(draw(st.tuples(*[st.floats(-1.5, 1.5)] * 3)))
    return np.stack([centre, end]), draw(st.floats(0.05, 1.0))


@st.composite
def shape_batches(draw, min_shapes=1, max_shapes=7):
    """(shapes, radii (S,), pairs (k, 2)): k in [0, 12], repeated rows allowed."""
    previous = []
    n = draw(st.integers(min_shapes, max_shapes))
    drawn = [draw(_shape(previous)) for _ in range(n)]
    shapes = [s for s, _ in drawn]
    radii = np.array([r for _, r in drawn])
    rows = draw(st.lists(st.tuples(st.integers(0, n - 1), st.integers(0, n - 1)), max_size=12))
    if rows and draw(st.booleans()):
        rows = rows + rows[: draw(st.integers(1, len(rows)))]  # repeated pairs
    pairs = np.array(rows, dtype=np.int64).reshape(-1, 2)
    return shapes, radii, pairs


def _corners(points, tol):
    """A contact polygon (k, 3) without the vertices within tol of the line through their neighbours (the kernel
    drops them; the reference keeps what clipping left)."""
    pts = list(points)
    changed = True
    while changed and len(pts) >= 3:
        changed = False
        for i in range(len(pts)):
            a, b = pts[i - 1], pts[(i + 1) % len(pts)]
            e = b - a
            off = np.linalg.norm(np.cross(e, pts[i] - a)) / np.linalg.norm(e) if np.linalg.norm(e) > 0 \
                else np.linalg.norm(pts[i] - a)
            if off <= tol:
                del pts[i]
                changed = True
                break
    return np.array(pts).reshape(-1, 3)


def _same_point_set(p, q, tol):
    return p.shape == q.shape and all(np.abs(q - x).max(axis=1).min() <= tol for x in p) \
        and all(np.abs(p - x).max(axis=1).min() <= tol for x in q)


def _full_dimensional(points):
    return points.shape[0] >= 4 and np.linalg.matrix_rank(points - points[0], tol=1e-6) == 3


# ---------------------------------------------------------------------------------------------------------------
# contact_feature_pairs
# ---------------------------------------------------------------------------------------------------------------

FALLBACKS = []  # (pairs that took Qhull's exact depth, pairs) per example; see ContactBatch.exact_fallback


@pytest.fixture(scope="module", autouse=True)
def _count_fallbacks():
    """Prints (pytest -s) how often EPA broke down and Qhull answered, over this module's batches."""
    yield
    if FALLBACKS:
        print(f"\ncontact_feature_pairs: Qhull fallback on {sum(f for f, _ in FALLBACKS)} of "
              f"{sum(k for _, k in FALLBACKS)} pairs")


@settings(max_examples=100)
@given(shape_batches())
def test_contact_batch_equals_single_pairs_and_reference(batch_input):
    shapes, radii, pairs = batch_input
    points, offsets = pack_point_sets(shapes)
    points_before = points.copy()
    batch = contact_feature_pairs(points, offsets, pairs, radii=radii)
    assert np.array_equal(points, points_before)  # the caller's arrays are not modified
    k = pairs.shape[0]
    assert len(batch) == k and batch.point_offsets.shape == (k + 1,) and batch.point_offsets[0] == 0
    assert batch.points.shape == (batch.point_offsets[-1], 3)
    assert (np.diff(batch.point_offsets) >= 1).all()
    assert batch.feature_a.dtype == np.int8 and set(batch.feature_a.tolist()) <= {1, 2, 3}
    FALLBACKS.append((int(batch.exact_fallback.sum()), k))
    seen = {}
    for p, (i, j) in enumerate(pairs):
        a, b, ra, rb = shapes[i], shapes[j], radii[i], radii[j]
        got = batch[p]
        scale = max(np.ptp(np.concatenate([a, b]), axis=0).max(), ra + rb, 1.0)
        # the single-pair form
        one = contact_feature(a, b, radius_a=ra, radius_b=rb)
        assert abs(got.separation - one.separation) <= 1e-9 * max(abs(one.separation), 1e-3)
        assert np.allclose(got.normal, one.normal, atol=1e-12) and got.kind == one.kind
        assert _same_point_set(got.points, one.points, 1e-12 * scale)
        assert batch.kind[p] == got.kind == f"{got.feature_a}-{got.feature_b}"
        # the numpy reference (the support features); nearly flush faces take the face manifold instead
        # (contact_manifold's face preference, properties/test_hull_nearly_flush.py): points and kind not compared
        sep, normal, kind, pts = _ref_contact_feature(a, b, ra, rb)
        assert abs(got.separation - sep) <= 1e-9 * max(abs(sep), 1e-3)
        assert np.allclose(got.normal, normal, atol=1e-9)
        if not (sep < 0.0 and ra == rb == 0.0 and _flush_faces(a, b, normal)):
            assert got.kind == kind
            assert _same_point_set(got.points, _corners(pts, 1e-7 * scale), 1e-7 * scale)
        # repeated pairs: identical rows
        if (i, j) in seen:
            q = seen[(i, j)]
            assert batch.separation[q] == batch.separation[p] and np.array_equal(batch.normal[q], batch.normal[p])
            assert np.array_equal(batch[q].points, got.points)
        seen[(i, j)] = p


@settings(max_examples=100)
@given(shape_batches(min_shapes=2))
def test_contact_batch_geometry(batch_input):
    """Unit normal; separation = GJK distance − radii (apart) or −EPA depth − radii (overlap); the two rounded
    support planes ⊥ n are `separation` apart; every contact point lies on their mid-plane and, moved onto each
    shape's support plane, on that shape (inside the feature's shadow)."""
    shapes, radii, pairs = batch_input
    points, offsets = pack_point_sets(shapes)
    batch = contact_feature_pairs(points, offsets, pairs, radii=radii)
    for p, (i, j) in enumerate(pairs):
        a, b, ra, rb = shapes[i], shapes[j], radii[i], radii[j]
        scale = max(np.ptp(np.concatenate([a, b]), axis=0).max(), ra + rb, 1.0)
        n = batch.normal[p]
        sep = batch.separation[p]
        assert abs(np.linalg.norm(n) - 1.0) <= 1e-12
        d, _, _ = gjk_distance(a, b)
        if d > 0:
            assert abs(sep - (d - ra - rb)) <= 1e-12 * scale
        else:
            assert abs(sep - (-epa_penetration(a, b)[0] - ra - rb)) <= 1e-12 * scale
        top_a = (a @ n).max() + ra
        bot_b = (b @ n).min() - rb
        # the support planes realise the separation, and hold the closest (deepest) points (also for two
        # overlapping flat sets: depth 0 along a direction in which their Minkowski difference does not extend)
        assert abs((bot_b - top_a) - sep) <= 1e-9 * scale
        assert abs(batch.closest_a[p] @ n - top_a) <= 1e-9 * scale
        assert abs(batch.closest_b[p] @ n - bot_b) <= 1e-9 * scale
        pts = batch.points[batch.point_offsets[p]:batch.point_offsets[p + 1]]
        flush = sep < 0.0 and ra == rb == 0.0 and _flush_faces(a, b, n)
        for x in pts:
            assert abs(x @ n - 0.5 * (top_a + bot_b)) <= 1e-9 * scale
            if flush:  # a face manifold: its points come from the tilted faces, inside both hulls grown by the depth
                assert hull_signed_distance(a, x) <= -sep + 1e-6 * scale
                assert hull_signed_distance(b, x) <= -sep + 1e-6 * scale
                continue
            if _full_dimensional(a):
                on_a = x - ((x @ n) - (top_a - ra)) * n  # onto A's core support plane
                assert hull_signed_distance(a, on_a) <= 1e-6 * scale
            if _full_dimensional(b):
                on_b = x - ((x @ n) - (bot_b + rb)) * n
                assert hull_signed_distance(b, on_b) <= 1e-6 * scale


def test_contact_batch_empty_and_named_features():
    cube = box_corners(np.array([-1.0, -1, -1]), np.array([1.0, 1, 1]))
    points, offsets = pack_point_sets([cube, cube + [0, 0, 3], np.zeros((1, 3))])
    empty = contact_feature_pairs(points, offsets, np.empty((0, 2), np.int64))
    assert len(empty) == 0 and empty.points.shape == (0, 3) and empty.point_offsets.tolist() == [0]
    assert empty.kind == []
    batch = contact_feature_pairs(points, offsets, [[0, 1], [2, 1], [1, 0]], radii=[0.0, 0.0, 1.0])
    assert batch.kind == ["face-face", "sphere-face", "face-face"]
    assert batch.feature_a.tolist() == [3, 1, 3] and batch.feature_b.tolist() == [3, 3, 3]
    assert np.allclose(batch.separation, [1.0, 1.0, 1.0])
    assert np.allclose(batch.normal, [[0, 0, 1], [0, 0, 1], [0, 0, -1]])
    assert np.diff(batch.point_offsets).tolist() == [4, 1, 4]
    assert np.allclose(batch[1].points, [[0, 0, 1.5]]) and batch[-1].kind == "face-face"
    with pytest.raises(IndexError):
        batch[3]


def test_contact_batch_bad_input():
    cube = box_corners(np.array([-1.0, -1, -1]), np.array([1.0, 1, 1]))
    points, offsets = pack_point_sets([cube, cube + 3])
    with pytest.raises(ValueError, match=r"pairs\[1\]"):
        contact_feature_pairs(points, offsets, [[0, 1], [0, 2]])
    with pytest.raises(ValueError, match="pairs"):
        contact_feature_pairs(points, offsets, [[0, 1, 1]])
    with pytest.raises(ValueError, match="pairs"):
        contact_feature_pairs(points, offsets, [[0, -1]])
    with pytest.raises(TypeError, match="pairs"):
        contact_feature_pairs(points, offsets, [[0.0, 1.0]])
    bad = points.copy()
    bad[3, 1] = np.nan
    with pytest.raises(ValueError, match="points"):
        contact_feature_pairs(bad, offsets, [[0, 1]])
    with pytest.raises(ValueError, match=r"radii\[1\]"):
        contact_feature_pairs(points, offsets, [[0, 1]], radii=[0.0, -0.5])
    with pytest.raises(ValueError, match="radii"):
        contact_feature_pairs(points, offsets, [[0, 1]], radii=[0.0])
    with pytest.raises(ValueError, match="radii"):
        contact_feature_pairs(points, offsets, [[0, 1]], radii=[0.0, np.inf])
    with pytest.raises(ValueError, match="offsets"):
        contact_feature_pairs(points, [0, 8, 15], [[0, 1]])
    with pytest.raises(ValueError, match="feature_tol"):
        contact_feature_pairs(points, offsets, [[0, 1]], feature_tol=0.0)


# ---------------------------------------------------------------------------------------------------------------
# overlap_convex_sat_pairs
# ---------------------------------------------------------------------------------------------------------------

GAP = 1e-7  # SAT and GJK may disagree on pairs closer than this (relative to their size)


@settings(max_examples=100)
@given(shape_batches())
def test_convex_sat_batch_equals_single_and_gjk(batch_input):
    shapes, _, pairs = batch_input
    points, offsets = pack_point_sets(shapes)
    got = overlap_convex_sat_pairs(points, offsets, pairs)
    assert got.dtype == np.bool_ and got.shape == (pairs.shape[0],)
    for p, (i, j) in enumerate(pairs):
        a, b = shapes[i], shapes[j]
        assert got[p] == overlap_convex_sat(a, b)
        d, _, _ = gjk_distance(a, b)
        scale = max(np.abs(np.concatenate([a, b])).max(), 1.0)
        if d == 0.0 or d > GAP * scale:
            assert got[p] == (d == 0.0)


def _coal_hull(points):
    import coal

    vertices = coal.StdVec_Vec3s()
    vertices.extend(list(points))
    return coal.Convex.convexHull(vertices, False, "")


@settings(max_examples=60)
@given(st.lists(point_clouds(spread=1.5), min_size=2, max_size=5), st.data())
def test_convex_sat_batch_agrees_with_coal(clouds, data):
    import coal

    points, offsets = pack_point_sets(clouds)
    n = len(clouds)
    rows = data.draw(st.lists(st.tuples(st.integers(0, n - 1), st.integers(0, n - 1)).filter(lambda r: r[0] != r[1]),
                              min_size=1, max_size=8))
    got = overlap_convex_sat_pairs(points, offsets, rows)
    hulls = [_coal_hull(c) for c in clouds]
    for p, (i, j) in enumerate(rows):
        a, b = clouds[i], clouds[j]
        scale = max(np.abs(np.concatenate([a, b])).max(), 1.0)
        d, _, _ = gjk_distance(a, b)
        # coal decides grazing contacts with its own tolerance: keep clear gaps and clear overlaps
        if d == 0.0 and epa_penetration(a, b)[0] <= 1e-5 * scale or 0.0 < d <= 1e-5 * scale:
            continue
        result = coal.CollisionResult()
        coal.collide(hulls[i], coal.Transform3s(), hulls[j], coal.Transform3s(), coal.CollisionRequest(), result)
        assert got[p] == result.isCollision()


def test_convex_sat_batch_empty_and_bad_input():
    cube = box_corners(np.array([-1.0, -1, -1]), np.array([1.0, 1, 1]))
    points, offsets = pack_point_sets([cube, cube + [2.0, 0, 0], cube + [2.0 + 1e-6, 0, 0]])
    assert overlap_convex_sat_pairs(points, offsets, np.empty((0, 2), np.int64)).shape == (0,)
    assert overlap_convex_sat_pairs(points, offsets, [[0, 1], [0, 2], [1, 2], [0, 1]]).tolist() == \
        [True, False, True, True]
    with pytest.raises(ValueError, match=r"pairs\[0\]"):
        overlap_convex_sat_pairs(points, offsets, [[0, 3]])
    with pytest.raises(ValueError, match="pairs"):
        overlap_convex_sat_pairs(points, offsets, [0, 1])
    bad = points.copy()
    bad[0, 0] = np.inf
    with pytest.raises(ValueError, match="points"):
        overlap_convex_sat_pairs(bad, offsets, [[0, 1]])
    with pytest.raises(ValueError, match="offsets"):
        overlap_convex_sat_pairs(points, [0, 8], [[0, 0]])


# ---------------------------------------------------------------------------------------------------------------
# curved ground
# ---------------------------------------------------------------------------------------------------------------

def _wavy(x):
    return np.sin(3 * x) + 0.2 * x


def _bowl(x):
    return 0.3 * x * x - 1.0


JITTED = [numba.njit(_wavy), numba.njit(_bowl)]
CURVES = [_wavy, _bowl, np.tanh]


@st.composite
def boxes_2d(draw, max_n=8):
    n = draw(st.integers(1, max_n))
    lo = np.array(draw(st.lists(st.tuples(st.floats(-4, 4), st.floats(-2, 2)), min_size=n, max_size=n)))
    size = np.array(draw(st.lists(st.tuples(st.floats(0.0, 3), st.floats(0.05, 2)), min_size=n, max_size=n)))
    return lo, lo + size


@settings(max_examples=40)
@given(st.sampled_from(range(len(CURVES))), boxes_2d(), st.lists(st.floats(0.0, 1.5), min_size=8, max_size=8))
def test_curve_batch_equals_one_call_per_shape(k, boxes, radii):
    f = CURVES[k]
    lo, hi = boxes
    n = lo.shape[0]
    r = np.array(radii[:n])
    x, fmax = max_on_intervals(f, lo[:, 0], hi[:, 0])
    dist, xc = min_distance_to_curve(lo, f, r)
    exact = overlap_aabb_curve(lo, hi, f)
    middle = overlap_aabb_curve_bottom_middle(lo, hi, f)
    circles = overlap_circle_curve(lo, r, f)
    for i in range(n):
        one_x, one_f = max_on_intervals(f, lo[i:i + 1, 0], hi[i:i + 1, 0])
        assert one_x[0] == x[i] and one_f[0] == fmax[i]
        one_d, one_xc = min_distance_to_curve(lo[i:i + 1], f, r[i])
        assert one_d[0] == dist[i] and one_xc[0] == xc[i]
        assert overlap_aabb_curve(lo[i:i + 1], hi[i:i + 1], f)[0] == exact[i]
        assert overlap_aabb_curve_bottom_middle(lo[i:i + 1], hi[i:i + 1], f)[0] == middle[i]
        assert overlap_circle_curve(lo[i:i + 1], r[i], f)[0] == circles[i]
        # and the answer itself: f's max on a dense grid is not above the search's (up to its refinement)
        grid = np.linspace(lo[i, 0], hi[i, 0], 2001)
        assert f(grid).max() <= fmax[i] + 1e-6 and lo[i, 0] <= x[i] <= hi[i, 0]
        assert abs(f(np.array([x[i]]))[0] - fmax[i]) <= 1e-12


@settings(max_examples=40)
@given(st.sampled_from(range(len(JITTED))), boxes_2d(), st.floats(0.0, 1.5))
def test_curve_jitted_f_equals_python_f(k, boxes, radius):
    """A numba-jitted f runs the whole search in one compiled call; a Python callable around the same compiled f
    runs the Python loop over iterations: the same arithmetic, the same answer to the bit."""
    fj = JITTED[k]

    def fp(x):
        return fj(x)

    lo, hi = boxes
    for name, call in (("max", lambda f: max_on_intervals(f, lo[:, 0], hi[:, 0])),
                       ("distance", lambda f: min_distance_to_curve(lo, f, radius)),
                       ("box", lambda f: (overlap_aabb_curve(lo, hi, f),)),
                       ("circle", lambda f: (overlap_circle_curve(lo, radius, f),))):
        for u, v in zip(call(fj), call(fp)):
            assert np.array_equal(u, v), name
    # and the numpy f (libm vs numpy ulps apart) agrees to round-off
    _, fmax_j = max_on_intervals(fj, lo[:, 0], hi[:, 0])
    _, fmax_p = max_on_intervals(CURVES[k], lo[:, 0], hi[:, 0])
    assert np.allclose(fmax_j, fmax_p, rtol=0, atol=1e-12)


def test_curve_jitted_f_bad_values():
    @numba.njit
    def log_curve(x):
        return np.log(x - 0.5)

    with pytest.raises(ValueError, match="non-finite"):
        overlap_aabb_curve(np.array([[0.0, 0.0]]), np.array([[1.0, 1.0]]), log_curve)
    with pytest.raises(ValueError, match="non-finite"):
        min_distance_to_curve(np.array([[0.0, 0.0]]), log_curve, 1.0)
    with pytest.raises(TypeError, match="f"):
        max_on_intervals(3.0, [0.0], [1.0])
    assert max_on_intervals(JITTED[0], [], [])[0].shape == (0,)


@settings(max_examples=60)
@given(st.floats(0.2, 1.5), st.floats(0.2, 1.5), st.sampled_from([1e-5, 1e-4, 1e-3, 0.1, 0.5, 0.785]),
       st.floats(-0.3, 0.3), st.floats(-0.3, 0.3), st.sampled_from([0.0, 0.05]))
def test_contact_face_face_patch_is_the_footprint_intersection(wa, wb, angle, dx, dy, overlap):
    """A box on a box turned by `angle` about the stacking axis z: the contact points are exactly the vertices
    of the intersection of the two footprints (Qhull's half-space intersection), none dropped, none extra."""
    from scipy.spatial import ConvexHull, HalfspaceIntersection

    c, s = np.cos(angle), np.sin(angle)
    rot = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])
    a = box_corners(np.array([-wa, -wa, -0.5]), np.array([wa, wa, 0.5]))
    b = box_corners(np.array([-wb, -wb, -0.5]), np.array([wb, wb, 0.5])) @ rot.T + [dx, dy, 1.0 - overlap]
    points, offsets = pack_point_sets([a, b])
    contact = contact_feature_pairs(points, offsets, [[0, 1], [1, 0]])[0]
    assert contact.kind == "face-face" and np.allclose(contact.normal, [0, 0, 1], atol=1e-9)
    # footprints as half-planes n·x <= h
    normals_b = np.array([[1.0, 0], [-1, 0], [0, 1], [0, -1]]) @ rot[:2, :2].T
    halfspaces = np.vstack([np.column_stack([[[1.0, 0], [-1, 0], [0, 1], [0, -1]], -np.full(4, wa)]),
                            np.column_stack([normals_b, -(wb + normals_b @ [dx, dy])])])
    from scipy.optimize import linprog

    # an interior point: the centre of the largest disc inside both footprints (Chebyshev centre, an LP)
    norms = np.linalg.norm(halfspaces[:, :2], axis=1)
    lp = linprog([0, 0, -1], A_ub=np.column_stack([halfspaces[:, :2], norms]), b_ub=-halfspaces[:, 2],
                 bounds=[(None, None), (None, None), (0, None)])
    assume(lp.status == 0 and lp.x[2] > 1e-6)
    inter = HalfspaceIntersection(halfspaces, lp.x[:2])
    hull = ConvexHull(inter.intersections)
    # the exact polygon, reduced as the kernel reduces it at its tolerance: near-duplicates merged, vertices within
    # tol of the line through their neighbours dropped (a turned box leaves corners ~angle × size off the line)
    tol = FEATURE_TOL * np.ptp(points, axis=0).max()
    exact = np.column_stack([inter.intersections[hull.vertices], np.zeros(len(hull.vertices))])
    merged = []
    for x in exact:
        if all(np.linalg.norm(x - y) > tol for y in merged):
            merged.append(x)
    corners = _corners(np.array(merged), tol)[:, :2]
    assert _same_point_set(contact.points[:, :2], corners, 2 * tol)


@settings(max_examples=60)
@given(st.data())
def test_convex_sat_batch_on_targeted_separations(data):
    """Pairs only one kind of axis separates, in both orders: crossing box edges (an edge × edge axis) and a point
    just outside a face of a rotated box (that box's face normal)."""
    from properties.strategies.narrow import edge_edge_obb_pairs

    a, b = data.draw(edge_edge_obb_pairs())
    box = b.corners()
    face = data.draw(st.integers(0, 5))
    axis, sign = face // 2, 1.0 if face % 2 else -1.0
    gap = data.draw(st.sampled_from([-1e-3, 1e-4, 1e-2, 0.3]))
    local = np.array(data.draw(st.tuples(*[st.floats(-0.9, 0.9)] * 3))) * b.half_extents
    local[axis] = sign * (b.half_extents[axis] + gap)
    point = (b.center + local @ b.axes)[None, :]
    shapes = [a.corners(), box, point]
    points, offsets = pack_point_sets(shapes)
    pairs = np.array([[0, 1], [1, 0], [2, 1], [1, 2]])
    got = overlap_convex_sat_pairs(points, offsets, pairs)
    for p, (i, j) in enumerate(pairs):
        d, _, _ = gjk_distance(shapes[i], shapes[j])
        scale = max(np.abs(np.concatenate([shapes[i], shapes[j]])).max(), 1.0)
        # grazing pairs (crossing edges exactly touching) are decided by round-off on either side: left out
        if d > GAP * scale or d == 0.0 and epa_penetration(shapes[i], shapes[j])[0] > GAP * scale:
            assert got[p] == (d == 0.0)


# --- the GJK batches check their values in the kernel ----------------------------------------------------------

@settings(max_examples=60)
@given(st.integers(1, 6), st.integers(1, 5), st.integers(1, 5), st.data(),
       st.sampled_from([np.nan, np.inf, -np.inf, 1.5e150, -1e200, 1e300]))
def test_gjk_batches_refuse_a_bad_value_anywhere_naming_it(k, m, p, data, bad):
    """One NaN, ±inf or over-large coordinate anywhere in a GJK batch (aligned or packed) raises ValueError naming
    the argument and the index; the caller's arrays are left as they were."""
    from engine.narrowphase import gjk_distance_batch, gjk_distance_pairs

    rng = np.random.default_rng(data.draw(st.integers(0, 2**32 - 1)))
    a = rng.normal(size=(k, m, 3))
    b = rng.normal(size=(k, p, 3)) + 3.0
    side = data.draw(st.sampled_from(["points_a", "points_b"]))
    target = a if side == "points_a" else b
    idx = tuple(data.draw(st.integers(0, n - 1)) for n in target.shape)
    target[idx] = bad
    before_a, before_b = a.copy(), b.copy()
    with pytest.raises(ValueError, match=rf"^{side}.*{side}\[{idx[0]}, {idx[1]}, {idx[2]}\]"):
        gjk_distance_batch(a, b)
    assert np.array_equal(a, before_a, equal_nan=True) and np.array_equal(b, before_b, equal_nan=True)
    packed = np.concatenate([a.reshape(-1, 3), b.reshape(-1, 3)])
    offsets = np.concatenate([np.arange(0, k * m + 1, m), k * m + np.arange(p, k * p + 1, p)])
    pairs = np.stack([np.arange(k), k + np.arange(k)], axis=1)
    row = (idx[0] * m + idx[1]) if side == "points_a" else (k * m + idx[0] * p + idx[1])
    with pytest.raises(ValueError, match=rf"^points.*points\[{row}, {idx[2]}\]"):
        gjk_distance_pairs(packed, offsets, pairs)


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 1500), st.integers(2, 4), st.integers(1, 12), st.integers(1, 12), st.integers(0, 2**32 - 1))
def test_gjk_batches_on_threads_give_the_same_answers_bit_for_bit(k, threads, m, p, seed):
    """``threads`` splits a batch into contiguous chunks run in parallel: every output equals the one-thread call
    exactly (and a pair list with repeated shapes too)."""
    from engine.narrowphase import gjk_distance_batch, gjk_distance_pairs
    from engine.narrowphase.gjk import MIN_PAIRS_PER_THREAD

    rng = np.random.default_rng(seed)
    a = rng.normal(size=(k, m, 3))
    b = rng.normal(size=(k, p, 3)) + rng.normal(scale=2.0, size=(k, 1, 3))
    one = gjk_distance_batch(a, b)
    many = gjk_distance_batch(a, b, threads=threads)
    assert all(np.array_equal(x, y) for x, y in zip(one, many))
    packed, offsets = pack_point_sets(list(a) + list(b)) if k else (np.zeros((1, 3)), np.array([0, 1]))
    n_shapes = offsets.shape[0] - 1
    pairs = rng.integers(0, n_shapes, size=(max(k, MIN_PAIRS_PER_THREAD * threads), 2))
    one = gjk_distance_pairs(packed, offsets, pairs)
    many = gjk_distance_pairs(packed, offsets, pairs, threads=threads)
    assert all(np.array_equal(x, y) for x, y in zip(one, many))
    # and the threads really ran: each chunk's distances are those of its own pairs
    d_direct = np.array([gjk_distance(packed[offsets[i]:offsets[i + 1]], packed[offsets[j]:offsets[j + 1]])[0]
                         for i, j in pairs[:: max(1, pairs.shape[0] // 7)]])
    assert np.array_equal(many[0][:: max(1, pairs.shape[0] // 7)], d_direct)


@pytest.mark.parametrize("threads", [0, -1, 1.5, True, "2", 10**6])
def test_gjk_batch_threads_is_validated(threads):
    from engine.narrowphase import gjk_distance_batch

    with pytest.raises((ValueError, TypeError), match="^threads"):
        gjk_distance_batch(np.zeros((1, 1, 3)), np.ones((1, 1, 3)), threads=threads)
