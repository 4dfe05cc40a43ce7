"""Algorithme 3's iteration bound, computed exactly in integers, and the bracket bookkeeping of ``bisect``.

The bound ceil(log2(|b - a| / tol)) + 1 (``max_bisection_iterations``) is checked against an integer oracle on
brackets whose width and tolerance are exact in binary (integer ends, tol a power of two): the number of
halvings k with width / 2^k <= tol, plus one.
"""
from __future__ import annotations

import math

from hypothesis import given
from hypothesis import strategies as st

from engine import bisect
from engine.dynamics.bisection import max_bisection_iterations


def exact_bound(width: int, log2_inv_tol: int) -> int:
    """1 when width <= tol, else 1 + the least k with width <= tol 2^k; tol = 2^-log2_inv_tol, all in integers."""
    scaled = width << log2_inv_tol  # width / tol, exact
    if scaled <= 1:
        return 1
    return (scaled - 1).bit_length() + 1


@given(st.integers(-10**6, 10**6), st.integers(-10**6, 10**6), st.integers(-20, 30))
def test_iteration_bound_is_exact_on_binary_brackets(a, b, j):
    tol = math.ldexp(1.0, -j)
    expected = exact_bound(abs(b - a), j) if j >= 0 else _exact_bound_coarse(abs(b - a), -j)
    assert max_bisection_iterations(float(a), float(b), tol) == expected
    assert max_bisection_iterations(float(b), float(a), tol) == expected


def _exact_bound_coarse(width: int, log2_tol: int) -> int:
    """The same bound for tol = 2^log2_tol >= 1."""
    tol = 1 << log2_tol
    if width <= tol:
        return 1
    k = 0
    while width > tol << k:
        k += 1
    return k + 1


@given(st.integers(1, 10**6), st.integers(0, 40), st.integers(-10**6, 10**6))
def test_final_bracket_of_a_linear_function_holds_the_root(width, j, shift):
    """f(x) = x - r with r = a + width/pi inside [a, b]: the final bracket holds r and is no wider than tol (or
    two adjacent doubles), within the iteration bound."""
    a, b = float(shift), float(shift + width)
    tol = math.ldexp(1.0, -j)
    r = a + width / math.pi
    root, info = bisect(lambda x: x - r, a, b, tol, full_output=True)
    assert info.a <= r <= info.b
    assert info.b - info.a <= tol or info.b == math.nextafter(info.a, math.inf)
    assert abs(root - r) <= tol
    assert info.iterations <= max_bisection_iterations(a, b, tol)
    assert info.converged
