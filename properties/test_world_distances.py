"""Properties of ``World.closest_points(ids_a, ids_b)`` and ``World.pairs_within(margin)`` (the "distance" question
of the dispatch table).

- oracles: two convex bodies apart — ``engine.gjk_distance`` on their world core points minus the two radii;
  overlapping — minus the depth of ``World.contacts()`` for the pair, and ``engine.epa_penetration`` for two
  polytopes; two spheres exactly |c_a − c_b| − r_a − r_b; a body over a Plane: min over its core points of
  y − altitude, minus its radius; the witness points: |point_b − point_a| = |distance|, point_b − point_a along
  the normal from the first body to the second (closest points when apart, deepest points when overlapping);
- the sign is the overlap test's: distance <= 0 exactly when ``pairs()`` reports the pair (closed), distance < 0
  exactly when ``contacts()`` reports a positive depth for it (within round-off), compounds and grounds included;
- ``pairs_within(margin)`` is the brute force over every pair of bodies (``closest_points``, then the filter of
  ``pairs()``: Box2D's rule, exclusions, two sensors never, two static bodies never — sensors are reported, as by
  ``pairs()``), for random margins and margin 0, where it is ``pairs()`` itself; it grows with the margin;
- moving every body by one vector leaves the distances unchanged;
- bad arguments raise ValueError / TypeError naming the argument and the first bad index, the world unchanged;
- each checker flags a planted defect (a kernel off by 1e-3, a margin ignored, a kernel that depends on the
  position).
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import engine.world.world as world_module
from engine import HeightField, Plane, Sphere, World, epa_penetration, gjk_distance
from engine.world import TABLE
from engine.world.dispatch import Kernel
from properties.strategies.world import any_bodies_near, bodies, curves, ground_kinds, planes, registered_shapes

#: a scene of side ~4: bodies touch, overlap and stand apart in about equal measure
CENTERS = st.tuples(*[st.floats(-2.0, 2.0, allow_nan=False) | st.integers(-2, 2).map(float)] * 3).map(np.array)
NEAR_GROUNDS = planes | curves | registered_shapes(ground_kinds, st.tuples(st.just(0.0), st.floats(-2.0, 0.0),
                                                                           st.just(0.0)).map(np.array))
#: absolute tolerance of the oracles (scene coordinates ~5: GJK and EPA stop at 1e-12 relative, the curve's
#: golden-section search at ~1e-9 of its window)
TOL = 1e-7
FEW = settings(max_examples=40)


def _scene(shapes, ground=None, static=()):
    world = World()
    if ground is not None:
        world.add(ground)
    for k, shape in enumerate(shapes):
        world.add(shape, static=k in static)
    return world


def _all_pairs(world):
    """Every pair of ids closest_points accepts (not two grounds), i < j."""
    ids = world.ids()
    bounded = world.bodies().bounded
    return np.array([(i, j) for x, i in enumerate(ids) for j in ids[x + 1:] if bounded[i] or bounded[j]],
                    np.int64).reshape(-1, 2)


# -- the checkers (each raises AssertionError) ------------------------------------------------------------------
def check_witnesses(distance, point_a, point_b):
    """|point_b − point_a| = |distance|, every value finite."""
    assert np.isfinite(distance).all() and np.isfinite(point_a).all() and np.isfinite(point_b).all()
    gap = np.linalg.norm(point_b - point_a, axis=1)
    np.testing.assert_allclose(gap, np.abs(distance), rtol=0, atol=TOL)


def check_convex_oracle(world, i, j):
    """closest_points of two convex bodies against GJK on the core points, the contacts' depth and EPA."""
    d, pa, pb = (x[0] for x in world.closest_points([i], [j]))
    check_witnesses(np.array([d]), pa[None], pb[None])
    core = gjk_distance(world.world_points(i), world.world_points(j))[0]
    ra, rb = world.radius(i), world.radius(j)
    if core - ra - rb > TOL:
        assert d == pytest.approx(core - ra - rb, abs=TOL)
        return
    contacts = world.contacts()
    depth = contacts.depth[(contacts.pairs == sorted((i, j))).all(axis=1)]
    assert depth.size, (i, j)  # touching (within round-off): contacts() has the pair
    assert d == pytest.approx(-depth.max(), abs=TOL)
    if ra == rb == 0.0 and core == 0.0:  # two polytopes that overlap
        assert d == pytest.approx(-epa_penetration(world.world_points(i), world.world_points(j))[0], abs=TOL)


