"""Convex hulls nearly face to face keep the face (engine/narrowphase/contact_manifold.py, ``face_contact``), by
the rule of box–box (``box_box.prefer_face``).

The penetration solver's normal between two nearly flush hulls is often an edge–edge direction between the two
face normals (its overlap is the least), and the support sets within ``FEATURE_TOL`` of that direction are one
vertex or one edge: one contact point where the hulls really touch over a polygon. The properties:

- nearly flush hull pairs (cubes, boxes, random convex prisms; face normals within 1e-3 rad; scales 1e-3 to 1e3),
  every corner of the overlap below the other face: a face manifold ("face-face", at least 3 points), every
  point inside both hulls grown by the depth (+ round-off);
- the depth and normal are the penetration chain's (``epa_penetration``), bit for bit, and depth · normal
  separates the pair: only the points (and the feature names) come from the face;
- MuJoCo's multi-contact case (two 0.1 cubes, corners of the overlap 5.96e-4 to 6.04e-4 deep): 4 points;
- crossed edges at 45° stay one edge–edge point;
- a hull that is a box gives box–box's point count (after the World's reduction to ``MAX_POINTS``) on nearly
  flush boxes.
"""
from __future__ import annotations

import itertools

import numpy as np
from hypothesis import given
from hypothesis import strategies as st
from scipy.spatial import ConvexHull
from scipy.spatial.transform import Rotation

from engine import contact_feature
from engine.narrowphase.box_box import contact_box_box_pair
from engine.narrowphase.contacts import MAX_POINTS
from engine.narrowphase.penetration import epa_penetration

U = np.finfo(float).eps
CORNERS = np.array(list(itertools.product((-1.0, 1.0), repeat=3)))

rotations = st.integers(0, 2**32 - 1).map(lambda s: Rotation.random(random_state=s).as_matrix())
unit_vectors = st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1)).filter(
    lambda v: 0.1 < np.linalg.norm(v) <= 1.0).map(lambda v: np.array(v) / np.linalg.norm(v))
halves = st.tuples(st.floats(0.2, 1.0), st.floats(0.2, 1.0), st.floats(0.2, 1.0)).map(np.array)
scales = st.floats(-3.0, 3.0).map(lambda e: 10.0 ** e)
tilts = st.floats(0.0, 1e-3)


def outside(points, hull_points):
    """How far each row of ``points`` lies outside the hull of ``hull_points`` (<= 0 inside): the largest signed
    distance to a face plane (Qhull's unit normals)."""
    eq = ConvexHull(hull_points).equations
    return (points @ eq[:, :3].T + eq[:, 3]).max(axis=1)


def check_flush_contact(pa, pb, c):
    """A face manifold, every point inside both hulls grown by the depth, the depth and normal of the
    penetration chain bit for bit, and depth · normal separating the pair."""
    size = max(np.abs(pa).max(), np.abs(pb).max())
    depth, normal = epa_penetration(pa, pb)
    assert c.separation == -depth and np.array_equal(c.normal, normal), (c.separation, -depth)
    assert c.kind == "face-face" and len(c.points) >= 3, (c.kind, len(c.points))
    slack = depth + 1e-9 * size
    for hull in (pa, pb):
        assert outside(c.points, hull).max() <= slack
    moved = pb + depth * c.normal
    assert (pa @ c.normal).max() - (moved @ c.normal).min() <= 1e-9 * size


def prism(base, height):
    """The prism of the convex polygon ``base`` (k, 2) from z = 0 to z = height: (2 k, 3)."""
    k = base.shape[0]
    return np.vstack([np.column_stack([base, np.zeros(k)]), np.column_stack([base, np.full(k, height)])])


@st.composite
def convex_polygons(draw):
    """A convex polygon inscribed in a circle of radius r in [0.5, 1]: 4 to 8 corners whose angular gaps are in
    the ratio of weights in [1, 1.5] (no gap wider than 2π/3), so it holds the disc of radius r / 2 about the
    origin."""
    k = draw(st.integers(4, 8))
    weights = np.array(draw(st.lists(st.floats(1.0, 1.5), min_size=k, max_size=k)))
    angles = draw(st.floats(0.0, 2 * np.pi)) + 2 * np.pi * np.cumsum(weights) / weights.sum()
    r = draw(st.floats(0.5, 1.0))
    return r * np.column_stack([np.cos(angles), np.sin(angles)])


def stack(lower, upper, height_a, tilt_axis, tilt, offset, press, q, scale):
    """Prism A of base ``lower`` and height ``height_a``; prism B of base ``upper`` standing on A's top face,
    shifted by ``offset`` (|offset| <= 1/4: the footprints share the disc of radius 1/4 about it), turned by
    ``tilt`` rad about ``tilt_axis`` around its bottom centre and pressed ``press`` × 0.1 deeper than the tilt
    lifts any corner of the overlap; both turned by ``q`` and scaled by ``scale``."""
    a = prism(lower, height_a)
    b = prism(upper, 0.6)
    turn = Rotation.from_rotvec(tilt * tilt_axis).as_matrix()
    lift = 2.5 * tilt  # the footprints lie within radius 1 + 1/4 of B's axis: a tilt lifts them at most this
    b = b @ turn.T + [offset[0], offset[1], height_a - lift - 0.1 * press]
    return scale * (a @ q.T), scale * (b @ q.T)


