"""The scene-query part of the main job: reports/queries.md, queries.csv and queries.png from the benchmark JSON.

Reads the benchmarks of bench/test_bench_queries.py (``extra_info["suite"] == "queries"``: ``query``,
``workload``, ``n``, ``peer``, ``call``, ``work`` and the agreement with the exact answer ``outside_*`` /
``all_*``) and writes, per workload and N, the rays per second of World (each broad phase), pybullet and MuJoCo,
World's ratios to the peers measured in the same run, the issue's targets (met / not met) and the agreement
columns; then World's shape casts per second. The chart (rays per second against N, log-log, one line per engine
and workload) is drawn on a Figure with its own Agg canvas: the process's matplotlib backend is never switched.

The main job (``python -m bench.report``) writes this section from its run of every suite; on its own::

    python -m bench.report_queries [--quick] [--out DIR] [-k EXPRESSION]

runs bench/test_bench_queries.py (without the ``large`` size) and writes queries.md, queries.csv and queries.png
(to ``reports/``, or ``reports-quick/`` with ``--quick``); queries.md names the command that produced it.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pandas as pd

from bench.query_peers import BULLET_BATCH, CASTS, FAN_AZIMUTHS, FAN_ELEVATIONS, RAYS

#: the issue's targets: one thread, N = 10,000 bodies, World's default broad phase
TARGET_N = 10_000
DEFAULT = "World tree"
TARGET_VS_BULLET = 10.0  # random rays, against rayTestBatch
TARGET_VS_MUJOCO = 5.0  # mj_multiRay on the fan, the mj_ray loop on random rays
GOAL_RAYS_PER_SECOND = 1e6
PEER_ORDER = ("World tree", "World sap", "World grid", "pybullet", "MuJoCo")
WORKLOAD_ORDER = ("random", "fan")
WORKLOAD_TEXT = {"random": f"random rays ({RAYS:,})", "fan": f"lidar fan ({FAN_AZIMUTHS} × {FAN_ELEVATIONS})"}


def query_rows(json_path: Path, info: dict) -> pd.DataFrame:
    """One row per query benchmark: its ``extra_info``, the minimum and median time of a batch, and the batch's
    rate (``per_second``: rays or casts per second at the minimum)."""
    rows = []
    for b in json.loads(Path(json_path).read_text())["benchmarks"]:
        extra = b.get("extra_info") or {}
        if extra.get("suite") != "queries":
            continue
        best = b["stats"]["min"]
        rows.append({**extra, "seconds_min": best, "seconds_median": b["stats"]["median"],
                     "rounds": b["stats"]["rounds"], "per_second": extra["work"] / best if best > 0 else np.nan,
                     "commit": info["commit"], "machine": info["machine"]})
    df = pd.DataFrame(rows)
    if not df.empty:
        df = _with_ratios(df)
    return df


def _rate(df, query, workload, n, peer) -> float:
    row = df[(df["query"] == query) & (df.workload == workload) & (df.n == n) & (df.peer == peer)]
    return float(row.per_second.iloc[0]) if len(row) else np.nan


def _with_ratios(df: pd.DataFrame) -> pd.DataFrame:
    """``vs_pybullet`` and ``vs_mujoco``: each ray row's rate over the peer's on the same workload and N."""
    df = df.copy()
    for column, peer in (("vs_pybullet", "pybullet"), ("vs_mujoco", "MuJoCo")):
        df[column] = [r.per_second / _rate(df, "rays", r.workload, r.n, peer) if r["query"] == "rays" else np.nan
                      for _, r in df.iterrows()]
    return df


def _mrays(x) -> str:
    return "" if x != x else f"{x / 1e6:,.3f}"


def _ratio(x) -> str:
    return "" if x != x else f"{x:.2f}×"


def _sci(x) -> str:
    return "" if x is None or x != x else f"{x:.1e}"


def _fraction(x) -> str:
    return "" if x is None or x != x else f"{100 * x:.2f} %"


def _count(x) -> str:
    return "" if x is None or x != x else f"{int(x):,}"


def _get(r, key):
    return r[key] if key in r and r[key] == r[key] else np.nan


def _verdict(x: float, target: float) -> str:
    if x != x:
        return "not measured"
    return "met" if x >= target else "not met"


def _targets(df: pd.DataFrame) -> list[str]:
    rays = df[df["query"] == "rays"]
    world_random = _rate(rays, "rays", "random", TARGET_N, DEFAULT)
    world_fan = _rate(rays, "rays", "fan", TARGET_N, DEFAULT)
    vs_bullet = world_random / _rate(rays, "rays", "random", TARGET_N, "pybullet")
    vs_multiray = world_fan / _rate(rays, "rays", "fan", TARGET_N, "MuJoCo")
    vs_mj_ray = world_random / _rate(rays, "rays", "random", TARGET_N, "MuJoCo")
    lines = [f"## Targets (one thread, N = {TARGET_N:,} bodies, `World()` — the tree broad phase)", "",
             f"- random rays against pybullet `rayTestBatch`: {_ratio(vs_bullet)} (target ≥ {TARGET_VS_BULLET:g}×: "
             f"{_verdict(vs_bullet, TARGET_VS_BULLET)})",
             f"- the lidar fan against MuJoCo `mj_multiRay`: {_ratio(vs_multiray)} (target ≥ "
             f"{TARGET_VS_MUJOCO:g}×: {_verdict(vs_multiray, TARGET_VS_MUJOCO)})",
             f"- random rays against an `mj_ray` loop: {_ratio(vs_mj_ray)} (target ≥ {TARGET_VS_MUJOCO:g}×: "
             f"{_verdict(vs_mj_ray, TARGET_VS_MUJOCO)})",
             f"- goal beyond: {GOAL_RAYS_PER_SECOND / 1e6:g} million rays per second on one core — random rays "
             f"{_mrays(world_random)} M/s ({_verdict(world_random, GOAL_RAYS_PER_SECOND)}), the fan "
             f"{_mrays(world_fan)} M/s ({_verdict(world_fan, GOAL_RAYS_PER_SECOND)})", ""]
    if world_random != world_random:
        lines.insert(-1, f"(N = {TARGET_N:,} is not in this run: the targets are stated, not measured.)")
    return lines


def _ray_table(df: pd.DataFrame, workload: str) -> list[str]:
    lines = ["| N | engine | call | Mrays/s | × pybullet | × MuJoCo | agree (outside) | distance error: median / max "
             "| normal error max | agree (all rays, own convention) | rays starting inside a body |",
             "|---:|---|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    g = df[(df["query"] == "rays") & (df.workload == workload)]
    for n in sorted(g.n.unique()):
        for peer in PEER_ORDER:
            row = g[(g.n == n) & (g.peer == peer)]
            if not len(row):
                continue
            r = row.iloc[0]
            lines.append(
                f"| {n:,} | {peer} | `{r['call']}` | {_mrays(r.per_second)} | "
                f"{_ratio(r.vs_pybullet) if peer != 'pybullet' else ''} | "
                f"{_ratio(r.vs_mujoco) if peer != 'MuJoCo' else ''} | {_fraction(_get(r, 'outside_agree'))} | "
                f"{_sci(_get(r, 'outside_distance_error_median'))} / {_sci(_get(r, 'outside_distance_error_max'))} "
                f"| {_sci(_get(r, 'outside_normal_error_max'))} | {_fraction(_get(r, 'all_agree'))} | "
                f"{_count(_get(r, 'inside_start'))} of {_count(_get(r, 'agreement_rays'))} |")
    return lines + [""]


def _cast_table(df: pd.DataFrame) -> list[str]:
    g = df[df["query"] == "shape cast"]
    if g.empty:
        return []
    lines = ["## Shape casts (World alone)", "",
             f"`World.cast_shape(shape, displacement)` over {CASTS:,} random sweeps per batch: a sphere (r = 0.3) "
             "or a randomly turned box (half extents 0.3, 0.2, 0.1) from points uniform in the scene's box, "
             "displacements of random direction and length up to a quarter of the scene's size; one Python call "
             "per cast. pybullet and MuJoCo have no shape cast in their Python APIs.", "",
             "| N | shape | casts/s | µs per cast | hits | casts that raised |", "|---:|---|---:|---:|---:|---:|"]
    errors = []
    for _, r in g.sort_values(["n", "workload"]).iterrows():
        failed = int(_get(r, "errors")) if _get(r, "errors") == _get(r, "errors") else 0
        lines.append(f"| {r.n:,} | {r.workload} | {r.per_second:,.0f} | {1e6 / r.per_second:,.1f} | "
                     f"{int(r.hits):,} | {failed:,} |")
        if failed:
            errors.append(f"- N = {r.n:,}, {r.workload}: {failed:,} of {int(r.work):,} casts raised "
                          f"(the first: `{r.first_error}`); they are timed with the batch and not counted as hits.")
    return lines + [""] + (errors + [""] if errors else [])


def queries_markdown(df: pd.DataFrame, info: dict, command: str = "python -m bench.report") -> str:
    lines = ["# Scene queries: ray casts against pybullet and MuJoCo", "",
             f"{info['date']} · commit `{info['commit']}` · {info['machine']}", "",
             f"Produced by `{command}`.", "",
             "Same scene, same run (bench/test_bench_queries.py, bench/query_peers.py): the mixed frame scene — "
             "half spheres (r = 0.5), half randomly rotated boxes (half extents 0.4), uniform in a cube at solid "
             "fraction 0.06 — with a ground plane at the bottom of the cube. One thread everywhere. Workloads: "
             f"{RAYS:,} random rays (origins uniform in the scene's box, random unit directions, max_distance the "
             f"scene's size) and a lidar fan of {FAN_AZIMUTHS} × {FAN_ELEVATIONS} rays from one point of the "
             "scene outside every body (elevation −15°..+15°, same max_distance). Calls: World "
             "`cast_rays(origins, directions, max_distance)` (broad phase tree; SAP and grid at N = 10,000 only); "
             f"pybullet `rayTestBatch(from, to, numThreads=1)` in DIRECT mode, in pieces of at most "
             f"{BULLET_BATCH:,} rays (pybullet answers a batch of 16,384 rays with 16,383 results without a word, "
             "and refuses larger ones); MuJoCo `mj_multiRay` on the fan (one origin, many directions: its API "
             "takes a single origin) and an `mj_ray` loop in Python on the random rays (`flg_static=1`, "
             "`geomgroup=None`, `bodyexclude=-1`). MuJoCo is not run at N = 100,000 (its model reserves 4 N² "
             "bytes, and `mj_ray` tests every geom).", "",
             "Timing: each batch is called once untimed (a warm-up: compilation excluded), then timed 3 times; "
             "the table gives the minimum (the least disturbed run). `× pybullet` and `× MuJoCo` are the row's "
             "rays per second over the peer's on the same workload and N, measured in the same run.", "",
             "![rays per second against N](queries.png)", ""]
    lines += _targets(df)
    for workload in WORKLOAD_ORDER:
        if workload in set(df[df["query"] == "rays"].workload):
            lines += [f"## {WORKLOAD_TEXT[workload]}", "", *_ray_table(df, workload)]
    lines += _agreement_notes()
    lines += _cast_table(df)
    return "\n".join(lines)


def _agreement_notes() -> list[str]:
    return ["## Agreement with the exact answer", "",
            "The reference (bench/ray_reference.py) is a brute force over every body, independent of any "
            "engine's traversal: the quadratic for a sphere, the slab test in the box's frame for a box, the "
            "plane's crossing for the ground, in float64, vectorised over chunks of rays. A ray agrees when "
            "the reference and the engine both miss, or both hit at distances within 1e-9 × the scene's size "
            "(the cube's side). Distance and normal errors (|n − n_ref|, 2 for opposite normals) are over the "
            "rays both hit. At N = 100,000 the check is on the first 1,000 rays of each batch.", "",
            "Conventions, converted before comparing:", "",
            "- distance: World's is along the unit direction; pybullet's `hitFraction` is relative to the segment "
            "(distance = fraction × max_distance); MuJoCo's is along `vec` (unit vectors are passed), −1 for a "
            "miss, and `mj_ray` has no cutoff (a hit beyond max_distance counts as a miss);",
            "- a ray that starts inside a body: World hits it at distance 0 with normal −direction; pybullet "
            "does not report a box that holds the origin (the ray goes on to the next body) and reports a "
            "sphere at distance 0 for some rays and not for others; MuJoCo reports the point where the ray "
            "leaves the geom. `agree (outside)` counts only the rays that start outside every body (where the "
            "three agree on what the answer is: every fan ray); `agree (all rays, own convention)` compares every "
            "ray with the reference computed in the engine's own convention (World: 0; pybullet: the box "
            "skipped — its mixed answers for spheres count as disagreements; MuJoCo: the exit point);",
            "- the normal: World's and the reference's are outward unit normals; pybullet's `hitNormal` and "
            "MuJoCo's `normal` (the optional output of mj_ray / mj_multiRay) likewise;",
            "- pybullet casts rays against its convex shapes with a tolerance (its convex cast): its sphere hits "
            "are ~1e-4 off and rays that graze a sphere within ~1e-3 are reported as hits.", ""]


def queries_chart(df: pd.DataFrame, path: Path):
    """Rays per second against N (log-log), one line per engine and workload; returns the Figure."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6.4, 4.4), dpi=100)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 1, 1)
    rays = df[df["query"] == "rays"]
    for k, peer in enumerate(PEER_ORDER):  # one colour per engine, the line style per workload
        for workload in WORKLOAD_ORDER:
            g = rays[(rays.peer == peer) & (rays.workload == workload)].sort_values("n")
            if len(g):
                style = ("o" if peer.startswith("World") else "s") + ("-" if workload == "random" else "--")
                ax.loglog(g.n, g.per_second, style, color=f"C{k}", label=f"{peer}, {workload} ({g.call.iloc[0]})")
    ax.axhline(GOAL_RAYS_PER_SECOND, color="grey", lw=0.8, ls=":", label="goal: 1e6 rays/s")
    ax.set_xlabel("bodies N")
    ax.set_ylabel("rays per second (one thread)")
    ax.set_title("Ray casts: random rays (solid) and lidar fan (dashed)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path)
    return fig


def queries_section(json_path: Path, out: Path, info: dict, quick: bool, command: str | None = None):
    """queries.md, queries.csv and queries.png from the benchmark JSON; ``command``: what produced it, named in
    queries.md (by default the main job, ``python -m bench.report [--quick]``). Returns the index's rows."""
    command = command or "python -m bench.report" + (" --quick" if quick else "")
    df = query_rows(json_path, info)
    if df.empty:
        return []
    df.to_csv(out / "queries.csv", index=False)
    (out / "queries.md").write_text(queries_markdown(df, info, command))
    queries_chart(df, out / "queries.png")
    return [("[queries.md](queries.md), [queries.csv](queries.csv), [queries.png](queries.png)",
             "scene queries: World's ray casts (random rays, a lidar fan) against pybullet rayTestBatch and MuJoCo "
             "mj_multiRay / mj_ray in rays per second, with the issue's targets and the agreement with an exact "
             "brute-force answer; World's shape casts per second")]


def main(argv=None) -> int:
    """``python -m bench.report_queries``: run bench/test_bench_queries.py and write the queries section alone."""
    from bench.report import section_main

    return section_main("queries", queries_section, argv)


if __name__ == "__main__":
    sys.exit(main())
