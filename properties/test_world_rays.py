"""Ray casts of the World: every answer equals a brute force over every body with the exact per-shape kernels.

The brute force here is independent of the World's traversals: a Python loop over ``world.ids()`` calling the
narrow-phase ray kernels on each body as the user sees it (``world.pose``, ``world.world_points``,
``world.radius``, ``world.shape``), a compound part by part and a triangle surface triangle by triangle, keeping
the nearest hit (ties: the lowest id). It runs
for every broad phase (tree, grid walked by DDA, sap, octree, brute), with rays from inside bodies, grazing rays
along box faces and edges, zero and finite lengths, masks, threads and scales from 1e-6 to 1e6.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st

from engine import (
    BROAD_PHASES,
    Box,
    Capsule,
    Compound,
    ConvexPolyhedron,
    HeightCurve,
    Plane,
    Sphere,
    World,
)
from engine.narrowphase.ray_box import ray_box
from engine.narrowphase.ray_capsule import ray_capsule
from engine.narrowphase.ray_curve import ray_curve_batch
from engine.narrowphase.ray_halfspace import ray_halfspace
from engine.narrowphase.ray_hull import hull_planes, ray_hull
from engine.narrowphase.ray_sphere import ray_sphere
from engine.narrowphase.ray_triangle import ray_triangle_side
from engine.world.kinds import KINDS
from engine.world.ray_cast import LIST, cast_ray_batch
from engine.world.ray_rows import RAY_ROWS

from .strategies.world import any_bodies, grounds

KIND_NAMES = [k.name for k in KINDS]


def _unit(d):
    d = np.asarray(d, float)
    return d / np.linalg.norm(d)


def _hit_shape(world, body, part_row, o, d, t_max):
    """(t, normal) of one convex core as the user sees it, by its kind's kernel."""
    kind = world.kind(body)
    pts = world.world_points(body, part_row)
    r = world.radius(body, part_row)
    if kind == "compound":
        shape = world.shape(body).parts[part_row][0]
        kind = shape.kind.name
        center, rotation = _part_pose(world, body, part_row)
    else:
        shape = world.shape(body)
        center, rotation, _ = world.pose(body)
    o3, d3 = tuple(o), tuple(d)
    if kind == "sphere":
        out = ray_sphere(o3, d3, t_max, tuple(pts[0]), r)
    elif kind == "capsule":
        out = ray_capsule(o3, d3, t_max, tuple(pts[0]), tuple(pts[1]), r)
    elif kind == "box":
        out = ray_box(o3, d3, t_max, tuple(center), np.ascontiguousarray(rotation), tuple(shape.half))
    elif kind == "hull":
        planes = hull_planes(shape.local)
        out = ray_hull(o3, d3, t_max, tuple(center), np.ascontiguousarray(rotation), planes, planes.shape[0])
    else:
        raise AssertionError(kind)
    return out[0], np.array(out[1:4])


def _part_pose(world, body, part):
    """A compound part's world pose: its row of the body store (``World.bodies``: owner = the compound)."""
    rows = world.bodies()
    s = np.flatnonzero((rows.owner == body) & (rows.part == part))[0]
    return rows.center[s], rows.rotation[s]


def _hit_surface(mesh, o, d, t_max):
    """[(t, triangle, normal)] of every triangle of a surface's MeshArrays, by the watertight kernel: the stored
    face normal turned against the ray."""
    found = []
    for k, tri in enumerate(mesh.triangles):
        a, b, c = (tuple(mesh.vertices[i]) for i in tri)
        t, side = ray_triangle_side(tuple(o), tuple(d), t_max, a, b, c)
        found.append((t, k, side * mesh.normals[k]))
    return found


