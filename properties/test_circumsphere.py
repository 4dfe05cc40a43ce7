"""``circumsphere`` (engine/bounding/sphere.py): the smallest sphere through 2, 3 or 4 points, the balls Welzl's
algorithm is built from.

Oracles: points in general position are all on the boundary (|x - c| = r) with the centre in their affine hull;
for degenerate points (collinear triples, coplanar quadruples, any four points of the plane) the answer is the
smallest sphere holding them, the brute force of properties.test_bounding_fits (every 1- to 4-point support).
The radius is always the distance from the centre to the farthest point, in every order of the points: a radius
measured on three of four points is caught on tetrahedra flat enough (volume ~1e-8 of |u||v||w|) that the four
computed distances differ in their eighth digit. A triangle with two corners 1e-7 to 5e-6 of its size apart (and
45 degrees between its short and long sides) still has a circumcircle, of radius |long side| / sqrt(2): a
collinearity threshold that is not relative to both edge lengths would take it for a flat triangle.
"""
from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from engine.bounding.sphere import circumsphere
from properties.strategies.geometry import seeds
from properties.test_bounding_fits import brute_force_min_sphere

scales = st.sampled_from([1.0, 1e-3, 1e3, 1e-40, 1e40])
shifts = st.sampled_from([0.0, 1.0, -7.5, 1e3])


def _size(pts) -> float:
    return float(np.ptp(pts, axis=0).max())


def _random_frame(rng, d):
    frame, _ = np.linalg.qr(rng.normal(size=(d, d)))
    return frame


@st.composite
def simplices(draw):
    """k = 2 to d + 1 points of d = 2 or 3 dimensions in general position: the edges from the first point have
    a smallest singular value >= 0.05 of their largest (no near-collinear or near-coplanar set)."""
    d = draw(st.sampled_from([2, 3]))
    k = draw(st.integers(2, d + 1))
    rng = np.random.default_rng(draw(seeds))
    while True:
        pts = rng.normal(size=(k, d))
        sv = np.linalg.svd(pts[1:] - pts[0], compute_uv=False)
        if sv[-1] >= 0.05 * sv[0]:
            break
    scale = draw(scales)
    return pts * scale + draw(shifts) * scale


@given(simplices())
def test_points_in_general_position_are_all_on_the_boundary(pts):
    center, radius = circumsphere(pts)
    assert center.shape == (pts.shape[1],) and np.isfinite(center).all()
    dist = np.linalg.norm(pts - center, axis=1)
    np.testing.assert_allclose(dist, radius, rtol=1e-9)
    # the centre is in the points' affine hull: c - p0 is a combination of the edges
    edges = pts[1:] - pts[0]
    coef, *_ = np.linalg.lstsq(edges.T, center - pts[0], rcond=None)
    assert np.linalg.norm(edges.T @ coef - (center - pts[0])) <= 1e-9 * radius


@st.composite
def degenerate_sets(draw):
    """Points with no sphere through them all: 3 collinear, 4 coplanar (in 3-D, in a random plane), 4 of the
    plane; four of the plane drawn on a small integer grid too (duplicates, collinear and cocircular sets, ties),
    scaled and moved."""
    rng = np.random.default_rng(draw(seeds))
    kind = draw(st.sampled_from(["collinear", "coplanar", "planar4", "grid"]))
    d = draw(st.sampled_from([2, 3]))
    if kind == "collinear":  # exactly, in floats: a + t u on a grid of 1/64, at any power-of-two scale
        start, step = rng.integers(-8, 9, size=(2, d)) / 8.0
        pts = start + np.outer(rng.integers(-8, 9, size=3), step)
    elif kind == "coplanar" or (kind == "planar4" and d == 3):
        pts = rng.normal(size=(4, 2))
        pts = pts @ _random_frame(rng, 3)[:2] if d == 3 else pts
    elif kind == "planar4":
        pts = rng.normal(size=(4, 2))
    else:
        pts = np.zeros((4, d))
        pts[:, :2] = rng.integers(-2, 3, size=(4, 2))
        if d == 3:
            pts = pts @ _random_frame(rng, 3)
    # powers of two and shifts a few times the size: the sets stay degenerate to far below the engine's
    # flatness thresholds (a collinear set spread over 0.02 at 1000 is a triangle of angle ~3e-10 in floats)
    scale = draw(st.sampled_from([1.0, 2.0**-10, 2.0**10, 2.0**-130, 2.0**130]))
    return pts * scale + draw(st.sampled_from([0.0, 1.0, -7.5])) * scale


