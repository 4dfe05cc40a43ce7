"""A real Dask cluster on 127.0.0.1 for the sweep fault tests, and the tasks and the driver it runs.

- ``Cluster``: a ``dask scheduler`` and ``dask worker`` processes started as subprocesses (each worker in its own
  process group, so that a test can SIGKILL one worker, or a worker and its nanny, by process id); every process
  exits by itself if the test process dies (scheduler idle timeout, worker death timeout).
- task functions: module level, imported by the workers by reference (the repository root is on their
  ``PYTHONPATH``); pure Python and cheap, each one appending a line to a per-configuration file per call, so that
  the tests count how often a configuration really ran, across processes;
- ``python -m properties.sweep_cluster drive STORE SCHEDULER CALLS [N [SLEEP]]``: a driving process (the client)
  that runs the counted sweep into ``STORE`` and prints its rows as JSON; the client-kill test SIGKILLs it;
- ``python -m properties.sweep_cluster compile``: a process that calls engine entry points (compiling their kernels
  or loading them from the numba cache) and prints a digest of the answers and the kernels it compiled.
Not a test module (no ``test_`` prefix): nothing here is collected.
"""
from __future__ import annotations

import contextlib
import hashlib
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

# ------------------------------------------------------------------------------------------------------------
# tasks: deterministic rows (a configuration's row never depends on the process or on the attempt)
# ------------------------------------------------------------------------------------------------------------


def record_call(calls: str, i: int) -> None:
    """One line per call in ``<calls>/<i>`` (O_APPEND: lines of concurrent processes never interleave)."""
    fd = os.open(os.path.join(calls, str(i)), os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o644)
    try:
        os.write(fd, f"{os.getpid()}\n".encode())
    finally:
        os.close(fd)


def calls_of(calls: str | Path, i: int) -> list[int]:
    """The pids of the processes that ran configuration i, one per call."""
    path = Path(calls) / str(i)
    return [int(x) for x in path.read_text().split()] if path.exists() else []


def pure_row(i: int) -> dict:
    """The row of configuration i (what ``counted_row`` returns)."""
    return {"square": i**2, "digest": hashlib.sha256(f"row {i}".encode()).hexdigest(), "root": i**0.5}


def counted_row(cfg: dict) -> dict:
    """Records the call, sleeps ``cfg["sleep"]`` s (so a sweep lasts long enough to be interrupted), returns a
    row that is a pure function of the configuration."""
    record_call(cfg["calls"], cfg["i"])
    time.sleep(cfg["sleep"])
    return pure_row(cfg["i"])


def counted_row_with_pid(cfg: dict) -> dict:
    """``counted_row`` plus the pid of the worker that produced it (which worker's result was kept)."""
    return {**counted_row(cfg), "pid": os.getpid()}


def raising_row(cfg: dict) -> dict:
    """Raises for every configuration listed in ``cfg["bad"]``; records every attempt."""
    record_call(cfg["calls"], cfg["i"])
    if cfg["i"] in cfg["bad"]:
        raise ValueError(f"configuration {cfg['i']} always fails")
    return {"square": cfg["i"] ** 2}


def worker_killing_row(cfg: dict) -> dict:
    """The configuration ``cfg["poison"]`` SIGKILLs the worker process that runs it, at every attempt."""
    record_call(cfg["calls"], cfg["i"])
    if cfg["i"] == cfg["poison"]:
        os.kill(os.getpid(), signal.SIGKILL)
    time.sleep(cfg["sleep"])
    return {"square": cfg["i"] ** 2}


def counted_configs(calls: str | Path, n: int, sleep: float) -> list[dict]:
    return [dict(i=i, sleep=sleep, calls=str(calls)) for i in range(n)]


# ------------------------------------------------------------------------------------------------------------
# the cluster
# ------------------------------------------------------------------------------------------------------------


def subprocess_environment(extra: dict | None = None) -> dict:
    paths = [str(ROOT), *[p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]]
    return {**os.environ, "PYTHONPATH": os.pathsep.join(paths), **(extra or {})}


