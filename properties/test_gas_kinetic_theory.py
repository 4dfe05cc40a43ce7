"""simulate_gas against kinetic theory and against the gas it runs, with few spheres and short runs.

- One sphere between walls (chapter 2.B, specular reflection): its trajectory is the unfolded straight line
  folded back into the reachable cube, for both methods (the stepped mirror is exact for one sphere); its wall
  hits are counted exactly; and the wall pressure of kinetic theory holds, Z_wall = P V'/(N kT) = 1, within
  the discreteness of the hits.
- The block observables of ``simulate_gas`` are the sums of an ``EventDrivenGas`` run to the same block ends,
  put through the kinetic-theory formulas (written out here).
- Initial states: packing fraction and radius are inverse, placements never overlap and stay in the reachable
  cube, velocities are at exactly kT with equipartition between masses.
- Every argument of ``simulate_gas`` is validated and named; the event cap raises; progress is monotone to 1.
- ``run_gas_command`` reports what ``simulate_gas`` measured and writes the PNG.
"""
from __future__ import annotations

import io
import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from engine.gas import (
    EventDrivenGas,
    GasEventCapReached,
    SteppedGas,
    packing_fraction,
    radius_for_packing,
    simulate_gas,
)
from engine.gas.command import run_gas_command
from engine.gas.initial import MAX_PACKING, check_gas_state, draw_velocities, place_spheres
from properties.strategies.gas import gas_scenes

L = 10.0
#: an event cap far above what these small, short runs need: a broken event loop that stalls in an endless
#: stream of events fails fast (GasEventCapReached) instead of hanging
STORM = 10**5
finite = dict(allow_nan=False, allow_infinity=False, allow_subnormal=False)


def folded(x0, v, t, lo, hi):
    """Position and velocity at time t of a point bouncing specularly between lo and hi (the unfolded line
    x0 + v t reflected into [lo, hi]), and the number of bounces."""
    span = hi - lo
    u = (x0 - lo) + v * t
    bounces = math.floor(u / span) if u >= 0 else math.floor(-u / span) + 1
    w = u % (2.0 * span)
    if w <= span:
        return lo + w, v, bounces
    return lo + 2.0 * span - w, -v, bounces


def _clear_of_a_bounce(u, span):
    """The unfolded coordinate u is not within round-off of a wall (a bounce there may fall either side of t)."""
    return abs(u - span * round(u / span)) > 1e-6


@st.composite
def lone_spheres(draw, min_component=0.05):
    r = draw(st.floats(0.05, 2.0))
    hi = L / 2 - r
    x0 = np.array([draw(st.floats(-hi, hi)) for _ in range(3)])
    speed = draw(st.floats(0.5, 20.0))
    direction = np.array([draw(st.floats(min_component, 1.0)) * draw(st.sampled_from([-1.0, 1.0])) for _ in range(3)])
    v = speed * direction / np.linalg.norm(direction)
    m = draw(st.floats(0.1, 10.0))
    return r, x0, v, m


def _assert_on_the_folded_line(gas, x0, v, m, t, lo, hi):
    """The lone sphere of ``gas`` at time t: on the straight line folded back at the walls (position, velocity),
    with the exact number of wall hits and their impulse 2 m |v_k| per hit."""
    hits = 0
    for k in range(3):
        x, vk, b = folded(x0[k], v[k], t, lo, hi)
        # a bounce within round-off of t may be counted either side of it
        assume(_clear_of_a_bounce(x0[k] - lo + v[k] * t, hi - lo))
        assert gas.positions[0, k] == pytest.approx(x, abs=1e-9 * (1 + abs(v[k]) * t))
        assert gas.velocities[0, k] == vk
        hits += b
    assert gas.wall_hits == hits
    assert gas.wall_impulse == pytest.approx(sum(2 * m * abs(v[k]) * folded(x0[k], v[k], t, lo, hi)[2]
                                                 for k in range(3)), rel=1e-12)


@given(lone_spheres(), st.floats(0.1, 20.0))
def test_one_sphere_bounces_specularly_between_the_walls(case, t):
    r, x0, v, m = case
    lo, hi = -L / 2 + r, L / 2 - r
    gas = EventDrivenGas(x0[None], v[None], r, m, L, periodic=False)
    gas.run(t)
    _assert_on_the_folded_line(gas, x0, v, m, t, lo, hi)
    assert gas.collisions == 0 and gas.virial == 0.0


