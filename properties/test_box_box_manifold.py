"""The box–box contact manifold (engine/narrowphase/box_box.py) against answers known in closed form.

- A small box resting on a large one, turned about the vertical by any angle, its bottom face inside the large
  box's top face: the contact points are the small box's four bottom corners, each moved halfway towards the
  reference face (depth / 2 along the normal), and their ids — which "do not depend on which box is the
  reference" — are the same, swapped, when the two boxes are given in the other order.
- Two boxes turned by 45° about perpendicular axes, an edge of one across an edge of the other: one edge–edge
  point, halfway between the closest points of the two edges (computed here in the boxes' common frame).
- More than four candidate points are reduced to four by ``contacts.reduce_manifold``: the deepest, the farthest
  from it, the largest triangle on either side of that segment (its docstring). The rule is written out here in
  numpy and compared on candidates about a contact plane of any orientation.
- A cube resting exactly (depth 0) on a long bar touches at its four bottom corners; boxes apart have no point.
- ``contact_feature`` of boxes apart whose nearest edges are parallel: the two ends of the edges' common stretch;
  of an edge above a face: the ends of the part of the edge over the face.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from engine.narrowphase.box_box import contact_box_box_pair
from engine.narrowphase.contacts import kernel_scratch, reduce_manifold, swap_point_id

SIGNS = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)


def _rows_sorted(p: np.ndarray) -> np.ndarray:
    return p[np.lexsort(np.round(p, 9).T[::-1])]


def _same_points(got: np.ndarray, expected: np.ndarray, tol: float) -> bool:
    return got.shape == expected.shape and np.abs(_rows_sorted(got) - _rows_sorted(expected)).max() <= tol


rotations = st.integers(0, 2**32 - 1).map(lambda s: Rotation.random(random_state=s).as_matrix())


#: turns about the vertical: exactly aligned, within 1e-9 .. 1e-2 rad of an alignment (edge axes that nearly tie
#: the face axis), or farther away
yaws = st.one_of(st.just(0.0), st.tuples(st.floats(1e-9, 1e-2) | st.floats(0.01, np.pi / 2 - 0.01),
                                         st.sampled_from([1.0, -1.0]), st.integers(0, 3)).map(
    lambda t: t[1] * t[0] + t[2] * np.pi / 2))


@given(yaws, st.floats(0.05, 0.4), st.floats(0.05, 0.4), st.floats(0.05, 0.4),
       st.floats(-0.3, 0.3), st.floats(-0.3, 0.3), st.floats(0.01, 0.9), rotations)
def test_a_box_resting_on_a_larger_one_touches_at_its_four_bottom_corners(yaw, hx, hy, hz, ox, oz, press, q):
    ha = np.array([1.5, 1.0, 1.5])
    hb = np.array([hx, hy, hz])
    turn = Rotation.from_euler("y", yaw).as_matrix()
    depth = press * hy
    cb = np.array([ox, ha[1] + hb[1] - depth, oz])
    bottom = cb + (SIGNS[SIGNS[:, 1] < 0] * hb) @ turn.T  # B's four bottom corners
    expected = bottom + [0.0, 0.5 * depth, 0.0]
    # the whole scene turned by q (A's frame is q): the same contact, turned
    cs = contact_box_box_pair(np.zeros(3), q, ha, q @ cb, q @ turn, hb)
    assert cs.kind == ["face-face"] and abs(cs.depth[0] - depth) <= 1e-12
    assert _same_points(cs.points_of(0) @ q, expected, 1e-12), (cs.points_of(0) @ q, expected)
    ids = cs.ids_of(0)
    assert len(set(ids.tolist())) == 4
    swapped = contact_box_box_pair(q @ cb, q @ turn, hb, np.zeros(3), q, ha)
    order = np.lexsort(np.round(cs.points_of(0), 9).T[::-1])
    order_swapped = np.lexsort(np.round(swapped.points_of(0), 9).T[::-1])
    assert np.abs(swapped.points_of(0)[order_swapped] - cs.points_of(0)[order]).max() <= 1e-12
    assert [swap_point_id(i) for i in ids[order]] == swapped.ids_of(0)[order_swapped].tolist()


def test_a_box_resting_nearly_aligned_touches_at_its_four_bottom_corners():
    """The case found by the property above (dev profile) when its yaw could come within 0.01 rad of alignment:
    yaw 2.5e-7 rad, the scene turned by scipy's ``Rotation.random(random_state=15)`` (also 16, 17, 30, ...)."""
    hb = np.full(3, 0.25)
    turn = Rotation.from_euler("y", 2.5208511193833e-07).as_matrix()
    q = Rotation.random(random_state=15).as_matrix()
    cb = np.array([0.0, 1.125, 0.0])
    cs = contact_box_box_pair(np.zeros(3), q, np.array([1.5, 1.0, 1.5]), q @ cb, q @ turn, hb)
    assert cs.kind == ["face-face"] and cs.points_of(0).shape == (4, 3), (cs.kind, cs.points_of(0))

