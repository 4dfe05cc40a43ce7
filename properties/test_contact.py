"""Contact features, contact points, time of impact and the ``collide contact`` JSON answer."""
from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st

from engine.contact_io import describe_contact, load_shape
from engine.narrowphase.contact_manifold import contact_feature
from engine.narrowphase.gjk import gjk_distance, pack_point_sets
from engine.narrowphase.penetration import epa_penetration
from engine.narrowphase.time_of_impact import time_of_impact, time_of_impact_pairs
from properties.strategies.narrow import (
    aabbs,
    box_corners,
    edge_edge_obb_pairs,
    hull_signed_distance,
    point_clouds,
    rotations,
    sizes,
    vectors,
)

CUBE = box_corners(np.array([-1.0, -1, -1]), np.array([1.0, 1, 1]))


# --- where ----------------------------------------------------------------------------------------------------

@settings(max_examples=80)
@given(point_clouds(), point_clouds(spread=5.0))
def test_separation_and_points_consistent_with_gjk_epa(a, b):
    contact = contact_feature(a, b)
    d, _, _ = gjk_distance(a, b)
    scale = max(np.ptp(np.concatenate([a, b]), axis=0).max(), 1.0)
    if d > 0:
        assert abs(contact.separation - d) <= 1e-12 * scale
    else:
        assert abs(contact.separation + epa_penetration(a, b)[0]) <= 1e-12 * scale
    assert abs(np.linalg.norm(contact.normal) - 1.0) <= 1e-12
    assert contact.kind == f"{contact.feature_a}-{contact.feature_b}"
    assert contact.points.shape[0] >= 1 and np.isfinite(contact.points).all()
    # every contact point lies between the two support planes, within the slab's half-width of each shape
    half = abs(contact.separation) / 2 + 1e-7 * scale
    for p in contact.points:
        assert abs(p @ contact.normal - ((a @ contact.normal).max() + (b @ contact.normal).min()) / 2) \
            <= 1e-9 * scale
        # ... and its projection lies in both features' shadows: within `half` of both hulls, up to the slab
        pa = p - half * contact.normal
        pb = p + half * contact.normal
        assert hull_signed_distance(a, pa) <= 2 * half + 1e-6 * scale or np.linalg.matrix_rank(a - a[0]) < 3
        assert hull_signed_distance(b, pb) <= 2 * half + 1e-6 * scale or np.linalg.matrix_rank(b - b[0]) < 3


@given(aabbs(), aabbs(), st.integers(0, 2), st.floats(0.01, 2.0), st.floats(0, 1), st.floats(0, 1))
def test_stacked_boxes_face_face_exact_patch(box_a, box_b, axis, gap, fu, fv):
    """Two axis-aligned boxes, B above A along `axis` with an overlapping footprint: face–face, and the contact
    points are the corners of the exact rectangle where the footprints overlap."""
    lo_a, hi_a = box_a
    size_b = box_b[1] - box_b[0]
    others = [k for k in range(3) if k != axis]
    lo_b = lo_a.copy()
    # B's footprint starts inside A's (so they overlap by a positive area on the other two axes)
    for k, f in zip(others, (fu, fv)):
        lo_b[k] = lo_a[k] + f * 0.9 * (hi_a[k] - lo_a[k]) - 0.5 * size_b[k]
    lo_b[axis] = hi_a[axis] + gap
    hi_b = lo_b + size_b
    contact = contact_feature(box_corners(lo_a, hi_a), box_corners(lo_b, hi_b))
    assert contact.kind == "face-face"
    assert abs(contact.separation - gap) <= 1e-9
    expected = np.zeros(3)
    expected[axis] = 1.0
    # GJK's closest points carry ~1e-12 relative round-off, which tilts the normal by that over the gap
    assert np.allclose(contact.normal, expected, atol=1e-9)
    lo_patch = np.maximum(lo_a, lo_b)[others]
    hi_patch = np.minimum(hi_a, hi_b)[others]
    assume((hi_patch - lo_patch).min() > 1e-6)
    corners = np.array([[x, y] for x in (lo_patch[0], hi_patch[0]) for y in (lo_patch[1], hi_patch[1])])
    got = contact.points[:, others]
    assert got.shape == (4, 2)
    # the same four corners, in some order
    assert all(np.abs(got - c).max(axis=1).min() <= 1e-9 for c in corners)
    assert all(np.abs(corners - g).max(axis=1).min() <= 1e-9 for g in got)
    assert np.allclose(contact.points[:, axis], hi_a[axis] + gap / 2, atol=1e-9)


