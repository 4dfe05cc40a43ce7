"""The adversarial geometry suite: the inputs that break collision code, as properties with pinned examples.

Each property holds for every draw; the ``@example`` decorators pin the nastiest case of its family so that it
runs in every profile, first. Under the ``nightly`` profile, ``target()`` steers the search toward near misses
(gaps and overlaps close to zero, extreme mass ratios), where round-off decides the answer.

Families (issue "Robustness"): exact touching under the closed-interval convention, tied SAP endpoints, large
coordinates with small objects, zero-size boxes and zero-radius spheres, concentric shapes in GJK/EPA,
degenerate hulls, coincident centres in the elastic formula, mass ratios of 1e12, overlapping-but-receding
pairs, bisection on values near ±1e-200, OBBs separated only along one axis of the first box.
"""
from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import example, given, target
from hypothesis import strategies as st

import engine
from engine.broadphase import brute_force_pairs, cull_separating_sphere_pairs
from engine.gas import collide_elastic
from engine.narrowphase import overlap_convex_sat

METHODS = engine.BROAD_PHASES


def _cube(center, half):
    c = np.asarray(center, dtype=np.float64)
    return np.array([c + half * np.array(s) for s in itertools.product((-1.0, 1.0), repeat=3)])


def _pairs_by_hand(lo, hi):
    n = lo.shape[0]
    return [(i, j) for i in range(n) for j in range(i + 1, n) if np.all(lo[i] <= hi[j]) and np.all(lo[j] <= hi[i])]


# ---------------------------------------------------------------------------------------------------------------
# exact touching, closed intervals, ties, zero sizes, large coordinates
# ---------------------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("method", METHODS)
@given(n=st.integers(2, 30), width=st.integers(0, 3), axis=st.integers(0, 2), offset=st.sampled_from([0.0, 1e8, -1e8]),
       scale=st.sampled_from([1.0, 1e-3, 0.5]))
@example(n=30, width=0, axis=0, offset=1e8, scale=1e-3)   # zero-size boxes, all endpoints tied, far from the origin
@example(n=2, width=1, axis=2, offset=0.0, scale=1.0)     # two unit boxes touching face to face
def test_touching_and_tied_boxes_are_reported_by_every_broad_phase(method, n, width, axis, offset, scale):
    """Boxes on an integer lattice: box i spans [i, i + width] on ``axis`` (so neighbours touch exactly when
    width = 1 and coincide when width = 0) and [0, 1] elsewhere, shifted by ``offset`` and scaled by ``scale``
    (powers of two are exact; 1e-3 and 0.5 keep the comparisons exact because every box uses the same rounding)."""
    lo = np.zeros((n, 3))
    hi = np.ones((n, 3))
    lo[:, axis] = np.arange(n) * (1 if width else 0)
    hi[:, axis] = lo[:, axis] + width
    lo = lo * scale + offset
    hi = hi * scale + offset
    got = engine.find_pairs(lo, hi, method=method)
    expected = _pairs_by_hand(lo, hi)
    assert [tuple(p) for p in got] == expected
    if width == 1 and offset == 0.0 and scale == 1.0:
        assert len(expected) == n - 1  # exact touching counts (closed boxes)


@given(n=st.integers(2, 40), seed=st.integers(0, 2**16))
@example(n=40, seed=0)
def test_sweep_intervals_with_tied_endpoints(n, seed):
    rng = np.random.default_rng(seed)
    begin = rng.integers(0, 4, n).astype(np.float64)  # few distinct values: many ties begin/begin, begin/end
    end = begin + rng.integers(0, 3, n)
    got = engine.sweep_intervals(begin, end)
    expected = [(i, j) for i in range(n) for j in range(i + 1, n) if begin[i] <= end[j] and begin[j] <= end[i]]
    assert [tuple(p) for p in got] == expected


@pytest.mark.parametrize("method", ("grid", *METHODS))
@given(r=st.sampled_from([0.0, 0.5, 1.0, 0.25]), gap=st.sampled_from([0.0, 2.0**-40, -(2.0**-40)]),
       offset=st.sampled_from([0.0, 2.0**26]))