@given(st.floats(-0.8, 0.8), st.floats(-0.8, 0.8), st.floats(0.001, 0.2), st.floats(0.5, 2.0), rotations)
def test_crossing_edges_touch_halfway_between_their_closest_points(ox, oz, press, h, q):
    """A turned 45° about z (its top edge runs along z at height √2 h), B turned 45° about x and placed above
    (its bottom edge runs along x at height y_B − √2 h, at z = oz): the closest points of the two edges are
    (0, √2 h, oz) and (0, y_B − √2 h, oz); B's shift by ox along its own edge moves neither."""
    half = np.full(3, h)
    ra = Rotation.from_euler("z", 45, degrees=True).as_matrix()
    rb = Rotation.from_euler("x", 45, degrees=True).as_matrix()
    top = np.sqrt(2.0) * h
    depth = press * h
    cb = np.array([ox * h, 2 * top - depth, oz * h])
    cs = contact_box_box_pair(np.zeros(3), q @ ra, half, q @ cb, q @ rb, half)
    assert cs.kind == ["edge-edge"], cs.kind
    expected = np.array([[0.0, top - 0.5 * depth, oz * h]])
    assert abs(cs.depth[0] - depth) <= 1e-9 * h
    assert np.abs(cs.points_of(0) @ q - expected).max() <= 1e-9 * h, (cs.points_of(0) @ q, expected)


def _reduced_by_the_rule(points, depths, normal):
    """The documented choice, written plainly: indices of the deepest point, the farthest from it, then the
    points of largest positive and of largest negative (p_1 − p_0) × (p_i − p_0) · n (first index on ties)."""
    k0 = int(np.argmax(depths))
    k1 = int(np.argmax(((points - points[k0]) ** 2).sum(axis=1)))
    area = np.cross(points[k1] - points[k0], points - points[k0]) @ normal
    others = [i for i in range(len(points)) if i not in (k0, k1)]
    positive = [i for i in others if area[i] > 0.0]
    negative = [i for i in others if area[i] < 0.0]
    kept = [k0, k1]
    if positive:
        kept.append(max(positive, key=lambda i: (area[i], -i)))
    if negative:
        kept.append(max(negative, key=lambda i: (-area[i], -i)))
    return kept


@given(st.integers(5, 8), st.integers(0, 2**32 - 1), rotations)
def test_manifold_reduction_keeps_the_documented_four(count, seed, q):
    """``contacts.reduce_manifold`` on 5–8 candidate points scattered about a contact plane of any orientation
    (normal q·y), with distinct depths: the four it keeps are those of the rule in its docstring."""
    rng = np.random.default_rng(seed)
    local = np.column_stack([rng.uniform(-1, 1, count), rng.uniform(-1e-3, 1e-3, count), rng.uniform(-1, 1, count)])
    points = local @ q.T
    normal = q[:, 1]
    depths = rng.permutation(count) * 1e-3 + rng.uniform(0, 1e-4, count)
    ids = np.arange(count, dtype=np.int64) << 8
    expected = _reduced_by_the_rule(points, depths, normal)
    work_p, work_d, work_i = points.copy(), depths.copy(), ids.copy()
    kept = reduce_manifold(work_p, work_d, work_i, count, normal[0], normal[1], normal[2], kernel_scratch(count))
    assert kept == len(expected)
    assert work_i[:kept].tolist() == ids[expected].tolist()
    assert np.array_equal(work_p[:kept], points[expected]) and np.array_equal(work_d[:kept], depths[expected])


