"""Locating an impact (slide "La particule qui chute sur le sol": trial times Dt/2, Dt/4 ...) with a tolerance
below the spacing of doubles: Algorithme 3 must stop when no double lies strictly inside the bracket.

Free fall without drag from rest at h: the first impact is at sqrt(2h/g) exactly (RK4 is exact on the quadratic
trajectory up to round-off), so the located time is checked against it.
"""
from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from engine import drop_particle

G = 9.81


@given(st.floats(0.05, 50.0, allow_nan=False), st.floats(1e-3, 1e-2, allow_nan=False),
       st.sampled_from([1e-300, 1e-200, 1e-30]))
def test_impact_located_with_a_tolerance_below_double_spacing(height, dt, tol):
    t_fall = math.sqrt(2 * height / G)
    r = drop_particle(height, dt=dt, tol=tol, t_end=1.2 * t_fall)
    assert len(r.impacts) == 1
    assert r.impacts[0].t == pytest.approx(t_fall, rel=1e-9)
    assert r.bisection_iterations < 80 * len(r.impacts)
    assert (r.y >= 0.0).all()
