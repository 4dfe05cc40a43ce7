"""The kinematic culling helpers (slide "Méthode cinématique") refuse bad input naming the argument.

The contract is README's "Validation contract"."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from engine.broadphase.kinematic import cull_separating_sphere_pairs, front_faces


@given(st.integers(2, 10), st.data())
def test_a_negative_radius_in_an_array_is_refused(n, data):
    k = data.draw(st.integers(0, n - 1))
    radii = np.ones(n)
    radii[k] = -data.draw(st.floats(1e-9, 10.0, allow_nan=False))
    with pytest.raises(ValueError, match=rf"^radii must be >= 0: radii\[{k}\]"):
        cull_separating_sphere_pairs(np.array([[0, 1]]), np.zeros((n, 3)), radii, np.zeros((n, 3)))


@given(st.integers(1, 6), st.sampled_from([np.nan, np.inf]))
def test_bad_normals_are_named(m, bad):
    normals = np.ones((m, 3))
    normals[m - 1, 0] = bad
    with pytest.raises(ValueError, match="^normals"):
        front_faces(normals, np.ones(3))
    with pytest.raises(ValueError, match="^normals"):
        front_faces(np.ones(3), np.ones(3))
