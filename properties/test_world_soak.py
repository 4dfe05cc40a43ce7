"""Soak of the World frame (engine.world.World): many random edits and frames, every answer checked.

For every broad phase, a World over a Plane is driven by a seeded random sequence of operations — add a sphere,
box or capsule, remove a body, move one, update a batch (unit quaternions (w, x, y, z) or rotation matrices),
sometimes several edits before a query — and at each query:
- the pairs and contacts equal a from-scratch recomputation: a fresh ``World("brute")`` holding the same bodies
  at the same poses (same pairs, depths and normals; so the broad phase's state carried across frames — the
  tree's fat boxes and pair cache, the SAP order — loses and invents nothing);
- no impossible contact: depth >= 0 and finite, unit normals, every contact point within depth/2 (+ 1e-9 of
  the scene's scale) of both shapes, measured by independent closed forms (distance to a point, a segment, an
  oriented box, the plane), and on a sample of pairs translating the second body by depth + tol along the
  normal (+ 1e-6) separates them (GJK on the cores).
Length: CI runs ``OPS`` = 600 operations per broad phase (seconds); the long soak, 1e5 operations per broad
phase, runs with ``SOAK=long`` (or under the ``nightly`` Hypothesis profile): ``SOAK=long pytest
properties/test_world_soak.py -s`` or ``tox -e soak``; each run prints its figures.
"""
from __future__ import annotations

import os
import time

import numpy as np
import pytest

from engine import BROAD_PHASES, Box, Capsule, Plane, Sphere, World, gjk_distance
from engine.workloads import quaternion_matrices

LONG = os.environ.get("SOAK", "").lower() == "long" or os.environ.get("HYPOTHESIS_PROFILE") == "nightly"
OPS = 100_000 if LONG else 600
QUERY_EVERY = 8  # mean number of operations between two queries
MAX_BODIES = 40
SIDE = 6.0  # bodies live in [-SIDE/2, SIDE/2]^3, the Plane at y = -SIDE/2 + 0.5
GROUND = -SIDE / 2 + 0.5
TOL = 1e-9 * SIDE

pytestmark = pytest.mark.soak


def _random_rotation(rng) -> np.ndarray:
    q = rng.normal(size=4)
    return quaternion_matrices((q / np.linalg.norm(q))[None])[0]


def _random_shape(rng):
    c = rng.uniform(-SIDE / 2, SIDE / 2, 3)
    kind = rng.integers(3)
    if kind == 0:
        return Sphere(c, rng.uniform(0.2, 0.8))
    if kind == 1:
        return Box(c, rng.uniform(0.2, 0.7, 3), _random_rotation(rng))
    d = rng.normal(size=3) * 0.5
    return Capsule(c - d, c + d, rng.uniform(0.15, 0.5))


def distance_to_shape(q, shape, center, rotation) -> float:
    """Euclidean distance from q to the shape at a pose (0 inside), in closed form per kind."""
    if isinstance(shape, Plane):
        return max(q[1] - shape.altitude, 0.0)
    if isinstance(shape, Box):
        u = rotation.T @ (q - center)
        return float(np.linalg.norm(np.maximum(np.abs(u) - shape.half_extents, 0.0)))
    core = center + shape.local @ rotation.T
    if core.shape[0] == 1:
        return max(float(np.linalg.norm(q - core[0])) - shape.radius, 0.0)
    a, b = core
    t = np.clip(np.dot(q - a, b - a) / np.dot(b - a, b - a), 0.0, 1.0)
    return max(float(np.linalg.norm(q - (a + t * (b - a)))) - shape.radius, 0.0)


