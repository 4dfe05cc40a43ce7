"""The stepped method's response (chapter 3, step 4) against the exact event-driven gas.

For a pair that meets away from the walls, moving it back to its contact instant, answering it there with the
elastic formulas and moving it forward again with its new velocities is exact: after the frame the pair is
where the event-driven gas puts it, with the same velocities and the same virial. A receding pair in contact
earlier in the candidate list does not stop the others from being answered. The kinetic energy the drift is
measured with is the compensated (Neumaier) sum: it equals math.fsum of the same terms.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st

from engine.gas import EventDrivenGas, SteppedGas

L = 10.0


@st.composite
def approaching_pairs(draw):
    """Two spheres 3 apart along x, offset sideways by less than 0.9 σ (no graze), closing at 1 to 4."""
    r = draw(st.floats(0.3, 0.6))
    side = draw(st.floats(0.0, 0.9 * 2 * r))
    phi = draw(st.floats(0.0, 2 * math.pi))
    p = np.array([[-1.5, 0.0, 0.0], [1.5, side * math.cos(phi), side * math.sin(phi)]])
    va, vb = draw(st.floats(0.5, 2.0)), draw(st.floats(0.5, 2.0))
    wobble = np.array([[draw(st.floats(-0.2, 0.2)) for _ in range(3)] for _ in range(2)])
    v = np.array([[va, 0.0, 0.0], [-vb, 0.0, 0.0]]) + wobble
    m = np.array([draw(st.floats(0.2, 5.0)), draw(st.floats(0.2, 5.0))])
    return p, v, np.full(2, r), m


@given(approaching_pairs(), st.sampled_from([0.005, 0.01, 0.03]), st.floats(0.3, 1.0))
def test_a_pair_meeting_away_from_the_walls_ends_where_the_event_gas_puts_it(pair, dt, extra):
    p, v, r, m = pair
    closing = v[0, 0] - v[1, 0]
    steps = int(math.ceil((3.0 / closing + extra) / dt))
    t = steps * dt
    exact = EventDrivenGas(p, v, r, m, L, periodic=False)
    exact.run(t)
    assume(exact.collisions == 1 and exact.wall_hits == 0)
    gas = SteppedGas(p, v, r, m, L, False, dt)
    gas.run(steps)
    assert gas.collisions == 1 and gas.wall_hits == 0 and gas.overlapping == 0
    np.testing.assert_allclose(gas.velocities, exact.velocities, rtol=0, atol=1e-9)
    np.testing.assert_allclose(gas.positions, exact.positions, rtol=0, atol=1e-8)
    assert gas.virial == pytest.approx(exact.virial, rel=1e-9)
    assert gas.virial > 0.0


@given(st.floats(0.3, 0.6), st.floats(0.02, 0.3), st.floats(0.02, 0.3), st.floats(0.1, 2.0), st.floats(0.0, 0.5),
       st.floats(0.2, 5.0), st.sampled_from([0.01, 0.02]))
def test_a_receding_pair_in_contact_does_not_stop_the_others(r, depth01, depth23, speed, sideways, m3, dt):
    """In the same frame, spheres 0 and 1 overlap while moving apart (first in the canonical order: not answered,
    only pushed apart) and spheres 2 and 3 overlap while approaching: 2 and 3 get exactly the response they get
    without 0 and 1 around, an elastic exchange (one collision, velocities changed, energy kept)."""
    sigma = 2 * r
    p01 = np.array([[-3.0, 3.0, 0.0], [-3.0 + sigma - depth01, 3.0, 0.0]])
    v01 = np.array([[-0.1, 0.0, 0.0], [0.1, 0.0, 0.0]])
    p23 = np.array([[0.0, -2.0, 0.0], [0.0, -2.0, 0.0]])
    p23[1, :2] += (sigma - depth23) * np.array([math.cos(sideways), math.sin(sideways)])  # in contact, 0.5 rad off x
    v23 = np.array([[speed, 0.0, 0.0], [-speed, 0.0, 0.0]])
    m23 = np.array([1.0, m3])
    alone = SteppedGas(p23, v23, r, m23, L, False, dt)
    alone.run(1)
    assert alone.collisions == 1
    assert not np.array_equal(alone.velocities, v23)
    both = SteppedGas(np.concatenate([p01, p23]), np.concatenate([v01, v23]), r, np.concatenate([[1.0, 1.0], m23]),
                      L, False, dt)
    both.run(1)
    np.testing.assert_array_equal(both.velocities[:2], v01)  # receding: never answered
    np.testing.assert_array_equal(both.velocities[2:], alone.velocities)
    np.testing.assert_array_equal(both.positions[2:], alone.positions)
    assert both.collisions == 1
    e = [0.5 * m23[i] * float(v23[i] @ v23[i]) for i in range(2)]
    assert alone.kinetic_energy() == pytest.approx(sum(e), rel=1e-14)


@given(st.integers(100, 300), st.floats(4e-17, 1e-16), st.integers(0, 2**16))
def test_kinetic_energy_is_the_correctly_rounded_sum(n, small, seed):
    """One sphere carries K = 1, the others 1e-17..1e-16 each (1e-15 or more together): a plain running sum
    drops every small term (each is below half an ulp of 1), the compensated sum keeps them all, as math.fsum
    does."""
    rng = np.random.default_rng(seed)
    m = np.full(n, 2.0)
    direction = rng.normal(size=(n, 3))
    v = direction / np.linalg.norm(direction, axis=1, keepdims=True) * math.sqrt(small) * rng.uniform(0.5, 1.0, (n, 1))
    v[0] = [1.0, 0.0, 0.0]
    terms = [0.5 * m[i] * (v[i, 0] * v[i, 0] + v[i, 1] * v[i, 1] + v[i, 2] * v[i, 2]) for i in range(n)]
    gas = SteppedGas(np.zeros((n, 3)), v, 0.1, m, L, False, 0.01)  # the frame loop starts from overlaps
    assert gas.kinetic_energy() == pytest.approx(math.fsum(terms), rel=4e-16)
    assert gas.kinetic_energy() - 1.0 >= 0.5 * math.fsum(terms[1:])


@given(st.floats(0.3, 0.6), st.floats(0.05, 0.9), st.floats(0.2, 5.0), st.floats(0.3, 2.8), st.floats(0.1, 3.0))
def test_an_overlap_at_rest_is_pushed_apart_along_the_line_of_centres(r, depth, m1, theta, phi):
    """Two spheres at rest overlapping by ``depth`` σ along a direction with x, y and z components, away from the
    walls: one frame pushes them apart along their line of centres (each sphere moves parallel to it), mass-
    weighted so the centre of mass stays put (momentum kept), until they just touch: |d| = σ to round-off."""
    sigma = 2 * r
    u = np.array([math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi), math.cos(theta)])
    p = np.array([[0.3, -0.2, 0.1], [0.3, -0.2, 0.1]])
    p[1] += (1.0 - depth) * sigma * u
    m = np.array([m1, 1.0])
    gas = SteppedGas(p, np.zeros((2, 3)), r, m, L, False, 0.01)
    gas.run(1)
    q = gas.positions
    for k in range(2):  # each displacement is parallel to u
        move = q[k] - p[k]
        assert np.linalg.norm(np.cross(move, u)) <= 1e-12 * sigma, k
    np.testing.assert_allclose(m @ q, m @ p, rtol=0, atol=1e-12 * m.sum())
    d = float(np.linalg.norm(q[1] - q[0]))
    assert sigma <= d <= sigma * (1 + 1e-13)
    assert gas.overlapping == 0
