"""Sweeps of the main job on Dask distributed: one pure task per configuration, rows stored as they complete.

A sweep is ``Sweep(name, function, configs, key_fields)``: ``function(config) -> row`` is a pure, module-level
function (a dict of JSON-able values in, a dict out) so that any worker can run it; ``key_fields`` name the
fields of a configuration that identify it (its key). ``run_sweep(sweep, store, client)`` submits every
configuration whose key is not yet stored with ``client.submit(function, config, retries=..., pure=False)`` and
collects them with ``as_completed``:

- **rows are durable at completion**: each completed row is appended to the store (one JSON line, flushed and
  fsync'ed) before the next result is looked at, so an interrupted sweep (client killed, Ctrl-C, a crash of the
  report) keeps every row it reported; a worker that dies only loses the task it was running, which the
  scheduler reruns on another worker;
- **resume**: a rerun skips the configurations whose key is already in the store (rows of another ``version``,
  e.g. another commit, are not reused) and only runs the missing ones;
- **failures**: a task that raises is retried ``retries`` times by the scheduler; if it still fails, it is
  reported on the console and in ``<name>.failures.csv`` and the sweep goes on: no completed row is lost, and a
  rerun retries only the failed configurations. A task the scheduler gave up on because its workers kept dying
  under it (``KilledWorker``: it may only have been queued behind one that crashes its worker) is run once
  more alone before it is reported;
- **progress**: a counter line (done / total, failures, resumed, elapsed), on one line in a terminal.

Where the tasks run (``sweep_client``): ``--scheduler tcp://HOST:8786`` (``python -m bench.report``) or the environment
variable ``COLLIDE_SCHEDULER`` submit to an existing cluster; otherwise an embedded ``LocalCluster`` of worker
processes on this machine. Two kinds of sweeps:

- ``"physics"`` (correctness and physics points): workers with one thread each, as many as cores;
- ``"timing"`` (anything that measures a time): at most one timing task per worker process at a time, a worker
  having one thread: the tasks ask for the worker resource ``timing=1`` and each timing worker offers exactly one.
  The embedded timing cluster has ``max(1, cores // 2)`` workers (one on a 2-core machine: the other core is
  left to the scheduler, the nanny and the OS, so timings are not disturbed by a sibling task). On a remote
  cluster, start the timing workers with ``dask worker tcp://HOST:8786 --nthreads 1 --resources timing=1``; if
  no worker offers the resource, the sweep says so and runs unconstrained.

Workers must import ``engine`` and ``bench``: embedded workers inherit ``PYTHONPATH`` with the repository root
prepended; remote workers need the same checkout (``pip install -e .`` and the repository root on
``PYTHONPATH``). No code is shipped to workers: the task functions are pickled by reference.

Serial mode (``client=None`` in ``run_sweep``) runs the same functions in this process with the same store,
resume and retry rules: the reference the distributed run is tested against (properties/test_sweep_dask.py).
The fault-tolerance promises (a worker or the client SIGKILLed mid-sweep, a store torn by a crash, a
configuration that always fails, workers compiling the engine's kernels at once into one numba cache) are tested
on a real scheduler and workers in properties/test_sweep_faults.py.
"""
from __future__ import annotations

import contextlib
import json
import math
import os
import sys
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCHEDULER_ENV = "COLLIDE_SCHEDULER"
KINDS = ("physics", "timing")
TIMING_RESOURCE = "timing"


@dataclass
class Sweep:
    """A named sweep: ``function(config) -> row`` over ``configs``, a configuration identified by ``key_fields``.

    Each stored row is the function's row plus the configuration's key fields (which win over row fields of the
    same name: the key is what resume compares).

    kind: "physics" (may fill every core) or "timing" (one task per worker process, one thread: see the module).
    retries: how many times the scheduler reruns a task that raised before it is reported as failed.
    version: rows stored under another version (e.g. another commit) are not reused on resume.
    """

    name: str
    function: Callable[[dict], dict]
    configs: Sequence[dict]
    key_fields: Sequence[str]
    kind: str = "physics"
    retries: int = 2
    version: str = ""

    def __post_init__(self):
        if self.kind not in KINDS:
            raise ValueError(f"kind must be one of {KINDS}, got {self.kind!r}")
        if not self.key_fields:
            raise ValueError("key_fields must name at least one field of the configurations")
        seen = set()
        for cfg in self.configs:
            missing = [f for f in self.key_fields if f not in cfg]
            if missing:
                raise ValueError(f"configs: {cfg!r} lacks the key fields {missing}")
            k = self.key(cfg)
            if k in seen:
                raise ValueError(f"configs: two configurations share the key {k}")
            seen.add(k)

    def key(self, config_or_row: dict) -> str:
        """The key of a configuration (or of its row, which carries the key fields): canonical JSON."""
        return json.dumps([config_or_row[f] for f in self.key_fields])