def check_sign(world):
    """distance <= 0 iff pairs() has the pair; distance < 0 (beyond round-off) iff contacts() gives it a depth,
    then -distance is that depth (the largest over a compound's parts)."""
    pairs = _all_pairs(world)
    if not pairs.shape[0]:
        return
    d, pa, pb = world.closest_points(pairs[:, 0], pairs[:, 1])
    check_witnesses(d, pa, pb)
    static = world.bodies().static
    askable = ~(static[pairs[:, 0]] & static[pairs[:, 1]])
    touching = {tuple(p) for p in world.pairs().tolist()}
    for p, (i, j) in enumerate(pairs.tolist()):
        if askable[p]:
            assert (d[p] <= 0.0) == ((i, j) in touching), (i, j, d[p])
    contacts = world.contacts()
    for p, (i, j) in enumerate(pairs.tolist()):
        if not askable[p]:
            continue
        depth = contacts.depth[(contacts.pairs == (i, j)).all(axis=1)]
        if d[p] < -TOL:
            assert depth.size and -d[p] == pytest.approx(depth.max(), abs=TOL), (i, j)
        elif depth.size and depth.max() > TOL:
            raise AssertionError(f"pair {(i, j)}: contact depth {depth.max()} but distance {d[p]}")


def passes_filter(world, filters, excluded, i, j):
    """Box2D's rule, the exclusions, two sensors never, two static bodies never (the model of ``pairs()``)."""
    static = world.bodies().static
    if static[i] and static[j] or (i, j) in excluded:
        return False
    (ci, mi, gi, si), (cj, mj, gj, sj) = filters.get(i, (1, -1, 0, False)), filters.get(j, (1, -1, 0, False))
    if si and sj:
        return False
    if gi == gj != 0:
        return gi > 0
    return bool(ci & mj) and bool(cj & mi)


def check_pairs_within(world, margin, filters=None, excluded=()):
    """pairs_within(margin) = the brute force: every pair of ``_all_pairs`` that passes the filter, with its
    closest_points distance <= margin."""
    got, dist = world.pairs_within(margin)
    assert got.dtype == np.int64 and got.shape[1] == 2
    assert (got[:, 0] < got[:, 1]).all()
    assert [tuple(p) for p in got.tolist()] == sorted({tuple(p) for p in got.tolist()})
    pairs = _all_pairs(world)
    want = np.empty((0, 2), np.int64)
    want_d = np.empty(0)
    if pairs.shape[0]:
        d = world.closest_points(pairs[:, 0], pairs[:, 1])[0]
        keep = np.array([passes_filter(world, filters or {}, excluded, i, j) for i, j in pairs.tolist()], bool)
        near = keep & (d <= margin)
        want, want_d = pairs[near], d[near]
    np.testing.assert_array_equal(got, want)
    # the same kernels on the same poses; the curve's vectorised search rounds differently in another batch
    np.testing.assert_allclose(dist, want_d, rtol=0, atol=TOL)


def _distances_of(world, pairs):
    return world.closest_points(pairs[:, 0], pairs[:, 1])[0]


def check_translation(world, shift):
    """Moving every (moving) body by ``shift`` leaves every distance unchanged."""
    pairs = _all_pairs(world)
    before = _distances_of(world, pairs)
    ids = np.array([i for i in world.ids().tolist() if not world.is_static(i)], np.int64)
    centers = np.array([world.pose(i)[0] for i in ids.tolist()]).reshape(-1, 3)
    world.update(ids, centers + shift)
    after = _distances_of(world, pairs)
    world.update(ids, centers)
    scale = 1.0 + np.abs(shift).max()
    np.testing.assert_allclose(after, before, rtol=0, atol=TOL * scale)


# -- the properties ---------------------------------------------------------------------------------------------
@FEW
@given(bodies, bodies)
def test_two_convex_bodies_against_gjk_epa_and_the_contacts(a, b):
    world = _scene([a, b])
    check_convex_oracle(world, 0, 1)
    check_convex_oracle(world, 1, 0)


@FEW
@given(CENTERS, st.floats(0.1, 1.5), CENTERS, st.floats(0.1, 1.5))
def test_two_spheres_exactly(ca, ra, cb, rb):
    world = _scene([Sphere(ca, ra), Sphere(cb, rb)])
    d, pa, pb = world.closest_points([0], [1])
    assert d[0] == pytest.approx(np.linalg.norm(cb - ca) - ra - rb, abs=1e-12)
    check_witnesses(d, pa, pb)
    if np.linalg.norm(cb - ca) > 1e-9:  # the witnesses lie on the spheres, along the line of the centres
        assert np.linalg.norm(pa[0] - ca) == pytest.approx(ra, abs=1e-12)
        assert np.linalg.norm(pb[0] - cb) == pytest.approx(rb, abs=1e-12)


