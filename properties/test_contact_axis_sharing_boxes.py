"""``contact_feature_pairs`` on boxes that share their axes (one common rotation, integer corners in its frame),
resting on each other face to face, overlapping, or apart — the configurations where GJK ends on a triangle of the
Minkowski difference with the origin on it and EPA's touching shortcut decides (engine/narrowphase/epa.py,
``nv == 3``). Oracle: the exact signed distance of two axis-aligned boxes in their common frame (interval gaps, or
the shortest push along one axis); for a face resting on a face (positive-area overlap), the normal is the
common axis, from A towards B.
"""
from __future__ import annotations

import numpy as np
from hypothesis import example, given
from hypothesis import strategies as st

from engine.narrowphase import contact_feature_pairs, pack_point_sets
from properties.strategies.narrow import aabb_depth, aabb_distance, box_corners, rotations

corner = st.tuples(*[st.integers(-2, 1)] * 3)
side = st.tuples(*[st.integers(1, 2)] * 3)


@st.composite
def axis_sharing_box_pairs(draw):
    lo_a = np.array(draw(corner), dtype=np.float64)
    hi_a = lo_a + np.array(draw(side))
    lo_b = np.array(draw(corner), dtype=np.float64)
    hi_b = lo_b + np.array(draw(side))
    if draw(st.booleans()):  # B rests on A's face along axis k
        k = draw(st.integers(0, 2))
        height = hi_b[k] - lo_b[k]
        lo_b[k] = hi_a[k]
        hi_b[k] = lo_b[k] + height
    rot = draw(st.one_of(st.just(np.eye(3)), rotations()))
    return lo_a, hi_a, lo_b, hi_b, rot


def _pair(lo_a, hi_a, lo_b, hi_b):
    return tuple(np.array(v, dtype=np.float64) for v in (lo_a, hi_a, lo_b, hi_b)) + (np.eye(3),)


# pairs on which a wrong normal in EPA's triangle-simplex test (the ``nv == 3`` block) sends the answer astray:
# B a corner block of A (depth 1 reported as touching), and faces resting on faces with coplanar side faces
PINNED = [
    _pair([1, -2, 0], [3, 0, 1], [1, -2, 0], [2, -1, 1]),
    _pair([0, -2, 0], [2, 0, 2], [-1, -2, 0], [0, -1, 2]),
    _pair([0, -2, 0], [2, -1, 1], [2, -2, 0], [4, 0, 1]),
]


@example(PINNED)
@given(st.lists(axis_sharing_box_pairs(), min_size=1, max_size=6))
def test_axis_sharing_boxes_get_the_exact_separation_and_the_face_normal(boxes):
    shapes = []
    for lo_a, hi_a, lo_b, hi_b, rot in boxes:
        shapes += [box_corners(lo_a, hi_a) @ rot.T, box_corners(lo_b, hi_b) @ rot.T]
    points, offsets = pack_point_sets(shapes)
    pairs = np.array([[2 * i, 2 * i + 1] for i in range(len(boxes))])
    batch = contact_feature_pairs(points, offsets, pairs)
    for p, (lo_a, hi_a, lo_b, hi_b, rot) in enumerate(boxes):
        gap = aabb_distance(lo_a, hi_a, lo_b, hi_b)
        expected = gap if gap > 0.0 else -aabb_depth(lo_a, hi_a, lo_b, hi_b)
        assert abs(batch.separation[p] - expected) <= 1e-9, (p, batch.separation[p], expected)
        assert abs(np.linalg.norm(batch.normal[p]) - 1.0) <= 1e-12
        # a face resting on a face: touching along exactly one axis k, a positive-area overlap across it
        touch = (hi_a == lo_b) | (hi_b == lo_a)
        inside = (np.minimum(hi_a, hi_b) - np.maximum(lo_a, lo_b)) > 0
        if gap == 0.0 and touch.sum() == 1 and inside.sum() == 2:
            k = int(np.argmax(touch))
            axis = rot[:, k] * (1.0 if hi_a[k] == lo_b[k] else -1.0)
            assert np.allclose(batch.normal[p], axis, atol=1e-9), (p, batch.normal[p], axis)
