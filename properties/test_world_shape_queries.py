"""Shape queries of the World (``query_aabb``, ``overlap``, ``cast_shape``) against independent answers.

- ``query_aabb``: a brute force over ``world.ids()`` with ``world.aabb(i)`` (a ground: its kind's candidates test on
  the box) and the category rule, for every broad phase;
- ``overlap``: the same scene rebuilt with the query shape as one more body, read off ``pairs()`` (the frame's
  pipeline: broad phase, filter, overlap table);
- ``cast_shape``: a sampled sweep — GJK distances of the cores minus the radii for bodies, the altitude for a
  Plane, the curve's own gap (``ground_gap`` of the lower boundary) for a HeightCurve: the reported fraction
  touches, no sampled earlier fraction does, a miss touches at no sampled fraction; the point lies on both
  surfaces, the normal is unit and against the motion; a sphere cast against a sphere is the quadratic's root;
- the world is unchanged by every query, failing ones included (ids, the store's live rows, the scratch rows past
  them, pairs, stats);
- each checker flags a planted defect (a dropped id, a shifted fraction).
"""
from __future__ import annotations

import copy
import os

import numpy as np
import pytest
from hypothesis import event, given, settings
from hypothesis import strategies as st

import engine
from engine import (
    ALL,
    BROAD_PHASES,
    Box,
    Capsule,
    Compound,
    ConvexPolyhedron,
    HeightCurve,
    Plane,
    ShapeHit,
    Sphere,
    World,
    epa_penetration,
    gjk_distance,
)
from engine.narrowphase.curve_ground import ground_gap, lower_boundary
from engine.world import shape_queries
from engine.world.bodies import _FIELDS

from .strategies.world import any_bodies, grounds, positions, velocities

FEW = settings(max_examples=40)
TOUCH_TOL = 1e-7  # a fraction's distance: the advancement stops at 1e-9, GJK's round-off on top
INSIDE = -1e-9  # an earlier fraction "touches" when it is deeper than the advancement's tolerance

# -- scenes ----------------------------------------------------------------------------------------------------
categories = st.sampled_from([1, 2, 3, 4, 1 << 63])
masks = st.sampled_from([ALL, 1, 2, 4, 6, 1 << 63, 0])


@st.composite
def scenes(draw, max_bodies=6, with_grounds=True):
    """A World over a drawn broad phase: bodies of every bounded kind (moving or static, a category, maybe a
    sensor), maybe a ground, maybe after a frame (the broad phases' state)."""
    world = World(broad_phase=draw(st.sampled_from(BROAD_PHASES)))
    for shape in draw(st.lists(any_bodies, min_size=0, max_size=max_bodies)):
        world.add(shape, static=draw(st.booleans()), category=draw(categories), sensor=draw(st.booleans()))
    if with_grounds and draw(st.booleans()):
        world.add(draw(grounds), category=draw(categories))
    if world.ids().size and draw(st.booleans()):
        world.remove(int(draw(st.sampled_from(world.ids().tolist()))))
    if draw(st.booleans()):
        world.pairs()
    return world


def snapshot(world):
    """What a user (and the next query) can see of a world, plus the store's scratch rows past the live ones.

    ``pairs()`` runs first (it refreshes the broad phase's fat boxes and ``stats``, so a second snapshot with no
    query in between is equal); ``stats`` is read before it (the last query's, which a shape query must leave)
    and after it."""
    stats_in = world.stats
    pairs = world.pairs().copy()
    st_ = world._store
    n = st_.n_ids
    past = {name: getattr(st_, name)[n:].copy() for name in _FIELDS}
    return dict(stats_in=stats_in, pairs=pairs, stats_out=world.stats, ids=world.ids().copy(),
                bodies={k: v.copy() for k, v in world.bodies()._asdict().items()}, n=n, free=list(st_.free),
                excluded=world.excluded().copy(), past=past, points=st_.points[n:].copy())


