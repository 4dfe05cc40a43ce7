"""Hulls that only touch have depth 0.0 — the positive zero — from ``epa_penetration`` and
``epa_penetration_pairs`` alike (engine/narrowphase/penetration.py).

EPA's depth for a touching pair is the distance of a face of the Minkowski difference through the origin, a sum
of products that can come out as −0.0 (products of zeros and negative normal components); both public functions
turn the chain's signed distance into a depth that must not carry that sign (``1 / depth``, ``copysign`` and
printing would tell them apart). The pinned pairs below share points with integer coordinates
and are known to reach that −0.0; the property runs the same check on touching pairs of the same family."""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st

from engine.narrowphase import epa_penetration, epa_penetration_pairs

# (A, B): two hulls sharing a vertex, an edge or a face, whose touching face of A − B has a normal in the
# negative octant (found by a random search over small integer hulls)
PINNED = [
    ([[1.0, 2.0, -2.0], [1.0, -1.0, 2.0], [1.0, -1.0, -2.0], [0.0, 0.0, 0.0]],
     [[0.0, 0.0, 0.0], [1.0, -1.0, -2.0], [1.0, -1.0, 2.0], [-1.0, -1.0, 3.0]]),
    ([[2.0, -1.0, 0.0], [-3.0, 0.0, 2.0], [2.0, 2.0, -2.0], [-2.0, 1.0, -2.0]],
     [[-2.0, 1.0, -2.0], [2.0, 2.0, -2.0], [3.0, -3.0, -2.0], [-3.0, 0.0, -3.0]]),
    ([[1.0, 2.0, -1.0], [1.0, 1.0, -1.0], [3.0, 2.0, -3.0]],
     [[1.0, 2.0, -1.0], [1.0, 1.0, -1.0], [-1.0, 0.0, 0.0]]),
]


def _check_depth_is_positive_zero_in_both_forms(a, b):
    depth, normal = epa_penetration(a, b)
    packed = np.array(a + b)
    depths, normals = epa_penetration_pairs(packed, [0, len(a), len(a) + len(b)], [[0, 1]])
    assert depth == 0.0 and math.copysign(1.0, depth) == 1.0, depth
    assert math.copysign(1.0, depths[0]) == 1.0 and depths[0] == 0.0, depths
    assert np.isclose(np.linalg.norm(normal), 1.0) and np.array_equal(normal, normals[0]), (normal, normals)


@pytest.mark.parametrize("a, b", PINNED)
def test_touching_pairs_whose_face_distance_is_negative_zero_report_depth_positive_zero(a, b):
    _check_depth_is_positive_zero_in_both_forms(a, b)


coordinate = st.integers(-3, 3).map(float)
point = st.lists(coordinate, min_size=3, max_size=3)


@given(shared=st.lists(point, min_size=1, max_size=3), rest_a=st.lists(point, min_size=1, max_size=3),
       rest_b=st.lists(point, min_size=1, max_size=3), shared_first=st.booleans())
def test_touching_hulls_report_depth_positive_zero(shared, rest_a, rest_b, shared_first):
    a = shared + rest_a if shared_first else rest_a + shared
    b = shared + rest_b
    depth, _ = epa_penetration(a, b)
    assume(depth == 0.0)  # they share points, so they touch or overlap: keep the touching ones
    _check_depth_is_positive_zero_in_both_forms(a, b)
