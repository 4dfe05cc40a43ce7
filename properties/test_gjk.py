"""GJK distance and EPA penetration: against coal, python-fcl, exact answers and Qhull on the Minkowski difference."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from engine.narrowphase.gjk import (
    GJKNotConverged,
    gjk_distance,
    gjk_distance_batch,
    gjk_distance_pairs,
    pack_point_sets,
)
from engine.narrowphase.penetration import epa_penetration, epa_penetration_pairs
from properties.strategies.narrow import (
    aabb_depth,
    aabb_distance,
    aabbs,
    box_corners,
    exact_penetration_depth,
    hull_signed_distance,
    point_clouds,
    rotations,
    vectors,
)

REL = 1e-6


def _scale(a, b):
    return max(np.ptp(np.concatenate([a, b]), axis=0).max(), 1.0)


def _coal_distance(a, b):
    import coal

    def convex(p):
        v = coal.StdVec_Vec3s()
        for q in p:
            v.append(q)
        return coal.Convex.convexHull(v, False, "")

    req = coal.DistanceRequest()
    req.gjk_tolerance = 1e-12
    res = coal.DistanceResult()  # fresh result per call
    return coal.distance(convex(a), coal.Transform3s(), convex(b), coal.Transform3s(), req, res)


def _fcl_distance(a, b):
    import fcl
    from scipy.spatial import ConvexHull

    def convex(p):
        h = ConvexHull(p)
        faces = np.hstack([np.full((len(h.simplices), 1), 3), h.simplices]).ravel()
        return fcl.CollisionObject(fcl.Convex(p, len(h.simplices), faces), fcl.Transform())

    return fcl.distance(convex(a), convex(b), fcl.DistanceRequest(), fcl.DistanceResult())


@settings(max_examples=60)
@given(point_clouds(), point_clouds(spread=8.0))
def test_distance_agrees_with_coal_and_fcl_on_separated_hulls(a, b):
    d, _, _ = gjk_distance(a, b)
    dc = _coal_distance(a, b)
    assume(dc > 1e-6 * _scale(a, b))
    assert abs(d - dc) <= REL * dc
    df = _fcl_distance(a, b)
    assert abs(d - df) <= REL * df


@settings(max_examples=60)
@given(point_clouds(), point_clouds(spread=2.0))
def test_overlap_iff_coal_collides(a, b):

    d, _, _ = gjk_distance(a, b)
    dc = _coal_distance(a, b)
    assume(abs(dc) > 1e-6 * _scale(a, b))
    assert (d == 0.0) == (dc < 0.0)


@given(point_clouds(), point_clouds(spread=6.0))
def test_closest_points_on_shapes_and_consistent(a, b):
    d, ca, cb = gjk_distance(a, b)
    scale = _scale(a, b)
    assert d >= 0.0 and np.isfinite(d)
    assert abs(np.linalg.norm(ca - cb) - d) <= 1e-9 * scale
    assert hull_signed_distance(a, ca) <= 1e-9 * scale
    assert hull_signed_distance(b, cb) <= 1e-9 * scale
    # no pair of points of the hulls is closer: the vertices project beyond the separating planes
    if d > 0:
        n = (cb - ca) / d
        assert (a @ n).max() <= ca @ n + 1e-9 * scale
        assert (b @ n).min() >= cb @ n - 1e-9 * scale


@given(point_clouds(), point_clouds(spread=6.0))
def test_symmetric(a, b):
    d1, ca1, cb1 = gjk_distance(a, b)
    d2, ca2, cb2 = gjk_distance(b, a)
    assert abs(d1 - d2) <= 1e-9 * _scale(a, b)


@given(point_clouds(), point_clouds(spread=6.0), vectors)
def test_translation_invariant(a, b, shift):
    d1, _, _ = gjk_distance(a, b)
    d2, _, _ = gjk_distance(a + shift, b + shift)
    assert abs(d1 - d2) <= 1e-8 * (_scale(a, b) + np.abs(shift).max())


@given(aabbs(), aabbs(spread=6.0))
def test_axis_aligned_boxes_exact(box_a, box_b):
    # python-fcl's box-box distance is wrong along y and z (FCL issue 508): the oracle is the interval gap
    exact = aabb_distance(*box_a, *box_b)
    d, _, _ = gjk_distance(box_corners(*box_a), box_corners(*box_b))
    scale = _scale(box_corners(*box_a), box_corners(*box_b))
    if exact > 1e-9 * scale:
        assert abs(d - exact) <= 1e-9 * scale
    elif exact == 0.0:
        assert d <= 1e-9 * scale


@given(vectors, vectors, vectors)
def test_point_and_segment_exact(p, s0, s1):
    d, _, _ = gjk_distance(p[None], p[None] + 0.0)
    assert d == 0.0
    d, ca, cb = gjk_distance(p[None], np.array([s0, s1]))
    seg = s1 - s0
    t = 0.0 if seg @ seg == 0 else np.clip((p - s0) @ seg / (seg @ seg), 0.0, 1.0)
    exact = np.linalg.norm(p - (s0 + t * seg))
    assert abs(d - exact) <= 1e-9 * (1 + np.abs(np.array([p, s0, s1])).max())
    d2, _, _ = gjk_distance(p[None], s0[None])
    assert abs(d2 - np.linalg.norm(p - s0)) <= 1e-12 * (1 + np.linalg.norm(p - s0))


@settings(max_examples=30)
@given(st.lists(point_clouds(spread=5.0), min_size=2, max_size=6), st.data())
def test_batched_forms_equal_single_calls(clouds, data):
    points, offsets = pack_point_sets(clouds)
    k = len(clouds)
    pairs = np.array(data.draw(st.lists(st.tuples(st.integers(0, k - 1), st.integers(0, k - 1)), min_size=1,
                                        max_size=10)))
    dist, ca, cb = gjk_distance_pairs(points, offsets, pairs)
    depth, normal = epa_penetration_pairs(points, offsets, pairs)
    for p, (i, j) in enumerate(pairs):
        d, a, b = gjk_distance(clouds[i], clouds[j])
        assert dist[p] == d and np.array_equal(ca[p], a) and np.array_equal(cb[p], b)
        e, n = epa_penetration(clouds[i], clouds[j])
        assert depth[p] == e and np.array_equal(normal[p], n)
    m = min(c.shape[0] for c in clouds)
    same = np.array([c[:m] for c in clouds])
    dist2, _, _ = gjk_distance_batch(same[:-1], same[1:])
    for p in range(k - 1):
        assert dist2[p] == gjk_distance(same[p], same[p + 1])[0]


# --- degenerate inputs: flat and collinear sets, duplicated vertices, touching shapes, large coordinates -------

@st.composite
def flat_sets(draw, height: float):
    """(n, 3) points in the plane z = ``height``: a single (repeated) point, collinear points on the x axis or
    coplanar points, every set holding (0, 0, height) so that the xy-projections of two such sets always meet;
    rows are shuffled and some are duplicated (ties in the support mapping, zero-length simplex edges)."""
    dim = draw(st.integers(0, 2))
    n = draw(st.integers(1, 8))
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    xy = rng.uniform(-2.0, 2.0, size=(n, 2))
    if dim == 0:
        xy[:] = 0.0
    elif dim == 1:
        xy[:, 1] = 0.0
    pts = np.column_stack([xy, np.full(n, height)])
    pts = np.vstack([pts, [0.0, 0.0, height]])
    pts = pts[rng.integers(0, pts.shape[0], size=draw(st.integers(0, 4)))].reshape(-1, 3).tolist() + pts.tolist()
    pts = np.array(pts)
    return pts[rng.permutation(pts.shape[0])]


heights = st.one_of(st.just(0.0), st.floats(-3.0, 3.0, allow_nan=False), st.floats(-1e-6, 1e-6, allow_nan=False))


@given(heights, st.data(), rotations(), vectors)
def test_flat_and_collinear_sets_in_parallel_planes_exact(h, data, rot, shift):
    """Flat sets in the parallel planes z = 0 and z = h whose projections meet are exactly |h| apart, whatever
    their dimension (point, segment, polygon): every GJK simplex of their Minkowski difference is degenerate
    (zero-area triangles, flat tetrahedra); h = 0 makes the shapes touch or overlap in a plane."""
    a0 = data.draw(flat_sets(0.0))
    b0 = data.draw(flat_sets(h))
    a = a0 @ rot.T + shift
    b = b0 @ rot.T + shift
    d, ca, cb = gjk_distance(a, b)
    tol = 1e-9 * (1.0 + np.abs(np.concatenate([a, b])).max())
    assert abs(d - abs(h)) <= tol
    assert abs(np.linalg.norm(ca - cb) - d) <= tol
    # the closest points lie in the two planes (back in the sets' own frame)
    assert abs(((ca - shift) @ rot)[2]) <= tol
    assert abs(((cb - shift) @ rot)[2] - h) <= tol
    d2, _, _ = gjk_distance(b, a)
    assert abs(d2 - d) <= tol


@given(point_clouds(), point_clouds(spread=6.0), st.data())
def test_duplicated_and_shuffled_vertices_change_nothing(a, b, data):
    """The hull of a point set does not depend on the order of its rows nor on repeated rows: the distance is the
    same to round-off (repeated rows tie in the support mapping and can enter the simplex twice)."""
    d, _, _ = gjk_distance(a, b)
    rng = np.random.default_rng(data.draw(st.integers(0, 2**32 - 1)))
    a2 = np.vstack([a, a[rng.integers(0, a.shape[0], size=data.draw(st.integers(1, 6)))]])
    b2 = np.vstack([b[rng.integers(0, b.shape[0], size=data.draw(st.integers(1, 6)))], b])
    a2 = a2[rng.permutation(a2.shape[0])]
    b2 = b2[rng.permutation(b2.shape[0])]
    d2, ca, cb = gjk_distance(a2, b2)
    scale = _scale(a, b)
    assert abs(d2 - d) <= 1e-9 * scale
    assert hull_signed_distance(a, ca) <= 1e-9 * scale
    assert hull_signed_distance(b, cb) <= 1e-9 * scale


far = st.floats(-1e8, 1e8, allow_nan=False).map(float)


@given(point_clouds(spread=1.0), point_clouds(spread=3.0), st.tuples(far, far, far).map(np.array))
def test_small_shapes_far_from_the_origin(a, b, offset):
    """Shapes of size ~1 at coordinates up to 1e8: the answer moves by the rounding of the shifted coordinates
    only (a few ulps of 1e8, ~1e-8), and GJK still converges."""
    d, _, _ = gjk_distance(a, b)
    a_far = a + offset
    b_far = b + offset
    d_far, ca, cb = gjk_distance(a_far, b_far)
    # what the shift itself costs: the largest change it made to any coordinate
    moved = max(np.abs((a_far - offset) - a).max(), np.abs((b_far - offset) - b).max())
    tol = 4.0 * moved + 1e-9 * _scale(a, b)
    assert abs(d_far - d) <= tol
    assert abs(np.linalg.norm(ca - cb) - d_far) <= 1e-9 * np.abs(offset).max() + 1e-9 * _scale(a, b) + tol
    # both points on their shapes (checked in the shapes' own frame, with the same allowance)
    assert hull_signed_distance(a, ca - offset) <= tol + 1e-9 * (1.0 + np.abs(offset).max())
    assert hull_signed_distance(b, cb - offset) <= tol + 1e-9 * (1.0 + np.abs(offset).max())


gaps = st.one_of(st.just(0.0), st.floats(-1e-9, 1e-9, allow_nan=False), st.floats(-1e-3, 1e-3, allow_nan=False))


@given(point_clouds(), point_clouds(), rotations(), gaps)
def test_touching_hulls(a, b0, rot, gap):
    """B is moved so that its lowest vertex along a direction u sits on A's highest vertex along u, then by ``gap``
    along u. For gap >= 0 the plane through A's vertex separates the hulls and the two vertices are gap apart, so
    the distance is exactly gap (touching to round-off at gap = 0); for gap < 0 the vertices are |gap| apart and
    the hulls may or may not overlap, so only 0 <= distance <= |gap| is known."""
    u = rot[:, 0]
    b = b0 + (a[np.argmax(a @ u)] - b0[np.argmin(b0 @ u)]) + gap * u
    d, ca, cb = gjk_distance(a, b)
    scale = _scale(a, b)
    if gap >= 0.0:
        assert abs(d - gap) <= 1e-9 * scale
    else:
        assert d <= -gap + 1e-9 * scale
    assert abs(np.linalg.norm(ca - cb) - d) <= 1e-9 * scale
    assert hull_signed_distance(a, ca) <= 1e-9 * scale
    assert hull_signed_distance(b, cb) <= 1e-9 * scale


def _closest_on_triangle_brute(a, b, c):
    """Distance from the origin to triangle (a, b, c), degenerate ones included: the best of its three clamped
    segment projections and of the least-squares projection onto its plane (or line) when the barycentric
    coordinates of that projection put it inside (any such point is a point of the triangle, so it is always a
    valid candidate). Independent of Ericson's Voronoi-region tests."""
    best = np.inf
    for p, q in ((a, b), (b, c), (a, c)):
        e = q - p
        t = 0.0 if e @ e == 0.0 else float(np.clip(-(p @ e) / (e @ e), 0.0, 1.0))
        best = min(best, float(np.linalg.norm(p + t * e)))
    e1, e2 = b - a, c - a
    (s, t), *_ = np.linalg.lstsq(np.column_stack([e1, e2]), -a, rcond=None)
    if s >= 0.0 and t >= 0.0 and s + t <= 1.0:
        best = min(best, float(np.linalg.norm(a + s * e1 + t * e2)))
    return best