class RowStore:
    """The rows of one sweep, one JSON line each, appended (flush + fsync) as each task completes.

    ``path`` is the store (``<out>/.sweeps/<name>.jsonl`` in the report). Rows carry the sweep's ``version``
    under ``_version``. A line that is not a whole JSON object — the last line cut short by a crash in the middle
    of a write, or bytes a crash left behind (zeros, undecodable text) — is not a row: ``read`` skips it and
    lists its line number (1-based) in ``torn_lines``, so its configuration simply runs again.
    """

    def __init__(self, path: Path | str):
        self.path = Path(path)
        self.torn_lines: list[int] = []

    def read(self, version: str = "") -> list[dict]:
        self.torn_lines = []
        if not self.path.exists():
            return []
        rows = []
        for number, line in enumerate(self.path.read_bytes().split(b"\n"), start=1):
            if not line:
                continue  # the end of the file after the last newline
            try:
                row = json.loads(line.decode("utf-8"))
            except (UnicodeDecodeError, json.JSONDecodeError):
                row = None
            if not isinstance(row, dict):
                self.torn_lines.append(number)
            elif row.get("_version", "") == version:
                rows.append(row)
        return rows

    def append(self, row: dict, version: str = "") -> None:
        self.path.parent.mkdir(parents=True, exist_ok=True)
        line = json.dumps({**row, "_version": version}, default=_jsonable) + "\n"
        with open(self.path, "a+b") as f:
            if f.tell() > 0:  # after a torn last line, start a fresh line rather than extend the broken one
                f.seek(-1, os.SEEK_END)
                if f.read(1) != b"\n":
                    line = "\n" + line
            f.write(line.encode())
            f.flush()
            os.fsync(f.fileno())

    def clear(self) -> None:
        """Forget the rows (a finished sweep): the file goes, and its folder too when that leaves it empty."""
        self.path.unlink(missing_ok=True)
        with contextlib.suppress(OSError):
            self.path.parent.rmdir()


def _jsonable(value):
    """numpy scalars and arrays in rows become plain JSON values."""
    if hasattr(value, "tolist"):
        return value.tolist()
    raise TypeError(f"a sweep row holds a value JSON cannot store: {type(value).__name__}")


@dataclass
class SweepResult:
    """rows: every stored row of the sweep, in the order of its configs (resumed ones included);
    computed: keys run in this call; resumed: keys found in the store; failures: (config, error text) of the
    tasks that failed after their retries; torn_lines: the store's lines that were not rows (see RowStore)."""

    rows: list[dict]
    computed: list[str] = field(default_factory=list)
    resumed: list[str] = field(default_factory=list)
    failures: list[tuple[dict, str]] = field(default_factory=list)
    torn_lines: list[int] = field(default_factory=list)

    @property
    def complete(self) -> bool:
        return not self.failures


class _Progress:
    """A counter line: ``[sweep eos] 12/45 done · 0 failed · 3 resumed · 10 s``; one line in a terminal, a line
    every tenth of the sweep in a log."""

    def __init__(self, name: str, total: int, resumed: int, stream=None):
        self.name, self.total, self.resumed = name, total, resumed
        self.stream = stream or sys.stdout
        self.done = resumed
        self.failed = 0
        self.started = time.perf_counter()
        self.tty = self.stream.isatty()
        self.step = max(1, math.ceil(total / 10))
        self.show(force=True)

    def show(self, force=False):
        text = (f"[sweep {self.name}] {self.done}/{self.total} done · {self.failed} failed · {self.resumed} "
                f"resumed · {time.perf_counter() - self.started:.0f} s")
        if self.tty:
            print("\r" + text, end="\n" if self.done + self.failed >= self.total else "", file=self.stream,
                  flush=True)
        elif force or (self.done + self.failed) % self.step == 0 or self.done + self.failed >= self.total:
            print(text, file=self.stream, flush=True)

    def row(self):
        self.done += 1
        self.show()

    def note(self, message: str):
        print(("\n" if self.tty else "") + f"[sweep {self.name}] {message}", file=self.stream, flush=True)

    def failure(self, message: str):
        self.failed += 1
        self.note(f"FAILED after retries: {message}")
        self.show()


