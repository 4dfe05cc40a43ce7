"""The standard workloads of the benchmarks and of the properties that check the benchmarks' claims.

Every generator is deterministic (a seed in, the same arrays out), so a figure in ``reports/`` can be reproduced
with the same call:

- ``w1_boxes(n)`` — Terdiman's box-pruning benchmark: n AABBs, centres integers uniform in [−2048, 2048)³,
  half extents integers uniform in [0, 127] (about 11.8k overlapping pairs at n = 10,000);
- ``w2_spheres(n, eta)`` — n equal spheres uniform in a cube at packing fraction ``eta`` (sphere volume over the
  cube's volume);
- ``mixed_world_scene(n)`` — n bodies for ``World``: spheres, rotated boxes and convex hulls uniform in a cube;
- ``random_steps(centers, rounds)`` — the per-frame motion: each body moves by a small random step every frame.
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["SEED", "w1_boxes", "w2_spheres", "mixed_world_scene", "random_steps"]

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
