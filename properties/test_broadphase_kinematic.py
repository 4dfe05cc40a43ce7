"""Kinematic culling never drops a pair that collides within the step (exact time of impact), and the first
contact of a translating convex polyhedron lies on a face it keeps."""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from scipy.spatial import ConvexHull

from engine.broadphase import cull_separating_box_pairs, cull_separating_sphere_pairs, front_faces

real = st.floats(-10, 10, allow_nan=False)
vec3 = arrays(np.float64, (3,), elements=real)


def sphere_time_of_impact(p, w, s):
    """Exact first time t >= 0 with |p + w t| = s (p = c_j − c_i, w = v_j − v_i), 0 if already touching,
    inf if never: the smaller root of |w|² t² + 2 (p·w) t + |p|² − s² = 0."""
    c = float(p @ p - s * s)
    if c <= 0.0:
        return 0.0
    a = float(w @ w)
    b = float(p @ w)
    if a == 0.0 or b >= 0.0:
        return math.inf
    disc = b * b - a * c
    if disc < 0.0:
        return math.inf
    return (-b - math.sqrt(disc)) / a


@settings(max_examples=300)
@given(vec3, vec3, vec3, vec3, st.floats(0, 3, allow_nan=False), st.floats(0, 3, allow_nan=False),
       st.floats(0.01, 5.0), st.booleans(), st.floats(0.05, 6.0))
def test_sphere_filter_keeps_every_pair_that_collides_within_the_step(c0, c1, v0, v1, r0, r1, dt, aim, t_meet):
    if aim:  # aim sphere 1 at sphere 0: centres meet at time t_meet
        v1 = v0 + (c0 - c1) / t_meet
    toi = sphere_time_of_impact(c1 - c0, v1 - v0, r0 + r1)
    # stay clear of grazing contacts decided by round-off
    assume(not math.isfinite(toi) or toi == 0.0 or toi < dt * (1 - 1e-9))
    kept = cull_separating_sphere_pairs(np.array([[0, 1]]), np.stack([c0, c1]), np.array([r0, r1]),
                                        np.stack([v0, v1]))
    if toi <= dt:
        assert kept.tolist() == [[0, 1]]
    if kept.size == 0:  # dropped: then the pair never collides at any later time
        assert toi == math.inf


@st.composite
def moving_boxes(draw):
    lo = np.stack([draw(vec3), draw(vec3)])
    hi = lo + np.stack([draw(arrays(np.float64, (3,), elements=st.floats(0, 4))) for _ in range(2)])
    v = np.stack([draw(vec3), draw(vec3)])
    if draw(st.booleans()):  # aim box 1 at box 0 so that their centres meet at time t_meet
        t_meet = draw(st.floats(0.05, 6.0))
        centre = 0.5 * (lo + hi)
        v[1] = v[0] + (centre[0] - centre[1]) / t_meet
    return lo, hi, v


def box_time_of_impact(lo, hi, v):
    """Exact first time t >= 0 at which box 1 (moving with v1 − v0 relative to box 0) touches box 0:
    the intersection over axes of the time intervals during which the projections overlap."""
    w = v[1] - v[0]
    start, end = 0.0, math.inf
    for k in range(3):
        a_lo, a_hi = lo[0, k] - hi[1, k], hi[0, k] - lo[1, k]  # box 1 offset x must stay in [a_lo, a_hi]
        if w[k] == 0.0:
            if not a_lo <= 0.0 <= a_hi:
                return math.inf
            continue
        t1, t2 = sorted(((a_lo - 0.0) / w[k], (a_hi - 0.0) / w[k]))
        start, end = max(start, t1), min(end, t2)
    return start if start <= end else math.inf


@settings(max_examples=300)
@given(moving_boxes(), st.floats(0.01, 5.0))
def test_box_filter_keeps_every_pair_that_collides_within_the_step(scene, dt):
    lo, hi, v = scene
    toi = box_time_of_impact(lo, hi, v)
    kept = cull_separating_box_pairs(np.array([[0, 1]]), lo, hi, v)
    if toi <= dt * (1 - 1e-9):
        assert kept.tolist() == [[0, 1]]
    if kept.size == 0:
        assert toi == math.inf or toi > 1e12


@settings(max_examples=200)
@given(arrays(np.float64, (12, 3), elements=st.floats(-5, 5, allow_nan=False)), vec3)
def test_first_contact_of_a_translating_hull_is_on_a_kept_face(points, v):
    assume(np.linalg.norm(v) > 1e-3)
    try:
        hull = ConvexHull(points)
    except Exception:  # degenerate (flat) point sets
        assume(False)
    assume(hull.volume > 1e-3)
    normals = hull.equations[:, :3]  # outward unit normals
    keep = front_faces(normals, v)
    # moving along v, the hull first touches an obstacle plane {x·v = big} at its support vertex in direction v
    heights = points[hull.vertices] @ v
    top = hull.vertices[np.argmax(heights)]
    assume(np.sort(heights)[-1] - np.sort(heights)[-2] > 1e-6 * (1 + np.abs(heights).max()))
    faces_at_top = np.flatnonzero((hull.simplices == top).any(axis=1))
    assert keep[faces_at_top].any()
    # and every culled face points away from the motion
    assert np.all(normals[~keep] @ v < 0)


def test_filters_drop_separating_pairs():
    c = np.array([[0.0, 0, 0], [3.0, 0, 0], [6.0, 0, 0]])
    v = np.array([[-1.0, 0, 0], [1.0, 0, 0], [0.0, 0, 0]])
    pairs = np.array([[0, 1], [1, 2]])
    # 0 and 1 move apart; 1 runs into 2
    assert cull_separating_sphere_pairs(pairs, c, 1.0, v).tolist() == [[1, 2]]
    assert cull_separating_box_pairs(pairs, c - 1.0, c + 1.0, v).tolist() == [[1, 2]]
    assert front_faces(np.eye(3), np.array([1.0, -1.0, 0.0])).tolist() == [True, False, True]


def test_kinematic_validation():
    with pytest.raises(ValueError, match="velocities"):
        cull_separating_sphere_pairs(np.array([[0, 1]]), np.zeros((2, 3)), 1.0, np.zeros((3, 3)))
    with pytest.raises(ValueError, match="pairs"):
        cull_separating_sphere_pairs(np.array([[0, 5]]), np.zeros((2, 3)), 1.0, np.zeros((2, 3)))
