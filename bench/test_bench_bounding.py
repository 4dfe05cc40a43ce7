"""Benchmarks of the bounding volumes: fits, batched overlap tests and convex hulls, each against a peer measured
in the same run (numpy vectorised code or scipy's Qhull), so the report reads as ratios.

Run: ``python -m pytest bench/test_bench_bounding.py --benchmark-only -q``; never asserted in tests.
Every benchmark checks its answer against the peer's once (outside the timed call).
"""
from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import ConvexHull as QhullHull

from engine.bounding import (
    convex_hull,
    fit_aabbs,
    fit_kdops,
    min_bounding_sphere,
    overlap_aabbs,
    overlap_spheres,
    ritter_sphere,
    ritter_spheres,
)

PAIRS = 100_000
RNG_SEED = 20


def _rounds(benchmark, func, *args, rounds=5):
    func(*args)  # compile / warm the cache outside the timing
    return benchmark.pedantic(func, args=args, rounds=rounds, iterations=1)


# ------------------------------------------------------------------------------------------------------------
# batched overlap tests, 1e5 pairs
# ------------------------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def sphere_pairs():
    rng = np.random.default_rng(RNG_SEED)
    ca, cb = rng.uniform(-10, 10, size=(2, PAIRS, 3))
    ra, rb = rng.uniform(0.1, 6.0, size=(2, PAIRS))
    return ca, ra, cb, rb


def _numpy_sphere_overlap(ca, ra, cb, rb):
    return ((ca - cb) ** 2).sum(axis=1) <= (ra + rb) ** 2


@pytest.mark.benchmark(group="sphere overlap, 1e5 pairs")
@pytest.mark.parametrize("impl", ["engine", "numpy"])
def test_bench_sphere_overlap(benchmark, sphere_pairs, impl):
    func = overlap_spheres if impl == "engine" else _numpy_sphere_overlap
    got = _rounds(benchmark, func, *sphere_pairs, rounds=20)
    assert np.array_equal(got, _numpy_sphere_overlap(*sphere_pairs))
    benchmark.extra_info["ns_per_pair"] = benchmark.stats.stats.median * 1e9 / PAIRS


@pytest.fixture(scope="module")
def box_pairs():
    rng = np.random.default_rng(RNG_SEED + 1)
    lo_a, lo_b = rng.uniform(-10, 10, size=(2, PAIRS, 3))
    hi_a = lo_a + rng.uniform(0, 6, size=(PAIRS, 3))
    hi_b = lo_b + rng.uniform(0, 6, size=(PAIRS, 3))
    return lo_a, hi_a, lo_b, hi_b


def _numpy_aabb_overlap(lo_a, hi_a, lo_b, hi_b):
    return ((lo_a <= hi_b) & (lo_b <= hi_a)).all(axis=1)


@pytest.mark.benchmark(group="AABB overlap, 1e5 pairs")
@pytest.mark.parametrize("impl", ["engine", "numpy"])
def test_bench_aabb_overlap(benchmark, box_pairs, impl):
    func = overlap_aabbs if impl == "engine" else _numpy_aabb_overlap
    got = _rounds(benchmark, func, *box_pairs, rounds=20)
    assert np.array_equal(got, _numpy_aabb_overlap(*box_pairs))
    benchmark.extra_info["ns_per_pair"] = benchmark.stats.stats.median * 1e9 / PAIRS


# ------------------------------------------------------------------------------------------------------------
# batched fits: 1e4 objects of 20 points
# ------------------------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def clouds():
    return np.random.default_rng(RNG_SEED + 2).normal(size=(10_000, 20, 3))


@pytest.mark.benchmark(group="fit 1e4 clouds of 20 points")
@pytest.mark.parametrize("impl", ["aabb engine", "aabb numpy", "18-dop engine", "ritter engine"])
def test_bench_batched_fits(benchmark, clouds, impl):
    if impl == "aabb engine":
        _rounds(benchmark, fit_aabbs, clouds)
    elif impl == "aabb numpy":
        _rounds(benchmark, lambda c: (c.min(axis=1), c.max(axis=1)), clouds)
    elif impl == "18-dop engine":
        _rounds(benchmark, fit_kdops, clouds, 18)
    else:
        _rounds(benchmark, ritter_spheres, clouds)
    benchmark.extra_info["ns_per_object"] = benchmark.stats.stats.median * 1e9 / len(clouds)


# ------------------------------------------------------------------------------------------------------------
# spheres: Welzl (exact) against Ritter (fast), 1e4 and 1e5 points
# ------------------------------------------------------------------------------------------------------------
@pytest.mark.benchmark(group="bounding sphere")
@pytest.mark.parametrize("n", [10_000, 100_000])
@pytest.mark.parametrize("method", ["welzl", "ritter"])
def test_bench_bounding_sphere(benchmark, n, method):
    pts = np.random.default_rng(RNG_SEED + 3).normal(size=(n, 3))
    func = min_bounding_sphere if method == "welzl" else ritter_sphere
    _, radius = _rounds(benchmark, func, pts)
    benchmark.extra_info["radius"] = radius
    benchmark.extra_info["ns_per_point"] = benchmark.stats.stats.median * 1e9 / n


# ------------------------------------------------------------------------------------------------------------
# convex hulls against Qhull
# ------------------------------------------------------------------------------------------------------------
def _cloud(kind, n, dim):
    pts = np.random.default_rng(RNG_SEED + 4).normal(size=(n, dim))
    if kind == "sphere":  # every point is a hull vertex: the worst case for output-sensitive hulls
        pts /= np.linalg.norm(pts, axis=1)[:, None]
    return pts


@pytest.mark.benchmark(group="convex hull")
@pytest.mark.parametrize("impl", ["engine", "qhull"])
@pytest.mark.parametrize("case", [("ball", 100_000, 3), ("sphere", 10_000, 3), ("ball", 100_000, 2),
                                  ("sphere", 10_000, 2)], ids=lambda c: f"{c[0]}-{c[1]}-{c[2]}d")
def test_bench_convex_hull(benchmark, impl, case):
    pts = _cloud(*case)
    func = convex_hull if impl == "engine" else QhullHull
    hull = _rounds(benchmark, func, pts, rounds=3)
    assert set(np.asarray(hull.vertices).tolist()) == set(QhullHull(pts).vertices.tolist())
    benchmark.extra_info["hull_vertices"] = len(hull.vertices)
