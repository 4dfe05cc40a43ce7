"""The gas runs the same with numba's JIT disabled as compiled, bit for bit.

The mutation run (properties/MUTATION.md) interprets every kernel (``NUMBA_DISABLE_JIT=1``), so a kernel that only
numba can run (for example attribute access on a structured record, which numpy's ``numpy.void`` rows lack) stops
the whole gas area there while the compiled suite stays green. Here a child process with the JIT disabled runs a
few small gases (both methods, walls and periodic, both partner searches of the event-driven gas, the event cap),
and every number it returns must equal the compiled run's: the same float64 bits, the same Python types.
"""
from __future__ import annotations

import numba
import numpy as np

from engine.gas import EventDrivenGas, GasEventCapReached, SteppedGas, radius_for_packing, simulate_gas
from engine.gas.initial import draw_velocities, place_spheres
from properties.jit_off import assert_same_bits, runs_in_child

#: GasResult fields that are clock readings, not results
CLOCK_FIELDS = ("seconds", "collisions_per_second")


def _scene(n, eta, boundary, seed):
    rng = np.random.default_rng(seed)
    r = radius_for_packing(n, eta, 6.0, boundary) * rng.uniform(0.8, 1.0, n)
    m = rng.uniform(0.5, 2.0, n)
    return place_spheres(n, r, 6.0, boundary, rng), draw_velocities(m, 1.0, boundary, rng), r, m


def _gas_state(gas):
    """Everything a gas reports, in the caller's order."""
    out = {"positions": gas.positions, "velocities": gas.velocities, "masses": gas.masses,
           "kinetic_energy": gas.kinetic_energy(), "collisions": gas.collisions, "wall_hits": gas.wall_hits,
           "wall_impulse": gas.wall_impulse, "virial": gas.virial, "time": gas.time}
    for name in ("events", "crossings", "stale", "processed", "overlapping"):
        if hasattr(gas, name):
            out[name] = getattr(gas, name)
    return out


def gas_runs() -> dict:
    """Small runs that reach every kernel of engine/gas: a name → the values each one reports."""
    runs: dict = {"jit_disabled": bool(numba.config.DISABLE_JIT)}
    for boundary in ("walls", "periodic"):
        for method in ("events", "stepped"):
            res = simulate_gas(40, radius=radius_for_packing(40, 0.15, 6.0, boundary), box=6.0, t_equilibrate=0.3,
                               t_measure=0.6, dt=0.05, method=method, boundary=boundary, seed=5, blocks=3)
            runs[f"simulate_gas/{method}/{boundary}"] = {k: v for k, v in vars(res).items() if k not in CLOCK_FIELDS}
    for boundary in ("walls", "periodic"):
        p, v, r, m = _scene(60, 0.25, boundary, 11)
        for search in ("cells", "neighbour_lists"):
            gas = EventDrivenGas(p, v, r, m, 6.0, boundary == "periodic", search=search)
            gas.run(0.4)
            gas.reset_sums()
            gas.run(2.0)
            runs[f"EventDrivenGas/{search}/{boundary}"] = _gas_state(gas)
        gas = SteppedGas(p, v, r, m, 6.0, boundary == "periodic", 0.01)
        gas.run(15)
        runs[f"SteppedGas/{boundary}"] = _gas_state(gas)
    try:
        simulate_gas(40, radius=0.3, box=6.0, t_equilibrate=1.0, t_measure=1.0, seed=2, max_events=50)
        runs["event cap"] = "not reached"
    except GasEventCapReached as exc:
        runs["event cap"] = str(exc)
    return runs


def test_gas_without_the_jit_equals_the_compiled_gas_bit_for_bit():
    here = "properties.test_gas_without_jit"
    compiled = gas_runs() if not numba.config.DISABLE_JIT else runs_in_child(here, "gas_runs", disable_jit=False)
    interpreted = runs_in_child(here, "gas_runs")
    assert compiled.pop("jit_disabled") is False
    assert interpreted.pop("jit_disabled") is True
    # the runs are not trivial: collisions, wall hits, cell crossings and stale events all happened
    walls, periodic = compiled["EventDrivenGas/cells/walls"], compiled["EventDrivenGas/cells/periodic"]
    assert min(walls["collisions"], walls["wall_hits"], walls["crossings"], periodic["collisions"]) > 0
    assert walls["stale"] + periodic["stale"] > 0
    assert compiled["SteppedGas/walls"]["collisions"] > 0 and compiled["event cap"] != "not reached"
    assert_same_bits(compiled, interpreted, "runs")
