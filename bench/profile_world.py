"""Where a World frame of the static-level benchmark goes: its stage timers and a cProfile of its frames.

    python -m bench.profile_world [--static 5000] [--moving 500] [--frames 20] [--top 25]

Builds ``engine.workloads.static_level(static, moving)`` twice — the level added ``static=True`` and the moving
bodies alone — runs ``WARMUP`` untimed frames on each (as the benchmark does), then ``frames`` frames (update +
contacts) and prints, for each, the median of ``world.stats.seconds`` per stage (wall clock) and of the whole
frame, the work counts of the last frame, and the functions of the level world's frames that take the most
time (cProfile, cumulative).
"""
from __future__ import annotations

import argparse
import cProfile
import pstats
import time

import numpy as np

from bench.world_peers import EngineFrame
from engine.workloads import frame_motion, static_level

WARMUP = 40
STAGES = ("upload", "broad", "narrow", "contacts")


def stage_medians(frame: EngineFrame, poses) -> dict:
    """The median over ``poses`` of each stage timer of ``world.stats.seconds`` and of the frame, in seconds."""
    rows = []
    for centers, quats in poses:
        t0 = time.perf_counter()
        frame.upload(centers, quats)
        frame.detect()
        rows.append([frame.world.stats.seconds.get(k, 0.0) for k in STAGES] + [time.perf_counter() - t0])
    return dict(zip((*STAGES, "frame"), np.median(np.array(rows), axis=0).tolist()))


def _counts(frame: EngineFrame) -> str:
    s = frame.world.stats
    return (f"candidate pairs {s.candidate_pairs:,} (static {s.static_pairs:,}), narrow tests {s.narrow_tests:,}, "
            f"touching {s.overlapping:,}, contact points {s.contacts:,}, by kind {s.groups}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench.profile_world", description=__doc__.split("\n")[0])
    parser.add_argument("--static", type=int, default=5_000, help="static boxes of the level")
    parser.add_argument("--moving", type=int, default=500, help="moving bodies")
    parser.add_argument("--frames", type=int, default=20, help="frames timed and profiled")
    parser.add_argument("--top", type=int, default=25, help="functions listed")
    args = parser.parse_args(argv)
    scene, level = static_level(args.static, args.moving)
    poses = frame_motion(scene, WARMUP + 2 * args.frames)
    for name, lvl in (("level static", level), ("moving bodies alone", None)):
        frame = EngineFrame(scene, level=lvl)
        for centers, quats in poses[:WARMUP]:
            frame.upload(centers, quats)
            frame.detect()
        medians = stage_medians(frame, poses[WARMUP:WARMUP + args.frames])
        print(f"{name}: " + ", ".join(f"{k} {1e3 * v:.3f} ms" for k, v in medians.items()))
        print(f"  {_counts(frame)}")
        if lvl is not None:
            profiler = cProfile.Profile()
            profiler.enable()
            for centers, quats in poses[WARMUP + args.frames:]:
                frame.upload(centers, quats)
                frame.detect()
            profiler.disable()
            pstats.Stats(profiler).sort_stats("cumulative").print_stats(args.top)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
