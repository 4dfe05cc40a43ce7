"""Soak of the exact event-driven gas (engine.gas.EventDrivenGas): millions of collisions, checked along the run.

The chapter's confined gas, run event by event for a long time, must keep the three things that make it exact:
- energy: elastic collisions and specular walls conserve K = Σ m v²/2, so the drift |K(t) − K0|/K0 stays
  at round-off (≤ 1e-10 after 1e7 collisions);
- no overlap: every pair of centres stays at least σ_ij (1 − 1e-9) apart (σ_ij = r_i + r_j);
- no sphere leaves the box: with walls every centre stays within L/2 − r_i (+ 1e-9 σ_i) of the centre of the
  box on each axis; periodic centres stay wrapped in [−L/2, L/2] (± 1e-9 σ_i);
and, periodic, the total momentum is conserved (no wall pushes). Checked every 1/CHECKS of the run with
independent code: scipy's cKDTree (minimum image when periodic) for the overlaps, math.fsum for the energy, on
the public state (``positions``, ``velocities``, ``masses``, ``collisions``, ``time``).

Length: CI runs 1e5 collisions per case (seconds; 3e3 with the kernels interpreted, NUMBA_DISABLE_JIT=1, as
mutation testing runs them). The long soak, 1e7 collisions per case, runs with
``SOAK=long`` (or under the ``nightly`` Hypothesis profile): ``SOAK=long pytest properties -m soak -s`` or
``tox -e soak``; each case prints its figures (collisions, wall time, max drift, max overlap, max excursion).
"""
from __future__ import annotations

import math
import os
import time

import numpy as np
import pytest
from scipy.spatial import cKDTree

from engine.gas import EventDrivenGas, radius_for_packing

LONG = os.environ.get("SOAK", "").lower() == "long" or os.environ.get("HYPOTHESIS_PROFILE") == "nightly"
INTERPRETED = os.environ.get("NUMBA_DISABLE_JIT", "0") not in ("", "0")  # mutation testing: kernels in Python
COLLISIONS = 10_000_000 if LONG else 3_000 if INTERPRETED else 100_000
CHECKS = 100 if LONG else 10
ENERGY_DRIFT = 1e-10  # relative
OVERLAP = 1e-9  # fraction of σ_ij
EXCURSION = 1e-9  # fraction of σ_i beyond the box
MOMENTUM_DRIFT = 1e-10  # periodic: |P(t) − P0| per component, relative to Σ m |v|

pytestmark = pytest.mark.soak

# (boundary, n, packing fraction of the large size, two sizes): dense gases, walled and periodic, one size or two
# (two sizes and masses: the mass weights of the collision response matter, and the momentum check sees them)
CASES = {
    "walls": ("walls", 1000, 0.30, False),
    "periodic": ("periodic", 1000, 0.30, False),
    "walls-two-sizes": ("walls", 729, 0.20, True),
    "periodic-two-sizes": ("periodic", 1000, 0.30, True),
}


