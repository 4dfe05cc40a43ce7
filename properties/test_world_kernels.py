"""The closed-form contact kernels of the World against GJK/EPA, on random and on degenerate poses, and exact on
the exact cases.

Kernels (engine.narrowphase): sphere–sphere, sphere–capsule, capsule–capsule (segment_segment.py), sphere–box
(sphere_box.py), box–box (box_box.py), every body on a plane (plane.py). For every pair:
- the depth (or, apart, the separation) equals the oracle's within 1e-9 × the pair's scale: EPA's penetration
  depth of the cores plus the radii when the cores overlap, the radii minus GJK's distance when they do not;
  apart / touching agrees with the oracle outside a round-off band;
- issue 18's "answers that cannot be true": the normal is unit; translating the second shape by depth · n
  (plus the tolerance) separates the pair, and by less than depth does not; every contact point lies within
  depth/2 of both shapes and inside the closed band [min of B along n, max of A along n];
- degenerate configurations: rotations by multiples of 90° ± 1e-9, boxes with parallel axes and faces that
  share a plane, parallel segments, scales from 1e-6 to 1e6.
Exact cases: a sphere resting on a box face gets exactly that face's normal (bit for bit), a box on a plane its
4 bottom corners with the normal ±y and the exact depth, parallel capsules two points with a normal exactly
perpendicular to them, stacked boxes 4 points.
"""
from __future__ import annotations

import numpy as np
from hypothesis import example, given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from engine import epa_penetration, gjk_distance
from engine.narrowphase.box_box import contact_box_box_pair
from engine.narrowphase.plane import contact_points_plane_pair
from engine.narrowphase.segment_segment import contact_segments_pair
from engine.narrowphase.sphere_box import contact_sphere_box_pair
from properties.strategies.world import degenerate_rotations, kernel_scales

SIGNS = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=float)
#: relative tolerance of the agreement with GJK/EPA (× the pair's scale)
REL = 1e-9


def box_core(center, rotation, half):
    return center + (SIGNS * half) @ rotation.T


def oracle_separation(pa, pb, rsum):
    """Signed distance of the two swept cores: GJK distance minus the radii, or minus (EPA depth + radii)."""
    d, _, _ = gjk_distance(pa, pb)
    if d > 0:
        return d - rsum
    return -(epa_penetration(pa, pb)[0] + rsum)


def check_contact(cs, pa, ra, pb, rb, scale, *, exact_depth=True):
    """The contact of one pair (ContactSet cs of one row) against the oracle and issue 18's invariants."""
    tol = REL * scale
    rsum = ra + rb
    expected = oracle_separation(pa, pb, rsum)
    sep = float(cs.separation[0])
    if abs(expected) > 1e3 * tol:  # outside the round-off band the verdicts agree
        assert (sep <= 0) == (expected <= 0), (sep, expected)
    if expected > 0 or sep > 0:
        return
    depth = float(cs.depth[0])
    n = cs.normal[0]
    if exact_depth:
        assert abs(depth + expected) <= tol, (depth, -expected)
    assert abs(np.linalg.norm(n) - 1.0) <= 1e-12
    gap_after, _, _ = gjk_distance(pa, pb + (depth + tol) * n)
    assert gap_after - rsum >= 0.0  # translated by the depth along n, B no longer overlaps A
    if depth > 100 * tol:
        gap_short, _, _ = gjk_distance(pa, pb + (depth - 10 * tol) * n)
        assert gap_short - rsum <= 0.0  # ... and not before
    top_a = (pa @ n).max() + ra
    bottom_b = (pb @ n).min() - rb
    points = cs.points_of(0)
    assert 1 <= points.shape[0] <= 4
    for q in points:
        for core, r in ((pa, ra), (pb, rb)):
            d, _, _ = gjk_distance(q[None], core)
            assert d - r <= depth / 2 + 10 * tol  # on or in both shapes, within the depth
        assert bottom_b - 10 * tol <= q @ n <= top_a + 10 * tol  # in the closed depth band along n
    assert len(set(cs.point_ids.tolist())) == points.shape[0]


vectors = st.tuples(*[st.floats(-1.0, 1.0, allow_nan=False)] * 3).map(np.array)
radii = st.floats(0.05, 1.0, allow_nan=False)
halves = st.tuples(*[st.floats(0.05, 1.0, allow_nan=False)] * 3).map(np.array)


# ---------------------------------------------------------------------------------------------------------------
# round cores: sphere–sphere, sphere–capsule, capsule–capsule
# ---------------------------------------------------------------------------------------------------------------

