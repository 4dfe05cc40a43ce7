"""The main job: run the benchmark suites and the validation runs, regenerate reports/.

    python -m bench.report [--quick] [--out DIR] [--scheduler tcp://HOST:8786]      (or: tox -e report)

A full run rewrites the committed ``reports/``; a ``--quick`` run (small sizes, a few minutes) writes to
``reports-quick/`` unless ``--out`` says otherwise, so that it never replaces the full reports.

Writes, in the output folder:
- benchmarks.json (pytest-benchmark's raw output), benchmarks.csv (one row per benchmark, long format) and
  benchmarks.md (one table per group, with each entry's ratio to the fastest of its group);
- one validation section per area of the chapter (dynamics.md/.csv/.png, ...), each checking the engine
  against its oracle on fixed cases;
- eos.csv/.md/.png, the hard-sphere equation of state, and broadphase_matrix.csv/.md, a timing matrix of the
  broad phases, both computed by distributed sweeps (bench/sweep.py): on the Dask scheduler given by
  ``--scheduler`` or $COLLIDE_SCHEDULER, else on an embedded LocalCluster of this machine;
- first_use.md/.csv: README's blocks cold and warm and ``colldet warmup`` with 1 and 2 processes, before (a
  baseline commit) and after (bench/report_first_use.py);
- README.md, the index that says how to read them.
"""
from __future__ import annotations

import argparse
import contextlib
import datetime as _dt
import inspect
import json
import os
import platform
import subprocess
import sys
from pathlib import Path

import pandas as pd

from bench.report_broadphase import broadphase_section
from bench.report_first_use import first_use_section
from bench.report_level import level_section
from bench.report_narrowphase import narrowphase_section
from bench.report_queries import queries_section
from bench.report_world import world_section

ROOT = Path(__file__).resolve().parents[1]


def machine_description() -> str:
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{cpu}, {os.cpu_count()} cores, Python {platform.python_version()}, {platform.system()}"


def current_commit() -> str:
    try:
        out = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True,
                             check=True)
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=ROOT,
                               capture_output=True, text=True).stdout.strip()
        return out.stdout.strip() + ("+dirty" if dirty else "")
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def stamp() -> dict:
    return {
        "date": _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%d %H:%M UTC"),
        "commit": current_commit(),
        "machine": machine_description(),
    }


def run_benchmarks(out: Path, quick: bool) -> Path:
    """pytest-benchmark over bench/, raw JSON into out/benchmarks.json (pytest prints its progress)."""
    json_path = out / "benchmarks.json"
    cmd = [sys.executable, "-m", "pytest", str(ROOT / "bench"), f"--ignore={ROOT / 'bench' / 'gate'}",
           "--benchmark-only", "-p", "no:cacheprovider",
           f"--benchmark-json={json_path}", "--benchmark-columns=min,median,rounds", "-q"]
    if quick:
        cmd.append("--quick")
    print("running:", " ".join(cmd), flush=True)
    subprocess.run(cmd, cwd=ROOT, check=True)
    return json_path


def section_main(name: str, section, argv=None) -> int:
    """``python -m bench.report_<name>``: run bench/test_bench_<name>.py and write that section of the report alone
    (``section(json_path, out, info, quick, command)``, as the main job calls it)."""
    import shlex
    import tempfile

    prog = f"python -m bench.report_{name}"
    parser = argparse.ArgumentParser(prog=prog, description=f"the {name} section of the reports, alone")
    parser.add_argument("--quick", action="store_true", help="small sizes (written to reports-quick/)")
    parser.add_argument("--out", default=None, help="output folder (default reports/, or reports-quick/)")
    parser.add_argument("-k", dest="select", default=None, help="pytest -k expression: which benchmarks to run")
    args = parser.parse_args(argv)
    out = Path(args.out or ("reports-quick" if args.quick else "reports")).resolve()
    out.mkdir(parents=True, exist_ok=True)
    command = shlex.join([*prog.split(), *(argv if argv is not None else sys.argv[1:])])
    with tempfile.TemporaryDirectory() as tmp:
        json_path = Path(tmp) / f"{name}.json"
        cmd = [sys.executable, "-m", "pytest", str(ROOT / "bench" / f"test_bench_{name}.py"), "--benchmark-only",
               "-m", "not large", "-p", "no:cacheprovider", f"--benchmark-json={json_path}",
               "--benchmark-columns=min,median,rounds", "-q", *(["--quick"] if args.quick else []),
               *(["-k", args.select] if args.select else [])]
        subprocess.run(cmd, cwd=ROOT, check=True)
        section(json_path, out, stamp(), args.quick, command)
    print(f"[report_{name}] wrote {out / (name + '.md')}", flush=True)
    return 0


