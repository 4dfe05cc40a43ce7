"""``simulate_gas``: the confined ideal gas of the chapter, run by the stepped frame loop or event by event.

Public contract: simulate_gas(n, *, radius, mass=1.0, box=10.0, temperature=1.0,
t_equilibrate=5.0, t_measure=20.0, dt=1e-3, method="events" | "stepped", broad_phase="sap",
boundary="walls" | "periodic", seed=0) returns an object with z_virial, z_wall (NaN for periodic),
collision_rate (Γ = 2·collisions/(n·t_measure)), collisions, energy_drift (max |E(t) − E0|/E0), positions and
velocities (final, (n, 3)). The measurement window is split into ``blocks`` equal blocks; each observable is the
mean of its block values, with the standard error of that mean.
"""
from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from engine._validate import MAX_STEPS, as_choice, as_count, as_float_array, as_nonnegative, as_positive
from engine.gas import observables as obs
from engine.gas.events import EventDrivenGas
from engine.gas.initial import (
    check_start_positions,
    draw_velocities,
    packing_fraction,
    per_sphere,
    place_spheres,
    reachable_side,
)
from engine.gas.stepped import SteppedGas

__all__ = ["simulate_gas", "GasResult", "GAS_METHODS", "GAS_BOUNDARIES", "GasEventCapReached", "MAX_STEPS"]

class GasEventCapReached(RuntimeError):
    """The event-driven loop processed ``max_events`` events before reaching the end of the run."""

GAS_METHODS = ("events", "stepped")
GAS_BOUNDARIES = ("walls", "periodic")


@dataclass
class GasResult:
    """What ``simulate_gas`` measured (after equilibration, over ``t_measure``) and the final state.

    ``z_*`` are compressibilities Z = PV'/(NkT) with their standard errors (``*_err``, over the blocks); z_wall is NaN
    for periodic boxes (there is no wall). z_collision_rate = 1 + Γσ sqrt(πm/kT)/6. energy_drift is
    ``max |E(t) − E0| / E0`` over the block ends (E0 at t = 0, equilibration included). momentum: total m v (3,).
    scaled_speeds: ``|v| sqrt(m/kT)`` of every sphere at every block end ((blocks·n,)), for the Maxwell test.
    events: events processed in the window (event-driven: collisions, wall hits, cell crossings, stale events)
    or frames (stepped). seconds: wall-clock time of the measurement window; collisions_per_second from it.
    """

    z_virial: float
    z_wall: float
    collision_rate: float
    collisions: int
    energy_drift: float
    positions: np.ndarray
    velocities: np.ndarray
    z_virial_err: float
    z_wall_err: float
    collision_rate_err: float
    z_collision_rate: float
    temperature: float
    packing_fraction: float
    momentum: np.ndarray
    scaled_speeds: np.ndarray
    method: str
    boundary: str
    broad_phase: str
    dt: float
    t_measure: float
    n: int
    sigma: float
    seconds: float
    collisions_per_second: float
    events: int
    block_z_virial: np.ndarray = field(repr=False)
    block_z_wall: np.ndarray = field(repr=False)
    block_collision_rate: np.ndarray = field(repr=False)


class _Request(NamedTuple):
    """The validated arguments of one ``simulate_gas`` call."""

    n: int
    method: str
    boundary: str
    broad_phase: str
    initial: str
    radii: np.ndarray
    masses: np.ndarray
    box: float
    kt: float
    t_eq: float
    t_meas: float
    dt: float
    seed: int
    blocks: int
    max_events: int
    progress: Callable[[float], object] | None

    @property
    def periodic(self) -> bool:
        return self.boundary == "periodic"


def _validate(n, radius, mass, box, temperature, t_equilibrate, t_measure, dt, method, broad_phase, boundary, seed,
              initial, blocks, progress, max_events) -> _Request:
    """Every scalar argument checked and named (ValueError/TypeError), in the order of the signature."""
    from engine.broadphase import BROAD_PHASES

    n = as_count(n, "n", 1)
    method = as_choice(method, "method", GAS_METHODS)
    boundary = as_choice(boundary, "boundary", GAS_BOUNDARIES)
    broad_phase = as_choice(broad_phase, "broad_phase", BROAD_PHASES)
    initial = as_choice(initial, "initial", ("auto", "random", "lattice"))
    if boundary == "periodic" and n < 2:
        raise ValueError("a periodic gas needs n >= 2 (zero total momentum leaves one sphere at rest)")
    req = _Request(n, method, boundary, broad_phase, initial, per_sphere(radius, "radius", n),
                   per_sphere(mass, "mass", n), as_positive(box, "box"), as_positive(temperature, "temperature"),
                   as_nonnegative(t_equilibrate, "t_equilibrate"), as_positive(t_measure, "t_measure"),
                   as_positive(dt, "dt"), as_count(seed, "seed", 0), as_count(blocks, "blocks", 2),
                   as_count(max_events, "max_events", 1), progress)
    total = req.t_eq + req.t_meas
    if method == "stepped" and total / req.dt > MAX_STEPS:
        raise ValueError(f"dt = {req.dt!r} asks for {total / req.dt:.3g} frames over t_equilibrate + t_measure "
                         f"= {total!r}; the stepped method is capped at MAX_STEPS = {MAX_STEPS}")
    if progress is not None and not callable(progress):
        raise TypeError("progress must be a callable or None")
    rmax = float(req.radii.max())
    if not req.periodic and 2.0 * rmax >= req.box:
        raise ValueError(f"radius must be < box/2: radius {rmax!r}, box {req.box!r}")
    if req.periodic and 6.0 * rmax > req.box:
        raise ValueError(f"a periodic box must be at least 3 diameters wide: radius {rmax!r}, box {req.box!r}")
    return req