class Cluster:
    """``dask scheduler`` + ``dask worker`` subprocesses on 127.0.0.1, one thread per worker.

    ``env``: extra environment of the scheduler (e.g. ``DASK_DISTRIBUTED__SCHEDULER__ALLOWED_FAILURES``).
    ``workers`` holds the ``Popen`` of each ``dask worker`` command (the nanny; its worker process is a child).
    """

    def __init__(self, folder: Path, n_workers: int = 2, env: dict | None = None, timeout: float = 60.0):
        self.folder = Path(folder)
        self.folder.mkdir(parents=True, exist_ok=True)
        self.scheduler_file = self.folder / "scheduler.json"
        self.processes: list[subprocess.Popen] = []
        self.workers: list[subprocess.Popen] = []
        self.scheduler = self._start(["scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                                      "--scheduler-file", str(self.scheduler_file), "--idle-timeout", "300"],
                                     "scheduler", env)
        deadline = time.monotonic() + timeout
        while not self.scheduler_file.exists():
            if self.scheduler.poll() is not None or time.monotonic() > deadline:
                self.close()
                raise RuntimeError(f"the dask scheduler did not start: {self._log('scheduler')}")
            time.sleep(0.1)
        time.sleep(0.2)  # the file is written in one go, but give the reader a complete one
        self.address = json.loads(self.scheduler_file.read_text())["address"]
        for _ in range(n_workers):
            self.add_worker()
        self.wait_for_workers(n_workers, timeout)

    def _start(self, args: list[str], name: str, env: dict | None = None) -> subprocess.Popen:
        log = open(self.folder / f"{name}.log", "wb")  # noqa: SIM115 - closed with the process
        proc = subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_" + args[0], *args[1:]],
                                stdout=log, stderr=subprocess.STDOUT, env=subprocess_environment(env), cwd=str(ROOT),
                                start_new_session=True)
        log.close()
        self.processes.append(proc)
        return proc

    def _log(self, name: str) -> str:
        path = self.folder / f"{name}.log"
        return path.read_text(errors="replace")[-3000:] if path.exists() else ""

    def add_worker(self) -> subprocess.Popen:
        """Start one more ``dask worker`` (nanny + one worker process, one thread)."""
        k = len(self.workers)
        proc = self._start(["worker", "--scheduler-file", str(self.scheduler_file), "--nthreads", "1",
                            "--nworkers", "1", "--host", "127.0.0.1", "--no-dashboard", "--name", f"w{k}",
                            "--death-timeout", "60", "--local-directory", str(self.folder / f"w{k}")],
                           f"worker{k}")
        self.workers.append(proc)
        return proc

    def client(self):
        from distributed import Client

        return Client(self.address, timeout=30)

    def wait_for_workers(self, n: int, timeout: float = 60.0) -> None:
        with self.client() as c:
            c.wait_for_workers(n, timeout=timeout)

    def kill_group(self, proc: subprocess.Popen) -> None:
        """SIGKILL a ``dask worker`` command and its worker process (its process group) and reap it."""
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGKILL)
        proc.wait(timeout=30)

    def close(self) -> None:
        """Stop every process this cluster started: SIGTERM to each group, then SIGKILL what is left."""
        for proc in reversed(self.processes):
            if proc.poll() is None:
                with contextlib.suppress(ProcessLookupError):
                    os.killpg(proc.pid, signal.SIGTERM)
        for proc in reversed(self.processes):
            try:
                proc.wait(timeout=15)
            except subprocess.TimeoutExpired:
                self.kill_group(proc)
            with contextlib.suppress(ProcessLookupError):  # orphaned worker processes of a stopped nanny
                os.killpg(proc.pid, signal.SIGKILL)


# ------------------------------------------------------------------------------------------------------------
# the driving process of the client-kill test
# ------------------------------------------------------------------------------------------------------------


def counted_sweep(calls: str | Path, n: int, sleep: float):
    from bench.sweep import Sweep

    return Sweep("counted", counted_row, counted_configs(calls, n, sleep), ("i",))


def drive(argv: list[str]) -> None:
    """``drive STORE SCHEDULER CALLS [N [SLEEP]]``: the counted sweep as a client of SCHEDULER; rows on stdout."""
    from distributed import Client

    from bench.sweep import RowStore, run_sweep

    store, address, calls = argv[0], argv[1], argv[2]
    n = int(argv[3]) if len(argv) > 3 else 12
    sleep = float(argv[4]) if len(argv) > 4 else 0.3
    with Client(address, timeout=30) as client:
        result = run_sweep(counted_sweep(calls, n, sleep), RowStore(store), client, stream=sys.stderr)
    json.dump({"rows": result.rows, "computed": result.computed, "resumed": result.resumed,
               "failures": [[c, e] for c, e in result.failures]}, sys.stdout)


def compile_probe(argv: list[str]) -> None:
    """``compile``: small calls of the engine's entry points; prints a digest of the answers and which engine
    kernels this process really compiled (numba's compile event fires for a compilation, not for a kernel
    loaded from the cache)."""
    import numba.core.event

    compiled = []

    class CountCompilations(numba.core.event.Listener):
        def on_start(self, event):
            if getattr(event.data["dispatcher"].py_func, "__module__", "").startswith("engine."):
                compiled.append(event.data["dispatcher"].py_func.__qualname__)

        def on_end(self, event):
            pass

    numba.core.event.register("numba:compile", CountCompilations())
    import numpy as np

    import engine

    rng = np.random.default_rng(7)
    centre = rng.uniform(0.0, 10.0, size=(300, 3))
    half = rng.uniform(0.0, 0.5, size=(300, 3))
    answers = {"sap": engine.find_pairs(centre - half, centre + half, method="sap").tolist(),
               "spheres": engine.sphere_pairs(centre, 0.4, method="grid").tolist()}
    digest = hashlib.sha256(json.dumps(answers).encode()).hexdigest()
    json.dump({"digest": digest, "pairs": [len(v) for v in answers.values()], "compiled": sorted(compiled),
               "cache_dir": engine._config.CACHE_DIR}, sys.stdout)


if __name__ == "__main__":
    {"drive": drive, "compile": compile_probe}[sys.argv[1]](sys.argv[2:])
