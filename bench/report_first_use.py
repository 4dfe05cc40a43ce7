"""The first-use section of the reports: README's Python blocks cold (an empty kernel cache) and warm, and
``colldet warmup`` on an empty cache with one and with two processes — before (a baseline commit) and after (this
checkout).

    python -m bench.report_first_use [--before REF] [--blocks 1 3] [--python PATH] [--out DIR]

Each version runs as a newcomer gets it (bench/first_run.py): a wheel installed in a fresh virtual environment, the
blocks run one by one from an empty folder; ``--python PATH`` runs the sources with that interpreter instead (its
packages, the version's tree first on PYTHONPATH), for a quick local check. Every run is a fresh process: its wall
seconds and its CPU seconds (user + system, the processes it started included) are recorded. The baseline's tree
is ``git archive REF`` of this repository. Writes first_use.md and first_use.csv.
"""
from __future__ import annotations

import argparse
import os
import resource
import shutil
import subprocess
import sys
import tarfile
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from bench.first_run import ROOT, build_wheel, clean_environment, fresh_venv, python_blocks

#: the commit the first-use work started from (main before the compile-time changes): the "before" columns
BASELINE = "9e6ea36"
#: its rows, measured once by ``python -m bench.report_first_use --before 9e6ea36 --save-before`` (a fresh venv and
#: wheel of that commit): the main job reads them instead of building and compiling the old code again
BASELINE_CSV = ROOT / "bench" / "first_use_baseline.csv"

#: the ``colldet warmup --jobs`` values timed (a version whose warmup has no --jobs runs its one way, as jobs 1)
WARMUP_JOBS = (1, 2)


@dataclass
class Timed:
    wall: float
    cpu: float
    returncode: int
    stderr: str


def timed(cmd: list[str], cwd: Path, env: dict) -> Timed:
    """Run ``cmd`` to completion: wall seconds, and CPU seconds of it and every process it waited for."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return Timed(wall, cpu, done.returncode, done.stderr)


def baseline_tree(ref: str, folder: Path) -> Path:
    """The files of commit ``ref`` of this repository, extracted into ``folder``."""
    folder.mkdir(parents=True)
    archive = folder.with_suffix(".tar")
    subprocess.run(["git", "archive", "--format=tar", "-o", str(archive), ref], cwd=ROOT, check=True)
    with tarfile.open(archive) as tar:
        tar.extractall(folder, filter="data")
    archive.unlink()
    return folder


def interpreter(tree: Path, folder: Path, python: Path | None) -> tuple[Path, dict]:
    """(python, environment) that runs ``tree``'s engine: a fresh venv with its wheel, or ``python`` with the tree
    first on PYTHONPATH."""
    env = {**clean_environment(), "MPLBACKEND": "Agg"}
    if python is not None:
        return python, {**env, "PYTHONPATH": str(tree)}
    return fresh_venv(folder / "venv", build_wheel(tree, folder / "wheel")), env


def measure(label: str, commit: str, tree: Path, folder: Path, python: Path | None, blocks: list[int] | None):
    """The rows of one version: each block cold then warm, then the warm-ups on empty caches."""
    py, env = interpreter(tree, folder, python)
    workdir = folder / "empty"
    workdir.mkdir(parents=True)
    shutil.copytree(tree / "examples", workdir / "examples")
    codes = python_blocks(tree / "README.md")
    chosen = range(len(codes)) if blocks is None else [b - 1 for b in blocks if 1 <= b <= len(codes)]
    rows = []
    cache = {**env, "NUMBA_CACHE_DIR": str(folder / "cache")}
    for b in chosen:
        script = workdir / f"block_{b}.py"
        script.write_text(codes[b])
        cold, warm = (timed([str(py), script.name], workdir, cache) for _ in range(2))
        first = next((line for line in codes[b].splitlines() if line and not line.startswith(("import", "from"))), "")
        rows.append({"version": label, "commit": commit, "item": f"block {b + 1}", "detail": first[:60],
                     "cold_wall_s": cold.wall, "cold_cpu_s": cold.cpu, "warm_wall_s": warm.wall,
                     "warm_cpu_s": warm.cpu, "ok": cold.returncode == 0 and warm.returncode == 0})
    has_jobs = "--jobs" in (tree / "engine" / "cli.py").read_text()
    for jobs in WARMUP_JOBS if has_jobs else WARMUP_JOBS[:1]:
        empty = {**env, "NUMBA_CACHE_DIR": str(folder / f"warmup_cache_{jobs}"), "COLLDET_COMPILE_NOTICE": "0"}
        args = ["--jobs", str(jobs)] if has_jobs else []
        run = timed([str(py), "-m", "engine", "warmup", "--no-progress", *args], workdir, empty)
        rows.append({"version": label, "commit": commit, "item": f"colldet warmup --jobs {jobs}",
                     "detail": "" if has_jobs else "(no --jobs: one process)", "cold_wall_s": run.wall,
                     "cold_cpu_s": run.cpu, "warm_wall_s": None, "warm_cpu_s": None, "ok": run.returncode == 0})
    return rows


def _cell(value) -> str:
    return "—" if value is None or pd.isna(value) else f"{value:.1f}"


def first_use_markdown(df: pd.DataFrame, info: dict, command: str) -> str:
    """One row per block and per warm-up: before and after, cold and warm, wall and CPU seconds."""
    # a block is matched by its first line (README gains and reorders blocks between versions), a warm-up by name
    df = df.assign(key=[f"{d}".strip() if i.startswith("block") else i for i, d in zip(df["item"], df["detail"])])
    before, after = (df[df.version == v].set_index("key") for v in ("before", "after"))
    items = list(dict.fromkeys([*after.index, *before.index]))
    lines = [
        "# First use: README's blocks and `colldet warmup` on an empty kernel cache", "",
        f"{info['date']}, commit {info['commit']}, {info['machine']}. Produced by `{command}`.", "",
        f"Before: commit {df[df.version == 'before'].commit.iloc[0] if len(before) else '—'} (measured once, the "
        "same way, on this machine kind: bench/first_use_baseline.csv); after: this "
        "checkout. The blocks run in README's order, as a newcomer meets them, each as a fresh process from an "
        "empty folder: the kernel cache is empty before block 1 and keeps what each block compiled (cold: a "
        "block's first run, which compiles what the blocks before it did not; warm: its second run); each "
        "warm-up on its own empty cache. Wall seconds, and CPU seconds (user + system, with "
        "the processes it started: compare these on a shared machine). A warm-up whose wall time is well under "
        "its CPU time compiled in parallel.", "",
        "| run | before cold wall (CPU) s | before warm s | after cold wall (CPU) s | after warm s | ran |",
        "|---|---:|---:|---:|---:|---|",
    ]
    for item in items:
        cells = []
        for side in (before, after):
            row = side.loc[item] if item in side.index else None
            cells.append("—" if row is None else f"{_cell(row.cold_wall_s)} ({_cell(row.cold_cpu_s)})")
            cells.append("—" if row is None else _cell(row.warm_wall_s))
        ok = all(side.loc[item].ok for side in (before, after) if item in side.index)
        row = after.loc[item] if item in after.index else before.loc[item]
        label, detail = row["item"], row.detail
        name = f"{label} `{detail}`" if detail and label.startswith("block") else f"{label} {detail}".strip()
        lines.append(f"| {name} | {' | '.join(cells)} | {'yes' if ok else 'no'} |")
    return "\n".join(lines) + "\n"


def first_use_section(out: Path, info: dict, quick: bool = False, before: str | None = "stored",
                      python: Path | None = None, blocks: list[int] | None = None, command: str | None = None):
    """first_use.md and first_use.csv (before: "stored" for the rows of BASELINE_CSV, a commit of this repository
    to measure it again, None for none; after: this checkout); ``quick`` times README's first two blocks only.
    Returns the index's rows."""
    command = command or "python -m bench.report" + (" --quick" if quick else "")
    blocks = [1, 2] if quick and blocks is None else blocks
    rows = []
    with tempfile.TemporaryDirectory(prefix="first_use_") as tmp:
        folder = Path(tmp)
        if before == "stored":
            stored = pd.read_csv(BASELINE_CSV)
            rows += stored.to_dict("records") if blocks is None else \
                stored[stored.item.isin([f"block {b}" for b in blocks])].to_dict("records")
        elif before is not None:
            tree = baseline_tree(before, folder / "before_src")
            rows += measure("before", before, tree, folder / "before", python, blocks)
        rows += measure("after", info["commit"], ROOT, folder / "after", python, blocks)
    df = pd.DataFrame(rows)
    df.to_csv(out / "first_use.csv", index=False)
    (out / "first_use.md").write_text(first_use_markdown(df, info, command))
    return [("[first_use.md](first_use.md)", "README's blocks cold and warm, `colldet warmup` with 1 and 2 "
             "processes: before and after the compile-time work")]