#: turns about the vertical by multiples of 90°, exact in binary (cos, sin in {−1, 0, 1})
QUARTER_TURNS = [np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]) for c, s in ((1, 0), (0, 1), (-1, 0), (0, -1))]


@pytest.mark.parametrize("long_axis", [0, 2])
@given(turn=st.sampled_from(QUARTER_TURNS), x=st.floats(-0.0625, 0.0625), z=st.floats(-0.0625, 0.0625))
def test_a_cube_resting_exactly_on_a_long_bar_touches_at_its_four_bottom_corners(long_axis, turn, x, z):
    """Depth exactly 0 (the heights are exact in binary): the four bottom corners are on the reference face to
    round-off, whatever the bar's proportions (the round-off allowance grows with the boxes' size; a bar 16 long
    and 0.125 wide must not turn it negative)."""
    ha = np.full(3, 0.125)
    ha[long_axis] = 16.0
    hb = np.full(3, 0.0625)
    cb = np.array([x, 0.1875, z])
    cs = contact_box_box_pair(np.zeros(3), np.eye(3), ha, cb, turn, hb)
    bottom = cb + (SIGNS[SIGNS[:, 1] < 0] * hb) @ turn.T
    assert cs.depth[0] == 0.0 and cs.kind == ["face-face"], (cs.depth, cs.kind)
    assert _same_points(cs.points_of(0), bottom, 1e-15), (cs.points_of(0), bottom)


@given(rotations, rotations, st.floats(0.01, 3.0), rotations)
def test_boxes_apart_report_no_contact_points(ra, rb, gap, q):
    """Boxes apart (B beyond A's bounding sphere plus B's by ``gap`` along a random direction): separation > 0
    (a lower bound of the distance, from the separating axis) and no contact point, no touching feature — the
    kernel computes none for a separated pair, so any point reported would be made up."""
    ha, hb = np.array([1.0, 0.5, 0.25]), np.array([0.3, 0.6, 0.9])
    direction = q[:, 0]
    cb = direction * (np.linalg.norm(ha) + np.linalg.norm(hb) + gap)
    cs = contact_box_box_pair(np.zeros(3), ra, ha, cb, rb, hb)
    assert cs.separation[0] > 0.0 and cs.depth[0] == 0.0
    assert cs.points_of(0).shape == (0, 3) and cs.feature_a[0] == 0 and cs.feature_b[0] == 0


@given(st.integers(5, 8), st.integers(0, 2**32 - 1), rotations)
def test_manifold_reduction_of_points_all_on_one_side(count, seed, q):
    """The same rule when every other candidate lies on one side of the segment from the deepest point (−1, 0, 0)
    to the farthest from it (1, 0, 0) — the others inside the half-disc between them: the other side contributes
    nothing, so three points are kept."""
    rng = np.random.default_rng(seed)
    radius, angle = rng.uniform(0.1, 0.9, count - 2), rng.uniform(0.1, np.pi - 0.1, count - 2)
    others = np.column_stack([radius * np.cos(angle), np.zeros(count - 2), radius * np.sin(angle)])
    local = np.vstack([[[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]], others])
    points = local @ q.T
    normal = q[:, 1]
    depths = np.concatenate([[1.0], rng.uniform(0.0, 0.5, count - 1)])
    ids = np.arange(count, dtype=np.int64) << 8
    expected = _reduced_by_the_rule(points, depths, normal)
    assert expected[:2] == [0, 1] and len(expected) == 3
    work_p, work_d, work_i = points.copy(), depths.copy(), ids.copy()
    kept = reduce_manifold(work_p, work_d, work_i, count, normal[0], normal[1], normal[2], kernel_scratch(count))
    assert kept == 3 and work_i[:kept].tolist() == ids[expected].tolist()


