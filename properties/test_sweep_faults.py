"""The report's sweeps survive faults (bench/sweep.py): what README promises, on real processes of this machine.

A real ``dask scheduler`` and ``dask worker`` processes on 127.0.0.1 (properties/sweep_cluster.py), tiny sweeps
of cheap pure-Python tasks that count their calls (one line per call in a per-configuration file, written by
whichever process ran it), and real SIGKILLs:
- a worker process killed mid-sweep (its nanny restarts it), and a whole worker (nanny and process) killed:
  every configuration stored exactly once, no failure;
- the client (the driving process) killed mid-sweep, then rerun: no stored row is computed again, and the rows
  equal those of an uninterrupted run;
- a store whose last line was cut by a crash during a write (any cut of the line, zeros, undecodable bytes): the
  line is reported, its configuration runs again, every row is read back once;
- a configuration that always raises, and one that kills its worker at every attempt (taking the tasks queued
  behind it down with it): listed in ``<name>.failures.csv`` after their attempts, every other configuration
  completes;
- rows that cannot be stored, and stored rows that lack a key field: failures, or simply not resumed;
- processes compiling the same engine kernels at once into an empty numba cache (as the workers of one machine
  do): identical answers, and a later process loads every kernel from that cache (compiles nothing) and gets
  the same answers.
Oracle: the configurations themselves (each stored once, rows a pure function of the configuration) and the
call counts. The whole file takes about 1.5 minutes, most of it the cold compilation.
"""
from __future__ import annotations

import csv
import json
import os
import signal
import subprocess
import sys
import time

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

pytest.importorskip("distributed")

from bench.sweep import RowStore, Sweep, run_sweep  # noqa: E402
from properties.sweep_cluster import (  # noqa: E402
    ROOT,
    Cluster,
    calls_of,
    counted_configs,
    counted_row,
    counted_row_with_pid,
    counted_sweep,
    pure_row,
    raising_row,
    subprocess_environment,
    worker_killing_row,
)

#: the poison test's scheduler gives up on a task (KilledWorker) as soon as a worker dies under it
ALLOWED_FAILURES = 0
QUIET = open(os.devnull, "w")  # noqa: SIM115 - the sweeps' progress lines are not what these tests read


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    c = Cluster(tmp_path_factory.mktemp("cluster"), n_workers=2)
    try:
        yield c
    finally:
        c.close()


@pytest.fixture
def client(cluster):
    cluster.wait_for_workers(2)  # a test that killed a worker leaves the next one a full cluster
    with cluster.client() as c:
        yield c


def stored_lines(store: RowStore) -> list[dict]:
    """Every line of the store that is a row (whatever its version)."""
    rows = []
    for line in store.path.read_bytes().split(b"\n"):
        try:
            rows.append(json.loads(line))
        except (UnicodeDecodeError, json.JSONDecodeError):
            pass
    return rows


def assert_every_config_stored_once(sweep: Sweep, store: RowStore) -> None:
    keys = [sweep.key(r) for r in stored_lines(store)]
    assert sorted(keys) == sorted(sweep.key(c) for c in sweep.configs), "a configuration missing or stored twice"


# ------------------------------------------------------------------------------------------------------------
# a worker dies
# ------------------------------------------------------------------------------------------------------------


def test_worker_process_killed_mid_sweep_every_config_stored_once(client, tmp_path):
    """SIGKILL of a worker process while both workers hold finished results the client has not fetched yet:
    those results are lost with it and computed again; each configuration is still stored exactly once."""
    calls = tmp_path / "calls"
    calls.mkdir()
    sweep = Sweep("kill_worker", counted_row_with_pid, counted_configs(calls, 40, 0.02), ("i",))
    store = RowStore(tmp_path / "kill_worker.jsonl")
    victim = sorted(client.run(os.getpid).values())[0]
    killed = []

    def kill_once(row):
        if not killed and len(list(calls.iterdir())) >= 6:
            time.sleep(0.5)  # the workers go on: finished results pile up in their memory
            os.kill(victim, signal.SIGKILL)
            killed.append(row)
            time.sleep(0.2)  # the scheduler tells the client that the victim's results are lost

    result = run_sweep(sweep, store, client, on_row=kill_once, stream=QUIET)
    assert killed, "the kill never happened"
    assert result.complete, result.failures
    assert [r["i"] for r in result.rows] == list(range(40))
    assert all(r["square"] == r["i"] ** 2 for r in result.rows)
    lost = [i for i in range(40) if victim in calls_of(calls, i) and len(calls_of(calls, i)) > 1]
    assert lost, "the kill lost no work: the test did not kill mid-sweep"
    assert_every_config_stored_once(sweep, store)


