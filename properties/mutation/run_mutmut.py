"""Mutation testing of the engine's kernels with mutmut 3 (``tox -e mutation``; method in properties/MUTATION.md).

    python3 properties/mutation/run_mutmut.py [AREA ...] [--sample K] [--only GLOB ...] [--max-children N]
        [--workdir DIR] [--keep]

AREA is one of properties/mutation/areas.py (dynamics, broadphase, gas, narrowphase, bounding, world; default:
all six, each on its own default sample, ``areas.py``'s ``sample``). For each area the driver

1. copies ``engine/``, ``properties/`` and ``pyproject.toml`` to a scratch directory outside the repository
   (``--workdir``, default ``$TMPDIR/engine-mutation``), so that mutmut's ``mutants/`` never lands in the repo;
2. runs mutmut 3 there with ``NUMBA_DISABLE_JIT=1`` and ``HYPOTHESIS_PROFILE=mutation``, its configuration set
   here (the area's modules, the area's property files, the pytest plugin that caps max_examples), and two
   patches of mutmut's mutation filter:
   - functions decorated with the engine's ``njit`` (bare or called) or the gas's ``state_kernel`` are mutated:
     mutmut 3.8 skips every decorated function but ``staticmethod``/``classmethod``. With the JIT disabled
     both return the trampoline unchanged, so a kernel that calls another kernel goes through its trampoline
     like plain Python;
   - ``raise`` statements are not mutated (their message strings are text, not behaviour; the condition that
     guards a raise is still mutated);
   Only a deterministic 1-in-K sample of the mutants is run (K: ``--sample K``, else the area's default; chosen
   by a hash of the mutant's name, so the sample is the same in every run and unbiased with respect to cost or
   module); ``--sample 1`` runs every mutant; ``--only GLOB ...`` narrows the mutated modules to those of the
   area that match (to re-measure the files changed since an area's last run; the tests are the area's own);
3. prints killed / total per area and the survivors, and writes them as JSON (``--json``).

``--inner`` is the mode the driver runs itself in (inside the scratch copy): it patches mutmut and hands the
remaining arguments to mutmut's command line. This file is not imported by the property suite (pytest collects
``test_*.py`` only) and does not import ``properties`` or ``engine`` itself (mutmut must import the mutated copy).
"""
from __future__ import annotations

import argparse
import hashlib
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

DEFAULT_AREAS = ["dynamics", "broadphase", "bounding", "gas", "narrowphase", "world"]
#: the engine's kernel decorators: ``njit`` (engine/_config.py) and the gas's ``state_kernel`` (engine/gas/kernels.py,
#: njit with two more options); with the JIT disabled both return the function they decorate
KERNEL_DECORATORS = ("njit", "state_kernel")
REPO = Path(__file__).resolve().parents[2]