@given(lone_spheres(), st.integers(1, 200), st.sampled_from([1e-3, 1e-2, 5e-2]))
def test_one_sphere_in_the_frame_loop_follows_the_same_folded_line(case, steps, dt):
    """The stepped method mirrors the distance travelled past a wall back: exact for a lone sphere."""
    r, x0, v, m = case
    lo, hi = -L / 2 + r, L / 2 - r
    gas = SteppedGas(x0[None], v[None], r, m, L, False, dt)
    gas.run(steps)
    t = steps * dt
    _assert_on_the_folded_line(gas, x0, v, m, t, lo, hi)
    assert gas.collisions == 0 and gas.overlapping == 0
    assert gas.kinetic_energy() == pytest.approx(0.5 * m * float(v @ v), rel=1e-15)


@given(lone_spheres(min_component=0.3), st.sampled_from(["events", "stepped"]))
def test_wall_pressure_of_one_sphere_is_the_ideal_gas_law(case, method):
    """Kinetic theory: each axis is hit |v_k| t / L' times (to within one hit), each hit gives 2 m |v_k|, so
    P V' = Σ_k m v_k² = 2K = 3 kT: Z_wall = 1 to within the hit discreteness Σ_k 2 m |v_k| L' / (6 t_b kT)."""
    r, x0, v, m = case
    side = L - 2 * r
    t_meas = 20.0 * side / np.abs(v).min()  # >= 10 hits per axis and per block
    dt = 0.25 * side / np.abs(v).max()  # stepped: a quarter of the box per frame at most (<= 270 frames)
    res = simulate_gas(1, radius=r, mass=m, positions=x0[None], velocities=v[None], t_equilibrate=0.0,
                       t_measure=t_meas, blocks=2, method=method, dt=dt)
    kt = m * float(v @ v) / 3.0
    assert res.temperature == pytest.approx(kt, rel=1e-12)
    bound = sum(2 * m * abs(v[k]) * side for k in range(3)) / (6.0 * (t_meas / 2) * kt)
    assert abs(res.z_wall - 1.0) <= bound + 1e-12
    assert bound < 0.2
    assert res.z_virial == 1.0 and res.collisions == 0 and res.collision_rate == 0.0
    assert res.z_collision_rate == 1.0
    assert res.energy_drift <= 1e-14


def _level_crossings(x0, v, t, lo, hi, level):
    """How many times the folded line of a point bouncing between lo and hi passes ``level`` (lo < level < hi)
    during [0, t]: the unfolded coordinate u = x0 − lo + v t meets c + 2 m span and 2 span − c + 2 m span."""
    span, c = hi - lo, level - lo
    a, b = sorted((x0 - lo, x0 - lo + v * t))
    count = 0
    for first in (c, 2 * span - c):
        m_lo = math.ceil((a - first) / (2 * span))
        m_hi = math.floor((b - first) / (2 * span))
        count += max(0, m_hi - m_lo + 1)
    return count


@settings(max_examples=25)
@given(st.integers(8, 27), st.floats(0.3, 5.0), st.floats(-1.0, 1.0), st.floats(-5.0, 5.0), st.floats(-5.0, 5.0),
       st.floats(1.0, 8.0))