class Soak:
    """A World and its model: id -> (shape, center, rotation matrix); grounds have no pose."""

    def __init__(self, broad_phase: str, rng):
        self.world, self.rng = World(broad_phase), rng
        self.model: dict = {}
        ground = Plane(GROUND)
        self.model[self.world.add(ground)] = (ground, None, None)
        self.queries = self.points = 0

    def movable(self) -> list[int]:
        return sorted(i for i, m in self.model.items() if m[1] is not None)

    def step(self) -> None:
        live, rng = self.movable(), self.rng
        op = rng.choice(["add", "remove", "move", "update"], p=[0.15, 0.1, 0.25, 0.5])
        if op == "add" and len(live) < MAX_BODIES or len(live) < 2:
            shape = _random_shape(rng)
            self.model[self.world.add(shape)] = (shape, shape.center.copy(), shape.rotation.copy())
        elif op == "remove":
            i = int(rng.choice(live))
            self.world.remove(i)
            del self.model[i]
        elif op == "move":
            i = int(rng.choice(live))
            shape, c, r = self.model[i]
            c = np.clip(c + rng.normal(0.0, 0.3, 3), -SIDE / 2, SIDE / 2)
            self.world.move(i, center=c)
            self.model[i] = (shape, c, r)
        else:
            chosen = rng.choice(live, size=rng.integers(1, len(live) + 1), replace=False)
            centers = np.array([self.model[i][1] for i in chosen]) + rng.normal(0.0, 0.05, (len(chosen), 3))
            centers = np.clip(centers, -SIDE / 2, SIDE / 2)
            q = rng.normal(size=(len(chosen), 4))
            q /= np.linalg.norm(q, axis=1, keepdims=True)
            rot = quaternion_matrices(q)
            self.world.update(chosen, centers, rotations=q if rng.random() < 0.5 else rot)
            for row, i in enumerate(chosen.tolist()):
                self.model[i] = (self.model[i][0], centers[row], rot[row])

    def from_scratch(self):
        """The contacts of a fresh brute-force World with the same bodies at the same poses, in this world's ids."""
        ids = sorted(self.model)
        fresh = World("brute")
        for i in ids:
            shape, c, r = self.model[i]
            if c is None:
                fresh.add(shape)
            elif isinstance(shape, Box):
                fresh.add(Box(c, shape.half_extents, r))
            elif isinstance(shape, Capsule):
                a, b = c + shape.local @ r.T
                fresh.add(Capsule(a, b, shape.radius))
            else:
                fresh.add(Sphere(c, shape.radius))
        got = fresh.contacts()
        return np.array(ids, np.int64)[got.pairs].reshape(-1, 2), got

    def check(self) -> None:
        cs = self.world.contacts()
        self.queries += 1
        self.points += cs.points.shape[0]
        pairs, fresh = self.from_scratch()
        np.testing.assert_array_equal(cs.pairs, pairs)
        np.testing.assert_allclose(cs.depth, fresh.depth, rtol=0, atol=TOL)
        np.testing.assert_allclose(cs.normal, fresh.normal, rtol=0, atol=1e-9)
        assert np.all(np.isfinite(cs.depth)) and np.all(cs.depth >= 0.0)
        assert np.all(np.isfinite(cs.points))
        assert np.all(np.abs(np.linalg.norm(cs.normal, axis=1) - 1.0) <= 1e-12)
        for p, (i, j) in enumerate(cs.pairs.tolist()):
            for q in cs.points_of(p):
                for body in (i, j):
                    assert distance_to_shape(q, *self.model[body]) <= cs.depth[p] / 2 + TOL, (p, i, j, body)
        for p in self.rng.choice(cs.pairs.shape[0], size=min(4, cs.pairs.shape[0]), replace=False).tolist():
            i, j = cs.pairs[p]
            (sa, ca, ra), (sb, cb, rb) = self.model[i], self.model[j]
            if ca is None or cb is None:
                continue
            pa, pb = ca + sa.local @ ra.T, cb + sb.local @ rb.T
            gap, _, _ = gjk_distance(pa, pb + (cs.depth[p] + 1e-6) * cs.normal[p])
            assert gap - sa.radius - sb.radius >= 0.0, (i, j)


@pytest.mark.parametrize("broad_phase", BROAD_PHASES)
def test_world_soak_against_a_fresh_world(broad_phase):
    rng = np.random.default_rng(sorted(BROAD_PHASES).index(broad_phase))
    soak = Soak(broad_phase, rng)
    start = time.perf_counter()
    for _ in range(OPS):
        soak.step()
        if rng.random() < 1.0 / QUERY_EVERY:
            soak.check()
    soak.check()
    assert soak.queries > OPS / (2 * QUERY_EVERY) and soak.points > 0
    print(f"\nWorld soak [{broad_phase}]: {OPS} operations, {soak.queries} queries checked, {soak.points} contact "
          f"points, {len(soak.movable())} bodies at the end, {time.perf_counter() - start:.1f} s")