@given(vectors, vectors, radii, vectors, vectors, radii, st.sampled_from(["ss", "sc", "cc"]), kernel_scales)
@settings(max_examples=200)
def test_round_cores_agree_with_gjk(a0, a1, ra, b0, b1, rb, kinds, scale):
    a1 = a0 if kinds[0] == "s" else a1
    b1 = b0 if kinds[1] == "s" else b1
    a0, a1, b0, b1, ra, rb = a0 * scale, a1 * scale, b0 * scale, b1 * scale, ra * scale, rb * scale
    cs = contact_segments_pair(a0, a1, ra, b0, b1, rb)
    pa, pb = np.unique(np.stack([a0, a1]), axis=0), np.unique(np.stack([b0, b1]), axis=0)
    check_contact(cs, pa, ra, pb, rb, 4 * scale)
    d, ca, cb = gjk_distance(pa, pb)
    if d > 1e-6 * scale:  # apart cores: the normal is the direction of GJK's closest points
        np.testing.assert_allclose(cs.normal[0], (cb - ca) / d, atol=1e-7)


@given(vectors, st.floats(0.1, 1.0), radii, radii, st.floats(-0.9, 0.9), st.floats(0.0, 2.0), kernel_scales)
@settings(max_examples=100)
def test_parallel_capsules_exact(direction, length, ra, rb, shift, offset, scale):
    """Parallel capsules: two points at the ends of their overlap, the normal exactly perpendicular to them, the
    depth ra + rb − (distance of the lines)."""
    u = direction / max(np.linalg.norm(direction), 1e-9)
    if np.linalg.norm(direction) < 1e-3:
        u = np.array([0.0, 0.0, 1.0])
    w = np.cross(u, [1.0, 0.0, 0.0] if abs(u[0]) < 0.9 else [0.0, 1.0, 0.0])
    w /= np.linalg.norm(w)
    gap = (ra + rb) * offset * 0.5 * scale
    a0, a1 = np.zeros(3), length * scale * u
    b0, b1 = a0 + shift * length * scale * u + gap * w, a1 + shift * length * scale * u + gap * w
    cs = contact_segments_pair(a0, a1, ra * scale, b0, b1, rb * scale)
    assert abs(cs.normal[0] @ u) <= 1e-15
    assert abs(cs.separation[0] - (gap - (ra + rb) * scale)) <= 1e-15 * 8 * scale
    if cs.separation[0] <= 0 and gap > 0:  # the direction of an offset of size gap, to the round-off of a0 ... b1
        np.testing.assert_allclose(cs.normal[0], w, rtol=0, atol=1e-12 + 1e-14 * scale / gap)
        assert cs.points.shape[0] == 2 and cs.kind == ["cylinder-cylinder"]


# ---------------------------------------------------------------------------------------------------------------
# sphere–box
# ---------------------------------------------------------------------------------------------------------------

@given(vectors, radii, degenerate_rotations, halves, kernel_scales)
@settings(max_examples=200)
def test_sphere_box_agrees_with_gjk_epa(p, r, rot, half, scale):
    p, r, half = 1.5 * p * scale, r * scale, half * scale
    cs = contact_sphere_box_pair(p, r, np.zeros(3), rot, half)
    check_contact(cs, p[None], r, box_core(np.zeros(3), rot, half), 0.0, 3 * scale)


@given(st.integers(0, 5), vectors, radii, halves, degenerate_rotations, st.floats(-0.5, 0.5), kernel_scales)
@settings(max_examples=200)
def test_sphere_on_a_face_gets_that_face_normal(face, inside, r, half, rot, press, scale):
    """A sphere whose centre lies over a face (inside its rectangle): the normal is exactly −(the face's outward
    normal), bit for bit, and the depth is r − (height of the centre above the face)."""
    half, r = half * scale, r * scale
    axis, side = face // 2, (1.0 if face % 2 else -1.0)
    local = 0.999 * inside * half
    local[axis] = side * (half[axis] + r * (1.0 - press))
    p = rot @ local
    cs = contact_sphere_box_pair(p, r, np.zeros(3), rot, half)
    outward = side * rot[:, axis]
    np.testing.assert_array_equal(cs.normal[0], -outward)
    assert cs.feature_b[0] == 3
    height = p @ rot[:, axis] * side - half[axis]
    assert abs(cs.separation[0] - (height - r)) <= 1e-15 * 4 * scale


# ---------------------------------------------------------------------------------------------------------------
# box–box
# ---------------------------------------------------------------------------------------------------------------

@st.composite
def box_pairs(draw):
    """Two boxes: random poses, or parallel axes with faces sharing a plane, at any scale."""
    scale = draw(kernel_scales)
    ha, hb = draw(halves) * scale, draw(halves) * scale
    ra = draw(degenerate_rotations)
    if draw(st.booleans()):  # parallel axes (up to 90° turns ± 1e-9), faces flush on one axis
        rb = ra @ Rotation.from_euler("xyz", draw(st.sampled_from([0, 90, 180])) * np.array(
            [0, 0, 1.0]), degrees=True).as_matrix()
        offset = draw(vectors) * (ha + hb)
        axis = draw(st.integers(0, 2))
        offset[axis] = ha[axis] - hb[axis] if abs(offset[axis]) < ha[axis] + hb[axis] else offset[axis]
        cb = ra @ offset
    else:
        rb = draw(degenerate_rotations)
        cb = draw(vectors) * 1.2 * (ha.max() + hb.max())
    return np.zeros(3), ra, ha, cb, rb, hb, scale