def test_whole_worker_killed_the_others_finish_the_sweep(cluster, client, tmp_path):
    """A third worker (nanny and worker process) SIGKILLed as a group mid-sweep: it never comes back; the two
    others finish; every configuration stored exactly once."""
    extra = cluster.add_worker()
    cluster.wait_for_workers(3)
    names = {address: w["name"] for address, w in client.scheduler_info()["workers"].items()}
    extra_name = f"w{len(cluster.workers) - 1}"
    extra_pid = [pid for address, pid in client.run(os.getpid).items() if names[address] == extra_name]
    calls = tmp_path / "calls"
    calls.mkdir()
    sweep = Sweep("kill_machine", counted_row, counted_configs(calls, 24, 0.1), ("i",))
    store = RowStore(tmp_path / "kill_machine.jsonl")
    killed = []

    def kill_group(row):
        if not killed and len(stored_lines(store)) >= 4:
            cluster.kill_group(extra)
            killed.append(row)

    result = run_sweep(sweep, store, client, on_row=kill_group, stream=QUIET)
    assert killed and extra.returncode == -signal.SIGKILL
    assert len(extra_pid) == 1
    lost = [i for i in range(24) if extra_pid[0] in calls_of(calls, i) and len(calls_of(calls, i)) > 1]
    assert lost, "the kill lost no work: the test did not kill mid-sweep"
    assert result.complete, result.failures
    assert [r["i"] for r in result.rows] == list(range(24))
    assert_every_config_stored_once(sweep, store)
    assert len(client.scheduler_info()["workers"]) == 2


# ------------------------------------------------------------------------------------------------------------
# the client dies
# ------------------------------------------------------------------------------------------------------------


def drive(cluster: Cluster, store, calls, n: int, sleep: float) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "properties.sweep_cluster", "drive", str(store), cluster.address,
                             str(calls), str(n), str(sleep)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            env=subprocess_environment(), cwd=str(ROOT), text=True)


def finish(proc: subprocess.Popen) -> dict:
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 0, err
    return json.loads(out)


def test_client_killed_mid_sweep_rerun_recomputes_no_stored_row(cluster, tmp_path):
    n, sleep = 16, 0.25
    reference = finish(drive(cluster, tmp_path / "reference.jsonl", _folder(tmp_path / "calls_ref"), n, sleep))
    assert reference["failures"] == [] and len(reference["rows"]) == n

    calls = _folder(tmp_path / "calls")
    store = RowStore(tmp_path / "interrupted.jsonl")
    first = drive(cluster, store.path, calls, n, sleep)
    deadline = time.monotonic() + 60
    while not (store.path.exists() and len(store.read()) >= 4):
        assert first.poll() is None, first.communicate()[1]
        assert time.monotonic() < deadline, "the first run stored nothing"
        time.sleep(0.02)
    first.send_signal(signal.SIGKILL)
    first.communicate(timeout=30)
    assert first.returncode == -signal.SIGKILL
    before = {r["i"] for r in store.read()}
    assert 4 <= len(before) < n, "the client was not killed mid-sweep"

    again = finish(drive(cluster, store.path, calls, n, sleep))
    sweep = counted_sweep(calls, n, sleep)
    assert sorted(again["resumed"]) == sorted(sweep.key({"i": i}) for i in before)
    assert sorted(again["computed"]) == sorted(sweep.key({"i": i}) for i in set(range(n)) - before)
    for i in before:
        assert len(calls_of(calls, i)) == 1, f"stored configuration {i} ran again"
    assert all(len(calls_of(calls, i)) >= 1 for i in range(n))
    assert again["rows"] == reference["rows"]
    assert_every_config_stored_once(sweep, store)


