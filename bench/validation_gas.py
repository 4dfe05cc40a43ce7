"""Validation section of the confined gas (reports/gas.md): kinetic theory against both simulation methods.

``gas_section(out, info, quick, client)`` writes gas.md, gas.csv and gas_speeds.png into ``out`` and returns the
index rows. Its runs are the points of a physics sweep (bench/sweep.py: ``gas_point`` over ``gas_configs``), on
the report's Dask client, or serially without one. Quick mode: smaller N and shorter windows.
"""
from __future__ import annotations

import math
import pathlib
import time

import numpy as np
import pandas as pd

from bench.edmd_peer import against_c_code, c_code_lines
from engine.gas import (
    carnahan_starling,
    maxwell_boltzmann_test,
    plot_speed_histogram,
    radius_for_packing,
    simulate_gas,
    speed_moment_ratio,
)

L = 10.0
ETAS = (0.1, 0.2, 0.3)


def _dt_for(sigma, ratio, kt=1.0, m=1.0):
    """The step with v_rms·Δt/σ = ratio (v_rms = sqrt(3kT/m))."""
    return ratio * sigma / math.sqrt(3.0 * kt / m)


def _row(res, **extra):
    ks, p = maxwell_boltzmann_test(res.scaled_speeds[-res.n:])
    return dict(method=res.method, boundary=res.boundary, n=res.n, eta=round(res.packing_fraction, 6),
                dt=res.dt, z_virial=res.z_virial, z_virial_err=res.z_virial_err, z_wall=res.z_wall,
                z_wall_err=res.z_wall_err, z_collision_rate=res.z_collision_rate,
                collision_rate=res.collision_rate, collision_rate_err=res.collision_rate_err,
                collisions=res.collisions, energy_drift=res.energy_drift, ks_pvalue=p,
                v4_over_v2sq=speed_moment_ratio(res.scaled_speeds),
                carnahan_starling=carnahan_starling(res.packing_fraction),
                collisions_per_second=res.collisions_per_second, **extra)


def _fit_to_zero(dts, zs, errs):
    """Weighted least squares Z = Z0 + a Δt; returns (Z0, its standard error, slope a)."""
    dts, zs, w = np.asarray(dts), np.asarray(zs), 1.0 / np.asarray(errs) ** 2
    A = np.stack([np.ones_like(dts), dts], axis=1)
    cov = np.linalg.inv(A.T @ (w[:, None] * A))
    coef = cov @ (A.T @ (w * zs))
    return float(coef[0]), float(math.sqrt(cov[0, 0])), float(coef[1])


def _in_errors(row):
    return (row["z_virial"] - row["z_wall"]) / math.hypot(row["z_virial_err"], row["z_wall_err"])


GAS_KEY = ("table", "eta_target", "boundary", "method", "vrms_dt_over_sigma", "n", "t_equilibrate", "t_measure",
           "seed")


def gas_configs(quick: bool = False) -> list[dict]:
    """The runs of the section, one sweep point each: the EOS table (both methods, both boundaries, η = 0.1, 0.2,
    0.3) and the stepped bias table (events, then stepped at decreasing v_rms·Δt/σ)."""
    # the same N for both methods, so that their rows compare the same box (wall effects depend on N)
    n_ev, t_ev = (400, 8.0) if quick else (2000, 40.0)
    n_st, t_st = (400, 4.0) if quick else (2000, 16.0)
    t_eq = 2.0 if quick else 5.0
    configs = []
    for eta in ETAS:
        for boundary in ("walls", "periodic"):
            configs.append(dict(table="eos", eta_target=eta, boundary=boundary, method="events",
                                vrms_dt_over_sigma=None, n=n_ev, t_equilibrate=t_eq, t_measure=t_ev, seed=1,
                                keep_speeds=eta == 0.2 and boundary == "walls"))
            configs.append(dict(table="eos", eta_target=eta, boundary=boundary, method="stepped",
                                vrms_dt_over_sigma=0.02, n=n_st, t_equilibrate=t_eq, t_measure=t_st, seed=1))
    n_b, t_b = (200, 6.0) if quick else (500, 30.0)
    ratios = (0.4, 0.2, 0.1, 0.05) if quick else (0.4, 0.2, 0.1, 0.05, 0.025)
    for method, ratio in [("events", None)] + [("stepped", x) for x in ratios]:
        configs.append(dict(table="bias", eta_target=0.2, boundary="walls", method=method, vrms_dt_over_sigma=ratio,
                            n=n_b, t_equilibrate=t_eq, t_measure=t_b, seed=2))
    return configs


