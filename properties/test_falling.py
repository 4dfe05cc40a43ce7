"""The falling particle and the falling cube: impacts against exact answers and scipy's solve_ivp."""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from engine import drop_cube, drop_particle
from engine.oracles import reference_impacts
from properties.jit_off import INTERPRETED
from properties.strategies.dynamics import finite, heights, linear_drag_scenes, restitutions, step_sizes

G = 9.81
# interpreted (the mutation run), an example of the two bounce properties runs thousands of RK4 steps in Python
# (about 8 s): the same invariants on 5 examples instead of the profile's 25
FEW_WHEN_INTERPRETED = settings(max_examples=5) if INTERPRETED else (lambda test: test)


@FEW_WHEN_INTERPRETED
@given(heights, step_sizes)
def test_free_fall_impact_times_are_exact(height, dt):
    """No drag, e = 1: impacts at sqrt(2h/g)(2k + 1), the bounce height kept, over 10 bounces."""
    t_fall = math.sqrt(2 * height / G)
    r = drop_particle(height, dt=dt, t_end=t_fall * 20.5)
    assert len(r.impacts) == 10
    for k, imp in enumerate(r.impacts):
        assert imp.t == pytest.approx(t_fall * (2 * k + 1), rel=1e-8)
        assert imp.v_after**2 / (2 * G) == pytest.approx(height, rel=1e-8)


@FEW_WHEN_INTERPRETED
@given(heights, restitutions, step_sizes)
def test_velocity_after_is_minus_e_times_velocity_before(height, e, dt):
    r = drop_particle(height, restitution=e, dt=dt, t_end=30.0)
    assert r.impacts
    for imp in r.impacts:
        assert imp.v_after == -e * imp.v_before
        assert imp.v_before < 0.0


@settings(max_examples=60)
@given(linear_drag_scenes(), st.floats(0.5, 1.0, **finite))
def test_linear_drag_impacts_match_solve_ivp(scene, e):
    height, mass, drag, dt = scene
    r = drop_particle(height, mass=mass, drag=drag, restitution=e, dt=dt, t_end=1e3)
    n = min(3, len(r.impacts))
    assert n >= 1
    ours = np.array([imp.t for imp in r.impacts[:n]])
    np.testing.assert_allclose(ours, reference_impacts(height, mass, drag, e, n), rtol=1e-7)


@settings(max_examples=40)
@given(heights, st.floats(0.0, 0.5, **finite), step_sizes)
def test_quadratic_drag_first_impact_matches_solve_ivp(height, c, dt):
    r = drop_particle(height, quadratic_drag=c, dt=dt, t_end=1e3)
    assert r.impacts[0].t == pytest.approx(reference_impacts(height, 1.0, 0.0, 1.0, 1, c)[0], rel=1e-7)


@settings(max_examples=40)
@given(linear_drag_scenes(), step_sizes)
def test_step_size_does_not_move_the_impact(scene, other_dt):
    height, mass, drag, dt = scene
    a = drop_particle(height, mass=mass, drag=drag, dt=dt, t_end=1e3).impacts[0].t
    b = drop_particle(height, mass=mass, drag=drag, dt=other_dt, t_end=1e3).impacts[0].t
    assert a == pytest.approx(b, rel=1e-7)


@given(heights, restitutions, step_sizes, st.floats(1e-12, 1e-6, **finite))
def test_never_below_the_ground(height, e, dt, tol):
    """Every sample is above y = -tol |v|max (the tolerance of tc turned into a height), and every impact state
    is on the non-penetrating side of the final bracket."""
    r = drop_particle(height, restitution=e, dt=dt, t_end=10.0, tol=tol)
    assert r.y.min() >= -tol * np.abs(r.v).max()
    assert (r.y >= 0.0).all()