@st.composite
def triangles(draw):
    """(3, 3) triangles: general, collinear (c on line ab, inside or beyond), with two or three coincident
    vertices, or needle-thin; vertex order shuffled."""
    a, b, c = draw(vectors), draw(vectors), draw(vectors)
    kind = draw(st.integers(0, 4))
    t = draw(st.floats(-2.0, 3.0, allow_nan=False))
    if kind == 1:
        c = a + t * (b - a)
    elif kind == 2:
        b = a.copy()
    elif kind == 3:
        b = a.copy()
        c = a.copy()
    elif kind == 4:
        c = a + t * (b - a) + draw(st.floats(1e-12, 1e-6)) * draw(vectors)
    tri = np.array([a, b, c])
    return tri[draw(st.permutations([0, 1, 2]))]


@given(triangles())
def test_triangle_subalgorithm_against_brute_force(tri):
    """The simplex sub-algorithm's triangle case (``closest_on_triangle_any``), degenerate triangles included (GJK
    meets them when round-off lets a support point nearly repeat): its m supporting vertices and weights give a
    point of the triangle as close to the origin as the brute-force answer."""
    from engine.narrowphase.simplex import closest_on_triangle_any

    a, b, c = tri
    m, s0, s1, s2, l0, l1, l2 = closest_on_triangle_any(*a, *b, *c)
    assert m in (1, 2, 3)
    idx = [s0, s1, s2][:m]
    lam = np.array([l0, l1, l2][:m])
    assert all(0 <= i <= 2 for i in idx) and idx == sorted(set(idx))
    assert (lam >= -1e-12).all() and abs(lam.sum() - 1.0) <= 1e-12
    point = lam @ tri[idx]
    exact = _closest_on_triangle_brute(a, b, c)
    scale = 1.0 + np.abs(tri).max()
    assert abs(np.linalg.norm(point) - exact) <= 1e-9 * scale


