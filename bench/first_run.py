"""A newcomer's first run, measured: a wheel of this checkout installed in a fresh virtual environment, README's
Python blocks run there one by one from an empty folder, cold (an empty kernel cache) then warm.

    python -m bench.first_run [--checkout PATH] [--keep DIR]

prints one row per README block: seconds cold, seconds warm, and whether it ran (exit status 0). The property
``properties/test_wheel.py`` runs the same steps and asserts that every block and ``colldet --version`` succeed.
"""
from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def python_blocks(readme: Path) -> list[str]:
    """README's fenced ```python blocks, in order."""
    return re.findall(r"^```python\n(.*?)^```", readme.read_text(), re.S | re.M)


def build_wheel(checkout: Path, out: Path) -> Path:
    """``pip wheel --no-deps`` of the checkout into ``out``; returns the wheel's path."""
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(out), str(checkout)],
                   check=True, capture_output=True, text=True)
    return next(out.glob("*.whl"))


def clean_environment() -> dict:
    """This process's environment without the variables that would let the checkout or its caches leak into
    the fresh environment (PYTHONPATH, PYTHONHOME, NUMBA_*)."""
    return {k: v for k, v in os.environ.items() if not k.startswith(("PYTHON", "NUMBA"))}


def fresh_venv(folder: Path, wheel: Path) -> Path:
    """A new virtual environment in ``folder`` with the wheel (and its dependencies, from the registry)."""
    subprocess.run([sys.executable, "-m", "venv", str(folder)], check=True, env=clean_environment())
    python = folder / "bin" / "python"
    subprocess.run([str(python), "-m", "pip", "install", "-q", str(wheel)], check=True, capture_output=True,
                   text=True, env=clean_environment(), cwd=folder)
    return python


@dataclass
class BlockRun:
    index: int
    seconds: float
    returncode: int
    stderr: str


def run_block(python: Path, code: str, index: int, workdir: Path, cache: Path) -> BlockRun:
    """Run one block as a script from ``workdir`` with the kernel cache in ``cache``."""
    script = workdir / f"block_{index}.py"
    script.write_text(code)
    env = {**clean_environment(), "NUMBA_CACHE_DIR": str(cache), "MPLBACKEND": "Agg"}
    start = time.perf_counter()
    done = subprocess.run([str(python), script.name], cwd=workdir, capture_output=True, text=True, env=env)
    return BlockRun(index, time.perf_counter() - start, done.returncode, done.stderr)


def first_run(checkout: Path, folder: Path) -> tuple[Path, list[BlockRun], list[BlockRun]]:
    """Wheel, venv, then every README block cold and warm. Returns (venv python, cold runs, warm runs)."""
    wheel = build_wheel(checkout, folder / "wheel")
    python = fresh_venv(folder / "venv", wheel)
    workdir = folder / "empty"
    workdir.mkdir()
    shutil.copytree(checkout / "examples", workdir / "examples")
    blocks = python_blocks(checkout / "README.md")
    cold = [run_block(python, b, i, workdir, folder / "cache") for i, b in enumerate(blocks)]
    warm = [run_block(python, b, i, workdir, folder / "cache") for i, b in enumerate(blocks)]
    return python, cold, warm


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench.first_run", description=__doc__.split("\n\n")[0])
    parser.add_argument("--checkout", type=Path, default=ROOT, help="the source tree to build (default: this one)")
    parser.add_argument("--keep", type=Path, default=None, help="work in this folder and keep it")
    args = parser.parse_args(argv)
    folder = args.keep or Path(tempfile.mkdtemp(prefix="first_run_"))
    folder.mkdir(parents=True, exist_ok=True)
    _, cold, warm = first_run(args.checkout.resolve(), folder)
    print("| README block | first line | cold (s) | warm (s) | ran |")
    print("|---:|---|---:|---:|---|")
    blocks = python_blocks(args.checkout / "README.md")
    for c, w in zip(cold, warm):
        first = next((line for line in blocks[c.index].splitlines() if line and not line.startswith("import")), "")
        ok = "yes" if c.returncode == 0 and w.returncode == 0 else f"no: {c.stderr.strip().splitlines()[-1:]}"
        print(f"| {c.index} | `{first[:60]}` | {c.seconds:.1f} | {w.seconds:.1f} | {ok} |")
    print(f"| all | | {sum(c.seconds for c in cold):.1f} | {sum(w.seconds for w in warm):.1f} | |")
    if args.keep is None:
        shutil.rmtree(folder, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
