"""The level benchmark's exact answer and peers (bench/level_peers.py), on small cases.

- ``point_triangle_distance`` equals coal's sphere–triangle distance plus the radius (apart pairs), to 1e-9;
- ``box_triangle_overlap`` (13-axis SAT) agrees with coal's box–triangle distance wherever that is farther than
  1e-6 from 0;
- ``TriangleBuckets.pairs`` gives exactly the brute-force AABB overlaps of every body box with every triangle;
- ``level_scene`` puts its near bodies within ``NEAR_OFFSET`` · size of touching, on the side it says (spheres:
  |distance − r| at most that offset);
- MuJoCo's hfield and pybullet's heightfield and concave mesh, built by the module's axis maps, classify every
  body the way the exact answer does outside a band (spheres whose distance is within ``BAND`` of r, boxes whose
  coal distance is within ``BAND`` of 0, may go either way): the maps put the peers' triangles on ours.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

coal = pytest.importorskip("coal")

from bench.level_peers import (  # noqa: E402
    NEAR_OFFSET,
    CoalDistance,
    LevelBulletFrame,
    LevelMuJoCoFrame,
    TriangleBuckets,
    box_triangle_overlap,
    exact_answer,
    level_scene,
    point_triangle_distance,
    rotation_matrices,
    sphere_distances,
    unit_quaternions,
)

#: bodies this close to touching (scene units, bodies of size ~0.3) may be classified either way by a peer
BAND = 1e-3
seeds = st.integers(0, 2**32 - 1)


def _triangle(rng):
    a, b, c = rng.normal(size=(3, 3)) * rng.uniform(0.2, 2.0)
    return a, b, c


def _coal_triangle(a, b, c):
    """One triangle as coal's BVH model (coal pairs shapes with BVH triangles, not with a bare TriangleP)."""
    model = coal.BVHModelOBBRSS()
    model.beginModel(1, 3)
    model.addVertices(np.array([a, b, c]))
    model.addTriangles(np.array([[0, 1, 2]], np.int64))
    model.endModel()
    return coal.CollisionObject(model, coal.Transform3s())


def _coal_distance(shape, rotation, center, a, b, c) -> float:
    result = coal.DistanceResult()
    coal.distance(coal.CollisionObject(shape, coal.Transform3s(rotation, center)), _coal_triangle(a, b, c),
                  coal.DistanceRequest(), result)
    return result.min_distance


@given(seeds)
def test_point_triangle_distance_is_coal_sphere_distance_plus_radius(seed):
    rng = np.random.default_rng(seed)
    a, b, c = _triangle(rng)
    p = rng.normal(size=(8, 3)) * 2.0
    got = point_triangle_distance(p, *(np.repeat(x[None], 8, axis=0) for x in (a, b, c)))
    radius = 1e-3
    for k in range(8):
        d = _coal_distance(coal.Sphere(radius), np.eye(3), p[k], a, b, c)
        if d > 1e-6:
            assert abs(got[k] - (d + radius)) <= 1e-9 * max(1.0, got[k]), (k, got[k], d + radius)


@given(seeds)
def test_box_triangle_sat_agrees_with_coal_outside_a_band(seed):
    rng = np.random.default_rng(seed)
    a, b, c = _triangle(rng)
    m = 16
    center = rng.normal(size=(m, 3)) * 1.5
    rot = rotation_matrices(unit_quaternions(m, rng))
    half = rng.uniform(0.1, 1.0, size=(m, 3))
    got = box_triangle_overlap(center, rot, half, *(np.repeat(x[None], m, axis=0) for x in (a, b, c)))
    for k in range(m):
        d = _coal_distance(coal.Box(*(2 * half[k])), rot[k], center[k], a, b, c)
        if abs(d) > 1e-6:
            assert got[k] == (d < 0), (k, got[k], d)


@given(seeds)
def test_bucket_pairs_are_the_brute_force_overlaps(seed):
    rng = np.random.default_rng(seed)
    nv, nt, n = 30, 40, 25
    vertices = rng.uniform(-5, 5, size=(nv, 3)) * np.array([1.0, 0.3, 1.0])
    triangles = np.array([rng.choice(nv, 3, replace=False) for _ in range(nt)])
    centers = rng.uniform(-6, 6, size=(n, 3)) * np.array([1.0, 0.3, 1.0])
    extent = rng.uniform(0.0, 2.0, size=(n, 3))
    lo, hi = centers - extent, centers + extent
    body, tri = TriangleBuckets(vertices, triangles).pairs(lo, hi)
    corners = vertices[triangles]
    t_lo, t_hi = corners.min(axis=1), corners.max(axis=1)
    meets = np.all((t_lo[None] <= hi[:, None]) & (lo[:, None] <= t_hi[None]), axis=2)
    expected_body, expected_tri = np.nonzero(meets)
    assert np.array_equal(body, expected_body) and np.array_equal(tri, expected_tri)


@pytest.mark.parametrize("seed", [1, 2])
def test_near_bodies_lie_within_the_offset_of_touching(seed):
    scene = level_scene(80, seed=seed, samples=20, near=40)
    touching, _ = exact_answer(scene)
    assert np.array_equal(touching[scene.near], scene.near_in)
    near_spheres = scene.is_sphere[scene.near]
    ids = scene.near[near_spheres]
    gap = sphere_distances(TriangleBuckets(scene.vertices, scene.triangles), scene.centers[ids],
                           scene.size[ids]) - scene.size[ids]
    inside = scene.near_in[near_spheres]
    assert np.all(np.where(inside, gap <= 0.0, gap > 0.0))
    assert np.all(np.abs(gap) <= NEAR_OFFSET * scene.size[ids])


def _clear_of_band(scene) -> np.ndarray:
    """Bodies farther than BAND from touching: spheres by the exact distance, boxes by coal's distance."""
    buckets = TriangleBuckets(scene.vertices, scene.triangles)
    gap = np.abs(sphere_distances(buckets, scene.centers, scene.size + 2.0) - scene.size)
    return np.where(scene.is_sphere, gap > BAND, np.abs(CoalDistance(scene).distances()) > BAND)


@pytest.mark.parametrize("peer", ["MuJoCo", "pybullet field", "pybullet mesh"])
def test_peers_touch_the_exact_bodies_outside_the_band(peer):
    pytest.importorskip("mujoco" if peer == "MuJoCo" else "pybullet")
    scene = level_scene(120, seed=5, samples=24, near=20)
    frame = LevelMuJoCoFrame(scene) if peer == "MuJoCo" else LevelBulletFrame(scene, peer.split()[1])
    frame.detect()
    bodies, _ = frame.touching()
    found = np.zeros(len(scene.shapes), bool)
    found[bodies] = True
    touching, _ = exact_answer(scene)
    clear = _clear_of_band(scene)
    assert touching[clear].sum() > 20 and (~touching[clear]).sum() > 20  # both answers are exercised
    wrong = np.flatnonzero(clear & (found != touching))
    assert wrong.size == 0, (wrong, touching[wrong])
    if hasattr(frame, "close"):
        frame.close()
