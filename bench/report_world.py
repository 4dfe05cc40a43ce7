"""The World part of the main job: reports/world.md, world.csv and world.png from the benchmark JSON.

Reads the benchmarks of bench/test_bench_world.py (``extra_info``: ``scene``, ``n``, ``peer``, per-stage minima
``stage_*``, agreement counts ``vs_world_*`` and exact-depth differences ``exact_*``) and writes, per scene and
N, the frame time of World (each broad phase), MuJoCo and pybullet with their stages and ratios, the issue's
targets (met / missed), the fitted slope of frame time against N, and the agreement of the penetrating pair
sets and depths; then the static-level and masked benchmarks (bench/report_world_suites.py). The chart is built
on a Figure with its own Agg canvas: the process's matplotlib backend is never switched.

The main job (``python -m bench.report``) writes this section from its run of every suite; on its own::

    python -m bench.report_world [--quick] [--out DIR] [-k EXPRESSION]

runs bench/test_bench_world.py (without the ``large`` sizes) and writes world.md, world.csv and world.png (to
``reports/``, or ``reports-quick/`` with ``--quick``); world.md names the command that produced it.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pandas as pd

from bench.report_world_suites import masked_lines, static_level_lines, suite_rows

#: issue 15's targets on the mixed scene at N = 10,000 with the default World()
TARGET_N = 10_000
TARGET_VS_MUJOCO = 1.0
GOAL_VS_MUJOCO = 2.0
TARGET_DETECT_VS_BULLET = 2.0
TARGET_SLOPE = 1.1
#: the slope is fitted from this N on: the small scenes (N = 100) measure the frame's fixed cost, not its growth
SLOPE_MIN_N = 1_000
DEFAULT = "World tree"
PEER_ORDER = ("World tree", "World sap", "World grid", "MuJoCo", "pybullet")


def world_rows(json_path: Path, info: dict) -> pd.DataFrame:
    rows = []
    for b in json.loads(Path(json_path).read_text())["benchmarks"]:
        extra = b.get("extra_info") or {}
        if "scene" not in extra or "peer" not in extra or "suite" in extra:
            continue
        rows.append({**extra, "frame_min": b["stats"]["min"], "frame_median": b["stats"]["median"],
                     "rounds": b["stats"]["rounds"], "commit": info["commit"], "machine": info["machine"]})
    return pd.DataFrame(rows)


def _ms(x) -> str:
    return "" if x is None or x != x else f"{1e3 * x:,.2f}"


def _ratio(x) -> str:
    return "" if x is None or x != x else f"{x:.2f}×"


def _value(df, scene, n, peer, column):
    row = df[(df.scene == scene) & (df.n == n) & (df.peer == peer)]
    return float(row[column].iloc[0]) if len(row) and column in row and row[column].notna().iloc[0] else np.nan


def fitted_slope(df, scene: str, peer: str) -> float:
    """Least-squares slope of log(frame time) against log(N) over the sizes measured from ``SLOPE_MIN_N`` on
    (NaN below 2 sizes)."""
    g = df[(df.scene == scene) & (df.peer == peer) & (df.n >= SLOPE_MIN_N)].sort_values("n")
    if len(g) < 2:
        return float("nan")
    return float(np.polyfit(np.log(g.n.astype(float)), np.log(g.frame_min.astype(float)), 1)[0])


def _timing_table(df, scene) -> list[str]:
    lines = ["| N | implementation | frame (ms) | upload | broad | narrow | contacts / read | time_of_impact "
             "| × MuJoCo frame | detection × pybullet |", "|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for n in sorted(df[df.scene == scene].n.unique()):
        mj = _value(df, scene, n, "MuJoCo", "frame_min")
        pb_detect = _value(df, scene, n, "pybullet", "stage_detect") + _value(df, scene, n, "pybullet", "stage_read")
        for peer in PEER_ORDER:
            if not len(df[(df.scene == scene) & (df.n == n) & (df.peer == peer)]):
                continue
            frame = _value(df, scene, n, peer, "frame_min")
            world = peer.startswith("World")
            detect = _value(df, scene, n, peer, "stage_detect") + _value(df, scene, n, peer, "stage_read")
            stage = {name: _ms(_value(df, scene, n, peer, f"stage_{name}"))
                     for name in ("upload", "broad", "narrow", "contacts", "detect", "read")}
            lines.append(
                f"| {n:,} | {peer} | {_ms(frame)} | {stage['upload']} | {stage['broad'] if world else ''} | "
                f"{stage['narrow'] if world else stage['detect']} | {stage['contacts'] if world else stage['read']} | "
                f"{_ms(_value(df, scene, n, peer, 'time_of_impact_min')) if world else ''} | "
                f"{_ratio(mj / frame) if world else ''} | {_ratio(pb_detect / detect) if world else ''} |")
    return lines


def _targets(df) -> list[str]:
    lines = ["## Targets (issue 15: mixed scene, N = 10,000, default `World()`)", ""]
    frame = _value(df, "mixed", TARGET_N, DEFAULT, "frame_min")
    mj = _value(df, "mixed", TARGET_N, "MuJoCo", "frame_min")
    detect = _value(df, "mixed", TARGET_N, DEFAULT, "stage_detect") + _value(df, "mixed", TARGET_N, DEFAULT,
                                                                              "stage_read")
    pb = _value(df, "mixed", TARGET_N, "pybullet", "stage_detect") + _value(df, "mixed", TARGET_N, "pybullet",
                                                                             "stage_read")

    def verdict(x, target):
        return "not measured" if x != x else ("met" if x >= target else "missed")

    lines.append(f"- upload + detect against MuJoCo's frame: {_ratio(mj / frame)} (target ≥ {TARGET_VS_MUJOCO:g}×: "
                 f"{verdict(mj / frame, TARGET_VS_MUJOCO)}; goal {GOAL_VS_MUJOCO:g}×: "
                 f"{verdict(mj / frame, GOAL_VS_MUJOCO)})")
    lines.append(f"- detection against pybullet's: {_ratio(pb / detect)} (target ≥ {TARGET_DETECT_VS_BULLET:g}×: "
                 f"{verdict(pb / detect, TARGET_DETECT_VS_BULLET)})")
    for scene in sorted(df.scene.unique()):
        for peer in PEER_ORDER:
            slope = fitted_slope(df, scene, peer)
            if slope == slope and peer.startswith("World"):
                sizes = sorted(df[(df.scene == scene) & (df.peer == peer) & (df.n >= SLOPE_MIN_N)].n.unique())
                reach = "met" if slope <= TARGET_SLOPE else "missed"
                if max(sizes) < 100_000:
                    reach += " (N = 1e5 not in this run: `-m large`)"
                lines.append(f"- {scene}, {peer}: fitted slope of frame time against N over "
                             f"{', '.join(f'{s:,}' for s in sizes)}: {slope:.2f} (target ≤ {TARGET_SLOPE:g}: {reach})")
    return lines + [""]


def _agreement(df) -> list[str]:
    lines = ["## Agreement at the last frame", "",
             "Penetrating pairs (depth > 1e-6) of each peer against World's (tree), and depths against World's "
             "and against the exact depth — the distance from the origin to the boundary of the Minkowski "
             "difference (Qhull), on a fixed sample of World's penetrating pairs. MuJoCo's and Bullet's depths "
             "are per contact point (the deepest point is taken); World's is the pair's minimum translation "
             "distance.", "",
             "| scene | N | implementation | penetrating pairs | both | World only | peer only | depth vs World: "
             "median / max | vs exact (sample): median / max |",
             "|---|---:|---|---:|---:|---:|---:|---:|---:|"]
    for (scene, n), g in df.sort_values(["scene", "n"]).groupby(["scene", "n"], sort=False):
        for _, r in g.set_index("peer").reindex([p for p in PEER_ORDER if p in set(g.peer)]).iterrows():
            both = r.get("vs_world_common")
            cells = ["", "", "", ""] if both != both or both is None else [
                f"{int(both):,}", f"{int(r['vs_world_reference_only']):,}", f"{int(r['vs_world_peer_only']):,}",
                f"{r['vs_world_depth_diff_median']:.1e} / {r['vs_world_depth_diff_max']:.1e}"]
            exact = f"{r['exact_diff_median']:.1e} / {r['exact_diff_max']:.1e} ({int(r['exact_sampled'])})"
            lines.append(f"| {scene} | {n:,} | {r.name} | {int(r['penetrating_pairs']):,} | {' | '.join(cells)} | "
                         f"{exact} |")
    return lines + [""]


def world_markdown(df: pd.DataFrame, info: dict, suites: tuple = (), command: str = "python -m bench.report"
                   ) -> str:
    """The report: the frame benchmark's sections (when ``df`` has rows), then the lines of each of ``suites``."""
    lines = ["# The collision frame: World against MuJoCo and pybullet", "",
             f"{info['date']} · commit `{info['commit']}` · {info['machine']}", "",
             f"Produced by `{command}`.", ""]
    if not df.empty:
        lines += _frame_lines(df)
    for suite in suites:
        lines += suite
    return "\n".join(lines)


