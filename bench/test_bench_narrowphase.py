"""Narrow-phase benchmarks: batched GJK (box–box, 20-vertex hulls) and OBB SAT against python-fcl and coal called
per pair from Python, in the same run (compare ratios, never absolute times; nothing here asserts a time).

Run: ``python -m pytest bench/test_bench_narrowphase.py --benchmark-only --benchmark-timer=time.process_time``
(process time is steadier than wall time on a shared machine). Each benchmark stores ``pairs`` in
``extra_info``; ns per pair = mean time / pairs. Targets (issue 3): <= 1 µs per box–box GJK distance and
<= 200 ns per OBB SAT test in batches of 1e5 pairs; >= 10× faster per pair than python-fcl's ``distance``.

The batched forms of the other narrow tests run against the engine's own per-pair loop (``peer`` "engine
per-pair": the single-pair function called from Python for every pair, as before the batch kernels):
``contact_feature_pairs`` on touching and overlapping box pairs, ``overlap_convex_sat_pairs`` on 20-vertex hulls
shared between pairs, and the curved-ground circle test (Python f, numba-jitted f, one call per circle).
"""
from __future__ import annotations

import os

import numpy as np
import pytest

from engine.narrowphase.contact_manifold import contact_feature, contact_feature_pairs
from engine.narrowphase.gjk import gjk_distance_batch, pack_point_sets
from engine.narrowphase.primitives import overlap_circle_curve
from engine.narrowphase.sat import overlap_convex_sat, overlap_convex_sat_pairs, overlap_obb_obb_batch

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
    """Time ``fn`` in the group of its test ("narrow phase: gjk box-box", ...): the engine's batch, its threads and
    the peers on one table, compared per pair."""
    benchmark.group = f"narrow phase: {test}"
    benchmark.extra_info.update({"pairs": pairs, "peer": peer, "test": test, "work": pairs, "unit": "pairs"})
    return benchmark.pedantic(fn, rounds=3, iterations=1, warmup_rounds=1)


# --- the engine ------------------------------------------------------------------------------------------------

def test_gjk_box_box_batch_engine(benchmark, boxes):
    a = boxes["corners"][:N_BATCH]
    b = boxes["corners"][N_BATCH:]
    dist, _, _ = _run(benchmark, lambda: gjk_distance_batch(a, b), N_BATCH, "engine", "gjk box-box")
    assert np.isfinite(dist).all()


def test_gjk_box_box_batch_engine_kernel_only(benchmark, boxes):
    """The compiled loop alone (no validation, no copies): what the public boundary costs is the difference."""
    from engine.narrowphase.gjk import MAX_ITERATIONS, gjk_pairs_kernel, gjk_scratch
    from engine.narrowphase.status import GJK_NOT_CONVERGED

    a = np.ascontiguousarray(boxes["corners"][:N_BATCH])
    b = np.ascontiguousarray(boxes["corners"][N_BATCH:])
    dist = np.empty(N_BATCH)
    ca = np.empty((N_BATCH, 3))
    cb = np.empty((N_BATCH, 3))
    status = np.empty(N_BATCH, np.int64)
    scratch = gjk_scratch(8)
    _run(benchmark, lambda: gjk_pairs_kernel(a, b, scratch.no_pairs, scratch.no_offsets, MAX_ITERATIONS, scratch,
                                             dist, ca, cb, status), N_BATCH, "engine-kernel", "gjk box-box")
    assert (status != GJK_NOT_CONVERGED).all()


def test_gjk_hull20_batch_engine(benchmark, hulls):
    dist, _, _ = _run(benchmark, lambda: gjk_distance_batch(hulls[:N_HULL], hulls[N_HULL:]), N_HULL, "engine",
                      "gjk hull20")
    assert np.isfinite(dist).all()


def _threads() -> int:
    n = os.cpu_count() or 1
    if n < 2:
        pytest.skip("one CPU: no threaded batch to time")
    return n


def test_gjk_box_box_batch_engine_threads(benchmark, boxes):
    """The same batch split among all CPUs (``threads=``); the issue's per-pair target is judged on one thread."""
    n = _threads()
    a = boxes["corners"][:N_BATCH]
    b = boxes["corners"][N_BATCH:]
    _run(benchmark, lambda: gjk_distance_batch(a, b, threads=n), N_BATCH, f"engine {n} threads", "gjk box-box")


def test_gjk_hull20_batch_engine_threads(benchmark, hulls):
    n = _threads()
    _run(benchmark, lambda: gjk_distance_batch(hulls[:N_HULL], hulls[N_HULL:], threads=n), N_HULL,
         f"engine {n} threads", "gjk hull20")


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


# --- batched forms of the other narrow tests, against the engine's per-pair loop ---------------------------------

N_CONTACT = 10_000  # box pairs per contact_feature_pairs call
N_CONTACT_LOOP = 1_000  # pairs of the per-pair loop over contact_feature
N_SAT_SHAPES = 1_000  # 20-vertex hulls shared by the SAT pairs
N_SAT = 5_000  # hull pairs per overlap_convex_sat_pairs call
N_SAT_LOOP = 250  # pairs of the per-pair loop over overlap_convex_sat (its quickhull runs per call)
N_CURVE = 10_000  # circles against the curved ground per call
N_CURVE_LOOP = 1_000  # circles of the per-circle loop


