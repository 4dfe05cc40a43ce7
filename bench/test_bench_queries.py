"""Scene queries: ray casts and shape casts of World against pybullet and MuJoCo, same scene, same run.

The scene (bench/query_peers.py): the "mixed" frame scene — half spheres (r = 0.5), half rotated boxes (half
extents 0.4), uniform in a cube at solid fraction 0.06 — with a ground plane at the bottom of the cube;
N = 1e3, 1e4 and 1e5 (``large``; MuJoCo is left out there, as in the frame benchmark: its model reserves 4 N²
bytes, and its ``mj_ray`` tests every geom). One thread everywhere.

``test_bench_rays`` — a fixed batch of rays per workload, in the pytest-benchmark group
"Queries: <workload> rays, N = <n>":
- "random": ``RAYS`` = 10,000 rays, origins uniform in the scene's box, random unit directions, max_distance
  the scene's size;
- "fan": a lidar's 360 × 32 rays from one point in the scene (outside every body), elevation −15°..+15°.
Peers: World ``cast_rays`` (broad phase "tree"; "sap" and "grid" at N = 1e4 only), pybullet ``rayTestBatch``
(DIRECT, ``numThreads=1``, in pieces of at most 16,383 rays: pybullet drops the 16,384th ray of a batch without a
word and refuses larger ones), MuJoCo ``mj_multiRay`` on the fan (its one origin, many directions) and an
``mj_ray`` loop on the random rays (``flg_static=1``: the ground is a geom of the world body). Each benchmark
makes one untimed warm-up call (compilation excluded), then times ``REPEATS`` calls; the report takes the
minimum. ``work`` = the rays of the batch.

``extra_info``: ``suite`` ("queries"), ``query`` ("rays"), ``workload``, ``n``, ``peer``, ``call`` (the API
called), ``scene_size``, ``inside_start`` (rays whose origin is inside a body) and the agreement with the exact
answer (bench/ray_reference.py: brute force over every body, closed forms), on hits: ``outside_*`` over the
rays that start outside every body (where the engines' conventions coincide), ``all_*`` over every ray against
the reference in the engine's own convention for a ray that starts inside a body (World: hit at 0; pybullet:
the box not reported; MuJoCo: the exit point). Keys: ``agree`` (fraction of rays whose hit or miss and distance
agree within 1e-9 × the scene's size), ``distance_error_median`` / ``_max``, ``normal_error_max``
(|n − n_ref|), ``same_body``, ``only_reference``, ``only_engine``. At N = 1e5 the agreement is on the first
``SAMPLE_LARGE`` rays of the batch.

``test_bench_shape_casts`` — ``CASTS`` = 1,000 ``World.cast_shape`` calls of a sphere (r = 0.3) or a turned box
over random displacements (group "Queries: shape casts, N = <n>"); the peers have no shape cast in their Python
APIs. ``work`` = the casts; ``extra_info`` adds ``hits`` and ``errors`` (casts for which ``cast_shape`` raised a
RuntimeError, kept in the batch and counted; ``first_error`` its message).

Run: ``python -m pytest bench/test_bench_queries.py --benchmark-only -q`` (``--quick``: N = 1e3 only;
``-m large`` for N = 1e5).
"""
from __future__ import annotations

import numpy as np
import pytest

from bench.query_peers import (
    MUJOCO_MAX_BODIES,
    WorldRays,
    inside_convention,
    lidar_fan,
    query_scene,
    random_rays,
    ray_peer,
    scene_size,
    shape_casts,
)
from bench.ray_reference import agreement, ray_reference

REPEATS = 3
#: rays of the agreement check at N = 1e5 (the brute-force reference tests every body)
SAMPLE_LARGE = 1_000
RAY_PEERS = ("World tree", "World sap", "World grid", "pybullet", "MuJoCo")
#: the broad phases measured at N = 1e4 only
SECOND_BROAD_PHASES = ("World sap", "World grid")
WORKLOADS = ("random", "fan")
SHAPES = ("sphere", "box")

_scenes: dict = {}
_peers: dict = {}
_references: dict = {}


def _sizes():
    return [pytest.param(1_000, id="1e3"), pytest.param(10_000, id="1e4"),
            pytest.param(100_000, id="1e5", marks=pytest.mark.large)]


def _scene(n):
    """(scene, {"random": Rays, "fan": Rays}) of n bodies, kept for the session."""
    if n not in _scenes:
        scene = query_scene(n)
        _scenes[n] = (scene, {"random": random_rays(scene), "fan": lidar_fan(scene)})
    return _scenes[n]