def test_a_column_of_spheres_crosses_the_cells_on_schedule(n, speed, angle, x0, z0, t):
    """n spheres stacked along y, all with the same velocity (vx, 0, vz): they move as one rigid column and never
    meet. Every event is a wall hit or a cell crossing, and both are counted exactly from the folded lines
    (cells of side L/ncell from −L/2; the column crosses a cell plane each time its folded x or z passes one)."""
    r = 0.1
    hi = L / 2 - r
    x0, z0 = min(max(x0, -hi), hi), min(max(z0, -hi), hi)
    p = np.zeros((n, 3))
    p[:, 0], p[:, 2] = x0, z0
    p[:, 1] = np.linspace(-hi, hi, n)
    v = np.zeros((n, 3))
    v[:, 0], v[:, 2] = speed * math.cos(angle), speed * math.sin(angle)
    gas = EventDrivenGas(p, v, r, 1.0, L, periodic=False)
    assert gas.ncell >= 2
    gas.run(t)
    planes = [-L / 2 + c * L / gas.ncell for c in range(1, gas.ncell)]
    for k, start in ((0, x0), (2, z0)):
        assume(_clear_of_a_bounce(start + r - L / 2 + v[0, k] * t, 2 * hi))
        assume(all(abs(folded(start, v[0, k], t, -hi, hi)[0] - q) > 1e-6 and abs(start - q) > 1e-6 for q in planes))
    crossings = sum(_level_crossings(start, v[0, k], t, -hi, hi, q) for k, start in ((0, x0), (2, z0))
                    for q in planes)
    hits = sum(folded(start, v[0, k], t, -hi, hi)[2] for k, start in ((0, x0), (2, z0)))
    assert gas.crossings == n * crossings
    assert gas.wall_hits == n * hits
    assert gas.collisions == 0 and gas.stale == 0
    assert gas.events == gas.crossings + gas.wall_hits
    np.testing.assert_allclose(gas.positions[:, 1], p[:, 1], rtol=0, atol=0)
    for k, start in ((0, x0), (2, z0)):
        np.testing.assert_allclose(gas.positions[:, k], folded(start, v[0, k], t, -hi, hi)[0], atol=1e-9)


def _reference(scene, t_eq, t_meas, blocks):
    """The event gas simulate_gas builds (same seed, same start), run to the same stops, with its block sums."""
    n = scene["n"]
    periodic = scene["boundary"] == "periodic"
    r = np.broadcast_to(np.asarray(scene["radius"], float), (n,)).copy()
    m = np.broadcast_to(np.asarray(scene["mass"], float), (n,)).copy()
    rng = np.random.default_rng(scene["seed"])
    p = place_spheres(n, r, L, scene["boundary"], rng, "auto")
    v = draw_velocities(m, 1.3, scene["boundary"], rng)
    gas = EventDrivenGas(p, v, r, m, L, periodic)
    for k in range(1, 11):
        gas.run(t_eq * k / 10.0)
    sums = []
    t_block = t_meas / blocks
    for b in range(blocks):
        gas.reset_sums()
        gas.run(t_eq + (b + 1) * t_block)
        sums.append((gas.virial, gas.wall_impulse, gas.collisions, gas.events, gas.velocities.copy()))
    return gas, r, m, v, sums


@settings(max_examples=25)
@given(gas_scenes(max_n=8), st.floats(0.0, 0.5), st.floats(0.2, 1.0), st.integers(2, 4))
def test_block_observables_are_the_design_formulas_of_the_event_sums(scene, t_eq, t_meas, blocks):
    n = scene["n"]
    res = simulate_gas(n, radius=scene["radius"], mass=scene["mass"], boundary=scene["boundary"], temperature=1.3,
                       seed=scene["seed"], t_equilibrate=t_eq, t_measure=t_meas, blocks=blocks, max_events=STORM)
    gas, r, m, v0, sums = _reference(scene, t_eq, t_meas, blocks)
    periodic = scene["boundary"] == "periodic"
    kt = float((m[:, None] * v0 * v0).sum()) / (3 * n)
    t_b = t_meas / blocks
    side = L if periodic else L - 2 * float(r.mean())
    zv = [1 + s[0] / (3 * t_b * n * kt) for s in sums]
    rates = [2 * s[2] / (n * t_b) for s in sums]
    assert res.temperature == pytest.approx(kt, rel=1e-12)
    np.testing.assert_allclose(res.block_z_virial, zv, rtol=1e-12)
    np.testing.assert_allclose(res.block_collision_rate, rates, rtol=1e-12)
    assert res.z_virial == pytest.approx(np.mean(zv), rel=1e-12)
    assert res.z_virial_err == pytest.approx(np.std(zv, ddof=1) / math.sqrt(blocks), rel=1e-9, abs=1e-12)
    assert res.collision_rate == pytest.approx(np.mean(rates), rel=1e-12, abs=1e-300)
    assert res.collision_rate_err == pytest.approx(np.std(rates, ddof=1) / math.sqrt(blocks), rel=1e-9, abs=1e-12)
    assert res.collisions == sum(s[2] for s in sums)
    assert res.events == sum(s[3] for s in sums)
    if periodic:
        assert math.isnan(res.z_wall) and math.isnan(res.z_wall_err) and np.isnan(res.block_z_wall).all()
    else:
        zw = [s[1] * side / (6 * t_b * n * kt) for s in sums]
        np.testing.assert_allclose(res.block_z_wall, zw, rtol=1e-12)
        assert res.z_wall == pytest.approx(np.mean(zw), rel=1e-12)
        assert res.z_wall_err == pytest.approx(np.std(zw, ddof=1) / math.sqrt(blocks), rel=1e-9, abs=1e-12)
    sigma = 2 * float(r.mean())
    assert res.sigma == pytest.approx(sigma, rel=1e-15)
    assert res.z_collision_rate == pytest.approx(
        1 + res.collision_rate * sigma * math.sqrt(math.pi * float(m.mean()) / kt) / 6, rel=1e-12)
    assert res.packing_fraction == pytest.approx(float((math.pi / 6 * (2 * r) ** 3).sum()) / side**3, rel=1e-12)
    np.testing.assert_array_equal(res.positions, gas.positions)
    np.testing.assert_array_equal(res.velocities, gas.velocities)
    np.testing.assert_allclose(res.momentum, (m[:, None] * gas.velocities).sum(0), rtol=1e-12, atol=1e-12)
    speeds = np.concatenate([np.sqrt((s[4] ** 2).sum(1) * m / kt) for s in sums])
    np.testing.assert_allclose(np.sort(res.scaled_speeds), np.sort(speeds), rtol=1e-12)
    assert res.scaled_speeds.shape == (blocks * n,)
    assert res.energy_drift <= 1e-12
    assert (res.method, res.boundary, res.broad_phase, res.dt, res.n) == ("events", scene["boundary"], "cells", 0.0, n)
    assert res.t_measure == pytest.approx(t_meas, rel=1e-15)
    # the throughput is the window's collisions over its clock time (the clock itself is not reproducible)
    assert res.collisions_per_second == (res.collisions / res.seconds if res.seconds > 0.0 else 0.0)
    if periodic:
        assert np.linalg.norm(res.momentum) <= 1e-12 * n


