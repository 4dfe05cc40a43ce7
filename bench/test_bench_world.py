"""The collision frame at game scale: World against MuJoCo and pybullet, same scenes, same run.

Scenes (engine.workloads.frame_scene): "mixed" — half spheres (r = 0.5), half boxes (half extents 0.4) with
random rotations, uniform in a cube at solid fraction 0.06, every body moving by a small random step and turn
each frame; "pile" — boxes and spheres resting on a Plane, most contacts persisting; "hulls" — capsules and
12-vertex convex hulls. N = 1e2, 1e3, 1e4 and 1e5 (``large``; MuJoCo is left out there: its broad phase reserves
4 N² bytes, 40 GB). A frame is pose upload + detection + reading the contacts (bench/world_peers.py): World
``update(ids, centers, rotations=quaternions)`` + ``contacts()`` (broad phases "tree" — the default — "sap" and
"grid"); MuJoCo ``qpos`` + ``mj_kinematics`` + ``mj_collision`` + ``d.contact``; pybullet
``resetBasePositionAndOrientation`` per body + ``performCollisionDetection`` + ``getContactPoints``.

Each frame benchmark is in the pytest-benchmark group "World frame: <scene>, N = <n>" (reports/benchmarks.md
ratios the entries of a group to its fastest: World, MuJoCo and pybullet on one scene at one size). Each
benchmark first runs ``WARMUP`` frames untimed (the tree's fat boxes reach their steady state: bodies
keep leaving them), then times ``ROUNDS`` frames (pytest-benchmark's statistics are over those). ``extra_info``:
``scene``, ``n``, ``peer``, the stages of the fastest frame in seconds (``stage_upload``, ``stage_detect``,
``stage_read``, ``stage_frame``, and for World ``stage_broad``, ``stage_narrow``, ``stage_contacts``:
``stage_detect`` split in the proportions of the World's own wall-clock stage timers, so that the stages add up
to the frame in the benchmark's clock), ``detection_min`` (the fastest detect + read over the timed frames),
the penetrating pairs (depth > 1e-6) and contact points at the last frame, and the agreement at that frame:
for each peer against World (pairs both find, only one finds, median / max depth difference on the common
pairs), and for World and each peer against the exact depth (distance from the origin to the boundary of the
Minkowski difference, Qhull) on a sample of ``EXACT_SAMPLE`` penetrating pairs.

Two more benchmarks, each in its own group:
- ``test_bench_static_level`` ("World static level: ..."): ``engine.workloads.static_level`` — 5,000 static
  boxes (floors, walls, pillars, crates) and 500 moving spheres and boxes of the mixed scene among them
  (``--quick``: 1,000 and 100). Peers: "World" (the level added ``static=True``), "World alone" (the moving
  bodies without the level), MuJoCo (the level as geoms of the world body), pybullet (the level as multibodies of
  mass 0). ``extra_info`` adds ``n_static``, ``n_moving``, the penetrating pairs with a level box
  (``level_pairs``), the moving bodies penetrating the level (``bodies_on_level``) and World's counts (candidate,
  static and filtered pairs, narrow tests). Asserts: MuJoCo's penetrating pair set equals World's outside
  ``AGREEMENT_BAND``, and World alone finds exactly World's pairs of two moving bodies.
- ``test_bench_masked`` ("World masked: mixed, N = ..."): the mixed scene at N = 1e3 and 1e4 (``--quick``: 1e3)
  with ``engine.workloads.category_masks`` (5 of the 10 category pairs masked off) and without, for World,
  MuJoCo (contype / conaffinity) and pybullet (setCollisionFilterGroupMask). ``extra_info`` adds ``masked`` and
  World's narrow tests and filtered pairs. Asserts (masked): World's pairs are exactly the unmasked World's
  pairs whose categories collide, and MuJoCo's and pybullet's penetrating pair sets equal World's outside
  ``AGREEMENT_BAND``.
Both add, for each peer, the pairs only one side finds deeper than ``AGREEMENT_BAND`` (``vs_world_beyond_band``)
and the depth of the deepest pair only one side finds (``vs_world_one_sided_max_depth``).

Run: ``python -m pytest bench/test_bench_world.py --benchmark-only -q`` (``--quick``: N = 1e2 and 1e3 only;
``-m large`` for N = 1e5).
"""
from __future__ import annotations

