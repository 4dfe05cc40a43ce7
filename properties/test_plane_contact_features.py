"""The feature a body touches the ground with (engine/narrowphase/plane.py) is named by how many of its core
vertices reach the ground: one a vertex, two an edge, three or more a face (``ContactSet.kind``: "vertex-face",
"edge-face", "face-face"), for a box resting on its corner, on an edge or on a face, at any altitude."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from engine.narrowphase.plane import contact_points_plane_pair

SIGNS = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)


@pytest.mark.parametrize("touching, kind", [(1, "vertex-face"), (2, "edge-face"), (4, "face-face")])
@given(altitude=st.floats(-10.0, 10.0), sink=st.floats(1e-3, 0.05), yaw=st.floats(0.0, 2 * np.pi))
def test_the_touching_feature_is_named_by_the_vertices_that_reach_the_ground(touching, kind, altitude, sink, yaw):
    # a unit cube standing on a corner (its diagonal vertical), on an edge (turned 45° about x), or on a face
    tilt = {1: Rotation.align_vectors([[0.0, -1.0, 0.0]], [[-1.0, -1.0, -1.0]])[0],
            2: Rotation.from_euler("x", 45, degrees=True), 4: Rotation.identity()}[touching]
    corners = (Rotation.from_euler("y", yaw) * tilt).apply(SIGNS * 0.5)
    corners += [0.0, altitude - corners[:, 1].min() - sink, 0.0]  # the lowest vertices `sink` below the ground
    cs = contact_points_plane_pair(corners, 0.0, altitude)
    assert cs.points_of(0).shape[0] == touching and cs.kind == [kind], (cs.points_of(0), cs.kind)
    assert abs(cs.depth[0] - sink) <= 1e-12 * max(1.0, abs(altitude))
