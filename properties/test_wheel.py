"""The wheel a user installs works outside the checkout: built from this tree, installed with its dependencies in
a fresh virtual environment, it runs ``colldet --version`` and every README Python block from an empty folder
(the steps of ``bench/first_run.py``). Slow (an install and cold compilations): marked ``slow``; CI runs it."""
from __future__ import annotations

import subprocess
from importlib.metadata import version

import pytest

from bench.first_run import ROOT, clean_environment, first_run, python_blocks


@pytest.mark.slow
def test_wheel_in_a_fresh_venv_runs_the_readme(tmp_path):
    python, cold, warm = first_run(ROOT, tmp_path)
    assert len(cold) == len(python_blocks(ROOT / "README.md")) >= 6
    for run in cold + warm:
        assert run.returncode == 0, f"README block {run.index}:\n{run.stderr}"
    colldet = python.parent / "colldet"
    env = clean_environment()
    done = subprocess.run([str(colldet), "--version"], capture_output=True, text=True, check=True, cwd=tmp_path,
                          env=env)
    assert done.stdout.strip() == f"colldet {version('colldet')}"
    # the installed package is the wheel's, not this checkout's
    where = subprocess.run([str(python), "-c", "import engine; print(engine.__file__)"], capture_output=True,
                           text=True, check=True, cwd=tmp_path, env=env).stdout
    assert str(ROOT) not in where and "site-packages" in where
    files = subprocess.run([str(python), "-c", "from importlib.metadata import files; "
                            "print(sorted(str(f) for f in files('colldet')))"], capture_output=True, text=True,
                           check=True, cwd=tmp_path, env=env).stdout
    assert "engine/py.typed" in files and "LICENSE" in files
