"""``as_rotation_matrix`` (the one reader of orientations: shapes, World, contact files) turns every accepted
form into the proper rotation it denotes, and nothing else:

- a unit quaternion (w, x, y, z) gives scipy's ``Rotation.from_quat(q, scalar_first=True).as_matrix()``;
- q and -q give the same matrix; None gives the identity (3, 3); a proper orthonormal matrix is returned as is;
- a quaternion accepted within ``tol`` of unit norm is used as given unless ``normalise=True``, which divides it
  by its norm first (the documented choice: file readers normalise rounded digits, the API does not);
- reflections, non-orthonormal matrices, non-unit quaternions and other shapes are refused by name.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from engine.bounding.aabb import ROTATION_TOL, as_rotation_matrix
from properties.strategies.geometry import seeds


@st.composite
def unit_quaternions(draw):
    if draw(st.booleans()):  # special angles about the axes: many zero components
        axis = draw(st.sampled_from(["x", "y", "z"]))
        angle = draw(st.sampled_from([0.0, 90.0, 180.0, -90.0, 45.0, 120.0]))
        q = Rotation.from_euler(axis, angle, degrees=True).as_quat(scalar_first=True)
    else:
        q = Rotation.random(random_state=draw(seeds)).as_quat(scalar_first=True)
    return q / np.linalg.norm(q)


@given(unit_quaternions())
def test_a_unit_quaternion_is_the_rotation_scipy_gives(q):
    expected = Rotation.from_quat(q, scalar_first=True).as_matrix()
    matrix = as_rotation_matrix(q)
    assert matrix.shape == (3, 3)
    assert np.allclose(matrix, expected, rtol=0, atol=1e-14)
    assert np.allclose(as_rotation_matrix(-q), matrix, rtol=0, atol=1e-15)
    assert np.allclose(as_rotation_matrix(list(q), normalise=True), expected, rtol=0, atol=1e-14)
    # the matrix form is accepted and returned unchanged
    assert np.array_equal(as_rotation_matrix(matrix), matrix)


def test_none_is_the_identity():
    assert np.array_equal(as_rotation_matrix(None), np.eye(3))


@pytest.mark.parametrize("component", [0, 1, 2, 3])
def test_a_nearly_unit_quaternion_is_used_as_given_unless_normalised(component):
    stretch = 1.0 + 0.25 * ROTATION_TOL  # accepted: within tol of unit norm
    q = np.zeros(4)
    q[component] = stretch
    w, x, y, z = q
    as_given = np.array([  # the documented formula on q itself
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])
    assert np.array_equal(as_rotation_matrix(q), as_given)
    normalised = as_rotation_matrix(q, normalise=True)
    assert np.allclose(normalised, Rotation.from_quat(q, scalar_first=True).as_matrix(), rtol=0, atol=1e-15)
    if component > 0:  # a half turn: the diagonal entries 1 - 2 q_k^2 show whether q was divided by its norm
        assert not np.array_equal(normalised, as_given)


@pytest.mark.parametrize("rotation, match", [
    ([1.0 + 2 * ROTATION_TOL, 0.0, 0.0, 0.0], "rotation quaternion must have unit norm"),
    (np.diag([1.0, 1.0, -1.0]), "rotation must be a proper rotation"),
    (np.eye(3) * (1.0 + 2 * ROTATION_TOL), "rotation must be orthonormal"),
    (np.eye(2), r"rotation must be a \(3, 3\) matrix or a \(4,\) quaternion"),
    (np.eye(4), r"rotation must be a \(3, 3\) matrix or a \(4,\) quaternion"),
    ([1.0, 0.0, 0.0], r"rotation must be a \(3, 3\) matrix or a \(4,\) quaternion"),
])
def test_what_is_not_a_proper_rotation_is_refused(rotation, match):
    with pytest.raises(ValueError, match="^" + match):
        as_rotation_matrix(rotation)


def test_the_tolerance_is_the_callers():
    q = [1.0 + 1e-7, 0.0, 0.0, 0.0]
    with pytest.raises(ValueError, match="^orientation quaternion"):
        as_rotation_matrix(q, "orientation")
    assert np.allclose(as_rotation_matrix(q, tol=1e-6), np.eye(3), rtol=0, atol=1e-15)
    tilted = Rotation.from_euler("z", 30, degrees=True).as_matrix() * (1.0 + 1e-7)
    with pytest.raises(ValueError, match="^orientation must be orthonormal"):
        as_rotation_matrix(tilted, "orientation")
    assert np.array_equal(as_rotation_matrix(tilted, tol=1e-6), tilted)
