"""``colldet warmup --jobs N``: the tasks of the warm-up dealt into balanced groups, one process each, all compiling
into one kernel cache.

- ``task_groups(jobs)`` is a partition of the tasks into at most ``jobs`` non-empty groups, each in task order, and
  its largest group is within Graham's bound of list scheduling: the mean load plus (1 − 1/m) of the largest task.
- End to end: ``colldet warmup --jobs 2`` on an empty cache succeeds, and a fresh process then runs the whole warm-up
  in itself without compiling a kernel of the engine (the compile notice, printed only when one compiles, stays
  silent). It compiles every kernel (several CPU minutes, more than CI's budget for one property): marked ``soak``
  and run only by the soak environment (``SOAK=long``, ``tox -e soak``).
"""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from engine.warmup import WARMUP_TASKS, task_groups

ROOT = Path(__file__).resolve().parent.parent


@given(st.integers(1, 2 * len(WARMUP_TASKS)))
def test_task_groups_partition_the_tasks_in_balanced_groups(jobs):
    groups = task_groups(jobs)
    assert 1 <= len(groups) <= jobs and all(groups)
    assert sorted(t for g in groups for t in g) == list(range(len(WARMUP_TASKS)))
    assert all(g == sorted(g) for g in groups)
    cost = [task[3] for task in WARMUP_TASKS]
    m = len(groups)
    assert max(sum(cost[t] for t in g) for g in groups) <= sum(cost) / m + (1.0 - 1.0 / m) * max(cost) + 1e-9


def test_one_job_is_one_group_in_task_order():
    assert task_groups(1) == [list(range(len(WARMUP_TASKS)))]


def _colldet(args, cache, notice="0"):
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache), "COLLDET_COMPILE_NOTICE": notice,
           "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))}
    return subprocess.run([sys.executable, "-m", "engine", *args], capture_output=True, text=True, env=env,
                          cwd=ROOT, timeout=900)


@pytest.mark.soak
@pytest.mark.skipif(os.environ.get("SOAK", "").lower() != "long",
                    reason="compiles every kernel (CPU minutes): run by the soak environment (SOAK=long)")
def test_parallel_warmup_leaves_a_cache_that_needs_no_compilation(tmp_path):
    done = _colldet(["warmup", "--jobs", "2", "--no-progress"], tmp_path)
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("every kernel is compiled and cached (")
    again = _colldet(["warmup", "--jobs", "1", "--no-progress"], tmp_path, notice="1")
    assert again.returncode == 0, again.stderr
    assert "compiling the engine's kernels" not in again.stderr, again.stderr
