"""The gas runs the same with numba's JIT disabled as compiled, bit for bit.

The mutation run (properties/MUTATION.md) interprets every kernel (``NUMBA_DISABLE_JIT=1``), so a kernel that only
numba can run (for example attribute access on a structured record, which numpy's ``numpy.void`` rows lack) stops
the whole gas area there while the compiled suite stays green. Here a child process with the JIT disabled runs a
few small gases (both methods, walls and periodic, both partner searches of the event-driven gas, the event cap),
and every number it returns must equal the compiled run's: the same float64 bits, the same Python types.
"""
from __future__ import annotations

import os
import pickle
import subprocess
import sys
from pathlib import Path

import numba
import numpy as np

import engine
from engine.gas import EventDrivenGas, GasEventCapReached, SteppedGas, radius_for_packing, simulate_gas
from engine.gas.initial import draw_velocities, place_spheres

#: the checkout whose ``engine`` this process imported (the child must import the same one)
ROOT = Path(engine.__file__).resolve().parents[1]
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


def _runs_in_child(disable_jit: bool) -> dict:
    env = {**os.environ, "NUMBA_DISABLE_JIT": "1" if disable_jit else "0",
           "PYTHONPATH": os.pathsep.join([str(ROOT), *filter(None, [os.environ.get("PYTHONPATH")])])}
    code = ("import pickle, sys; from properties.test_gas_without_jit import gas_runs; "
            "sys.stdout.buffer.write(pickle.dumps(gas_runs()))")
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=env, capture_output=True, timeout=600)
    assert done.returncode == 0, done.stderr.decode(errors="replace")[-3000:]
    return pickle.loads(done.stdout)


def assert_same_bits(a, b, where: str) -> None:
    """a and b are the same value: same type, same float64 bits (NaN included), arrays of the same dtype."""
    assert type(a) is type(b), f"{where}: {type(a).__name__} compiled, {type(b).__name__} interpreted"
    if isinstance(a, dict):
        assert a.keys() == b.keys(), where
        for k in a:
            assert_same_bits(a[k], b[k], f"{where}.{k}")
    elif isinstance(a, np.ndarray):
        assert a.dtype == b.dtype and a.shape == b.shape, where
        assert a.tobytes() == b.tobytes(), f"{where}: first difference at {np.flatnonzero(a.ravel() != b.ravel())[:1]}"
    elif isinstance(a, float):
        assert np.float64(a).tobytes() == np.float64(b).tobytes(), f"{where}: {a!r} compiled, {b!r} interpreted"
    else:
        assert a == b, f"{where}: {a!r} compiled, {b!r} interpreted"


def test_gas_without_the_jit_equals_the_compiled_gas_bit_for_bit():
    compiled = gas_runs() if not numba.config.DISABLE_JIT else _runs_in_child(disable_jit=False)
    interpreted = _runs_in_child(disable_jit=True)
    assert compiled.pop("jit_disabled") is False
    assert interpreted.pop("jit_disabled") is True
    # the runs are not trivial: collisions, wall hits, cell crossings and stale events all happened
    walls, periodic = compiled["EventDrivenGas/cells/walls"], compiled["EventDrivenGas/cells/periodic"]
    assert min(walls["collisions"], walls["wall_hits"], walls["crossings"], periodic["collisions"]) > 0
    assert walls["stale"] + periodic["stale"] > 0
    assert compiled["SteppedGas/walls"]["collisions"] > 0 and compiled["event cap"] != "not reached"
    assert_same_bits(compiled, interpreted, "runs")
