"""The event-driven gas against Smallenburg's EDMD "Cell" code (F. Smallenburg, EPJE 45, 22 (2022),
arXiv 2201.01100; public repository FSmallenburg/EDMD): collisions per second of processor time, periodic box,
same N and packing fraction η, runs alternated in one process.

The C code is not part of the project and is never downloaded here: set ``EDMD_C_SOURCE`` to a local copy of the
repository (or of its ``Cell`` folder). Its source is copied into a temporary folder, its settings (N, η, the
run length, an FCC start) are written into the copy, and it is built with ``gcc -O3 -march=native``. Without
the variable, the table says the peer was skipped.

Rates are differences of two runs (short and long) of the C program, so its start (FCC lattice, first events)
cancels: (collisions(T_long) − collisions(T_short)) / (CPU(T_long) − CPU(T_short)), CPU time of the child
process (user + system). The engine's rate is collisions / process time over rounds of ``EventDrivenGas.run``
after t = 1 of equilibration; the best of ``rounds`` for both, as timing on a shared machine only adds.
"""
from __future__ import annotations

import os
import pathlib
import re
import resource
import shutil
import subprocess
import tempfile
import time

import numpy as np

from engine.gas import EventDrivenGas, radius_for_packing
from engine.gas.initial import draw_velocities, place_spheres

ENV = "EDMD_C_SOURCE"
_FILES = ("mdCell.c", "mdCell.h", "mt19937ar.c")
_OUTPUT = re.compile(r"Simtime:\s*([0-9.eE+-]+),\s*Collisions:\s*(\d+)")


def peer_source() -> pathlib.Path | None:
    """The folder holding mdCell.c (``$EDMD_C_SOURCE`` or its ``Cell`` subfolder), None when not set."""
    root = os.environ.get(ENV)
    if not root:
        return None
    root = pathlib.Path(root).expanduser()
    for folder in (root / "Cell", root):
        if all((folder / f).is_file() for f in _FILES):
            return folder
    raise FileNotFoundError(f"{ENV}={root}: no {', '.join(_FILES)} there nor in its Cell folder")


def _set(source: str, pattern: str, value: str) -> str:
    """Replace the initial value of one global setting of the C file (exactly one definition must match)."""
    new, count = re.subn(rf"^({pattern}\s*=\s*)[^;]*;", rf"\g<1>{value};", source, flags=re.M)
    if count != 1:
        raise RuntimeError(f"the EDMD source has {count} definitions matching {pattern!r} (expected 1)")
    return new


def build_cell_code(folder: pathlib.Path, workdir: pathlib.Path, n: int, eta: float, maxtime: float) -> pathlib.Path:
    """Copy the Cell code into workdir, set N (4 k³, FCC start), η and the run length, build it; the binary."""
    workdir.mkdir(parents=True, exist_ok=True)
    for f in _FILES[1:]:
        shutil.copy(folder / f, workdir / f)
    text = (folder / _FILES[0]).read_text()
    for pattern, value in ((r"int\s+initialconfig", "1"), (r"double\s+packfrac", repr(float(eta))),
                           (r"int\s+N", str(int(n))), (r"double\s+maxtime", repr(float(maxtime))),
                           (r"int\s+makesnapshots", "0"), (r"double\s+writeinterval", "1")):
        text = _set(text, pattern, value)
    (workdir / _FILES[0]).write_text(text)
    binary = workdir / "md"
    subprocess.run(["gcc", "-O3", "-march=native", _FILES[0], "-o", binary.name, "-lm"], cwd=workdir, check=True,
                   capture_output=True)
    return binary