@example(r=0.0, gap=0.0, offset=0.0)        # zero-radius spheres at the same point touch
@example(r=0.5, gap=0.0, offset=2.0**26)    # unit spheres touching exactly, 6.7e7 from the origin
def test_touching_spheres_and_zero_radii(method, r, gap, offset):
    """Two spheres of radius r whose centres are exactly 2r + gap apart (all values exact in binary)."""
    centers = np.array([[offset, 0.0, 0.0], [offset + 2 * r + gap, 0.0, 0.0]])
    if gap < 0 and r == 0.0:
        return  # negative distance between zero-radius spheres is not a geometry
    got = engine.sphere_pairs(centers, np.array([r, r]), method=method)
    touching = abs(centers[1, 0] - centers[0, 0]) <= 2 * r
    assert len(got) == int(touching)


@given(size=st.floats(1e-4, 1e-2), gap=st.floats(-1.0, 1.0), offset=st.sampled_from([1e8, -1e8, 3e7]))
@example(size=1e-3, gap=0.0, offset=1e8)
def test_small_boxes_far_from_the_origin_keep_their_pairs(size, gap, offset):
    """Millimetre boxes at 1e8: every broad phase agrees with brute force on the exact float boxes."""
    rng = np.random.default_rng(1)
    base = offset + np.round(rng.uniform(0, 0.1, size=(20, 3)), 3)
    lo = base
    hi = base + size * (1.0 + gap * 0.5)
    truth = brute_force_pairs(lo, hi)
    for method in METHODS:
        assert np.array_equal(engine.find_pairs(lo, hi, method=method), truth), method


# ---------------------------------------------------------------------------------------------------------------
# GJK / EPA / SAT: concentric, touching, separated along one axis only, far from the origin
# ---------------------------------------------------------------------------------------------------------------

@given(ha=st.floats(0.1, 3.0), hb=st.floats(0.1, 3.0), shift=st.sampled_from([0.0, 1e6]))
@example(ha=1.0, hb=1.0, shift=0.0)   # identical concentric cubes
def test_concentric_cubes_gjk_zero_and_epa_exact_depth(ha, hb, shift):
    a = _cube([shift] * 3, ha)
    b = _cube([shift] * 3, hb)
    d, _, _ = engine.gjk_distance(a, b)
    assert d == 0.0
    depth, normal = engine.epa_penetration(a, b)
    assert abs(np.linalg.norm(normal) - 1.0) < 1e-9
    # concentric axis-aligned cubes: the smallest translation separating them is ha + hb along an axis
    assert depth == pytest.approx(ha + hb, rel=1e-7, abs=1e-9 * (1.0 + shift))


@given(gap=st.floats(0.0, 4.0), axis=st.integers(0, 2), offset=st.sampled_from([0.0, 1e5, -1e5]))
@example(gap=0.0, axis=1, offset=0.0)   # face-to-face contact: distance exactly 0
@example(gap=1e-9, axis=2, offset=0.0)  # a near miss
def test_axis_aligned_cubes_gjk_distance_is_the_gap(gap, axis, offset):
    target(-gap, label="near miss")
    a = _cube([offset] * 3, 1.0)
    c = np.full(3, offset)
    c[axis] += 2.0 + gap
    b = _cube(c, 1.0)
    d, pa, pb = engine.gjk_distance(a, b)
    assert d == pytest.approx(gap, abs=1e-9 * (1.0 + abs(offset)))
    assert np.linalg.norm(pa - pb) == pytest.approx(d, abs=1e-9 * (1.0 + abs(offset)))


def _rot(angle, axis):
    c, s = np.cos(angle), np.sin(angle)
    i, j = [k for k in range(3) if k != axis]
    r = np.eye(3)
    r[i, i], r[i, j], r[j, i], r[j, j] = c, -s, s, c
    return r