@settings(max_examples=60)
@given(edge_edge_obb_pairs())
def test_crossing_edges_are_edge_edge(pair):
    a, b = pair
    contact = contact_feature(a.corners(), b.corners())
    assume(contact.separation > 1e-6)
    assert contact.kind == "edge-edge" and contact.points.shape == (1, 3)
    # the contact point is the midpoint of GJK's closest points
    assert np.allclose(contact.points[0], 0.5 * (contact.closest_a + contact.closest_b), atol=1e-9)


def test_named_features():
    from scipy.spatial.transform import Rotation

    def kind(a, b):
        return contact_feature(a, b).kind

    assert kind(CUBE, CUBE + [0, 0, 3]) == "face-face"
    r45x = Rotation.from_euler("x", 45, degrees=True).as_matrix()
    assert kind(CUBE, CUBE @ r45x.T + [0, 0, 3]) == "face-edge"
    tip = CUBE @ Rotation.from_euler("xy", [45, 35.26438968], degrees=True).as_matrix().T
    assert kind(CUBE, tip - [0, 0, tip[:, 2].min()] + [0.2, 0.1, 1.5]) == "face-vertex"
    rb = Rotation.from_euler("y", 45, degrees=True).as_matrix()
    edge_edge = contact_feature(CUBE @ r45x.T, CUBE @ rb.T + [0, 0, 3.5])
    assert edge_edge.kind == "edge-edge" and edge_edge.points.shape == (1, 3)
    assert np.allclose(edge_edge.points[0], [0, 0, 1.75], atol=1e-9)
    sphere = contact_feature(np.zeros((1, 3)), CUBE + [0, 0, 3], radius_a=1.0)
    assert sphere.kind == "sphere-face" and abs(sphere.separation - 1.0) <= 1e-12
    assert np.allclose(sphere.points, [[0, 0, 1.5]])


# --- when -----------------------------------------------------------------------------------------------------

def _closest_gap_over(lo_a, hi_a, lo_b, hi_b, velocity, t_max):
    """Least distance between box A and box B + velocity·t over t in [0, t_max] (a convex function of t: golden
    section search)."""
    def gap(t):
        lb, hb = lo_b + velocity * t, hi_b + velocity * t
        return np.linalg.norm(np.maximum(0.0, np.maximum(lb - hi_a, lo_a - hb)))

    a, b = 0.0, t_max
    g = (np.sqrt(5.0) - 1.0) / 2.0
    for _ in range(200):
        c, d = b - g * (b - a), a + g * (b - a)
        if gap(c) <= gap(d):
            b = d
        else:
            a = c
    return min(gap(0.0), gap(t_max), gap(0.5 * (a + b)))


