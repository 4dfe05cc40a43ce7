"""The falling cube (slide "Application", cube): its default size, and a cube that has not reached the ground.

Without drag the centre follows y(t) = h - g t^2 / 2 exactly under RK4 (constant acceleration: RK4 integrates
a quadratic exactly, up to round-off), so both the contact time and the state at t_end have closed forms.
"""
from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from engine import drop_cube

G = 9.81
finite = dict(allow_nan=False, allow_infinity=False)


@given(st.floats(0.5, 20.0, **finite))
def test_default_cube_has_unit_edge(height):
    """size defaults to 1: contact when the centre is at 1/2, at t = sqrt(2 (h - 1/2) / g)."""
    cube = drop_cube(height, t_end=10.0)
    assert cube.size == 1.0
    assert cube.position[1] == 0.5
    if height > 0.5:
        assert cube.t_contact == pytest.approx(math.sqrt(2 * (height - 0.5) / G), rel=1e-8, abs=1e-9)


@given(st.floats(5.0, 100.0, **finite), st.floats(0.05, 0.5, **finite), st.floats(1e-3, 1e-2, **finite))
def test_cube_still_falling_at_t_end(height, size, dt):
    """t_end before the contact time: no contact reported, state at t_end is free fall's."""
    t_contact = math.sqrt(2 * (height - size / 2) / G)
    t_end = 0.5 * t_contact
    cube = drop_cube(height, size=size, dt=dt, t_end=t_end)
    assert cube.t_contact is None and cube.v_contact is None
    assert cube.position[1] == pytest.approx(height - G * t_end**2 / 2, rel=1e-9)
    assert cube.velocity[1] == pytest.approx(-G * t_end, rel=1e-9)
    assert cube.position[0] == cube.position[2] == 0.0
