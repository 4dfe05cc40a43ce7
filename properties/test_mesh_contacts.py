"""Bodies against static triangle surfaces (``TriangleMesh``, ``HeightField``) through the World: every answer —
pairs(), contacts() (separation, normal, features, points), closest_points, time_of_impact, overlap, cast_shape
— equals a brute force over ALL the surface's triangles (the per-triangle kernels of
engine.narrowphase.mesh_contact, merged here in Python: no candidate_triangles, no BVH, no grid); a HeightField
answers exactly as the TriangleMesh of its triangles (bit for bit); a sphere's depth is its radius minus the exact
distance to the nearest triangle (an independent numpy closest-point oracle); the round-core kernel agrees with
GJK's distance on apart pairs.

Planted defects caught (each reverted): the pair kernels' candidates dropping their last triangle (the contact,
closest-points, overlap/cast and sphere-depth properties fail); the merge keeping the first touching triangle
instead of the deepest (the contact and sphere-depth properties fail); the face region's offset taken as +h n
instead of −h n (the round-core-vs-GJK property fails: the point is on the wrong side); the distance search
stopping once its reach passes half the best distance, without the radius (the far-bodies property fails; the
near-body closest-points property did not notice).
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from engine.narrowphase import gjk_distance
from engine.narrowphase.gjk import gjk_scratch
from engine.narrowphase.mesh_contact import (
    BODY_BOX,
    BODY_HULL,
    BODY_ROUND,
    IMPACT_ITERATIONS,
    IMPACT_TOL,
    fix_normal,
    mesh_work,
    triangle_answer,
    triangle_distance,
)
from engine.narrowphase.status import OVERLAP
from engine.narrowphase.time_of_impact import toi_kernel
from engine.narrowphase.triangle_contact import round_core_triangle, triangle_contact
from engine.world import World
from engine.world.shapes import Box, Capsule, ConvexPolyhedron, HeightField, Sphere, TriangleMesh

BODY_CLASSES = (Sphere, Box, Capsule, ConvexPolyhedron)
SCALES = (1e-3, 1.0, 1e3)
_SHAPE_CODE = {"sphere": BODY_ROUND, "capsule": BODY_ROUND, "box": BODY_BOX, "hull": BODY_HULL}


def _scene(seed, scale, field: bool, n_bodies: int = 4, velocity: bool = False):
    """A World with one random surface about the origin (size 2·scale) and n random bodies over it: (world,
    surface id, body ids)."""
    rng = np.random.default_rng(seed)
    center = np.zeros(3)
    surface = (HeightField if field else TriangleMesh).random(rng, center, 2.0 * scale)
    world = World()
    g = world.add(surface)
    ids = []
    for _ in range(n_bodies):
        cls = BODY_CLASSES[int(rng.integers(len(BODY_CLASSES)))]
        at = rng.uniform(-1.0, 1.0, 3) * scale * np.array([1.0, 0.5, 1.0])
        body = cls.random(rng, at, float(rng.uniform(0.2, 0.8)) * scale)
        v = rng.normal(size=3) * scale if velocity else None
        ids.append(world.add(body, velocity=v))
    return world, g, ids


def _brute_triangles(world, g, body, kernel=triangle_answer):
    """Every triangle of surface g against body by ``kernel`` (triangle_answer, or triangle_distance: apart, the
    exact distance): (separation (nt,), normals (nt, 3) after the active-edge fix, body feature (nt,), triangle
    feature type (nt,), per triangle the list of (point, depth))."""
    view = world._store.view()
    mesh = world.shape(g).mesh
    work = mesh_work(mesh, view.points.shape[1])
    out = triangle_contact()
    code = _SHAPE_CODE[world.kind(body)]
    nt = mesh.triangles.shape[0]
    sep, normal = np.empty(nt), np.empty((nt, 3))
    fa, fb, points = np.empty(nt, np.int64), np.empty(nt, np.int64), []
    for t in range(nt):
        sep[t] = kernel(view, code, body, mesh, t, out, work)
        fix_normal(mesh, t, out)
        normal[t], fa[t], fb[t] = out.normal, out.body_feature[0], out.tri_feature[0]
        points.append([(out.points[v].copy(), out.depths[v]) for v in range(out.count[0])])
    return sep, normal, fa, fb, points


def _brute_impact(world, body, mesh, dt):
    """The earliest conservative-advancement time of body against every triangle (inf for none)."""
    view = world._store.view()
    pa = view.points[body, :view.count[body]]
    zero = np.zeros(3)
    scratch, poses, g, res = gjk_scratch(max(pa.shape[0], 3)), np.empty((2, max(pa.shape[0], 3), 3)), np.empty(7), \
        np.empty(4)
    best = np.inf
    for t in range(mesh.triangles.shape[0]):
        tri = np.ascontiguousarray(mesh.vertices[mesh.triangles[t]])
        st_ = toi_kernel(pa, view.center[body], view.velocity[body], zero, view.radius[body], tri, tri[0], zero, zero,
                         0.0, dt, IMPACT_TOL, IMPACT_ITERATIONS, scratch, poses, g, res)
        if st_ == OVERLAP:
            best = min(best, res[0])
    return best


def _signed_towards(pair, g, normal):
    """A body→triangle normal as World reports it for ``pair`` (first → second)."""
    return -normal if pair[0] == g else normal


surfaces = st.tuples(st.integers(0, 2**32 - 1), st.sampled_from(SCALES), st.booleans())


@settings(deadline=None)
@given(surfaces)
def test_world_contacts_equal_the_brute_force_over_every_triangle(case):
    seed, scale, field = case
    world, g, ids = _scene(seed, scale, field)
    pairs = {tuple(p) for p in world.pairs().tolist()}
    contacts = world.contacts()
    rows = {tuple(p): k for k, p in enumerate(contacts.pairs.tolist())}
    for body in ids:
        sep, normal, fa, fb, points = _brute_triangles(world, g, body)
        pair = (min(g, body), max(g, body))
        touching = bool((sep <= 0.0).any())
        assert (pair in pairs) == touching
        assert (pair in rows) == touching
        if not touching:
            continue
        k = rows[pair]
        best = int(np.argmin(sep))  # the first minimum: the lowest triangle id
        assert contacts.separation[k] == sep[best]
        np.testing.assert_array_equal(contacts.normal[k], _signed_towards(pair, g, normal[best]))
        got_features = (contacts.feature_a[k], contacts.feature_b[k])
        assert got_features == ((fb[best], fa[best]) if pair[0] == g else (fa[best], fb[best]))
        expected = [pd for t in np.flatnonzero(sep <= 0.0) for pd in points[t]]
        expected.sort(key=lambda pd: -pd[1])  # stable: deepest first, triangle order among ties
        got = contacts.points_of(k)
        if len(expected) <= 4:
            np.testing.assert_array_equal(got, np.array([p for p, _ in expected]).reshape(-1, 3))
        else:
            assert 2 <= got.shape[0] <= 4
            pool = np.array([p for p, _ in expected])
            for x in got:
                assert (pool == x).all(axis=1).any()
        assert len(set(contacts.ids_of(k).tolist())) == got.shape[0]


@settings(deadline=None)
@given(surfaces)
def test_closest_points_equal_the_nearest_triangle(case):
    seed, scale, field = case
    world, g, ids = _scene(seed, scale, field)
    body = np.array(ids)
    distance, point_a, point_b = world.closest_points(body, np.full(len(ids), g))
    for k, b in enumerate(ids):
        sep = _brute_triangles(world, g, b, triangle_distance)[0]
        best = sep.min()
        if best <= 0.0:
            assert distance[k] == best
        else:
            assert distance[k] == max(best, np.nextafter(0.0, 1.0))
        gap = np.linalg.norm(point_b[k] - point_a[k])
        assert gap == pytest.approx(abs(distance[k]), rel=1e-7, abs=1e-9 * scale)


@settings(deadline=None)
@given(surfaces, st.floats(0.5, 20.0))
def test_closest_points_of_far_bodies_equal_the_nearest_triangle(case, lift):
    """Bodies moved away from the surface (up to 20 sizes, sideways past its edge): the distance search must grow
    its boxes until no farther triangle can be nearer."""
    seed, scale, field = case
    world, g, ids = _scene(seed, scale, field)
    rng = np.random.default_rng(seed + 2)
    centers = world.bodies().center[ids] + rng.uniform(-1.0, 1.0, (len(ids), 3)) * lift * scale
    world.update(ids, centers)
    distance, point_a, point_b = world.closest_points(np.array(ids), np.full(len(ids), g))
    for k, b in enumerate(ids):
        best = _brute_triangles(world, g, b, triangle_distance)[0].min()
        assert distance[k] == (best if best <= 0.0 else max(best, np.nextafter(0.0, 1.0)))
        assert np.linalg.norm(point_b[k] - point_a[k]) == pytest.approx(abs(distance[k]), rel=1e-7, abs=1e-9 * scale)


@settings(deadline=None)
@given(surfaces, st.floats(0.05, 1.0))
def test_time_of_impact_equals_the_earliest_triangle(case, dt):
    seed, scale, field = case
    world, g, ids = _scene(seed, scale, field, velocity=True)
    impacts = world.time_of_impact(dt)
    got = {tuple(p): t for p, t in zip(impacts.pairs.tolist(), impacts.times.tolist())}
    mesh = world.shape(g).mesh
    for b in ids:
        pair = (min(g, b), max(g, b))
        touching_now = (_brute_triangles(world, g, b)[0] <= 0.0).any()
        want = 0.0 if touching_now else _brute_impact(world, b, mesh, dt)
        assert got.get(pair, np.inf) == want


@settings(deadline=None)
@given(surfaces, st.integers(0, 3))
def test_overlap_and_cast_shape_against_the_brute_force(case, which):
    seed, scale, field = case
    world, g, _ = _scene(seed, scale, field, n_bodies=0)
    rng = np.random.default_rng(seed + 1)
    query = BODY_CLASSES[which].random(rng, rng.uniform(-1.0, 1.0, 3) * scale * np.array([1.0, 0.5, 1.0]),
                                       0.5 * scale)
    probe = world.add(query)  # the brute force reads the query as a body of the store
    touching = bool((_brute_triangles(world, g, probe)[0] <= 0.0).any())
    world.remove(probe)
    assert (g in world.overlap(query).tolist()) == touching
    move = rng.normal(size=3) * scale
    probe = world.add(query, velocity=move)
    want = 0.0 if touching else _brute_impact(world, probe, world.shape(g).mesh, 1.0)
    world.remove(probe)
    hit = world.cast_shape(query, move)
    if not np.isfinite(want):
        assert hit is None
        return
    assert hit is not None and hit.body == g and hit.fraction == pytest.approx(min(want, 1.0), abs=0.0)
    assert abs(np.linalg.norm(hit.normal) - 1.0) < 1e-12


@settings(deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from(SCALES))
def test_a_heightfield_answers_as_the_mesh_of_its_triangles(seed, scale):
    w_field, g_field, ids = _scene(seed, scale, True, velocity=True)
    field = w_field.shape(g_field)
    w_mesh = World()
    g_mesh = w_mesh.add(TriangleMesh(field.mesh.vertices, field.mesh.triangles))
    assert g_mesh == g_field
    for b in ids:
        w_mesh.add(w_field.shape(b), velocity=w_field.bodies().velocity[b])
    np.testing.assert_array_equal(w_field.pairs(), w_mesh.pairs())
    cf, cm = w_field.contacts(), w_mesh.contacts()
    for name in ("pairs", "separation", "normal", "feature_a", "feature_b", "points", "point_offsets", "point_ids"):
        np.testing.assert_array_equal(getattr(cf, name), getattr(cm, name))
    ids_b = np.full(len(ids), g_field)
    for x, y in zip(w_field.closest_points(np.array(ids), ids_b), w_mesh.closest_points(np.array(ids), ids_b)):
        np.testing.assert_array_equal(x, y)
    tf, tm = w_field.time_of_impact(0.5), w_mesh.time_of_impact(0.5)
    np.testing.assert_array_equal(tf.pairs, tm.pairs)
    np.testing.assert_array_equal(tf.times, tm.times)


def _numpy_distance_to_triangle(p, a, b, c):
    """The exact distance from p to the triangle (an independent formulation): the plane's foot when it lies
    inside (same-side tests by cross products), else the least distance to the three edges (clamped
    projections)."""
    n = np.cross(b - a, c - a)
    n = n / np.linalg.norm(n)
    h = np.dot(p - a, n)
    foot = p - h * n
    inside = all(np.dot(np.cross(e1 - e0, foot - e0), n) >= 0.0 for e0, e1 in ((a, b), (b, c), (c, a)))
    if inside:
        return abs(h)
    best = np.inf
    for e0, e1 in ((a, b), (b, c), (c, a)):
        e = e1 - e0
        t = np.clip(np.dot(p - e0, e) / np.dot(e, e), 0.0, 1.0)
        best = min(best, np.linalg.norm(p - (e0 + t * e)))
    return best


@settings(deadline=None)
@given(surfaces)
def test_sphere_depth_is_its_radius_minus_the_exact_distance(case):
    seed, scale, field = case
    rng = np.random.default_rng(seed)
    surface = (HeightField if field else TriangleMesh).random(rng, np.zeros(3), 2.0 * scale)
    world = World()
    g = world.add(surface)
    mesh = surface.mesh
    for _ in range(4):
        x = rng.uniform(-1.0, 1.0) * scale
        z = rng.uniform(-1.0, 1.0) * scale
        centre = np.array([x, rng.uniform(-0.6, 0.6) * scale, z])
        exact = min(_numpy_distance_to_triangle(centre, *mesh.vertices[tri]) for tri in mesh.triangles)
        radius = exact + rng.uniform(0.01, 0.3) * scale  # touching: its depth is radius − exact
        s = world.add(Sphere(centre, radius))
        contacts = world.contacts()
        k = int(np.flatnonzero((contacts.pairs == [g, s]).all(axis=1))[0])
        assert contacts.depth[k] == pytest.approx(radius - exact, rel=1e-12, abs=1e-12 * scale)
        world.remove(s)


@settings(deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from(SCALES), st.booleans())
def test_round_core_triangle_agrees_with_gjk_on_apart_pairs(seed, scale, capsule):
    rng = np.random.default_rng(seed)
    a, b, c = rng.normal(size=(3, 3)) * scale
    n = np.cross(b - a, c - a)
    assume(np.linalg.norm(n) > 1e-3 * scale * scale)
    n /= np.linalg.norm(n)
    p0 = rng.normal(size=3) * scale * 2
    p1 = p0 + rng.normal(size=3) * scale if capsule else p0.copy()
    d_gjk, _, _ = gjk_distance(np.array([p0, p1]) if capsule else p0[None], np.array([a, b, c]))
    assume(d_gjk > 1e-3 * scale)
    r = rng.uniform(0.0, 0.9) * d_gjk
    out = triangle_contact()
    s = round_core_triangle(p0, p1, r, a, b, c, n, out)
    assert s == pytest.approx(d_gjk - r, rel=1e-9, abs=1e-12 * scale)
    assert np.linalg.norm(out.normal) == pytest.approx(1.0, abs=1e-12)
    # the point lies halfway: the body's surface point (point − s/2 n) is at distance r from the core
    surface = out.points[0] - 0.5 * s * out.normal
    core = np.array([p0, p1]) if capsule else p0[None]
    d_surface = gjk_distance(core, surface[None])[0]
    assert d_surface == pytest.approx(r, rel=1e-7, abs=1e-9 * scale)
