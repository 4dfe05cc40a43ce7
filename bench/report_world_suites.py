"""The static-level and masked benchmarks of bench/test_bench_world.py, as sections of reports/world.md.

Reads the benchmarks whose ``extra_info["suite"]`` is "static_level" or "masked" (``peer``, the stages of the
fastest frame ``stage_*``, World's counts, the agreement ``vs_world_*`` with World's penetrating pairs) and writes
one table per size with the frame times, the ratios against the peers measured in the same run, the targets
(met / missed), the narrow tests and the agreement counts.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

from bench.world_peers import AGREEMENT_BAND
from engine.workloads import CATEGORY_MASKS, COLLIDING_CATEGORY_PAIRS, MASKED_CATEGORY_PAIRS

#: the static level the targets are stated for: (static boxes, moving bodies)
LEVEL_TARGET_SIZE = (5_000, 500)
#: World's frame with the level at most this many times its frame of the moving bodies alone
TARGET_LEVEL_VS_ALONE = 2.0
#: MuJoCo's frame over World's, at least
TARGET_LEVEL_VS_MUJOCO = 1.0
#: pybullet's detection (performCollisionDetection + getContactPoints) over World's contacts(), at least
TARGET_LEVEL_DETECT_VS_BULLET = 2.0
LEVEL_PEERS = ("World", "World alone", "World, level filtered", "MuJoCo", "pybullet")
MASKED_PEERS = ("World", "MuJoCo", "pybullet")


def suite_rows(json_path: Path, suite: str) -> pd.DataFrame:
    """One row per benchmark of ``suite``: its ``extra_info``, the minimum and median frame, and ``detection``
    (the fastest detect + read over the timed frames)."""
    rows = []
    for b in json.loads(Path(json_path).read_text())["benchmarks"]:
        extra = b.get("extra_info") or {}
        if extra.get("suite") == suite:
            rows.append({**extra, "frame_min": b["stats"]["min"], "frame_median": b["stats"]["median"],
                         "detection": extra["detection_min"]})
    return pd.DataFrame(rows)


def _ms(x) -> str:
    return "" if x != x else f"{1e3 * x:,.3f}"


def _times(x) -> str:
    return "" if x != x else f"{x:.2f}×"


def _count(x) -> str:
    return "" if x is None or x != x else f"{int(x):,}"


def _verdict(x: float, target: float, at_most: bool = False) -> str:
    if x != x:
        return "not measured"
    return "met" if (x <= target if at_most else x >= target) else "missed"


def _value(g: pd.DataFrame, column: str, **where) -> float:
    """The value of ``column`` in the row of ``g`` matching ``where`` (NaN when absent)."""
    for key, value in where.items():
        g = g[g[key] == value]
    return float(g[column].iloc[0]) if len(g) and column in g and g[column].notna().iloc[0] else float("nan")


def _agreement_cells(r) -> list[str]:
    return [_count(r.get(f"vs_world_{k}")) for k in ("common", "reference_only", "peer_only")]


def _agreement_text(r, peer: str) -> str:
    """Whether a peer's penetrating pairs are World's: identical, identical outside the band, or not, with the
    counts."""
    both, w_only, p_only = (int(r[f"vs_world_{k}"]) for k in ("common", "reference_only", "peer_only"))
    counts = f"{both:,} both, {w_only:,} World only, {p_only:,} {peer} only"
    if w_only == p_only == 0:
        return f"{peer}'s identical to World's ({counts})"
    beyond = int(r["vs_world_beyond_band"])
    if beyond == 0:
        return (f"{peer}'s identical to World's outside the {AGREEMENT_BAND:g} band ({counts}; the deepest pair "
                f"found by one side only: {r['vs_world_one_sided_max_depth']:.1e})")
    return f"{peer}'s differ from World's: {beyond:,} pairs deeper than {AGREEMENT_BAND:g} found by one side ({counts})"


# ---------------------------------------------------------------------------------------------------------------
# the static level
# ---------------------------------------------------------------------------------------------------------------

def _level_ratios(g: pd.DataFrame) -> dict:
    """World's frame over World alone's, MuJoCo's frame over World's, pybullet's detection over World's."""
    frame, detection = _value(g, "frame_min", peer="World"), _value(g, "detection", peer="World")
    alone = _value(g, "frame_min", peer="World alone")
    return {"alone": frame / alone, "filtered": _value(g, "frame_min", peer="World, level filtered") / alone,
            "mujoco": _value(g, "frame_min", peer="MuJoCo") / frame,
            "bullet": _value(g, "detection", peer="pybullet") / detection}


def _level_table(g: pd.DataFrame) -> list[str]:
    ratios = _level_ratios(g)
    lines = ["| implementation | frame (ms) | upload | detection | frame ÷ World alone | × MuJoCo frame | "
             "detection × pybullet | candidate pairs (with the level) | narrow tests | penetrating pairs "
             "(with the level) | both | World only | peer only |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for _, r in g.set_index("peer").reindex([p for p in LEVEL_PEERS if p in set(g.peer)]).iterrows():
        world = r.name == "World"
        cells = [_times(ratios[k]) if world else "" for k in ("alone", "mujoco", "bullet")]
        cand = _count(r.get("candidate_pairs"))
        cand = f"{cand} ({_count(r.get('static_pairs'))})" if cand else ""
        lines.append(f"| {r.name} | {_ms(r.frame_min)} | {_ms(r.stage_upload)} | {_ms(r.detection)} | "
                     f"{' | '.join(cells)} | {cand} | {_count(r.get('narrow_tests'))} | "
                     f"{_count(r.penetrating_pairs)} ({_count(r.level_pairs)}) | {' | '.join(_agreement_cells(r))} |")
    return lines


def _level_targets(g: pd.DataFrame) -> list[str]:
    ratios = _level_ratios(g)
    ms = {p: _ms(_value(g, "frame_min", peer=p)) for p in LEVEL_PEERS}
    det = {p: _ms(_value(g, "detection", peer=p)) for p in ("World", "pybullet")}
    mj = g[g.peer == "MuJoCo"]
    return [
        f"- World's frame with the level ÷ its frame of the moving bodies alone: {_times(ratios['alone'])} "
        f"({ms['World']} ms against {ms['World alone']} ms; target ≤ {TARGET_LEVEL_VS_ALONE:g}×: "
        f"{_verdict(ratios['alone'], TARGET_LEVEL_VS_ALONE, at_most=True)})",
        f"- against MuJoCo's frame: {_times(ratios['mujoco'])} ({ms['MuJoCo']} ms against {ms['World']} ms; "
        f"target ≥ {TARGET_LEVEL_VS_MUJOCO:g}×: {_verdict(ratios['mujoco'], TARGET_LEVEL_VS_MUJOCO)})",
        f"- detection against pybullet's: {_times(ratios['bullet'])} ({det['pybullet']} ms against "
        f"{det['World']} ms; target ≥ {TARGET_LEVEL_DETECT_VS_BULLET:g}×: "
        f"{_verdict(ratios['bullet'], TARGET_LEVEL_DETECT_VS_BULLET)})",
        "- penetrating pairs: " + (_agreement_text(mj.iloc[0], "MuJoCo") if len(mj) else "MuJoCo not run"),
        f"- what holding the level costs when it makes no pair (World, level filtered ÷ World alone): "
        f"{_times(ratios['filtered'])} ({ms['World, level filtered']} ms against {ms['World alone']} ms): the "
        "difference between World's frame with the level and alone is the narrow phase and the contacts of the "
        "pairs the level makes (see the narrow tests and penetrating pairs below)"]


def static_level_lines(df: pd.DataFrame) -> list[str]:
    """The section of the static-level benchmark (empty when it was not run)."""
    if df.empty:
        return []
    lines = ["## Static level", "",
             "`engine.workloads.static_level`: a level of static boxes on a grid of 4 m cells — a floor slab per "
             "cell, walls, pillars and crates (two boxes per cell on average, sizes 0.3 to 4) — and the mixed "
             "scene's moving spheres and boxes among them, 60 % pressing into the floor, the others above it "
             "among the walls, pillars and crates; every frame each moving body steps by 0.02 and turns by 0.02. "
             "World: the level added `static=True` (a tree of its own, never paired with itself); World alone: "
             "the moving bodies without the level, same poses; World, level filtered: the level present in a "
             "category the moving bodies' mask leaves out (its pairs are found and dropped before the narrow "
             "phase); MuJoCo: the level as geoms of the world body "
             "(never tested against each other); pybullet: the level as multibodies of mass 0. Detection: "
             "World's `contacts()`, MuJoCo's `mj_kinematics` + `mj_collision` + `d.contact`, pybullet's "
             "`performCollisionDetection` + `getContactPoints`, the fastest over the timed frames (frame: the fastest "
             "frame, upload: its upload). Candidate pairs: those of World's broad phase "
             "(fat boxes), in brackets those with a level box; penetrating pairs (depth > 1e-6) at the last "
             "frame, in brackets those with a level box; both / World only / peer only: against World's "
             "penetrating pairs (the benchmark asserts MuJoCo's equal World's outside a band of 5e-3).", ""]
    for (n_static, n_moving), g in df.sort_values(["n_static", "n_moving"]).groupby(["n_static", "n_moving"]):
        lines += [f"### {n_static:,} static boxes, {n_moving:,} moving bodies", ""]
        if (n_static, n_moving) == LEVEL_TARGET_SIZE:
            lines += ["Targets:", "", *_level_targets(g), ""]
        lines += [*_level_table(g), ""]
    return lines


# ---------------------------------------------------------------------------------------------------------------
# the masked mixed scene
# ---------------------------------------------------------------------------------------------------------------

def _masks_text() -> str:
    masks = ", ".join(f"category {c} (bit {1 << c}): mask {m:#06b}" for c, m in enumerate(CATEGORY_MASKS))
    pairs = ", ".join(f"({a}, {b})" for a, b in COLLIDING_CATEGORY_PAIRS)
    off = ", ".join(f"({a}, {b})" for a, b in MASKED_CATEGORY_PAIRS)
    return (f"`engine.workloads.category_masks`: body i in category i mod 4; {masks}. The category pairs that "
            f"collide: {pairs}; masked off: {off} — 5 of the 10, and half of the body pairs. The masks are "
            "symmetric (a's mask holds b iff b's holds a), so Box2D's and pybullet's rule (`category_i & mask_j` "
            "and `category_j & mask_i`), World's, and MuJoCo's (`contype_i & conaffinity_j` or `contype_j & "
            "conaffinity_i`, with contype = category and conaffinity = mask) give the same pair sets.")


def _masked_table(g: pd.DataFrame) -> list[str]:
    lines = ["| implementation | filter | frame (ms) | detection | masked ÷ unmasked frame | × MuJoCo frame | "
             "detection × pybullet | candidate pairs | filtered | narrow tests | penetrating pairs | both | "
             "World only | peer only |", "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for peer in [p for p in MASKED_PEERS if p in set(g.peer)]:
        for masked in (True, False):
            r = g[(g.peer == peer) & (g.masked == masked)]
            if not len(r):
                continue
            r = r.iloc[0]
            own = _value(g, "frame_min", peer=peer, masked=not masked)
            change = _times(r.frame_min / own) if masked else ""
            world = peer == "World"
            mj = _value(g, "frame_min", peer="MuJoCo", masked=masked) / r.frame_min if world else np.nan
            pb = _value(g, "detection", peer="pybullet", masked=masked) / r.detection if world else np.nan
            lines.append(f"| {peer} | {'masked' if masked else 'none'} | {_ms(r.frame_min)} | {_ms(r.detection)} | "
                         f"{change} | {_times(mj)} | {_times(pb)} | {_count(r.get('candidate_pairs'))} | "
                         f"{_count(r.get('filtered'))} | {_count(r.get('narrow_tests'))} | "
                         f"{_count(r.penetrating_pairs)} | {' | '.join(_agreement_cells(r))} |")
    return lines


def _pair_sets_line(g: pd.DataFrame) -> str:
    """Whether MuJoCo's and pybullet's masked penetrating pair sets are World's, with the counts."""
    parts = [_agreement_text(g[(g.peer == peer) & g.masked].iloc[0], peer) for peer in ("MuJoCo", "pybullet")
             if len(g[(g.peer == peer) & g.masked])]
    return "- masked penetrating pair sets: " + "; ".join(parts)


