"""Properties of the collision pipeline (engine.world.World): the compiled frame against reference paths.

- stateful, for every broad phase (and a tree and a SAP that rebuild at every escape or insertion, and ones
  that never rebuild): after every random add / remove / move / batch update (quaternions, matrices, scipy
  Rotations), or several adds and removes before one query, grounds included (Plane and HeightCurve),
  ``pairs()`` equals (a) the reference path — every pair of live ids through the same dispatch tables, no broad
  phase — and (b) an independent oracle, the GJK distance between the point sets minus the radii (a Plane: the
  lowest point against the altitude); ``contacts()`` has the same pairs, and the same contacts in every world;
- contacts: unit normal from the first body to the second (translating the second by depth along it separates
  the pair, by less does not), depth >= 0 and equal to engine.epa_penetration (+ the radii), points within
  depth/2 of both shapes, point ids distinct within a pair;
- time_of_impact: touching at the returned time, apart before it, and no pair that meets on a fine time grid
  is missed;
- moving a body away and back restores the same pairs and contacts exactly;
- the curve ground against dense sampling; validation of shapes and of World's arguments.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st
from hypothesis.stateful import Bundle, RuleBasedStateMachine, consumes, invariant, multiple, rule
from scipy.spatial.transform import Rotation

from engine import (
    BROAD_PHASES,
    Box,
    Capsule,
    ConvexPolyhedron,
    HeightCurve,
    Plane,
    Sphere,
    World,
    epa_penetration,
    gjk_distance,
)
from engine.narrowphase import gjk_distance_batch
from engine.workloads import quaternion_matrices
from engine.world.shapes import BOX, as_rotation
from properties.strategies.world import bodies, curves, planes, poses, positions, velocities
from properties.world_reference import reference_pairs

#: pairs whose GJK gap is this close to 0 are "touching": the exact primitive tests and GJK may round apart
AMBIGUOUS = 1e-7


# ---------------------------------------------------------------------------------------------------------------
# oracles, independent of the world's storage
# ---------------------------------------------------------------------------------------------------------------

def core_points(shape, center, rotation):
    """The core of a shape at a pose, from the shape's own parameters."""
    if isinstance(shape, Box):
        signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=float)
        return center + (signs * shape.half_extents) @ rotation.T
    return center + shape.local @ rotation.T


def oracle_gap(a, b):
    """(gap, ambiguous): GJK distance of the cores minus the radii; a Plane: lowest point minus altitude;
    a HeightCurve: (nan, True) — its pairs are checked by the reference path only."""
    (sa, ca, ra), (sb, cb, rb) = a, b
    if isinstance(sa, HeightCurve) or isinstance(sb, HeightCurve):
        return np.nan, True
    if isinstance(sa, Plane) or isinstance(sb, Plane):
        plane, (shape, c, r) = (sa, b) if isinstance(sa, Plane) else (sb, a)
        if isinstance(shape, Plane):
            return np.inf, False
        gap = core_points(shape, c, r)[:, 1].min() - shape.radius - plane.altitude
    else:
        d, _, _ = gjk_distance(core_points(sa, ca, ra), core_points(sb, cb, rb))
        gap = d - sa.radius - sb.radius
    return gap, abs(gap) <= AMBIGUOUS


def oracle_pairs(model):
    """The set of overlapping pairs, and the set of ambiguous pairs."""
    ids = sorted(model)
    hits, ambiguous = set(), set()
    for x, i in enumerate(ids):
        for j in ids[x + 1:]:
            gap, amb = oracle_gap(model[i], model[j])
            if amb:
                ambiguous.add((i, j))
            elif gap <= 0:
                hits.add((i, j))
    return hits, ambiguous