def benchmark_table(json_path: Path, info: dict) -> pd.DataFrame:
    data = json.loads(json_path.read_text())
    untitled = [b.get("fullname", b["name"]) for b in data["benchmarks"] if not b.get("group")]
    if untitled:  # one group, one table of ratios: a benchmark outside every group would be compared with anything
        raise ValueError(f"benchmarks without a pytest-benchmark group: {untitled}")
    rows = []
    for b in data["benchmarks"]:
        extra = b.get("extra_info", {})
        stats = b["stats"]
        work = extra.get("work")
        rows.append({
            "group": b["group"],
            "name": b["name"],
            "params": json.dumps(b.get("params") or {}, sort_keys=True),
            "seconds_min": stats["min"],
            "seconds_median": stats["median"],
            "rounds": stats["rounds"],
            "work": work,
            "unit": extra.get("unit", ""),
            "ns_per_unit": (stats["min"] * 1e9 / work) if work else None,
            "units_per_second": (work / stats["min"]) if work else None,
            **{k: v for k, v in extra.items() if k not in ("work", "unit")},
            **info,
        })
    return pd.DataFrame(rows)


def benchmark_markdown(df: pd.DataFrame, info: dict) -> str:
    lines = ["# Benchmarks", "",
             f"{info['date']} · commit `{info['commit']}` · {info['machine']}", "",
             "Times are the minimum over pytest-benchmark's rounds (the least disturbed run on a shared machine); "
             "`ratio` is each entry's time per unit of work divided by the fastest entry of its group, measured "
             "in the same run.", ""]
    for group, g in df.groupby("group", sort=True):
        g = g.copy()
        per = g["ns_per_unit"].where(g["ns_per_unit"].notna(), g["seconds_min"] * 1e9)
        g["ratio"] = per / per.min()
        lines += [f"## {group}", "", "| benchmark | min (ms) | median (ms) | work | ns per unit | ratio |",
                  "|---|---:|---:|---:|---:|---:|"]
        for _, r in g.sort_values("ratio").iterrows():
            work = "" if pd.isna(r["work"]) else f"{int(r['work']):,} {r['unit']}"
            nsu = "" if pd.isna(r["ns_per_unit"]) else f"{r['ns_per_unit']:,.1f}"
            lines.append(f"| {r['name']} | {r['seconds_min'] * 1e3:,.3f} | {r['seconds_median'] * 1e3:,.3f} "
                         f"| {work} | {nsu} | {r['ratio']:.2f} |")
        lines.append("")
    return "\n".join(lines)


def write_index(out: Path, sections: list[tuple[str, str]], info: dict) -> None:
    lines = ["# Reports", "",
             f"Regenerated by the main job (`tox -e report`, or `python -m bench.report`) on {info['date']}, commit "
             f"`{info['commit']}`, {info['machine']}.", "",
             "| report | what it shows |", "|---|---|",
             "| [benchmarks.md](benchmarks.md), [benchmarks.csv](benchmarks.csv) | every pytest-benchmark "
             "suite of bench/: time per run and per unit of work, ratio to the fastest of its group |"]
    lines += [f"| {link} | {what} |" for link, what in sections]
    lines += ["", "## How to read them", "",
              "- A validation report compares the engine with an independent oracle on fixed cases and prints "
              "the largest error next to the tolerance the property suite enforces; `ok` means within it.",
              "- Benchmark ratios are measured in one run, on one machine: compare ratios, not absolute times, "
              "across machines.",
              "- gas, eos and broadphase_matrix are distributed sweeps (bench/sweep.py, one task per "
              "configuration, on `--scheduler` / $COLLIDE_SCHEDULER or an embedded LocalCluster): "
              "an interrupted report keeps their completed rows in `.sweeps/` and resumes from them on the next "
              "run; a configuration that still fails after two retries is listed in `<name>.failures.csv`.", ""]
    (out / "README.md").write_text("\n".join(lines))


