"""The narrow-phase part of the main job: reports/narrowphase.csv and .md from the benchmark JSON.

Reads the benchmarks of bench/test_bench_narrowphase.py, which store ``test`` (gjk box-box, gjk hull20,
sat obb, contact box-box, sat convex hull20, curve circle), ``peer`` (engine, engine-kernel, engine jit-f,
engine per-pair, python-fcl, coal) and ``pairs`` in ``extra_info``.
"""
from __future__ import annotations

import json
from pathlib import Path

import pandas as pd

#: targets of issue 3, ns per pair in batches (None: no absolute target)
TARGET_NS = {"gjk box-box": 1000.0, "sat obb": 200.0}
#: the per-pair speed-up over python-fcl that issue 3 asks for
TARGET_FCL_RATIO = 10.0


def narrowphase_rows(json_path: Path, info: dict) -> pd.DataFrame:
    rows = []
    for b in json.loads(Path(json_path).read_text())["benchmarks"]:
        extra = b.get("extra_info") or {}
        if "test" not in extra or "peer" not in extra or not extra.get("pairs"):
            continue
        pairs = int(extra["pairs"])
        rows.append({"test": extra["test"], "implementation": extra["peer"], "pairs": pairs,
                     "seconds_min": b["stats"]["min"], "seconds_median": b["stats"]["median"],
                     "ns_per_pair": b["stats"]["min"] * 1e9 / pairs, "commit": info["commit"],
                     "machine": info["machine"]})
    return pd.DataFrame(rows)


def _ratio_text(x: float) -> str:
    return "" if x != x else f"{x:.1f}"  # NaN (no such peer in this test) -> blank


def narrowphase_markdown(df: pd.DataFrame, info: dict) -> str:
    lines = ["# Narrow phase: batched tests against python-fcl and coal", "",
             f"{info['date']} · commit `{info['commit']}` · {info['machine']}", "",
             "The engine runs each test over a batch of pairs in one compiled call (`gjk_distance_batch`, "
             "`overlap_obb_obb_batch`); python-fcl and coal are called per pair from Python, as a user of their "
             "bindings would. `engine-kernel` is the compiled loop alone (no validation, no copies); "
             "`engine N threads` is the same batch split among N threads (`threads=N`, wall time; the targets "
             "are judged on one thread). "
             "Times are minimums over rounds; `× fcl` and `× coal` say how many times faster per pair than "
             "those, measured in the same run; `× per-pair` how many times faster than `engine per-pair`, the "
             "engine's single-pair function called from Python for every pair (contact features, convex SAT, "
             "curved ground: `contact_feature_pairs`, `overlap_convex_sat_pairs`, `overlap_circle_curve` on all "
             "circles at once, `engine jit-f` with a numba-jitted ground function).", "",
             "| test | implementation | pairs | ns / pair | × fcl | × coal | × per-pair | target |",
             "|---|---|---:|---:|---:|---:|---:|---|"]
    for test, g in df.groupby("test", sort=False):
        ref = g.set_index("implementation")["ns_per_pair"]
        for _, r in g.iterrows():
            x_fcl = ref.get("python-fcl", float("nan")) / r["ns_per_pair"]
            x_coal = ref.get("coal", float("nan")) / r["ns_per_pair"]
            x_loop = ref.get("engine per-pair", float("nan")) / r["ns_per_pair"]
            target = ""
            if r["implementation"] == "engine":
                parts = []
                if test in TARGET_NS:
                    ok = r["ns_per_pair"] <= TARGET_NS[test]
                    parts.append(f"≤ {TARGET_NS[test]:g} ns: {'met' if ok else 'missed'}")
                if "python-fcl" in ref:
                    ok = x_fcl >= TARGET_FCL_RATIO
                    parts.append(f"≥ {TARGET_FCL_RATIO:g}× fcl: {'met' if ok else 'missed'}")
                target = "; ".join(parts)
            lines.append(f"| {test} | {r['implementation']} | {r['pairs']:,} | {r['ns_per_pair']:,.0f} | "
                         f"{_ratio_text(x_fcl)} | {_ratio_text(x_coal)} | {_ratio_text(x_loop)} | {target} |")
    lines.append("")
    return "\n".join(lines)


def narrowphase_section(json_path: Path, out: Path, info: dict, quick: bool):
    df = narrowphase_rows(json_path, info)
    if df.empty:
        return []
    df.to_csv(out / "narrowphase.csv", index=False)
    (out / "narrowphase.md").write_text(narrowphase_markdown(df, info))
    return [("[narrowphase.md](narrowphase.md), [narrowphase.csv](narrowphase.csv)",
             "narrow phase: ns per pair of batched GJK (boxes, 20-vertex hulls) and OBB SAT against python-fcl "
             "and coal per pair, with the issue's targets; batched contact features, convex SAT and curved ground "
             "against the engine's per-pair loop")]