@settings(max_examples=10)
@given(gas_scenes(max_n=8), st.sampled_from([0.01, 0.02]), st.integers(2, 3))
def test_stepped_run_reports_its_frames_and_its_sums(scene, dt, blocks):
    n = scene["n"]
    t_meas = 0.2
    kwargs = dict(radius=scene["radius"], mass=scene["mass"], boundary=scene["boundary"], seed=scene["seed"],
                  t_equilibrate=0.1, t_measure=t_meas, blocks=blocks, method="stepped", dt=dt)
    res = simulate_gas(n, **kwargs)
    frames = int(round(0.1 / dt)) + blocks * max(1, int(round(t_meas / blocks / dt)))
    r = np.broadcast_to(np.asarray(scene["radius"], float), (n,)).copy()
    m = np.broadcast_to(np.asarray(scene["mass"], float), (n,)).copy()
    rng = np.random.default_rng(scene["seed"])
    p = place_spheres(n, r, L, scene["boundary"], rng, "auto")
    v = draw_velocities(m, 1.0, scene["boundary"], rng)
    gas = SteppedGas(p, v, r, m, L, scene["boundary"] == "periodic", dt)
    gas.run(frames)
    np.testing.assert_array_equal(res.positions, gas.positions)
    np.testing.assert_array_equal(res.velocities, gas.velocities)
    assert res.events == blocks * max(1, int(round(t_meas / blocks / dt)))
    assert (res.method, res.broad_phase, res.dt) == ("stepped", "sap", dt)
    assert res.collisions_per_second == (res.collisions / res.seconds if res.seconds > 0.0 else 0.0)
    assert res.energy_drift <= 1e-12


@given(st.integers(1, 60), st.floats(0.01, MAX_PACKING), st.sampled_from(["walls", "periodic"]))
def test_radius_for_packing_inverts_packing_fraction(n, eta, boundary):
    r = radius_for_packing(n, eta, L, boundary)
    side = L - 2 * r if boundary == "walls" else L
    assert n * math.pi / 6 * (2 * r) ** 3 / side**3 == pytest.approx(eta, rel=1e-12)
    assert packing_fraction(np.full(n, r), L, boundary) == pytest.approx(eta, rel=1e-12)