import time

import numpy as np
import pytest

from bench.world_peers import (
    AGREEMENT_BAND,
    MUJOCO_MAX_BODIES,
    BulletFrame,
    EngineFrame,
    MuJoCoFrame,
    agreement,
    benchmark_clock,
    benchmark_frames,
    disagreements,
    exact_depth,
)
from engine.workloads import category_masks, frame_motion, frame_scene, static_level
from engine.world import Plane

SCENES = ("mixed", "pile", "hulls")
WARMUP = 40
ROUNDS = 8
EXACT_SAMPLE = 60
PEERS = ("World tree", "World sap", "World grid", "MuJoCo", "pybullet")

_scenes: dict = {}
_reference: dict = {}


def _sizes():
    return [pytest.param(100, id="1e2"), pytest.param(1_000, id="1e3"), pytest.param(10_000, id="1e4"),
            pytest.param(100_000, id="1e5", marks=pytest.mark.large)]


def _scene(name, n):
    if (name, n) not in _scenes:
        scene = frame_scene(name, n)
        _scenes[(name, n)] = (scene, frame_motion(scene, WARMUP + ROUNDS))
    return _scenes[(name, n)]


def _make(peer, scene):
    if peer.startswith("World"):
        return EngineFrame(scene, peer.split()[1])
    return MuJoCoFrame(scene) if peer == "MuJoCo" else BulletFrame(scene)


def _exact_sample(scene, poses_last, pairs, depth):
    """|depth − exact depth| over a fixed sample of the penetrating pairs, and the sample's exact depths."""
    rng = np.random.default_rng(5)
    pick = rng.choice(len(pairs), size=min(EXACT_SAMPLE, len(pairs)), replace=False) if len(pairs) else []
    centers, quats = poses_last
    exact = {}
    for k in pick:
        i, j = pairs[k]
        shape_b = Plane(scene.ground) if j == len(scene.shapes) else scene.shapes[j]
        pose_b = None if j == len(scene.shapes) else (centers[j], quats[j])
        exact[(int(i), int(j))] = exact_depth(scene.shapes[i], (centers[i], quats[i]), shape_b, pose_b)
    return exact


def _against_exact(exact, pairs, depth) -> dict:
    got = {tuple(p): d for p, d in zip(pairs.tolist(), depth.tolist())}
    diff = np.array([abs(got[p] - e) for p, e in exact.items() if p in got]) if exact else np.zeros(1)
    return {"exact_sampled": len(exact), "exact_diff_median": float(np.median(diff)) if diff.size else 0.0,
            "exact_diff_max": float(diff.max()) if diff.size else 0.0,
            "exact_missing": sum(p not in got for p in exact)}


def _engine_reference(name, n):
    """World (tree) at the last pose of the sequence: its penetrating pairs and the sampled exact depths."""
    if (name, n) not in _reference:
        scene, poses = _scene(name, n)
        frame = EngineFrame(scene)
        for centers, quats in poses:
            frame.upload(centers, quats)
            frame.detect()
        pen = frame.penetrating()
        _reference[(name, n)] = (pen, _exact_sample(scene, poses[-1], *pen))
    return _reference[(name, n)]


def _stage_split(wall: dict, detect: float) -> dict:
    """World's ``contacts()`` (``detect``, in the benchmark's clock) split into broad / narrow / contacts in the
    proportions of the World's own stage timers (wall clock): under load wall time exceeds process time, so the
    raw timers could not be compared with the frame."""
    stages = {k: wall[k] for k in ("broad", "narrow", "contacts")}
    total = sum(stages.values())
    return {k: detect * v / total if total > 0.0 else 0.0 for k, v in stages.items()}


