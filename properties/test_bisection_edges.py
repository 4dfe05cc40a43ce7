"""Algorithme 3's iteration bound, computed exactly in integers, and the bracket bookkeeping of ``bisect``.

The bound ceil(log2(|b - a| / tol)) + 1 (``max_bisection_iterations``) is checked against an integer oracle on
brackets whose width and tolerance are exact in binary (integer ends, tol a power of two): the number of
halvings k with width / 2^k <= tol, plus one.
"""
from __future__ import annotations

import math

from hypothesis import assume, given
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


@given(st.integers(1, 2**10), st.integers(0, 30))
def test_halvings_are_counted_exactly(width, j):
    """On [0, width] with tol = 2^-j every midpoint is an exact double, so each halving halves the bracket
    exactly: unless a midpoint hits the root exactly, bisection makes exactly (bound - 1) halvings."""
    tol = math.ldexp(1.0, -j)
    r = width / math.pi
    root, info = bisect(lambda x: x - r, 0.0, float(width), tol, full_output=True)
    assert info.iterations == exact_bound(width, j) - 1 or root == r
    assert info.b - info.a <= tol and info.converged


@given(st.floats(-1e3, 1e3, allow_nan=False), st.floats(1e-3, 1e3, allow_nan=False), st.booleans())
def test_a_root_at_an_endpoint_costs_no_halving(a, width, at_b):
    """f vanishes exactly at one end: that end is returned, with zero halvings and converged."""
    b = a + width
    assume(b > a)
    end = b if at_b else a
    root, info = bisect(lambda x: 0.0 if x == end else (1.0 if x > end else -1.0), a, b, 1e-9, full_output=True)
    assert root == end and info.a == info.b == end
    assert info.iterations == 0 and info.converged


@given(st.floats(0.5, 1e3, allow_nan=False), st.sampled_from([1e-300, 1e-200, 1e-17]))
def test_bracket_of_adjacent_doubles_counts_as_converged(scale, tol):
    """tol below the spacing of doubles: the loop stops at two adjacent doubles, and reports convergence.
    f is a step at the double m (never exactly 0), so the final bracket is [m, the next double]."""
    m = scale * math.pi
    root, info = bisect(lambda x: -1.0 if x <= m else 1.0, scale * 3.0, scale * 4.0, tol, full_output=True)
    assert (info.a, info.b) == (m, math.nextafter(m, math.inf))
    assert root in (info.a, info.b)
    assert info.converged


@given(st.floats(0.0, 1.0, allow_nan=False), st.booleans())
def test_nan_from_f_names_the_x_where_it_happened(x_bad, at_b):
    """A NaN at an end of the bracket: the ValueError gives that end (as repr) in its message."""
    a, b = (0.0, 1.0 + x_bad) if at_b else (-x_bad - 1.0, 0.0)
    end = b if at_b else a

    def f(x):
        return math.nan if x == end else (x - 0.5 if at_b else x + 0.5)

    try:
        bisect(f, a, b, 1e-6)
    except ValueError as error:
        assert "NaN" in str(error) and repr(end) in str(error)
    else:
        raise AssertionError("NaN from f was not reported")


@given(st.sampled_from([1, 3, 5, 7, 11]), st.integers(-60, 60), st.integers(1000, 1074))
def test_iteration_bound_is_exact_when_width_over_tol_overflows(c, m, j):
    """A denormal tol (down to 2^-1074) under a normal width: width / tol overflows to inf and the bound is taken
    from the difference of the logarithms; it is still ceil(log2(width / tol)) + 1 exactly (integer oracle:
    width / tol = c 2^(m + j), with c odd so that log2 never sits within round-off of an integer unless c = 1)."""
    width, tol = math.ldexp(float(c), m), math.ldexp(1.0, -j)
    assume(math.isinf(width / tol))
    scaled = c << (m + j)  # width / tol, exact (m + j >= 1024 - 4 here)
    expected = (scaled - 1).bit_length() + 1
    assert max_bisection_iterations(0.0, width, tol) == expected
    assert max_bisection_iterations(width, -0.0, tol) == expected
