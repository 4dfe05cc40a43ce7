"""Where the cold start goes: the compile time of every engine kernel during ``engine.warmup.warm_up()``.

    python -m bench.compile_times [--top 30]

runs the warm-up in a fresh process with an empty kernel cache and prints, per kernel, how many type
specialisations were compiled and the seconds spent compiling it (its own time: the nested compilations of the
kernels it calls are counted for them, not for it), most expensive first, then the total.
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
            stack.append([event.data["dispatcher"], time.perf_counter(), 0.0])

        def on_end(self, event):
            dispatcher, start, nested = stack.pop()
            spent = time.perf_counter() - start
            if stack:
                stack[-1][2] += spent
            name = f"{dispatcher.py_func.__module__}.{dispatcher.py_func.__qualname__}"
            records.append((name, spent - nested))

    ev.register("numba:compile", Timer())
    from engine.warmup import warm_up
    total = warm_up(progress=False)
    json.dump({"total": total, "records": records}, sys.stdout)
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
    args = parser.parse_args(argv)
    data = measure()
    seconds, count = defaultdict(float), defaultdict(int)
    for name, spent in data["records"]:
        seconds[name] += spent
        count[name] += 1
    engine_total = sum(s for n, s in seconds.items() if n.startswith("engine."))
    print(f"warm-up: {data['total']:.1f} s wall; engine kernels compiled: {sum(count.values())} specialisations of "
          f"{len(count)} kernels, {engine_total:.1f} s compiling")
    print(f"{'seconds':>8} {'specs':>5}  kernel")
    for name in sorted(seconds, key=seconds.get, reverse=True)[: args.top]:
        print(f"{seconds[name]:8.2f} {count[name]:5d}  {name}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