def brute_hits(world, o, d, t_max, mask=None):
    """Every hit (t, body, part, normal) of the ray o + t·d (d unit) in [0, t_max], by the per-shape kernels."""
    hits = []
    for b in world.ids().tolist():
        if world.bodies().sensor[b] or (mask is not None and int(world.bodies().category[b]) & mask == 0):
            continue
        kind = world.kind(b)
        if kind == "plane":
            t, nx, ny, nz = ray_halfspace(tuple(o), tuple(d), t_max, (0.0, world.shape(b).altitude, 0.0),
                                          (0.0, 1.0, 0.0))
            found = [(t, 0, np.array([nx, ny, nz]))]
        elif kind == "curve":
            shape = world.shape(b)
            reach = t_max if np.isfinite(t_max) else world._rays().reach
            t, n = ray_curve_batch(shape.height, shape.slope, 4 * shape.samples, o[None], d[None],
                                   np.array([reach]))
            found = [(t[0], 0, n[0])]
        elif kind in ("mesh", "field"):
            found = _hit_surface(world.shape(b).mesh, o, d, t_max)
        elif kind == "compound":
            found = [(*_hit_shape(world, b, p, o, d, t_max),) for p in range(len(world.shape(b).parts))]
            found = [(t, p, n) for p, (t, n) in enumerate(found)]
        else:
            t, n = _hit_shape(world, b, None, o, d, t_max)
            found = [(t, 0, n)]
        best = min(found, key=lambda f: (f[0], f[1]))
        if np.isfinite(best[0]):
            hits.append((best[0], b, best[1], best[2]))
    return sorted(hits, key=lambda h: (h[0], h[1]))


def assert_nearest_equals_brute(world, o, d, t_max, mask=None):
    hits = world.cast_rays(o, d, t_max, **({} if mask is None else {"mask": mask}))
    for r in range(o.shape[0]):
        du = _unit(d[r])
        expected = brute_hits(world, o[r], du, float(np.broadcast_to(t_max, (o.shape[0],))[r]), mask)
        if not expected:
            assert hits.body[r] == -1 and hits.distance[r] == np.inf, (r, hits.body[r], hits.distance[r])
            assert np.isnan(hits.normal[r]).all() and np.isnan(hits.point[r]).all()
            continue
        t, b, part, n = expected[0]
        assert (hits.body[r], hits.distance[r], hits.part[r]) == (b, t, part), (r, hits.body[r],
                                                                                 hits.distance[r], expected[:2])
        np.testing.assert_array_equal(hits.normal[r], n)
        assert abs(np.linalg.norm(hits.normal[r]) - 1.0) < 1e-12
        np.testing.assert_array_equal(hits.point[r], o[r] + t * du)
    return hits


def _world(method, shapes, ground=None, **kw):
    world = World(method, **kw)
    if ground is not None:
        world.add(ground)
    for k, s in enumerate(shapes):
        world.add(s, static=(k % 3 == 2))
    return world


def _rays(data, n, scale=1.0):
    coords = st.floats(-6.0, 6.0, allow_nan=False)
    o = np.array(data.draw(st.lists(st.tuples(coords, coords, coords), min_size=n, max_size=n))) * scale
    d = np.array(data.draw(st.lists(st.tuples(coords, coords, coords), min_size=n, max_size=n)))
    assume(np.all(np.linalg.norm(d, axis=1) > 1e-3))
    return o, d


@pytest.mark.parametrize("method", BROAD_PHASES)
@given(shapes=st.lists(any_bodies, min_size=1, max_size=8), ground=st.none() | grounds, data=st.data())
def test_nearest_hit_equals_brute_force(method, shapes, ground, data):
    world = _world(method, shapes, ground)
    o, d = _rays(data, 6)
    # aim half the rays at a body: from its outside towards its centre, and from its centre (inside)
    ids = [b for b in world.ids().tolist() if world.kind(b) not in ("plane", "curve")]
    for r in range(0, 6, 2):
        c, _, _ = world.pose(ids[r % len(ids)])
        d[r] = c - o[r] if r % 4 == 0 and np.linalg.norm(c - o[r]) > 1e-6 else d[r]
        o[r] = o[r] if r % 4 == 0 else c
    t_max = data.draw(st.sampled_from([np.inf, 0.0, 3.0]))
    assert_nearest_equals_brute(world, o, d, t_max)