def check_against_oracles(world, model, oracle=None):
    """``oracle``: ``oracle_pairs(model)`` if already computed (it depends on the model only)."""
    got = world.pairs()
    assert got.dtype == np.int64 and got.ndim == 2 and got.shape[1] == 2
    rows = [tuple(p) for p in got.tolist()]
    assert rows == sorted(set(rows)) and all(i < j for i, j in rows)
    np.testing.assert_array_equal(got, reference_pairs(world))
    hits, ambiguous = oracle_pairs(model) if oracle is None else oracle
    assert set(rows) - ambiguous == hits - ambiguous
    return got


# ---------------------------------------------------------------------------------------------------------------
# stateful: every broad phase against the reference path and the oracle after random edits
# ---------------------------------------------------------------------------------------------------------------

class WorldMachine(RuleBasedStateMachine):
    """The same edits on one World per broad phase (and tree and SAP worlds that always / never rebuild)."""

    ids = Bundle("ids")

    def __init__(self):
        super().__init__()
        self.worlds = [World(bp) for bp in BROAD_PHASES]
        for method in ("tree", "sap"):
            for threshold in (0, 10**9):
                world = World(method)
                world.rebuild_threshold = threshold
                self.worlds.append(world)
        self.model: dict = {}

    def _same(self, results):
        assert all(r == results[0] for r in results)
        return results[0]

    def _add(self, shape):
        i = self._same([w.add(shape) for w in self.worlds])
        self.model[i] = (shape, shape.center.copy(), shape.rotation.copy())
        return i

    def _remove(self, i):
        for w in self.worlds:
            w.remove(i)
        del self.model[i]

    @rule(target=ids, shape=bodies)
    def add(self, shape):
        return self._add(shape)

    @rule(target=ids, shapes=st.lists(bodies, min_size=1, max_size=3), drop=st.sets(st.integers(0, 2)))
    def add_several_remove_some(self, shapes, drop):
        """Several edits before the next query: bodies added, some removed again, one more added (it may take a
        removed body's id); the broad phases see them all at once."""
        added = [self._add(shape) for shape in shapes]
        for i in [added[k] for k in sorted(drop) if k < len(added)]:
            self._remove(i)
            added.remove(i)
        return multiple(*added, self._add(shapes[0]))

    @rule(ground=planes | curves)
    def add_ground(self, ground):
        i = self._same([w.add(ground) for w in self.worlds])
        self.model[i] = (ground, None, None)

    @rule(i=consumes(ids))
    def remove(self, i):
        self._remove(i)

    @rule(i=ids, pose=poses)
    def move(self, i, pose):
        center, rotation = pose
        for w in self.worlds:
            w.move(i, center=center, rotation=rotation)
        shape, _, rot = self.model[i]
        self.model[i] = (shape, center, rot if rotation is None else rotation)

    @rule(data=st.data())
    def update_many(self, data):
        live = sorted(i for i, m in self.model.items() if m[1] is not None)
        if not live:
            return
        chosen = data.draw(st.lists(st.sampled_from(live), unique=True, min_size=1))
        nudge = data.draw(st.sampled_from([0.01, 0.05, 0.5, 3.0]))
        rng = np.random.default_rng(data.draw(st.integers(0, 2**16)))
        centers = np.array([self.model[i][1] for i in chosen]) + rng.normal(0, nudge, (len(chosen), 3))
        q = rng.normal(size=(len(chosen), 4))
        q /= np.linalg.norm(q, axis=1, keepdims=True)
        form = data.draw(st.sampled_from(["quaternions", "matrices", "scipy"]))
        rot = quaternion_matrices(q)
        given_rotations = {"quaternions": q, "matrices": rot,
                           "scipy": Rotation.from_quat(q, scalar_first=True)}[form]
        for w in self.worlds:
            w.update(chosen, centers, rotations=given_rotations)
        for row, i in enumerate(chosen):
            self.model[i] = (self.model[i][0], centers[row], rot[row])

    @invariant()
    def frame_equals_reference(self):
        first, oracle = None, oracle_pairs(self.model)
        for w in self.worlds:
            got = check_against_oracles(w, self.model, oracle)
            contacts = w.contacts()
            np.testing.assert_array_equal(contacts.pairs, got)
            if first is None:
                first = contacts
            for name in ("pairs", "depth", "normal", "points", "point_offsets", "point_ids"):
                np.testing.assert_array_equal(getattr(contacts, name), getattr(first, name))