@given(degenerate_sets())
def test_degenerate_points_get_the_smallest_sphere_holding_them(pts):
    center, radius = circumsphere(pts)
    c_ref, r_ref = brute_force_min_sphere(pts)
    scale = float(np.abs(pts).max()) + _size(pts)
    assert radius == pytest.approx(r_ref, rel=1e-7, abs=1e-9 * scale)
    assert np.linalg.norm(center - c_ref) <= 1e-5 * scale
    # the kernels work relative to the centroid: moving back rounds each coordinate by an ulp of |x|
    assert (np.linalg.norm(pts - center, axis=1) <= radius * (1 + 1e-13) + 1e-15 * scale).all()


@st.composite
def flat_tetrahedra(draw):
    """Four points in 3-D, the fourth at a height of 1e-8 to 1e-7 of the triangle's size above its plane:
    a circumsphere exists (the engine's flatness threshold is 1e-10), computed to ~1e-8 only."""
    rng = np.random.default_rng(draw(seeds))
    tri = rng.normal(size=(3, 2))
    apex = tri.mean(axis=0) + rng.normal(size=2) * 0.3
    height = rng.uniform(1e-8, 1e-7) * _size(tri)
    pts = np.column_stack([np.vstack([tri, apex]), [0.0, 0.0, 0.0, height]]) @ _random_frame(rng, 3)
    return pts * draw(scales)


@given(flat_tetrahedra())
def test_the_radius_reaches_the_farthest_point_in_every_order(pts):
    for order in itertools.permutations(range(4)):
        center, radius = circumsphere(pts[list(order)])
        farthest = np.linalg.norm(pts - center, axis=1).max()
        assert radius == pytest.approx(farthest, rel=1e-13), order


@st.composite
def triangles_with_a_nearly_doubled_corner(draw):
    """(p, a, b): b at distance L from p, a at a distance delta = 1e-7 L to 5e-6 L from p, 45 degrees off pb."""
    rng = np.random.default_rng(draw(seeds))
    d = draw(st.sampled_from([2, 3]))
    frame = _random_frame(rng, d)
    length = rng.uniform(0.5, 2.0)
    delta = rng.uniform(1e-7, 5e-6) * length
    p = rng.normal(size=d)
    b = p + length * frame[0]
    a = p + delta * (frame[0] + frame[1]) / np.sqrt(2.0)
    return np.array([p, a, b]), length


@given(triangles_with_a_nearly_doubled_corner(), scales)
def test_a_nearly_doubled_corner_still_gives_the_circumcircle(case, scale):
    pts, length = case
    pts, length = pts * scale, length * scale
    for order in itertools.permutations(range(3)):
        center, radius = circumsphere(pts[list(order)])
        # the angle at a tends to 135 degrees: 2 R = L / sin(135) = sqrt(2) L, to O(delta / L)
        assert radius == pytest.approx(length / np.sqrt(2.0), rel=1e-5), order
        np.testing.assert_allclose(np.linalg.norm(pts - center, axis=1), radius, rtol=1e-8)


@pytest.mark.parametrize("points", [[[0.0, 0.0]], np.zeros((5, 3)), np.zeros((3, 4)), np.zeros((2, 1))])
def test_a_count_or_dimension_out_of_range_is_refused(points):
    with pytest.raises(ValueError, match="points"):
        circumsphere(points)