def _time_frames(benchmark, clock, frame, poses) -> dict:
    """``benchmark_frames`` (``WARMUP`` untimed frames, then ``ROUNDS`` timed; the stages of the fastest frame and
    the fastest detection), World's detect split into ``broad``, ``narrow``, ``contacts`` (``_stage_split``)."""
    split = None
    if isinstance(frame, EngineFrame):
        def split(engine, detect):
            return _stage_split(engine.world.stats.seconds, detect)
    return benchmark_frames(benchmark, frame, poses, WARMUP, ROUNDS, clock, split)


def _agreement_info(reference, pairs, depth) -> dict:
    """``agreement`` with World's answer, and the pairs only one side finds: how many are deeper than
    ``AGREEMENT_BAND`` and the deepest of them."""
    one_sided = [d for *_, d, _ in disagreements(reference, (pairs, depth), band=0.0)]
    return {**{f"vs_world_{k}": v for k, v in agreement(reference, (pairs, depth)).items()},
            "vs_world_one_sided_max_depth": max(one_sided, default=0.0),
            "vs_world_beyond_band": sum(d > AGREEMENT_BAND for d in one_sided)}


def _world_counts(frame) -> dict:
    """The World's work at the last frame (``world.stats``)."""
    s = frame.world.stats
    return {"contact_points": int(s.contacts), "persisting_points": int(s.persisting),
            "candidate_pairs": int(s.candidate_pairs), "static_pairs": int(s.static_pairs),
            "filtered": int(s.filtered), "narrow_tests": int(s.narrow_tests)}


#: the frame's time step: the poses of consecutive frames give the bodies' velocities for ``time_of_impact``
FRAME_DT = 1.0 / 60.0


def _impact_time(frame, clock, poses) -> dict:
    """``time_of_impact(FRAME_DT)`` of the World at the last pose, each body moving to its pose of the next frame
    (the sequence's last two poses): the fastest of ``ROUNDS`` calls in the benchmark's clock, and its impacts."""
    (c0, q0), (c1, _) = poses[-2], poses[-1]
    frame.world.update(frame.ids, c0, rotations=q0, velocities=(c1 - c0) / FRAME_DT)
    best = np.inf
    for _ in range(ROUNDS):
        t0 = clock()
        impacts = frame.world.time_of_impact(FRAME_DT)
        best = min(best, clock() - t0)
    return {"time_of_impact_min": best, "impacts": int(impacts.pairs.shape[0])}


@pytest.mark.parametrize("n", _sizes())
@pytest.mark.parametrize("scene_name", SCENES)
@pytest.mark.parametrize("peer", PEERS)
def test_bench_frame(benchmark, request, quick, peer, scene_name, n):
    if quick and n > 1_000:
        pytest.skip("--quick: N = 1e2 and 1e3 only")
    if peer == "MuJoCo" and n > MUJOCO_MAX_BODIES:
        pytest.skip(f"MuJoCo's broad phase needs 4 n^2 bytes of arena ({4 * n * n / 1e9:.0f} GB at n = {n})")
    scene, poses = _scene(scene_name, n)
    frame = _make(peer, scene)
    benchmark.group = f"World frame: {scene_name}, N = {n:,}"
    stages = _time_frames(benchmark, benchmark_clock(request), frame, poses)
    pairs, depth = frame.penetrating()
    info = {"scene": scene_name, "n": n, "peer": peer, "warmup_frames": WARMUP, "penetrating_pairs": len(pairs),
            **stages}
    (ref, exact) = _engine_reference(scene_name, n)
    info.update(_against_exact(exact, pairs, depth))
    if peer != "World tree":
        info.update({f"vs_world_{k}": v for k, v in agreement(ref, (pairs, depth)).items()})
    if peer.startswith("World"):
        info.update(_world_counts(frame))
        info.update(_impact_time(frame, benchmark_clock(request), poses))
    benchmark.extra_info.update(info)
    if isinstance(frame, BulletFrame):
        frame.close()