def assert_same(a, b):
    assert b["stats_in"] is a["stats_out"]  # the query left stats alone
    for key in ("pairs", "ids", "excluded"):
        np.testing.assert_array_equal(a[key], b[key], err_msg=key)
    for k in a["bodies"]:
        np.testing.assert_array_equal(a["bodies"][k], b["bodies"][k], err_msg=k)
    assert (a["n"], a["free"]) == (b["n"], b["free"])
    for k, rows in b["past"].items():  # the rows past the live ones are fresh (the store may have grown)
        if k in ("rotation", "part_rotation"):
            assert (rows == np.eye(3)).all(), k
        else:
            assert (rows == _FIELDS[k][2]).all(), k
    assert (b["points"] == 0.0).all()


def moved(shape, offset):
    """The shape translated by offset (same geometry, same rotation)."""
    out = copy.copy(shape)
    out.center = shape.center + np.asarray(offset, float)
    return out


def cores(shape, offset=None):
    """[(world points (m, 3), radius)] of a shape's convex cores (a compound: its parts), translated."""
    offset = np.zeros(3) if offset is None else offset
    if isinstance(shape, Compound):
        out = []
        for part, position, rotation in shape.parts:
            local = position + part.local @ rotation.T
            out.append((shape.center + offset + local @ shape.rotation.T, part.radius))
        return out
    return [(shape.world_points() + offset, shape.radius)]


def body_cores(world, i):
    parts = world._store.parts_of(i)
    return [(world.world_points(i, k if parts else None), world.radius(i, k if parts else None))
            for k in range(max(len(parts), 1))]


def eligible(world, mask, *, sensors):
    b = world.bodies()
    return [int(i) for i in world.ids() if int(b.category[i]) & mask and (sensors or not b.sensor[i])]


def gap(world, i, shape, offset):
    """Signed-ish distance of ``shape`` translated by offset to body i (0 when the cores overlap: GJK), or the
    ground's gap."""
    ground = world.shape(i)
    if isinstance(ground, Plane):
        return min(float((p[:, 1] - r).min()) for p, r in cores(shape, offset)) - ground.altitude
    if isinstance(ground, HeightCurve):
        out = np.inf
        for p, r in cores(shape, offset):
            out = min(out, float(ground_gap(ground, lower_boundary(p[None], np.array([r]), ground.samples))[0][0]))
        return out
    return min(gjk_distance(pa, pb)[0] - ra - rb for pa, ra in body_cores(world, i) for pb, rb in cores(shape, offset))


def depth(world, i, shape, offset):
    """How deep ``shape`` translated by offset is in body i (>= 0): the radii less the cores' GJK distance, or
    with EPA's depth when the cores overlap; a ground's: minus its gap."""
    if not world.shape(i).kind.bounded:
        return max(-gap(world, i, shape, offset), 0.0)
    out = 0.0
    for pa, ra in body_cores(world, i):
        for pb, rb in cores(shape, offset):
            d = gjk_distance(pa, pb)[0]
            inside = epa_penetration(pa, pb)[0] if d == 0.0 else -d
            out = max(out, inside + ra + rb)
    return out


def surface_distance(world, i, point):
    """Distance of a point to body i (0 inside), or |height above the plane|; None for a curve."""
    ground = world.shape(i)
    if isinstance(ground, Plane):
        return abs(point[1] - ground.altitude)
    if isinstance(ground, HeightCurve):
        return None
    return min(gjk_distance(p, point[None])[0] - r for p, r in body_cores(world, i))


# -- the checkers (each returns the list of what is wrong) ---------------------------------------------------------
def aabb_problems(world, lo, hi, mask, got):
    want = []
    for i in world.ids().tolist():
        if not int(world.bodies().category[i]) & mask:
            continue
        shape = world.shape(i)
        if not shape.kind.bounded:
            hit = bool(shape.kind.candidates(shape, np.asarray(lo, float)[None], np.asarray(hi, float)[None])[0])
        else:
            blo, bhi = world.aabb(i)
            hit = bool((blo <= hi).all() and (lo <= bhi).all())
        if hit:
            want.append(i)
    return [] if np.array_equal(got, np.array(want, np.int64)) else [f"query_aabb {got.tolist()} != {want}"]


