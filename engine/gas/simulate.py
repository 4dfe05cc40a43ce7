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
from engine.gas.periodic import check_periodic_box
from engine.gas.stepped import SteppedGas

__all__ = ["simulate_gas", "GasResult", "GAS_METHODS", "GAS_BOUNDARIES", "GasEventCapReached", "MAX_STEPS"]

class GasEventCapReached(RuntimeError):
    """The event-driven loop processed ``max_events`` events before reaching the end of the run.

    Raised by ``simulate_gas(method="events")``; raise ``max_events`` or shorten the run.
    """

GAS_METHODS = ("events", "stepped")
GAS_BOUNDARIES = ("walls", "periodic")


@dataclass
class GasResult:
    """What ``simulate_gas`` measured (after equilibration, over ``t_measure``) and the final state.

    The measurement window is split into ``blocks`` equal blocks; each observable is the mean of its block values,
    ``*_err`` the standard error of that mean.

    Attributes
    ----------
    z_virial, z_virial_err : float
        Z = P V'/(N kT) from the collision virial, and its standard error.
    z_wall, z_wall_err : float
        Z from the wall impulses; NaN for a periodic box (there is no wall).
    collision_rate, collision_rate_err : float
        Γ = 2·collisions/(n·t) per block, collisions per particle per unit time.
    z_collision_rate : float
        1 + Γ σ sqrt(π m/kT)/6.
    collisions : int
        Collisions in the window.
    energy_drift : float
        ``max |E(t) − E0| / E0`` over the block ends (E0 at t = 0, equilibration included).
    positions, velocities : numpy.ndarray, shape (n, 3), float64
        The final state.
    temperature : float
        The run's kT = 2 E0/(3n).
    packing_fraction : float
        η of the spheres in the box (``packing_fraction``).
    momentum : numpy.ndarray, shape (3,), float64
        The final total momentum Σ m v.
    scaled_speeds : numpy.ndarray, shape (blocks·n,), float64
        ``|v| sqrt(m/kT)`` of every sphere at every block end, for ``maxwell_boltzmann_test``.
    method, boundary, broad_phase : str
        The run's choices.
    dt, t_measure : float
        The frame step (stepped method) and the window's length.
    n : int
        The number of spheres.
    sigma : float
        The mean diameter 2r̄.
    seconds, collisions_per_second : float
        Wall-clock time of the measurement window, and the collisions it answered per second.
    events : int
        Events processed in the window (event-driven: collisions, wall hits, cell crossings, stale events) or
        frames (stepped).
    block_z_virial, block_z_wall, block_collision_rate : numpy.ndarray, shape (blocks,), float64
        The per-block values behind the means.
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
    if req.periodic:
        check_periodic_box(req.box, rmax, "radius")
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
    """Simulate n hard spheres in a cube and measure their compressibility Z, collision rate Γ and energy drift.

    The chapter's confined gas: elastic spheres in a cube of side ``box`` (walls at ±box/2, or periodic). Velocities
    are drawn from Maxwell–Boltzmann and scaled so that 2K/(3n) = kT exactly (zero total momentum when periodic);
    the gas runs ``t_equilibrate``, then ``t_measure`` split into ``blocks``. Two methods: "events", exact
    event-driven dynamics (``EventDrivenGas``), and "stepped", the chapter's frame loop of step ``dt``
    (``SteppedGas``: move, walls, broad phase, exact test, response).

    Parameters
    ----------
    n : int
        The number of spheres, >= 1 (>= 2 periodic).
    radius : float or array_like, shape (n,)
        Sphere radii, > 0 (keyword only, required).
    mass : float or array_like, shape (n,), default 1.0
        Masses, > 0.
    box : float, default 10.0
        The side L of the cube, > 0; 2r < L with walls, 6r (1 + 1e-12) <= L periodic (engine/gas/periodic.py).
    temperature : float, default 1.0
        kT, > 0.
    t_equilibrate : float, default 5.0
        Time run before measuring, >= 0.
    t_measure : float, default 20.0
        Length of the measurement window, > 0.
    dt : float, default 1e-3
        The frame step of the stepped method, > 0 (unused by "events"); at most ``MAX_STEPS`` frames.
    method : {"events", "stepped"}, default "events"
        See above (``GAS_METHODS``).
    broad_phase : str, default "sap"
        A name of ``BROAD_PHASES`` for the stepped method; "sap" is the incremental sweep-and-prune.
    boundary : {"walls", "periodic"}, default "walls"
        ``GAS_BOUNDARIES``.
    seed : int, default 0
        Seed of the initial state (numpy's default generator), >= 0; the same seed gives the same run.
    initial : {"auto", "random", "lattice"}, default "auto"
        Random sequential addition, a melting FCC lattice (dense fluids up to η = 0.45), or random below
        η = 0.25 and the lattice above.
    blocks : int, default 10
        Measurement blocks, >= 2.
    positions, velocities : array_like, shape (n, 3), optional
        A start state instead of ``initial`` (non-overlapping, inside the box).
    progress : callable, optional
        Called with the fraction done, in [0, 1].
    max_events : int, default 10**10
        The event method's cap, >= 1.

    Returns
    -------
    GasResult
        The measurements and the final state.

    Raises
    ------
    ValueError
        For an impossible packing, a bad argument (named), or more than ``MAX_STEPS`` frames (naming ``dt``).
    TypeError
        For a non-integer count, a non-string choice, or a ``progress`` that is not callable.
    GasEventCapReached
        When the event loop reaches ``max_events``.

    Examples
    --------
    A dilute gas of 50 spheres; an exact event-driven run conserves the energy:

    >>> import engine
    >>> result = engine.simulate_gas(50, radius=0.3, t_equilibrate=1.0, t_measure=4.0, seed=1)
    >>> result.positions.shape, result.method
    ((50, 3), 'events')
    >>> bool(result.energy_drift < 1e-9), bool(1.0 < result.z_virial < 1.2)
    (True, True)
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
