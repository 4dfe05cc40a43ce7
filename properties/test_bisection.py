"""Algorithme 3 (bisection): tolerance, exact endpoints, no bracket, iteration bound, hostile values."""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import example, given
from hypothesis import strategies as st
from scipy.optimize import brentq

from engine import bisect
from engine.dynamics.bisection import max_bisection_iterations
from properties.strategies.dynamics import finite, shifted_cubics

tolerances = st.floats(1e-9, 1.0, **finite)


@given(shifted_cubics(), tolerances)
def test_root_within_tol_and_iteration_bound(cubic, tol):
    f, root, a, b = cubic
    x, info = bisect(f, a, b, tol, full_output=True)
    assert abs(x - root) <= tol
    assert info.a <= root <= info.b
    assert info.iterations <= max(0, math.ceil(math.log2((b - a) / tol)) + 1)
    assert info.iterations <= max_bisection_iterations(a, b, tol)


@given(shifted_cubics(), tolerances)
def test_order_of_the_bracket_does_not_matter(cubic, tol):
    f, _, a, b = cubic
    assert bisect(f, a, b, tol) == bisect(f, b, a, tol)


@given(st.floats(0.5, 50.0, **finite), st.floats(0.05, 3.0, **finite), st.floats(1e-10, 1e-4, **finite))
def test_drag_trajectory_root(height, lam, tol):
    """The landing time of y(t) = h - (g/λ) t + (g/λ²)(1 - e^{-λ t}) (linear drag, from rest) against brentq."""
    g = 9.81

    def y(t):
        return height - (g / lam) * t + (g / lam**2) * (-math.expm1(-lam * t))

    t_hi = 2.0 * math.sqrt(2 * height / g) + 2.0 * height * lam / g + 1.0
    reference = brentq(y, 0.0, t_hi, xtol=1e-15, rtol=4 * np.finfo(float).eps)
    assert abs(bisect(y, 0.0, t_hi, tol) - reference) <= tol + 1e-12


@given(st.floats(-1e6, 1e6, **finite), st.floats(1e-3, 1e3, **finite), tolerances)
def test_endpoint_root_is_returned_exactly(a, width, tol):
    b = a + width
    assert bisect(lambda x: x - a, a, b, tol) == a
    assert bisect(lambda x: x - b, a, b, tol) == b


@given(st.floats(-1e3, 1e3, **finite), st.floats(1e-3, 1e3, **finite), st.floats(0.1, 1e3, **finite))
def test_no_bracket_raises(a, width, offset):
    with pytest.raises(ValueError, match="does not bracket"):
        bisect(lambda x: (x - a) ** 2 + offset, a, a + width, 1e-6)


@given(st.sampled_from([1e-200, -1e-200, 1e-300, -1e-300]), st.floats(0.01, 0.99, **finite))
@example(1e-200, 0.3)
def test_tiny_values_keep_their_sign(scale, root):
    """f(a) f(x') underflows to 0 for |f| ~ 1e-200; the sign test must not be fooled."""
    x = bisect(lambda t: scale * (t - root), 0.0, 1.0, 1e-12)
    assert abs(x - root) <= 1e-12


def test_exact_zero_at_a_midpoint_is_returned():
    # f(0.5) == 0 exactly: the textbook loop would move `a` past the root and end near b
    assert bisect(lambda x: x - 0.5, 0.0, 1.0, 1e-12) == 0.5
    assert bisect(lambda x: x - 0.25, 0.0, 1.0, 1e-12) == 0.25


def test_tolerance_below_double_spacing_terminates():
    x, info = bisect(math.sin, 3.0, 4.0, 1e-300, full_output=True)
    assert abs(x - math.pi) <= 4.5e-16
    assert info.iterations < 70


@pytest.mark.parametrize("kwargs, name", [
    (dict(a=float("nan"), b=1.0, tol=1e-6), "a"),
    (dict(a=0.0, b=float("inf"), tol=1e-6), "b"),
    (dict(a=0.0, b=1.0, tol=0.0), "tol"),
    (dict(a=0.0, b=1.0, tol=-1e-3), "tol"),
    (dict(a=0.0, b=1.0, tol=float("nan")), "tol"),
])
def test_bad_arguments_name_themselves(kwargs, name):
    with pytest.raises(ValueError, match=rf"^{name} "):
        bisect(lambda x: x - 0.5, **kwargs)


def test_nan_from_f_raises_and_non_callable_is_a_type_error():
    with pytest.raises(ValueError, match="NaN"):
        bisect(lambda x: float("nan") if x > 0.4 else -1.0, 0.0, 1.0, 1e-6)
    with pytest.raises(TypeError, match="callable"):
        bisect(3.0, 0.0, 1.0, 1e-6)
