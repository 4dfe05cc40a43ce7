"""Narrow-phase benchmarks: batched GJK (box–box, 20-vertex hulls) and OBB SAT against python-fcl and coal called
per pair from Python, in the same run (compare ratios, never absolute times; nothing here asserts a time).

Run: ``python -m pytest bench/test_bench_narrowphase.py --benchmark-only --benchmark-timer=time.process_time``
(process time is steadier than wall time on a shared machine). Each benchmark stores ``pairs`` in
``extra_info``; ns per pair = mean time / pairs. Targets (issue 3): <= 1 µs per box–box GJK distance and
<= 200 ns per OBB SAT test in batches of 1e5 pairs; >= 10× faster per pair than python-fcl's ``distance``.
"""
from __future__ import annotations

import numpy as np
import pytest

from engine.narrowphase.gjk import gjk_distance_batch
from engine.narrowphase.sat import overlap_obb_obb_batch

N_BATCH = 100_000  # pairs per batched call (the workload)
N_HULL = 20_000  # 20-vertex hull pairs per batched call
N_PEER = 2_000  # pairs timed for the per-pair peers (python-fcl, coal): a Python loop, so fewer

_SIGNS = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=np.float64)


def _random_rotations(n: int, rng) -> np.ndarray:
    """(n, 3, 3) uniformly random rotations (from normalised quaternions); columns are the box axes."""
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1)[:, None]
    w, x, y, z = q.T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], axis=1),
        np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], axis=1),
        np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], axis=1),
    ], axis=1)


@pytest.fixture(scope="module")
def boxes():
    """2·N_BATCH random boxes: centres uniform in [-3, 3]^3, half extents in [0.1, 1] (≈5 % of pairs overlap)."""
    rng = np.random.default_rng(20261122)
    n = 2 * N_BATCH
    rot = _random_rotations(n, rng)
    half = rng.uniform(0.1, 1.0, size=(n, 3))
    center = rng.uniform(-3.0, 3.0, size=(n, 3))
    corners = center[:, None, :] + np.einsum("nkj,nij->nki", _SIGNS[None] * half[:, None, :], rot)
    return {"rot": rot, "half": half, "center": center, "axes": np.ascontiguousarray(np.transpose(rot, (0, 2, 1))),
            "corners": corners}


@pytest.fixture(scope="module")
def hulls():
    """2·N_HULL point sets of 20 vertices (Gaussian clouds), the second of each pair shifted by N(0, 2)."""
    rng = np.random.default_rng(7)
    pts = rng.normal(size=(2 * N_HULL, 20, 3))
    pts[N_HULL:] += 2.0 * rng.normal(size=(N_HULL, 1, 3))
    return pts


def _run(benchmark, fn, pairs: int, peer: str, test: str):
    benchmark.extra_info.update({"pairs": pairs, "peer": peer, "test": test})
    return benchmark.pedantic(fn, rounds=3, iterations=1, warmup_rounds=1)


# --- the engine ------------------------------------------------------------------------------------------------

def test_gjk_box_box_batch_engine(benchmark, boxes):
    a = boxes["corners"][:N_BATCH]
    b = boxes["corners"][N_BATCH:]
    dist, _, _ = _run(benchmark, lambda: gjk_distance_batch(a, b), N_BATCH, "engine", "gjk box-box")
    assert np.isfinite(dist).all()


def test_gjk_box_box_batch_engine_kernel_only(benchmark, boxes):
    """The compiled loop alone (no validation, no copies): what the public boundary costs is the difference."""
    from engine.narrowphase.gjk import MAX_ITERATIONS, _gjk_batch

    a = np.ascontiguousarray(boxes["corners"][:N_BATCH])
    b = np.ascontiguousarray(boxes["corners"][N_BATCH:])
    dist = np.empty(N_BATCH)
    ca = np.empty((N_BATCH, 3))
    cb = np.empty((N_BATCH, 3))
    status = np.empty(N_BATCH, np.int64)
    _run(benchmark, lambda: _gjk_batch(a, b, MAX_ITERATIONS, dist, ca, cb, status), N_BATCH, "engine-kernel",
         "gjk box-box")
    assert (status != 2).all()