# --- EPA ------------------------------------------------------------------------------------------------------

@settings(max_examples=100)
@given(point_clouds(), point_clouds(spread=1.5))
def test_epa_depth_equals_qhull_minkowski_depth(a, b):
    exact = exact_penetration_depth(a, b)
    depth, normal = epa_penetration(a, b)
    scale = _scale(a, b)
    assert depth >= 0.0 and abs(np.linalg.norm(normal) - 1.0) <= 1e-12
    if exact > 1e-7 * scale:
        assert abs(depth - exact) <= 1e-8 * scale
        # moving B by the depth along the normal separates the hulls; by a little less, they still overlap
        assert gjk_distance(a, b + (depth + 1e-6 * scale) * normal)[0] > 0.0
        assert gjk_distance(a, b + (depth - 1e-6 * scale) * normal)[0] == 0.0
    elif exact < -1e-7 * scale:
        assert depth == 0.0


fractions = st.tuples(*[st.floats(0.0, 1.0)] * 3).map(np.array)


@settings(max_examples=100)
@given(point_clouds(), point_clouds(spread=1.5))
def test_epa_kernel_needs_no_fallback_in_general_position(a, b):
    """Random clouds are in general position: the expanding polytope itself must converge there (the exact Qhull
    fallback of ``epa_penetration`` is for degenerate inputs only, and must not hide a broken EPA)."""
    from engine.narrowphase.epa import epa_polytope
    from engine.narrowphase.gjk import gjk_scratch
    from engine.narrowphase.penetration import penetration_kernel
    from engine.narrowphase.status import EPA_NOT_CONVERGED

    out = np.empty(10)
    assert penetration_kernel(a, b, 128, gjk_scratch(max(len(a), len(b))), epa_polytope(), np.empty(7),
                              out) != EPA_NOT_CONVERGED
    out[0] = max(-out[0], 0.0)  # the chain's signed distance (−depth when overlapping) as the depth
    exact = exact_penetration_depth(a, b)
    scale = _scale(a, b)
    if exact > 1e-7 * scale:
        assert abs(out[0] - exact) <= 1e-8 * scale


