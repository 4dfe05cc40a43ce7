"""The confined ideal gas (chapter: "comportement des particules dans un volume confiné").

- ``simulate_gas`` (engine/gas/simulate.py): the public entry point, method "stepped" (the chapter's frame
  loop, engine/gas/stepped.py) or "events" (exact event-driven, engine/gas/events.py);
- the chapter's formulas (engine/gas/elastic.py): ``collide_elastic``, ``reflect_off_wall``;
- initial states (engine/gas/initial.py) and observables (engine/gas/observables.py).

.. _gas-notation:

Notation
--------
The observables' arguments use the kinetic theory's symbols, all plain Python floats (or ints) unless said:

- ``n`` (N): the number of spheres, an int >= 1;
- ``temperature`` (kT): the temperature in energy units, > 0 (velocities are drawn so that 2K/(3N) = kT);
- ``t``: the length of the measurement window, > 0;
- ``side`` (L'): the side of the cube the centres can reach, L − 2r with walls, L when periodic;
- ``sigma`` (σ = 2r): the sphere diameter; ``eta`` (η): the packing fraction Σ π σ³/6 / V';
- Z = P V'/(N kT): the compressibility factor, 1 for the ideal gas.

A bad value raises ``ValueError`` naming the argument (``TypeError`` for a non-integer count).
"""
from __future__ import annotations

from engine.gas.elastic import collide_elastic, reflect_off_wall
from engine.gas.events import EventDrivenGas
from engine.gas.initial import packing_fraction, radius_for_packing
from engine.gas.observables import (
    carnahan_starling,
    collision_rate,
    compressibility_from_collision_rate,
    compressibility_from_virial,
    compressibility_from_walls,
    kinetic_temperature,
    maxwell_boltzmann_test,
    mean_and_standard_error,
    plot_speed_histogram,
    scaled_speeds,
    speed_moment_ratio,
)
from engine.gas.simulate import GAS_BOUNDARIES, GAS_METHODS, MAX_STEPS, GasEventCapReached, GasResult, simulate_gas
from engine.gas.stepped import SteppedGas

__all__ = [
    "simulate_gas",
    "GasResult",
    "GAS_METHODS",
    "GAS_BOUNDARIES",
    "GasEventCapReached",
    "MAX_STEPS",
    "collide_elastic",
    "reflect_off_wall",
    "EventDrivenGas",
    "SteppedGas",
    "packing_fraction",
    "radius_for_packing",
    "carnahan_starling",
    "collision_rate",
    "compressibility_from_collision_rate",
    "compressibility_from_virial",
    "compressibility_from_walls",
    "kinetic_temperature",
    "maxwell_boltzmann_test",
    "mean_and_standard_error",
    "plot_speed_histogram",
    "scaled_speeds",
    "speed_moment_ratio",
]