def test_gjk_hull20_batch_engine(benchmark, hulls):
    dist, _, _ = _run(benchmark, lambda: gjk_distance_batch(hulls[:N_HULL], hulls[N_HULL:]), N_HULL, "engine",
                      "gjk hull20")
    assert np.isfinite(dist).all()


def test_obb_sat_batch_engine(benchmark, boxes):
    c, r, h = boxes["center"], boxes["axes"], boxes["half"]
    out = _run(benchmark, lambda: overlap_obb_obb_batch(c[:N_BATCH], r[:N_BATCH], h[:N_BATCH], c[N_BATCH:],
                                                        r[N_BATCH:], h[N_BATCH:]), N_BATCH, "engine", "sat obb")
    assert out.shape == (N_BATCH,)


# --- peers, called per pair from Python ------------------------------------------------------------------------

def test_gjk_box_box_fcl(benchmark, boxes):
    fcl = pytest.importorskip("fcl")
    objs = [(fcl.CollisionObject(fcl.Box(*(2 * boxes["half"][i])), fcl.Transform(boxes["rot"][i],
                                                                                 boxes["center"][i])),
             fcl.CollisionObject(fcl.Box(*(2 * boxes["half"][N_BATCH + i])),
                                 fcl.Transform(boxes["rot"][N_BATCH + i], boxes["center"][N_BATCH + i])))
            for i in range(N_PEER)]
    request = fcl.DistanceRequest()

    def run():
        return [fcl.distance(a, b, request, fcl.DistanceResult()) for a, b in objs]  # fresh result per call

    _run(benchmark, run, N_PEER, "python-fcl", "gjk box-box")


def _coal_boxes(boxes, coal):
    return [(coal.Box(*(2 * boxes["half"][i])), coal.Transform3s(boxes["rot"][i], boxes["center"][i]),
             coal.Box(*(2 * boxes["half"][N_BATCH + i])),
             coal.Transform3s(boxes["rot"][N_BATCH + i], boxes["center"][N_BATCH + i])) for i in range(N_PEER)]


def test_gjk_box_box_coal(benchmark, boxes):
    coal = pytest.importorskip("coal")
    objs = _coal_boxes(boxes, coal)
    request = coal.DistanceRequest()

    def run():
        return [coal.distance(ga, ta, gb, tb, request, coal.DistanceResult()) for ga, ta, gb, tb in objs]

    _run(benchmark, run, N_PEER, "coal", "gjk box-box")


def test_obb_sat_coal_collide(benchmark, boxes):
    coal = pytest.importorskip("coal")
    objs = _coal_boxes(boxes, coal)
    request = coal.CollisionRequest()

    def run():
        return [coal.collide(ga, ta, gb, tb, request, coal.CollisionResult()) for ga, ta, gb, tb in objs]

    _run(benchmark, run, N_PEER, "coal", "sat obb")


def test_gjk_hull20_fcl(benchmark, hulls):
    fcl = pytest.importorskip("fcl")
    from scipy.spatial import ConvexHull

    def convex(p):
        h = ConvexHull(p)
        faces = np.hstack([np.full((len(h.simplices), 1), 3), h.simplices]).ravel()
        return fcl.CollisionObject(fcl.Convex(p, len(h.simplices), faces), fcl.Transform())

    n = N_PEER // 2
    objs = [(convex(hulls[i]), convex(hulls[N_HULL + i])) for i in range(n)]
    request = fcl.DistanceRequest()

    def run():
        return [fcl.distance(a, b, request, fcl.DistanceResult()) for a, b in objs]

    _run(benchmark, run, n, "python-fcl", "gjk hull20")


def test_gjk_hull20_coal(benchmark, hulls):
    coal = pytest.importorskip("coal")

    def convex(p):
        v = coal.StdVec_Vec3s()
        for q in p:
            v.append(q)
        return coal.Convex.convexHull(v, False, "")

    n = N_PEER // 2
    objs = [(convex(hulls[i]), convex(hulls[N_HULL + i])) for i in range(n)]
    request = coal.DistanceRequest()
    identity = coal.Transform3s()

    def run():
        return [coal.distance(a, identity, b, identity, request, coal.DistanceResult()) for a, b in objs]

    _run(benchmark, run, n, "coal", "gjk hull20")