def _folder(path):
    path.mkdir()
    return path


# ------------------------------------------------------------------------------------------------------------
# a crash in the middle of a write
# ------------------------------------------------------------------------------------------------------------


def store_row(store: RowStore, sweep: Sweep, i: int) -> None:
    """Append configuration i's row as run_sweep does (its row, then its key fields)."""
    store.append({**pure_row(i), "i": i}, sweep.version)


def line_bytes(sweep: Sweep, i: int, folder) -> bytes:
    """The bytes RowStore.append writes for configuration i's row (written to a scratch store, read back)."""
    scratch = RowStore(folder / "scratch.jsonl")
    store_row(scratch, sweep, i)
    line = scratch.path.read_bytes()
    scratch.path.unlink()
    return line


def torn_tails():
    """What a crash during the append of the last line leaves: a prefix of the line (fraction of its bytes),
    or zeros where the data never reached the disk, or bytes that do not decode."""
    prefix = st.floats(0.0, 1.0).map(lambda f: ("prefix", f))
    zeros = st.integers(1, 80).map(lambda k: ("zeros", k))
    garbage = st.floats(0.0, 1.0).map(lambda f: ("undecodable", f))
    return st.one_of(prefix, zeros, garbage)


def cut(line: bytes, tail) -> bytes:
    kind, amount = tail
    if kind == "zeros":
        return b"\0" * amount
    if kind == "prefix":
        return line[: round(amount * len(line))]
    return line[: round(amount * (len(line) - 1))] + b"\xff\xfe"  # cut before the newline, then junk


@settings(max_examples=60)
@given(n_stored=st.integers(0, 5), tail=torn_tails())
def test_torn_last_line_is_reported_and_its_row_recomputed(tmp_path_factory, n_stored, tail):
    folder = tmp_path_factory.mktemp("torn")
    calls = _folder(folder / "calls")
    sweep = Sweep("torn", counted_row, counted_configs(calls, 6, 0.0), ("i",), version="v1")
    reference = run_sweep(sweep, RowStore(folder / "reference.jsonl"), stream=QUIET).rows
    store = RowStore(folder / "torn.jsonl")
    for i in range(n_stored):
        store_row(store, sweep, i)
    line = line_bytes(sweep, n_stored, folder)
    torn = cut(line, tail)
    with open(store.path, "ab") as f:
        f.write(torn)
    for p in calls.iterdir():
        p.unlink()
    whole = torn in (line, line[:-1])  # the row's JSON is complete (the newline alone may be missing)
    blank = torn == b""
    result = run_sweep(sweep, store, stream=QUIET)
    assert result.rows == reference
    assert result.torn_lines == ([] if whole or blank else [n_stored + 1])
    missing = set(range(n_stored + (1 if whole else 0), 6))
    assert sorted(result.computed) == sorted(sweep.key({"i": i}) for i in missing)
    for i in range(6):
        assert len(calls_of(calls, i)) == (1 if i in missing else 0)
    # the store read back afterwards: every row once, the torn line (now inside the file) still skipped
    assert_every_config_stored_once(sweep, store)
    again = run_sweep(sweep, store, stream=QUIET)
    assert again.computed == [] and again.rows == reference


