"""Where the cold start goes: the compile time of every engine kernel during ``engine.warmup.warm_up()``.

    python -m bench.compile_times [--top 30] [--signatures NAME]

runs the warm-up in a fresh process with an empty kernel cache and prints, per kernel, how many type
specialisations were compiled and the CPU seconds spent compiling it (its own time: the nested compilations of the
kernels it calls are counted for them, not for it), most expensive first, then the totals (wall and CPU seconds
of the whole warm-up; CPU time is the figure to compare on a shared machine). ``--signatures NAME`` also lists
the argument types of every specialisation of the kernels compiled more than once whose name contains NAME: such a
kernel is called with different array layouts (``C`` / ``A``), ranks, read-only arrays or literal constants
(numba compiles a kernel once per distinct constant passed straight to it, e.g. ``Literal[int](128)``).
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import textwrap
from collections import defaultdict

_PROBE = textwrap.dedent("""
    import json, sys, time
    import numba.core.event as ev

    records, stack = [], []

    class Timer(ev.Listener):
        def on_start(self, event):
            stack.append([event.data["dispatcher"], time.process_time(), 0.0, event.data["args"]])

        def on_end(self, event):
            dispatcher, start, nested, args = stack.pop()
            spent = time.process_time() - start
            if stack:
                stack[-1][2] += spent
            name = f"{dispatcher.py_func.__module__}.{dispatcher.py_func.__qualname__}"
            records.append((name, spent - nested, str(args)))

    ev.register("numba:compile", Timer())
    from engine.warmup import warm_up
    cpu = time.process_time()
    total = warm_up(progress=False)
    json.dump({"total": total, "cpu": time.process_time() - cpu, "records": records}, sys.stdout)
""")


def measure() -> dict:
    """Run the warm-up in a fresh interpreter with an empty cache; returns its timing records."""
    with tempfile.TemporaryDirectory() as cache:
        env = {**os.environ, "NUMBA_CACHE_DIR": cache, "COLLDET_COMPILE_NOTICE": "0"}
        done = subprocess.run([sys.executable, "-c", _PROBE], capture_output=True, text=True, env=env, check=True)
    return json.loads(done.stdout)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench.compile_times", description=__doc__.split("\n\n")[0])
    parser.add_argument("--top", type=int, default=30, help="how many kernels to list (default 30)")
    parser.add_argument("--signatures", metavar="NAME", default=None,
                        help="the argument types of each specialisation of the kernels compiled more than once whose "
                             "name holds NAME")
    args = parser.parse_args(argv)
    data = measure()
    seconds, signatures = defaultdict(float), defaultdict(list)
    for name, spent, types in data["records"]:
        seconds[name] += spent
        signatures[name].append(types)
    engine = [n for n in seconds if n.startswith("engine.")]
    print(f"warm-up: {data['total']:.1f} s wall, {data['cpu']:.1f} s CPU; engine kernels compiled: "
          f"{sum(len(signatures[n]) for n in engine)} specialisations of {len(engine)} kernels, "
          f"{sum(seconds[n] for n in engine):.1f} s CPU compiling")
    print(f"{'CPU s':>8} {'specs':>5}  kernel")
    for name in sorted(seconds, key=seconds.get, reverse=True)[: args.top]:
        print(f"{seconds[name]:8.2f} {len(signatures[name]):5d}  {name}")
    if args.signatures:
        for name in sorted(n for n in seconds if args.signatures in n and len(signatures[n]) > 1):
            print(f"\n{name}:")
            for types in signatures[name]:
                print(f"    {types}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