@given(angle=st.floats(0.0, np.pi / 2), gap=st.floats(1e-6, 1.0), axis=st.integers(0, 2))
@example(angle=np.pi / 4, gap=1e-6, axis=0)
def test_obbs_separated_only_along_an_axis_of_the_first_box(angle, gap, axis):
    """B is A's neighbour along A's local ``axis`` (gap > 0), rotated about that same axis: every other axis
    family sees the boxes overlap, only A's face axis separates them. SAT must say "apart", and so must GJK."""
    target(-gap, label="near miss")
    ra = _rot(0.3, (axis + 1) % 3)                   # A's axes (columns) in the world
    ea = np.array([1.0, 0.5, 0.25])
    eb = np.array([0.25, 0.25, 0.25])
    u = ra[:, axis]                                  # A's face normal
    rb = ra @ _rot(angle, axis)
    reach_b = np.abs(rb.T @ u) @ eb                  # B's half width along u
    cb = (ea[axis] + gap + reach_b) * u
    a = engine.OBB(np.zeros(3), ra.T, ea)
    b = engine.OBB(cb, rb.T, eb)
    assert not engine.obb_overlap(a, b)
    pts_a = np.array([ra @ (ea * np.array(s)) for s in itertools.product((-1, 1), repeat=3)])
    pts_b = np.array([cb + rb @ (eb * np.array(s)) for s in itertools.product((-1, 1), repeat=3)])
    d, _, _ = engine.gjk_distance(pts_a, pts_b)
    assert d == pytest.approx(gap, rel=1e-6, abs=1e-9)
    assert not overlap_convex_sat(pts_a, pts_b)


@pytest.mark.parametrize("points", [
    np.zeros((6, 3)),                                                       # one point, repeated
    np.array([[0.0, 0, 0], [1, 1, 1], [2, 2, 2], [3, 3, 3]]),               # collinear
    np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0], [0.5, 0.5, 0]]),  # coplanar
    np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]),                          # fewer than 4 points
], ids=["coincident", "collinear", "coplanar", "three-points"])
def test_degenerate_hulls_are_refused_clearly(points):
    with pytest.raises(ValueError, match="points"):
        engine.convex_hull(points)


@given(eps=st.sampled_from([1e-12, 1e-9, 1e-6]))
@example(eps=1e-12)
def test_nearly_flat_hull_is_refused_or_exact(eps):
    """A unit square with one point lifted by eps: either a clean refusal or a hull of the right volume."""
    pts = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0], [0.5, 0.5, eps]])
    try:
        hull = engine.convex_hull(pts)
    except ValueError as exc:
        assert "points" in str(exc)
        return
    assert hull.volume == pytest.approx(eps / 3.0, rel=1e-6)


# ---------------------------------------------------------------------------------------------------------------
# the elastic formula: coincident centres, extreme mass ratios, receding overlaps
# ---------------------------------------------------------------------------------------------------------------

_v = st.lists(st.floats(-10, 10), min_size=3, max_size=3).map(np.array)


@given(v1=_v, v2=_v, log_ratio=st.floats(-12, 12))
@example(v1=np.array([1.0, 0, 0]), v2=np.array([-1.0, 0, 0]), log_ratio=12.0)
@example(v1=np.array([1.0, 0, 0]), v2=np.array([-1.0, 0, 0]), log_ratio=-12.0)
def test_mass_ratio_1e12_conserves_momentum_and_energy(v1, v2, log_ratio):
    target(abs(log_ratio), label="mass ratio")
    m1, m2 = 1.0, 10.0**log_ratio
    p1, p2 = np.zeros(3), np.array([1.0, 0.0, 0.0])
    if (v1 - v2) @ (p1 - p2) >= 0:
        v1, v2 = v2, v1  # make the pair approach
    w1, w2, virial = collide_elastic(v1, v2, m1, m2, p1, p2)
    scale_p = m1 * np.abs(v1).max() + m2 * np.abs(v2).max() + 1e-300
    assert np.allclose(m1 * w1 + m2 * w2, m1 * v1 + m2 * v2, rtol=0, atol=1e-12 * scale_p)
    e0 = m1 * v1 @ v1 + m2 * v2 @ v2
    e1 = m1 * w1 @ w1 + m2 * w2 @ w2
    assert e1 == pytest.approx(e0, rel=1e-9, abs=1e-300)
    assert virial >= 0.0
    assert np.isfinite(w1).all() and np.isfinite(w2).all()