def run_sweep(sweep: Sweep, store: RowStore, client=None, *, on_row: Callable[[dict], None] | None = None,
              failures_path: Path | str | None = None, stream=None) -> SweepResult:
    """Run the configurations of ``sweep`` missing from ``store``, appending each row to it as it completes.

    client: a ``distributed.Client`` (see ``sweep_client``), or None to run serially in this process with the
    same rules. on_row(row) is called after each row is stored (the tests use it to interrupt or kill).
    failures_path: where to write the failed configurations (CSV; removed when none failed).
    Returns the stored rows in the order of ``sweep.configs``; never raises for a failing task (only for an
    interruption, after which every completed row is in the store). A task whose row cannot be stored (not a
    dict, or holding a value JSON cannot store) is a failed configuration; nothing of it is written.
    Stored lines that are not rows (``RowStore.torn_lines``: a write cut short by a crash) are reported and
    skipped, so their configurations run again; so are rows lacking one of the key fields.
    """
    stored = {sweep.key(r): r for r in store.read(sweep.version) if all(f in r for f in sweep.key_fields)}
    todo = [c for c in sweep.configs if sweep.key(c) not in stored]
    resumed = [sweep.key(c) for c in sweep.configs if sweep.key(c) in stored]
    result = SweepResult(rows=[], resumed=resumed, torn_lines=list(store.torn_lines))
    progress = _Progress(sweep.name, len(sweep.configs), len(resumed), stream)
    if result.torn_lines:
        progress.note(f"{store.path}: line(s) {result.torn_lines} are not whole rows (a write cut short by a "
                      "crash): skipped, their configurations run again unless stored on another line")

    def fail(cfg, error):
        result.failures.append((cfg, error))
        progress.failure(f"{sweep.key(cfg)}: {error}")

    def keep(cfg, row):
        if not isinstance(row, dict):
            return fail(cfg, f"TypeError: the task returned a {type(row).__name__}, not a dict")
        row = {**row, **{f: cfg[f] for f in sweep.key_fields}}  # the configuration's key identifies the row
        try:
            store.append(row, sweep.version)
        except (TypeError, ValueError) as exc:  # refused before anything is written
            return fail(cfg, f"{type(exc).__name__}: {exc}")
        stored[sweep.key(cfg)] = {**row, "_version": sweep.version}
        result.computed.append(sweep.key(cfg))
        progress.row()
        if on_row is not None:
            on_row(row)

    if client is None:
        _run_serially(sweep, todo, keep, fail)
    elif todo:
        _run_on_cluster(sweep, todo, client, keep, fail)
    result.rows = [stored[sweep.key(c)] for c in sweep.configs if sweep.key(c) in stored]
    for r in result.rows:
        r.pop("_version", None)
    if failures_path is not None:
        write_failures(result.failures, failures_path)
    return result


def _run_serially(sweep: Sweep, todo: list[dict], keep, fail) -> None:
    """Each configuration in this process, retried ``sweep.retries`` times as the scheduler would."""
    for cfg in todo:
        for attempt in range(sweep.retries + 1):
            try:
                row = sweep.function(dict(cfg))
            except Exception as exc:  # noqa: BLE001 - any failure of a task is recorded, as Dask would
                if attempt == sweep.retries:
                    fail(cfg, f"{type(exc).__name__}: {exc}")
            else:
                keep(cfg, row)
                break


