"""Strategies for the World pipeline: shapes of every kind, poses, small scenes."""
from __future__ import annotations

import numpy as np
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from engine.world import Box, Capsule, ConvexPolyhedron, HeightCurve, Plane, Sphere

from .geometry import rotations, seeds

__all__ = ["positions", "sizes", "spheres", "boxes", "capsules", "hulls", "bodies", "velocities", "poses", "planes",
           "curves", "degenerate_rotations", "kernel_scales"]

#: a scene of side ~8 with shapes of size ~0.3-1.5: a moderate density, pairs of every kind meet
positions = st.tuples(*[st.floats(-4.0, 4.0, allow_nan=False) | st.integers(-4, 4).map(float)] * 3).map(np.array)
sizes = st.floats(0.3, 1.5, allow_nan=False) | st.sampled_from([0.5, 1.0])


@st.composite
def spheres(draw):
    return Sphere(draw(positions), draw(sizes))


@st.composite
def boxes(draw):
    half = np.array([draw(sizes) for _ in range(3)])
    return Box(draw(positions), half, draw(st.none() | rotations()))


@st.composite
def capsules(draw):
    c = draw(positions)
    d = draw(st.tuples(*[st.floats(-1.5, 1.5, allow_nan=False)] * 3).map(np.array))
    return Capsule(c - d / 2, c + d / 2, draw(sizes) * 0.5)


@st.composite
def hulls(draw):
    rng = np.random.default_rng(draw(seeds))
    n = draw(st.integers(4, 20))
    pts = rng.normal(size=(n, 3)) * draw(sizes) * 0.7
    return ConvexPolyhedron(pts + draw(positions))


bodies = st.one_of(spheres(), boxes(), capsules(), hulls())
velocities = st.tuples(*[st.floats(-6.0, 6.0, allow_nan=False) | st.just(0.0)] * 3).map(np.array)
poses = st.tuples(positions, st.none() | rotations())
planes = st.floats(-5.0, 0.0, allow_nan=False).map(Plane)


def _wave(level, amplitude, wavenumber):
    def f(x):
        return level + amplitude * np.sin(wavenumber * x)
    return f


#: curved grounds y <= level + a sin(k x)
curves = st.builds(lambda level, a, k: HeightCurve(_wave(level, a, k), samples=64), st.floats(-5.0, -1.0),
                   st.floats(0.1, 1.5), st.floats(0.3, 2.0))


#: the 24 rotations of the cube (multiples of 90° about the axes)
CUBE_ROTATIONS = Rotation.create_group("O").as_matrix()


@st.composite
def _degenerate_rotation(draw):
    """Rotations aimed at degenerate contacts: a rotation of the cube (axes parallel to the world's), the same
    turned by ±1e-9 about a random axis, or a uniformly random one."""
    how = draw(st.sampled_from(["cube", "cube+eps", "random"]))
    if how == "random":
        return Rotation.random(random_state=draw(seeds)).as_matrix()
    base = CUBE_ROTATIONS[draw(st.integers(0, 23))]
    if how == "cube":
        return base
    axis = np.random.default_rng(draw(seeds)).normal(size=3)
    tilt = Rotation.from_rotvec(draw(st.sampled_from([1e-9, -1e-9])) * axis / np.linalg.norm(axis)).as_matrix()
    return tilt @ base


degenerate_rotations = _degenerate_rotation()

#: length scales of the kernel properties: from 1e-6 to 1e6
kernel_scales = st.sampled_from([1e-6, 1e-3, 1.0, 1e3, 1e6])