def _masked_summary(g: pd.DataFrame) -> list[str]:
    tests = {m: _value(g, "narrow_tests", peer="World", masked=m) for m in (True, False)}
    frames = {m: _value(g, "frame_min", peer="World", masked=m) for m in (True, False)}
    return [f"- World's narrow tests: {_count(tests[True])} masked against {_count(tests[False])} unmasked "
            f"({_times(tests[True] / tests[False])}); {_count(_value(g, 'filtered', peer='World', masked=True))} of "
            f"{_count(_value(g, 'candidate_pairs', peer='World', masked=True))} candidate pairs filtered",
            f"- World's frame: {_ms(frames[True])} ms masked against {_ms(frames[False])} ms unmasked "
            f"({_times(frames[True] / frames[False])})", _pair_sets_line(g)]


def masked_lines(df: pd.DataFrame) -> list[str]:
    """The section of the masked benchmark (empty when it was not run)."""
    if df.empty:
        return []
    lines = ["## Collision filters: the mixed scene with half of the category pairs masked off", "", _masks_text(),
             "", "Each N: World, MuJoCo and pybullet with the masks and without, in the same run. Detection as "
             "in the static level; candidate pairs, filtered (dropped by the filter before the narrow phase) and "
             "narrow tests are World's `stats` at the last frame; both / World only / peer only: penetrating pairs "
             "(depth > 1e-6) against World's with the same filter (the benchmark asserts, masked, that World's "
             "pairs are exactly its unmasked pairs whose categories collide, and that MuJoCo's and pybullet's "
             "equal World's outside a band of 5e-3).", ""]
    for n, g in df.sort_values("n").groupby("n"):
        lines += [f"### N = {n:,}", "", *_masked_summary(g), "", *_masked_table(g), ""]
    return lines
