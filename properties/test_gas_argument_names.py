"""Every public function of the gas names the bad argument at the start of its error ("errors start
with the argument name"): ValueError or TypeError whose message begins with the argument's name (``unknown
NAME ...`` for a choice), and, where the pattern says more (``masses\\[1\\]``), names the offending element too.

The anchor matters: a message merely containing the name (``XXspeedsXX must be ...``) would pass a plain search.
"""
from __future__ import annotations

import io
import math
import re

import numpy as np
import pytest

from engine.gas import (
    EventDrivenGas,
    SteppedGas,
    collide_elastic,
    collision_rate,
    compressibility_from_collision_rate,
    compressibility_from_virial,
    compressibility_from_walls,
    kinetic_temperature,
    maxwell_boltzmann_test,
    mean_and_standard_error,
    packing_fraction,
    radius_for_packing,
    reflect_off_wall,
    scaled_speeds,
    simulate_gas,
    speed_moment_ratio,
)
from engine.gas.command import run_gas_command

L = 10.0


def check_names(call, pattern):
    """call() raises ValueError/TypeError whose message starts with the name in ``pattern`` (its leading
    identifier; ``unknown NAME`` for choices) and matches ``pattern`` somewhere."""
    with pytest.raises((ValueError, TypeError)) as info:
        call()
    message = str(info.value)
    name = re.match(r"[A-Za-z_0-9]+", pattern).group()
    assert re.match(rf"(unknown )?{name}\b", message), message
    assert re.search(pattern, message), message


@pytest.mark.parametrize("call, name", [
    (lambda: compressibility_from_walls(-1.0, 1, 1.0, 1.0, 1.0), "wall_impulse"),
    (lambda: compressibility_from_walls(1.0, 0, 1.0, 1.0, 1.0), "n"),
    (lambda: compressibility_from_walls(1.0, 1, 0.0, 1.0, 1.0), "temperature"),
    (lambda: compressibility_from_walls(1.0, 1, 1.0, 0.0, 1.0), "side"),
    (lambda: compressibility_from_walls(1.0, 1, 1.0, 1.0, 0.0), "t"),
    (lambda: compressibility_from_virial(-1.0, 1, 1.0, 1.0), "virial"),
    (lambda: compressibility_from_virial(1.0, 0, 1.0, 1.0), "n"),
    (lambda: compressibility_from_virial(1.0, 1, -1.0, 1.0), "temperature"),
    (lambda: compressibility_from_virial(1.0, 1, 1.0, 0.0), "t"),
    (lambda: collision_rate(-1, 1, 1.0), "collisions"),
    (lambda: collision_rate(1, 0, 1.0), "n"),
    (lambda: collision_rate(1, 1, 0.0), "t"),
    (lambda: compressibility_from_collision_rate(-1.0, 1.0, 1.0, 1.0), "rate"),
    (lambda: compressibility_from_collision_rate(1.0, 0.0, 1.0, 1.0), "sigma"),
    (lambda: compressibility_from_collision_rate(1.0, 1.0, 0.0, 1.0), "mass"),
    (lambda: compressibility_from_collision_rate(1.0, 1.0, 1.0, 0.0), "temperature"),
    (lambda: kinetic_temperature(np.ones((2, 3)), [1.0, 0.0]), r"masses\[1\]"),
    (lambda: kinetic_temperature(np.ones((2, 3)), -1.0), r"masses\[0\]"),
    (lambda: kinetic_temperature(np.ones((2, 3)), [1.0, 1.0, 1.0]), "masses"),
    (lambda: kinetic_temperature(np.ones((2, 2))), "velocities"),
    (lambda: kinetic_temperature(np.ones((0, 3))), "velocities"),
    (lambda: scaled_speeds(np.ones((2, 3)), 1.0, 0.0), "temperature"),
    (lambda: scaled_speeds(np.ones((2, 3)), [2.0, 0.0]), r"masses\[1\]"),
    (lambda: scaled_speeds([[1.0, 2.0, math.nan]]), "velocities"),
    (lambda: maxwell_boltzmann_test([1.0, 2.0, -0.5]), r"speeds\[2\]"),
    (lambda: maxwell_boltzmann_test([]), "speeds"),
    (lambda: speed_moment_ratio([[1.0, 2.0]]), "speeds"),
    (lambda: mean_and_standard_error([1.0, math.inf]), "values"),
    (lambda: mean_and_standard_error([[1.0, 2.0], [3.0, 4.0]]), "values"),
])
def test_observables_name_their_bad_argument_first(call, name):
    check_names(call, name)