def overlap_reference(world, shape, mask):
    """The bodies overlapping ``shape`` by the frame: the scene rebuilt in a new World (current poses, same
    static / category / sensor flags) with the shape as one more body, read off ``pairs()``."""
    other = World()
    b = world.bodies()
    original = {}
    for i in world.ids().tolist():
        body = world.shape(i)
        if body.kind.bounded:
            c, r, _ = world.pose(i)
            body = copy.copy(body)
            body.center, body.rotation = c, r
        j = other.add(body, static=bool(b.static[i]), category=int(b.category[i]), sensor=bool(b.sensor[i]))
        original[j] = i
    q = other.add(shape, category=ALL)
    pairs = other.pairs()
    with_q = pairs[(pairs == q).any(axis=1)]
    found = sorted(original[j] for j in np.where(with_q[:, 0] == q, with_q[:, 1], with_q[:, 0]).tolist())
    return np.array([i for i in found if int(b.category[i]) & mask], np.int64)


def overlap_problems(world, shape, mask, got):
    want = overlap_reference(world, shape, mask)
    return [] if np.array_equal(got, want) else [f"overlap {got.tolist()} != {want.tolist()}"]


def cast_problems(world, shape, displacement, mask, hit, samples=64):
    d = np.asarray(displacement, float)
    targets = eligible(world, mask, sensors=False)
    scale = 1.0 + float(np.abs(d).max()) + max((float(np.abs(p).max()) + r for p, r in cores(shape)), default=0.0)
    problems = []

    def touching(fraction):
        return [i for i in targets if gap(world, i, shape, fraction * d) <= INSIDE * scale]

    if hit is None:
        for s in np.linspace(0.0, 1.0, samples):
            if touching(s):
                problems.append(f"None, but fraction {s} touches {touching(s)}")
                break
        return problems
    f = hit.fraction
    if not (0.0 <= f <= 1.0) or hit.body not in targets:
        return [f"fraction {f} or body {hit.body} not allowed (targets {targets})"]
    at = gap(world, hit.body, shape, f * d)
    if at > TOUCH_TOL * scale:
        problems.append(f"body {hit.body} is {at} apart at fraction {f}")
    if f > 1e-6:
        for s in np.linspace(0.0, f - 1e-6, samples):
            if touching(s):
                problems.append(f"fraction {s} < {f} already touches {touching(s)}")
                break
    if abs(np.linalg.norm(hit.normal) - 1.0) > 1e-9:
        problems.append(f"normal {hit.normal} is not unit")
    if f > 0.0 and hit.normal @ d > 1e-6 * np.linalg.norm(d):
        problems.append(f"normal {hit.normal} does not oppose the motion {d}")
    on_body = surface_distance(world, hit.body, hit.point)
    on_shape = min(gjk_distance(p, hit.point[None])[0] - r for p, r in cores(shape, f * d))
    tol = 1e-6 * scale
    deep = at <= 0.0 and depth(world, hit.body, shape, f * d) > tol  # started inside: the contact's own point
    if not deep and ((on_body is not None and on_body > tol) or on_shape > tol):
        problems.append(f"point {hit.point} is off the surfaces: {on_body}, {on_shape}")
    return problems


# -- properties -------------------------------------------------------------------------------------------------
boxes_lo_size = st.tuples(positions, st.tuples(*[st.floats(0.0, 4.0)] * 3).map(np.array))


@FEW
@given(scenes(), boxes_lo_size, masks)
def test_query_aabb_is_the_brute_force(world, box, mask):
    lo, size = box
    before = snapshot(world)
    got = world.query_aabb(lo, lo + size, mask=mask)
    assert got.dtype == np.int64
    assert aabb_problems(world, lo, lo + size, mask, got) == []
    assert_same(before, snapshot(world))


