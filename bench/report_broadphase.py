"""The broad-phase part of the main job: reports/broadphase.csv, .md, .png and .svg from the benchmark JSON.

Reads the groups of bench/test_bench_broadphase.py ("W1 boxes", "W2 spheres", "scaling: ...", "big levels",
"threads") from pytest-benchmark's JSON output; one row per (workload, method, n, packing fraction, scene,
threads). The big-level rows get a fitted slope per (scene, method), which must stay <= 1.2 (no quadratic cliff);
the thread rows give the 2-core scaling from their wall-clock minimums.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd

COLUMNS = ["workload", "method", "n", "packing_fraction", "scene", "threads", "seed", "seconds_min",
           "seconds_median", "wall_min", "ns_per_object", "pairs", "candidates", "cycles_per_box", "commit", "machine"]
#: the largest fitted log-log slope a method may have on a big-level scene
MAX_BIG_LEVEL_SLOPE = 1.2
_WORKLOADS = {"W1": "W1", "W2": "W2", "scaling": "scaling", "big levels": "big levels", "threads": "threads"}
SEED = 4  # the seed of bench/test_bench_broadphase.py's workloads


def broadphase_rows(json_path: Path, info: dict) -> pd.DataFrame:
    data = json.loads(Path(json_path).read_text())
    rows = []
    for b in data["benchmarks"]:
        group = b.get("group") or ""
        workload = next((w for key, w in _WORKLOADS.items() if group.startswith(key)), None)
        if workload is None:
            continue
        params, extra, stats = b.get("params") or {}, b.get("extra_info") or {}, b["stats"]
        n = int(extra.get("work", params.get("n", 0)))
        eta = params.get("eta", extra.get("eta", 0.05 if workload == "scaling" else math.nan))
        rows.append({
            "workload": workload,
            "method": params.get("method") or params.get("impl") or params.get("case"),
            "n": n,
            "packing_fraction": eta,
            "scene": params.get("scene", extra.get("scene", "")),
            "threads": params.get("threads", 1),
            "seed": SEED,
            "seconds_min": stats["min"],
            "seconds_median": stats["median"],
            "wall_min": extra.get("wall_min"),
            "ns_per_object": stats["min"] * 1e9 / n,
            "pairs": extra.get("pairs"),
            "candidates": extra.get("candidates"),
            "cycles_per_box": extra.get("cycles_per_box"),
            "commit": info["commit"],
            "machine": info["machine"],
        })
    df = pd.DataFrame(rows, columns=COLUMNS)
    return df.sort_values(["workload", "scene", "packing_fraction", "method", "threads", "n"],
                          na_position="first").reset_index(drop=True)


def loglog_slope(n, seconds) -> float:
    """Least-squares slope of log(time) against log(N); NaN with fewer than two sizes."""
    n, seconds = np.asarray(n, float), np.asarray(seconds, float)
    if len(np.unique(n)) < 2:
        return math.nan
    return float(np.polyfit(np.log(n), np.log(seconds), 1)[0])


def _ratio_table(d: pd.DataFrame, reference: str) -> pd.DataFrame:
    """time(reference) / time(method) at the same (n, eta): how many times faster than the reference."""
    ref = d[d["method"] == reference].set_index(["n", "packing_fraction"])["seconds_min"]
    key = list(zip(d["n"], d["packing_fraction"]))
    return pd.Series([ref.get(k, math.nan) for k in key], index=d.index) / d["seconds_min"]


def broadphase_markdown(df: pd.DataFrame, info: dict, quick: bool) -> str:
    lines = ["# Broad phase: scaling and peers", "",
             f"{info['date']} · commit `{info['commit']}` · {info['machine']}"
             + (" · **quick mode** (N <= 1e4)" if quick else ""), "",
             "Workloads (`engine.workloads`): **W1** Terdiman's box pruning (centres integers in [−2048, 2048)³, "
             "half-extents integers in [0, 127]); **W2** equal spheres uniform in a cube at packing fraction η, "
             "all exact overlapping pairs (ours: `sphere_pairs(method)`; peers: scipy cKDTree build + query_pairs, "
             "python-fcl's and coal's DynamicAABBTree managers); **scaling** `find_pairs` on the bounding boxes "
             "of W2 spheres at η = 0.05. Times are the minimum over rounds; `× brute` and `× cKDTree` say how many "
             "times faster than those, measured in the same run (> 1 is faster). Brute force is run only up to "
             "N = 1e4 on W1 and 3e4 on the scaling workload (beyond, it would take over a minute per round); "
             "python-fcl and coal up to 1e5 (their per-object Python registration dominates beyond). `box tests` is "
             "the number of box–box overlap tests the method made (`find_pairs(..., return_tests=True)`; brute "
             "force: (n² − n)/2), the deterministic measure of how much it prunes.", ""]
    for workload, d in df.groupby("workload", sort=False):
        if workload in ("big levels", "threads"):
            continue
        d = d.copy()
        d["x_brute"] = _ratio_table(d, "brute")
        d["x_ckdtree"] = _ratio_table(d, "ckdtree")
        lines += [f"## {workload}", ""]
        header = "| method | η | N | time (ms) | ns / object | pairs | box tests | × brute | × cKDTree |"
        if workload == "W1":
            header = "| method | N | time (ms) | ns / box | cycles / box | pairs | box tests | × brute |"
        lines += [header, "|" + "---|" * (header.count("|") - 1)]
        for _, r in d.iterrows():
            pairs = "" if pd.isna(r["pairs"]) else f"{int(r['pairs']):,}"
            tests = "" if pd.isna(r["candidates"]) else f"{int(r['candidates']):,}"
            xb = "" if pd.isna(r["x_brute"]) else f"{r['x_brute']:.1f}"
            xk = "" if pd.isna(r["x_ckdtree"]) else f"{r['x_ckdtree']:.2f}"
            if workload == "W1":
                cyc = "" if pd.isna(r["cycles_per_box"]) else f"{r['cycles_per_box']:,.0f}"
                lines.append(f"| {r['method']} | {r['n']:,} | {r['seconds_min'] * 1e3:,.2f} | "
                             f"{r['ns_per_object']:,.1f} | {cyc} | {pairs} | {tests} | {xb} |")
            else:
                lines.append(f"| {r['method']} | {r['packing_fraction']:g} | {r['n']:,} | "
                             f"{r['seconds_min'] * 1e3:,.2f} | {r['ns_per_object']:,.1f} | {pairs} | {tests} | {xb} | "
                             f"{xk} |")
        lines.append("")
        if workload != "W1":
            lines += ["Fitted log-log slope of time against N (1.0 is linear, 2.0 is brute force's n²):", "",
                      "| method | η | sizes | slope |", "|---|---|---|---:|"]
            for (method, eta), g in d.groupby(["method", "packing_fraction"]):
                slope = loglog_slope(g["n"], g["seconds_min"])
                sizes = f"{g['n'].min():.0e} … {g['n'].max():.0e}"
                lines.append(f"| {method} | {eta:g} | {sizes} | {'' if math.isnan(slope) else f'{slope:.2f}'} |")
            lines.append("")
    lines += big_level_markdown(df[df["workload"] == "big levels"])
    lines += threads_markdown(df[df["workload"] == "threads"])
    lines += ["![broad-phase scaling](broadphase.png)", ""]
    return "\n".join(lines)


def big_level_markdown(d: pd.DataFrame) -> list[str]:
    """The big-level scenes: time per N and the fitted slope of each (scene, method), against the bound."""
    if d.empty:
        return []
    lines = ["## Big levels (no quadratic cliff)", "",
             "`find_pairs` (and `sphere_pairs`, method `spheres`) on `engine.workloads.big_level_boxes`: "
             "**clusters** two dense W2 clusters (η = 0.2) 1e6 apart, **huge** 8 boxes each half the scene among "
             "W2 boxes (η = 0.05), **plane** every centre on z = 0 (area fraction 0.3). A grid whose stored cells "
             f"are capped would put a whole cluster in one cell (slope 2); every slope must stay <= "
             f"{MAX_BIG_LEVEL_SLOPE}.", "",
             "| scene | method | " + " | ".join(f"N = {n:.0e} (ms)" for n in sorted(d["n"].unique()))
             + " | slope | ok |", "|---|---|" + "---:|" * (d["n"].nunique() + 2)]
    for (scene, method), g in d.groupby(["scene", "method"]):
        times = g.set_index("n")["seconds_min"]
        slope = loglog_slope(g["n"], g["seconds_min"])
        cells = " | ".join(f"{times[n] * 1e3:,.2f}" if n in times else "" for n in sorted(d["n"].unique()))
        ok = "" if math.isnan(slope) else ("yes" if slope <= MAX_BIG_LEVEL_SLOPE else "**no**")
        lines.append(f"| {scene} | {method} | {cells} | {'' if math.isnan(slope) else f'{slope:.2f}'} | {ok} |")
    return lines + [""]


def threads_markdown(d: pd.DataFrame) -> list[str]:
    """The 2-core scaling: wall-clock minimum with one and two threads (the same answer, bit for bit)."""
    if d.empty:
        return []
    lines = ["## Threads (2-core scaling, reported apart from the single-thread figures)", "",
             "`threads=` of `find_pairs` and `sphere_pairs` cuts the sweep into ranges of columns, cells or "
             "queries, one per thread (the pairs are merged into canonical form, equal bit for bit to one thread). "
             "Wall-clock minimum of the rounds; the machine has 2 cores.", "",
             "| case | N | 1 thread (ms) | 2 threads (ms) | speed-up |", "|---|---:|---:|---:|---:|"]
    for case, g in d.groupby("method"):
        wall = g.set_index("threads")["wall_min"]
        one, two = wall.get(1, math.nan), wall.get(2, math.nan)
        lines.append(f"| {case} | {int(g['n'].iloc[0]):,} | {one * 1e3:,.2f} | {two * 1e3:,.2f} | {one / two:.2f} |")
    return lines + [""]


def broadphase_plot(df: pd.DataFrame, out: Path | None = None):
    """The scaling figure (time against N per method, with O(n), O(n log n), O(n²) guides): a matplotlib Figure,
    saved as broadphase.png and .svg in ``out`` when given; None when there is nothing to plot."""
    from matplotlib import colormaps
    from matplotlib.figure import Figure

    panels = [("scaling", 0.05, "find_pairs on W2 boxes, η = 0.05"), ("W2", 0.05, "sphere pairs, η = 0.05"),
              ("W2", 0.2, "sphere pairs, η = 0.2")]
    panels = [p for p in panels if ((df["workload"] == p[0]) & np.isclose(df["packing_fraction"], p[1])).any()]
    if not panels:
        return None
    plotted = df[df["workload"].isin([p[0] for p in panels])]
    methods = sorted(plotted["method"].unique())
    colours = {m: colormaps["tab10"](i % 10) for i, m in enumerate(methods)}
    fig = Figure(figsize=(5.2 * len(panels), 4.8), dpi=110)
    axes = fig.subplots(1, len(panels), squeeze=False)
    for ax, (workload, eta, title) in zip(axes[0], panels):
        d = df[(df["workload"] == workload) & np.isclose(df["packing_fraction"], eta)]
        for method, g in d.groupby("method"):
            g = g.sort_values("n")
            ax.loglog(g["n"], g["seconds_min"], marker="o", ms=4, color=colours[method], label=method)
        n0, n1 = d["n"].min(), d["n"].max()
        t0 = d[d["n"] == n0]["seconds_min"].median()
        ns = np.geomspace(n0, n1, 20)
        for label, f, style in [("O(n)", ns / n0, ":"), ("O(n log n)", ns * np.log(ns) / (n0 * np.log(n0)), "-."),
                                ("O(n²)", (ns / n0) ** 2, "--")]:
            ax.loglog(ns, t0 * f, color="grey", ls=style, lw=0.9, label=label)
        ax.set_ylim(d["seconds_min"].min() / 3, d["seconds_min"].max() * 3)
        ax.set_title(title)
        ax.set_xlabel("N (objects)")
        ax.set_ylabel("time (s)")
        ax.grid(True, which="both", alpha=0.25)
    handles = {}
    for ax in axes[0]:
        for h, lab in zip(*ax.get_legend_handles_labels()):
            handles.setdefault(lab, h)
    labels = list(handles)
    fig.legend([handles[k] for k in labels], labels, loc="lower center", ncol=min(len(labels), 11), fontsize=8,
               frameon=False)
    fig.tight_layout(rect=(0, 0.07, 1, 1))
    if out is not None:
        fig.savefig(Path(out) / "broadphase.png")
        fig.savefig(Path(out) / "broadphase.svg")
    return fig


def broadphase_section(json_path: Path, out: Path, info: dict, quick: bool):
    df = broadphase_rows(json_path, info)
    if df.empty:
        return []
    df.to_csv(out / "broadphase.csv", index=False)
    (out / "broadphase.md").write_text(broadphase_markdown(df, info, quick))
    broadphase_plot(df, out)
    return [("[broadphase.md](broadphase.md), [broadphase.csv](broadphase.csv), [broadphase.png](broadphase.png)",
             "broad phase: time against N per method (W1 boxes, W2 spheres, scaling), ratios against brute force "
             "and cKDTree, fitted log-log slopes, O(n)/O(n log n)/O(n²) guides")]


# ----------------------------------------------------------------------------------------------------------
# The timing matrix: broad-phase method × N × packing fraction × seed, one timing task per configuration
# ----------------------------------------------------------------------------------------------------------
MATRIX_KEY = ("method", "n", "packing_fraction", "seed", "repeats", "scene")
MATRIX_METHODS = ("brute", "sap", "grid", "octree", "tree")
BRUTE_MAX_N = 1_000  # brute force beyond: (n² − n)/2 tests, over a second per call (broadphase.md has it to 3e4)


def matrix_configs(quick: bool = False) -> list[dict]:
    """Full: N = 1e3, 1e4, 1e5 (brute at 1e3 only), η = 0.05 and 0.2, seeds 1-3, 3 timed calls each, on the
    uniform W2 scene; and the big-level scenes of ``engine.workloads.big_level_boxes`` ("clusters", "huge",
    "plane", their own densities: packing fraction NaN) at the same N and seeds, every method but brute.
    Quick: N = 1e3 and 1e4, seeds 1-2, 3 timed calls. A few minutes in full mode on 2 cores."""
    sizes, seeds, repeats = ((1_000, 10_000), (1, 2), 3) if quick else ((1_000, 10_000, 100_000), (1, 2, 3), 3)
    uniform = [dict(method=m, n=n, packing_fraction=eta, seed=seed, repeats=repeats, scene="uniform")
               for m in MATRIX_METHODS for n in sizes for eta in (0.05, 0.2) for seed in seeds
               if m != "brute" or n <= BRUTE_MAX_N]
    big = [dict(method=m, n=n, packing_fraction=math.nan, seed=seed, repeats=repeats, scene=scene)
           for scene in BIG_LEVEL_MATRIX_SCENES for m in MATRIX_METHODS if m != "brute" for n in sizes
           for seed in seeds]
    return uniform + big


#: the big-level scenes of the matrix (engine.workloads.big_level_boxes)
BIG_LEVEL_MATRIX_SCENES = ("clusters", "huge", "plane")


def _matrix_boxes(cfg: dict):
    from engine.workloads import big_level_boxes, w2_spheres

    if cfg.get("scene", "uniform") == "uniform":
        centres, radius = w2_spheres(cfg["n"], cfg["packing_fraction"], seed=cfg["seed"])
        return centres - radius, centres + radius
    return big_level_boxes(cfg["scene"], cfg["n"], seed=cfg["seed"])


def time_find_pairs(cfg: dict) -> dict:
    """One timing task: ``find_pairs`` on the bounding boxes of a seeded scene (W2 spheres of
    ``engine.workloads``, or a big-level scene); a warm-up call (compilation, caches), then ``repeats`` timed
    calls (perf_counter; minimum and median)."""
    import time

    from engine.broadphase import find_pairs

    lo, hi = _matrix_boxes(cfg)
    pairs = find_pairs(lo, hi, cfg["method"])
    tests = (cfg["n"] * (cfg["n"] - 1) // 2 if cfg["method"] == "brute"
             else int(find_pairs(lo, hi, cfg["method"], return_tests=True)[1]))
    times = []
    for _ in range(cfg["repeats"]):
        t0 = time.perf_counter()
        find_pairs(lo, hi, cfg["method"])
        times.append(time.perf_counter() - t0)
    return dict(seconds_min=min(times), seconds_median=float(np.median(times)),
                ns_per_object=min(times) * 1e9 / cfg["n"], pairs=int(pairs.shape[0]), box_tests=tests)


def matrix_markdown(df: pd.DataFrame, info: dict, quick: bool, where: str, failures: list) -> str:
    lines = ["# Broad phase: timing matrix (method × N × η × seed)", "",
             f"{info['date']} · commit `{info['commit']}` · {info['machine']}" + (" · **quick mode**" if quick else ""),
             "",
             "`find_pairs(lo, hi, method)` on the bounding boxes of N equal spheres uniform in a cube at packing "
             "fraction η (W2 of `engine.workloads`), one seeded scene per seed. Each configuration is one task of a "
             f"distributed timing sweep ({where}): a warm-up call, then the minimum of the timed calls; a timing "
             "worker runs one task at a time on one thread, so no sibling task disturbs it. Below, per (method, N, "
             "η): the median over the seeds of the minimum time, the spread (max/min) between seeds, and the "
             "ratio to sweep-and-prune at the same N and η (> 1 is slower). Pairs and box tests are the same for "
             "every timed call (deterministic).", "",
             "| method | η | N | seeds | time (ms) | ns / object | seed spread | × sap | pairs | box tests |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    if "scene" not in df:
        df = df.assign(scene="uniform")
    df = df.assign(scene=df["scene"].fillna("uniform"))
    uniform = df[df["scene"] == "uniform"]
    g = uniform.groupby(["packing_fraction", "n", "method"], sort=True)
    agg = g.agg(seeds=("seed", "count"), t=("seconds_min", "median"), tmax=("seconds_min", "max"),
                tmin=("seconds_min", "min"), pairs=("pairs", "median"), tests=("box_tests", "median")).reset_index()
    sap = agg[agg["method"] == "sap"].set_index(["packing_fraction", "n"])["t"]
    for _, r in agg.iterrows():
        ref = sap.get((r["packing_fraction"], r["n"]), math.nan)
        lines.append(f"| {r['method']} | {r['packing_fraction']:g} | {int(r['n']):,} | {r['seeds']} | "
                     f"{r['t'] * 1e3:,.3f} | {r['t'] * 1e9 / r['n']:,.1f} | {r['tmax'] / r['tmin']:.2f} | "
                     f"{r['t'] / ref:.2f} | {int(r['pairs']):,} | {int(r['tests']):,} |")
    lines.append("")
    lines += matrix_slopes_markdown(df)
    if failures:
        lines += ["**Failed configurations** (after retries; rerun to retry them only): "
                  + "; ".join(f"{c['method']} N={c['n']} η={c['packing_fraction']} seed {c['seed']}: {e}"
                              for c, e in failures), ""]
    return "\n".join(lines)


def matrix_slopes_markdown(df: pd.DataFrame) -> list[str]:
    """Per (scene, method): the median over seeds of the minimum time at each N and the fitted log-log slope,
    against MAX_BIG_LEVEL_SLOPE (the uniform scene at η = 0.05 for reference)."""
    d = df[(df["scene"] != "uniform") | np.isclose(df["packing_fraction"].fillna(-1.0), 0.05)]
    d = d[d["method"] != "brute"]
    if d.empty:
        return []
    sizes = sorted(d["n"].unique())
    lines = ["Big levels: median time (ms) over the seeds and the fitted log-log slope (uniform: W2 at η = 0.05; "
             "clusters: two W2 clusters 1e6 apart; huge: 8 boxes each half the scene; plane: every centre on one "
             f"plane). Every slope must stay <= {MAX_BIG_LEVEL_SLOPE} (no quadratic cliff).", "",
             "| scene | method | " + " | ".join(f"N = {n:.0e}" for n in sizes) + " | slope | ok |",
             "|---|---|" + "---:|" * (len(sizes) + 2)]
    for (scene, method), g in d.groupby(["scene", "method"]):
        med = g.groupby("n")["seconds_min"].median()
        slope = loglog_slope(med.index, med.values)
        ok = "" if math.isnan(slope) else ("yes" if slope <= MAX_BIG_LEVEL_SLOPE else "**no**")
        cells = " | ".join(f"{med[n] * 1e3:,.3f}" if n in med else "" for n in sizes)
        lines.append(f"| {scene} | {method} | {cells} | {'' if math.isnan(slope) else f'{slope:.2f}'} | {ok} |")
    return lines + [""]


def broadphase_matrix_section(out: Path, info: dict, quick: bool, client=None, where: str = "serial"):
    """The timing matrix as a distributed timing sweep: broadphase_matrix.csv and .md in ``out``."""
    from bench.sweep import RowStore, Sweep, run_sweep

    out = Path(out)
    sweep = Sweep("broadphase_matrix", time_find_pairs, matrix_configs(quick), MATRIX_KEY, kind="timing",
                  version=info["commit"])
    store = RowStore(out / ".sweeps" / "broadphase_matrix.jsonl")
    result = run_sweep(sweep, store, client, failures_path=out / "broadphase_matrix.failures.csv")
    if not result.rows:
        return []
    df = pd.DataFrame(result.rows)
    df["commit"], df["machine"] = info["commit"], info["machine"]
    df.to_csv(out / "broadphase_matrix.csv", index=False)
    (out / "broadphase_matrix.md").write_text(matrix_markdown(df, info, quick, where, result.failures))
    if result.complete:
        store.clear()
    return [("[broadphase_matrix.md](broadphase_matrix.md), [broadphase_matrix.csv](broadphase_matrix.csv)",
             "broad phase timing matrix: method × N × packing fraction × seed, one timing task per configuration "
             "on dedicated one-thread workers (distributed sweep); median over seeds, seed spread, ratio to SAP")]
