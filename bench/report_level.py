"""The level part of the main job: reports/level.md, level.csv and level.png from the benchmark JSON.

Reads the benchmarks of bench/test_bench_level.py (``extra_info["suite"]`` "level": ``n``, ``peer``, the
stages ``stage_*`` and the counts against the exact answer; "level_distance": the distance agreement columns) and
writes, per N, the frame time of World (HeightField, TriangleMesh), MuJoCo's hfield and pybullet's heightfield
and concave mesh with World's ratios to them, the issue's targets (met / missed / not measured), each peer's
bodies wrong against the exact answer (missed, extra, those within 1e-7 of touching) and its sphere depth error,
then World's ``closest_points`` against coal. level.png (``level_picture``) draws a corner of the terrain with the
bodies over it, those that touch it coloured, and the contact points of World (of MuJoCo while the World has no
body–surface kernel, as the title says). Figures are drawn on their own Agg canvas: the process's matplotlib
backend is never switched.

The main job (``python -m bench.report``) writes this section from its run of every suite; on its own::

    python -m bench.report_level [--quick] [--out DIR] [-k EXPRESSION]
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pandas as pd

from bench.level_peers import NEAR_OFFSET, NEAR_TOUCHING, TERRAIN_SAMPLES, TERRAIN_SPACING

#: issue 31's targets (reported, not asserted): World's frame against MuJoCo's and pybullet's, its answers
TARGET_VS_MUJOCO, GOAL_VS_MUJOCO, TARGET_VS_BULLET = 1.0, 2.0, 3.0
TARGET_DEPTH = 1e-12
WORLDS = ("World field", "World mesh")
PEERS = ("MuJoCo hfield", "pybullet heightfield", "pybullet mesh")
FRAME_ORDER = (*WORLDS, *PEERS)
DISTANCE_ORDER = (*WORLDS, "coal BVH")


def level_rows(json_path: Path, info: dict, suite: str) -> pd.DataFrame:
    """One row per benchmark of ``suite``: its ``extra_info`` and the minimum and median time."""
    rows = []
    for b in json.loads(Path(json_path).read_text())["benchmarks"]:
        extra = b.get("extra_info") or {}
        if extra.get("suite") == suite:
            rows.append({**extra, "seconds_min": b["stats"]["min"], "seconds_median": b["stats"]["median"],
                         "rounds": b["stats"]["rounds"], "commit": info["commit"], "machine": info["machine"]})
    return pd.DataFrame(rows)


def _value(df, n, peer, column) -> float:
    row = df[(df.n == n) & (df.peer == peer)] if len(df) else df
    return float(row[column].iloc[0]) if len(row) and column in row and row[column].notna().iloc[0] else np.nan


def _ms(x) -> str:
    return "" if x != x else f"{1e3 * x:,.2f}"


def _num(x, fmt="{:,.0f}") -> str:
    return "" if x != x else fmt.format(x)


def _verdict(x, target) -> str:
    return "not measured" if x != x else ("met" if x >= target else "missed")


def _frame_lines(df) -> list[str]:
    lines = ["## Frame: upload + detection + reading the contacts", "",
             "The fastest of the timed frames; `× peer` is the peer's frame time over World's (HeightField): "
             "above 1, World is faster.", "",
             "| N | implementation | frame (ms) | upload | detect | read | World field × peer | World mesh × peer |",
             "|---:|---|---:|---:|---:|---:|---:|---:|"]
    for n in sorted(df.n.unique()):
        for peer in FRAME_ORDER:
            frame = _value(df, n, peer, "seconds_min")
            if frame != frame:
                continue
            ratios = [_num(frame / _value(df, n, w, "seconds_min"), "{:.2f}×") if peer not in WORLDS else ""
                      for w in WORLDS]
            stages = [_ms(_value(df, n, peer, f"stage_{s}")) for s in ("upload", "detect", "read")]
            lines.append(f"| {n:,} | {peer} | {_ms(frame)} | {' | '.join(stages)} | {' | '.join(ratios)} |")
    return lines + [""]


def _target_lines(df) -> list[str]:
    lines = ["## Targets (issue 31; reported, not asserted)", ""]
    skipped = not any(df.peer.isin(WORLDS))
    for n in sorted(df.n.unique()):
        for world in WORLDS:
            t = _value(df, n, world, "seconds_min")
            mj = _value(df, n, "MuJoCo hfield", "seconds_min") / t
            pb = min(_value(df, n, p, "seconds_min") for p in PEERS[1:]) / t
            lines.append(f"- N = {n:,}, {world}: × MuJoCo {_num(mj, '{:.2f}×')} (target ≥ {TARGET_VS_MUJOCO:g}×: "
                         f"{_verdict(mj, TARGET_VS_MUJOCO)}; goal {GOAL_VS_MUJOCO:g}×: "
                         f"{_verdict(mj, GOAL_VS_MUJOCO)}), × the faster pybullet {_num(pb, '{:.2f}×')} "
                         f"(target ≥ {TARGET_VS_BULLET:g}×: {_verdict(pb, TARGET_VS_BULLET)})")
            wrong, depth = _value(df, n, world, "wrong"), _value(df, n, world, "sphere_depth_error_max")
            exact = "not measured" if wrong != wrong else ("met" if wrong == 0 else f"missed ({wrong:.0f} bodies)")
            deep = "not measured" if depth != depth else ("met" if depth <= TARGET_DEPTH else "missed")
            lines.append(f"- N = {n:,}, {world}: touching set = the exact answer, every near body included: "
                         f"{exact}; sphere depths within {TARGET_DEPTH:g}: {deep}"
                         + ("" if depth != depth else f" ({depth:.1e})"))
    if skipped:
        lines.append("- World's rows were skipped in this run: the World has no kernel for a body against a "
                     "surface yet (`UnsupportedQuery`); they run unchanged once it has.")
    return lines + [""]


def _exact_lines(df) -> list[str]:
    lines = ["## Against the exact answer", "",
             f"Bodies whose touching verdict differs from the exact answer at the scene's poses (missed: touching "
             f"but not reported; extra: reported but apart), and how many of them are among the {NEAR_TOUCHING} "
             f"bodies placed within {NEAR_OFFSET:g}·size of touching; the sphere depth error is the largest "
             f"|depth − exact depth| over the spheres both find touching.", "",
             "| N | implementation | exact touching | touching | missed (near) | extra (near) | wrong | sphere "
             "depth error |", "|---:|---|---:|---:|---:|---:|---:|---:|"]
    for n in sorted(df.n.unique()):
        for peer in FRAME_ORDER:
            v = {k: _value(df, n, peer, k) for k in ("exact_touching", "touching", "missed", "missed_near",
                                                      "extra", "extra_near", "wrong", "sphere_depth_error_max")}
            if v["touching"] != v["touching"]:
                continue
            lines.append(f"| {n:,} | {peer} | {v['exact_touching']:,.0f} | {v['touching']:,.0f} | "
                         f"{v['missed']:.0f} ({v['missed_near']:.0f}) | {v['extra']:.0f} ({v['extra_near']:.0f}) | "
                         f"{v['wrong']:.0f} | {_num(v['sphere_depth_error_max'], '{:.1e}')} |")
    return lines + [""]


def _distance_lines(dist) -> list[str]:
    if dist.empty:
        return []
    lines = ["## Distances: World `closest_points` against coal", "",
             "The signed distance of every body to the surface at the scene's poses (one call for World, one "
             "`coal.distance` per body on coal's BVHModelOBBRSS). Against the exact answer: the largest error on "
             "the spheres (coal: apart spheres only — its distance of a penetrating sphere is that of one "
             "triangle), the bodies whose sign (distance ≤ 0) differs from the touching answer; against coal: "
             "the largest difference over bodies both find apart, the bodies whose sign differs.", "",
             "| N | implementation | time (ms) | × coal | sphere vs exact | sign ≠ exact | vs coal (apart) | "
             "sign ≠ coal |", "|---:|---|---:|---:|---:|---:|---:|---:|"]
    for n in sorted(dist.n.unique()):
        coal = _value(dist, n, "coal BVH", "seconds_min")
        for peer in DISTANCE_ORDER:
            t = _value(dist, n, peer, "seconds_min")
            if t != t:
                continue
            lines.append(f"| {n:,} | {peer} | {_ms(t)} | {_num(coal / t, '{:.2f}×') if peer != 'coal BVH' else ''} "
                         f"| {_num(_value(dist, n, peer, 'sphere_exact_max'), '{:.1e}')} "
                         f"| {_num(_value(dist, n, peer, 'vs_exact_sign_differs'))} "
                         f"| {_num(_value(dist, n, peer, 'vs_coal_apart_max'), '{:.1e}')} "
                         f"| {_num(_value(dist, n, peer, 'vs_coal_sign_differs'))} |")
    return lines + [""]


def level_markdown(frames: pd.DataFrame, dist: pd.DataFrame, info: dict, command: str, picture: str) -> str:
    lines = ["# The level: bodies on a terrain — World against MuJoCo, pybullet and coal", "",
             f"{info['date']} · commit `{info['commit']}` · {info['machine']} · produced by `{command}`", "",
             f"A {TERRAIN_SAMPLES} × {TERRAIN_SAMPLES} terrain of smooth hills at spacing {TERRAIN_SPACING:g} "
             f"(bench/level_peers.py), as World's `HeightField` and as the `TriangleMesh` of its triangles; N "
             f"bodies, half spheres (r = 0.3), half turned boxes (half extent 0.25), about half touching it, "
             f"{NEAR_TOUCHING} of them within {NEAR_OFFSET:g}·size of touching (half in, half out, placed by "
             f"bisection on the exact answer). Bodies pair with the terrain only (collision categories). MuJoCo "
             f"holds the heights normalised in float32 (its surface is ours to ~2e-7), pybullet computes in "
             f"float32: near-touching bodies are below their resolution. Each peer is judged at the scene's poses "
             f"after the timed frames, as a game would read it: pybullet's contact manifolds persist across frames "
             f"(earlier points are refreshed, not recomputed), which its depths show.", ""]
    if not frames.empty:
        lines += _frame_lines(frames) + _target_lines(frames) + _exact_lines(frames)
    lines += _distance_lines(dist)
    lines += ["## The picture", "", f"![level.png](level.png) — {picture}", ""]
    return "\n".join(lines)


def _box_faces(center, rotation, half):
    signs = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)], float)
    corners = center + (signs * half) @ rotation.T
    quads = [[0, 1, 3, 2], [4, 5, 7, 6], [0, 1, 5, 4], [2, 3, 7, 6], [0, 2, 6, 4], [1, 3, 7, 5]]
    return [corners[q][:, [0, 2, 1]] for q in quads]  # plotted as (x, z, y): y up


def _contacts(scene):
    """(points (M, 3), body (M,), whose) of World's contacts, or MuJoCo's while World cannot answer."""
    from bench.level_peers import LevelMuJoCoFrame, LevelWorldFrame
    from engine.world import UnsupportedQuery

    try:
        frame = LevelWorldFrame(scene, "field")
        frame.detect()
        return (*frame.contact_points(), "World (HeightField)")
    except UnsupportedQuery:
        frame = LevelMuJoCoFrame(scene)
        frame.detect()
        return (*frame.contact_points(), "MuJoCo (World has no body–surface kernel yet)")


def level_picture(path: Path, n: int = 2_000, window=(4.0, 16.0, 0.0, 12.0)) -> str:
    """Draw the terrain's window x0..x1, z0..z1 of ``level_scene(n)``, its bodies (touching ones orange by the
    exact answer) and the contact points (red); returns the caption."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    from bench.level_peers import exact_answer, level_scene, rotation_matrices

    scene = level_scene(n)
    touching, _ = exact_answer(scene)
    x0, x1, z0, z1 = window
    nx, nz = scene.heights.shape
    xs = scene.origin[0] + np.arange(nx) * scene.spacing
    zs = scene.origin[1] + np.arange(nz) * scene.spacing
    i, k = (xs >= x0) & (xs <= x1), (zs >= z0) & (zs <= z1)
    fig = Figure(figsize=(8, 6.5), dpi=110)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(projection="3d")
    gx, gz = np.meshgrid(xs[i], zs[k], indexing="ij")
    ax.plot_surface(gx, gz, scene.heights[np.ix_(i, k)], color="0.75", edgecolor="0.55", linewidth=0.2, alpha=0.6)
    c = scene.centers
    inside = (c[:, 0] >= x0 + 0.3) & (c[:, 0] <= x1 - 0.3) & (c[:, 2] >= z0 + 0.3) & (c[:, 2] <= z1 - 0.3)
    rot = rotation_matrices(scene.quaternions)
    u, v = np.meshgrid(np.linspace(0, 2 * np.pi, 14), np.linspace(0, np.pi, 8))
    for b in np.flatnonzero(inside):
        colour = "tab:orange" if touching[b] else "tab:blue"
        if scene.is_sphere[b]:
            r = scene.size[b]
            ax.plot_surface(c[b, 0] + r * np.cos(u) * np.sin(v), c[b, 2] + r * np.sin(u) * np.sin(v),
                            c[b, 1] + r * np.cos(v), color=colour, linewidth=0, alpha=0.85)
        else:
            ax.add_collection3d(Poly3DCollection(_box_faces(c[b], rot[b], scene.size[b]), facecolor=colour,
                                                 edgecolor="k", linewidth=0.2, alpha=0.85))
    points, body, whose = _contacts(scene)
    shown = inside[body]
    ax.scatter(points[shown, 0], points[shown, 2], points[shown, 1], color="red", s=10, depthshade=False)
    ax.set_xlabel("x")
    ax.set_ylabel("z")
    ax.set_zlabel("y (up)")
    ax.set_box_aspect((x1 - x0, z1 - z0, 4.0))
    caption = (f"the terrain over x ∈ [{x0:g}, {x1:g}], z ∈ [{z0:g}, {z1:g}] with the bodies of the N = {n:,} "
               f"scene whose centres lie over it (orange: touching by the exact answer, blue: apart) and the "
               f"contact points of {whose} (red)")
    ax.set_title(f"Level: bodies on the terrain, contacts of {whose.split(' (World')[0]}", fontsize=10)
    fig.tight_layout()
    fig.savefig(path)
    return caption