@FEW
@given(any_bodies_near(CENTERS), st.floats(-3.0, 1.0))
def test_a_body_against_a_plane(shape, altitude):
    world = _scene([shape], ground=Plane(altitude))
    d, pa, pb = world.closest_points([1, 0], [0, 1])
    parts = range(len(shape.parts)) if hasattr(shape, "parts") else [None]
    want = min((world.world_points(1, part=k)[:, 1] - altitude).min() - world.radius(1, part=k) for k in parts)
    np.testing.assert_allclose(d, [want, want], rtol=0, atol=1e-12)
    check_witnesses(d, pa, pb)
    np.testing.assert_allclose(pb[0, 1], altitude, atol=1e-12)  # the ground's witness is on the plane
    np.testing.assert_allclose(pa[1, 1], altitude, atol=1e-12)


@FEW
@given(st.lists(any_bodies_near(CENTERS), min_size=1, max_size=5), st.none() | NEAR_GROUNDS, st.data())
def test_the_sign_is_the_overlap_test(shapes, ground, data):
    static = set(data.draw(st.sets(st.integers(0, len(shapes) - 1))))
    world = _scene(shapes, ground, static)
    check_sign(world)


@FEW
@given(st.lists(any_bodies_near(CENTERS), min_size=1, max_size=5), NEAR_GROUNDS)
def test_a_curve_or_any_ground_witness_is_on_the_ground(shapes, ground):
    world = _scene(shapes, ground)
    ids = world.ids()[1:]  # the ground is 0
    d, pa, pb = world.closest_points(ids, np.zeros_like(ids))
    check_witnesses(d, pa, pb)
    apart = d > 0
    if hasattr(ground, "f"):
        np.testing.assert_allclose(pb[apart, 1], ground.height(pb[apart, 0]), atol=1e-9)
    if hasattr(ground, "mesh"):  # a triangle surface: the ground's witness lies on one of its triangles
        for k in np.flatnonzero(apart).tolist():
            on = min(gjk_distance(pb[k][None], ground.mesh.vertices[t])[0] for t in ground.mesh.triangles)
            assert on <= TOL
        return
    # never farther than the gap straight down (the vertical distance bounds the distance)
    for k, i in enumerate(ids.tolist()):
        if apart[k]:
            lo = world.aabb(i)[0]
            level = ground.height(np.array([pa[k, 0]]))[0] if hasattr(ground, "f") else ground.center[1]
            assert d[k] <= pa[k, 1] - level + TOL and lo[1] <= pa[k, 1] + TOL


FILTERS = st.tuples(st.integers(1, 3), st.integers(0, 3), st.sampled_from([0, 0, 1, -1]), st.booleans())


@FEW
@given(st.lists(st.tuples(any_bodies_near(CENTERS), FILTERS, st.booleans()), min_size=1, max_size=6),
       st.none() | NEAR_GROUNDS, st.floats(0.0, 3.0) | st.just(0.0), st.sampled_from(["tree", "sap", "brute"]),
       st.data())
def test_pairs_within_is_the_brute_force(items, ground, margin, method, data):
    world = World(method)
    if ground is not None:
        world.add(ground)
    filters = {}
    for shape, (cat, mask, group, sensor), static in items:
        i = world.add(shape, static=static, category=cat, mask=mask, group=group, sensor=sensor)
        filters[i] = (cat, mask, group, sensor)
    ids = world.ids().tolist()
    excluded = set()
    if len(ids) > 1 and data.draw(st.booleans()):
        i, j = sorted(data.draw(st.lists(st.sampled_from(ids), min_size=2, max_size=2, unique=True)))
        world.exclude(i, j)
        excluded.add((i, j))
    check_pairs_within(world, margin, filters, excluded)
    check_pairs_within(world, 0.0, filters, excluded)
    np.testing.assert_array_equal(world.pairs_within(0.0)[0], world.pairs())  # sensors included, as pairs()
    small, big = world.pairs_within(margin / 2)[0], world.pairs_within(margin)[0]
    assert {tuple(p) for p in small.tolist()} <= {tuple(p) for p in big.tolist()}


@FEW
@given(st.lists(any_bodies_near(CENTERS), min_size=2, max_size=4), st.none() | planes,
       st.tuples(*[st.floats(-5.0, 5.0)] * 3).map(np.array))
def test_translation_leaves_distances_unchanged(shapes, ground, shift):
    world = _scene(shapes)
    if ground is not None:  # a ground does not move: shift only along it
        world.add(ground)
        shift = shift * np.array([1.0, 0.0, 1.0])
    check_translation(world, shift)


def _world_for_errors():
    world = World()
    world.add(Plane(-1.0))
    world.add(Sphere([0.0, 0.0, 0.0], 0.5))
    world.add(Sphere([2.0, 0.0, 0.0], 0.5), static=True)
    world.add(Plane(-3.0))
    world.add(HeightField(np.zeros((2, 2)), 1.0, (5.0, 5.0)))
    return world


