"""Welzl's minimal sphere (engine/bounding/sphere.py) at every scale a float can hold.

Multiplying a cloud by a power of two 2^k is exact in floating point (while the coordinates stay normal numbers),
and the minimal sphere of 2^k p is 2^k times the minimal sphere of p. The engine works on the cloud scaled to
|coordinates| < 1 by a power of two, so the equality is exact, bit for bit, for every k: the centre and the radius
of the scaled cloud are the original ones times 2^k. Without that normalisation the kernels' products of squared
lengths (|u|^2 |v|^2 in the three-point ball) underflow to 0 for tiny clouds and overflow for huge ones, and Welzl's
answer is wrong: measured on 30 random clouds of 20 points per scale, not 2^k times the unit-scale sphere for 24-30
of 30 at every scale from 2^-400 (4e-121) to 2^-220 (6e-67) and from 2^220 (2e66) to 2^480 (3e144), and a radius of
inf for 27-29 of 30 at 2^260 and 2^300. The clouds are on a grid of 1/64 (no coordinate below 2^-6 but 0), so every
scaled coordinate is a normal float for -1000 <= k, the multiplication is exact, and k <= 480 keeps them below the
magnitude 1e150 the engine accepts.
"""
from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from engine.bounding.sphere import min_bounding_sphere


@st.composite
def grid_clouds(draw):
    """(n, d) points with coordinates in {-64000, ..., 64000} / 64, n 1-30, d 2 or 3."""
    d = draw(st.sampled_from([2, 3]))
    n = draw(st.integers(1, 30))
    ints = draw(st.lists(st.integers(-64000, 64000), min_size=n * d, max_size=n * d))
    return np.array(ints, dtype=float).reshape(n, d) / 64.0


@given(grid_clouds(), st.integers(-1000, 480), st.integers(0, 3))
def test_minimal_sphere_scales_exactly_with_a_power_of_two(cloud, k, seed):
    center, radius = min_bounding_sphere(cloud, seed=seed)
    scaled_center, scaled_radius = min_bounding_sphere(np.ldexp(cloud, k), seed=seed)
    assert scaled_radius == np.ldexp(radius, k), (k, radius, scaled_radius)
    assert np.array_equal(scaled_center, np.ldexp(center, k)), (k, center, scaled_center)