# --------------------------------------------------------------------------------------------- inner mode
def _patch_mutmut(spec: dict) -> None:
    import libcst as cst
    import mutmut.configuration as configuration
    from mutmut.mutation import file_mutation

    load_config = configuration._load_config

    def load_area_config():
        cfg = load_config()
        cfg.source_paths = [Path("engine")]
        cfg.resolved_mutated_source_paths = [Path.cwd().resolve() / "mutants" / "engine"]
        cfg.only_mutate = list(spec["mutate"])
        cfg.do_not_mutate = list(spec.get("skip", []))
        cfg.also_copy = [*cfg.also_copy, Path("properties")]
        cfg.pytest_add_cli_args = ["-p", "properties.mutation.pytest_plugin", "-p", "no:cacheprovider",
                                   "-m", "not large"] + [a for node in spec["deselect"] for a in ("--deselect", node)]
        cfg.pytest_add_cli_args_test_selection = list(spec["tests"])
        cfg.use_git_change_detection = False
        # a mutant that makes a test loop forever is stopped at its CPU-time limit, (estimate + constant) x
        # multiplier x 2 in mutmut: 15 x 2 = 30 times the clean estimate costs up to an hour per hung
        # event-loop mutant, so the limit is 8 x the estimate + 80 s (a mutant that slow is killed: "timeout")
        cfg.timeout_multiplier = 4.0
        cfg.timeout_constant = 10.0
        return cfg

    configuration._guess_source_paths = lambda: ["engine"]
    configuration._load_config = load_area_config
    configuration.reset_config()

    def is_njit(decorator) -> bool:
        if isinstance(decorator, cst.Call):
            decorator = decorator.func
        return isinstance(decorator, cst.Name) and decorator.value in KERNEL_DECORATORS

    skip = file_mutation.MutationVisitor._skip_node_and_children

    def skip_node_and_children(self, node) -> bool:
        if isinstance(node, cst.Raise):
            return True
        if isinstance(node, cst.FunctionDef) and node.decorators and all(is_njit(d.decorator) for d in node.decorators):
            # the checks mutmut makes on an undecorated function (pragma, never-mutate names), then mutate it
            position = self.get_metadata(file_mutation.PositionProvider, node, None)
            if position and position.start.line in self._ignored_node_lines:
                self.ignored_functions.add(node.name.value)
                return True
            return node.name.value in file_mutation.NEVER_MUTATE_FUNCTION_NAMES
        return skip(self, node)

    file_mutation.MutationVisitor._skip_node_and_children = skip_node_and_children

    sample = int(spec.get("sample", 1))
    if sample > 1:
        import mutmut.__main__ as mutmut_main

        collect = mutmut_main.collect_source_file_mutation_data

        def collect_sample(*, mutant_names):
            mutants, by_path = collect(mutant_names=mutant_names)
            return [item for item in mutants if in_sample(item[1], sample)], by_path

        mutmut_main.collect_source_file_mutation_data = collect_sample


def in_sample(mutant_name: str, sample: int) -> bool:
    """Deterministic 1-in-``sample`` choice of a mutant, by a hash of its name (independent of run and order)."""
    return int(hashlib.sha256(mutant_name.encode()).hexdigest(), 16) % sample == 0


def _inner(argv: list[str]) -> None:
    spec = json.loads(os.environ["ENGINE_MUTATION_SPEC"])
    _patch_mutmut(spec)
    from mutmut.__main__ import cli

    cli.main(args=argv, prog_name="mutmut", standalone_mode=True)


# --------------------------------------------------------------------------------------------- outer mode
def _areas() -> tuple[dict, dict]:
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import areas

    return areas.AREAS, areas.DESELECT


def _copy_project(dest: Path) -> None:
    if dest.exists():
        shutil.rmtree(dest)
    dest.mkdir(parents=True)
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc", ".hypothesis", ".pytest_cache")
    for name in ("engine", "properties"):
        shutil.copytree(REPO / name, dest / name, ignore=ignore)
    shutil.copy2(REPO / "pyproject.toml", dest / "pyproject.toml")


STATUS = re.compile(r"^\s*(\S+): (.+?)\s*$")


def run_area(area: str, spec: dict, workdir: Path, max_children: int, keep: bool) -> dict:
    dest = workdir / area
    _copy_project(dest)
    env = {**os.environ, "NUMBA_DISABLE_JIT": "1", "HYPOTHESIS_PROFILE": "mutation",
           "ENGINE_MUTATION_SPEC": json.dumps(spec)}
    me = [sys.executable, str(dest / "properties" / "mutation" / "run_mutmut.py"), "--inner"]
    start = time.monotonic()
    subprocess.run([*me, "run", "--max-children", str(max_children)], cwd=dest, env=env, check=False)
    wall = time.monotonic() - start
    out = subprocess.run([*me, "results", "--all", "true"], cwd=dest, env=env, check=True,
                         capture_output=True, text=True).stdout
    statuses, mutants = {}, 0
    for line in out.splitlines():
        match = STATUS.match(line)
        if match and match.group(1).startswith("engine."):
            mutants += 1
            if match.group(2) != "not checked":
                statuses[match.group(1)] = match.group(2)
    # a mutant that makes a test hang is detected too (mutmut stops it at its CPU-time limit: "timeout")
    killed = sorted(k for k, s in statuses.items() if s in ("killed", "timeout"))
    result = {
        "area": area,
        "mutants": mutants,  # every mutant of the area, sampled or not
        "total": len(statuses),
        "killed": len(killed),
        "wall_seconds": round(wall),
        "by_status": {s: sorted(k for k, v in statuses.items() if v == s) for s in sorted(set(statuses.values()))},
    }
    if not keep:
        shutil.rmtree(dest)
    return result