@pytest.mark.parametrize("kwargs, pattern", [
    (dict(n=0), "n"),
    (dict(n=2.5), "n"),
    (dict(radius=-0.1), "radius"),
    (dict(radius=[0.1, 0.2]), "radius"),
    (dict(radius=6.0), "radius"),
    (dict(mass=0.0), "mass"),
    (dict(mass=[1.0, 2.0]), "mass"),
    (dict(mass=[1.0, 0.0, 2.0]), r"mass\[1\]"),
    (dict(box=-1.0), "box"),
    (dict(temperature=0.0), "temperature"),
    (dict(temperature=math.nan), "temperature"),
    (dict(t_equilibrate=-0.1), "t_equilibrate"),
    (dict(t_measure=0.0), "t_measure"),
    (dict(dt=0.0), "dt"),
    (dict(seed=-1), "seed"),
    (dict(blocks=1), "blocks"),
    (dict(max_events=0), "max_events"),
    (dict(method="leapfrog"), "method"),
    (dict(broad_phase="kd"), "broad_phase"),
    (dict(initial="fcc"), "initial"),
    (dict(boundary="open"), "boundary"),
    (dict(progress=3), "progress"),
    (dict(positions=np.zeros((2, 3))), "positions"),
    (dict(positions=[[0, 0, 0], [4.9, 0, 0], [1, 1, 1]]), r"positions\[1\]"),
    (dict(velocities=np.zeros((3, 3))), "velocities"),
    (dict(velocities=np.ones((2, 3))), "velocities"),
    (dict(method="stepped", dt=0.15), "dt"),
    (dict(method="stepped", dt=1e-10, t_measure=1.0), "dt.*MAX_STEPS"),
])
def test_simulate_gas_names_its_bad_argument_first(kwargs, pattern):
    args = dict(n=3, radius=0.2, t_equilibrate=0.0, t_measure=0.2, blocks=2) | kwargs
    check_names(lambda: simulate_gas(**args), pattern)


@pytest.mark.parametrize("kwargs, pattern", [
    (dict(eta=0.0), "eta"), (dict(eta=0.5), "eta"), (dict(eta=math.nan), "eta"),
    (dict(n=True), "n"), (dict(n=0), "n"), (dict(n=2.0), "n"), (dict(t_measure=-1.0), "t_measure"),
    # the command hands its broad phase to simulate_gas, which refuses an unknown one (short run if it did not)
    (dict(method="stepped", broad_phase="kd", t_equilibrate=0.0, t_measure=0.01), "broad_phase"),
])
def test_command_names_its_bad_argument_first(kwargs, pattern, tmp_path):
    check_names(lambda: run_gas_command(**(dict(n=4, out=str(tmp_path / "x.png"), progress=False,
                                                stdout=io.StringIO(), stderr=io.StringIO()) | kwargs)), pattern)
    assert not (tmp_path / "x.png").exists()


@pytest.mark.parametrize("call, pattern", [
    (lambda: collide_elastic([1.0, 0], [0.0, 0, 0], 1.0, 1.0, [0.0, 0, 0], [1.0, 0, 0]), "v1"),
    (lambda: collide_elastic([1.0, 0, 0], [0.0, math.nan, 0], 1.0, 1.0, [0.0, 0, 0], [1.0, 0, 0]), "v2"),
    (lambda: collide_elastic([1.0, 0, 0], [0.0, 0, 0], 0.0, 1.0, [0.0, 0, 0], [1.0, 0, 0]), "m1"),
    (lambda: collide_elastic([1.0, 0, 0], [0.0, 0, 0], 1.0, -2.0, [0.0, 0, 0], [1.0, 0, 0]), "m2"),
    (lambda: collide_elastic([1.0, 0, 0], [0.0, 0, 0], 1.0, 1.0, [0.0, 0], [1.0, 0, 0]), "p1"),
    (lambda: collide_elastic([1.0, 0, 0], [0.0, 0, 0], 1.0, 1.0, [0.0, 0, 0], "abc"), "p2"),
    (lambda: reflect_off_wall([1.0, 0], [1.0, 0, 0]), "velocity"),
    (lambda: reflect_off_wall([1.0, math.inf, 0], [1.0, 0, 0]), "velocity"),
    (lambda: reflect_off_wall([1.0, 0, 0], [1.0, 0]), "normal"),
    (lambda: reflect_off_wall([1.0, 0, 0], [math.nan, 0, 0]), "normal"),
    (lambda: reflect_off_wall([1.0, 0, 0], [2.0, 0, 0]), "normal"),
    (lambda: packing_fraction([0.1, -0.1], L), r"radii\[1\]"),
    (lambda: packing_fraction([[0.1]], L), "radii"),
    (lambda: packing_fraction(0.1, 0.0), "box"),
    (lambda: packing_fraction(0.1, L, "open"), "boundary"),
    (lambda: packing_fraction(6.0, L), "radii"),
    (lambda: radius_for_packing(0, 0.1), "n"),
    (lambda: radius_for_packing(3, 0.0), "eta"),
    (lambda: radius_for_packing(3, 1.0), "eta"),
    (lambda: radius_for_packing(3, 0.1, -1.0), "box"),
    (lambda: radius_for_packing(3, 0.1, L, "open"), "boundary"),
    (lambda: EventDrivenGas(np.zeros((1, 3)), np.zeros((1, 3)), 0.5, 1.0, L, False).run(math.nan), "t_stop"),
    (lambda: EventDrivenGas(np.zeros((1, 3)), np.zeros((1, 3)), 0.5, 1.0, L, False).run(1.0, 0), "max_events"),
    (lambda: EventDrivenGas(np.zeros((1, 3)), np.zeros((1, 3)), 0.5, 1.0, L, 1), "periodic"),
    (lambda: SteppedGas(np.zeros((1, 3)), np.zeros((1, 3)), 0.5, 1.0, L, False, 0.0), "dt"),
    (lambda: SteppedGas(np.zeros((1, 3)), np.zeros((1, 3)), 0.5, 1.0, L, False, 0.1, "kd"), "broad_phase"),
    (lambda: SteppedGas(np.zeros((1, 3)), np.zeros((1, 3)), 0.5, 1.0, L, False, 0.1).run(-1), "steps"),
])
def test_gas_functions_name_their_bad_argument_first(call, pattern):
    check_names(call, pattern)