@given(heights, st.floats(0.0, 0.95, **finite), st.floats(0.0, 0.3, **finite))
def test_bouncing_comes_to_rest_then_contact_force_holds_it(height, e, drag):
    """e < 1: finitely many impacts, then resting contact: y = 0, v = 0, contact force = m g, no more impacts."""
    dt = 0.01
    v0 = math.sqrt(2 * G * height)
    bound = 1 if e == 0.0 else math.ceil(math.log(G * dt / v0) / math.log(e)) + 1
    t_rest_free = math.sqrt(2 * height / G) * (1 + 2 * e / (1 - e))  # geometric series of flight times
    r = drop_particle(height, mass=2.0, restitution=e, drag=drag, dt=dt, t_end=t_rest_free + 1.0)
    assert r.rest_time is not None
    assert 1 <= len(r.impacts) <= max(bound, 1)
    assert r.impacts[-1].came_to_rest and not any(imp.came_to_rest for imp in r.impacts[:-1])
    resting = r.t > r.rest_time
    assert resting.any()
    assert (r.y[resting] == 0.0).all() and (r.v[resting] == 0.0).all()
    np.testing.assert_allclose(r.contact_force[resting], 2.0 * G, rtol=1e-15)
    assert (r.contact_force[r.t < r.impacts[0].t] == 0.0).all()


@given(st.floats(0.6, 100.0, **finite), st.floats(0.1, 1.0, **finite), step_sizes)
def test_cube_stops_on_the_ground(height, size, dt):
    c = drop_cube(height + size / 2, size=size, dt=dt)
    assert c.t_contact == pytest.approx(math.sqrt(2 * height / G), rel=1e-8)
    np.testing.assert_array_equal(c.position, [0.0, size / 2, 0.0])
    np.testing.assert_array_equal(c.velocity, [0.0, 0.0, 0.0])
    assert c.t[-1] == c.t_contact and (c.y >= size / 2).all()
    assert c.v_contact == pytest.approx(-G * c.t_contact, rel=1e-8)


@settings(max_examples=40)
@given(linear_drag_scenes(), st.floats(0.1, 2.0, **finite))
def test_cube_with_drag_matches_solve_ivp(scene, size):
    height, mass, drag, dt = scene
    c = drop_cube(height + size / 2, size=size, mass=mass, drag=drag, dt=dt)
    ref = reference_impacts(height + size / 2, mass, drag, 0.0, 1, ground=size / 2)[0]
    assert c.t_contact == pytest.approx(ref, rel=1e-7)


def test_particle_starting_on_the_ground_rests():
    r = drop_particle(0.0, t_end=1.0)
    assert r.impacts == [] and r.rest_time == 0.0
    assert (r.y == 0.0).all() and (r.contact_force == G).all()


@pytest.mark.parametrize("kwargs, name", [
    (dict(height=-1.0), "height"), (dict(height=float("nan")), "height"), (dict(height=float("inf")), "height"),
    (dict(height=1.0, mass=0.0), "mass"), (dict(height=1.0, mass=-2.0), "mass"),
    (dict(height=1.0, restitution=1.5), "restitution"), (dict(height=1.0, restitution=-0.1), "restitution"),
    (dict(height=1.0, dt=0.0), "dt"), (dict(height=1.0, dt=-0.01), "dt"),
    (dict(height=1.0, tol=0.0), "tol"), (dict(height=1.0, tol=-1e-9), "tol"), (dict(height=1.0, tol=0.1), "tol"),
    (dict(height=1.0, drag=-1.0), "drag"), (dict(height=1.0, t_end=0.0), "t_end"),
    (dict(height=1.0, rest_speed=0.0), "rest_speed"), (dict(height=1.0, gravity=float("inf")), "gravity"),
])
def test_drop_particle_bad_input_names_the_argument(kwargs, name):
    with pytest.raises(ValueError, match=rf"^{name} "):
        drop_particle(**kwargs)


@pytest.mark.parametrize("kwargs, name", [
    (dict(height=-1.0), "height"), (dict(height=0.2, size=1.0), "height"), (dict(height=1.0, size=0.0), "size"),
    (dict(height=1.0, mass=0.0), "mass"), (dict(height=1.0, dt=0.0), "dt"), (dict(height=1.0, tol=-1.0), "tol"),
])
def test_drop_cube_bad_input_names_the_argument(kwargs, name):
    with pytest.raises(ValueError, match=rf"^{name} "):
        drop_cube(**kwargs)


def test_type_errors():
    with pytest.raises(TypeError, match="^height "):
        drop_particle("10")
    with pytest.raises(TypeError, match="^mass "):
        drop_particle(1.0, mass=1j)
