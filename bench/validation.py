"""Validation runs of the main job: the engine against its oracles on fixed, documented cases.

Each section is a function ``(out, info, quick) -> [(link, what it shows)]`` that writes its files in ``out``;
a section whose runs are points of a distributed sweep (bench/sweep.py) also takes ``client=`` (the report's
Dask client, None for a serial run), as the gas section does.
The tolerances are the ones the property suite enforces (properties/), so a row marked ``FAIL`` here is a
regression the CI would also catch on random cases.
"""
from __future__ import annotations

import math

import numpy as np
import pandas as pd

from bench.validation_gas import gas_section
from engine.oracles import free_fall_impacts, reference_impacts


def _rows_to_markdown(df: pd.DataFrame) -> list[str]:
    lines = ["| case | quantity | engine | oracle | relative error | tolerance | |",
             "|---|---|---:|---:|---:|---:|---|"]
    for _, r in df.iterrows():
        lines.append(f"| {r['case']} | {r['quantity']} | {r['engine']:.12g} | {r['oracle']:.12g} | "
                     f"{r['rel_error']:.2e} | {r['tolerance']:.0e} | {'ok' if r['ok'] else 'FAIL'} |")
    return lines


def dynamics_section(out, info, quick=False):
    """Falling bodies: impact times against exact answers and solve_ivp; RK4's order; bisection's bound."""
    from engine import bisect, drop_cube, drop_particle, rk4_step
    from engine.dynamics.plot import plot_fall

    rows = []

    def add(case, quantity, engine, oracle, tolerance):
        rel = abs(engine - oracle) / abs(oracle)
        rows.append(dict(case=case, quantity=quantity, engine=engine, oracle=oracle, rel_error=rel,
                         tolerance=tolerance, ok=rel <= tolerance))

    for h in (1.0, 10.0, 50.0):
        r = drop_particle(h, t_end=float(free_fall_impacts(h, 6)[-1]))
        for k, (imp, ref) in enumerate(zip(r.impacts, free_fall_impacts(h, 5))):
            add(f"free fall h={h:g}, e=1", f"t impact {k + 1}", imp.t, ref, 1e-8)
        add(f"free fall h={h:g}, e=1", "bounce height after 5", r.impacts[4].v_after ** 2 / (2 * 9.81), h, 1e-8)
    for h, m, k, e, dt in [(10.0, 1.0, 0.2, 0.8, 0.01), (2.0, 0.5, 0.8, 1.0, 0.005), (40.0, 3.0, 1.5, 0.6, 0.01)]:
        r = drop_particle(h, mass=m, drag=k, restitution=e, dt=dt, t_end=1e3)
        for j, ref in enumerate(reference_impacts(h, m, k, e, 3)):
            add(f"linear drag h={h:g} m={m:g} k={k:g} e={e:g} dt={dt:g}", f"t impact {j + 1}", r.impacts[j].t, ref,
                1e-7)
    r = drop_particle(10.0, quadratic_drag=0.3, t_end=1e3)
    add("quadratic drag h=10 c=0.3", "t impact 1", r.impacts[0].t, reference_impacts(10.0, 1.0, 0.0, 1.0, 1, 0.3)[0],
        1e-7)
    c = drop_cube(5.0, size=1.0)
    add("cube h=5 size=1", "t contact", c.t_contact, math.sqrt(2 * 4.5 / 9.81), 1e-8)
    c = drop_cube(5.0, size=1.0, mass=2.0, drag=0.7)
    add("cube h=5 size=1 m=2 k=0.7", "t contact", c.t_contact, reference_impacts(5.0, 2.0, 0.7, 0.0, 1, ground=0.5)[0],
        1e-7)
    df = pd.DataFrame(rows)
    df.insert(0, "commit", info["commit"])
    df.to_csv(out / "dynamics.csv", index=False)

    # RK4 order on the damped oscillator x'' = -x - 0.4 x', t in [0, 2]
    from scipy.linalg import expm

    A = np.array([[0.0, 1.0], [-1.0, -0.4]])
    y0 = np.array([1.0, 0.3])
    exact = expm(2.0 * A) @ y0
    order_rows = []
    for n in (10, 20, 40, 80, 160):
        y, dt = y0.copy(), 2.0 / n
        for i in range(n):
            y = rk4_step(lambda t, Y: A @ Y, i * dt, y, dt)
        order_rows.append((dt, float(np.linalg.norm(y - exact))))

    _, info_b = bisect(lambda x: x**3 - 2.0, 0.0, 2.0, 1e-12, full_output=True)
    bound = math.ceil(math.log2(2.0 / 1e-12)) + 1

    demo = drop_particle(10.0, restitution=0.8, drag=0.2, t_end=10.0)
    plot_fall(demo.t, demo.y, [i.t for i in demo.impacts], [0.0] * len(demo.impacts),
              "particle, h = 10 m, e = 0.8, k = 0.2", path=out / "fall_particle.png")

    lines = ["# Falling bodies: validation", "",
             f"{info['date']} · commit `{info['commit']}` · {info['machine']}", "",
             "Chapter slides: \"La particule qui chute sur le sol\" (RK4 with drag, tc by bisection — Algorithme 3 —, "
             "v_after = −e·v_before) and the cube \"Application\". Oracles: the exact free-fall times "
             "sqrt(2h/g)(2k+1); scipy `solve_ivp` (RK45, rtol = atol = 1e-12) with a terminal event, restarted "
             "after each impact. Engine: dt = 0.01 s unless stated, tol = 1e-10 s.", "",
             *_rows_to_markdown(df), "",
             "## RK4 is fourth order", "",
             "Damped oscillator x'' = −x − 0.4x' on [0, 2] against the matrix exponential; halving dt divides "
             "the global error by ≈ 16.", "", "| dt | global error | ratio to previous |", "|---:|---:|---:|"]
    prev = None
    for dt, err in order_rows:
        lines.append(f"| {dt:g} | {err:.3e} | {'' if prev is None else f'{prev / err:.2f}'} |")
        prev = err
    lines += ["", "## Bisection (Algorithme 3)", "",
              f"Root of x³ − 2 on [0, 2] with ε = 1e-12: {info_b.iterations} halvings "
              f"(bound ceil(log2((b − a)/ε)) + 1 = {bound}); error {abs(info_b.root - 2 ** (1 / 3)):.1e}.", "",
              f"Demonstration run (h = 10 m, e = 0.8, k = 0.2): {len(demo.impacts)} impacts, resting contact from "
              f"t = {demo.rest_time:.4f} s, {demo.bisection_iterations} bisection re-integrations in all.", "",
              "![falling particle](fall_particle.png)", ""]
    (out / "dynamics.md").write_text("\n".join(lines))
    n_fail = int((~df["ok"]).sum())
    print(f"  dynamics: {len(df)} checks, {n_fail} failing", flush=True)
    return [("[dynamics.md](dynamics.md), [dynamics.csv](dynamics.csv), [fall_particle.png](fall_particle.png)",
             "falling particle and cube: impact times against exact answers and solve_ivp, RK4's order, "
             "bisection's iteration bound")]


SECTIONS = [("dynamics", dynamics_section), ("gas", gas_section)]
