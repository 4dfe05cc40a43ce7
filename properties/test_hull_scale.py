"""The convex hull (engine/bounding/hull.py) at every scale a float can hold.

Scaling points by a power of two 2^k is exact while they stay normal floats, and the hull of 2^k p is 2^k times
the hull of p. The engine builds the hull of the points scaled to |coordinates| < 1 by a power of two, so the
answer is exact for every k: the same vertices, faces and normals, and the offsets, area and volume scaled by
2^k, 2^(k(d-1)), 2^(kd) (inf when beyond the float range, as the scaled value is); points that have no hull (all
collinear, coplanar in 3-D) are refused at every scale alike. Without that scaling the cross products and squared
lengths of quickhull under- and overflow: a random 30-point cloud in general position was refused as "coplanar"
at 2^-400 and 2^300 and as "all points coincide" at 2^-600 (2-D hulls likewise lose their areas below ~1e-154).
The clouds are on a grid of 1/64 with coordinates up to 1000, so every scaled coordinate is a normal float for
k >= -1000 and k <= 480 keeps them below the magnitude 1e150 the engine accepts.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from engine.bounding.hull import convex_hull


@st.composite
def grid_clouds(draw):
    """(n, d) points with coordinates in {-64000, ..., 64000} / 64, n d+1 to 30, d 2 or 3 (some degenerate)."""
    d = draw(st.sampled_from([2, 3]))
    n = draw(st.integers(d + 1, 30))
    ints = draw(st.lists(st.integers(-64000, 64000), min_size=n * d, max_size=n * d))
    return np.array(ints, dtype=float).reshape(n, d) / 64.0


def _hull_or_refusal(points):
    try:
        return convex_hull(points)
    except ValueError as exc:
        return str(exc)


@given(grid_clouds(), st.integers(-1000, 480))
def test_the_hull_scales_exactly_with_a_power_of_two(cloud, k):
    hull = _hull_or_refusal(cloud)
    scaled = _hull_or_refusal(np.ldexp(cloud, k))
    if isinstance(hull, str):
        assert scaled == hull, (k, hull, scaled)
        return
    assert not isinstance(scaled, str), (k, scaled)
    d = cloud.shape[1]
    assert np.array_equal(scaled.vertices, hull.vertices) and np.array_equal(scaled.faces, hull.faces)
    assert np.array_equal(scaled.normals, hull.normals)
    assert np.array_equal(scaled.offsets, np.ldexp(hull.offsets, k)), k
    with np.errstate(over="ignore"):
        assert scaled.volume == np.ldexp(hull.volume, d * k), (k, hull.volume, scaled.volume)
        assert scaled.area == np.ldexp(hull.area, (d - 1) * k), (k, hull.area, scaled.area)


@pytest.mark.parametrize("k", [-600, -400, 300])
def test_a_cloud_in_general_position_has_a_hull_far_from_unit_scale(k):
    """The three scales where the unscaled quickhull refused this cloud."""
    cloud = np.random.default_rng(0).normal(size=(30, 3))
    hull, unit = convex_hull(np.ldexp(cloud, k)), convex_hull(cloud)
    assert np.array_equal(hull.vertices, unit.vertices) and np.array_equal(hull.faces, unit.faces)