@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("n", [10_000, 100_000])
def test_bench_frame_threads(benchmark, quick, n, threads):
    """``World(threads=N)``: the mixed scene's frame on 1 and 2 threads, wall clock (each thread's time is not
    summed): the 2-core scaling of the whole frame, in its own group of reports/benchmarks.md."""
    if quick and n > 10_000:
        pytest.skip("--quick: N = 1e4 only")
    scene, poses = _scene("mixed", n)
    frame = EngineFrame(scene, threads=threads)
    benchmark.group = f"World frame threads: mixed, N = {n:,}"
    stages = _time_frames(benchmark, time.perf_counter, frame, poses)
    benchmark.extra_info.update({"threads": threads, "work": n, "unit": "bodies", **stages})


# ---------------------------------------------------------------------------------------------------------------
# the static level: moving bodies among static boxes
# ---------------------------------------------------------------------------------------------------------------

#: "World": the moving bodies and the level (``static=True``); "World alone": the moving bodies without it;
#: "World, level filtered": the level present but in a category the moving bodies' mask leaves out (what holding
#: the level costs when it makes no pair)
LEVEL_PEERS = ("World", "World alone", "World, level filtered", "MuJoCo", "pybullet")

_levels: dict = {}
_level_references: dict = {}


def _level_sizes():
    return [pytest.param((1_000, 100), id="1e3+1e2"), pytest.param((5_000, 500), id="5e3+5e2")]


def _level(size):
    if size not in _levels:
        scene, level = static_level(*size)
        _levels[size] = (scene, level, frame_motion(scene, WARMUP + ROUNDS))
    return _levels[size]


def _record(benchmark, frame, info, ref, pairs, depth) -> None:
    """Store ``info`` with World's counts (World) or the agreement of ``pairs``, ``depth`` with World's reference
    answer ``ref`` (a peer), in the benchmark's ``extra_info``; close a pybullet client."""
    if isinstance(frame, EngineFrame):
        info.update(_world_counts(frame))
    else:
        info.update(_agreement_info(ref, pairs, depth))
    if isinstance(frame, BulletFrame):
        frame.close()
    benchmark.extra_info.update(info)


def _make_level(peer, scene, level):
    if peer == "World, level filtered":
        frame = EngineFrame(scene, level=level)
        frame.world.set_filter(np.setdiff1d(frame.world.ids(), frame.ids), category=2)
        frame.world.set_filter(frame.ids, mask=1)
        return frame
    if peer.startswith("World"):
        return EngineFrame(scene, level=None if peer == "World alone" else level)
    return MuJoCoFrame(scene, level=level) if peer == "MuJoCo" else BulletFrame(scene, level=level)


def _last_pose_pairs(frame, poses):
    """A frame's penetrating pairs (depth > 1e-6) at the last pose, every pose of the sequence run through it."""
    for centers, quats in poses:
        frame.upload(centers, quats)
        frame.detect()
    return frame.penetrating()


def _level_reference(size):
    """World (level static) at the last pose: its penetrating pairs and depths."""
    if size not in _level_references:
        scene, level, poses = _level(size)
        _level_references[size] = _last_pose_pairs(EngineFrame(scene, level=level), poses)
    return _level_references[size]


