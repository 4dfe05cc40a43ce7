"""The feature kinds of box–box contacts (engine/narrowphase/box_box.py): "the feature of each side that touches"
(``engine.narrowphase.contacts``, ``ContactSet.feature_a``/``feature_b``, ``kind``), checked on scenes whose
touching features are known.

- A cube turned by θ about x (15° to 75°, so that its lowest feature is one edge along x) pressed by a small depth
  into the top face of a larger box: the large box touches with its face, the cube with that edge. The contact
  is "face-edge" (the cube second) or "edge-face" (the cube first), with two points: the ends of the part of the
  edge over the face, each halfway between the edge and the face; the whole scene is turned by a random rotation.
- The same cube pressed corner first (turned about two axes, its lowest vertex below the face): "face-vertex",
  one point.
"""
from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from engine.narrowphase.box_box import contact_box_box_pair

rotations = st.integers(0, 2**32 - 1).map(lambda s: Rotation.random(random_state=s).as_matrix())

HALF_A = np.array([1.0, 0.5, 1.0])  # the large box: top face y = 0.5, x and z in [-1, 1]
HALF_B = np.array([0.5, 0.5, 0.5])  # the cube


def _rows_sorted(p: np.ndarray) -> np.ndarray:
    return p[np.lexsort(np.round(p, 9).T[::-1])]


@given(st.floats(15.0, 75.0), st.floats(1e-4, 0.05), st.floats(-1.4, 1.4), rotations, st.booleans())
def test_a_cube_pressed_edge_first_into_a_face_is_face_edge(theta, depth, shift, q, cube_first):
    turn = Rotation.from_euler("x", theta, degrees=True).as_matrix()
    # the cube's lowest edge (along x) lies this far below its centre: 0.5 (cos θ + sin θ)
    low = 0.5 * (np.cos(np.radians(theta)) + np.sin(np.radians(theta)))
    cb = np.array([shift, 0.5 + low - depth, 0.0])
    big = (np.zeros(3), q, HALF_A)
    cube = (q @ cb, q @ turn, HALF_B)
    cs = contact_box_box_pair(*(cube + big if cube_first else big + cube))
    assert cs.kind == (["edge-face"] if cube_first else ["face-edge"]), (cs.kind, cs.points_of(0) @ q)
    assert abs(cs.depth[0] - depth) <= 1e-12, (cs.depth, depth)
    # the edge's stretch over the face, halfway between the edge (y = 0.5 - depth) and the face (y = 0.5)
    y = 0.5 - 0.5 * depth
    z = cb[2] + 0.5 * (np.cos(np.radians(theta)) - np.sin(np.radians(theta)))  # the edge's z in A's frame
    expected = np.array([[max(-1.0, shift - 0.5), y, z], [min(1.0, shift + 0.5), y, z]])
    got = cs.points_of(0) @ q
    assert got.shape == (2, 3) and np.abs(_rows_sorted(got) - _rows_sorted(expected)).max() <= 1e-9, (got, expected)


@given(st.floats(1e-4, 0.05), st.floats(-0.8, 0.8), st.floats(-0.8, 0.8), rotations, st.booleans())
def test_a_cube_pressed_corner_first_into_a_face_is_face_vertex(depth, sx, sz, q, cube_first):
    # turned so that a body diagonal is vertical: one corner lowest, sqrt(3)/2 below the centre
    turn = Rotation.from_euler("xz", [45.0, np.degrees(np.arctan(1 / np.sqrt(2)))], degrees=True).as_matrix()
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float) * HALF_B @ turn.T
    lowest = corners[np.argmin(corners[:, 1])]
    cb = np.array([sx, 0.5 - depth, sz]) - lowest
    big = (np.zeros(3), q, HALF_A)
    cube = (q @ cb, q @ turn, HALF_B)
    cs = contact_box_box_pair(*(cube + big if cube_first else big + cube))
    assert cs.kind == (["vertex-face"] if cube_first else ["face-vertex"]), cs.kind
    assert abs(cs.depth[0] - depth) <= 1e-12, (cs.depth, depth)
    got = cs.points_of(0) @ q
    assert got.shape == (1, 3) and np.abs(got[0] - [sx, 0.5 - 0.5 * depth, sz]).max() <= 1e-9, got
