"""The ``colldet`` command: what it prints, and how it fails.

- ``--version`` gives the installed distribution's version, also through ``python -m engine``;
- a missing file, a directory where a file is expected, an unwritable ``--out``: one line on stderr naming the
  argument, a non-zero exit status, and no work done (nothing on stdout: the check comes before the simulation);
- results are printed before the files are written.
"""
from __future__ import annotations

import json
import subprocess
import sys
from importlib.metadata import version

import pytest

from engine.cli import main

EXAMPLES = "examples/contact"


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_version_is_the_distribution_metadata(capsys):
    with pytest.raises(SystemExit) as stop:
        main(["--version"])
    assert stop.value.code == 0
    assert capsys.readouterr().out.strip() == f"colldet {version('colldet')}"


def test_python_dash_m_engine_is_the_same_command():
    done = subprocess.run([sys.executable, "-m", "engine", "--version"], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == f"colldet {version('colldet')}"


@pytest.mark.parametrize("argv", [
    ["contact", "missing_a.json", f"{EXAMPLES}/ground_box.json"],
    ["contact", EXAMPLES, f"{EXAMPLES}/ground_box.json"],
    ["hull", "no_such_cloud.csv"],
    ["bound", "examples"],
    ["decompose", "missing.csv"],
])
def test_unreadable_inputs_fail_in_one_line(capsys, argv):
    code, out, err = run(capsys, *argv)
    assert code == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and "error:" in err and "Traceback" not in err
    name = {"contact": "shape_a", "hull": "points", "bound": "points", "decompose": "polygon"}[argv[0]]
    assert name in err


@pytest.mark.parametrize("argv, name", [
    (["gas", "--n", "50", "--out", "no_such_folder/speeds.png"], "--out"),
    (["gas", "--n", "50", "--out", "."], "--out"),
    (["demo", "--out", "no_such_folder/demo.gif"], "--out"),
    (["demo", "--no-gif", "--png", "no_such_folder/frame.png"], "--png"),
    (["fall", "--out", "README.md"], "--out"),
])
def test_unwritable_outputs_fail_before_the_work(capsys, argv, name):
    code, out, err = run(capsys, *argv)
    assert code == 2
    assert out == ""  # nothing was simulated: the path is checked first
    assert len(err.strip().splitlines()) == 1 and name in err and "Traceback" not in err


def test_fall_prints_then_writes(capsys, tmp_path):
    code, out, err = run(capsys, "fall", "--height", "10", "--restitution", "0.8", "--out", str(tmp_path / "new"))
    assert code == 0
    lines = out.splitlines()
    assert lines[0].startswith("particle dropped from y = 10.0")
    assert lines[-1] == f"wrote {tmp_path / 'new' / 'fall_particle.csv'} and {tmp_path / 'new' / 'fall_particle.png'}"
    header, first = (tmp_path / "new" / "fall_particle.csv").read_text().splitlines()[:2]
    assert header == "t,y,v" and [float(x) for x in first.split(",")] == [0.0, 10.0, 0.0]
    assert (tmp_path / "new" / "fall_particle.png").read_bytes()[:4] == b"\x89PNG"


def test_hull_answers_in_json(capsys):
    code, out, _ = run(capsys, "hull", "examples/bounding/cloud.csv")
    assert code == 0 and {"vertices", "faces"} <= set(json.loads(out))


def test_sap_example_prints_the_slides_pairs(capsys):
    code, out, _ = run(capsys, "sap-example")
    assert code == 0 and "pairs" in out.lower()


def test_warmup_runs_every_area(capsys):
    from engine.warmup import WARMUP_STEPS

    assert [area for area, _ in WARMUP_STEPS] == ["falling bodies", "bounding volumes", "broad phase",
                                                  "narrow phase", "pipeline (World)", "gas"]
    code, out, err = run(capsys, "warmup", "--no-progress")
    assert code == 0 and out.startswith("every kernel is compiled and cached (") and err == ""