@given(v1=_v, v2=_v)
@example(v1=np.array([1.0, 2.0, 3.0]), v2=np.array([-1.0, 0.0, 0.0]))
def test_coincident_centres_are_returned_unchanged(v1, v2):
    p = np.array([0.5, 0.5, 0.5])
    w1, w2, virial = collide_elastic(v1, v2, 1.0, 2.0, p, p.copy())
    assert np.array_equal(w1, v1) and np.array_equal(w2, v2) and virial == 0.0


@given(depth=st.floats(0.0, 0.9), speed=st.floats(0.01, 5.0))
@example(depth=0.5, speed=1.0)
def test_overlapping_but_receding_pairs_are_left_alone(depth, speed):
    """Two unit-radius spheres overlapping by ``depth`` and moving apart: no impulse (else they would stick), and
    the kinematic broad-phase filter drops the pair."""
    centers = np.array([[0.0, 0, 0], [2.0 - depth, 0, 0]])
    velocities = np.array([[-speed, 0, 0], [speed, 0, 0]])
    w1, w2, virial = collide_elastic(velocities[0], velocities[1], 1.0, 1.0, centers[0], centers[1])
    assert np.array_equal(w1, velocities[0]) and np.array_equal(w2, velocities[1]) and virial == 0.0
    kept = cull_separating_sphere_pairs(np.array([[0, 1]]), centers, 1.0, velocities)
    assert len(kept) == 1 or depth == 0.0  # overlapping pairs are kept for the narrow phase; touching+receding go


# ---------------------------------------------------------------------------------------------------------------
# bisection near ±1e-200
# ---------------------------------------------------------------------------------------------------------------

@given(scale=st.sampled_from([1e-200, -1e-200, 1e-300, 1e200]), root=st.floats(-5, 5), tol=st.floats(1e-12, 1e-3))
@example(scale=1e-200, root=0.1, tol=1e-12)
@example(scale=-1e-200, root=-3.3, tol=1e-10)
def test_bisection_on_tiny_values(scale, root, tol):
    """f(x) = scale·(x − root): the textbook product f(a)·f(x) underflows to 0 at 1e-200; the sign test does not."""
    x = engine.bisect(lambda t: scale * (t - root), root - 1.7, root + 2.9, tol)
    assert abs(x - root) <= tol


# ---------------------------------------------------------------------------------------------------------------
# iteration caps: a loop that cannot finish says so instead of hanging
# ---------------------------------------------------------------------------------------------------------------

def test_gas_event_loop_cap_raises_a_clear_error():
    from engine.gas import GasEventCapReached

    with pytest.raises(GasEventCapReached, match="max_events = 50"):
        engine.simulate_gas(20, radius=0.4, t_equilibrate=0.0, t_measure=50.0, max_events=50, seed=1)


def test_stepped_gas_refuses_an_endless_run():
    with pytest.raises(ValueError, match="dt"):
        engine.simulate_gas(4, radius=0.3, method="stepped", t_measure=1e12, dt=1e-3)


def test_gjk_and_epa_and_toi_caps_raise_their_errors():
    from engine.narrowphase import EPANotConverged, GJKNotConverged, TOINotConverged

    rng = np.random.default_rng(3)
    a = rng.normal(size=(40, 3))
    b = rng.normal(size=(40, 3)) + np.array([5.0, 0.3, 0.1])
    with pytest.raises(GJKNotConverged):
        engine.gjk_distance(a, b, max_iterations=1)
    with pytest.raises((EPANotConverged, GJKNotConverged)):  # EPA starts from GJK's simplex, under the same cap
        engine.epa_penetration(a, a * 0.9 + 0.05, max_iterations=1)
    with pytest.raises(TOINotConverged):
        engine.time_of_impact(a, np.array([1.0, 0, 0]), b + 20.0, np.zeros(3), t_max=100.0, max_iterations=1)


