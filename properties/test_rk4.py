"""RK4: fourth order, exact on low-degree polynomials, shape-preserving, never modifies its input."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from engine import rk4_step, split_state, state_vector
from properties.strategies.dynamics import finite


def integrate(f, y0, t_end, n):
    y, dt = np.array(y0, dtype=float), t_end / n
    for i in range(n):
        y = rk4_step(f, i * dt, y, dt)
    return y


@given(st.floats(0.5, 3.0, **finite), st.floats(0.0, 1.0, **finite), st.integers(24, 48))
def test_halving_dt_divides_global_error_by_16(omega, damping, n):
    """Damped oscillator x'' = -ω² x - 2ζω x' over t in [0, 2], exact solution by the matrix exponential."""
    from scipy.linalg import expm

    A = np.array([[0.0, 1.0], [-omega**2, -2.0 * damping * omega]])
    y0 = np.array([1.0, 0.3])
    exact = expm(2.0 * A) @ y0

    def f(t, y):
        return A @ y

    e1 = np.linalg.norm(integrate(f, y0, 2.0, n) - exact)
    e2 = np.linalg.norm(integrate(f, y0, 2.0, 2 * n) - exact)
    # observed order log2(e1/e2) = 4 +- 0.3 (a third-order slip gives ~8, a fifth-order claim ~32)
    assert 2**3.7 <= e1 / e2 <= 2**4.3


@given(st.lists(st.floats(-5, 5, **finite), min_size=5, max_size=5), st.floats(-2, 2, **finite),
       st.floats(-1.0, 1.0, **finite))
def test_exact_on_quartic_quadrature(c, t0, dt):
    """For dy/dt = p(t) with deg p <= 3, RK4 is Simpson's rule: exact (to round-off)."""
    p = np.polynomial.Polynomial(c[:4])
    exact = p.integ()(t0 + dt) - p.integ()(t0)
    got = rk4_step(lambda t, y: p(t), t0, 0.0, dt)
    scale = 1.0 + np.abs(c).sum() * 8.0
    assert abs(got - exact) <= 1e-13 * scale


@given(st.integers(1, 4), st.floats(-1.0, 1.0, **finite))
def test_free_fall_state_vector_is_exact(d, dt):
    """Constant acceleration: the RK4 step on Y = (p, v) reproduces p + v dt + a dt²/2 and v + a dt."""
    rng = np.random.default_rng(d)
    p, v, acc = rng.normal(size=d), rng.normal(size=d), rng.normal(size=d)
    y = state_vector(p, v)
    before = y.copy()
    y1 = rk4_step(lambda t, Y: np.concatenate([Y[d:], acc]), 0.0, y, dt)
    p1, v1 = split_state(y1)
    np.testing.assert_allclose(p1, p + v * dt + 0.5 * acc * dt**2, rtol=1e-14, atol=1e-14)
    np.testing.assert_allclose(v1, v + acc * dt, rtol=1e-14, atol=1e-14)
    np.testing.assert_array_equal(y, before)


def test_wrong_shape_from_f_and_bad_arguments():
    with pytest.raises(ValueError, match="shape"):
        rk4_step(lambda t, y: np.zeros(3), 0.0, np.zeros(2), 0.1)
    with pytest.raises(ValueError, match="^dt "):
        rk4_step(lambda t, y: y, 0.0, np.zeros(2), float("nan"))
    with pytest.raises(ValueError, match=r"^y must be finite: y\[1\]"):
        rk4_step(lambda t, y: y, 0.0, np.array([0.0, np.inf]), 0.1)
    with pytest.raises(ValueError, match="non-finite"):
        rk4_step(lambda t, y: y * np.nan, 0.0, np.ones(2), 0.1)
    with pytest.raises(TypeError, match="callable"):
        rk4_step(None, 0.0, np.ones(2), 0.1)
    with pytest.raises(TypeError, match="^y "):
        rk4_step(lambda t, y: y, 0.0, np.ones(2, dtype=complex), 0.1)
