"""Boxes nearly face to face keep the face (engine/narrowphase/box_box.py, ``prefer_face``).

Two boxes whose faces are within 1e-3 rad of parallel overlap in a thin slab; an edge–edge axis A_a × B_b that
lies between the two face normals can have a smaller overlap than either face (the faces' overlaps count the
corners that hang past the other face), and a separating-axis test that takes the least overlap answers with one
edge–edge point where the boxes really touch over a polygon (MuJoCo's multi-contact box tests: 4 points). The
properties:

- nearly flush boxes of any sizes and scale (1e-3 to 1e3), every corner of the overlap below the other face:
  "face-face" with at least 3 points, every point inside both boxes grown by the depth (+ round-off);
- the depth is the exact least overlap over the 15 axes (computed here in numpy, independently), and translating
  the second box by depth · normal separates the pair (the ContactSet's contract): the normal is the least-overlap
  axis, whichever feature pair gives the points;
- MuJoCo's case, reconstructed: two 0.1 cubes turned 1.15e-3 rad about the vertical and 6e-5 rad out of it,
  corners 5.96e-4 to 6.04e-4 deep: 4 points;
- an edge across an edge (boxes turned 45° about perpendicular axes, and random crossings far from any face
  normal) is still one edge–edge point.
"""
from __future__ import annotations

import itertools

import numpy as np
from hypothesis import assume, given
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from engine.narrowphase.box_box import FACE_KEEP_COS, contact_box_box_pair, prefer_face

U = np.finfo(float).eps
CORNERS = np.array(list(itertools.product((-1.0, 1.0), repeat=3)))
SIGNED_PERMUTATIONS = [P for P in (np.diag(s) @ np.eye(3)[list(p)] for p in itertools.permutations(range(3))
                                   for s in itertools.product((-1.0, 1.0), repeat=3)) if np.linalg.det(P) > 0]

rotations = st.integers(0, 2**32 - 1).map(lambda s: Rotation.random(random_state=s).as_matrix())
unit_vectors = st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1)).filter(
    lambda v: 0.1 < np.linalg.norm(v) <= 1.0).map(lambda v: np.array(v) / np.linalg.norm(v))
halves = st.tuples(st.floats(0.2, 1.0), st.floats(0.2, 1.0), st.floats(0.2, 1.0)).map(np.array)
scales = st.floats(-3.0, 3.0).map(lambda e: 10.0 ** e)


def least_overlap(ca, Ra, ea, cb, Rb, eb):
    """The least overlap over the 15 SAT axes (face normals, then the edge cross products longer than 1e-7,
    the kernel's EDGE_AXIS_MIN), in world coordinates, and the size scale of its round-off."""
    t = cb - ca
    axes = [Ra[:, k] for k in range(3)] + [Rb[:, k] for k in range(3)]
    axes += [np.cross(Ra[:, a], Rb[:, b]) for a in range(3) for b in range(3)]
    best, rounding = np.inf, 0.0
    for L in axes:
        length = np.linalg.norm(L)
        if length <= 1e-7:
            continue
        L = L / length
        terms = np.abs(Ra.T @ L) @ ea + np.abs(Rb.T @ L) @ eb
        best = min(best, terms - abs(t @ L))
        rounding = max(rounding, (terms + np.abs(t).sum()) / length)
    return best, rounding


def outside(p, c, R, e):
    """How far the rows of p lie outside box (c, R, e) (<= 0 inside)."""
    return (np.abs((p - c) @ R) - e).max(axis=1)


def flush_pair(q, tilt_axis, tilt, ha, hb, offset, press, scale, perm):
    """Box A (q, ha) and box B turned by ``tilt`` rad about ``tilt_axis`` from A's frame, then by a signed
    permutation of its axes (any face of B may face A's top face), B above A's top face (A's axis 2) by
    ``press`` × the depth that keeps every corner of the overlap below both faces."""
    P = SIGNED_PERMUTATIONS[perm]
    turn = Rotation.from_rotvec(tilt * tilt_axis).as_matrix()
    Rb = q @ turn @ P
    eb = np.abs(P).T @ hb  # B's half extents along its own axes: its extents along A's frame are hb
    # the overlap's corners lie within |x|, |y| <= ha + hb of the axis; a tilt of ``tilt`` lifts them by at most
    # tilt · (|x| + |y|) · sqrt(2) over the flush height, so deeper than that every one of them penetrates
    lift = 2.0 * tilt * (ha[0] + ha[1] + hb[0] + hb[1])
    depth = lift + press * min(ha[2], hb[2])
    cb = np.array([offset[0] * min(ha[0], hb[0]), offset[1] * min(ha[1], hb[1]), ha[2] + hb[2] - depth])
    return (np.zeros(3), q, scale * ha), (scale * (q @ cb), Rb, scale * eb)


flush_pairs = st.builds(flush_pair, rotations, unit_vectors, st.floats(0.0, 1e-3), halves, halves,
                        st.tuples(st.floats(-0.9, 0.9), st.floats(-0.9, 0.9)), st.floats(0.02, 0.5), scales,
                        st.integers(0, len(SIGNED_PERMUTATIONS) - 1))