offsets = st.tuples(st.floats(-0.17, 0.17), st.floats(-0.17, 0.17))


@given(convex_polygons(), convex_polygons(), st.floats(0.3, 1.0), unit_vectors, tilts, offsets,
       st.floats(0.01, 1.0), rotations, scales, st.booleans())
def test_nearly_flush_prisms_touch_face_to_face(lower, upper, height_a, tilt_axis, tilt, offset, press, q, scale,
                                                swap):
    a, b = stack(lower, upper, height_a, tilt_axis, tilt, offset, press, q, scale)
    pa, pb = (b, a) if swap else (a, b)
    check_flush_contact(pa, pb, contact_feature(pa, pb))


def box_pair(q, tilt_axis, tilt, ha, hb, offset, press, scale):
    """Boxes A (half extents ha) and B (hb) in the frame q, B above A's top face turned by ``tilt`` about
    ``tilt_axis``, pressed ``press`` × the thinner half height deeper than the tilt lifts any corner of the
    overlap: (centre, rotation, half extents) of each."""
    turn = Rotation.from_rotvec(tilt * tilt_axis).as_matrix()
    lift = 2.0 * tilt * (ha[0] + ha[1] + hb[0] + hb[1])
    depth = lift + press * min(ha[2], hb[2])
    cb = np.array([offset[0] * min(ha[0], hb[0]), offset[1] * min(ha[1], hb[1]), ha[2] + hb[2] - depth])
    return (np.zeros(3), q, scale * ha), (scale * (q @ cb), q @ turn, scale * hb)


def corners(c, R, e):
    return c + (CORNERS * e) @ R.T


box_pairs = st.builds(box_pair, rotations, unit_vectors, tilts, halves, halves,
                      st.tuples(st.floats(-0.9, 0.9), st.floats(-0.9, 0.9)), st.floats(0.02, 0.5), scales)


@given(box_pairs, st.booleans())
def test_nearly_flush_boxes_as_hulls_touch_face_to_face_as_box_box_does(pair, swap):
    first, second = (pair[1], pair[0]) if swap else pair
    pa, pb = corners(*first), corners(*second)
    c = contact_feature(pa, pb)
    check_flush_contact(pa, pb, c)
    assert min(len(c.points), MAX_POINTS) == len(contact_box_box_pair(*first, *second).points_of(0))


def test_mujoco_multicontact_case_gets_four_points():
    """Two cubes of half size 0.05, B turned 1.152e-3 rad about the vertical and (-4.9e-5, -3.8e-5) rad about
    the horizontal axes, 6e-4 into A: every corner of the overlap 5.96e-4 to 6.04e-4 deep."""
    half = np.full(3, 0.05)
    Rb = Rotation.from_rotvec([-4.93331466e-05, -3.83306082e-05, 0.0011523691115879876]).as_matrix()
    cb = np.array([0.00474186, 0.00397678, 0.1 - 6e-4])
    pa, pb = CORNERS * half, corners(cb, Rb, half)
    bottom = pb[CORNERS[:, 2] < 0]
    assert np.all((0.05 - bottom[:, 2] > 5.9e-4) & (0.05 - bottom[:, 2] < 6.1e-4))
    for first, second in ((pa, pb), (pb, pa)):
        c = contact_feature(first, second)
        assert c.kind == "face-face" and len(c.points) == 4, (c.kind, len(c.points))
        check_flush_contact(first, second, c)


@given(st.floats(1e-4, 0.05), st.floats(-0.3, 0.3), st.floats(-0.3, 0.3), rotations, scales, st.booleans())
def test_an_edge_across_an_edge_is_one_edge_point(depth, sx, sz, q, scale, swap):
    """A cube turned 45° about z (a top edge along z) under a cube turned 45° about x (a bottom edge along x),
    the edges crossing at right angles ``depth`` deep: one edge–edge point, the normal the edge axis."""
    r = np.sqrt(2.0) * 0.5
    Ra = q @ Rotation.from_euler("z", 45, degrees=True).as_matrix()
    Rb = q @ Rotation.from_euler("x", 45, degrees=True).as_matrix()
    a = corners(np.zeros(3), Ra, np.full(3, 0.5 * scale))
    b = corners(scale * (q @ np.array([sx, 2 * r - depth, sz])), Rb, np.full(3, 0.5 * scale))
    first, second = (b, a) if swap else (a, b)
    c = contact_feature(first, second)
    assert c.kind == "edge-edge" and len(c.points) == 1, (c.kind, len(c.points))
    assert abs(abs(c.normal @ q[:, 1]) - 1.0) <= 1e-9
