"""``World.time_of_impact`` asks the world's kept broad phase (the tree's fat boxes, the SAP's order, the static
tree's cached pairs), which it enlarges around the swept boxes: over a run of frames, with bodies moved by small
and large steps (staying in their fat boxes, leaving them), static bodies and a ground, its answer equals that of a
fresh brute-force World holding the same bodies at the same poses and velocities, bit for bit, and the pairs and
contacts of the following frames are unchanged by the enlarged fat boxes."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from engine import BROAD_PHASES
from engine.workloads import quaternion_matrices
from engine.world import Box, Capsule, Plane, Sphere, World

SIDE = 8.0


def _shape(rng, center):
    kind = rng.integers(3)
    if kind == 0:
        return Sphere(center, rng.uniform(0.2, 0.8))
    q = rng.normal(size=4)
    rotation = quaternion_matrices(q[None] / np.linalg.norm(q))[0]
    if kind == 1:
        return Box(center, rng.uniform(0.1, 0.7, 3), rotation)
    axis = rotation[:, 0] * rng.uniform(0.1, 0.8)
    return Capsule(center - axis, center + axis, rng.uniform(0.1, 0.5))


class Run:
    """A World and its model (id -> (shape as added, its centre now, velocity, static)); a Plane at y = 0."""

    def __init__(self, broad_phase, rng, n_moving, n_static):
        self.world, self.rng, self.model = World(broad_phase), rng, {}
        for k in range(n_moving + n_static):
            shape = _shape(rng, rng.uniform(-SIDE / 2, SIDE / 2, 3) + [0.0, SIDE / 2, 0.0])
            static = k >= n_moving
            v = np.zeros(3) if static else rng.normal(0.0, 2.0, 3)
            self.model[self.world.add(shape, velocity=v, static=static)] = (shape, shape.center, v, static)
        self.model[self.world.add(Plane(0.0))] = (Plane(0.0), None, np.zeros(3), True)

    def move(self):
        """Most bodies jitter (inside their fat boxes), a few jump (out of them); new velocities."""
        ids = self.moving()
        step = self.rng.normal(0.0, 0.02, (ids.size, 3))
        jump = self.rng.random(ids.size) < 0.2
        step[jump] = self.rng.normal(0.0, 1.5, (int(jump.sum()), 3))
        centers = np.array([self.model[i][1] for i in ids]) + step
        velocity = self.rng.normal(0.0, 2.0, (ids.size, 3))
        self.world.update(ids, centers, velocities=velocity)
        for row, i in enumerate(ids.tolist()):
            self.model[i] = (self.model[i][0], centers[row], velocity[row], False)

    def paired(self, pairs) -> np.ndarray:
        """Which rows of ``pairs`` (k, 2) the run's world may report: not two static bodies (grounds included)."""
        static = np.array([self.model[i][3] for i in sorted(self.model)])
        return ~(static[pairs[:, 0]] & static[pairs[:, 1]])

    def moving(self) -> np.ndarray:
        return np.array([i for i, (_, _, _, static) in self.model.items() if not static])

    def fresh(self) -> World:
        """A brute-force World given the same bodies, every one moving (the static path is not the oracle's), then
        the same poses and velocities by one update (the same upload arithmetic as the run's)."""
        world = World("brute")
        for i in sorted(self.model):
            world.add(self.model[i][0])
        ids = self.moving()
        world.update(ids, [self.model[i][1] for i in ids], velocities=[self.model[i][2] for i in ids])
        return world


@pytest.mark.parametrize("broad_phase", BROAD_PHASES)
@given(seed=st.integers(0, 2**32 - 1), n_static=st.integers(0, 16))
@settings(max_examples=6, deadline=None)
def test_time_of_impact_through_the_kept_broad_phase_equals_a_fresh_world(broad_phase, seed, n_static):
    rng = np.random.default_rng(seed)
    run = Run(broad_phase, rng, 24, n_static)
    for _ in range(5):
        run.move()
        dt = float(rng.choice([0.05, 0.3, 1.0]))
        kept, fresh_world = run.world.time_of_impact(dt), run.fresh()
        fresh = fresh_world.time_of_impact(dt)
        paired = run.paired(fresh.pairs)  # two static bodies are never paired
        np.testing.assert_array_equal(kept.pairs, fresh.pairs[paired])
        np.testing.assert_array_equal(kept.times, fresh.times[paired])
        # the fat boxes enlarged around the swept boxes change no later answer
        pairs = fresh_world.pairs()
        np.testing.assert_array_equal(run.world.pairs(), pairs[run.paired(pairs)])
        a, b = run.world.contacts(), fresh_world.contacts()
        paired = run.paired(b.pairs)
        np.testing.assert_array_equal(a.pairs, b.pairs[paired])
        np.testing.assert_array_equal(a.depth, b.depth[paired])