def check_contact_is_exact(a, b, cs):
    """The depth is the least overlap of the 15 axes, and depth · normal is a translation of B that separates
    (the overlap along the normal is the depth: a face normal or the least-overlap edge axis)."""
    depth, rounding = least_overlap(*a, *b)
    tol = 1e-12 * depth + 64 * U * rounding
    assert abs(cs.depth[0] - depth) <= tol, (cs.depth[0], depth)
    n = cs.normal[0]
    assert abs(np.linalg.norm(n) - 1.0) <= 1e-12
    along = np.abs(a[1].T @ n) @ a[2] + np.abs(b[1].T @ n) @ b[2] - abs((b[0] - a[0]) @ n)
    assert abs(along - cs.depth[0]) <= tol + 64 * U * rounding, (along, cs.depth[0])
    assert n @ (b[0] - a[0]) >= -tol


@given(flush_pairs, st.booleans())
def test_nearly_flush_boxes_touch_face_to_face(pair, swap):
    a, b = pair
    first, second = (b, a) if swap else (a, b)
    cs = contact_box_box_pair(*first, *second)
    assert cs.kind == ["face-face"], cs.kind
    points = cs.points_of(0)
    assert len(points) >= 3
    size = max(first[2].max(), second[2].max()) + np.abs(second[0]).max()
    slack = cs.depth[0] + 64 * U * size
    for c, R, e in (first, second):
        assert outside(points, c, R, e).max() <= slack
    check_contact_is_exact(first, second, cs)


@given(rotations, rotations, halves, halves, st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1)),
       scales)
def test_depth_is_the_least_overlap_and_the_normal_separates(qa, qb, ha, hb, direction, scale):
    """Any two overlapping boxes: the depth is exact whatever feature pair gives the points."""
    d = np.array(direction)
    cb = 0.9 * d * (ha.sum() + hb.sum()) / 3.0
    a, b = (np.zeros(3), qa, scale * ha), (scale * cb, qb, scale * hb)
    cs = contact_box_box_pair(*a, *b)
    if cs.depth[0] > 0.0:
        check_contact_is_exact(a, b, cs)


def test_mujoco_multicontact_case_gets_four_points():
    """Two cubes of half size 0.05, B turned 1.152e-3 rad about the vertical and (-4.9e-5, -3.8e-5) rad about
    the horizontal axes, 6e-4 into A: all 8 corners of the overlap (B's bottom corners, A's top corners under B)
    penetrate, 5.96e-4 to 6.04e-4 deep, and an edge axis beats both faces by 3.0e-4 of the depth."""
    half = np.full(3, 0.05)
    Rb = Rotation.from_rotvec([-4.93331466e-05, -3.83306082e-05, 0.0011523691115879876]).as_matrix()
    cb = np.array([0.00474186, 0.00397678, 0.1 - 6e-4])
    bottom = cb + (CORNERS[CORNERS[:, 2] < 0] * half) @ Rb.T
    assert np.all((0.05 - bottom[:, 2] > 5.9e-4) & (0.05 - bottom[:, 2] < 6.1e-4))
    cs = contact_box_box_pair(np.zeros(3), np.eye(3), half, cb, Rb, half)
    assert cs.kind == ["face-face"] and len(cs.points_of(0)) == 4
    depth, _ = least_overlap(np.zeros(3), np.eye(3), half, cb, Rb, half)
    assert abs(cs.depth[0] - depth) <= 1e-12 * depth + 1e-16


@given(st.floats(1e-4, 0.05), st.floats(-0.3, 0.3), st.floats(-0.3, 0.3), rotations, scales, st.booleans())
def test_an_edge_across_an_edge_is_one_edge_point(depth, sx, sz, q, scale, swap):
    """A box turned 45° about z (a top edge along z) under a box turned 45° about x (a bottom edge along x),
    the edges crossing at right angles ``depth`` deep: one edge–edge point, and the normal is the edge axis."""
    r = np.sqrt(2.0) * 0.5  # a unit cube's edge lies this far from its centre, turned 45°
    Ra = q @ Rotation.from_euler("z", 45, degrees=True).as_matrix()
    Rb = q @ Rotation.from_euler("x", 45, degrees=True).as_matrix()
    a = (np.zeros(3), Ra, np.full(3, 0.5 * scale))
    b = (scale * (q @ np.array([sx, 2 * r - depth, sz])), Rb, np.full(3, 0.5 * scale))
    first, second = (b, a) if swap else (a, b)
    cs = contact_box_box_pair(*first, *second)
    assert cs.kind == ["edge-edge"] and len(cs.points_of(0)) == 1
    assert abs(abs(cs.normal[0] @ q[:, 1]) - 1.0) <= 1e-12
    check_contact_is_exact(first, second, cs)


@given(st.floats(0.0, 1.0), st.floats(0.0, 1.0), st.floats(0.0, 1.0), st.floats(0.0, 1.0))
def test_prefer_face_keeps_the_face_within_the_angle_or_the_tie(face, gap, cos_angle, tie):
    """The rule itself: the face is kept when the edge axis does not beat it by more than ``tie``, or when the
    edge axis lies within the angle arccos(FACE_KEEP_COS) of the face normal."""
    edge = face - gap
    # the gap the floats hold (face − gap rounds: a gap below half an ulp of face is no gap); the rule's own
    # subtraction rounds too, so only gaps clearly on one side of the tie decide the expected answer
    held = face - edge
    assume(abs(held - tie) > 4 * np.spacing(max(face, tie, 1e-300)))
    assert prefer_face(face, edge, cos_angle, tie) == (held <= tie or cos_angle >= FACE_KEEP_COS)
    assert prefer_face(face, edge, -cos_angle, tie) == prefer_face(face, edge, cos_angle, tie)
