"""Strategies for the World pipeline: shapes of every kind, poses, small scenes.

The shapes are read off the registry of shape kinds (``engine.world.KINDS``): every registered kind is built
through its shape class's ``random(rng, center, size)`` with a Hypothesis-drawn seed, centre and size, so that a
kind registered in engine/world/shapes.py reaches the tests without an edit here. The hand-written strategies of
the four first convex kinds (``spheres``, ``boxes``, ``capsules``, ``hulls``: coordinates drawn one by one, so
that they shrink well) are kept beside them.

- ``bodies``: convex shapes only (every registered convex kind) — what the oracles of properties/test_world.py
  (GJK on the core points) understand;
- ``compounds``: shapes of the composite kinds (``Compound``): the registry's ``random`` and compounds of
  ``bodies`` parts at drawn positions and rotations;
- ``any_bodies``: ``bodies`` or ``compounds`` (every bounded kind), for the tests that take compounds;
- ``grounds``: shapes of the static-only kinds (``Plane``, ``HeightCurve``), below the scene.
"""
from __future__ import annotations

import numpy as np
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from engine.world import KINDS, Box, Capsule, Compound, ConvexPolyhedron, HeightCurve, Plane, Sphere
from engine.world.shapes import Shape

from .geometry import rotations, seeds

__all__ = ["positions", "sizes", "spheres", "boxes", "capsules", "hulls", "bodies", "velocities", "poses", "planes",
           "curves", "degenerate_rotations", "kernel_scales", "shape_class", "shapes_of_kind", "registered_shapes",
           "compounds", "any_bodies", "grounds", "convex_kinds", "composite_kinds", "ground_kinds"]

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


def _subclasses(cls):
    for sub in cls.__subclasses__():
        yield sub
        yield from _subclasses(sub)


def shape_class(kind):
    """The shape class of a registered kind (the subclass of ``Shape`` whose ``kind`` is it); LookupError when
    no class or several claim it."""
    found = sorted({c for c in _subclasses(Shape) if c.__dict__.get("kind") is kind}, key=lambda c: c.__name__)
    if len(found) != 1:
        raise LookupError(f"the kind {kind.name!r} has {len(found)} shape classes: {[c.__name__ for c in found]}")
    return found[0]


def convex_kinds():
    """The registered convex kinds (a body of any of them may be a compound's part), by code."""
    return [k for k in KINDS if k.convex and k.bounded and not k.static_only]


def composite_kinds():
    """The registered composite kinds (made of parts), by code."""
    return [k for k in KINDS if k.composite and k.bounded and not k.static_only]


def ground_kinds():
    """The registered static-only kinds (the grounds), by code."""
    return [k for k in KINDS if k.static_only]


def shapes_of_kind(kind, centers=None, size=None):
    """Shapes of one registered kind, from its class's ``random(rng, center, size)`` with a drawn seed, centre
    (``centers``, default ``positions``) and size (``size``, default ``sizes``)."""
    cls = shape_class(kind)
    return st.builds(lambda seed, c, s: cls.random(np.random.default_rng(seed), np.asarray(c, float), float(s)),
                     seeds, positions if centers is None else centers, sizes if size is None else size)


def registered_shapes(kinds, centers=None, size=None):
    """Shapes of any of ``kinds`` (a callable returning registered kinds, read when first drawn), each through
    ``shapes_of_kind``."""
    return st.deferred(lambda: st.one_of(*[shapes_of_kind(k, centers, size) for k in kinds()]))


#: convex shapes of every registered convex kind (the hand-written strategies beside the registry's random ones)
bodies = st.one_of(spheres(), boxes(), capsules(), hulls(), registered_shapes(convex_kinds))


@st.composite
def _compounds_of_bodies(draw, centers=None):
    """A Compound of 1-3 ``bodies`` parts at drawn positions (within ~1 of its centre) and rotations."""
    parts = draw(st.lists(bodies, min_size=1, max_size=3))
    offsets = [np.array(draw(st.tuples(*[st.floats(-1.0, 1.0, allow_nan=False)] * 3))) for _ in parts]
    turns = [draw(st.none() | rotations()) for _ in parts]
    rots = np.stack([p.rotation if r is None else r for p, r in zip(parts, turns)])
    # the parts' own sizes: hand-written bodies sit anywhere in the scene; keep their geometry, not their place
    return Compound(parts, offsets, rots, center=draw(positions if centers is None else centers),
                    rotation=draw(st.none() | rotations()))


def compounds_near(centers=None, size=None):
    """Compounds: every registered composite kind's ``random``, and compounds of ``bodies`` parts."""
    return registered_shapes(composite_kinds, centers, size) | _compounds_of_bodies(centers)


def any_bodies_near(centers=None, size=None):
    """Shapes of every bounded kind (convex and composite) about ``centers``."""
    convex = bodies if centers is None and size is None else registered_shapes(convex_kinds, centers, size)
    return convex | compounds_near(centers, size)


compounds = compounds_near()
any_bodies = any_bodies_near()
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

#: grounds of every static-only kind: the hand-written planes and curves, and each kind's ``random`` below the
#: scene (centre y in [-5, 0])
grounds = planes | curves | registered_shapes(ground_kinds, st.tuples(st.just(0.0), st.floats(-5.0, 0.0),
                                                                     st.just(0.0)).map(np.array))


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
