"""``simulate_gas``: the confined ideal gas of the chapter, run by the stepped frame loop or event by event.

Public contract (DESIGN.md section 3): simulate_gas(n, *, radius, mass=1.0, box=10.0, temperature=1.0,
t_equilibrate=5.0, t_measure=20.0, dt=1e-3, method="events" | "stepped", broad_phase="sap",
boundary="walls" | "periodic", seed=0) returns an object with z_virial, z_wall (NaN for periodic),
collision_rate (Γ = 2·collisions/(n·t_measure)), collisions, energy_drift (max |E(t) − E0|/E0), positions and
velocities (final, (n, 3)). The measurement window is split into ``blocks`` equal blocks; each observable is the
mean of its block values, with the standard error of that mean.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

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

    z_* are compressibilities Z = PV'/(NkT) with their standard errors (*_err, over the blocks); z_wall is NaN
    for periodic boxes (there is no wall). z_collision_rate = 1 + Γσ sqrt(πm/kT)/6. energy_drift is
    max |E(t) − E0|/E0 over the block ends (E0 at t = 0, equilibration included). momentum: total m v (3,).
    scaled_speeds: |v| sqrt(m/kT) of every sphere at every block end ((blocks·n,)), for the Maxwell test.
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


def _run_events(gas: EventDrivenGas, t_stop: float, max_events: int) -> None:
    """Advance the event-driven gas to t_stop under the run's event cap (counted over the whole run)."""
    left = max_events - gas.processed
    if left <= 0 or gas.run(t_stop, max_events=left) >= left and gas.time < t_stop:
        raise GasEventCapReached(f"the event loop reached max_events = {max_events} before t = {t_stop!r}")


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
    from engine.broadphase import BROAD_PHASES

    n = as_count(n, "n", 1)
    method = as_choice(method, "method", GAS_METHODS)
    boundary = as_choice(boundary, "boundary", GAS_BOUNDARIES)
    broad_phase = as_choice(broad_phase, "broad_phase", BROAD_PHASES)
    initial = as_choice(initial, "initial", ("auto", "random", "lattice"))
    periodic = boundary == "periodic"
    if periodic and n < 2:
        raise ValueError("a periodic gas needs n >= 2 (zero total momentum leaves one sphere at rest)")
    radii = per_sphere(radius, "radius", n)
    masses = per_sphere(mass, "mass", n)
    box = as_positive(box, "box")
    kt = as_positive(temperature, "temperature")
    t_eq = as_nonnegative(t_equilibrate, "t_equilibrate")
    t_meas = as_positive(t_measure, "t_measure")
    dt = as_positive(dt, "dt")
    seed = as_count(seed, "seed", 0)
    blocks = as_count(blocks, "blocks", 2)
    max_events = as_count(max_events, "max_events", 1)
    if method == "stepped" and (t_eq + t_meas) / dt > MAX_STEPS:
        raise ValueError(f"dt = {dt!r} asks for {(t_eq + t_meas) / dt:.3g} frames over t_equilibrate + t_measure "
                         f"= {t_eq + t_meas!r}; the stepped method is capped at MAX_STEPS = {MAX_STEPS}")
    if progress is not None and not callable(progress):
        raise TypeError("progress must be a callable or None")
    rmax = float(radii.max())
    if not periodic and 2.0 * rmax >= box:
        raise ValueError(f"radius must be < box/2: radius {rmax!r}, box {box!r}")
    if periodic and 6.0 * rmax > box:
        raise ValueError(f"a periodic box must be at least 3 diameters wide: radius {rmax!r}, box {box!r}")

    rng = np.random.default_rng(seed)
    if positions is None:
        pos = place_spheres(n, radii, box, boundary, rng, initial)
    else:
        pos = check_start_positions(positions, radii, box, periodic)
    if velocities is None:
        vel = draw_velocities(masses, kt, boundary, rng)
    else:
        vel = as_float_array(velocities, "velocities", shape=(n, 3))
        if not np.any(vel):
            raise ValueError("velocities are all zero: the gas has no temperature")
    if method == "stepped":
        if dt * blocks > t_meas:
            raise ValueError(f"dt = {dt!r} is too long for t_measure = {t_meas!r} split into {blocks} blocks")
        gas = SteppedGas(pos, vel, radii, masses, box, periodic, dt, broad_phase)
    else:
        gas = EventDrivenGas(pos, vel, radii, masses, box, periodic)

    e0 = gas.kinetic_energy()
    kt_run = 2.0 * e0 / (3.0 * n)
    drift = 0.0
    r_mean = float(radii.mean())
    side = reachable_side(box, r_mean, boundary)
    eta = packing_fraction(radii, box, boundary)

    total = t_eq + t_meas
    started = time.perf_counter()
    if method == "stepped":
        eq_steps = int(round(t_eq / dt))
        block_steps = max(1, int(round(t_meas / blocks / dt)))
        t_block = block_steps * dt
        done_steps = 0
        chunk = max(1, eq_steps // 20)
        while done_steps < eq_steps:
            k = min(chunk, eq_steps - done_steps)
            gas.run(k)
            done_steps += k
            drift = max(drift, abs(gas.kinetic_energy() - e0) / e0)
            if progress is not None:
                progress(min(1.0, done_steps * dt / total))
    else:
        t_block = t_meas / blocks
        for k in range(1, 11):
            _run_events(gas, t_eq * k / 10.0, max_events)
            drift = max(drift, abs(gas.kinetic_energy() - e0) / e0)
            if progress is not None and t_eq > 0.0:
                progress(t_eq * k / 10.0 / total)

    zv, zw, rates, speeds = [], [], [], []
    collisions = 0
    events = 0
    measure_start = time.perf_counter()
    for b in range(blocks):
        gas.reset_sums()
        if method == "stepped":
            gas.run(block_steps)
        else:
            _run_events(gas, t_eq + (b + 1) * t_block, max_events)
            events += gas.events
        e = gas.kinetic_energy()
        drift = max(drift, abs(e - e0) / e0)
        collisions += gas.collisions
        zv.append(1.0 + gas.virial / (3.0 * t_block * n * kt_run))
        zw.append(gas.wall_impulse * side / (6.0 * t_block * n * kt_run) if not periodic else math.nan)
        rates.append(2.0 * gas.collisions / (n * t_block))
        speeds.append(np.sqrt((gas.vel_view() ** 2).sum(axis=1) * gas.mass / kt_run))
        if progress is not None:
            progress((t_eq + (b + 1) * t_block) / (t_eq + blocks * t_block))
    measure_seconds = time.perf_counter() - measure_start
    del started

    zv = np.array(zv)
    zw = np.array(zw)
    rates = np.array(rates)
    z_virial, z_virial_err = obs.mean_and_standard_error(zv)
    if periodic:
        z_wall, z_wall_err = math.nan, math.nan
    else:
        z_wall, z_wall_err = obs.mean_and_standard_error(zw)
    rate, rate_err = obs.mean_and_standard_error(rates)
    m_mean = float(masses.mean())
    vel_out = gas.velocities
    return GasResult(
        z_virial=z_virial, z_wall=z_wall, collision_rate=rate, collisions=int(collisions), energy_drift=float(drift),
        positions=gas.positions, velocities=vel_out, z_virial_err=z_virial_err, z_wall_err=z_wall_err,
        collision_rate_err=rate_err,
        z_collision_rate=1.0 + rate * 2.0 * r_mean * math.sqrt(math.pi * m_mean / kt_run) / 6.0,
        temperature=kt_run, packing_fraction=eta, momentum=(gas.masses[:, None] * vel_out).sum(axis=0),
        scaled_speeds=np.concatenate(speeds), method=method, boundary=boundary,
        broad_phase=broad_phase if method == "stepped" else "cells", dt=dt if method == "stepped" else 0.0,
        t_measure=blocks * t_block, n=n, sigma=2.0 * r_mean, seconds=measure_seconds,
        collisions_per_second=collisions / measure_seconds if measure_seconds > 0.0 else 0.0,
        events=int(events) if method == "events" else int(round(blocks * t_block / dt)),
        block_z_virial=zv, block_z_wall=zw, block_collision_rate=rates,
    )