def run_cell_code(binary: pathlib.Path) -> tuple[float, int, float]:
    """Run the program in its folder: (its last reported time, collisions then, CPU seconds of the run)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    out = subprocess.run([str(binary)], cwd=binary.parent, check=True, capture_output=True, text=True).stdout
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    found = _OUTPUT.findall(out)
    if not found:
        raise RuntimeError(f"no 'Simtime: …, Collisions: …' line in the output of {binary}")
    t, collisions = found[-1]
    return float(t), int(collisions), cpu


def cell_code_rate(folder: pathlib.Path, n: int, eta: float, rounds: int = 3, target: int = 300_000) -> float:
    """Collisions per CPU second of the Cell code, best of ``rounds`` differences of a run to t = 1 and a run long
    enough for about ``target`` collisions more."""
    with tempfile.TemporaryDirectory(prefix="edmd-") as tmp:
        short = build_cell_code(folder, pathlib.Path(tmp) / "short", n, eta, 1.0)
        _, per_unit, _ = run_cell_code(short)
        span = max(1, int(np.ceil(target / max(per_unit, 1))))
        long = build_cell_code(folder, pathlib.Path(tmp) / "long", n, eta, 1.0 + span)
        best = 0.0
        for _ in range(rounds):
            _, c0, cpu0 = run_cell_code(short)
            _, c1, cpu1 = run_cell_code(long)
            if cpu1 > cpu0:
                best = max(best, (c1 - c0) / (cpu1 - cpu0))
        return best


def engine_rate(n: int, eta: float, rounds: int = 3, box: float = 10.0, seed: int = 0) -> float:
    """Collisions per second of process time of ``EventDrivenGas``, periodic, best of ``rounds`` rounds of about
    ``n`` collisions each, after t = 1 of equilibration."""
    r = np.full(n, radius_for_packing(n, eta, box))
    m = np.ones(n)
    rng = np.random.default_rng(seed)
    gas = EventDrivenGas(place_spheres(n, r, box, "periodic", rng), draw_velocities(m, 1.0, "periodic", rng),
                         r, m, box, periodic=True)
    gas.run(1.0)
    span = n / max(gas.collisions, 1)  # time units for about n collisions
    best = 0.0
    for _ in range(rounds):
        gas.reset_sums()
        start = time.process_time()
        gas.run(gas.time + span)
        best = max(best, gas.collisions / max(time.process_time() - start, 1e-9))
    return best


def against_c_code(n: int = 32_000, etas=(0.1, 0.3), alternations: int = 2) -> list[dict]:
    """Rows {n, eta, engine, cell_code (None: skipped), ratio} in collisions per second, the engine and the C code
    measured alternately ``alternations`` times (best of all)."""
    folder = peer_source()
    rows = []
    for eta in etas:
        engine, peer = 0.0, None
        for _ in range(alternations):
            engine = max(engine, engine_rate(n, eta))
            if folder is not None:
                peer = max(peer or 0.0, cell_code_rate(folder, n, eta))
        rows.append({"n": n, "eta": eta, "engine": engine, "cell_code": peer,
                     "ratio": engine / peer if peer else None})
    return rows


def c_code_lines(rows: list[dict]) -> list[str]:
    """The gas report's "against the C code" table (markdown lines) from ``against_c_code`` rows."""
    lines = ["## The event-driven gas against the C code", "",
             "Collisions per second of processor time, one thread, periodic box, alternated runs (best of each). "
             "Peer: F. Smallenburg's EDMD \"Cell\" code (EPJE 45, 22 (2022); cell lists, Paul's event calendar), "
             "built with `gcc -O3 -march=native`.", ""]
    if all(r["cell_code"] is None for r in rows):
        lines += [f"Peer skipped: set {ENV} to a local copy of the EDMD repository to measure it. The engine "
                  "alone:", ""]
    lines += ["| N | η | engine (collisions/s) | EDMD Cell (collisions/s) | engine / C |", "|---|---|---|---|---|"]
    for r in rows:
        peer = "skipped" if r["cell_code"] is None else f"{r['cell_code']:,.0f}"
        ratio = "—" if r["ratio"] is None else f"{r['ratio']:.2f}×"
        lines.append(f"| {r['n']:,} | {r['eta']} | {r['engine']:,.0f} | {peer} | {ratio} |")
    return lines + [""]


if __name__ == "__main__":
    print("\n".join(c_code_lines(against_c_code())))