def main(argv=None) -> int:
    """``python -m bench.report_first_use``: the first-use section alone."""
    import shlex

    from bench.report import stamp

    parser = argparse.ArgumentParser(prog="python -m bench.report_first_use", description=__doc__.split("\n\n")[0])
    parser.add_argument("--before", default="stored",
                        help=f"'stored' (default: the rows of {BASELINE_CSV.name}, measured on {BASELINE}), a commit "
                             "to measure again, or 'none'")
    parser.add_argument("--blocks", type=int, nargs="*", default=None,
                        help="README's Python blocks to run, counted from 1 (default: all)")
    parser.add_argument("--python", type=Path, default=None,
                        help="run the sources with this interpreter instead of a fresh venv with the wheel")
    parser.add_argument("--quick", action="store_true", help="the first two blocks only (written to reports-quick/)")
    parser.add_argument("--out", default=None, help="output folder (default reports/, or reports-quick/)")
    parser.add_argument("--save-before", action="store_true",
                        help=f"measure commit --before and store its rows in bench/{BASELINE_CSV.name}, nothing else")
    args = parser.parse_args(argv)
    if args.save_before:
        with tempfile.TemporaryDirectory(prefix="first_use_before_") as tmp:
            tree = baseline_tree(args.before, Path(tmp) / "before_src")
            rows = measure("before", args.before, tree, Path(tmp) / "before", args.python, args.blocks)
        pd.DataFrame(rows).to_csv(BASELINE_CSV, index=False)
        return 0
    out = Path(args.out or ("reports-quick" if args.quick else "reports")).resolve()
    out.mkdir(parents=True, exist_ok=True)
    command = shlex.join(["python", "-m", "bench.report_first_use", *(argv if argv is not None else sys.argv[1:])])
    before = None if args.before == "none" else args.before
    first_use_section(out, stamp(), args.quick, before, args.python, args.blocks, command)
    print(f"[report_first_use] wrote {out / 'first_use.md'}", flush=True)
    return 0


if __name__ == "__main__":
    os.environ.setdefault("MPLBACKEND", "Agg")
    sys.exit(main())