def _start(req: _Request, positions, velocities):
    """The gas of the requested method at its start: given or drawn positions and velocities (seeded)."""
    rng = np.random.default_rng(req.seed)
    if positions is None:
        pos = place_spheres(req.n, req.radii, req.box, req.boundary, rng, req.initial)
    else:
        pos = check_start_positions(positions, req.radii, req.box, req.periodic)
    if velocities is None:
        vel = draw_velocities(req.masses, req.kt, req.boundary, rng)
    else:
        vel = as_float_array(velocities, "velocities", shape=(req.n, 3))
        if not np.any(vel):
            raise ValueError("velocities are all zero: the gas has no temperature")
    if req.method == "stepped":
        if req.dt * req.blocks > req.t_meas:
            raise ValueError(f"dt = {req.dt!r} is too long for t_measure = {req.t_meas!r} split into "
                             f"{req.blocks} blocks")
        return SteppedGas(pos, vel, req.radii, req.masses, req.box, req.periodic, req.dt, req.broad_phase)
    return EventDrivenGas(pos, vel, req.radii, req.masses, req.box, req.periodic)


def _run_events(gas: EventDrivenGas, t_stop: float, max_events: int) -> None:
    """Advance the event-driven gas to t_stop under the run's event cap (counted over the whole run)."""
    left = max_events - gas.processed
    if left <= 0 or gas.run(t_stop, max_events=left) >= left and gas.time < t_stop:
        raise GasEventCapReached(f"the event loop reached max_events = {max_events} before t = {t_stop!r}")


class _Drift:
    """max |E(t) − E0|/E0 over the times it is given E(t)."""

    def __init__(self, e0: float):
        self.e0 = e0
        self.value = 0.0

    def see(self, e: float) -> None:
        self.value = max(self.value, abs(e - self.e0) / self.e0)


