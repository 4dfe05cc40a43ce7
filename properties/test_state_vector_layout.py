"""The state vector Y = (position, velocity) of the chapter's RK4 slides: layout, inverse, and its input checks.

``state_vector`` flattens (d,) position and velocity into Y (2d,); ``split_state`` is its inverse. Both refuse
what is not that layout, with a ValueError that starts with the argument's name (README, "Validation contract").
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from engine import split_state, state_vector

finite = st.floats(-1e6, 1e6, allow_nan=False, allow_infinity=False)


def vectors(d):
    return hnp.arrays(np.float64, d, elements=finite)


@given(st.integers(1, 6).flatmap(lambda d: st.tuples(vectors(d), vectors(d))))
def test_split_state_inverts_state_vector(pv):
    p, v = pv
    y = state_vector(p, v)
    assert y.shape == (2 * p.shape[0],)
    np.testing.assert_array_equal(y[: p.shape[0]], p)
    np.testing.assert_array_equal(y[p.shape[0]:], v)
    p1, v1 = split_state(y)
    np.testing.assert_array_equal(p1, p)
    np.testing.assert_array_equal(v1, v)


@given(st.integers(1, 4), st.integers(1, 4), st.sampled_from(["position", "velocity"]))
def test_state_vector_refuses_a_matrix_naming_the_argument(rows, cols, which):
    """A (rows, cols) position (with a velocity of the same shape), or a (rows,) position with a matrix velocity."""
    matrix = np.ones((rows, cols))
    position = matrix if which == "position" else np.ones(rows)
    with pytest.raises(ValueError, match=f"^{which}"):
        state_vector(position, matrix)


@given(st.integers(1, 5), st.sampled_from(["position", "velocity"]), st.sampled_from([np.nan, np.inf, -np.inf]))
def test_state_vector_refuses_non_finite_naming_the_argument(d, which, bad):
    p, v = np.zeros(d), np.zeros(d)
    (p if which == "position" else v)[d - 1] = bad
    with pytest.raises(ValueError, match=f"^{which}"):
        state_vector(p, v)


@given(st.integers(1, 5), st.integers(1, 5).filter(lambda k: k > 0))
def test_state_vector_refuses_different_lengths(d, extra):
    with pytest.raises(ValueError, match="same shape"):
        state_vector(np.zeros(d), np.zeros(d + extra))


@given(st.integers(0, 5))
def test_split_state_refuses_odd_lengths(k):
    with pytest.raises(ValueError, match="^y "):
        split_state(np.zeros(2 * k + 1))


@given(st.integers(1, 4), st.integers(1, 4))
def test_split_state_refuses_a_matrix_even_with_an_even_first_axis(half_rows, cols):
    with pytest.raises(ValueError, match="^y "):
        split_state(np.zeros((2 * half_rows, cols)))