def _frame_lines(df: pd.DataFrame) -> list[str]:
    lines = ["Same scenes, same run (bench/test_bench_world.py, engine.workloads.frame_scene). A frame is the pose "
             "upload of every body, detection, and reading the contacts: World `update(ids, centers, "
             "rotations=quaternions)` + `contacts()`; MuJoCo `qpos` + `mj_kinematics` + `mj_collision` + "
             "`d.contact`; pybullet `resetBasePositionAndOrientation` per body + `performCollisionDetection` + "
             "`getContactPoints`. Each benchmark runs 40 untimed frames first (the tree's fat boxes reach their "
             "steady state), then times 8; times are minimums. Stages: World's broad phase (the fat-box tree, "
             "IncrementalSAP or the grid), narrow phase (the compiled dispatch loop and the batched GJK/EPA rows) "
             "and contacts (the record, persistence); MuJoCo's and Bullet's detection is one call (shown under "
             "narrow). `time_of_impact`: World's `time_of_impact(1/60)` at the last pose, each body moving to its "
             "next pose (its own call, not part of the frame). "
             "`× MuJoCo frame` = MuJoCo's frame / World's; `detection × pybullet` = pybullet's detection "
             "and reading / World's `contacts()`. MuJoCo is not run at N = 1e5: its broad phase reserves 4 N² "
             "bytes (40 GB).", "", "![frame time against N](world.png)", ""]
    lines += _targets(df)
    for scene in ("mixed", "pile", "hulls"):
        if scene in set(df.scene):
            lines += [f"## Scene: {scene}", "", *_timing_table(df, scene), ""]
    return lines + _agreement(df)


