"""The standard workloads of the benchmarks and of the properties that check the benchmarks' claims.

Every generator is deterministic (a seed in, the same arrays out), so a figure in ``reports/`` can be reproduced
with the same call:

- ``w1_boxes(n)`` — Terdiman's box-pruning benchmark: n AABBs, centres integers uniform in [−2048, 2048)³,
  half extents integers uniform in [0, 127] (about 11.8k overlapping pairs at n = 10,000);
- ``w2_spheres(n, eta)`` — n equal spheres uniform in a cube at packing fraction ``eta`` (sphere volume over the
  cube's volume);
- ``mixed_world_scene(n)`` — n bodies for ``World``: spheres, rotated boxes and convex hulls uniform in a cube;
- ``random_steps(centers, rounds)`` — the per-frame motion: each body moves by a small random step every frame.

The big-level scenes, where a grid whose cell count is capped would coarsen until one cell holds a whole cluster
(the quadratic cliff the broad-phase benchmarks watch for):

- ``clustered_spheres(n, eta, clusters, separation)`` — ``clusters`` dense W2 clusters ``separation`` apart;
- ``huge_among_small_boxes(n, huge)`` — the boxes of W2 spheres plus ``huge`` boxes each as large as half the
  scene;
- ``planar_spheres(n, area_fraction)`` — equal spheres whose centres all lie on one plane (z = 0).
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["SEED", "w1_boxes", "w2_spheres", "mixed_world_scene", "random_steps", "clustered_spheres",
           "huge_among_small_boxes", "planar_spheres", "BIG_LEVEL_SCENES", "big_level_boxes"]

#: the seed of every benchmark workload
SEED = 4


def w1_boxes(n: int, seed: int = SEED) -> tuple[np.ndarray, np.ndarray]:
    """Terdiman's box-pruning workload: ``(lo, hi)``, two float64 (n, 3) arrays (integer-valued)."""
    rng = np.random.default_rng(seed)
    centre = rng.integers(-2048, 2048, size=(n, 3)).astype(float)
    half = rng.integers(0, 128, size=(n, 3)).astype(float)
    return centre - half, centre + half


def w2_spheres(n: int, eta: float, seed: int = SEED, radius: float = 0.5) -> tuple[np.ndarray, float]:
    """n equal spheres of radius ``radius`` uniform in a cube at packing fraction ``eta``:
    ``(centres (n, 3) float64, radius)``."""
    side = (n * math.pi * (2 * radius) ** 3 / (6 * eta)) ** (1 / 3)
    return np.random.default_rng(seed).uniform(0.0, side, size=(n, 3)), radius


def mixed_world_scene(n: int, seed: int = 8):
    """``(shapes, centers (n, 3), rotations (n, 3, 3))``: 40 % spheres (r in [0.3, 0.7]), 30 % rotated boxes
    (half extents in [0.2, 0.6]), 30 % convex hulls of 12–20 random points (radius ~0.5), uniform in a cube at a
    bounding-sphere packing fraction of about 0.1."""
    from scipy.spatial.transform import Rotation

    from engine.world import Box, ConvexPolyhedron, Sphere
    from engine.world.shapes import Shape

    rng = np.random.default_rng(seed)
    kinds = rng.choice(3, size=n, p=[0.4, 0.3, 0.3])
    mean_volume = 4 / 3 * np.pi * 0.6 ** 3
    side = (n * mean_volume / 0.1) ** (1 / 3)
    centers = rng.uniform(0.0, side, size=(n, 3))
    rotations = Rotation.random(n, random_state=seed).as_matrix()
    shapes: list[Shape] = []
    for i in range(n):
        if kinds[i] == 0:
            shapes.append(Sphere(centers[i], rng.uniform(0.3, 0.7)))
        elif kinds[i] == 1:
            shapes.append(Box(centers[i], rng.uniform(0.2, 0.6, 3), rotations[i]))
        else:
            pts = rng.normal(size=(int(rng.integers(12, 21)), 3))
            pts *= 0.5 / np.linalg.norm(pts, axis=1, keepdims=True).max()
            shapes.append(ConvexPolyhedron(centers[i] + pts))
    return shapes, centers, rotations


