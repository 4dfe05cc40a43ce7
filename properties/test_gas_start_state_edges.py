"""The edges of a gas's start state: spheres that exactly touch are a valid start, one ulp closer is an overlap;
a radius or a mass of exactly zero in a per-sphere array is refused by name and index.

Exactness: the centres and radii below are small binary fractions, so |p_i − p_j|² and (r_i + r_j)² are computed
without rounding and "touching" means equality, not a round-off accident.
"""
from __future__ import annotations

import numpy as np
import pytest

from engine.gas import EventDrivenGas, SteppedGas, simulate_gas

BOX = 8.0


def _touching_chain(scale):
    """Three spheres of radius scale/2 in an L: 0–1 touch along x, 0–2 along y (centre distances = scale)."""
    p = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]) * scale
    v = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    return p, v, 0.5 * scale


@pytest.mark.parametrize("periodic", [False, True])
@pytest.mark.parametrize("scale", [1.0, 0.5, 0.25])
def test_spheres_that_exactly_touch_are_a_valid_start(periodic, scale):
    p, v, r = _touching_chain(scale)
    for gas in (EventDrivenGas(p, v, r, 1.0, BOX, periodic), SteppedGas(p, v, r, 1.0, BOX, periodic, 0.01)):
        assert np.array_equal(gas.positions, p)
    res = simulate_gas(3, radius=r, box=BOX, boundary="periodic" if periodic else "walls", positions=p,
                       velocities=v, t_equilibrate=0.0, t_measure=0.1, blocks=2)
    assert res.n == 3


@pytest.mark.parametrize("periodic", [False, True])
@pytest.mark.parametrize(("moved", "axis"), [(1, 0), (2, 1)])
def test_one_ulp_closer_than_touching_is_an_overlap(periodic, moved, axis):
    p, v, r = _touching_chain(1.0)
    p[moved, axis] = np.nextafter(1.0, 0.0)
    with pytest.raises(ValueError, match=rf"^positions overlap: spheres 0 and {moved} "):
        EventDrivenGas(p, v, r, 1.0, BOX, periodic)


@pytest.mark.parametrize("name", ["radii", "masses"])
@pytest.mark.parametrize("bad", [0, 2])
def test_a_zero_in_a_per_sphere_array_is_refused_by_index(name, bad):
    p, v, _ = _touching_chain(2.0)
    values = {"radii": [0.25, 0.25, 0.25], "masses": [1.0, 2.0, 3.0]}
    values[name][bad] = 0.0
    for make in (lambda: EventDrivenGas(p, v, values["radii"], values["masses"], BOX, False),
                 lambda: SteppedGas(p, v, values["radii"], values["masses"], BOX, False, 0.01)):
        with pytest.raises(ValueError, match=rf"^{name} must be > 0: {name}\[{bad}\] = 0\.0$"):
            make()


@pytest.mark.parametrize("radius", [5.0, 6.0])
@pytest.mark.parametrize("given_positions", [False, True])
def test_simulate_gas_refuses_spheres_that_cannot_fit_between_the_walls(radius, given_positions):
    """2 r >= box with walls: refused by simulate_gas's own check, before any start is drawn or positions are
    checked (whose errors would name other things)."""
    kwargs = dict(positions=np.zeros((1, 3)), velocities=np.ones((1, 3))) if given_positions else {}
    with pytest.raises(ValueError, match=rf"^radius must be < box/2: radius {radius!r}, box 10\.0$"):
        simulate_gas(1, radius=radius, box=10.0, t_equilibrate=0.0, t_measure=0.1, blocks=2, **kwargs)