def level_section(json_path: Path, out: Path, info: dict, quick: bool, command: str | None = None):
    """level.md, level.csv (both suites, told apart by ``suite``) and level.png from the benchmark JSON; returns
    the index's rows."""
    command = command or "python -m bench.report" + (" --quick" if quick else "")
    frames, dist = level_rows(json_path, info, "level"), level_rows(json_path, info, "level_distance")
    if frames.empty and dist.empty:
        return []
    pd.concat([frames, dist], ignore_index=True).to_csv(out / "level.csv", index=False)
    caption = level_picture(out / "level.png")
    (out / "level.md").write_text(level_markdown(frames, dist, info, command, caption))
    return [("[level.md](level.md), [level.csv](level.csv), [level.png](level.png)",
             "the level: bodies on a 128 × 128 terrain — World's HeightField and TriangleMesh against MuJoCo's "
             "hfield and pybullet's heightfield and concave mesh (frame time, targets, bodies wrong against the "
             "exact answer, sphere depth error) and World's closest_points against coal; a picture of the "
             "bodies resting on the terrain with their contacts")]


def main(argv=None) -> int:
    """``python -m bench.report_level``: run bench/test_bench_level.py and write the level section alone."""
    from bench.report import section_main

    return section_main("level", level_section, argv)


if __name__ == "__main__":
    sys.exit(main())
