"""Box–box contact points are distinct (engine/narrowphase/box_box.py, ``_face_contact``).

Sutherland–Hodgman keeps a vertex of the incident face that lies on a side of the reference face, and when the
next vertex is outside it also emits the crossing of that edge with the side, at u ≈ 0: the same point again, up
to round-off. A solver given two coincident contact points gets a singular block (two equal rows of the contact
Jacobian), so the kernel keeps such a point once. The scenes: a box turned about the vertical whose lowest corner
touches the top edge of the unit cube, the whole scene turned by a random rotation and shifted. The corner is the
whole contact, so there is exactly one point, and no two points of a pair may be closer than 1e-9 × the scene's
size. (Without the deduplication the kernel returned that corner twice, 5e-16 apart, and this property failed.)
"""
from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from engine.narrowphase.box_box import contact_box_box_pair


def _check_distinct(args, at_least):
    cs = contact_box_box_pair(*args)
    points = cs.points_of(0)
    scale = 1.0 + max(np.abs(np.asarray(a)).max() for a in args)
    assert points.shape[0] >= at_least, cs
    gaps = np.linalg.norm(points[:, None, :] - points[None, :, :], axis=2)
    np.fill_diagonal(gaps, np.inf)
    assert gaps.min(initial=np.inf) > 1e-9 * scale, (points, gaps)
    return points


@given(turn=st.floats(0.1, 1.4), halves=st.tuples(*[st.floats(0.2, 1.0)] * 3), side=st.sampled_from([-1.0, 1.0]),
       y=st.floats(-0.8, 0.8), seed=st.integers(0, 2**32 - 1), shift=st.tuples(*[st.floats(-3.0, 3.0)] * 3))
def test_a_corner_touching_an_edge_is_one_contact_point(turn, halves, side, y, seed, shift):
    rb = Rotation.from_euler("z", turn).as_matrix()
    hb = np.array(halves)
    signs = -np.sign(rb[0, :]) * side  # B's corner of least side·x and least z: its edges run away from A
    signs[2] = -1.0
    corner = np.array([side, y, 1.0])  # on A's top edge x = side, z = 1 (A: the cube of half edge 1 at 0)
    cb = corner - rb @ (signs * hb)
    q = Rotation.random(random_state=seed).as_matrix()
    s = np.array(shift)
    cs = contact_box_box_pair(s, q, np.ones(3), q @ cb + s, q @ rb, hb)
    if cs.separation[0] > 0.0:  # round-off may call them apart (checked in test_box_box_face_clipping_edges.py)
        return
    points = _check_distinct((s, q, np.ones(3), q @ cb + s, q @ rb, hb), 1)
    assert points.shape[0] == 1, points

