"""``load_shape`` (the contact JSON format of engine/contact_io.py) against independent oracles.

- The pose of a parsed shape at time t, ``ShapeSpec.at(t)``, is the rigid motion the format describes: every
  local vertex x goes to ``center + velocity t + R(ω t) rotation x`` with R(ω t) scipy's rotation of rotation
  vector ω t (an oracle independent of the engine's Rodrigues kernel) and ``rotation`` given as a quaternion
  (w first) or a matrix.
- Every vector field (center, half_extents, velocity, angular_velocity) of the wrong length is refused with a
  ValueError naming the field (DESIGN §4: errors start with the argument's name), for every kind that reads it.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from engine.contact_io import load_shape
from properties.strategies.narrow import sizes, vectors

quaternions = st.tuples(*[st.floats(-1.0, 1.0)] * 4).filter(lambda q: 0.1 < np.linalg.norm(q))
spins = st.tuples(*[st.floats(-3.0, 3.0)] * 3).map(np.array)


def _local(kind: str, half, radius, points):
    if kind == "box":
        return np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * half
    if kind == "capsule":
        return np.array([[0.0, -half[1], 0.0], [0.0, half[1], 0.0]])
    if kind == "sphere":
        return np.zeros((1, 3))
    return points


@given(st.sampled_from(["box", "capsule", "sphere", "convex"]), vectors, st.tuples(sizes, sizes, sizes).map(np.array),
       quaternions, st.booleans(), vectors, spins, st.floats(0.0, 5.0), st.integers(0, 2**31))
def test_pose_at_t_is_the_described_rigid_motion(kind, center, half, quat, as_matrix, velocity, spin, t, seed):
    points = np.random.default_rng(seed).normal(size=(6, 3))
    spec = {"shape": kind, "center": center.tolist(), "velocity": velocity.tolist(),
            "angular_velocity": spin.tolist()}
    w, x, y, z = np.asarray(quat) / np.linalg.norm(quat)
    rot = Rotation.from_quat([x, y, z, w])  # scipy is scalar-last
    spec["rotation"] = rot.as_matrix().tolist() if as_matrix else [w, x, y, z]
    if kind == "box":
        spec["half_extents"] = half.tolist()
    elif kind == "capsule":
        spec.update(radius=0.5, half_height=float(half[1]))
    elif kind == "sphere":
        spec["radius"] = 0.5
    else:
        spec["points"] = points.tolist()
    shape = load_shape(spec)
    local = _local(kind, half, 0.5, points)
    expected = center + velocity * t + Rotation.from_rotvec(spin * t).apply(rot.apply(local))
    assert shape.kind == kind
    assert np.array_equal(shape.velocity, velocity) and np.array_equal(shape.angular_velocity, spin)
    assert np.allclose(shape.center, center, atol=1e-12)
    assert np.allclose(shape.at(t), expected, atol=1e-9), (shape.at(t), expected)


FIELDS = {"box": ("center", "half_extents", "velocity", "angular_velocity"),
          "sphere": ("center", "velocity", "angular_velocity"),
          "capsule": ("center", "velocity", "angular_velocity"),
          "convex": ("center", "velocity", "angular_velocity")}
GOOD = {"box": {"shape": "box", "center": [0, 0, 0], "half_extents": [1, 1, 1]},
        "sphere": {"shape": "sphere", "center": [0, 0, 0], "radius": 1.0},
        "capsule": {"shape": "capsule", "center": [0, 0, 0], "radius": 1.0, "half_height": 1.0},
        "convex": {"shape": "convex", "points": [[0, 0, 0], [1, 0, 0], [0, 1, 0]]}}


@pytest.mark.parametrize("kind,field", [(k, f) for k, fields in FIELDS.items() for f in fields])
@pytest.mark.parametrize("bad", [[1.0], [1.0, 2.0], [1.0, 2.0, 3.0, 4.0], [[1.0, 2.0, 3.0]]])
def test_wrong_length_vectors_are_refused_by_name(kind, field, bad):
    spec = {**GOOD[kind], field: bad}
    assert load_shape(GOOD[kind]).kind == kind
    with pytest.raises(ValueError, match=field):
        load_shape(spec)


@pytest.mark.parametrize("kind", sorted(GOOD))
@given(t=st.floats(0.0, 5.0))
def test_omitted_motion_fields_mean_a_shape_at_rest(kind, t):
    """"velocity" and "angular_velocity" are optional, default 0 (the format's own words): a shape that gives
    neither has zero velocities and the same vertices at every t."""
    shape = load_shape(GOOD[kind])
    assert np.array_equal(shape.velocity, np.zeros(3)) and np.array_equal(shape.angular_velocity, np.zeros(3))
    assert np.array_equal(shape.at(t), shape.at(0.0)) and np.array_equal(shape.at(0.0), shape.core)