def gas_point(cfg: dict) -> dict:
    """One run of the section (pure: the row depends only on cfg); the demo run also returns its speeds."""
    r = radius_for_packing(cfg["n"], cfg["eta_target"], L, cfg["boundary"])
    step = {}
    if cfg["method"] == "stepped":
        step = dict(method="stepped", dt=_dt_for(2.0 * r, cfg["vrms_dt_over_sigma"]))
    res = simulate_gas(cfg["n"], radius=r, boundary=cfg["boundary"], t_equilibrate=cfg["t_equilibrate"],
                       t_measure=cfg["t_measure"], blocks=20, seed=cfg["seed"], **step)
    row = _row(res)
    if cfg.get("keep_speeds"):
        row["scaled_speeds"] = res.scaled_speeds.tolist()
    return row


def _bias_fit(rows):
    """The event-driven row of the bias table, its stepped rows [(v_rms·Δt/σ, row)] and the fit Z0 ± err, slope
    over the steps with v_rms·Δt/σ <= 0.2 (the bias is linear in Δt only for small steps: at 0.4 a sphere meets
    several others per frame and Z collapses); agree: Z0 within three standard errors of the event-driven Z."""
    from types import SimpleNamespace

    ev = SimpleNamespace(**next(r_ for r_ in rows if r_["table"] == "bias" and r_["method"] == "events"))
    bias = [(r_["vrms_dt_over_sigma"], SimpleNamespace(**r_)) for r_ in rows
            if r_["table"] == "bias" and r_["method"] == "stepped"]
    fit = [b for b in bias if b[0] <= 0.2]
    z0, z0_err, slope = _fit_to_zero([b[1].dt for b in fit], [b[1].z_virial for b in fit],
                                     [b[1].z_virial_err for b in fit])
    agree = abs(z0 - ev.z_virial) <= 3.0 * math.hypot(z0_err, ev.z_virial_err)
    return ev, bias, (z0, z0_err, slope), agree


def _pm(x, e):
    return "—" if not math.isfinite(x) else f"{x:.4f} ± {e:.4f}"


