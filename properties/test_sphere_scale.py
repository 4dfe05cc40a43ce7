"""The bounding spheres (engine/bounding/sphere.py: Welzl's minimal sphere, Ritter's sphere, one cloud or a batch)
at every scale a float can hold.

Multiplying a cloud by a power of two 2^k is exact in floating point (while the coordinates stay normal numbers),
and the minimal sphere of 2^k p is 2^k times the minimal sphere of p; Ritter's construction commutes with the
scaling too (its comparisons and its arithmetic are homogeneous). The engine works on the cloud scaled to
|coordinates| < 1 by a power of two, so the equality is exact, bit for bit, for every k: the centre and the radius
of the scaled cloud are the original ones times 2^k. Without that normalisation the kernels' products of squared
lengths (|u|^2 |v|^2 in the three-point ball) underflow to 0 for tiny clouds and overflow for huge ones, and Welzl's
answer is wrong: measured on 30 random clouds of 20 points per scale, not 2^k times the unit-scale sphere for 24-30
of 30 at every scale from 2^-400 (4e-121) to 2^-220 (6e-67) and from 2^220 (2e66) to 2^480 (3e144), and a radius of
inf for 27-29 of 30 at 2^260 and 2^300. The clouds are on a grid of 1/64 (no coordinate below 2^-6 but 0), so every
scaled coordinate is a normal float for -1000 <= k, the multiplication is exact, and k <= 480 keeps them below the
magnitude 1e150 the engine accepts. Ritter's sphere had the same defect (squared distances underflow to 0): a
radius of 0 for clouds spread over less than ~1e-154, and points outside the sphere (by 4e-6 of the radius) at
1e-160; found by test_summaries_are_json_ready_and_agree_with_the_fits.
"""
from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from engine.bounding.sphere import min_bounding_sphere, ritter_sphere, ritter_spheres


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


@given(grid_clouds(), st.integers(-1000, 480))
def test_ritter_sphere_scales_exactly_with_a_power_of_two(cloud, k):
    center, radius = ritter_sphere(cloud)
    scaled_center, scaled_radius = ritter_sphere(np.ldexp(cloud, k))
    assert scaled_radius == np.ldexp(radius, k), (k, radius, scaled_radius)
    assert np.array_equal(scaled_center, np.ldexp(center, k)), (k, center, scaled_center)


@given(grid_clouds(), st.lists(st.integers(-1000, 480), min_size=1, max_size=4))
def test_batched_ritter_spheres_scale_each_cloud_on_its_own(cloud, ks):
    """One batch holding the cloud at several scales: each sphere is the single-cloud one at its scale."""
    centers, radii = ritter_spheres(np.stack([np.ldexp(cloud, k) for k in ks]))
    center, radius = ritter_sphere(cloud)
    for i, k in enumerate(ks):
        assert radii[i] == np.ldexp(radius, k), (k, radius, radii[i])
        assert np.array_equal(centers[i], np.ldexp(center, k)), (k, center, centers[i])