@FEW
@given(scenes(), any_bodies, masks)
def test_overlap_is_the_frame_with_the_shape_added(world, shape, mask):
    before = snapshot(world)
    got = world.overlap(shape, mask=mask)
    assert got.dtype == np.int64
    assert overlap_problems(world, shape, mask, got) == []
    assert_same(before, snapshot(world))


@st.composite
def casts(draw):
    """(world, shape, displacement, mask): a drawn sweep, or (half the time) one aimed at a body's AABB centre
    from well outside it (overshooting or falling short), so that hits at fractions > 0 are common."""
    world, shape, displacement = draw(scenes(max_bodies=4)), draw(any_bodies), draw(velocities)
    mask = draw(masks)
    bounded = [i for i in eligible(world, mask, sensors=False) if world.shape(i).kind.bounded]
    if bounded and draw(st.booleans()):
        lo, hi = world.aabb(draw(st.sampled_from(bounded)))
        away = draw(st.tuples(*[st.floats(-1.0, 1.0)] * 3).map(np.array))
        shape = moved(shape, 0.5 * (lo + hi) - shape.center + 6.0 * away / max(np.linalg.norm(away), 1e-3))
        displacement = (0.5 * (lo + hi) - shape.center) * draw(st.floats(0.7, 1.5)) + draw(velocities) * 0.1
    return world, shape, displacement, mask


@settings(max_examples=int(os.environ.get("SHAPEQ_EXAMPLES", 30)))
@given(casts())
def test_cast_shape_is_the_first_touch(case):
    world, shape, displacement, mask = case
    before = snapshot(world)
    hit = world.cast_shape(shape, displacement, mask=mask)
    assert hit is None or isinstance(hit, ShapeHit)
    event("miss" if hit is None else f"hit a {world.kind(hit.body)} at {'0' if hit.fraction == 0 else '> 0'}")
    assert cast_problems(world, shape, displacement, mask, hit) == []
    assert_same(before, snapshot(world))


@FEW
@given(positions, st.floats(0.2, 1.5), positions, st.floats(0.2, 1.5), velocities)
def test_sphere_cast_against_a_sphere_is_the_quadratic(c0, r0, c1, r1, d):
    world = World()
    world.add(Sphere(c1, r1))
    hit = world.cast_shape(Sphere(c0, r0), d)
    # |c0 + t d - c1| = r0 + r1: a t^2 + 2 b t + c = 0, first root in [0, 1]
    m, r = c0 - c1, r0 + r1
    a, b, c = d @ d, m @ d, m @ m - r * r
    if c <= 0.0:
        want = 0.0
    elif a == 0.0 or b >= 0.0 or b * b - a * c < 0.0:
        want = None
    else:
        want = (-b - np.sqrt(b * b - a * c)) / a
        want = want if want <= 1.0 else None
    if want is None or hit is None:  # a miss; or a root at 1 within round-off
        assert hit is None or hit.fraction > 1.0 - 1e-9
        assert want is None or want > 1.0 - 1e-9
        return
    assert hit.body == 0
    assert hit.fraction == pytest.approx(want, abs=1e-9)
    centre = c0 + hit.fraction * d
    if np.linalg.norm(centre - c1) > 1e-6:
        np.testing.assert_allclose(hit.normal, (centre - c1) / np.linalg.norm(centre - c1), atol=1e-7)
    if c > 0.0:
        np.testing.assert_allclose(hit.point, c1 + r1 * hit.normal, atol=1e-7)


