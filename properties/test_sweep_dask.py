"""The report's sweeps on Dask distributed (bench/sweep.py): same rows as the serial run, durable rows, resume,
retried then reported failures.

Oracle: the serial run of the same pure functions in this process (``run_sweep(..., client=None)``), and the set
of configurations itself (every one stored exactly once). The clusters are real ``LocalCluster``s of two worker
processes; the worker kill is a real SIGKILL of a worker process.
"""
from __future__ import annotations

import json
import os
import signal
import time

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

pytest.importorskip("distributed")

from bench.sweep import SCHEDULER_ENV, RowStore, Sweep, run_sweep, scheduler_address, sweep_client  # noqa: E402

# ----------------------------------------------------------------------------------------------------------
# task functions: module level, so that workers import them by reference (PYTHONPATH holds the repository)
# ----------------------------------------------------------------------------------------------------------


def scene_row(cfg: dict) -> dict:
    """Deterministic: the pairs of a seeded box scene by one broad phase, and a tiny periodic gas run."""
    from engine import find_pairs, simulate_gas

    rng = np.random.default_rng(cfg["seed"])
    centre = rng.uniform(0.0, 10.0, size=(cfg["n"], 3))
    half = rng.uniform(0.0, 0.6, size=(cfg["n"], 3))
    pairs = find_pairs(centre - half, centre + half, method=cfg["method"])
    gas = simulate_gas(20, radius=0.4, box=5.0, boundary="periodic", t_equilibrate=0.0, t_measure=0.5, blocks=2,
                       seed=cfg["seed"])
    return {"pairs": int(pairs.shape[0]), "pair_checksum": int((pairs[:, 0] * cfg["n"] + pairs[:, 1]).sum()),
            "gas_collisions": int(gas.collisions), "gas_z_virial": float(gas.z_virial)}


def slow_row(cfg: dict) -> dict:
    time.sleep(cfg["sleep"])
    return {"square": cfg["i"] ** 2, "pid": os.getpid()}


def flaky_row(cfg: dict) -> dict:
    """Logs each attempt; fails for i == bad while the marker file exists."""
    with open(cfg["log"], "a") as f:
        f.write(f"{cfg['i']}\n")
    if cfg["i"] == cfg["bad"] and os.path.exists(cfg["marker"]):
        raise ValueError(f"configuration {cfg['i']} is broken")
    return {"square": cfg["i"] ** 2}


def square_row(cfg: dict) -> dict:
    return {"square": cfg["i"] ** 2, "half": cfg["i"] / 2}


class Interrupted(Exception):
    pass


# ----------------------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def client():
    with sweep_client(kind="physics", n_workers=2) as c:
        yield c


def _scene_sweep():
    configs = [dict(seed=s, n=n, method=m) for s in (1, 2) for n in (50, 300) for m in ("brute", "sap", "grid")]
    return Sweep("scenes", scene_row, configs, ("seed", "n", "method"))


def test_local_cluster_gives_the_serial_rows(client, tmp_path):
    sweep = _scene_sweep()
    serial = run_sweep(sweep, RowStore(tmp_path / "serial.jsonl"))
    distributed = run_sweep(sweep, RowStore(tmp_path / "dask.jsonl"), client)
    assert serial.complete and distributed.complete
    assert len(serial.rows) == len(sweep.configs)
    assert distributed.rows == serial.rows  # bit-identical floats: same seeds, same kernels
    # the broad phases agree with brute force on each scene, so the rows carry real work
    by_scene = {}
    for r in serial.rows:
        by_scene.setdefault((r["seed"], r["n"]), set()).add((r["pairs"], r["pair_checksum"]))
    assert all(len(v) == 1 for v in by_scene.values())
    assert any(r["pairs"] > 0 for r in serial.rows)
    # the stored file holds exactly these rows, one line each
    lines = [json.loads(x) for x in (tmp_path / "dask.jsonl").read_text().splitlines()]
    assert sorted(sweep.key(r) for r in lines) == sorted(sweep.key(c) for c in sweep.configs)


def test_interrupted_sweep_resumes_with_the_missing_configs_only(client, tmp_path):
    configs = [dict(i=i, sleep=0.05) for i in range(12)]
    sweep = Sweep("resume", slow_row, configs, ("i",))
    store = RowStore(tmp_path / "resume.jsonl")
    seen = []

    def interrupt(row):
        seen.append(row)
        if len(seen) == 4:
            raise Interrupted

    with pytest.raises(Interrupted):
        run_sweep(sweep, store, client, on_row=interrupt)
    kept = {sweep.key(r): r for r in store.read()}
    assert set(kept) == {sweep.key(r) for r in seen}  # every reported row is stored, nothing more
    again = run_sweep(sweep, store, client)
    assert sorted(again.resumed) == sorted(kept)
    assert sorted(again.computed) == sorted(set(sweep.key(c) for c in configs) - set(kept))
    assert [r["i"] for r in again.rows] == list(range(12))
    for r in again.rows:
        if sweep.key(r) in kept:
            assert r == {k: v for k, v in kept[sweep.key(r)].items() if k != "_version"}


