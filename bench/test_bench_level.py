"""The level benchmark: bodies on a terrain — World's HeightField and TriangleMesh against MuJoCo's hfield,
pybullet's heightfield and concave mesh, and coal's BVH distances, same scene, same run.

The scene (bench/level_peers.py, ``level_scene``): a 128 × 128 terrain of smooth hills at spacing 0.5, N bodies
(half spheres r = 0.3, half turned boxes of half extent 0.25) over it, about half touching it, 200 of them
within 1e-7 of touching (half just in, half just out); the bodies never pair with each other (collision
categories), only with the terrain. N = 2,000 and 20,000 (``--quick``: 2,000).

``test_bench_level_frame`` (group "Level frame: N = <n>"): a frame is pose upload + detection + reading the
contacts; ``WARMUP`` untimed frames, then ``ROUNDS`` frames timed by pytest-benchmark, the poses jittered about the
scene's (``level_motion``). Peers: "World field" (``HeightField``), "World mesh" (the ``TriangleMesh`` of the same
triangles), "MuJoCo hfield", "pybullet heightfield", "pybullet mesh". After the timed frames each peer detects at
the scene's poses and its touching bodies are compared with the exact answer (``wrong_against_exact``):
``extra_info`` has ``exact_touching``, ``touching``, ``missed``, ``extra``, ``missed_near``, ``extra_near``,
``wrong`` and ``sphere_depth_error_max`` (the largest |depth − exact depth| over the spheres both find touching),
the stages of the fastest frame (``stage_upload``, ``stage_detect``, ``stage_read``, ``stage_frame``) and
``detection_min`` (the fastest detect + read).

``test_bench_level_distance`` (group "Level distance: N = <n>"): the signed distance of every body to the surface
at the scene's poses — World ``closest_points`` (field and mesh) against coal ``distance`` per body on its
``BVHModelOBBRSS``. ``extra_info``: for World, the largest |distance − coal's| over the bodies both find apart
(``vs_coal_apart_max``), the bodies whose sign differs from coal's (``vs_coal_sign_differs``); for every peer,
the largest |distance − exact| over the spheres (``sphere_exact_max``; coal: apart spheres only, its distance
of a penetrating sphere being that of one triangle, not of the surface) and the bodies whose sign (distance <= 0)
differs from the exact touching answer (``vs_exact_sign_differs``).

World rows skip (naming the reason) while the World has no kernel for a body against a surface
(``UnsupportedQuery``); they run unchanged once it has.

Run: ``python -m pytest bench/test_bench_level.py --benchmark-only -q`` (``--quick``: N = 2,000 only), or
``python -m bench.report_level`` for the report section alone.
"""
from __future__ import annotations

import numpy as np
import pytest

from bench.level_peers import (
    CoalDistance,
    LevelBulletFrame,
    LevelMuJoCoFrame,
    LevelWorldFrame,
    TriangleBuckets,
    exact_answer,
    level_motion,
    level_scene,
    sphere_distances,
    wrong_against_exact,
)
from bench.world_peers import benchmark_clock, benchmark_frames
from engine.world import UnsupportedQuery

WARMUP = 3
ROUNDS = 8
DISTANCE_ROUNDS = 3
FRAME_PEERS = ("World field", "World mesh", "MuJoCo hfield", "pybullet heightfield", "pybullet mesh")
DISTANCE_PEERS = ("World field", "World mesh", "coal BVH")

_scenes: dict = {}


def _sizes():
    return [pytest.param(2_000, id="2e3"), pytest.param(20_000, id="2e4")]


def _scene(n):
    """(scene, poses of the frames, exact touching (n,), exact sphere depth (n,)) for N = n, built once."""
    if n not in _scenes:
        scene = level_scene(n)
        _scenes[n] = (scene, level_motion(scene, WARMUP + ROUNDS), *exact_answer(scene))
    return _scenes[n]


