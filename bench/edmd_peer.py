"""The event-driven gas against Smallenburg's EDMD codes (F. Smallenburg, EPJE 45, 22 (2022), arXiv 2201.01100;
public repository FSmallenburg/EDMD): collisions per second of processor time, periodic box, same N and packing
fraction η, runs alternated in one process. Three codes (``CODES``), each its authors' variant:

- "Cell": collisions searched in a cell list (cells >= one diameter), every pair event scheduled;
- "Multi": neighbour lists of radius 1.5 σ (skin 0.5 σ), rebuilt when a sphere has moved 0.25 σ, every event
  scheduled;
- "Single": the same neighbour lists, one event per sphere (the README calls it typically the most efficient).

The C code is not part of the project and is never downloaded here: set ``EDMD_C_SOURCE`` to a local copy of the
repository (or of one code's folder). The source is copied into a temporary folder, the run's settings (N, η,
the run length, an FCC start, no snapshots, the thermostat off: microcanonical, as in the paper's benchmarks and
as the engine runs) are written into the copy, and it is built with ``gcc -O3 -march=native``; every other
parameter (neighbour shell 1.5 σ, cell sizes, event-calendar sizes) keeps the authors' default. Without the
variable, the table says the peer was skipped.

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
#: the EDMD codes measured, in the order of the table
CODES = ("Cell", "Multi", "Single")
_OUTPUT = re.compile(r"Simtime:\s*([0-9.eE+-]+),\s*Collisions:\s*(\d+)")


def _files(code: str) -> tuple[str, str, str]:
    return f"md{code}.c", f"md{code}.h", "mt19937ar.c"


def peer_source(code: str = "Cell") -> pathlib.Path | None:
    """The folder holding md<code>.c (``$EDMD_C_SOURCE`` or its ``<code>`` subfolder), None when not set."""
    if code not in CODES:
        raise ValueError(f"code must be one of {CODES}, got {code!r}")
    value = os.environ.get(ENV)
    if not value:
        return None
    root = pathlib.Path(value).expanduser()
    files = _files(code)
    for folder in (root / code, root):
        if all((folder / f).is_file() for f in files):
            return folder
    raise FileNotFoundError(f"{ENV}={root}: no {', '.join(files)} there nor in its {code} folder")


def _set(source: str, pattern: str, value: str) -> str:
    """Replace the initial value of one global setting of the C file (exactly one definition must match)."""
    new, count = re.subn(rf"^({pattern}\s*=\s*)[^;]*;", rf"\g<1>{value};", source, flags=re.M)
    if count != 1:
        raise RuntimeError(f"the EDMD source has {count} definitions matching {pattern!r} (expected 1)")
    return new


def build_c_code(folder: pathlib.Path, workdir: pathlib.Path, n: int, eta: float, maxtime: float,
                 code: str = "Cell") -> pathlib.Path:
    """Copy one EDMD code into workdir, set N (4 k³, FCC start), η, the run length and the thermostat off, build
    it; the binary."""
    workdir.mkdir(parents=True, exist_ok=True)
    files = _files(code)
    for f in files[1:]:
        shutil.copy(folder / f, workdir / f)
    text = (folder / files[0]).read_text()
    for pattern, value in ((r"int\s+initialconfig", "1"), (r"double\s+packfrac", repr(float(eta))),
                           (r"int\s+N", str(int(n))), (r"double\s+maxtime", repr(float(maxtime))),
                           (r"int\s+makesnapshots", "0"), (r"double\s+writeinterval", "1"),
                           (r"const\s+int\s+usethermostat", "0")):
        text = _set(text, pattern, value)
    (workdir / files[0]).write_text(text)
    binary = workdir / "md"
    subprocess.run(["gcc", "-O3", "-march=native", files[0], "-o", binary.name, "-lm"], cwd=workdir, check=True,
                   capture_output=True)
    return binary


def run_c_code(binary: pathlib.Path) -> tuple[float, int, float]:
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


def c_code_rate(folder: pathlib.Path, n: int, eta: float, rounds: int = 3, target: int = 300_000,
                code: str = "Cell") -> float:
    """Collisions per CPU second of one EDMD code, best of ``rounds`` differences of a run to t = 1 and a run long
    enough for about ``target`` collisions more."""
    with tempfile.TemporaryDirectory(prefix="edmd-") as tmp:
        short = build_c_code(folder, pathlib.Path(tmp) / "short", n, eta, 1.0, code)
        _, per_unit, _ = run_c_code(short)
        span = max(1, int(np.ceil(target / max(per_unit, 1))))
        long = build_c_code(folder, pathlib.Path(tmp) / "long", n, eta, 1.0 + span, code)
        best = 0.0
        for _ in range(rounds):
            _, c0, cpu0 = run_c_code(short)
            _, c1, cpu1 = run_c_code(long)
            if cpu1 > cpu0:
                best = max(best, (c1 - c0) / (cpu1 - cpu0))
        return best


def engine_rate(n: int, eta: float, rounds: int = 3, box: float = 10.0, seed: int = 0, search: str = "cells") -> float:
    """Collisions per second of process time of ``EventDrivenGas`` (its ``search``), periodic, best of ``rounds``
    rounds of about ``n`` collisions each, after t = 1 of equilibration."""
    r = np.full(n, radius_for_packing(n, eta, box, "periodic"))
    m = np.ones(n)
    rng = np.random.default_rng(seed)
    gas = EventDrivenGas(place_spheres(n, r, box, "periodic", rng), draw_velocities(m, 1.0, "periodic", rng),
                         r, m, box, periodic=True, search=search)
    gas.run(1.0)
    span = n / max(gas.collisions, 1)  # time units for about n collisions
    best = 0.0
    for _ in range(rounds):
        gas.reset_sums()
        start = time.process_time()
        gas.run(gas.time + span)
        best = max(best, gas.collisions / max(time.process_time() - start, 1e-9))
    return best


def against_c_code(n: int = 32_000, etas=(0.1, 0.3), alternations: int = 2, codes=CODES) -> list[dict]:
    """Rows {n, eta, engine, peers: {code: collisions/s or None (skipped)}, fastest, ratio} in collisions per
    second, the engine and each C code measured alternately ``alternations`` times (best of each); ``ratio`` is
    the engine over the fastest C code (None when every peer was skipped)."""
    folders = {code: peer_source(code) for code in codes}
    rows = []
    for eta in etas:
        engine = 0.0
        peers: dict[str, float | None] = {code: None for code in codes}
        for _ in range(alternations):
            for code in codes:
                engine = max(engine, engine_rate(n, eta))
                folder = folders[code]
                if folder is not None:
                    peers[code] = max(peers[code] or 0.0, c_code_rate(folder, n, eta, code=code))
        measured = {code: rate for code, rate in peers.items() if rate}
        fastest = max(measured, key=measured.__getitem__) if measured else None
        rows.append({"n": n, "eta": eta, "engine": engine, "peers": peers, "fastest": fastest,
                     "ratio": engine / measured[fastest] if fastest else None})
    return rows


def c_code_lines(rows: list[dict]) -> list[str]:
    """The gas report's "against the C codes" table (markdown lines) from ``against_c_code`` rows."""
    codes = list(rows[0]["peers"]) if rows else list(CODES)
    lines = ["## The event-driven gas against the C codes", "",
             "Collisions per second of processor time, one thread, periodic box, alternated runs (best of each). "
             "Peers: F. Smallenburg's EDMD codes (EPJE 45, 22 (2022)): Cell (cell lists), Multi (neighbour lists, "
             "every event scheduled), Single (neighbour lists, one event per sphere), each with Paul's event "
             "calendar and its authors' parameters, built with `gcc -O3 -march=native`, thermostat off. The ratio "
             "is the engine's over the fastest C code.", ""]
    if all(r["fastest"] is None for r in rows):
        lines += [f"Peers skipped: set {ENV} to a local copy of the EDMD repository to measure them. The engine "
                  "alone:", ""]
    lines += ["| N | η | engine (collisions/s) | " + " | ".join(f"EDMD {c}" for c in codes)
              + " | engine / fastest C |", "|---|---|---|" + "---|" * len(codes) + "---|"]
    for r in rows:
        peers = ["skipped" if r["peers"][c] is None else f"{r['peers'][c]:,.0f}" for c in codes]
        ratio = "—" if r["ratio"] is None else f"{r['ratio']:.2f}× ({r['fastest']})"
        lines.append(f"| {r['n']:,} | {r['eta']} | {r['engine']:,.0f} | " + " | ".join(peers) + f" | {ratio} |")
    return lines + [""]


if __name__ == "__main__":
    print("\n".join(c_code_lines(against_c_code())))