def test_torn_store_on_the_cluster(client, tmp_path):
    """The same repair when the rows come from workers: the torn row is recomputed there, nothing else."""
    calls = _folder(tmp_path / "calls")
    sweep = Sweep("torn_cluster", counted_row, counted_configs(calls, 8, 0.0), ("i",))
    store = RowStore(tmp_path / "torn_cluster.jsonl")
    for i in range(3):
        store_row(store, sweep, i)
    with open(store.path, "ab") as f:
        f.write(line_bytes(sweep, 3, tmp_path)[:17])
    result = run_sweep(sweep, store, client, stream=QUIET)
    assert result.complete and result.torn_lines == [4]
    assert sorted(r["i"] for r in result.rows) == list(range(8))
    assert [len(calls_of(calls, i)) for i in range(8)] == [0, 0, 0, 1, 1, 1, 1, 1]
    assert_every_config_stored_once(sweep, store)


# ------------------------------------------------------------------------------------------------------------
# configurations that keep failing
# ------------------------------------------------------------------------------------------------------------


def read_failures(path) -> list[dict]:
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def test_always_raising_config_is_listed_after_its_retries(client, tmp_path):
    calls = _folder(tmp_path / "calls")
    configs = [dict(i=i, bad=[2, 5], calls=str(calls)) for i in range(9)]
    sweep = Sweep("raising", raising_row, configs, ("i",), retries=2)
    store = RowStore(tmp_path / "raising.jsonl")
    failures_csv = tmp_path / "raising.failures.csv"
    result = run_sweep(sweep, store, client, failures_path=failures_csv, stream=QUIET)
    assert sorted(c["i"] for c, _ in result.failures) == [2, 5]
    assert [r["i"] for r in result.rows] == [0, 1, 3, 4, 6, 7, 8]
    assert [len(calls_of(calls, i)) for i in range(9)] == [1, 1, 3, 1, 1, 3, 1, 1, 1]  # 1 run + 2 retries
    listed = read_failures(failures_csv)
    assert sorted(int(r["i"]) for r in listed) == [2, 5]
    assert all(f"configuration {r['i']} always fails" in r["error"] and "ValueError" in r["error"] for r in listed)
    # rerun: only the failing configurations are tried again (and fail again); the others are resumed
    again = run_sweep(sweep, store, client, failures_path=failures_csv, stream=QUIET)
    assert again.computed == [] and sorted(c["i"] for c, _ in again.failures) == [2, 5]
    assert [len(calls_of(calls, i)) for i in range(9)] == [1, 1, 6, 1, 1, 6, 1, 1, 1]
    assert sorted(int(r["i"]) for r in read_failures(failures_csv)) == [2, 5]
    assert_every_config_stored_once(Sweep("good", raising_row, [c for c in configs if c["i"] not in (2, 5)],
                                          ("i",)), store)


def test_config_that_kills_its_worker_is_listed_and_the_others_complete(tmp_path):
    """On a scheduler that gives up on a task at the first death of its worker (allowed-failures = 0, the worst
    case), so that every task queued on the poisoned worker ends in KilledWorker with it: only the configuration
    that kills its worker is listed (run once, then once more alone), every other one completes."""
    cluster = Cluster(tmp_path / "cluster", n_workers=2,
                      env={"DASK_DISTRIBUTED__SCHEDULER__ALLOWED_FAILURES": str(ALLOWED_FAILURES)})
    try:
        calls = _folder(tmp_path / "calls")
        configs = [dict(i=i, poison=4, sleep=0.05, calls=str(calls)) for i in range(12)]
        sweep = Sweep("poison", worker_killing_row, configs, ("i",))
        store = RowStore(tmp_path / "poison.jsonl")
        failures_csv = tmp_path / "poison.failures.csv"
        with cluster.client() as client:
            result = run_sweep(sweep, store, client, failures_path=failures_csv, stream=QUIET)
        assert [c["i"] for c, _ in result.failures] == [4]
        assert "KilledWorker" in result.failures[0][1] and "run alone" in result.failures[0][1]
        assert len(calls_of(calls, 4)) == 2 * (ALLOWED_FAILURES + 1)
        assert [r["i"] for r in result.rows] == [i for i in range(12) if i != 4]
        assert [int(r["i"]) for r in read_failures(failures_csv)] == [4]
        assert_every_config_stored_once(Sweep("good", worker_killing_row, [c for c in configs if c["i"] != 4],
                                              ("i",)), store)
        cluster.wait_for_workers(2)  # the nannies brought the workers back
    finally:
        cluster.close()