@pytest.mark.parametrize("method", ["tree", "grid", "brute"])
@given(shapes=st.lists(any_bodies, min_size=1, max_size=6), ground=st.none() | grounds, data=st.data())
def test_all_hits_equal_brute_force(method, shapes, ground, data):
    world = _world(method, shapes, ground)
    o, d = _rays(data, 4)
    hits = world.cast_rays(o, d, 10.0, all_hits=True)
    expected = []
    for r in range(4):
        expected += [(r, h[0], h[1]) for h in brute_hits(world, o[r], _unit(d[r]), 10.0)]
    got = list(zip(hits.ray.tolist(), hits.distance.tolist(), hits.body.tolist()))
    assert got == expected


@given(shapes=st.lists(any_bodies, min_size=1, max_size=6), data=st.data())
def test_rays_from_inside_hit_at_zero_with_reversed_normal(shapes, data):
    world = _world("tree", shapes)
    b = data.draw(st.sampled_from(world.ids().tolist()))
    center = world.pose(b)[0] if world.kind(b) != "compound" else None
    if center is None:  # a compound's first part's centre is inside it
        center = world.world_points(b, 0).mean(axis=0)
    else:
        center = world.world_points(b).mean(axis=0)
    d = np.array(data.draw(st.tuples(*[st.floats(-1, 1, allow_nan=False)] * 3)))
    assume(np.linalg.norm(d) > 1e-3)
    hit = world.cast_ray(center, d, data.draw(st.sampled_from([0.0, 1.0, np.inf])))
    assert hit is not None and hit.distance == 0.0
    np.testing.assert_allclose(hit.normal, -_unit(d), rtol=0, atol=1e-15)
    inside = brute_hits(world, center, _unit(d), 0.0)
    assert hit.body == inside[0][1]


@pytest.mark.parametrize("method", ["tree", "grid", "sap"])
@given(data=st.data())
def test_grazing_rays_along_box_faces_and_edges_hit(method, data):
    """A ray running along a face or an edge of a box touches the closed box: the hit lies on its surface."""
    half = np.array(data.draw(st.tuples(*[st.floats(0.2, 2.0)] * 3)))
    world = World(method)
    b = world.add(Box([0.0, 0.0, 0.0], half))
    world.add(Sphere([20.0, 20.0, 20.0], 0.5))
    axis = data.draw(st.integers(0, 2))
    on = [data.draw(st.sampled_from([-1.0, 1.0])) * half[k] for k in range(3)]
    face_only = data.draw(st.booleans())
    o = np.array(on)
    if face_only:  # along a face: one coordinate on the face, one inside
        other = (axis + 1) % 3
        o[other] = data.draw(st.floats(-0.9, 0.9)) * half[other]
    o[axis] = -5.0 * half[axis] - 1.0
    d = np.zeros(3)
    d[axis] = 1.0
    hit = world.cast_ray(o, d)
    assert hit is not None and hit.body == b
    assert hit.distance == pytest.approx(4.0 * half[axis] + 1.0, rel=1e-12)
    assert np.all(np.abs(hit.point) <= half * (1 + 1e-12))


@pytest.mark.parametrize("scale", [1e-6, 1e6])
@given(shapes=st.lists(any_bodies, min_size=1, max_size=5), data=st.data())
def test_scaled_scenes_scale_the_answers(scale, shapes, data):
    """The scene scaled by s: the same bodies hit, distances times s, the same normals (to round-off)."""
    world, scaled = World(), World()
    for s in shapes:
        world.add(s)
        scaled.add(_scaled(s, scale))
    o, d = _rays(data, 5)
    a, b = world.cast_rays(o, d), scaled.cast_rays(o * scale, d)
    clear = a.distance * (1 + 1e-9) < np.inf
    np.testing.assert_array_equal(a.body >= 0, b.body >= 0)
    np.testing.assert_allclose(b.distance[clear], a.distance[clear] * scale, rtol=1e-9, atol=1e-9 * scale)