@pytest.fixture(scope="module")
def contact_boxes(quick):
    """Touching and overlapping box pairs: half are axis-aligned boxes stacked on z (gap 0 or overlapping by up to
    10 %: face–face patches), half randomly rotated boxes whose centres are 0.6–1.0 × (sum of half diagonals)
    apart. Packed as points/offsets with pairs (2p, 2p + 1)."""
    n = N_CONTACT // 10 if quick else N_CONTACT
    rng = np.random.default_rng(3)
    half = rng.uniform(0.2, 1.0, size=(2 * n, 3))
    rot = _random_rotations(2 * n, rng)
    center = np.zeros((2 * n, 3))
    for p in range(n):
        a, b = 2 * p, 2 * p + 1
        if p < n // 2:
            rot[a] = rot[b] = np.eye(3)
            shift = rng.uniform(-0.5, 0.5, 3) * half[a]
            shift[2] = half[a, 2] + half[b, 2] - (0.0 if p % 2 else rng.uniform(0.0, 0.1) * half[b, 2])
            center[b] = shift
        else:
            u = rng.normal(size=3)
            u /= np.linalg.norm(u)
            reach = np.linalg.norm(half[a]) + np.linalg.norm(half[b])
            center[b] = u * reach * rng.uniform(0.6, 1.0)
    corners = center[:, None, :] + np.einsum("nkj,nij->nki", _SIGNS[None] * half[:, None, :], rot)
    points = np.ascontiguousarray(corners.reshape(-1, 3))
    offsets = np.arange(0, 8 * (2 * n) + 1, 8, dtype=np.int64)
    pairs = np.stack([np.arange(0, 2 * n, 2), np.arange(1, 2 * n, 2)], axis=1)
    return {"corners": corners, "points": points, "offsets": offsets, "pairs": pairs}


def test_contact_box_box_batch_engine(benchmark, contact_boxes):
    d = contact_boxes
    batch = _run(benchmark, lambda: contact_feature_pairs(d["points"], d["offsets"], d["pairs"]),
                 d["pairs"].shape[0], "engine", "contact box-box")
    benchmark.extra_info["exact_fallbacks"] = int(batch.exact_fallback.sum())
    assert np.isfinite(batch.separation).all() and (batch.separation <= 1e-9).mean() > 0.5


def test_contact_box_box_per_pair(benchmark, contact_boxes):
    corners = contact_boxes["corners"]
    n = min(N_CONTACT_LOOP, contact_boxes["pairs"].shape[0])

    def run():
        return [contact_feature(corners[2 * p], corners[2 * p + 1]) for p in range(n)]

    out = _run(benchmark, run, n, "engine per-pair", "contact box-box")
    assert len(out) == n


@pytest.fixture(scope="module")
def sat_hulls(quick):
    """N_SAT_SHAPES Gaussian clouds of 20 vertices, centres uniform in a cube where about a third of the random
    pairs overlap; N_SAT random pairs among them (each hull in ≈10 pairs)."""
    rng = np.random.default_rng(11)
    shapes = rng.normal(size=(N_SAT_SHAPES, 20, 3)) * 0.5 + rng.uniform(-2.5, 2.5, size=(N_SAT_SHAPES, 1, 3))
    points, offsets = pack_point_sets(list(shapes))
    k = N_SAT // 10 if quick else N_SAT
    pairs = rng.integers(0, N_SAT_SHAPES, size=(k, 2))
    return {"shapes": shapes, "points": points, "offsets": offsets, "pairs": pairs}


def test_sat_convex_batch_engine(benchmark, sat_hulls):
    d = sat_hulls
    out = _run(benchmark, lambda: overlap_convex_sat_pairs(d["points"], d["offsets"], d["pairs"]),
               d["pairs"].shape[0], "engine", "sat convex hull20")
    assert out.shape == (d["pairs"].shape[0],)


def test_sat_convex_per_pair(benchmark, sat_hulls):
    shapes, pairs = sat_hulls["shapes"], sat_hulls["pairs"][:N_SAT_LOOP]

    def run():
        return [overlap_convex_sat(shapes[i], shapes[j]) for i, j in pairs]

    _run(benchmark, run, pairs.shape[0], "engine per-pair", "sat convex hull20")


def _ground(x):
    return np.sin(3 * x) + 0.2 * x


@pytest.fixture(scope="module")
def circles(quick):
    rng = np.random.default_rng(5)
    n = N_CURVE // 10 if quick else N_CURVE
    return rng.uniform(-5, 5, size=(n, 2)), rng.uniform(0.05, 1.0, size=n)


def test_curve_circle_batch_engine(benchmark, circles):
    c, r = circles
    out = _run(benchmark, lambda: overlap_circle_curve(c, r, _ground), c.shape[0], "engine", "curve circle")
    assert out.shape == (c.shape[0],)


def test_curve_circle_batch_engine_jit_f(benchmark, circles):
    import numba

    c, r = circles
    ground = numba.njit(_ground)
    out = _run(benchmark, lambda: overlap_circle_curve(c, r, ground), c.shape[0], "engine jit-f", "curve circle")
    assert np.array_equal(out, overlap_circle_curve(c, r, _ground))


def test_curve_circle_per_shape(benchmark, circles):
    c, r = circles
    n = min(N_CURVE_LOOP, c.shape[0])

    def run():
        return [overlap_circle_curve(c[i:i + 1], r[i], _ground) for i in range(n)]

    _run(benchmark, run, n, "engine per-pair", "curve circle")