def test_unstorable_rows_are_failures_and_nothing_of_them_is_written(tmp_path):
    """A task that returns something else than a dict, or a row JSON cannot hold: a failure of that
    configuration (nothing appended for it), the sweep goes on."""
    sweep = Sweep("unstorable", _odd_row, [dict(i=i) for i in range(5)], ("i",), retries=0)
    store = RowStore(tmp_path / "unstorable.jsonl")
    result = run_sweep(sweep, store, failures_path=tmp_path / "unstorable.failures.csv", stream=QUIET)
    assert sorted(c["i"] for c, _ in result.failures) == [1, 3]
    assert [r["i"] for r in result.rows] == [0, 2, 4]
    assert sorted(r["i"] for r in stored_lines(store)) == [0, 2, 4] and store.torn_lines == []
    assert sorted(int(r["i"]) for r in read_failures(tmp_path / "unstorable.failures.csv")) == [1, 3]


def _odd_row(cfg: dict):
    if cfg["i"] == 1:
        return [cfg["i"]]
    if cfg["i"] == 3:
        return {"value": object()}
    return {"square": cfg["i"] ** 2}


def test_rows_without_the_key_fields_are_not_resumed(tmp_path):
    """A stored row of the same version but without a key field (the sweep's key changed, the version did not):
    not a row of this sweep; its configurations run, nothing crashes."""
    sweep = Sweep("rekeyed", _odd_row, [dict(i=i) for i in (0, 2)], ("i",))
    store = RowStore(tmp_path / "rekeyed.jsonl")
    store.append({"j": 0, "square": -1})
    result = run_sweep(sweep, store, stream=QUIET)
    assert result.complete and result.resumed == [] and sorted(result.computed) == ["[0]", "[2]"]
    assert [r["square"] for r in result.rows] == [0, 4]


# ------------------------------------------------------------------------------------------------------------
# workers compiling the same kernels at once
# ------------------------------------------------------------------------------------------------------------


def compile_in_processes(count: int, cache) -> list[tuple[dict, str]]:
    env = subprocess_environment({"NUMBA_CACHE_DIR": str(cache), "COLLDET_COMPILE_NOTICE": "1"})
    procs = [subprocess.Popen([sys.executable, "-m", "properties.sweep_cluster", "compile"], stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, env=env, cwd=str(ROOT), text=True) for _ in range(count)]
    done = []
    for proc in procs:
        out, err = proc.communicate(timeout=600)
        assert proc.returncode == 0, err
        done.append((json.loads(out), err))
    return done


def test_concurrent_cold_compilation_leaves_a_sound_cache(tmp_path):
    cache = tmp_path / "numba"
    cold = compile_in_processes(2, cache)
    answers = {out["digest"] for out, _ in cold}
    assert len(answers) == 1, "processes compiling at once disagree"
    assert all(out["pairs"][0] > 0 and out["pairs"][1] > 0 for out, _ in cold)
    assert all(out["compiled"] for out, _ in cold), "a cold process compiled nothing: the cache was not empty"
    assert all(err.count("colldet: compiling the engine's kernels") == 1 for _, err in cold)
    (warm, err), = compile_in_processes(1, cache)
    assert warm["compiled"] == [], f"the next process recompiled {warm['compiled']}: the cache is not sound"
    assert err == ""  # no compile notice: every kernel came from the cache
    assert warm["digest"] in answers
    # one folder for all (the engine's, under NUMBA_CACHE_DIR), holding numba's index files
    assert {out["cache_dir"] for out, _ in [*cold, (warm, err)]} == {warm["cache_dir"]}
    assert warm["cache_dir"].startswith(str(cache) + os.sep)
    assert any(name.endswith(".nbi") for _, _, files in os.walk(cache) for name in files)