@settings(max_examples=25)
@given(st.integers(1, 30), st.floats(0.01, MAX_PACKING), st.sampled_from(["walls", "periodic"]),
       st.sampled_from(["auto", "random", "lattice"]), st.integers(0, 2**16))
def test_placements_never_overlap_and_stay_in_the_reachable_cube(n, eta, boundary, initial, seed):
    r = radius_for_packing(n, eta, L, boundary)
    assume(boundary == "walls" or 6 * r <= L)
    radii = np.full(n, r)
    try:
        p = place_spheres(n, radii, L, boundary, np.random.default_rng(seed), initial)
    except ValueError:
        assume(initial == "random" and eta > 0.2)  # random addition may jam; the lattice and auto never do here
        return
    assert p.shape == (n, 3) and np.isfinite(p).all()
    if boundary == "walls":
        assert (np.abs(p) <= L / 2 - r + 1e-12).all()
    else:
        assert (p >= -L / 2).all() and (p < L / 2).all()
    d = p[:, None] - p[None]
    if boundary == "periodic":
        d -= L * np.round(d / L)
    dist = np.sqrt((d * d).sum(-1)) + np.eye(n) * 1e9
    assert dist.min() >= 2 * r * (1 - 1e-12)


def test_random_placement_keeps_each_radius_off_the_walls():
    radii = np.array([0.2, 1.5, 0.4, 2.0])
    p = place_spheres(4, radii, L, "walls", np.random.default_rng(0), "random")
    assert (np.abs(p) <= L / 2 - radii[:, None]).all()
    p = place_spheres(4, radii, L, "walls", np.random.default_rng(0), "auto")
    assert (np.abs(p) <= L / 2 - radii[:, None]).all()


def test_impossible_packings_raise():
    with pytest.raises(ValueError, match="too dense"):
        place_spheres(10, np.full(10, 3.0), L, "walls", np.random.default_rng(0), "auto")
    with pytest.raises(ValueError, match="equal radii"):
        place_spheres(2, np.array([0.1, 0.2]), L, "walls", np.random.default_rng(0), "lattice")
    # 5 spheres at eta = 0.45: the smallest FCC lattice with >= 5 sites (2³ cells) is too fine for them
    r = radius_for_packing(5, 0.45, L)
    with pytest.raises(ValueError, match="on a lattice"):
        place_spheres(5, np.full(5, r), L, "walls", np.random.default_rng(0), "lattice")


@given(st.integers(2, 50), st.floats(0.1, 10.0), st.sampled_from(["walls", "periodic"]), st.integers(0, 2**16))
def test_drawn_velocities_have_exactly_the_temperature(n, kt, boundary, seed):
    m = np.random.default_rng(seed).uniform(0.5, 5.0, size=n)
    v = draw_velocities(m, kt, boundary, np.random.default_rng(seed))
    assert float((m[:, None] * v * v).sum()) / (3 * n) == pytest.approx(kt, rel=1e-12)
    if boundary == "periodic":
        assert np.linalg.norm((m[:, None] * v).sum(0)) <= 1e-12 * float((m * np.linalg.norm(v, axis=1)).sum())


def test_drawn_velocities_share_the_energy_equally_between_masses():
    """Equipartition: light and heavy spheres have the same mean m v²/3 = kT (each component ~ N(0, kT/m))."""
    m = np.repeat([1.0, 100.0], 2000)
    v = draw_velocities(m, 2.0, "walls", np.random.default_rng(4))
    light = float((v[:2000] ** 2).sum(1).mean()) * 1.0 / 3
    heavy = float((v[2000:] ** 2).sum(1).mean()) * 100.0 / 3
    assert light == pytest.approx(2.0, rel=0.1) and heavy == pytest.approx(2.0, rel=0.1)


def test_stepped_runs_beyond_max_steps_frames_are_refused():
    from engine.gas import MAX_STEPS

    with pytest.raises(ValueError, match="MAX_STEPS"):
        simulate_gas(2, radius=0.1, method="stepped", t_equilibrate=0.0, t_measure=2.0, dt=2.0 / MAX_STEPS / 1.5)