@given(aabbs(), fractions, aabbs())
def test_epa_axis_aligned_boxes_exact(box_a, where, box_b):
    # B is moved so that it contains a point of A: the boxes always overlap
    inside = box_a[0] + where * (box_a[1] - box_a[0])
    box_b = (box_b[0] - box_b[0] + inside - 0.5 * (box_b[1] - box_b[0]),
             inside + 0.5 * (box_b[1] - box_b[0]))
    exact = aabb_depth(*box_a, *box_b)
    assume(exact > 1e-9)
    depth, normal = epa_penetration(box_corners(*box_a), box_corners(*box_b))
    assert abs(depth - exact) <= 1e-9 * (1 + exact)


@given(vectors, vectors, st.floats(0.1, 3.0), st.floats(0.1, 3.0), st.floats(1e-3, 0.999))
def test_epa_spheres_exact(c1, direction, r1, r2, fraction):
    from engine.narrowphase.contact_manifold import contact_feature

    assume(np.linalg.norm(direction) > 1e-3)
    c2 = c1 + direction / np.linalg.norm(direction) * fraction * (r1 + r2)
    dist = np.linalg.norm(c1 - c2)
    contact = contact_feature(c1[None], c2[None], radius_a=r1, radius_b=r2)
    assert abs(-contact.separation - (r1 + r2 - dist)) <= 1e-9 * (1 + r1 + r2)
    assert np.allclose(contact.normal, (c2 - c1) / dist, atol=1e-9)