def _peer(name, n):
    """The peer ``name`` on the scene of n bodies, shared by the workloads; peers of another size are dropped."""
    for key in [k for k in _peers if k[1] != n]:
        old = _peers.pop(key)
        if hasattr(old, "close"):
            old.close()
    if (name, n) not in _peers:
        _peers[(name, n)] = ray_peer(name, _scene(n)[0])
    return _peers[(name, n)]


def _sample(rays, n):
    """The rays of the agreement check: all of them, or the first ``SAMPLE_LARGE`` above N = 1e4."""
    return slice(None) if n <= 10_000 else slice(0, SAMPLE_LARGE)


def _reference(n, workload, inside):
    key = (n, workload, inside)
    if key not in _references:
        scene, batches = _scene(n)
        rays = batches[workload]
        pick = _sample(rays, n)
        _references[key] = ray_reference(scene, rays.origins[pick], rays.directions[pick], rays.max_distance,
                                         inside=inside)
    return _references[key]


def _agreement_info(n, workload, peer, answer) -> dict:
    """The agreement of ``answer`` (body, distance, normal) with the exact answer (the module's summary)."""
    scene, batches = _scene(n)
    rays = batches[workload]
    pick = _sample(rays, n)
    answer = tuple(None if a is None else np.asarray(a)[pick] for a in answer)
    size = scene_size(scene)
    solid = _reference(n, workload, "zero")
    outside = ~(solid[1] == 0.0)  # distance 0 in World's convention: the origin is inside a body
    own = _reference(n, workload, inside_convention(peer))
    info = {f"all_{k}": v for k, v in agreement(own, answer, size).items()}
    info.update({f"outside_{k}": v for k, v in agreement(
        tuple(x[outside] for x in own), tuple(None if a is None else a[outside] for a in answer), size).items()})
    info["inside_start"] = int((~outside).sum())
    info["agreement_rays"] = int(len(outside))
    return info


def _call(peer, workload) -> str:
    if peer.startswith("World"):
        return "World.cast_rays"
    if peer == "pybullet":
        return "rayTestBatch"
    return "mj_multiRay" if workload == "fan" else "mj_ray loop"


@pytest.mark.parametrize("n", _sizes())
@pytest.mark.parametrize("workload", WORKLOADS)
@pytest.mark.parametrize("peer", RAY_PEERS)
def test_bench_rays(benchmark, quick, peer, workload, n):
    if quick and n > 1_000:
        pytest.skip("--quick: N = 1e3 only")
    if peer in SECOND_BROAD_PHASES and n != 10_000:
        pytest.skip("the second broad phases at N = 1e4 only")
    if peer == "MuJoCo" and n > MUJOCO_MAX_BODIES:
        pytest.skip(f"MuJoCo's model reserves 4 n^2 bytes ({4 * n * n / 1e9:.0f} GB at n = {n})")
    scene, batches = _scene(n)
    rays = batches[workload]
    engine = _peer(peer, n)
    benchmark.group = f"Queries: {workload} rays, N = {n:,}"
    raw = benchmark.pedantic(engine.cast, args=(rays,), rounds=REPEATS, iterations=1, warmup_rounds=1)
    answer = engine.answer(rays, raw)
    benchmark.extra_info.update({
        "suite": "queries", "query": "rays", "workload": workload, "n": n, "peer": peer,
        "call": _call(peer, workload), "work": len(rays.directions), "unit": "rays",
        "scene_size": scene_size(scene), **_agreement_info(n, workload, peer, answer)})


@pytest.mark.parametrize("n", _sizes())
@pytest.mark.parametrize("shape", SHAPES)
def test_bench_shape_casts(benchmark, quick, shape, n):
    if quick and n > 1_000:
        pytest.skip("--quick: N = 1e3 only")
    scene, _ = _scene(n)
    casts = shape_casts(scene, shape)
    engine = _peers.get(("World tree", n)) or WorldRays(scene, "tree")
    benchmark.group = f"Queries: shape casts, N = {n:,}"
    hits = benchmark.pedantic(engine.cast_shapes, args=(casts,), rounds=REPEATS, iterations=1, warmup_rounds=1)
    errors = [h for h in hits if isinstance(h, Exception)]
    benchmark.extra_info.update({
        "suite": "queries", "query": "shape cast", "workload": f"{shape} cast", "n": n, "peer": "World tree",
        "call": "World.cast_shape", "work": len(casts.shapes), "unit": "casts", "scene_size": scene_size(scene),
        "hits": sum(h is not None and not isinstance(h, Exception) for h in hits),
        "errors": len(errors), "first_error": str(errors[0]) if errors else ""})