def test_the_event_cap_is_counted_over_the_whole_run():
    """max_events caps the events of the whole run (equilibration and every block), not of one stop."""
    args = dict(radius=1.0, t_equilibrate=3.0, t_measure=3.0, blocks=2, seed=2, temperature=1.3)
    res = simulate_gas(10, **args, max_events=STORM)
    gas, *_ = _reference(dict(n=10, radius=1.0, mass=1.0, boundary="walls", seed=2), 3.0, 3.0, 2)
    processed = gas.processed  # the events of the same run, stop by stop
    assert processed > 20
    capped = simulate_gas(10, **args, max_events=processed + 1)
    np.testing.assert_array_equal(capped.positions, res.positions)
    for cap in (processed - 1, processed // 2, 1):
        with pytest.raises(GasEventCapReached):
            simulate_gas(10, **args, max_events=cap)


@pytest.mark.parametrize("method", ["events", "stepped"])
def test_progress_is_monotone_and_ends_at_one(method):
    seen = []
    simulate_gas(4, radius=0.3, t_equilibrate=0.2, t_measure=0.4, blocks=2, method=method, dt=0.01,
                 progress=seen.append)
    assert seen and all(0.0 <= f <= 1.0 for f in seen)
    assert all(a <= b for a, b in zip(seen, seen[1:]))
    assert seen[-1] == pytest.approx(1.0, rel=1e-12)
    # the fraction done when equilibration ends is t_equilibrate / (t_equilibrate + t_measure)
    assert any(f == pytest.approx(0.2 / 0.6, rel=1e-12) for f in seen)


def test_state_validation_names_the_argument():
    p = np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0]])
    v = np.zeros((2, 3))
    with pytest.raises(TypeError, match="periodic"):
        check_gas_state(p, v, 0.5, 1.0, L, "yes")
    with pytest.raises(ValueError, match="radii"):
        check_gas_state(p, v, 5.0, 1.0, L, False)
    with pytest.raises(ValueError, match="3 diameters"):
        check_gas_state(p, v, 1.7, 1.0, L, True)
    with pytest.raises(ValueError, match=r"masses\[1\]"):
        check_gas_state(p, v, 0.5, [1.0, -1.0], L, False)
    with pytest.raises(ValueError, match="overlap"):
        check_gas_state(p, v, 1.2, 1.0, L, False)
    with pytest.raises(ValueError, match=r"positions\[1\]"):
        check_gas_state(np.array([[0.0, 0, 0], [4.8, 0, 0]]), v, 0.5, 1.0, L, False, allow_overlap=True)
    q, *_ = check_gas_state(p, v, 1.2, 1.0, L, False, allow_overlap=True)  # the frame loop starts from overlaps
    np.testing.assert_array_equal(q, p)
    q, *_ = check_gas_state(p + [6.0, 0, 0], v, 0.5, 1.0, L, True)  # periodic: wrapped into [−L/2, L/2)
    np.testing.assert_allclose(q, [[-4.0, 0, 0], [-2.0, 0, 0]])
    with pytest.raises(ValueError, match="t_stop"):
        EventDrivenGas(p, v, 0.5, 1.0, L, False).run(-1.0)


def test_command_prints_what_simulate_gas_measured(tmp_path):
    out, err = io.StringIO(), io.StringIO()
    png = tmp_path / "speeds.png"
    args = dict(t_measure=0.4, t_equilibrate=0.2, seed=3)
    assert run_gas_command(n=12, eta=0.1, out=str(png), stdout=out, stderr=err, **args) == 0
    res = simulate_gas(12, radius=radius_for_packing(12, 0.1, L), **args)
    text = out.getvalue()
    assert f"N = 12, eta = 0.1, sigma = {res.sigma:.5g}, box = 10, walls, event-driven" in text
    assert f"Z (collision virial)  = {res.z_virial:.4f} +- {res.z_virial_err:.4f}" in text
    assert f"Z (wall impulses)     = {res.z_wall:.4f} +- {res.z_wall_err:.4f}" in text
    assert f"collisions = {res.collisions}," in text
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert err.getvalue() == ""  # stderr is not a terminal: no carriage-return frames in a log