def random_steps(centers, rounds: int, step: float = 0.02, seed: int = 9) -> list[np.ndarray]:
    """``rounds`` successive (n, 3) centre arrays, each the previous one moved by a normal step of scale ``step``."""
    rng = np.random.default_rng(seed)
    out, c = [], np.asarray(centers, dtype=float)
    for _ in range(rounds):
        c = c + rng.normal(0.0, step, c.shape)
        out.append(c)
    return out


def clustered_spheres(n: int, eta: float = 0.2, clusters: int = 2, separation: float = 1e6, seed: int = SEED,
                      radius: float = 0.5) -> tuple[np.ndarray, float]:
    """n equal spheres in ``clusters`` dense clusters: cluster k is a W2 cube of about n / clusters spheres at
    packing fraction ``eta``, shifted by k·separation along every axis. ``(centres (n, 3) float64, radius)``."""
    rng = np.random.default_rng(seed)
    sizes = [n // clusters + (1 if k < n % clusters else 0) for k in range(clusters)]
    parts = []
    for k, m in enumerate(sizes):
        side = (max(m, 1) * math.pi * (2 * radius) ** 3 / (6 * eta)) ** (1 / 3)
        parts.append(rng.uniform(0.0, side, size=(m, 3)) + k * separation)
    return np.concatenate(parts), radius


def huge_among_small_boxes(n: int, huge: int = 8, eta: float = 0.05, seed: int = SEED) -> tuple[np.ndarray, np.ndarray]:
    """``(lo, hi)`` (n, 3) float64: the bounding boxes of n − huge W2 spheres (radius 0.5, packing fraction
    ``eta``) and ``huge`` boxes each spanning half the scene along every axis at a random place in it."""
    small = max(n - huge, 0)
    centres, radius = w2_spheres(small, eta, seed)
    side = (max(small, 1) * math.pi / (6 * eta)) ** (1 / 3)
    rng = np.random.default_rng(seed + 1)
    corner = rng.uniform(0.0, side / 2, size=(n - small, 3))
    lo = np.concatenate([centres - radius, corner])
    hi = np.concatenate([centres + radius, corner + side / 2])
    return lo, hi


def planar_spheres(n: int, area_fraction: float = 0.3, seed: int = SEED,
                   radius: float = 0.5) -> tuple[np.ndarray, float]:
    """n equal spheres whose centres are uniform in a square of the plane z = 0, the discs covering
    ``area_fraction`` of it: ``(centres (n, 3) float64, radius)``."""
    side = math.sqrt(n * math.pi * radius ** 2 / area_fraction)
    centres = np.zeros((n, 3))
    centres[:, :2] = np.random.default_rng(seed).uniform(0.0, side, size=(n, 2))
    return centres, radius


#: the scenes of ``big_level_boxes``: the uniform W2 cube and the three big-level scenes
BIG_LEVEL_SCENES = ("uniform", "clusters", "huge", "plane")


def big_level_boxes(scene: str, n: int, seed: int = SEED) -> tuple[np.ndarray, np.ndarray]:
    """``(lo, hi)`` (n, 3) float64 boxes of one scene of ``BIG_LEVEL_SCENES``: "uniform" the boxes of W2
    spheres at η = 0.05, "clusters" those of ``clustered_spheres`` (two clusters at η = 0.2, 1e6 apart), "huge"
    ``huge_among_small_boxes`` (8 huge boxes), "plane" those of ``planar_spheres`` (area fraction 0.3)."""
    if scene == "huge":
        return huge_among_small_boxes(n, seed=seed)
    if scene == "uniform":
        centres, radius = w2_spheres(n, 0.05, seed)
    elif scene == "clusters":
        centres, radius = clustered_spheres(n, seed=seed)
    elif scene == "plane":
        centres, radius = planar_spheres(n, seed=seed)
    else:
        raise ValueError(f"scene must be one of {BIG_LEVEL_SCENES}, got {scene!r}")
    return centres - radius, centres + radius