TestWorldStateful = WorldMachine.TestCase
TestWorldStateful.settings = settings(max_examples=40, stateful_step_count=12, deadline=None)


@given(st.lists(st.tuples(bodies, st.none() | poses), min_size=2, max_size=8), st.none() | planes,
       st.sampled_from(BROAD_PHASES))
@settings(max_examples=100)
def test_pairs_of_dense_scenes_match_the_oracles(shapes_poses, ground, broad_phase):
    """Crowded scenes (centres pulled into a cube of side ~3): many pairs near touching, of every kind pair."""
    w = World(broad_phase)
    model = {}
    for shape, pose in shapes_poses:
        i = w.add(shape)
        center = shape.center * 0.35
        rotation = shape.rotation if pose is None or pose[1] is None else pose[1]
        w.move(i, center=center, rotation=rotation)
        model[i] = (shape, center, rotation)
    if ground is not None:
        model[w.add(ground)] = (ground, None, None)
    check_against_oracles(w, model)


def test_rotation_forms_give_the_same_world():
    """Quaternions (w, x, y, z), matrices and scipy Rotations of the same rotations give the same poses."""
    rng = np.random.default_rng(3)
    q = rng.normal(size=(5, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    forms = [q, quaternion_matrices(q), Rotation.from_quat(q, scalar_first=True)]
    got = []
    for form in forms:
        w = World()
        ids = [w.add(Box(np.zeros(3), [0.3, 0.5, 0.7])) for _ in range(5)]
        w.update(ids, rng.normal(size=(5, 3)) * 0 + np.arange(5)[:, None], rotations=form)
        got.append(np.array([w.pose(i)[1] for i in ids]))
    np.testing.assert_allclose(got[0], got[1], atol=1e-15)
    np.testing.assert_allclose(got[0], got[2], atol=1e-15)
    np.testing.assert_allclose(as_rotation(Rotation.from_quat(q[0], scalar_first=True)), got[0][0], atol=1e-15)


# ---------------------------------------------------------------------------------------------------------------
# contacts
# ---------------------------------------------------------------------------------------------------------------

def build(shapes, ground=None, broad_phase="tree"):
    w = World(broad_phase)
    model = {}
    for s in shapes:
        model[w.add(s)] = (s, s.center.copy(), s.rotation.copy())
    if ground is not None:
        model[w.add(ground)] = (ground, None, None)
    return w, model


def shape_distance(point, shape, center, rotation):
    d, _, _ = gjk_distance(point[None], core_points(shape, center, rotation))
    return d - shape.radius


@given(st.lists(bodies, min_size=2, max_size=6), st.none() | planes)
@settings(max_examples=60)
def test_contacts_normal_depth_points(shapes, ground):
    w, model = build(shapes, ground)
    cs = w.contacts()
    np.testing.assert_array_equal(cs.pairs, w.pairs())
    assert cs.point_offsets[0] == 0 and cs.point_offsets[-1] == cs.points.shape[0]
    counts = np.diff(cs.point_offsets)
    assert np.all((counts >= 1) & (counts <= 4))
    assert np.all(cs.depth >= 0) and np.all(np.isfinite(cs.points))
    assert set(cs.feature_a.tolist()) | set(cs.feature_b.tolist()) <= {1, 2, 3}
    for p, (i, j) in enumerate(cs.pairs.tolist()):
        assert len(set(cs.ids_of(p).tolist())) == counts[p]  # the points of a pair have distinct ids
        n = cs.normal[p]
        depth = cs.depth[p]
        assert abs(np.linalg.norm(n) - 1.0) <= 1e-9
        (sa, ca, ra), (sb, cb, rb) = model[i], model[j]
        if isinstance(sa, Plane) or isinstance(sb, Plane):
            plane_first = isinstance(sa, Plane)
            plane, (shape, c, r) = (sa, model[j]) if plane_first else (sb, model[i])
            np.testing.assert_allclose(n, [0, 1 if plane_first else -1, 0])
            bottom = core_points(shape, c, r)[:, 1].min() - shape.radius
            assert abs(depth - (plane.altitude - bottom)) <= 1e-9 * max(1.0, abs(bottom))
            for q in cs.points_of(p):
                assert shape_distance(q, shape, c, r) <= depth / 2 + 1e-7
                assert abs(q[1] - plane.altitude) <= depth / 2 + 1e-9
            continue
        pa, pb = core_points(sa, ca, ra), core_points(sb, cb, rb)
        rsum = sa.radius + sb.radius
        scale = max(np.ptp(np.concatenate([pa, pb]), axis=0).max(), rsum, 1.0)
        tol = 1e-6 * scale
        # depth agrees with EPA (on the cores, plus the radii) or with GJK when the cores are apart
        d_core, _, _ = gjk_distance(pa, pb)
        expected = rsum - d_core if d_core > 0 else epa_penetration(pa, pb)[0] + rsum
        assert abs(depth - expected) <= tol
        # the normal points from i to j: moving j by (depth + tol) n separates them, by (depth - tol) does not
        gap_after, _, _ = gjk_distance(pa, pb + (depth + tol) * n)
        assert gap_after - rsum >= 0.5 * tol
        if depth > 10 * tol:
            gap_short, _, _ = gjk_distance(pa, pb + (depth - 5 * tol) * n)
            assert gap_short - rsum <= (-tol if rsum > 0 else 0.0)
        for q in cs.points_of(p):
            assert shape_distance(q, sa, ca, ra) <= depth / 2 + tol
            assert shape_distance(q, sb, cb, rb) <= depth / 2 + tol


# ---------------------------------------------------------------------------------------------------------------
# time of impact
# ---------------------------------------------------------------------------------------------------------------

@given(st.lists(st.tuples(bodies, velocities), min_size=2, max_size=5), st.none() | planes,
       st.sampled_from(["tree", "sap", "brute"]))
@settings(max_examples=25)
def test_time_of_impact_first_contact(bodies_vel, ground, broad_phase):
    dt = 1.0
    w = World(broad_phase)
    model = {}
    for s, v in bodies_vel:
        model[w.add(s, velocity=v)] = (s, s.center.copy(), s.rotation.copy(), v)
    if ground is not None:
        model[w.add(ground)] = (ground, None, None, np.zeros(3))
    imp = w.time_of_impact(dt)
    rows = [tuple(p) for p in imp.pairs.tolist()]
    assert rows == sorted(set(rows))
    assert np.all((imp.times >= 0) & (imp.times <= dt))
    found = dict(zip(rows, imp.times.tolist()))

    def gaps(i, j, times):
        """Oracle gap of the pair at each time (a vectorised GJK over the time grid)."""
        (sa, ca, ra, va), (sb, cb, rb, vb) = model[i], model[j]
        if isinstance(sa, Plane) or isinstance(sb, Plane):
            plane, (shape, c, r, v) = (sa, model[j]) if isinstance(sa, Plane) else (sb, model[i])
            return core_points(shape, c, r)[:, 1].min() + v[1] * times - shape.radius - plane.altitude
        pa = core_points(sa, ca, ra)[None] + times[:, None, None] * va
        pb = core_points(sb, cb, rb)[None] + times[:, None, None] * vb
        return gjk_distance_batch(pa, pb)[0] - sa.radius - sb.radius

    grid = np.linspace(0.0, dt, 201)
    ids = sorted(model)
    for x, i in enumerate(ids):
        for j in ids[x + 1:]:
            if isinstance(model[i][0], Plane) and isinstance(model[j][0], Plane):
                continue
            if (i, j) in found:
                t = found[(i, j)]
                assert gaps(i, j, np.array([t]))[0] <= 1e-6  # touching at t
                before = grid[grid < t - 1e-6]
                if before.size:
                    assert gaps(i, j, before).min() > -1e-6  # apart before t
            else:
                assert gaps(i, j, grid).min() > -1e-6, f"pair {(i, j)} meets on the grid but was not reported"


# ---------------------------------------------------------------------------------------------------------------
# move and move back; the curve ground against dense sampling
# ---------------------------------------------------------------------------------------------------------------

@given(st.lists(bodies, min_size=2, max_size=6), st.data(), st.sampled_from(BROAD_PHASES))
@settings(max_examples=40)
def test_move_and_back_restores_pairs_and_contacts(shapes, data, broad_phase):
    w, _ = build(shapes, Plane(-3.0), broad_phase)
    body = data.draw(st.sampled_from(list(range(len(shapes)))))
    center, rotation, _ = w.pose(body)
    before_pairs = w.pairs()
    before = w.contacts()
    w.move(body, center=data.draw(positions), rotation=data.draw(poses)[1])
    w.pairs()
    w.move(body, center=center, rotation=rotation)
    np.testing.assert_array_equal(w.pairs(), before_pairs)
    after = w.contacts()
    for name in ("pairs", "separation", "depth", "normal", "feature_a", "feature_b", "points", "point_offsets",
                 "point_ids"):
        np.testing.assert_array_equal(getattr(after, name), getattr(before, name))
    assert after.kind == before.kind


#: a turn that puts one of a box's edges over the crest of the curve, below it, while its corners stay above
EDGE_OVER_CREST = np.array([[0.9015481978307106, -0.43031098623017633, 0.04520289944030692],
                            [-0.10918636188339109, -0.12516943265442537, 0.9861089957543426],
                            [-0.4186755132162217, -0.8939603281234475, -0.1598303674980167]])


@given(bodies, st.floats(0.2, 1.5), st.floats(0.3, 3.0), st.floats(-3.0, 3.0))
@settings(max_examples=60)
@example(Box([0.0, 2.0, 0.0], [1.0, 0.625, 1.0]), 1.5, 2.0, 0.0)  # f's crest between the bottom corners
@example(Box([2.5, 2.0, 0.0], [0.5, 1.0, 1.0], EDGE_OVER_CREST), 0.90625, 0.875, 0.0)  # an edge 3.5e-4 under f
def test_curve_ground_against_dense_sampling(shape, amplitude, wavenumber, level):
    def f(x):
        return level + amplitude * np.sin(wavenumber * x)

    w = World()
    b = w.add(shape)
    g = w.add(HeightCurve(f, samples=128))
    # oracle: dense points of the shape, min of y - f(x). Along x = const the height y - f(x) is linear, so on a
    # polytope core its minimum lies on a segment between two core points (an edge): those are sampled densely
    # (random convex combinations alone miss the inside of edges: a box's edge over the curve's crest dipped
    # 3.5e-4 under it while every sample stayed 0.054 above). Each core sample also carries its ball's point
    # along the curve's downward normal at its x, next to random points of the ball.
    rng = np.random.default_rng(0)
    core = w.world_points(b)
    weights = rng.dirichlet(np.ones(core.shape[0]) * 0.3, size=20000)
    i, j = np.triu_indices(core.shape[0], 1)
    t = np.linspace(0.0, 1.0, max(2, 60000 // max(len(i), 1)))[:, None, None]
    edges = (core[i] + t * (core[j] - core[i])).reshape(-1, 3)
    cloud = np.concatenate([weights @ core, edges, core])
    slope = amplitude * wavenumber * np.cos(wavenumber * cloud[:, 0])
    down = np.stack([slope, -np.ones_like(slope), np.zeros_like(slope)], axis=1)
    down /= np.linalg.norm(down, axis=1)[:, None]
    ball = rng.normal(size=(20000, 3))
    ball *= (shape.radius * rng.random(20000) ** (1 / 3) / np.linalg.norm(ball, axis=1))[:, None]
    pts = np.concatenate([weights @ core + ball, cloud + shape.radius * down])
    lowest = (pts[:, 1] - f(pts[:, 0])).min()
    got = (b, g) in {tuple(p) for p in w.pairs().tolist()}
    if lowest <= 0:
        assert got  # a sampled point of the shape is under the curve: the test must see it
    margin = 0.02 * max(1.0, amplitude * wavenumber ** 2)
    assume(lowest > margin)
    assert not got


# ---------------------------------------------------------------------------------------------------------------
# validation
# ---------------------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("make, name", [
    (lambda: Sphere([0, 0, 0], -1.0), "radius"),
    (lambda: Sphere([0, np.nan, 0], 1.0), "center"),
    (lambda: Sphere([0, 0], 1.0), "center"),
    (lambda: Box([0, 0, 0], [1, 0, 1]), "half_extents"),
    (lambda: Box([0, 0, 0], [1, 1, 1], np.diag([1.0, 1.0, 1.1])), "rotation"),
    (lambda: Box([0, 0, 0], [1, 1, 1], np.diag([1.0, 1.0, -1.0])), "rotation"),
    (lambda: Box([0, 0, 0], [1, 1, 1], [2.0, 0, 0, 0]), r"rotation must be a unit quaternion in \(w, x, y, z\)"),
    (lambda: Box([0, 0, 0], [1, 1, 1], np.eye(2)), "rotation"),
    (lambda: Capsule([0, 0, 0], [1, 0, 0], 0.0), "radius"),
    (lambda: Capsule([0, 0, np.inf], [1, 0, 0], 1.0), "p0"),
    (lambda: ConvexPolyhedron([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]]), "points"),
    (lambda: ConvexPolyhedron([[0, 0, 0], [1, 0, 0], [0, 1, 0]]), "points"),
    (lambda: Plane(np.nan), "altitude"),
    (lambda: HeightCurve(3.0), "f"),
    (lambda: World("kd-tree"), "broad_phase"),
    (lambda: World(3), "broad_phase"),
    (lambda: World().add("sphere"), "shape"),
    (lambda: World().add(Sphere([0, 0, 0], 1), velocity=[0, np.nan, 0]), "velocity"),
    (lambda: World().move(0, center=[0, 0, 0]), "id"),
    (lambda: World().move(1.5), "id"),
    (lambda: World().remove(7), "id"),
    (lambda: World().time_of_impact(-1.0), "dt"),
])
def test_validation_names_the_argument(make, name):
    with pytest.raises((ValueError, TypeError), match=name):
        make()


def test_validation_of_world_edits():
    w = World()
    a = w.add(Sphere([0, 0, 0], 1.0))
    g = w.add(Plane(0.0))
    with pytest.raises(ValueError, match="id"):
        w.move(g, center=[0, 1, 0])  # grounds do not move
    with pytest.raises(ValueError, match=r"rotation must be a unit quaternion in \(w, x, y, z\) order"):
        w.move(a, rotation=[1.0, 1.0, 0.0, 0.0])  # unnormalised quaternion: rejected, not normalised
    with pytest.raises(ValueError, match=r"ids\[1\] = 1 is a ground"):
        w.update([a, g], np.zeros((2, 3)))
    with pytest.raises(ValueError, match="centers"):
        w.update([a], np.zeros((2, 3)))
    with pytest.raises(ValueError, match=r"rotations\[0\] must be a unit quaternion in \(w, x, y, z\) order"):
        w.update([a], np.zeros((1, 3)), rotations=[[2.0, 0, 0, 0]])
    w.remove(a)
    with pytest.raises(ValueError, match="id"):
        w.move(a, center=[0, 0, 0])
    center = np.array([1.0, 2.0, 3.0])
    b = w.add(Box(center, [1, 1, 1]))
    w.update(np.array([b]), center[None] + 1)
    np.testing.assert_array_equal(center, [1.0, 2.0, 3.0])  # the caller's arrays are never modified
    assert w.kind(b) == "box" and w.bodies().kind[b] == BOX.code
