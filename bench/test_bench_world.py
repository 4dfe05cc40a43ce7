"""Benchmark of the World pipeline per frame against trimesh's CollisionManager and coal's broad phase.

Scene: N = 10,000 mixed bodies — 40 % spheres (r in [0.3, 0.7]), 30 % rotated boxes (half extents in
[0.2, 0.6]), 30 % convex hulls of 12–20 random points (radius ~0.5) — uniform in a cube at a moderate density
(bounding-sphere packing fraction ~0.1). One frame: every body moves a little (a random step of 0.02) —
``World.update(ids, centers)`` (one broad-phase refit) + ``World.pairs()`` (broad phase + exact narrow tests).

Peers, same scene, same run:
- trimesh ``CollisionManager`` (python-fcl BVH meshes; spheres as icospheres, subdivisions=1, boxes as their 12
  triangles, hulls as their hull meshes): ``set_transform`` for each body, then
  ``in_collision_internal(return_names=True)`` (the pairs of meshes in contact);
- coal ``DynamicAABBTreeCollisionManager`` with coal's exact primitives (Sphere, Box, Convex): ``setTransform``
  for each object, ``update()``, ``collide`` with the C++ ``CollisionCallBackCollect`` — its broad-phase pairs
  only (a lower bound of its time: no narrow test).

``extra_info``: bodies, pairs found, and for the World the per-stage counts (candidates, narrow tests).
Run: ``python -m pytest bench/test_bench_world.py --benchmark-only -q`` (``--quick``: N = 2,000).
"""
from __future__ import annotations

import numpy as np
import pytest

from engine.workloads import mixed_world_scene, random_steps
from engine.world import Box, Sphere, World


@pytest.fixture(scope="module")
def scene(quick):
    return mixed_world_scene(2_000 if quick else 10_000)


def _world(shapes, broad_phase):
    w = World(broad_phase)
    ids = np.array([w.add(s) for s in shapes], dtype=np.int64)
    return w, ids


@pytest.mark.benchmark(group="World frame (update + pairs)")
@pytest.mark.parametrize("broad_phase", ["tree", "sap", "grid"])
def test_bench_world_frame(benchmark, scene, broad_phase):
    shapes, centers, _ = scene
    w, ids = _world(shapes, broad_phase)
    w.pairs()  # compile
    todo = iter(random_steps(centers, 50))

    def frame():
        w.update(ids, next(todo))
        return w.pairs()

    got = benchmark.pedantic(frame, rounds=8, iterations=1, warmup_rounds=1)
    benchmark.extra_info.update(bodies=len(shapes), pairs=int(len(got)), candidates=w.stats.candidate_pairs,
                                narrow_tests=w.stats.narrow_tests, groups=w.stats.groups)


def _trimesh_manager(shapes):
    import trimesh

    manager = trimesh.collision.CollisionManager()
    sphere = trimesh.creation.icosphere(subdivisions=1)
    names = []
    for i, s in enumerate(shapes):
        if isinstance(s, Sphere):
            mesh = sphere.copy()
            mesh.apply_scale(s.radius)
        elif isinstance(s, Box):
            mesh = trimesh.creation.box(extents=2 * s.half_extents)
        else:
            mesh = trimesh.convex.convex_hull(s.local)
        transform = np.eye(4)
        transform[:3, :3] = s.rotation
        transform[:3, 3] = s.center
        manager.add_object(str(i), mesh, transform=transform)
        names.append(str(i))
    return manager, names


@pytest.mark.benchmark(group="World frame (update + pairs)")
def test_bench_trimesh_frame(benchmark, scene):
    shapes, centers, rotations = scene
    manager, names = _trimesh_manager(shapes)
    todo = iter(random_steps(centers, 10))
    transform = np.tile(np.eye(4), (len(shapes), 1, 1))
    transform[:, :3, :3] = np.array([s.rotation for s in shapes])

    def frame():
        transform[:, :3, 3] = next(todo)
        for name, t in zip(names, transform):
            manager.set_transform(name, t)
        return manager.in_collision_internal(return_names=True)[1]

    got = benchmark.pedantic(frame, rounds=2, iterations=1, warmup_rounds=1)
    benchmark.extra_info.update(bodies=len(shapes), pairs=int(len(got)))


@pytest.mark.benchmark(group="World frame (update + pairs)")
def test_bench_coal_frame(benchmark, scene):
    import coal

    shapes, centers, _ = scene
    manager = coal.DynamicAABBTreeCollisionManager()
    objects = []
    for s in shapes:
        if isinstance(s, Sphere):
            geom = coal.Sphere(s.radius)
        elif isinstance(s, Box):
            geom = coal.Box(*(2 * s.half_extents))
        else:
            vertices = coal.StdVec_Vec3s()
            for p in s.local:
                vertices.append(p)
            geom = coal.Convex.convexHull(vertices, False, "")
        transform = coal.Transform3s()
        transform.setRotation(s.rotation)
        transform.setTranslation(s.center)
        obj = coal.CollisionObject(geom, transform)
        objects.append(obj)
        manager.registerObject(obj)
    manager.setup()
    todo = iter(random_steps(centers, 10))

    def frame():
        for obj, c in zip(objects, next(todo)):
            obj.setTranslation(c)
            obj.computeAABB()
        manager.update()
        callback = coal.CollisionCallBackCollect(8 * len(objects))
        manager.collide(callback)
        return callback.numCollisionPairs()

    got = benchmark.pedantic(frame, rounds=3, iterations=1, warmup_rounds=1)
    benchmark.extra_info.update(bodies=len(shapes), broad_phase_pairs=int(got))