@pytest.mark.parametrize("ids_a, ids_b, error, message", [
    ([1, 2], [2, 9], ValueError, r"ids_b\[1\] = 9 is not a body"),
    ([1, -1], [2, 1], ValueError, r"ids_a\[1\] = -1 is not a body"),
    ([1, 2, 1], [2, 1, 1], ValueError, r"ids_b\[2\] = 1 is ids_a\[2\]"),
    ([1, 0], [2, 3], ValueError, r"ids_a\[1\] = 0 and ids_b\[1\] = 3 are both level geometry"),
    ([4, 1], [0, 4], ValueError, r"ids_a\[0\] = 4 and ids_b\[0\] = 0 are both level geometry"),
    ([1, 2], [2], ValueError, "ids_a and ids_b must have the same length"),
    ([1.0], [2], TypeError, "ids_a must be a 1-D integer array"),
    ([1], [[2]], TypeError, "ids_b must be a 1-D integer array"),
])
def test_bad_ids_are_named_and_leave_the_world_unchanged(ids_a, ids_b, error, message):
    world = _world_for_errors()
    before = (world.ids().copy(), world.pairs().copy(), world.bodies().center.copy())
    with pytest.raises(error, match=message):
        world.closest_points(np.array(ids_a), np.array(ids_b))
    np.testing.assert_array_equal(world.ids(), before[0])
    np.testing.assert_array_equal(world.pairs(), before[1])
    np.testing.assert_array_equal(world.bodies().center, before[2])
    d = world.closest_points(np.array([1, 2, 0, 2]), np.array([2, 1, 1, 3]))[0]  # static and grounds are fine
    np.testing.assert_allclose(d, [1.0, 1.0, 0.5, 2.5])


@pytest.mark.parametrize("margin, error", [(-0.1, ValueError), (np.inf, ValueError), (np.nan, ValueError),
                                           ("1", TypeError), (True, TypeError)])
def test_a_bad_margin_is_named(margin, error):
    world = _world_for_errors()
    with pytest.raises(error, match="margin"):
        world.pairs_within(margin)


def test_empty_and_touching_answers():
    world = World()
    assert world.pairs_within(1.0)[0].shape == (0, 2)
    d = world.closest_points(np.empty(0, np.int64), np.empty(0, np.int64))[0]
    assert d.shape == (0,)
    world.add(Sphere([0.0, 0.0, 0.0], 1.0))
    world.add(Sphere([2.0, 0.0, 0.0], 1.0))  # touching: distance 0, a pair at margin 0
    pairs, dist = world.pairs_within(0.0)
    np.testing.assert_array_equal(pairs, [[0, 1]])
    assert dist.tolist() == [0.0]


# -- the checkers flag planted defects ------------------------------------------------------------------------
def _planted(monkeypatch, change):
    """Every distance kernel of the table followed by ``change(ctx, pairs, sel, out)``."""
    def planted(kernel):
        def run(ctx, pairs, sel, out):
            kernel.run(ctx, pairs, sel, out)
            change(ctx, pairs, sel, out)
        return Kernel(kernel.name, run)
    monkeypatch.setitem(TABLE.kernels, "distance", [planted(k) for k in TABLE.kernels["distance"]])


def _off_by(delta):
    def change(ctx, pairs, sel, out):
        out.distance[sel] += delta
    return change


def test_the_checkers_flag_planted_defects(monkeypatch):
    from engine import Box

    apart = _scene([Box([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]), Box([3.0, 0.5, 0.0], [1.0, 1.0, 1.0])])
    deep = _scene([Box([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]), Sphere([0.0, 1.5, 0.0], 1.0)], ground=Plane(-0.5))
    check_convex_oracle(apart, 0, 1)
    check_sign(deep)
    check_pairs_within(apart, 1.5)
    check_translation(deep, np.array([1.0, 0.0, 2.0]))
    with monkeypatch.context() as m:
        _planted(m, _off_by(1e-3))
        with pytest.raises(AssertionError):
            check_convex_oracle(apart, 0, 1)
    with monkeypatch.context() as m:
        _planted(m, _off_by(1e-3))
        with pytest.raises(AssertionError):
            check_sign(deep)
    with monkeypatch.context() as m:  # the margin dropped before the box test
        real = world_module.answer
        m.setattr(world_module, "answer",
                  lambda *args: real(*args[:-1], args[-1] if np.isinf(args[-1]) else 0.0))
        with pytest.raises(AssertionError):
            check_pairs_within(apart, 1.5)

    def by_position(ctx, pairs, sel, out):
        out.distance[sel] += 1e-3 * out.point_a[sel, 0]
    with monkeypatch.context() as m:
        _planted(m, by_position)
        with pytest.raises(AssertionError):
            check_translation(deep, np.array([1.0, 0.0, 2.0]))