@given(aabbs(), aabbs(spread=6.0), vectors)
def test_toi_axis_aligned_boxes_exact(box_a, box_b, velocity):
    """Translating axis-aligned boxes: the exact first time the three interval pairs overlap at once."""
    assume(np.linalg.norm(velocity) > 1e-3)
    lo_a, hi_a = box_a
    lo_b, hi_b = box_b
    # B moves with `velocity` relative to A: on each axis the intervals overlap for t in [t_in, t_out]
    t_in, t_out = 0.0, np.inf
    for k in range(3):
        v = velocity[k]
        if v == 0.0:
            if hi_b[k] < lo_a[k] or hi_a[k] < lo_b[k]:
                t_in, t_out = np.inf, -np.inf
            continue
        t1 = (lo_a[k] - hi_b[k]) / v
        t2 = (hi_a[k] - lo_b[k]) / v
        t_in = max(t_in, min(t1, t2))
        t_out = min(t_out, max(t1, t2))
    t_max = 2.0
    exact = t_in if t_in <= t_out and t_in <= t_max else None
    if exact is not None:
        assume(exact < t_max - 1e-6 and t_out - t_in > 1e-6)
    else:
        assume(t_in > t_max + 1e-6 or t_out < t_in - 1e-6)
        # time_of_impact answers to within its distance tolerance (1e-9 × the size): a pair that passes closer
        # than that (a tiny velocity along an axis where the boxes touch keeps them 1e-100 apart for a while)
        # is a contact for it, so the "never" cases must also stay apart in space, not only in time
        assume(_closest_gap_over(lo_a, hi_a, lo_b, hi_b, velocity, t_max) > 1e-6)
    t = time_of_impact(box_corners(lo_a, hi_a), np.zeros(3), box_corners(lo_b, hi_b), velocity, t_max=t_max)
    if exact is None:
        assert t is None
    else:
        assert t is not None and abs(t - exact) <= 1e-6 * (1 + exact)


def test_toi_counts_a_pass_closer_than_its_tolerance_as_contact():
    """Boxes touching along x while B slides away at 1.45e-102 per second: when the z intervals meet (t = 0.5)
    they are 7e-103 apart, far below the 1e-9 distance tolerance: time_of_impact reports that contact (the exact
    interval oracle says "never": this is why its "never" cases must stay apart in space)."""
    lo_a, hi_a = np.array([0.0, 0.0, 1.0]), np.array([1.0, 1.0, 2.0])
    lo_b, hi_b = np.array([1.0, 0.0, 0.0]), np.array([2.0, 1.0, 0.5])
    velocity = np.array([1.45479815e-102, 0.0, 1.0])
    t = time_of_impact(box_corners(lo_a, hi_a), np.zeros(3), box_corners(lo_b, hi_b), velocity, t_max=2.0)
    assert t is not None and abs(t - 0.5) <= 1e-8
    lb, hb = lo_b + velocity * t, hi_b + velocity * t
    assert np.linalg.norm(np.maximum(0.0, np.maximum(lb - hi_a, lo_a - hb))) <= 1e-9


@given(vectors, vectors, sizes, sizes, vectors, vectors)
def test_toi_spheres_exact(c1, c2, r1, r2, v1, v2):
    """Two moving spheres: the smallest root of |Δc + Δv t| = r1 + r2."""
    dc = c2 - c1
    dv = v2 - v1
    s = r1 + r2
    assume(np.linalg.norm(dc) > s + 1e-3)
    qa, qb, qc = dv @ dv, 2 * dc @ dv, dc @ dc - s * s
    disc = qb * qb - 4 * qa * qc
    exact = None
    if qa > 0 and disc > 0:
        root = (-qb - np.sqrt(disc)) / (2 * qa)
        if 0 <= root <= 1.0:
            exact = root
    if exact is None:
        assume(disc < -1e-6 or qa == 0 or (-qb - np.sqrt(max(disc, 0))) / (2 * qa) > 1.0 + 1e-6
               or (-qb - np.sqrt(max(disc, 0))) / (2 * qa) < 0)
    else:
        assume(disc > 1e-6 and exact < 1.0 - 1e-6)
    t = time_of_impact(c1[None], v1, c2[None], v2, t_max=1.0, radius_a=r1, radius_b=r2, tol=1e-10)
    if exact is None:
        assert t is None
    else:
        assert t is not None and abs(t - exact) <= 1e-6 * (1 + exact)