def _narrowed(area: str, spec: dict, only: list[str], parser: argparse.ArgumentParser) -> list[str]:
    """The globs of ``--only`` that name files of ``area`` (and not of its ``skip``); any other is an error."""
    for glob in only:
        files = [f for f in REPO.glob(glob) if f.is_file()]
        inside = [f for f in files
                  if any(f.match(str(REPO / m)) for m in spec["mutate"])
                  and not any(f.match(str(REPO / m)) for m in spec.get("skip", []))]
        if not files or len(inside) != len(files):
            parser.error(f"--only {glob}: no file, or a file outside the mutated modules of area {area}")
    return list(only)


def main() -> None:
    if len(sys.argv) > 1 and sys.argv[1] == "--inner":
        _inner(sys.argv[2:])
        return
    all_areas, deselect = _areas()
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("areas", nargs="*", default=DEFAULT_AREAS, choices=sorted(all_areas), metavar="AREA")
    parser.add_argument("--max-children", type=int, default=1, help="parallel mutants (mutmut --max-children)")
    parser.add_argument("--workdir", type=Path, default=Path(tempfile.gettempdir()) / "engine-mutation")
    parser.add_argument("--keep", action="store_true", help="keep the scratch copy (mutmut show/browse there)")
    parser.add_argument("--json", type=Path, help="write the results here")
    parser.add_argument("--sample", type=int, default=None, metavar="K",
                        help="run a deterministic 1-in-K sample of the mutants (by a hash of their names); "
                             "default: each area's own (areas.py); 1: every mutant")
    parser.add_argument("--only", nargs="+", default=None, metavar="GLOB",
                        help="mutate only the area's modules matching these globs (e.g. engine/gas/events.py)")
    args = parser.parse_args()
    if args.sample is not None and args.sample < 1:
        parser.error("--sample must be >= 1")

    results = []
    for area in args.areas or DEFAULT_AREAS:
        sample = args.sample if args.sample is not None else all_areas[area].get("sample", 1)
        spec = {**all_areas[area], "deselect": sorted(deselect), "sample": sample}
        spec["tests"] = [t for t in spec["tests"] if (REPO / t).exists()]
        if args.only:
            spec["mutate"] = _narrowed(area, spec, args.only, parser)
        result = run_area(area, spec, args.workdir, args.max_children, args.keep)
        results.append({**result, "sample": sample})
    print("\narea         killed / total   score   wall   sample   (killed includes timeouts)")
    for r in results:
        score = 100.0 * r["killed"] / r["total"] if r["total"] else float("nan")
        print(f"{r['area']:<12} {r['killed']:>6} / {r['total']:<6} {score:6.1f}%  {r['wall_seconds']:>5} s  "
              f"1 in {r['sample']}")
        for status, names in r["by_status"].items():
            if status not in ("killed", "timeout"):
                print(f"  {status}: {len(names)}")
                for name in names:
                    print(f"    {name}")
    killed, total = sum(r["killed"] for r in results), sum(r["total"] for r in results)
    if total:
        print(f"{'overall':<12} {killed:>6} / {total:<6} {100.0 * killed / total:6.1f}%")
    if args.json:
        args.json.write_text(json.dumps(results, indent=1) + "\n")


if __name__ == "__main__":
    main()
