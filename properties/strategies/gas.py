"""Strategies for the confined gas: elastic collisions over wide mass ratios, wall normals, small gas scenes."""
from __future__ import annotations

import numpy as np
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

# with the JIT disabled (INTERPRETED, the mutation run) the longest gas properties check the same invariant on a
# smaller case, each asserting that the smaller case still takes the path it is about
from properties.jit_off import INTERPRETED  # noqa: F401  (re-exported for the gas properties)

finite = dict(allow_nan=False, allow_infinity=False, allow_subnormal=False)


def masses(min_value=1e-6, max_value=1e6):
    """Positive masses spanning 12 decades (ratios up to 1e12 between two draws)."""
    return st.floats(min_value, max_value, **finite).filter(lambda m: m > 0.0)


def vectors(scale=1e3):
    """(3,) vectors with components 0 or of magnitude in [1e-100, scale] (no products underflowing to
    subnormals: velocities of a gas, not of the float format's corners)."""
    component = st.floats(-scale, scale, **finite).filter(lambda x: x == 0.0 or abs(x) >= 1e-100)
    return arrays(np.float64, (3,), elements=component)


def unit_vectors():
    """Unit vectors: random directions plus the six axis normals (the box's walls)."""
    axis = st.sampled_from([np.eye(3)[k] * s for k in range(3) for s in (1.0, -1.0)])
    rand = vectors(1.0).filter(lambda v: float(v @ v) > 1e-6).map(lambda v: v / np.sqrt(v @ v))
    return st.one_of(axis, rand)


@st.composite
def collisions(draw):
    """(v1, v2, m1, m2, p1, p2): two spheres in contact (|p1 − p2| = 1 up to scale) with any velocities."""
    m1 = draw(masses())
    m2 = draw(masses())
    n = draw(unit_vectors())
    scale = draw(st.sampled_from([1e-3, 1.0, 1e3]))
    p1 = draw(vectors(10.0))
    p2 = p1 - scale * n
    v1 = draw(vectors())
    v2 = draw(vectors())
    return v1, v2, m1, m2, p1, p2


@st.composite
def gas_scenes(draw, max_n=24, periodic=None, equal=False):
    """Keyword arguments of a small, short simulate_gas run: n, radius (scalar or (n,)), mass, boundary, seed."""
    n = draw(st.integers(2, max_n))
    boundary = draw(st.sampled_from(["walls", "periodic"])) if periodic is None else (
        "periodic" if periodic else "walls")
    eta = draw(st.floats(0.01, 0.3))
    from engine.gas import radius_for_packing

    r = radius_for_packing(n, eta, 10.0, boundary)
    if boundary == "periodic":
        r = min(r, 10.0 / 6.0 * 0.999)
    if equal or draw(st.booleans()):
        radius = r
        mass = draw(st.sampled_from([1.0, 0.5, 3.0]))
    else:
        radius = r * draw(arrays(np.float64, (n,), elements=st.floats(0.4, 1.0, **finite)))
        mass = draw(arrays(np.float64, (n,), elements=st.floats(0.1, 10.0, **finite)))
    seed = draw(st.integers(0, 2**16))
    return dict(n=n, radius=radius, mass=mass, boundary=boundary, seed=seed)