def test_failing_task_is_retried_then_reported_and_rows_are_kept(client, tmp_path):
    marker = tmp_path / "broken"
    marker.write_text("")
    log = tmp_path / "attempts.log"
    configs = [dict(i=i, bad=3, log=str(log), marker=str(marker)) for i in range(8)]
    sweep = Sweep("flaky", flaky_row, configs, ("i",), retries=2)
    store = RowStore(tmp_path / "flaky.jsonl")
    failures_csv = tmp_path / "flaky.failures.csv"
    result = run_sweep(sweep, store, client, failures_path=failures_csv)
    assert [c["i"] for c, _ in result.failures] == [3]
    assert "configuration 3 is broken" in result.failures[0][1]
    attempts = log.read_text().split()
    assert attempts.count("3") == 3  # one run and two retries
    assert sorted(r["i"] for r in result.rows) == [0, 1, 2, 4, 5, 6, 7]
    assert "configuration 3 is broken" in failures_csv.read_text()
    # fixed: the rerun runs the failed configuration only, and the failure report goes away
    marker.unlink()
    log.write_text("")
    again = run_sweep(sweep, store, client, failures_path=failures_csv)
    assert again.complete and again.computed == [sweep.key(configs[3])]
    assert log.read_text().split() == ["3"]
    assert [r["i"] for r in again.rows] == list(range(8))
    assert not failures_csv.exists()


@settings(max_examples=50)
@given(stored=st.sets(st.integers(0, 9)), torn=st.booleans(), other_version=st.sets(st.integers(0, 9)))
def test_resume_runs_exactly_the_missing_configs(tmp_path_factory, stored, torn, other_version):
    """Serial store logic: pre-stored rows are reused, rows of another version and a torn last line are not."""
    configs = [dict(i=i) for i in range(10)]
    sweep = Sweep("squares", square_row, configs, ("i",), version="v2")
    store = RowStore(tmp_path_factory.mktemp("store") / "squares.jsonl")
    for i in sorted(other_version):
        store.append({"i": i, "square": -1, "half": -1.0}, version="v1")
    for i in sorted(stored):
        store.append({"i": i, **square_row({"i": i})}, version="v2")
    if torn:
        with open(store.path, "a") as f:
            f.write('{"i": 0, "squ')
    result = run_sweep(sweep, store)
    assert sorted(result.resumed) == sorted(sweep.key({"i": i}) for i in stored)
    assert sorted(result.computed) == sorted(sweep.key({"i": i}) for i in set(range(10)) - stored)
    assert result.rows == [{"i": i, **square_row({"i": i})} for i in range(10)]
    # what the next resume sees: every row, once, from the file (a torn line must not swallow the next row)
    again = sorted((r for r in store.read("v2")), key=lambda r: r["i"])
    assert [{k: v for k, v in r.items() if k != "_version"} for r in again] == result.rows


def test_scheduler_comes_from_the_option_then_the_environment(monkeypatch):
    monkeypatch.delenv(SCHEDULER_ENV, raising=False)
    assert scheduler_address(None) is None  # embedded LocalCluster
    monkeypatch.setenv(SCHEDULER_ENV, "tcp://cluster:8786")
    assert scheduler_address(None) == "tcp://cluster:8786"
    assert scheduler_address("tcp://other:8786") == "tcp://other:8786"  # --scheduler wins


def test_sweep_rejects_duplicate_keys_and_missing_fields():
    with pytest.raises(ValueError, match="share the key"):
        Sweep("dup", square_row, [dict(i=1), dict(i=1)], ("i",))
    with pytest.raises(ValueError, match="lacks the key fields"):
        Sweep("missing", square_row, [dict(j=1)], ("i",))
    with pytest.raises(ValueError, match="kind"):
        Sweep("kind", square_row, [dict(i=1)], ("i",), kind="fast")


def test_killing_a_worker_loses_no_completed_row(client, tmp_path):
    """Runs last on the shared cluster: its nanny restarts the killed worker."""
    configs = [dict(i=i, sleep=0.3) for i in range(16)]
    sweep = Sweep("kill", slow_row, configs, ("i",))
    store = RowStore(tmp_path / "kill.jsonl")
    snapshot, reported = {}, []
    pids = client.run(os.getpid)
    assert len(pids) == 2
    killed = []

    def kill_one(row):
        if killed:
            return
        reported.append(row)
        if len(reported) < 2:
            return
        # the rows reported so far must already be on disk when the worker dies
        snapshot.update({sweep.key(r): r for r in store.read()})
        os.kill(sorted(pids.values())[0], signal.SIGKILL)
        killed.append(row)

    result = run_sweep(sweep, store, client, on_row=kill_one)
    assert killed, "the kill never happened"
    assert {sweep.key(r) for r in reported} <= set(snapshot)  # reported rows were durable before the kill
    assert result.complete, result.failures
    assert [r["i"] for r in result.rows] == list(range(16))
    assert all(r["square"] == r["i"] ** 2 for r in result.rows)
    final = {sweep.key(r): r for r in store.read()}
    assert len(store.path.read_text().splitlines()) == len(configs)  # every config stored exactly once
    for key, row in snapshot.items():
        assert final[key] == row