@given(st.floats(0.05, 1.0), st.floats(-1.5, 1.5), rotations)
def test_parallel_edges_apart_touch_over_the_overlap_of_their_lengths(gap, shift, q):
    """``contact_feature`` (GJK, then the features' clipping) of two boxes turned 45° about z, one above the
    other by ``gap`` and shifted along z by ``shift``: their nearest edges are parallel (along z), so the contact
    points are the two ends of the edges' common stretch, halfway across the gap."""
    from engine import contact_feature

    half = np.array([0.5, 0.5, 1.0])
    turn = Rotation.from_euler("z", 45, degrees=True).as_matrix()
    top = np.sqrt(0.5)
    a = (SIGNS * half) @ turn.T
    b = a + [0.0, 2 * top + gap, shift]
    c = contact_feature(a @ q.T, b @ q.T)
    assert c.kind == "edge-edge", c.kind
    y = top + 0.5 * gap
    expected = np.array([[0.0, y, max(-1.0, shift - 1.0)], [0.0, y, min(1.0, shift + 1.0)]])
    assert _same_points(c.points @ q, expected, 1e-9), (c.points @ q, expected)


@given(st.floats(0.05, 1.0), st.floats(-1.4, 1.4), rotations)
def test_an_edge_above_a_face_touches_over_the_part_inside_the_face(gap, shift, q):
    """``contact_feature`` of a large box (top face [−1, 1] × [−1, 1] at y = 0.5) and a cube turned 45° about x
    resting on its bottom edge (along x, ``gap`` above the face, shifted by ``shift`` along x): the contact
    points are the ends of the part of that edge over the face, halfway across the gap."""
    from engine import contact_feature

    a = SIGNS * [1.0, 0.5, 1.0]
    turn = Rotation.from_euler("x", 45, degrees=True).as_matrix()
    low = np.sqrt(2.0) * 0.5  # the turned cube's (half 0.5) bottom edge is this far below its centre
    b = (SIGNS * 0.5) @ turn.T + [shift, 0.5 + gap + low, 0.0]
    c = contact_feature(a @ q.T, b @ q.T)
    assert c.kind == "face-edge", c.kind
    y = 0.5 + 0.5 * gap
    expected = np.array([[max(-1.0, shift - 0.5), y, 0.0], [min(1.0, shift + 0.5), y, 0.0]])
    assert _same_points(c.points @ q, expected, 1e-9), (c.points @ q, expected)


@given(rotations, rotations, st.floats(0.2, 3.0), rotations)
def test_boxes_apart_get_a_unit_separating_normal(ra, rb, distance, q):
    """For a pair the kernel calls apart (separation > 0), the normal it reports is a certificate: a unit vector
    along which A's corners all lie at least ``separation`` below B's (up to round-off). Centres at 0.2 to 3 apart,
    so that face axes of either box and edge–edge axes both separate some pairs; an overlapping pair can have no
    such certificate."""
    ha, hb = np.array([1.0, 0.5, 0.25]), np.array([0.3, 0.6, 0.9])
    cb = q[:, 0] * distance
    cs = contact_box_box_pair(np.zeros(3), ra, ha, cb, rb, hb)
    if cs.separation[0] <= 0.0:
        return
    n = cs.normal[0]
    assert abs(np.linalg.norm(n) - 1.0) <= 1e-12, n
    corners_a = (SIGNS * ha) @ ra.T
    corners_b = cb + (SIGNS * hb) @ rb.T
    gap = (corners_b @ n).min() - (corners_a @ n).max()
    assert gap >= cs.separation[0] - 1e-12 * (1.0 + distance), (gap, cs.separation[0], n)