def _scaled(shape, s):
    if isinstance(shape, Sphere):
        return Sphere(shape.center * s, shape.radius * s)
    if isinstance(shape, Box):
        return Box(shape.center * s, shape.half * s, shape.rotation)
    if isinstance(shape, Capsule):
        p = shape.world_points()
        return Capsule(p[0] * s, p[1] * s, shape.radius * s)
    if isinstance(shape, ConvexPolyhedron):
        return ConvexPolyhedron(shape.world_points() * s)
    if isinstance(shape, Compound):
        return Compound([_scaled(p, s) for p, _, _ in shape.parts], [np.asarray(q) * s for _, q, _ in shape.parts],
                        [r for _, _, r in shape.parts], center=shape.center * s, rotation=shape.rotation)
    raise AssertionError(type(shape))


@given(shapes=st.lists(any_bodies, min_size=1, max_size=8), categories=st.lists(st.integers(0, 7), min_size=8,
                                                                                 max_size=8),
       mask=st.integers(0, 7), data=st.data())
def test_masks_select_bodies_by_category(shapes, categories, mask, data):
    world = World()
    for s, c in zip(shapes, categories):
        world.add(s, category=c)
    o, d = _rays(data, 5)
    hits = assert_nearest_equals_brute(world, o, d, np.inf, mask)
    cats = world.bodies().category
    assert all(int(cats[b]) & mask for b in hits.body[hits.body >= 0].tolist())


@given(shapes=st.lists(any_bodies, min_size=2, max_size=8), data=st.data())
def test_sensors_are_never_hit(shapes, data):
    world = World()
    sensors = [world.add(s, sensor=(k % 2 == 0)) for k, s in enumerate(shapes)][::2]
    o, d = _rays(data, 5)
    hits = world.cast_rays(o, d, all_hits=True)
    assert not set(hits.body.tolist()) & set(sensors)


@given(shapes=st.lists(any_bodies, min_size=1, max_size=8), threads=st.integers(2, 4), data=st.data())
def test_threads_give_identical_answers(shapes, threads, data):
    one, many = World(), World(threads=threads)
    for s in shapes:
        one.add(s)
        many.add(s)
    o, d = _rays(data, 9)
    for every in (False, True):
        a, b = one.cast_rays(o, d, all_hits=every), many.cast_rays(o, d, all_hits=every)
        for f in ("ray", "body", "distance", "point", "normal", "part"):
            np.testing.assert_array_equal(getattr(a, f), getattr(b, f))


@pytest.mark.parametrize("method", ["tree", "grid", "sap"])
@given(shapes=st.lists(any_bodies, min_size=2, max_size=6), moves=st.integers(1, 12), data=st.data())
def test_rays_follow_the_bodies_as_they_move(method, shapes, moves, data):
    """After updates (the rays' tree refitted, or rebuilt when it decayed) the answers equal the brute force."""
    world = World(method)
    ids = [world.add(s) for s in shapes]
    rng = np.random.default_rng(data.draw(st.integers(0, 2**32 - 1)))
    o, d = _rays(data, 4)
    for _ in range(moves):
        world.cast_rays(o, d)
        step = rng.normal(size=(len(ids), 3)) * data.draw(st.sampled_from([0.01, 1.0, 20.0]))
        world.update(ids, np.array([world.pose(b)[0] for b in ids]) + step)
    assert_nearest_equals_brute(world, o, d, np.inf)


def test_every_kind_has_a_ray_row():
    assert set(RAY_ROWS) == set(KINDS)
    for kind, row in RAY_ROWS.items():
        assert (row.hit is None) != (row.host is None), kind


