"""``collide gas``: run the confined gas and report Z, Γ (with standard errors), energy drift and speed.

``run_gas_command`` prints a short report on stdout (a progress bar on stderr when it is a terminal), then writes
the speed histogram against the Maxwell–Boltzmann curve as a PNG.
"""
from __future__ import annotations

import pathlib
import sys

from engine._validate import as_fraction, as_positive
from engine.gas.initial import MAX_PACKING, radius_for_packing
from engine.gas.observables import (
    carnahan_starling,
    maxwell_boltzmann_test,
    plot_speed_histogram,
    speed_moment_ratio,
)
from engine.gas.simulate import simulate_gas

__all__ = ["run_gas_command"]


def progress_bar(stream, description: str = "gas"):
    """A ``progress(fraction)`` callable drawing a tqdm bar on ``stream`` — only when ``stream`` is a terminal (tqdm's
    ``disable=None``), so logs get no carriage-return frames — and the bar, to close when the run ends."""
    from tqdm import tqdm

    bar = tqdm(total=1000, desc=description, file=stream, disable=None, leave=False,
               bar_format="{desc}: {percentage:5.1f}%|{bar}| {elapsed} elapsed, {remaining} left")

    def show(fraction: float) -> None:
        target = int(round(1000 * min(max(fraction, 0.0), 1.0)))
        if target > bar.n:
            bar.update(target - bar.n)
            if target == 1000:  # the end is always drawn (updates in between are throttled)
                bar.refresh()

    return show, bar


def run_gas_command(n=2000, eta=0.2, method="events", boundary="walls", t_measure=20.0, seed=0, out="gas_speeds.png",
                    progress=True, *, dt=1e-3, broad_phase="sap", t_equilibrate=5.0, stdout=None, stderr=None) -> int:
    """Run ``simulate_gas`` for n spheres at packing fraction ``eta`` in the L = 10 box; returns 0 (exit status).

    Prints Z (virial, wall; periodic: Carnahan–Starling), Z from Γ, Γ, each with its standard error, the
    energy drift, the Kolmogorov–Smirnov p-value against Maxwell–Boltzmann, ⟨v⁴⟩/⟨v²⟩² and collisions per
    second; writes the speed histogram to ``out`` (PNG). Bad arguments raise ValueError/TypeError.
    """
    stdout = sys.stdout if stdout is None else stdout
    stderr = sys.stderr if stderr is None else stderr
    eta = as_fraction(eta, "eta")
    if not 0.0 < eta <= MAX_PACKING:
        raise ValueError(f"eta must lie in (0, {MAX_PACKING}], got {eta!r}")
    t_measure = as_positive(t_measure, "t_measure")
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise ValueError(f"n must be a positive int, got {n!r}")
    radius = radius_for_packing(n, eta, 10.0, boundary)
    show, bar = progress_bar(stderr) if progress else (None, None)
    try:
        res = simulate_gas(n, radius=radius, method=method, boundary=boundary, t_measure=t_measure,
                           t_equilibrate=t_equilibrate, dt=dt, broad_phase=broad_phase, seed=seed, progress=show)
    finally:
        if bar is not None:
            bar.close()
    ks, pvalue = maxwell_boltzmann_test(res.scaled_speeds[-n:])
    path = pathlib.Path(out)
    what = "event-driven" if method == "events" else f"stepped, dt = {dt:g}, broad phase {broad_phase}"
    lines = [
        f"confined gas: N = {n}, eta = {eta:g}, sigma = {res.sigma:.5g}, box = 10, {boundary}, {what}",
        f"  measured over t = {res.t_measure:g} after t = {t_equilibrate:g} of equilibration, "
        f"kT = {res.temperature:.6g}",
        f"  Z (collision virial)  = {res.z_virial:.4f} +- {res.z_virial_err:.4f}",
    ]
    if boundary == "walls":
        lines.append(f"  Z (wall impulses)     = {res.z_wall:.4f} +- {res.z_wall_err:.4f}")
    else:
        lines.append(f"  Z (Carnahan-Starling) = {carnahan_starling(res.packing_fraction):.4f}  "
                     "(bulk equation of state)")
    lines += [
        f"  Z = 1 + Gamma sigma sqrt(pi m/kT)/6 = {res.z_collision_rate:.4f}",
        f"  Gamma (collisions per particle per unit time) = {res.collision_rate:.4f} +- {res.collision_rate_err:.4f}",
        f"  collisions = {res.collisions}, energy drift max|E - E0|/E0 = {res.energy_drift:.2e}",
        f"  speeds: KS p-value against Maxwell-Boltzmann = {pvalue:.3f}, <v^4>/<v^2>^2 = "
        f"{speed_moment_ratio(res.scaled_speeds):.4f} (5/3 = 1.6667)",
        f"  speed: {res.collisions_per_second:,.0f} collisions per second (measurement window, {res.seconds:.2f} s)",
        f"  speed histogram: {path}",
    ]
    stdout.write("\n".join(lines) + "\n")
    stdout.flush()
    plot_speed_histogram(res.scaled_speeds, path,
                         f"{method}, {boundary}, N = {n}, eta = {eta:g} (KS p = {pvalue:.2f})")
    return 0