@settings(max_examples=60)
@given(point_clouds(), point_clouds(spread=8.0), vectors, vectors, vectors)
def test_toi_conservative_for_moving_spinning_hulls(a, b, va, vb, wb):
    """At the returned time the shapes are (within tolerance) in contact, and at sampled earlier times apart."""
    assume(gjk_distance(a, b)[0] > 1e-3)
    wb = 0.3 * wb
    tol = 1e-9 * max(np.ptp(a, axis=0).max(), np.ptp(b, axis=0).max())
    t = time_of_impact(a, va, b, vb, t_max=1.0, angular_velocity_b=wb, max_iterations=5000)

    def at(points, v, w, tt):
        c = points.mean(axis=0)
        theta = np.linalg.norm(w) * tt
        if theta == 0:
            rot = np.eye(3)
        else:
            k = w / np.linalg.norm(w)
            kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
            rot = np.eye(3) + np.sin(theta) * kx + (1 - np.cos(theta)) * kx @ kx
        return c + v * tt + (points - c) @ rot.T

    end = 1.0 if t is None else t
    for s in np.linspace(0.0, end, 9)[:-1]:
        assert gjk_distance(at(a, va, np.zeros(3), s), at(b, vb, wb, s))[0] > 0.0
    if t is not None:
        assert gjk_distance(at(a, va, np.zeros(3), t), at(b, vb, wb, t))[0] <= 2 * tol


@settings(max_examples=30)
@given(st.lists(point_clouds(spread=6.0), min_size=2, max_size=5), st.data())
def test_toi_pairs_equal_single(clouds, data):
    k = len(clouds)
    vel = np.array([data.draw(vectors) for _ in range(k)])
    points, offsets = pack_point_sets(clouds)
    pairs = np.array([[i, j] for i in range(k) for j in range(i + 1, k)])
    centers = np.array([c.mean(axis=0) for c in clouds])
    times = time_of_impact_pairs(points, offsets, vel, pairs, centers=centers, max_iterations=5000)
    for p, (i, j) in enumerate(pairs):
        t = time_of_impact(clouds[i], vel[i], clouds[j], vel[j], center_a=centers[i], center_b=centers[j],
                           tol=1e-9, max_iterations=5000)
        assert (t is None and times[p] == np.inf) or t == times[p]


def test_toi_rotation_only_and_misses():
    # a box spinning in place next to another: its corner sweeps a circle of radius sqrt(2)
    b = CUBE + [0.0, 0.0, 0.0]
    a = CUBE * [1, 1, 1] + [2.0 + 0.2, 0.0, 0.0]
    t = time_of_impact(b, np.zeros(3), a, np.zeros(3), angular_velocity_a=[0, 0, 0], angular_velocity_b=[0, 0, 0])
    assert t is None
    t = time_of_impact(b, np.zeros(3), a, np.zeros(3), angular_velocity_a=[0, 0, 1.0], t_max=2.0)
    # corner of B at angle 45° + θ reaches x = 1.2: sqrt(2) cos(π/4 − θ) = 1.2
    exact = np.pi / 4 - np.arccos(1.2 / np.sqrt(2))
    assert t is not None and abs(t - exact) <= 1e-6


def test_bad_input_raises():
    with pytest.raises(ValueError):
        contact_feature(np.zeros((0, 3)), CUBE)
    with pytest.raises(ValueError, match="radius_a"):
        contact_feature(CUBE, CUBE, radius_a=-1.0)
    with pytest.raises(ValueError, match="velocity_a"):
        time_of_impact(CUBE, [np.nan, 0, 0], CUBE + 5, [0, 0, 0])
    with pytest.raises(ValueError, match="t_max"):
        time_of_impact(CUBE, [0, 0, 0], CUBE + 5, [0, 0, 0], t_max=-1.0)
    # the velocities are required: None is refused naming the argument (it was once read as zero velocity)
    with pytest.raises(TypeError, match="velocity_a"):
        time_of_impact(CUBE, None, CUBE + 5, [0, 0, 0])
    with pytest.raises(TypeError, match="velocity_b"):
        time_of_impact(CUBE, [0, 0, 0], CUBE + 5, None)