def lattice_gas(boundary: str, n: int, eta: float, polydisperse: bool, seed: int = 0):
    """n spheres on a simple cubic lattice (side k = n^(1/3)) filling the reachable cube, random velocities.

    Monodisperse: the radius of packing fraction eta (radius_for_packing). Two sizes: half the spheres 0.6 of that
    radius, masses ∝ r³. The lattice spacing exceeds the largest diameter, so the start has no overlap."""
    box = 10.0
    k = round(n ** (1 / 3))
    assert k**3 == n
    r = radius_for_packing(n, eta, box, boundary)
    rng = np.random.default_rng(seed)
    radii = np.full(n, r)
    if polydisperse:
        radii[rng.permutation(n)[: n // 2]] = 0.6 * r
    masses = (radii / r) ** 3
    side = box - 2.0 * radii.max() if boundary == "walls" else box
    spacing = side / k
    assert spacing > 2.0 * radii.max() * 1.01, "the lattice would overlap"
    axis = -side / 2.0 + spacing * (np.arange(k) + 0.5)
    positions = np.stack(np.meshgrid(axis, axis, axis, indexing="ij"), axis=-1).reshape(n, 3)
    velocities = rng.normal(size=(n, 3)) / np.sqrt(masses)[:, None]
    if boundary == "periodic":
        velocities -= (masses[:, None] * velocities).sum(axis=0) / masses.sum()  # zero total momentum
    return EventDrivenGas(positions, velocities, radii, masses, box, boundary == "periodic"), radii


def kinetic_energy(gas) -> float:
    v = gas.velocities
    return math.fsum((0.5 * gas.masses * np.einsum("ij,ij->i", v, v)).tolist())


def worst_overlap(positions, radii, box, periodic) -> float:
    """max over near pairs of (σ_ij − |c_i − c_j|)/σ_ij: > 0 is an overlap; the closest pair when negative."""
    if periodic:
        tree = cKDTree(np.mod(positions + box / 2.0, box), boxsize=box)
    else:
        tree = cKDTree(positions)
    pairs = tree.query_pairs(2.0 * radii.max() * 1.01, output_type="ndarray")
    if pairs.size == 0:
        return -math.inf
    d = positions[pairs[:, 0]] - positions[pairs[:, 1]]
    if periodic:
        d -= box * np.round(d / box)
    sigma = radii[pairs[:, 0]] + radii[pairs[:, 1]]
    return float(np.max((sigma - np.sqrt(np.einsum("ij,ij->i", d, d))) / sigma))


def worst_excursion(positions, radii, box, periodic) -> float:
    """How far (in σ_i = 2 r_i) the furthest centre lies beyond where it may be (≤ 0 inside)."""
    limit = np.full_like(radii, box / 2.0) if periodic else box / 2.0 - radii
    return float(np.max((np.abs(positions) - limit[:, None]) / (2.0 * radii[:, None])))


def check(gas, radii, e0, p0, worst: dict) -> None:
    """The invariants at the current time (every sphere synchronised to it), worst values so far in ``worst``."""
    pos, vel = gas.positions, gas.velocities
    assert np.isfinite(pos).all() and np.isfinite(vel).all()
    worst["drift"] = max(worst["drift"], abs(kinetic_energy(gas) - e0) / e0)
    worst["overlap"] = max(worst["overlap"], worst_overlap(pos, radii, gas.box, gas.periodic))
    worst["excursion"] = max(worst["excursion"], worst_excursion(pos, radii, gas.box, gas.periodic))
    if gas.periodic:  # no wall: the total momentum is conserved too
        scale = float(np.sum(gas.masses * np.linalg.norm(vel, axis=1)))
        worst["momentum"] = max(worst["momentum"], float(np.abs((gas.masses[:, None] * vel).sum(0) - p0).max()) / scale)
    broken = [text for bad, text in [
        (worst["drift"] > ENERGY_DRIFT, f"energy drift {worst['drift']:.3g}"),
        (worst["overlap"] > OVERLAP, f"two spheres overlap by {worst['overlap']:.3g} σ"),
        (worst["excursion"] > EXCURSION, f"a sphere lies {worst['excursion']:.3g} σ outside the box"),
        (worst["momentum"] > MOMENTUM_DRIFT, f"momentum drift {worst['momentum']:.3g}")] if bad]
    assert not broken, "; ".join(broken) + f" after {gas.collisions:,} collisions (t = {gas.time:.6g})"


@pytest.mark.parametrize("case", list(CASES))
def test_event_driven_gas_soak(case):
    boundary, n, eta, polydisperse = CASES[case]
    gas, radii = lattice_gas(boundary, n, eta, polydisperse)
    e0 = kinetic_energy(gas)
    p0 = (gas.masses[:, None] * gas.velocities).sum(axis=0)
    worst = {"drift": 0.0, "overlap": -math.inf, "excursion": -math.inf, "momentum": 0.0}
    per_check = COLLISIONS // CHECKS
    step = 0.01  # then adapted, so that about per_check collisions separate two checks
    started, cpu = time.perf_counter(), time.process_time()
    for _ in range(20 * CHECKS):
        last = gas.collisions
        t_next = gas.time + step
        gas.run(t_next)
        assert gas.time == t_next
        check(gas, radii, e0, p0, worst)
        if gas.collisions >= COLLISIONS:
            break
        gained = gas.collisions - last
        step *= min(10.0, per_check / gained) if gained else 10.0
    assert gas.collisions >= COLLISIONS, f"only {gas.collisions:,} collisions in {20 * CHECKS} check intervals"
    seconds, cpu = time.perf_counter() - started, time.process_time() - cpu
    print(f"\n[soak {case}] n={n} eta={eta} {gas.collisions:,} collisions ({gas.events:,} events) in {seconds:.1f} s "
          f"wall, {cpu:.1f} s CPU ({gas.collisions / cpu:,.0f}/s CPU), t={gas.time:.4g}; "
          f"max energy drift {worst['drift']:.2e}, "
          f"max overlap {worst['overlap']:.2e} σ, max excursion {worst['excursion']:.2e} σ (negative: none), "
          f"max momentum drift {worst['momentum']:.2e}")
