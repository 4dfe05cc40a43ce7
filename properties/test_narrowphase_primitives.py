"""Primitive narrow tests (sphere, AABB, OBB, segment, capsule, flat and curved ground) against exact answers and
GJK on the same shapes; batched forms equal single calls; bad input raises."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from engine.narrowphase.gjk import gjk_distance
from engine.narrowphase.primitives import (
    distance_point_segment,
    max_on_intervals,
    min_distance_to_curve,
    overlap_aabb_aabb,
    overlap_aabb_aabb_batch,
    overlap_aabb_curve,
    overlap_aabb_curve_bottom_middle,
    overlap_aabb_ground,
    overlap_aabb_ground_batch,
    overlap_circle_curve,
    overlap_circle_segment,
    overlap_circle_segment_batch,
    overlap_sphere_aabb,
    overlap_sphere_aabb_batch,
    overlap_sphere_capsule,
    overlap_sphere_capsule_batch,
    overlap_sphere_ground_batch,
    overlap_sphere_obb,
    overlap_sphere_obb_batch,
    overlap_sphere_sphere,
    overlap_sphere_sphere_batch,
)
from properties.strategies.narrow import aabb_distance, aabbs, box_corners, obbs, sizes, vectors

MARGIN = 1e-9  # cases within this relative distance of tangency are left to round-off


def _away(value, threshold, scale):
    assume(abs(value - threshold) > MARGIN * (1.0 + scale))


@given(vectors, sizes, vectors, sizes)
def test_sphere_sphere_exact(c1, r1, c2, r2):
    d = float(np.linalg.norm(c1 - c2))
    _away(d, r1 + r2, d)
    assert overlap_sphere_sphere(c1, r1, c2, r2) == (d <= r1 + r2)
    assert overlap_sphere_sphere(c1, r1, c1, r2)  # concentric
    assert overlap_sphere_sphere(c1, 0.0, c1, 0.0)  # two coincident points touch


@given(aabbs(), aabbs())
def test_aabb_aabb_exact_and_gjk(a, b):
    exact = aabb_distance(*a, *b)
    expected = bool(np.all(a[0] <= b[1]) and np.all(b[0] <= a[1]))
    assert overlap_aabb_aabb(*a, *b) == expected == (exact == 0.0)
    for d in (1, 2):  # the same test in 1-D and 2-D
        assert overlap_aabb_aabb(a[0][:d], a[1][:d], b[0][:d], b[1][:d]) == bool(
            np.all(a[0][:d] <= b[1][:d]) and np.all(b[0][:d] <= a[1][:d]))
    g, _, _ = gjk_distance(box_corners(*a), box_corners(*b))
    if exact > 1e-9:
        assert not overlap_aabb_aabb(*a, *b) and g > 0


@given(vectors, sizes, aabbs())
def test_sphere_aabb_against_gjk(c, r, box):
    d, _, _ = gjk_distance(c[None], box_corners(*box))
    _away(d, r, 10.0)
    assert overlap_sphere_aabb(c, r, *box) == (d <= r)


@given(vectors, sizes, obbs())
def test_sphere_obb_against_gjk(c, r, box):
    d, _, _ = gjk_distance(c[None], box.corners())
    _away(d, r, 10.0)
    assert overlap_sphere_obb(c, r, box) == (d <= r)


@given(vectors, sizes, vectors, vectors)
def test_circle_segment_and_sphere_capsule_against_gjk(c, r, p0, p1):
    # 3-D: sphere against a capsule of radius r/2 around [p0, p1]
    d, _, _ = gjk_distance(c[None], np.array([p0, p1]))
    assert abs(distance_point_segment(c[None], p0[None], p1[None])[0] - d) <= 1e-9 * (1 + d)
    _away(d, 1.5 * r, 10.0)
    assert overlap_sphere_capsule(c, r, p0, p1, 0.5 * r) == (d <= 1.5 * r)
    # 2-D: the ball and the paddle, in the plane z = 0
    c2, a2, b2 = c[:2], p0[:2], p1[:2]
    d2, _, _ = gjk_distance(np.append(c2, 0.0)[None], np.array([np.append(a2, 0.0), np.append(b2, 0.0)]))
    _away(d2, r, 10.0)
    assert overlap_circle_segment(c2, r, a2, b2) == (d2 <= r)


def test_ball_on_horizontal_paddle():
    paddle = (np.array([-1.0, 0.0]), np.array([1.0, 0.0]))
    assert overlap_circle_segment([0.3, 0.5], 0.5, *paddle)  # resting on it
    assert not overlap_circle_segment([0.3, 0.5 + 1e-9], 0.5, *paddle)
    assert overlap_circle_segment([1.375, 0.5], 0.625, *paddle)  # touching the end (exact in binary)
    assert not overlap_circle_segment([1.375, 0.5 + 1e-9], 0.625, *paddle)


@given(aabbs(), st.floats(-5, 5))
def test_flat_ground(box, a):
    lo, hi = box
    assert overlap_aabb_ground(lo, hi, a) == (not lo[1] > a)
    assert overlap_aabb_ground(lo[:2], hi[:2], a) == (not lo[1] > a)


@given(st.lists(st.tuples(vectors, sizes), min_size=1, max_size=6), st.floats(-5, 5))
def test_sphere_ground_batch(spheres, a):
    c = np.array([s[0] for s in spheres])
    r = np.array([s[1] for s in spheres])
    assert np.array_equal(overlap_sphere_ground_batch(c, r, a), ~(c[:, 1] - r > a))


CURVES = [np.sin, np.cos, lambda x: 0.3 * x * x - 1.0, lambda x: np.sin(3 * x) + 0.2 * x, np.tanh]


def _brute_max(f, lo, hi, n=200_001):
    x = np.linspace(lo, hi, n)
    return f(x).max()


@settings(max_examples=60)
@given(st.sampled_from(range(len(CURVES))), st.floats(-4, 4), st.floats(0.05, 3), st.floats(-2, 2),
       st.floats(0.05, 2))
def test_curved_ground_box(k, x0, width, y0, height):
    f = CURVES[k]
    lo = np.array([[x0, y0]])
    hi = np.array([[x0 + width, y0 + height]])
    exact_max = _brute_max(f, x0, x0 + width)
    assume(abs(exact_max - y0) > 1e-6)
    assert overlap_aabb_curve(lo, hi, f)[0] == (exact_max >= y0)
    _, fmax = max_on_intervals(f, lo[:, 0], hi[:, 0])
    assert fmax[0] >= exact_max - 1e-9
    # the slide's bottom-middle test never finds contact where the exact test finds none
    middle = overlap_aabb_curve_bottom_middle(lo, hi, f)[0]
    assert middle == (f(np.array([x0 + width / 2]))[0] >= y0)
    if middle:
        assert overlap_aabb_curve(lo, hi, f)[0]


@settings(max_examples=60)
@given(st.sampled_from(range(len(CURVES))), st.floats(-4, 4), st.floats(-2, 2), st.floats(0.05, 1.5))
def test_curved_ground_circle(k, cx, cy, r):
    f = CURVES[k]
    x = np.linspace(cx - r, cx + r, 200_001)
    exact = np.sqrt((x - cx) ** 2 + (f(x) - cy) ** 2).min()
    below = f(np.array([cx]))[0] >= cy
    assume(below or abs(exact - r) > 1e-6)
    assert overlap_circle_curve(np.array([[cx, cy]]), r, f)[0] == (below or exact <= r)
    d, _ = min_distance_to_curve(np.array([[cx, cy]]), f, r)
    assert d[0] <= exact + 1e-9


@given(st.lists(st.tuples(vectors, sizes), min_size=1, max_size=5),
       st.lists(st.tuples(vectors, vectors, sizes), min_size=1, max_size=5), st.data())
def test_batches_equal_single_calls(spheres, segments, data):
    c = np.array([s[0] for s in spheres])
    r = np.array([s[1] for s in spheres])
    p0 = np.array([s[0] for s in segments])
    p1 = np.array([s[1] for s in segments])
    rc = np.array([s[2] for s in segments])
    n, m = len(spheres), len(segments)
    k = data.draw(st.integers(1, 8))
    ia = np.array(data.draw(st.lists(st.integers(0, n - 1), min_size=k, max_size=k)))
    ib = np.array(data.draw(st.lists(st.integers(0, m - 1), min_size=k, max_size=k)))
    caps = overlap_sphere_capsule_batch(c, r, p0, p1, rc, ia, ib)
    circ = overlap_circle_segment_batch(c[:, :2], r, p0[:, :2], p1[:, :2], ia, ib)
    sph = overlap_sphere_sphere_batch(c, r, p0, rc, ia, ib)
    lo, hi = np.minimum(p0, p1), np.maximum(p0, p1)
    sab = overlap_sphere_aabb_batch(c, r, lo, hi, ia, ib)
    aab = overlap_aabb_aabb_batch(c - r[:, None], c + r[:, None], lo, hi, ia, ib)
    ident = np.broadcast_to(np.eye(3), (m, 3, 3))
    sob = overlap_sphere_obb_batch(c, r, (lo + hi) / 2, ident, (hi - lo) / 2, ia, ib)
    for p in range(k):
        i, j = ia[p], ib[p]
        assert caps[p] == overlap_sphere_capsule(c[i], r[i], p0[j], p1[j], rc[j])
        assert circ[p] == overlap_circle_segment(c[i, :2], r[i], p0[j, :2], p1[j, :2])
        assert sph[p] == overlap_sphere_sphere(c[i], r[i], p0[j], rc[j])
        assert sab[p] == overlap_sphere_aabb(c[i], r[i], lo[j], hi[j])
        assert aab[p] == overlap_aabb_aabb(c[i] - r[i], c[i] + r[i], lo[j], hi[j])
        assert sob[p] == sab[p]  # an axis-aligned OBB is the AABB
    lo2 = np.minimum(p0, p1)
    alt = np.linspace(-3, 3, m)
    assert np.array_equal(overlap_aabb_ground_batch(lo2, lo2 + 1, alt),
                          [overlap_aabb_ground(lo2[j], lo2[j] + 1, alt[j]) for j in range(m)])


def test_bad_input_raises():
    with pytest.raises(ValueError, match="radius"):
        overlap_sphere_sphere([0, 0, 0], -1.0, [1, 0, 0], 1.0)
    with pytest.raises(ValueError, match=r"radii_b\[1\]"):
        overlap_sphere_sphere_batch(np.zeros((2, 3)), 1.0, np.zeros((2, 3)), [1.0, -2.0])
    with pytest.raises(ValueError, match="finite"):
        overlap_sphere_sphere([np.nan, 0, 0], 1.0, [1, 0, 0], 1.0)
    with pytest.raises(ValueError, match=r"lo_a\[0, 2\]"):
        overlap_aabb_aabb_batch([[0, 0, 2]], [[1, 1, 1]], [[0, 0, 0]], [[1, 1, 1]])
    with pytest.raises(ValueError, match="same length"):
        overlap_sphere_sphere_batch(np.zeros((2, 3)), 1.0, np.zeros((3, 3)), 1.0)
    with pytest.raises(ValueError, match="orthonormal"):
        overlap_sphere_obb_batch(np.zeros((1, 3)), 1.0, np.zeros((1, 3)), np.ones((1, 3, 3)), np.ones((1, 3)))
    with pytest.raises(ValueError, match="finite"):
        overlap_aabb_ground([0, np.inf], [1, 1], 0.0)
    with pytest.raises(ValueError, match="non-finite"):
        overlap_aabb_curve(np.array([[0.0, 0.0]]), np.array([[1.0, 1.0]]), lambda x: np.log(x - 0.5))
    with pytest.raises(TypeError):
        overlap_aabb_curve(np.array([[0.0, 0.0]]), np.array([[1.0, 1.0]]), 3.0)
    with pytest.raises(ValueError, match="vectorised"):
        overlap_aabb_curve_bottom_middle(np.zeros((2, 2)), np.ones((2, 2)), lambda x: np.zeros(3))