def test_ground_rules_and_compound_ids():
    world = World()
    plane = world.add(Plane(0.0))
    comp = world.add(Compound([Sphere([0, 0, 0], 0.5), Box([0, 0, 0], [0.5, 0.5, 0.5])], [[0, 1, 0], [2, 1, 0]]))
    curve = world.add(HeightCurve(lambda x: -3.0 + 0.0 * x))
    assert world.query_aabb([-1, 2, -1], [1, 3, 1]).tolist() == []  # above the plane: not reported
    assert world.query_aabb([-1, -1, -1], [1, 3, 1]).tolist() == [plane, comp]
    assert world.query_aabb([-1, -9, -1], [1, 3, 1]).tolist() == [plane, comp, curve]
    assert world.overlap(Sphere([2, 1, 0], 0.1)).tolist() == [comp]  # the part 1's box: the compound's id
    hit = world.cast_shape(Sphere([2, 4, 0], 0.5), [0, -4, 0])
    assert hit.body == comp and hit.fraction == pytest.approx(0.5)
    np.testing.assert_allclose(hit.normal, [0, 1, 0], atol=1e-12)
    hit = world.cast_shape(Sphere([9, 4, 0], 0.5), [0, -10, 0])
    assert hit.body == plane and hit.fraction == pytest.approx(0.35)
    np.testing.assert_allclose(hit.point, [9, 0, 0], atol=1e-9)
    hit = world.cast_shape(Sphere([9, 4, 0], 0.5), [0, -10, 0], mask=0)
    assert hit is None


def test_sensors_masks_and_zero_displacement():
    world = World()
    sensor = world.add(Sphere([0, 0, 0], 1.0), sensor=True, category=2)
    solid = world.add(Box([3, 0, 0], [1, 1, 1]), category=4)
    assert world.overlap(Sphere([1.5, 0, 0], 1.0)).tolist() == [sensor, solid]
    assert world.overlap(Sphere([1.5, 0, 0], 1.0), mask=4).tolist() == [solid]
    assert world.query_aabb([0, 0, 0], [0, 0, 0], mask=2).tolist() == [sensor]
    hit = world.cast_shape(Sphere([-3, 0, 0], 0.5), [10, 0, 0])  # through the sensor, onto the box
    assert hit.body == solid and hit.fraction == pytest.approx(0.45)
    assert world.cast_shape(Sphere([-3, 0, 0], 0.5), [10, 0, 0], mask=2) is None
    hit = world.cast_shape(Sphere([2.0, 0, 0], 0.5), [0, 0, 0])
    assert hit.body == solid and hit.fraction == 0.0
    assert world.cast_shape(Sphere([-3.0, 0, 0], 0.5), [0, 0, 0]) is None


def test_compound_and_hull_queries_against_every_kind():
    rng = np.random.default_rng(3)
    world = World()
    ids = [world.add(Box([0, 0, 0], [1, 1, 1])), world.add(Capsule([4, 0, 0], [4, 2, 0], 0.5)),
           world.add(ConvexPolyhedron(rng.normal(size=(12, 3)) + [8, 0, 0]), static=True)]
    q = Compound([Sphere([0, 0, 0], 0.3), ConvexPolyhedron(rng.normal(size=(8, 3)) * 0.3)], [[0, 0, 0], [0, 0, 1]],
                 center=[-4, 0.2, -0.5])
    for d in ([16, 0, 0], [0, 5, 0], [0.0, 0.0, 0.0]):
        hit = world.cast_shape(q, d)
        assert cast_problems(world, q, d, ALL, hit) == []
    assert world.cast_shape(q, [16, 0, 0]).body == ids[0]


@pytest.mark.parametrize("call", [
    lambda w: w.query_aabb([0, 0], [1, 1, 1]), lambda w: w.query_aabb([0, 0, np.inf], [1, 1, 1]),
    lambda w: w.query_aabb([2, 0, 0], [1, 1, 1]), lambda w: w.query_aabb([0, 0, 0], [1, 1, 1], mask=-1),
    lambda w: w.query_aabb([0, 0, 0], [1, 1, 1], mask=1.0), lambda w: w.overlap([0, 0, 0]),
    lambda w: w.overlap(Plane(0.0)), lambda w: w.cast_shape(HeightCurve(np.sin), [0, 0, 0]),
    lambda w: w.cast_shape(Sphere([0, 0, 0], 1), [np.nan, 0, 0]), lambda w: w.cast_shape(Sphere([0, 0, 0], 1), [1]),
    lambda w: w.cast_shape(Sphere([0, 0, 0], 1), [0, 0, 1], mask=1 << 64), lambda w: w.overlap(None),
])
def test_bad_input_is_refused_by_name_and_changes_nothing(call):
    world = World()
    world.add(Sphere([0, 0, 0], 1.0))
    world.add(Plane(-2.0))
    before = snapshot(world)
    with pytest.raises((ValueError, TypeError)) as err:
        call(world)
    assert any(name in str(err.value) for name in ("lo", "hi", "mask", "shape", "displacement"))
    assert_same(before, snapshot(world))