def _equilibrate(gas, req: _Request, drift: _Drift) -> None:
    """Run t_equilibrate (stepped: in chunks of a 20th, events: in 10 stops), checking the energy at each stop."""
    total = req.t_eq + req.t_meas
    if req.method == "stepped":
        eq_steps = int(round(req.t_eq / req.dt))
        chunk = max(1, eq_steps // 20)
        done_steps = 0
        while done_steps < eq_steps:
            k = min(chunk, eq_steps - done_steps)
            gas.run(k)
            done_steps += k
            drift.see(gas.kinetic_energy())
            if req.progress is not None:
                req.progress(min(1.0, done_steps * req.dt / total))
        return
    for k in range(1, 11):
        _run_events(gas, req.t_eq * k / 10.0, req.max_events)
        drift.see(gas.kinetic_energy())
        if req.progress is not None and req.t_eq > 0.0:
            req.progress(req.t_eq * k / 10.0 / total)


class _Blocks(NamedTuple):
    """What the measurement blocks gave: per-block Z (virial, wall), rates and speeds; totals; block length."""

    zv: np.ndarray
    zw: np.ndarray
    rates: np.ndarray
    speeds: np.ndarray
    collisions: int
    events: int
    t_block: float
    seconds: float


def _measure(gas, req: _Request, drift: _Drift, kt_run: float) -> _Blocks:
    """The measurement window: ``blocks`` equal blocks, each one's sums put through the observables' formulas."""
    n = req.n
    side = reachable_side(req.box, float(req.radii.mean()), req.boundary)
    if req.method == "stepped":
        block_steps = max(1, int(round(req.t_meas / req.blocks / req.dt)))
        t_block = block_steps * req.dt
    else:
        t_block = req.t_meas / req.blocks
    zv, zw, rates, speeds = [], [], [], []
    collisions = events = 0
    started = time.perf_counter()
    for b in range(req.blocks):
        gas.reset_sums()
        if req.method == "stepped":
            gas.run(block_steps)
        else:
            _run_events(gas, req.t_eq + (b + 1) * t_block, req.max_events)
            events += gas.events
        drift.see(gas.kinetic_energy())
        collisions += gas.collisions
        zv.append(1.0 + gas.virial / (3.0 * t_block * n * kt_run))
        zw.append(gas.wall_impulse * side / (6.0 * t_block * n * kt_run) if not req.periodic else math.nan)
        rates.append(2.0 * gas.collisions / (n * t_block))
        speeds.append(np.sqrt((gas.vel_view() ** 2).sum(axis=1) * gas.mass / kt_run))
        if req.progress is not None:
            req.progress((req.t_eq + (b + 1) * t_block) / (req.t_eq + req.blocks * t_block))
    if req.method == "stepped":
        events = int(round(req.blocks * t_block / req.dt))
    return _Blocks(np.array(zv), np.array(zw), np.array(rates), np.concatenate(speeds), int(collisions),
                   int(events), t_block, time.perf_counter() - started)


def _result(gas, req: _Request, blocks: _Blocks, drift: _Drift, kt_run: float) -> GasResult:
    z_virial, z_virial_err = obs.mean_and_standard_error(blocks.zv)
    if req.periodic:
        z_wall, z_wall_err = math.nan, math.nan
    else:
        z_wall, z_wall_err = obs.mean_and_standard_error(blocks.zw)
    rate, rate_err = obs.mean_and_standard_error(blocks.rates)
    r_mean = float(req.radii.mean())
    m_mean = float(req.masses.mean())
    stepped = req.method == "stepped"
    vel_out = gas.velocities
    return GasResult(
        z_virial=z_virial, z_wall=z_wall, collision_rate=rate, collisions=blocks.collisions,
        energy_drift=float(drift.value), positions=gas.positions, velocities=vel_out, z_virial_err=z_virial_err,
        z_wall_err=z_wall_err, collision_rate_err=rate_err,
        z_collision_rate=1.0 + rate * 2.0 * r_mean * math.sqrt(math.pi * m_mean / kt_run) / 6.0,
        temperature=kt_run, packing_fraction=packing_fraction(req.radii, req.box, req.boundary),
        momentum=(gas.masses[:, None] * vel_out).sum(axis=0), scaled_speeds=blocks.speeds, method=req.method,
        boundary=req.boundary, broad_phase=req.broad_phase if stepped else "cells", dt=req.dt if stepped else 0.0,
        t_measure=req.blocks * blocks.t_block, n=req.n, sigma=2.0 * r_mean, seconds=blocks.seconds,
        collisions_per_second=blocks.collisions / blocks.seconds if blocks.seconds > 0.0 else 0.0,
        events=blocks.events, block_z_virial=blocks.zv, block_z_wall=blocks.zw, block_collision_rate=blocks.rates,
    )


def simulate_gas(n, *, radius, mass=1.0, box=10.0, temperature=1.0, t_equilibrate=5.0, t_measure=20.0, dt=1e-3,
                 method="events", broad_phase="sap", boundary="walls", seed=0, initial="auto", blocks=10,
                 positions=None, velocities=None, progress=None, max_events=10**10) -> GasResult:
    """Simulate n hard spheres in a cube of side ``box`` (walls at ±box/2, or periodic) and measure Z, Γ, drift.

    n: number of spheres; radius, mass: positive scalars or (n,) arrays; temperature kT > 0 (velocities drawn
    from Maxwell–Boltzmann and scaled to exactly 2K/(3n) = kT; zero total momentum when periodic).
    method: "events" (exact event-driven; ``dt`` unused) or "stepped" (the chapter's frame loop with step
    ``dt`` and broad phase ``broad_phase``, a name of ``BROAD_PHASES``, "sap" = incremental sweep-and-prune).
    initial: "auto", "random" or "lattice" (a melting FCC lattice; dense fluids up to η = 0.45); or give
    ``positions`` (n, 3) (non-overlapping, inside the box) and ``velocities`` (n, 3) to start from a given
    state. blocks >= 2 measurement blocks. progress: an optional callable receiving the fraction done in [0, 1].
    Raises ValueError for an impossible packing or bad arguments. Iteration caps: the stepped method refuses more
    than ``MAX_STEPS`` frames (ValueError naming dt); the event loop stops after ``max_events`` events and raises
    ``GasEventCapReached``.
    """
    req = _validate(n, radius, mass, box, temperature, t_equilibrate, t_measure, dt, method, broad_phase, boundary,
                    seed, initial, blocks, progress, max_events)
    gas = _start(req, positions, velocities)
    e0 = gas.kinetic_energy()
    kt_run = 2.0 * e0 / (3.0 * req.n)
    drift = _Drift(e0)
    _equilibrate(gas, req, drift)
    measured = _measure(gas, req, drift, kt_run)
    return _result(gas, req, measured, drift, kt_run)
