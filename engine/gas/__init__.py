"""The confined ideal gas (chapter: "comportement des particules dans un volume confiné").

- ``simulate_gas`` (engine/gas/simulate.py): the public entry point, method "stepped" (the chapter's frame
  loop, engine/gas/stepped.py) or "events" (exact event-driven, engine/gas/events.py);
- the chapter's formulas (engine/gas/elastic.py): ``collide_elastic``, ``reflect_off_wall``;
- initial states (engine/gas/initial.py) and observables (engine/gas/observables.py).
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