@pytest.mark.parametrize("method", METHODS)
@given(k=st.integers(1, 40), n=st.integers(2, 12))
@example(k=1, n=9)  # the stateful SAP test found this: a span of 5e-324 made the column size 0 (division by zero)
def test_denormal_coordinates(method, k, n):
    """Boxes whose coordinates are a few multiples of the smallest denormal, 5e-324."""
    tiny = 5e-324
    lo = np.zeros((n, 3))
    lo[:, 2] = (np.arange(n) % (k + 1)) * tiny
    hi = lo.copy()
    assert np.array_equal(engine.find_pairs(lo, hi, method=method), brute_force_pairs(lo, hi))


@given(t=st.floats(-0.49, 0.49), r_a=st.floats(0.1, 2.0), r_b=st.floats(0.1, 2.0))  # ends: -x or +x are minimal too
@example(t=0.0, r_a=1.0, r_b=0.5)  # a sphere's centre on a capsule's axis: the cores' Minkowski difference is a segment
def test_sphere_centre_on_a_capsule_axis(t, r_a, r_b):
    """EPA once returned the segment's own direction here (depth right, normal wrong): the minimum translation is
    any direction orthogonal to the axis, by r_a + r_b."""
    c = engine.contact_feature(np.array([[t, 0.0, 0.0]]), np.array([[-0.5, 0, 0], [0.5, 0, 0]]),
                               radius_a=r_a, radius_b=r_b)
    assert c.separation == pytest.approx(-(r_a + r_b), abs=1e-12)
    assert abs(c.normal[0]) <= 1e-12 and abs(np.linalg.norm(c.normal) - 1.0) <= 1e-12


@given(st.integers(0, 2**32 - 1), st.integers(-1000, 480), st.booleans())
@example(seed=0, k=-1000, apart=True)
@example(seed=1, k=480, apart=False)
@example(seed=46, k=-180, apart=True)  # degree-6 products in GJK's tetrahedron test underflowed: a false overlap
def test_narrow_phase_answers_scale_with_the_shapes_over_the_whole_range(seed, k, apart):
    """Shapes scaled by 2^k (exact), from 2^-1000 to 2^480 (coordinates up to ~1e145): distances, depths and
    separations scale by 2^k, normals do not change. (Below about 1e-60 squared cross products underflow and above
    1e75 they overflow: the kernels solve such pairs on copies scaled into range.)"""
    rng = np.random.default_rng(seed)
    a = rng.normal(size=(int(rng.integers(1, 9)), 3))
    b = rng.normal(size=(int(rng.integers(1, 9)), 3)) + (rng.normal(size=3) * 4.0 if apart else 0.3)
    s = 2.0**k
    d1, _, _ = engine.gjk_distance(a, b)
    ds, ca, cb = engine.gjk_distance(a * s, b * s)
    assert abs(ds / s - d1) <= 1e-9 * max(d1, 1.0)
    assert abs(np.linalg.norm((ca - cb) / s) - ds / s) <= 1e-9 * max(d1, 1.0)  # (norm of 1e-301s underflows)
    depth1, n1 = engine.epa_penetration(a, b)
    depth_s, n_s = engine.epa_penetration(a * s, b * s)
    assert abs(depth_s / s - depth1) <= 1e-9 * max(depth1, 1.0)
    if depth1 > 1e-6 or d1 > 1e-6:
        assert np.allclose(n_s, n1, atol=1e-9), (n_s, n1)
    c1 = engine.contact_feature(a, b)
    c_s = engine.contact_feature(a * s, b * s)
    assert abs(c_s.separation / s - c1.separation) <= 1e-9 * max(abs(c1.separation), 1.0)
    assert np.allclose(c_s.normal, c1.normal, atol=1e-9) or abs(c1.separation) <= 1e-6
    assert np.all(np.isfinite(c_s.points)) and np.allclose(c_s.points / s, c1.points, atol=1e-8)