# --- collide contact A.json B.json ----------------------------------------------------------------------------

@settings(max_examples=20)
@given(rotations(), st.floats(2.5, 6.0), st.floats(0.5, 3.0))
# B tilted by 1e-9 lands at distance 5.7e-10 (GJK's tolerance): the normal along the closest points was tilted by
# 5e-7 and made a vertex-edge contact at A's corner (-1, -1, 1), outside B's footprint
@example(rot=np.array([[1.0, 0.0, 0.0], [0.0, 1.0, -1e-9], [0.0, 1e-9, 1.0]]), height=2.5, speed=1.0)
def test_describe_contact_box_falling_on_box(tmp_path_factory, rot, height, speed):
    tmp = tmp_path_factory.mktemp("contact")
    a = {"shape": "box", "center": [0, 0, 0], "half_extents": [1, 1, 1]}
    b = {"shape": "box", "center": [0.1, -0.2, height], "half_extents": [0.5, 0.5, 0.5],
         "rotation": rot.tolist(), "velocity": [0, 0, -speed]}
    (tmp / "a.json").write_text(json.dumps(a))
    (tmp / "b.json").write_text(json.dumps(b))
    text = describe_contact(tmp / "a.json", tmp / "b.json", t_max=100.0)
    spec_b = load_shape(b)
    lowest = spec_b.core[:, 2].min()
    exact = (lowest - 1.0) / speed
    assert "time of impact" in text
    t = float(text.split("time of impact: t = ")[1].split()[0])
    assert abs(t - exact) <= 1e-6 * (1 + exact)
    # B's lowest feature lands inside A's top face
    assert text.split("contact at t: ")[1].startswith("face-")


def test_describe_contact_examples(tmp_path):
    a = {"shape": "box", "center": [0, 0, 0], "half_extents": [1, 1, 1]}
    s = {"shape": "sphere", "center": [0.5, 0, 4], "radius": 0.5, "velocity": [0, 0, -1]}
    cap = {"shape": "capsule", "center": [0, 0, 3], "radius": 0.25, "half_height": 1.0,
           "rotation": [0.7071067811865476, 0, 0, 0.7071067811865476], "velocity": [0, 0, -1]}
    hull = {"shape": "convex", "points": (CUBE * 0.5).tolist(), "center": [0, 0, 0.5]}
    for name, spec in {"a": a, "s": s, "cap": cap, "hull": hull}.items():
        (tmp_path / f"{name}.json").write_text(json.dumps(spec))
    text = describe_contact(tmp_path / "a.json", tmp_path / "s.json")
    assert "time of impact: t = 2.5" in text and "face-sphere" in text and "(0.5, 0, 1)" in text
    text = describe_contact(tmp_path / "a.json", tmp_path / "cap.json")
    assert "time of impact: t = 1.75" in text and "face-cylinder" in text
    text = describe_contact(tmp_path / "a.json", tmp_path / "hull.json")
    assert "overlapping" in text and "penetration depth 1" in text
    (tmp_path / "bad.json").write_text(json.dumps({"shape": "box", "center": [0, 0, 0]}))
    with pytest.raises(ValueError, match="half_extents"):
        describe_contact(tmp_path / "a.json", tmp_path / "bad.json")
    (tmp_path / "bad2.json").write_text(json.dumps({"shape": "cone"}))
    with pytest.raises(ValueError, match="shape"):
        describe_contact(tmp_path / "a.json", tmp_path / "bad2.json")
    (tmp_path / "bad3.json").write_text("{not json")
    with pytest.raises(ValueError, match="JSON"):
        describe_contact(tmp_path / "a.json", tmp_path / "bad3.json")