def _world_frame(peer, scene, query):
    """The World frame of ``peer`` ("World field" or "World mesh") once ``query(frame)`` has run; a World that
    cannot answer a body against a surface (``UnsupportedQuery``) skips the benchmark."""
    frame = LevelWorldFrame(scene, peer.split()[1])
    try:
        query(frame)
    except UnsupportedQuery as e:
        pytest.skip(f"World has no body-surface kernel yet: {e}")
    return frame


def _make(peer, scene):
    """The peer's frame; a World frame that cannot detect a body against a surface skips the benchmark."""
    if peer.startswith("World"):
        return _world_frame(peer, scene, LevelWorldFrame.detect)
    if peer == "MuJoCo hfield":
        return LevelMuJoCoFrame(scene)
    return LevelBulletFrame(scene, "field" if peer == "pybullet heightfield" else "mesh")


@pytest.mark.parametrize("n", _sizes())
@pytest.mark.parametrize("peer", FRAME_PEERS)
def test_bench_level_frame(benchmark, request, quick, peer, n):
    if quick and n > 2_000:
        pytest.skip("--quick: N = 2,000 only")
    scene, poses, touching, depth = _scene(n)
    frame = _make(peer, scene)
    benchmark.group = f"Level frame: N = {n:,}"
    stages = benchmark_frames(benchmark, frame, poses, WARMUP, ROUNDS, benchmark_clock(request))
    frame.upload(scene.centers, scene.quaternions)
    frame.detect()
    bodies, found_depth = frame.touching()
    benchmark.extra_info.update({"suite": "level", "n": n, "peer": peer, "work": n, "unit": "bodies",
                                 "warmup_frames": WARMUP, **stages,
                                 **wrong_against_exact(scene, touching, bodies, found_depth, depth)})
    if hasattr(frame, "close"):
        frame.close()


def _distance_peer(peer, scene):
    if peer == "coal BVH":
        return CoalDistance(scene)
    return _world_frame(peer, scene, LevelWorldFrame.distances)


def _coal_reference(n):
    key = ("coal", n)
    if key not in _scenes:
        _scenes[key] = CoalDistance(_scene(n)[0]).distances()
    return _scenes[key]


def _distance_info(scene, peer, distance, touching, coal) -> dict:
    """The agreement columns of ``test_bench_level_distance`` (module docstring)."""
    s = scene.is_sphere
    buckets = TriangleBuckets(scene.vertices, scene.triangles)
    exact = sphere_distances(buckets, scene.centers[s], scene.size[s] + 2.0) - scene.size[s]
    spheres = np.ones(exact.shape, bool) if peer != "coal BVH" else exact > 0.0
    info = {"sphere_exact_max": float(np.max(np.abs(distance[s][spheres] - exact[spheres]), initial=0.0)),
            "vs_exact_sign_differs": int(np.count_nonzero((distance <= 0.0) != touching))}
    if peer != "coal BVH":
        apart = (distance > 0.0) & (coal > 0.0)
        info["vs_coal_apart_max"] = float(np.max(np.abs(distance[apart] - coal[apart]), initial=0.0))
        info["vs_coal_sign_differs"] = int(np.count_nonzero((distance <= 0.0) != (coal <= 0.0)))
    return info


@pytest.mark.parametrize("n", _sizes())
@pytest.mark.parametrize("peer", DISTANCE_PEERS)
def test_bench_level_distance(benchmark, quick, peer, n):
    if quick and n > 2_000:
        pytest.skip("--quick: N = 2,000 only")
    scene, _, touching, _ = _scene(n)
    frame = _distance_peer(peer, scene)
    benchmark.group = f"Level distance: N = {n:,}"
    distance = benchmark.pedantic(frame.distances, rounds=DISTANCE_ROUNDS, iterations=1, warmup_rounds=1)
    benchmark.extra_info.update({"suite": "level_distance", "n": n, "peer": peer, "work": n, "unit": "bodies",
                                 **_distance_info(scene, peer, distance, touching, _coal_reference(n))})