def world_chart(df: pd.DataFrame, path: Path):
    """Frame time against N per scene (log-log), one line per implementation; returns the Figure."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    scenes = [s for s in ("mixed", "pile", "hulls") if s in set(df.scene)]
    fig = Figure(figsize=(4.2 * max(len(scenes), 1), 3.6), dpi=100)
    FigureCanvasAgg(fig)
    for k, scene in enumerate(scenes):
        ax = fig.add_subplot(1, len(scenes), k + 1)
        for peer in PEER_ORDER:
            g = df[(df.scene == scene) & (df.peer == peer)].sort_values("n")
            if len(g):
                ax.loglog(g.n, 1e3 * g.frame_min, "o-" if peer.startswith("World") else "s--", label=peer)
        ax.set_title(f"scene: {scene}")
        ax.set_xlabel("bodies N")
        ax.set_ylabel("frame (ms)")
        ax.grid(True, which="both", alpha=0.3)
    if scenes:
        fig.axes[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path)
    return fig


def world_section(json_path: Path, out: Path, info: dict, quick: bool, command: str | None = None):
    """world.md, world.csv (the frame rows, then the static-level and masked rows, told apart by ``suite``) and
    world.png from the benchmark JSON; ``command``: what produced it, named in world.md (by default the main
    job, ``python -m bench.report [--quick]``)."""
    command = command or "python -m bench.report" + (" --quick" if quick else "")
    df = world_rows(json_path, info)
    level, masked = suite_rows(json_path, "static_level"), suite_rows(json_path, "masked")
    if df.empty and level.empty and masked.empty:
        return []
    pd.concat([df.assign(suite="frame"), level, masked], ignore_index=True).to_csv(out / "world.csv", index=False)
    (out / "world.md").write_text(world_markdown(df, info, (static_level_lines(level), masked_lines(masked)),
                                                 command))
    if not df.empty:
        world_chart(df, out / "world.png")
    return [("[world.md](world.md), [world.csv](world.csv), [world.png](world.png)",
             "the collision frame: World (tree, SAP, grid) against MuJoCo and pybullet on three scenes (mixed "
             "spheres and boxes, a resting pile, capsules and hulls), per stage, with the issue's targets, the "
             "fitted slope against N, and the agreement of pair sets and depths (with exact Qhull depths); a "
             "static level (5,000 static boxes, 500 moving bodies) and the mixed scene with collision masks")]


def main(argv=None) -> int:
    """``python -m bench.report_world``: run bench/test_bench_world.py and write the world section alone."""
    from bench.report import section_main

    return section_main("world", world_section, argv)


if __name__ == "__main__":
    sys.exit(main())