@contextlib.contextmanager
def _sweep_client(scheduler: str | None, kind: str):
    """(client, where) for the report's sweeps; (None, "serial") when dask.distributed is not installed."""
    try:
        import distributed  # noqa: F401
    except ImportError:
        print("[report] dask.distributed is not installed (pip install 'engine[sweep]'): sweeps run serially",
              flush=True)
        yield None, "serial, in the report's process"
        return
    from bench.sweep import embedded_workers, scheduler_address, sweep_client

    address = scheduler_address(scheduler)
    with sweep_client(address, kind) as client:
        n = len(client.scheduler_info().get("workers", {}))
        where = (f"Dask scheduler {address}, {n} workers" if address else
                 f"embedded Dask LocalCluster, {embedded_workers(kind)} {kind} worker process(es) of one thread")
        yield client, where


def main(quick: bool = False, out: Path | str = "reports", scheduler: str | None = None) -> int:
    """scheduler: address of a Dask scheduler for the sweeps (else $COLLIDE_SCHEDULER, else a LocalCluster)."""
    from bench import validation
    from bench.eos import eos_section
    from bench.report_broadphase import broadphase_matrix_section

    out = Path(out)
    if not out.is_absolute():
        out = Path.cwd() / out
    out.mkdir(parents=True, exist_ok=True)
    info = stamp()
    sections = []
    with _sweep_client(scheduler, "physics") as (client, where):
        for name, section in validation.SECTIONS:
            print(f"[report] validation: {name}", flush=True)
            # sections whose runs are sweep points (e.g. gas) take the client; the others run here
            takes_client = "client" in inspect.signature(section).parameters
            sections += section(out, info, quick=quick, **({"client": client} if takes_client else {}))
        print("[report] equation of state (physics sweep)", flush=True)
        sections += eos_section(out, info, quick, client, where)
    print("[report] benchmarks", flush=True)
    json_path = run_benchmarks(out, quick)
    df = benchmark_table(json_path, info)
    df.to_csv(out / "benchmarks.csv", index=False)
    (out / "benchmarks.md").write_text(benchmark_markdown(df, info))
    sections += broadphase_section(json_path, out, info, quick)
    print("[report] broad-phase timing matrix (timing sweep)", flush=True)
    with _sweep_client(scheduler, "timing") as (client, where):
        sections += broadphase_matrix_section(out, info, quick, client, where)
    sections += narrowphase_section(json_path, out, info, quick)
    sections += world_section(json_path, out, info, quick)
    sections += queries_section(json_path, out, info, quick)
    sections += level_section(json_path, out, info, quick)
    print("[report] first use (README's blocks cold and warm, the warm-up)", flush=True)
    sections += first_use_section(out, info, quick)
    write_index(out, sections, info)
    print(f"[report] wrote {out}", flush=True)
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="python -m bench.report",
        description="The main job: validation sections, the pytest-benchmark suites, and two distributed sweeps on "
                    "Dask (the hard-sphere equation of state, eos.md; a broad-phase timing matrix, "
                    "broadphase_matrix.md). Sweeps run on the Dask scheduler given by --scheduler or the environment "
                    "variable COLLIDE_SCHEDULER, else on an embedded LocalCluster of this machine. Rows are stored as "
                    "they complete: rerunning an interrupted report resumes its sweeps (see bench/sweep.py).",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="small sizes, a few minutes (written to reports-quick/)")
    parser.add_argument("--out", default=None, help="output folder (default: reports/, or reports-quick/ with --quick)")
    parser.add_argument("--scheduler", metavar="ADDRESS", default=None,
                        help="address of an existing Dask scheduler for the sweeps, e.g. tcp://HOST:8786 (overrides "
                             "$COLLIDE_SCHEDULER; without either, an embedded LocalCluster). Its workers need this "
                             "checkout importable (pip install -e '.[sweep]', repository root on PYTHONPATH); timing "
                             "workers: dask worker tcp://HOST:8786 --nthreads 1 --resources timing=1")
    return parser


def cli(argv=None) -> int:
    args = build_parser().parse_args(argv)
    out = args.out or ("reports-quick" if args.quick else "reports")
    return main(quick=args.quick, out=out, scheduler=args.scheduler)


if __name__ == "__main__":
    sys.exit(cli())