def test_concentric_and_touching_cubes():
    cube = box_corners(np.array([-1.0, -1, -1]), np.array([1.0, 1, 1]))
    depth, normal = epa_penetration(cube, cube)
    assert abs(depth - 2.0) <= 1e-12 and abs(np.linalg.norm(normal) - 1) <= 1e-12
    assert epa_penetration(cube, cube + [2.0, 0, 0])[0] == 0.0
    assert gjk_distance(cube, cube + [2.0, 0, 0])[0] == 0.0
    assert gjk_distance(cube, cube + [0, 4.0, 0])[0] == 2.0  # the case python-fcl gets wrong


def test_bad_input_raises():
    good = np.zeros((4, 3))
    for bad in (np.full((4, 3), np.nan), np.array([[0, 0, np.inf]]), np.zeros((0, 3)), np.zeros((4, 2))):
        with pytest.raises(ValueError):
            gjk_distance(bad, good)
        with pytest.raises(ValueError):
            epa_penetration(good, bad)
    with pytest.raises(TypeError):
        gjk_distance(np.array([["a", "b", "c"]]), good)
    with pytest.raises(ValueError):
        gjk_distance(good, good, max_iterations=0)
    with pytest.raises(ValueError, match=r"pairs\[1\]"):
        points, offsets = pack_point_sets([good, good + 1])
        gjk_distance_pairs(points, offsets, np.array([[0, 1], [0, 2]]))


def test_iteration_cap_is_a_clear_error():
    rng = np.random.default_rng(3)
    a = rng.normal(size=(30, 3))
    b = rng.normal(size=(30, 3)) + [5.0, 1.0, 0.5]
    with pytest.raises(GJKNotConverged, match="max_iterations=1"):
        gjk_distance(a, b, max_iterations=1)
    d, _, _ = gjk_distance(a, b)
    assert d > 0


def test_inputs_not_modified():
    rng = np.random.default_rng(4)
    a = rng.normal(size=(10, 3))
    b = rng.normal(size=(10, 3)) + 1.0
    a0, b0 = a.copy(), b.copy()
    gjk_distance(a, b)
    epa_penetration(a, b)
    assert np.array_equal(a, a0) and np.array_equal(b, b0)