def test_a_missing_body_is_caught_by_the_brute_force():
    """Planted defect: a scene whose body list leaves one body out answers differently from the brute force."""
    world = World("brute")
    world.add(Sphere([0.0, 0.0, 5.0], 1.0))
    world.add(Sphere([0.0, 0.0, 10.0], 1.0))
    scene = world._rays()
    assert scene.method == LIST
    broken = scene._replace(listed=scene.listed[1:])  # the first body left out
    o, d = np.zeros((1, 3)), np.array([[0.0, 0.0, 1.0]])
    from engine.world.ray_cast import as_rays
    oo, dd, tt = as_rays(o, d, np.inf)
    answer = cast_ray_batch(broken, oo, dd, tt, 0xFFFFFFFFFFFFFFFF, False, 1)
    assert answer.body[0] == 1 and brute_hits(world, o[0], dd[0], np.inf)[0][1] == 0


def test_curve_ground_rays():
    world = World()
    g = world.add(HeightCurve(lambda x: np.sin(x)))
    hit = world.cast_ray([0.5, 5.0, 0.0], [0.0, -1.0, 0.0])
    assert hit is not None and hit.body == g
    assert hit.point[1] == pytest.approx(np.sin(0.5), abs=1e-12)
    n = np.array([-np.cos(0.5), 1.0, 0.0])
    np.testing.assert_allclose(hit.normal, n / np.linalg.norm(n), atol=1e-8)
    assert world.cast_ray([0.5, 5.0, 0.0], [0.0, 1.0, 0.0]) is None
    assert world.cast_ray([0.5, -5.0, 0.0], [1.0, 0.0, 0.0]).distance == 0.0


@pytest.mark.parametrize("kwargs, name", [
    ({"origins": [[0, 0, np.nan]], "directions": [[1, 0, 0]]}, "origins"),
    ({"origins": [[0, 0, 0], [0, 0, 0]], "directions": [[1, 0, 0], [0, 0, 0]]}, r"directions\[1\]"),
    ({"origins": [[0, 0, 0]], "directions": [[1, 0, 0], [1, 0, 0]]}, "directions"),
    ({"origins": [[0, 0, 0]], "directions": [[np.inf, 0, 0]]}, "directions"),
    ({"origins": [[0, 0, 0]], "directions": [[1, 0, 0]], "max_distance": -1.0}, "max_distance"),
    ({"origins": [[0, 0, 0]] * 2, "directions": [[1, 0, 0]] * 2, "max_distance": [1.0, np.nan]},
     r"max_distance\[1\]"),
    ({"origins": [[0, 0, 0]] * 2, "directions": [[1, 0, 0]] * 2, "max_distance": [1.0]}, "max_distance"),
    ({"origins": [0, 0, 0], "directions": [[1, 0, 0]]}, "origins"),
])
def test_bad_rays_are_refused_by_name_and_the_world_is_unchanged(kwargs, name):
    world = World()
    world.add(Sphere([0.0, 0.0, 0.0], 1.0))
    before = [a.copy() for a in world.bodies()]
    with pytest.raises(ValueError, match=name):
        world.cast_rays(**kwargs)
    for a, b in zip(before, world.bodies()):
        np.testing.assert_array_equal(a, b)


def test_bad_single_ray_and_options():
    world = World()
    world.add(Plane(0.0))
    with pytest.raises(ValueError, match="direction"):
        world.cast_ray([0, 1, 0], [0, 0, 0])
    with pytest.raises(TypeError, match="all_hits"):
        world.cast_rays([[0, 1, 0]], [[0, -1, 0]], all_hits=1)
    with pytest.raises(TypeError, match="mask"):
        world.cast_rays([[0, 1, 0]], [[0, -1, 0]], mask=1.5)
    with pytest.raises(ValueError, match="threads"):
        World(threads=0)
    with pytest.raises(TypeError, match="threads"):
        World(threads=2.0)