def test_a_failure_inside_a_query_leaves_the_world_as_it_was(monkeypatch):
    world = World()
    world.add(Sphere([0, 0, 0], 1.0))
    world.add(Compound([Box([0, 0, 0], [1, 1, 1])], [[3, 0, 0]]))
    before = snapshot(world)

    def broken(*args, **kwargs):
        raise RuntimeError("planted")
    monkeypatch.setattr(shape_queries, "answer", broken)
    q = Compound([Sphere([0, 0, 0], 0.5), Sphere([0, 0, 0], 0.5)], [[0, 0, 0], [1, 0, 0]])
    for call in (lambda: world.overlap(q), lambda: world.cast_shape(q, [5, 0, 0])):
        with pytest.raises(RuntimeError, match="planted"):
            call()
        after = snapshot(world)
        assert_same(before, after)
        before = after
    monkeypatch.undo()
    assert world.overlap(q).tolist() == [0]


# -- the checkers catch planted defects ---------------------------------------------------------------------------
def _defect_scene():
    world = World()
    world.add(Sphere([0, 0, 0], 1.0))
    world.add(Box([3, 0, 0], [1, 1, 1]), static=True)
    world.add(Plane(-1.5))
    return world


def test_checkers_flag_planted_defects():
    world = _defect_scene()
    got = world.query_aabb([-2, -2, -2], [5, 2, 2])
    assert got.size == 3 and aabb_problems(world, [-2, -2, -2], [5, 2, 2], ALL, got) == []
    assert aabb_problems(world, [-2, -2, -2], [5, 2, 2], ALL, got[:-1])  # the last candidate dropped
    shape = Box([1.5, 0, 0], [0.6, 0.6, 0.6])
    got = world.overlap(shape)
    assert got.tolist() == [0, 1] and overlap_problems(world, shape, ALL, got) == []
    assert overlap_problems(world, shape, ALL, got[:-1])
    d = np.array([-8.0, -0.3, 0.0])
    start = Sphere([8, 0.2, 0], 0.5)
    hit = world.cast_shape(start, d)
    assert hit is not None and hit.body == 1 and cast_problems(world, start, d, ALL, hit) == []
    for shift in (1e-3, -1e-3):
        assert cast_problems(world, start, d, ALL, ShapeHit(hit.fraction + shift, hit.body, hit.point, hit.normal))
    assert cast_problems(world, start, d, ALL, ShapeHit(hit.fraction, hit.body, hit.point, -hit.normal))
    assert cast_problems(world, start, d, ALL, ShapeHit(hit.fraction, hit.body, hit.point + 0.01, hit.normal))
    assert cast_problems(world, start, d, ALL, None)


def test_planted_candidate_drop_is_caught(monkeypatch):
    """A query that loses its last candidate disagrees with the references."""
    world = _defect_scene()
    real = shape_queries.bodies_in_box
    monkeypatch.setattr(shape_queries, "bodies_in_box", lambda *a, **k: real(*a, **k)[:-1])
    monkeypatch.setattr(engine.world.world, "bodies_in_box", shape_queries.bodies_in_box)
    got = world.query_aabb([-2, -2, -2], [5, 2, 2])
    assert aabb_problems(world, [-2, -2, -2], [5, 2, 2], ALL, got)
    shape = Box([1.5, 0, 0], [0.6, 0.6, 0.6])
    assert overlap_problems(world, shape, ALL, world.overlap(shape))
    start, d = Sphere([8, 0.2, 0], 0.5), np.array([-8.0, -0.3, 0.0])
    assert cast_problems(world, start, d, ALL, world.cast_shape(start, d))
