"""README.md's code runs as pasted.

- every ```python block runs on its own, in a fresh namespace (a user pastes one block into a new interpreter);
- every ``colldet ...`` line of a shell block runs and exits 0 (from an empty folder holding only the examples);
  install and tox lines are left to CI itself, which runs them;
- every ``>>>`` example of an engine docstring (the API reference's Examples sections) gives the output it shows.
``properties/test_wheel.py`` runs the same blocks against a wheel installed in a fresh virtual environment.
"""
from __future__ import annotations

import os
import re
import shlex
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"


def code_blocks(text: str, language: str) -> list[str]:
    """The bodies of the fenced blocks of ``language`` ("python", or "" for unlabelled shell blocks)."""
    return [m.group(2) for m in re.finditer(r"^```([a-z]*)\n(.*?)^```", text, re.S | re.M) if m.group(1) == language]


def python_blocks() -> list[str]:
    return code_blocks(README.read_text(), "python")


def command_lines() -> list[str]:
    lines = []
    for block in code_blocks(README.read_text(), ""):
        for line in block.splitlines():
            command = line.split("#", 1)[0].strip()
            if command.startswith("colldet "):
                lines.append(command)
    return lines


def example_modules() -> list[str]:
    """The engine modules whose docstrings hold doctest examples."""
    names = []
    for path in sorted((ROOT / "engine").rglob("*.py")):
        if ">>> " in path.read_text():
            parts = path.relative_to(ROOT).with_suffix("").parts
            names.append(".".join(parts[:-1] if parts[-1] == "__init__" else parts))
    return names


@pytest.mark.parametrize("module", example_modules())
def test_docstring_examples_run(module):
    import doctest
    import importlib
    import io

    finder = doctest.DocTestFinder()
    runner = doctest.DocTestRunner(optionflags=doctest.NORMALIZE_WHITESPACE)
    report = io.StringIO()
    for test in finder.find(importlib.import_module(module), module):
        runner.run(test, out=report.write)
    result = runner.summarize(verbose=False)
    assert result.attempted > 0, f"{module}: no example found"
    assert result.failed == 0, report.getvalue()


def test_readme_has_the_blocks_it_promises():
    assert len(python_blocks()) >= 6
    assert any(c.startswith("colldet fall") for c in command_lines())


@pytest.mark.parametrize("index", range(len(python_blocks())))
def test_python_block_runs_as_pasted(index, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "examples").symlink_to(ROOT / "examples")
    exec(compile(python_blocks()[index], f"README.md python block {index}", "exec"), {"__name__": "__main__"})


@pytest.mark.parametrize("command", command_lines())
def test_command_line_runs(command, tmp_path, monkeypatch, capsys):
    from engine.cli import main

    monkeypatch.chdir(tmp_path)
    (tmp_path / "examples").symlink_to(ROOT / "examples")
    argv = shlex.split(command)[1:]
    if argv[0] == "gas":  # the README's full-size run, shortened: the same code path in a tenth of the time
        argv += ["--t-measure", "2", "--t-equilibrate", "0.5"]
    if argv[0] == "demo":
        argv += ["--frames", "12", "--png-frame", "5"]
    try:
        code = main(argv)
    except SystemExit as stop:  # --version, --help
        code = stop.code
    assert code == 0, capsys.readouterr().err
    produced = {p.name for p in tmp_path.iterdir()} - {"examples"}
    assert all(os.path.getsize(tmp_path / name) > 0 for name in produced)