def _eos_lines(rows):
    """The equation-of-state table and its two comparison sentences."""
    lines = ["## Equation of state", "",
             "| method | boundary | N | η | Z virial | Z wall | 1 + Γσ√(πm/kT)/6 | Carnahan–Starling | Γ | "
             "energy drift | KS p (Maxwell) | ⟨v⁴⟩/⟨v²⟩² | collisions/s |",
             "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    eos = [r_ for r_ in rows if r_["table"] == "eos"]
    for r_ in eos:
        lines.append(f"| {r_['method']} | {r_['boundary']} | {r_['n']} | {r_['eta']:.2f} | "
                     f"{_pm(r_['z_virial'], r_['z_virial_err'])} | {_pm(r_['z_wall'], r_['z_wall_err'])} | "
                     f"{r_['z_collision_rate']:.4f} | {r_['carnahan_starling']:.4f} | "
                     f"{_pm(r_['collision_rate'], r_['collision_rate_err'])} | {r_['energy_drift']:.1e} | "
                     f"{r_['ks_pvalue']:.3f} | {r_['v4_over_v2sq']:.4f} | {r_['collisions_per_second']:,.0f} |")
    walls_ev = [r_ for r_ in eos if r_["boundary"] == "walls" and r_["method"] == "events"]
    per_ev = [r_ for r_ in eos if r_["boundary"] == "periodic" and r_["method"] == "events"]
    return lines + ["",
                    "Z virial against Z wall (walls, events), in combined standard errors: " + ", ".join(
                        f"η = {r_['eta']:.1f}: {_in_errors(r_):+.1f}" for r_ in walls_ev) + ".",
                    "Periodic Z against Carnahan–Starling (events): " + ", ".join(
                        f"η = {r_['eta']:.1f}: {100 * (r_['z_virial'] / r_['carnahan_starling'] - 1):+.2f} %"
                        for r_ in per_ev) + "; walled box: " + ", ".join(
                        f"η = {r_['eta']:.1f}: {100 * (r_['z_virial'] / r_['carnahan_starling'] - 1):+.1f} %"
                        for r_ in walls_ev) + ".", ""]


def _bias_lines(rows):
    """The stepped method's bias table against Δt and its extrapolation to Δt → 0."""
    ev, bias, (z0, z0_err, slope), agree = _bias_fit(rows)
    n_b, t_b = rows[-1]["n"], rows[-1]["t_measure"]
    lines = ["## The stepped method's bias against Δt", "",
             f"N = {n_b}, η = 0.2, walls, t_measure = {t_b:g}. Linear weighted fit Z(Δt) = Z0 + aΔt over the "
             f"steps with v_rms·Δt/σ <= 0.2 (beyond, a sphere meets several others per frame and the bias is no "
             f"longer linear), extrapolated to Δt → 0. Each contact is answered at its own contact instant "
             f"(backtracked inside the frame), so the bias comes from contacts missed or answered in the wrong "
             f"order within a frame.", "",
             "| v_rms·Δt/σ | Δt | Z virial | Z wall | Γ | Z − Z(events) |", "|---:|---:|---:|---:|---:|---:|"]
    for ratio, res in bias:
        lines.append(f"| {ratio:g} | {res.dt:.3e} | {_pm(res.z_virial, res.z_virial_err)} | "
                     f"{_pm(res.z_wall, res.z_wall_err)} | {_pm(res.collision_rate, res.collision_rate_err)} | "
                     f"{res.z_virial - ev.z_virial:+.4f} |")
    return lines + [f"| events (exact) | — | {_pm(ev.z_virial, ev.z_virial_err)} | {_pm(ev.z_wall, ev.z_wall_err)} | "
                    f"{_pm(ev.collision_rate, ev.collision_rate_err)} | 0 |", "",
                    f"Extrapolation: Z0 = {z0:.4f} ± {z0_err:.4f}, slope {slope:+.3f} per unit Δt; event-driven "
                    f"Z = {ev.z_virial:.4f} ± {ev.z_virial_err:.4f}: "
                    f"{'agree' if agree else 'DISAGREE'} within three standard errors.", ""]


def gas_section(out: pathlib.Path, info: dict, quick: bool = False, client=None) -> list[tuple[str, str]]:
    """Runs the section's simulations as a physics sweep (bench/sweep.py) on ``client`` (serially when None)."""
    from bench.sweep import RowStore, Sweep, run_sweep

    out = pathlib.Path(out)
    started = time.perf_counter()
    sweep = Sweep("gas", gas_point, gas_configs(quick), GAS_KEY, kind="physics", version=info["commit"])
    store = RowStore(out / ".sweeps" / "gas.jsonl")
    result = run_sweep(sweep, store, client, failures_path=out / "gas.failures.csv")
    if not result.complete:
        print(f"  gas: {len(result.failures)} runs failed (see gas.failures.csv); rerun to retry them only",
              flush=True)
        return []
    rows = result.rows
    demo_row = next(r_ for r_ in rows if "scaled_speeds" in r_)  # eos table, η = 0.2, walls, events
    speeds = np.asarray(demo_row["scaled_speeds"])
    for r_ in rows:
        r_.pop("scaled_speeds", None)
    df = pd.DataFrame(rows)
    df.insert(0, "commit", info["commit"])
    df.to_csv(out / "gas.csv", index=False)
    plot_speed_histogram(speeds, out / "gas_speeds.png",
                         f"event-driven, walls, N = {demo_row['n']}, eta = 0.2: {speeds.size} speeds")
    lines = ["# The confined gas: validation against kinetic theory", "",
             f"{info['date']} · commit `{info['commit']}` · {info['machine']}" + (" · quick mode" if quick else ""),
             "",
             "Chapter slides \"comportement des particules dans un volume confiné\": spheres in the box L = 10 "
             "(walls at ±L/2, v − 2(v·n)n), elastic mass-weighted collisions, the frame loop with "
             "sweep-and-prune. Two methods: **events** (exact event-driven) and **stepped** (the chapter's frame "
             "loop; Δt such that v_rms·Δt/σ = 0.02 in the first table). kT = 1, m = 1. Z = PV'/(NkT) with "
             "V' = (L − 2r)³ (walls) or L³ (periodic); standard errors over 20 blocks. Kinetic theory: the two "
             "routes to Z agree in equilibrium, Z − 1 = Γσ·sqrt(πm/kT)/6, the periodic Z follows "
             "Carnahan–Starling, and a walled box of this size lies several % below it.", ""]
    lines += _eos_lines(rows) + _bias_lines(rows)
    lines += c_code_lines(against_c_code(4_000, alternations=1) if quick else against_c_code())
    lines += ["![speed histogram](gas_speeds.png)", "", f"Section computed in {time.perf_counter() - started:.0f} s.",
              ""]
    (out / "gas.md").write_text("\n".join(lines))
    store.clear()  # complete: the next report computes afresh
    agree = _bias_fit(rows)[3]
    print(f"  gas: {len(rows)} runs, stepped extrapolation {'agrees' if agree else 'DISAGREES'}", flush=True)
    return [("[gas.md](gas.md), [gas.csv](gas.csv), [gas_speeds.png](gas_speeds.png)",
             "confined gas: Z virial vs wall, Z vs collision rate, periodic Z vs Carnahan–Starling, "
             "Maxwell–Boltzmann KS test, stepped bias vs Δt extrapolated to 0")]