#: touching boxes of size 1e-6 (faces flush on y and z, an edge of contact): the incident face lies 1 ulp
#: (2e-22) above the reference face by round-off, which once dropped every clipped point
TINY_TOUCHING_BOXES = (np.zeros(3), np.diag([1.0, -1.0, -1.0]), np.full(3, 1e-6), np.array([5e-7, -1.5e-6, -2e-6]),
                       np.diag([1.0, -1.0, -1.0]), np.array([5e-7, 5e-7, 1e-6]), 1e-6)


@given(box_pairs())
@example(TINY_TOUCHING_BOXES)
@settings(max_examples=200)
def test_box_box_agrees_with_epa(boxes):
    ca, ra, ha, cb, rb, hb, scale = boxes
    cs = contact_box_box_pair(ca, ra, ha, cb, rb, hb)
    check_contact(cs, box_core(ca, ra, ha), 0.0, box_core(cb, rb, hb), 0.0, 4 * scale)


@given(halves, halves, vectors, st.floats(0.001, 0.9), st.floats(-0.3, 0.3), kernel_scales)
@settings(max_examples=100)
def test_stacked_boxes_four_points(ha, hb, slide, press, yaw, scale):
    """A smaller box resting on a larger one (turned about the vertical): 4 contact points, normal ±y exactly
    when the axes are shared."""
    ha, hb = (ha + 1.0) * scale, np.minimum(hb, 0.4) * scale
    rb = Rotation.from_euler("y", yaw).as_matrix()
    cb = np.array([0.3 * slide[0] * ha[0], ha[1] + hb[1] - press * hb[1], 0.3 * slide[2] * ha[2]])
    cs = contact_box_box_pair(np.zeros(3), np.eye(3), ha, cb, rb, hb)
    if cs.separation[0] < 0:
        assert cs.points.shape[0] == 4 and cs.kind == ["face-face"]
        np.testing.assert_array_equal(np.abs(cs.normal[0]), [0.0, 1.0, 0.0])


# ---------------------------------------------------------------------------------------------------------------
# bodies on a plane
# ---------------------------------------------------------------------------------------------------------------

@given(st.sampled_from(["sphere", "capsule", "box", "hull"]), degenerate_rotations, halves, st.integers(0, 2**16),
       st.floats(-1.0, 1.0), kernel_scales)
@settings(max_examples=200)
def test_bodies_on_a_plane(kind, rot, half, seed, level, scale):
    rng = np.random.default_rng(seed)
    if kind == "sphere":
        core, r = np.zeros((1, 3)), half[0]
    elif kind == "capsule":
        core, r = np.array([-half, half]) @ rot.T, half.min()
    elif kind == "box":
        core, r = box_core(np.zeros(3), rot, half), 0.0
    else:
        core, r = rng.normal(size=(12, 3)) @ rot.T * half, 0.0
    core, r, altitude = core * scale, r * scale, level * scale
    cs = contact_points_plane_pair(core, r, altitude)
    lowest = core[:, 1].min() - r
    assert abs(cs.separation[0] - (lowest - altitude)) <= 4e-16 * scale * (2 + abs(level))
    np.testing.assert_array_equal(cs.normal[0], [-0.0, -1.0, -0.0])
    if cs.separation[0] <= 0:
        for q in cs.points_of(0):
            assert lowest - 1e-15 * scale <= q[1] <= altitude + 1e-15 * scale
            d, _, _ = gjk_distance(q[None], core)
            assert d - r <= cs.depth[0] / 2 + 1e-12 * scale
        assert 1 <= cs.points.shape[0] <= 4


@given(halves, st.floats(-np.pi, np.pi), st.floats(0.0, 0.5), kernel_scales)
@settings(max_examples=100)
def test_box_on_a_plane_exact(half, yaw, press, scale):
    """A box turned about the vertical on the ground: its 4 bottom corners, normal exactly −y, exact depth."""
    half = half * scale
    rot = Rotation.from_euler("y", yaw).as_matrix()
    rot[1] = [0.0, 1.0, 0.0]  # exactly the vertical axis
    rot[:, 1] = [0.0, 1.0, 0.0]
    center = np.array([0.3 * scale, half[1] - press * half[1], -0.2 * scale])
    cs = contact_points_plane_pair(box_core(center, rot, half), 0.0, 0.0)
    assert cs.separation[0] == center[1] - half[1]
    np.testing.assert_array_equal(cs.normal[0], [-0.0, -1.0, -0.0])
    assert cs.points.shape[0] == 4 and cs.kind == ["face-face"]