def test_command_histogram_shows_the_run_and_its_ks_p_value(tmp_path, monkeypatch):
    """The histogram the command writes is of the run's scaled speeds, titled with the method, boundary, N, eta
    and the KS p-value of the last block's speeds against Maxwell-Boltzmann (the value the command prints)."""
    import engine.gas.command as command
    from engine.gas import maxwell_boltzmann_test

    calls = []
    monkeypatch.setattr(command, "plot_speed_histogram", lambda *a, **k: calls.append((a, k)))
    args = dict(t_measure=0.4, t_equilibrate=0.2, seed=3)
    png = tmp_path / "speeds.png"
    run_gas_command(n=12, eta=0.1, out=str(png), stdout=io.StringIO(), stderr=io.StringIO(), **args)
    res = simulate_gas(12, radius=radius_for_packing(12, 0.1, L), **args)
    (speeds, path, title), kwargs = calls[0]
    assert len(calls) == 1 and kwargs == {} and str(path) == str(png)
    np.testing.assert_array_equal(speeds, res.scaled_speeds)
    _, p = maxwell_boltzmann_test(res.scaled_speeds[-12:])
    assert title == f"events, walls, N = 12, eta = 0.1 (KS p = {p:.2f})"


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_command_progress_bar_on_a_terminal_reaches_the_end(tmp_path):
    """On a terminal the bar is drawn and reaches 100 %; it is cleared when the run ends (the report follows)."""
    err = _Terminal()
    run_gas_command(n=6, eta=0.05, out=str(tmp_path / "a.png"), stdout=io.StringIO(), stderr=err, t_measure=0.2,
                    t_equilibrate=0.1)
    frames = err.getvalue().split("\r")
    assert any("100.0%" in f for f in frames) and any(" 0.0%" in f or " 1" in f for f in frames[:3])


def test_command_periodic_and_stepped_reports(tmp_path):
    out = io.StringIO()
    run_gas_command(n=8, eta=0.05, boundary="periodic", method="stepped", dt=0.02, out=str(tmp_path / "a.png"),
                    progress=False, stdout=out, stderr=io.StringIO(), t_measure=0.2, t_equilibrate=0.0)
    text = out.getvalue()
    from engine.gas import carnahan_starling

    assert "stepped, dt = 0.02, broad phase sap" in text
    assert "Z (wall impulses)" not in text
    assert f"Z (Carnahan-Starling) = {carnahan_starling(0.05):.4f}" in text


def test_default_seed_is_zero():
    """simulate_gas(..., seed=0) is the default; the same call without seed gives the same gas."""
    args = dict(radius=0.4, t_equilibrate=0.0, t_measure=0.5, blocks=2)
    np.testing.assert_array_equal(simulate_gas(5, **args).positions, simulate_gas(5, seed=0, **args).positions)
    assert not np.array_equal(simulate_gas(5, **args).positions, simulate_gas(5, seed=1, **args).positions)


def test_command_without_progress_writes_nothing_on_stderr(tmp_path):
    err = io.StringIO()
    run_gas_command(n=4, eta=0.05, out=str(tmp_path / "a.png"), progress=False, stdout=io.StringIO(), stderr=err,
                    t_measure=0.2, t_equilibrate=0.0)
    assert err.getvalue() == ""


@settings(max_examples=25)
@given(st.integers(1, 5), st.floats(0.0, 1.0), st.floats(0.05, MAX_PACKING), st.sampled_from(["walls", "periodic"]),
       st.integers(0, 2**16))
def test_lattice_start_holds_every_n_that_fills_most_of_its_cells(k, fill, eta, boundary, seed):
    """The FCC start uses the smallest k³-cell lattice with >= n sites (4 per cell); when n fills at least 61 % of
    them (n >= 2.44 k³), spheres at any η <= 0.45 fit on it (nearest sites a/√2 apart, σ <= 0.7 a):
    n = 4k³ is the full lattice."""
    n = max(1, math.ceil(0.61 * 4 * k**3 + fill * (4 * k**3 - math.ceil(0.61 * 4 * k**3))))
    r = radius_for_packing(n, eta, L, boundary)
    assume(boundary == "walls" or 6 * r <= L)
    p = place_spheres(n, np.full(n, r), L, boundary, np.random.default_rng(seed), "lattice")
    assert p.shape == (n, 3)
    d = p[:, None] - p[None]
    if boundary == "periodic":
        d -= L * np.round(d / L)
    dist = np.sqrt((d * d).sum(-1)) + np.eye(n) * 1e9
    assert dist.min() >= 2 * r * (1 - 1e-12)
    if boundary == "walls":
        assert (np.abs(p) <= L / 2 - r + 1e-12).all()