@pytest.mark.parametrize("size", _level_sizes())
@pytest.mark.parametrize("peer", LEVEL_PEERS)
def test_bench_static_level(benchmark, request, quick, peer, size):
    n_static, n_moving = size
    if quick and n_static > 1_000:
        pytest.skip("--quick: the level of 1,000 static boxes only")
    scene, level, poses = _level(size)
    frame = _make_level(peer, scene, level)
    benchmark.group = f"World static level: {n_static:,} static boxes, {n_moving:,} moving bodies"
    stages = _time_frames(benchmark, benchmark_clock(request), frame, poses)
    pairs, depth = frame.penetrating()
    on_level = pairs[:, 1] >= n_moving  # the level's boxes follow the moving bodies
    info = {"suite": "static_level", "n_static": n_static, "n_moving": n_moving, "peer": peer,
            "warmup_frames": WARMUP, "penetrating_pairs": len(pairs), "level_pairs": int(on_level.sum()),
            "bodies_on_level": len(np.unique(pairs[on_level, 0])), **stages}
    ref = _level_reference(size)
    _record(benchmark, frame, info, ref, pairs, depth)
    if peer in ("World alone", "World, level filtered"):  # without the level, the same pairs of moving bodies
        assert np.array_equal(pairs, ref[0][ref[0][:, 1] < n_moving])
    if peer == "MuJoCo":
        assert not disagreements(ref, (pairs, depth)), disagreements(ref, (pairs, depth))[:10]


# ---------------------------------------------------------------------------------------------------------------
# collision filters: the mixed scene with half of the category pairs masked off
# ---------------------------------------------------------------------------------------------------------------

MASKED_PEERS = ("World", "MuJoCo", "pybullet")

_masked_references: dict = {}


def _masked_sizes():
    return [pytest.param(1_000, id="1e3"), pytest.param(10_000, id="1e4")]


def _make_filtered(peer, scene, filters):
    if peer == "World":
        return EngineFrame(scene, filters=filters)
    return MuJoCoFrame(scene, filters=filters) if peer == "MuJoCo" else BulletFrame(scene, filters=filters)


def _masked_reference(n, masked: bool):
    """World on the mixed scene at the last pose, with ``category_masks(n)`` or without: penetrating pairs."""
    if (n, masked) not in _masked_references:
        scene, poses = _scene("mixed", n)
        frame = EngineFrame(scene, filters=category_masks(n) if masked else None)
        _masked_references[(n, masked)] = _last_pose_pairs(frame, poses)
    return _masked_references[(n, masked)]


def _passing_masks(pairs, n):
    """The rows of ``pairs`` whose bodies' categories collide under ``category_masks(n)`` (Box2D's rule)."""
    category, mask = category_masks(n)
    i, j = pairs[:, 0], pairs[:, 1]
    return ((category[i] & mask[j]) != 0) & ((category[j] & mask[i]) != 0)


@pytest.mark.parametrize("n", _masked_sizes())
@pytest.mark.parametrize("masked", (True, False), ids=("masked", "unmasked"))
@pytest.mark.parametrize("peer", MASKED_PEERS)
def test_bench_masked(benchmark, request, quick, peer, masked, n):
    if quick and n > 1_000:
        pytest.skip("--quick: N = 1e3 only")
    scene, poses = _scene("mixed", n)
    frame = _make_filtered(peer, scene, category_masks(n) if masked else None)
    benchmark.group = f"World masked: mixed, N = {n:,}"
    stages = _time_frames(benchmark, benchmark_clock(request), frame, poses)
    pairs, depth = frame.penetrating()
    info = {"suite": "masked", "n": n, "peer": peer, "masked": masked, "warmup_frames": WARMUP,
            "penetrating_pairs": len(pairs), **stages}
    ref = _masked_reference(n, masked)
    _record(benchmark, frame, info, ref, pairs, depth)
    if masked and peer == "World":  # the filter drops exactly the masked-off pairs of the unmasked answer
        unmasked = _masked_reference(n, False)[0]
        assert np.array_equal(pairs, unmasked[_passing_masks(unmasked, n)])
    if masked and peer != "World":
        assert not disagreements(ref, (pairs, depth)), disagreements(ref, (pairs, depth))[:10]