def _run_on_cluster(sweep: Sweep, todo: list[dict], client, keep, fail) -> None:
    """One task per configuration (retried by the scheduler), each result handled as it completes.

    A worker that dies takes with it every task it holds (the running one and those queued behind it), and the
    scheduler gives up on a task whose workers died under it more than ``allowed-failures`` times
    (``KilledWorker``): so a configuration that kills its worker can get innocent ones reported with it. Each
    configuration that ended in ``KilledWorker`` is therefore run once more on its own, after the others, and is
    reported only if it fails alone too.
    """
    from distributed import KilledWorker, as_completed

    resources = _timing_resources(client) if sweep.kind == "timing" else None
    futures: dict = {}
    suspects: list[dict] = []

    def submit(cfg):
        fut = client.submit(sweep.function, dict(cfg), retries=sweep.retries, pure=False, resources=resources)
        futures[fut] = cfg
        return fut

    def collect(fut, alone: bool):
        cfg = futures.pop(fut)
        # not fut.status: a result held by a worker that died since it finished is "lost" for a moment, then
        # computed again; result() waits for that, and raises what the task raised after its retries
        try:
            row = fut.result()
        except KilledWorker as exc:
            if alone:
                fail(cfg, f"KilledWorker: {exc} (run alone after a worker died under it)")
            else:
                suspects.append(cfg)
        except Exception as exc:  # noqa: BLE001 - the task's error, or cancelled
            fail(cfg, f"{type(exc).__name__}: {exc}")
        else:
            keep(cfg, row)
        fut.release()

    try:
        for fut in as_completed([submit(cfg) for cfg in todo]):
            collect(fut, alone=False)
        for cfg in suspects:  # alone: nothing else runs on its worker
            collect(submit(cfg), alone=True)
    finally:  # interrupted: the tasks still running are cancelled; the stored rows stay
        if futures:
            with contextlib.suppress(Exception):
                client.cancel(list(futures))


def write_failures(failures: list[tuple[dict, str]], path: Path | str) -> None:
    """``<name>.failures.csv``: one line per failed configuration and its last error; removed when none."""
    import pandas as pd

    path = Path(path)
    if not failures:
        path.unlink(missing_ok=True)
        return
    pd.DataFrame([{**cfg, "error": err} for cfg, err in failures]).to_csv(path, index=False)


def _timing_resources(client) -> dict | None:
    """resources={"timing": 1} when some worker offers it; else a warning and no constraint."""
    workers = client.scheduler_info().get("workers", {})
    if any(TIMING_RESOURCE in (w.get("resources") or {}) for w in workers.values()):
        return {TIMING_RESOURCE: 1}
    print(f"[sweep] warning: no worker offers the '{TIMING_RESOURCE}' resource; timing tasks run unconstrained "
          f"(start timing workers with: dask worker ADDRESS --nthreads 1 --resources {TIMING_RESOURCE}=1)",
          flush=True)
    return None


def scheduler_address(scheduler: str | None = None) -> str | None:
    """The scheduler to use: the argument, else $COLLIDE_SCHEDULER, else None (embedded LocalCluster)."""
    return scheduler or os.environ.get(SCHEDULER_ENV) or None


def _worker_environment() -> None:
    """Embedded workers import ``engine`` and ``bench`` from this checkout: the repository root goes first on
    the PYTHONPATH they inherit (spawned processes read it at start-up)."""
    paths = [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]
    if str(ROOT) not in paths:
        os.environ["PYTHONPATH"] = os.pathsep.join([str(ROOT), *paths])


def embedded_workers(kind: str) -> int:
    cores = os.cpu_count() or 1
    return max(1, cores // 2) if kind == "timing" else cores


@contextlib.contextmanager
def sweep_client(scheduler: str | None = None, kind: str = "physics", n_workers: int | None = None) -> Iterator:
    """A ``distributed.Client`` for sweeps of ``kind``: on ``scheduler`` (or $COLLIDE_SCHEDULER) when given,
    else on an embedded ``LocalCluster(processes=True)`` of one-thread workers (timing workers each offer the
    resource ``timing=1``), closed on exit."""
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
    from distributed import Client, LocalCluster

    address = scheduler_address(scheduler)
    if address:
        print(f"[sweep] scheduler {address}", flush=True)
        with Client(address) as client:
            yield client
        return
    _worker_environment()
    n = n_workers or embedded_workers(kind)
    resources = {TIMING_RESOURCE: 1} if kind == "timing" else None
    with LocalCluster(n_workers=n, threads_per_worker=1, processes=True, resources=resources,
                      dashboard_address=":0", silence_logs=40) as cluster, Client(cluster) as client:
        print(f"[sweep] embedded LocalCluster: {n} {kind} worker process(es), 1 thread each", flush=True)
        yield client
