"""Compile every kernel ahead of time: ``colldet warmup`` (or ``engine.warmup.warm_up()``).

The engine's kernels are compiled by numba on their first call (tens of seconds in all on a cold machine) and
cached on disk; a later process loads them in milliseconds. ``warm_up`` calls every public entry point once on
small inputs, area by area, so that an installation (a Docker image build, a CI cache, a lab machine) starts warm.

The work is a list of independent tasks (``WARMUP_TASKS``), each with its compile cost measured on a cold cache.
With ``jobs`` > 1 they are dealt into that many groups of about equal cost (the longest first, each to the group
that has the least so far) and each group runs in its own process, all writing the one kernel cache (numba
writes each cache file whole, so processes compiling into one cache at once all succeed).
"""
from __future__ import annotations

import contextlib
import os
import queue
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

__all__ = ["WARMUP_STEPS", "WARMUP_TASKS", "warm_up", "task_groups"]


def _dynamics() -> None:
    from engine import bisect, drop_cube, drop_particle, rk4_step

    rk4_step(lambda t, y: -y, 0.0, [1.0, 2.0], 0.1)
    bisect(lambda x: x**3 - 2.0, 0.0, 2.0, 1e-6)
    drop_particle(1.0, drag=0.2, restitution=0.8, t_end=1.0)
    drop_cube(1.0)


def _cloud() -> np.ndarray:
    return np.random.default_rng(0).normal(size=(24, 3))


def _volumes() -> None:
    from engine import bounding

    pts = _cloud()
    bounding.describe_bounding_volumes(pts)
    bounding.describe_bounding_volumes(pts[:, :2])
    for k in (2, 3, 4):
        bounding.circumsphere(pts[:k])


def _hulls() -> None:
    from engine import bounding

    pts = _cloud()
    bounding.describe_hull(pts)
    bounding.describe_hull(pts[:, :2])
    bounding.describe_decomposition(np.array([[0, 0], [4, 0], [4, 3], [2, 1], [0, 3.0]]))


def _boxes(*methods: str) -> Callable[[], None]:
    """``find_pairs`` by each of ``methods`` in 1, 2 and 3 dimensions."""
    def run() -> None:
        from engine import find_pairs

        rng = np.random.default_rng(1)
        for d in (1, 2, 3):
            lo = rng.uniform(0, 10, (40, d))
            for method in methods:
                find_pairs(lo, lo + 1.0, method)
    return run


def _spheres() -> None:
    from engine import BROAD_PHASES, sphere_pairs, sweep_intervals

    centres = np.random.default_rng(1).uniform(0, 10, (40, 3))
    for method in BROAD_PHASES:
        sphere_pairs(centres, 0.5, method)
    sweep_intervals([3.0, 7.7, 1.0], [7.0, 18.0, 8.0])


def _incremental() -> None:
    from engine.broadphase import DynamicAABBTree, IncrementalSAP

    lo = np.random.default_rng(1).uniform(0, 10, (40, 3))
    IncrementalSAP(lo, lo + 1.0).update(lo + 0.1, lo + 1.1)
    tree = DynamicAABBTree.from_boxes(lo, lo + 1.0)
    tree.update(lo + 0.1, lo + 1.1)
    tree.pairs()
    tree.query(lo[0], lo[0] + 2.0)
    tree.move(tree.insert(lo[1], lo[1] + 1.0), lo[1] + 0.5, lo[1] + 1.5)


def _threads() -> None:
    """The broad phase's threaded kernels (the sort by cell, the per-thread sweeps, the parallel merge): two threads
    on boxes and spheres enough to be split."""
    from engine import find_pairs, sphere_pairs
    from engine.workloads import w1_boxes

    lo, hi = w1_boxes(20_000, seed=0)
    for method in ("sap", "grid", "octree", "tree"):
        find_pairs(lo, hi, method, threads=2)
    sphere_pairs(0.5 * (lo + hi), 0.5 * (hi - lo).max(axis=1), threads=2)


def _two_boxes():
    from engine import OBB

    return OBB([0, 0, 0], np.eye(3), [1, 1, 1]), OBB([1.5, 0.2, 0], np.eye(3), [1, 1, 1])


def _separating_axes() -> None:
    from engine import narrowphase as npf
    from engine import obb_overlap

    a, b = _two_boxes()
    obb_overlap(a, b)
    pts, off = npf.pack_point_sets([a.corners(), b.corners()])
    npf.overlap_convex_sat_pairs(pts, off, np.array([[0, 1]]))


def _gjk_epa() -> None:
    from engine import contact_feature, epa_penetration, gjk_distance
    from engine import narrowphase as npf

    a, b = _two_boxes()
    gjk_distance(a.corners(), b.corners())
    epa_penetration(a.corners(), b.corners())
    contact_feature(a.corners(), b.corners())
    pts, off = npf.pack_point_sets([a.corners(), b.corners()])
    pairs = np.array([[0, 1]])
    npf.gjk_distance_pairs(pts, off, pairs)
    npf.epa_penetration_pairs(pts, off, pairs)
    npf.contact_feature_pairs(pts, off, pairs)


def _time_of_impact() -> None:
    from engine import time_of_impact

    a, b = _two_boxes()
    time_of_impact(a.corners(), [1.0, 0, 0], b.corners() + [3.0, 0, 0], [0, 0, 0], t_max=2.0)


def _scene(broad_phase: str = "tree"):
    """A World holding two examples of every registered shape kind (engine.world.KINDS), all near the origin, so
    that every cell of the dispatch table that a scene can reach meets its pairs; the same bodies again as static
    level geometry, sensors and filtered bodies; every moving body moved once. Returns (world, examples)."""
    from engine.world import KINDS, World

    examples = [(kind, kind.shape.example()) for kind in KINDS for _ in range(2)]
    world = World(broad_phase=broad_phase)
    moving = [body for kind, shape in examples if not kind.static_only
              for body in [world.add(shape, velocity=[0.0, -1.0, 0.0])]]
    statics = [world.add(shape, static=True, sensor=k == 0, category=2) for k, (kind, shape) in enumerate(examples)
               if not kind.static_only]
    statics += [world.add(shape) for kind, shape in examples[::2] if kind.static_only]
    world.exclude(moving[0], statics[-1])
    world.update(moving, [world.pose(b)[0] + 0.01 for b in moving])
    return world, examples


def _frame(world, examples) -> None:
    world.pairs()
    world.events()


def _contacts(world, examples) -> None:
    world.contacts()


def _impacts(world, examples) -> None:
    world.time_of_impact(1.0)


def _distances(world, examples) -> None:
    bounded = [b for b in world.ids().tolist() if world.shape(b).kind.bounded]
    moving = [b for b in bounded if not world.is_static(b)]
    # every bounded body (level geometry included) against a moving one: two static bodies are never paired
    pairs = [(moving[k % len(moving)], b) for k, b in enumerate(bounded) if b != moving[k % len(moving)]]
    world.closest_points([a for a, _ in pairs], [b for _, b in pairs])
    world.pairs_within(0.5)


#: two rays: one down through the scene, one along it
_RAYS = np.array([[0.0, 5.0, 0.0], [3.0, 0.5, 0.2]]), np.array([[0.0, -1.0, 0.0], [-1.0, 0.0, 0.0]])


def _nearest_rays(world, examples) -> None:
    world.cast_rays(*_RAYS)


def _every_hit(world, examples) -> None:
    world.cast_rays(*_RAYS, 10.0, all_hits=True)


def _shape_queries(world, examples) -> None:
    """Region, overlap and shape cast: the queries of the World that are not a frame or a ray."""
    world.query_aabb([-1.0, -1.0, -1.0], [1.0, 1.0, 1.0])
    for kind, shape in examples[::2]:
        if not kind.static_only:
            world.overlap(shape)
            world.cast_shape(shape, [0.0, -1.0, 0.0])


def _world(question: Callable, broad_phases=("tree", "sap", "grid")) -> Callable[[], None]:
    """``question(world, examples)`` on the scene of ``_scene`` under each broad phase of ``broad_phases`` (each
    keeps a World's structures its own way; the rays walk a tree under "tree" and "sap", the grid under "grid")."""
    def run() -> None:
        for broad_phase in broad_phases:
            question(*_scene(broad_phase))
    return run


def _gas(method: str) -> Callable[[], None]:
    def run() -> None:
        from engine import simulate_gas

        for boundary in ("walls", "periodic"):
            simulate_gas(16, radius=0.3, method=method, boundary=boundary, t_equilibrate=0.05, t_measure=0.1,
                         dt=0.01, blocks=2)
    return run


#: (area, task, step, cost): the independent tasks of the warm-up, in the order ``warm_up`` runs them in one
#: process; ``cost`` weighs the CPU time the task adds to a cold warm-up (only the ratios matter: they balance the
#: groups of ``task_groups``): each ray walk (a tree or the grid, the nearest hit or every hit) compiles a large
#: kernel of its own (the walks and the ray table inlined in it); every other task shares most of its kernels with
#: the others and weighs its cost alone on an empty cache, scaled down to what two-process warm-ups measured it
#: to add
WARMUP_TASKS: list[tuple[str, str, Callable[[], None], float]] = [
    ("falling bodies", "falling bodies", _dynamics, 1.1),
    ("bounding volumes", "volumes", _volumes, 1.5),
    ("bounding volumes", "hulls", _hulls, 4.2),
    ("broad phase", "sap, brute", _boxes("sap", "brute"), 2.1),
    ("broad phase", "grid, octree", _boxes("grid", "octree"), 2.5),
    ("broad phase", "tree", _boxes("tree"), 0.8),
    ("broad phase", "spheres", _spheres, 3.9),
    ("broad phase", "incremental", _incremental, 2.2),
    ("broad phase", "threads", _threads, 8.0),
    ("narrow phase", "SAT", _separating_axes, 4.4),
    ("narrow phase", "GJK, EPA", _gjk_epa, 7.6),
    ("narrow phase", "time of impact", _time_of_impact, 2.3),
    ("pipeline (World)", "pairs, events", _world(_frame), 12.0),
    ("pipeline (World)", "contacts", _world(_contacts), 20.9),
    ("pipeline (World)", "impacts", _world(_impacts), 10.2),
    ("pipeline (World)", "distances", _world(_distances), 15.7),
    ("pipeline (World)", "rays through the tree", _world(_nearest_rays, ("tree", "sap")), 30.0),
    ("pipeline (World)", "every hit through the tree", _world(_every_hit, ("tree", "sap")), 30.0),
    ("pipeline (World)", "rays through the grid", _world(_nearest_rays, ("grid",)), 30.0),
    ("pipeline (World)", "every hit through the grid", _world(_every_hit, ("grid",)), 30.0),
    ("pipeline (World)", "shape queries", _world(_shape_queries), 10.0),
    ("gas", "events", _gas("events"), 2.5),
    ("gas", "stepped", _gas("stepped"), 2.5),
]


def _area(name: str) -> Callable[[], None]:
    def run() -> None:
        for area, _, step, _ in WARMUP_TASKS:
            if area == name:
                step()
    return run


#: (area, step): the areas of the warm-up, each running its tasks, in the order ``warm_up`` runs them
WARMUP_STEPS: list[tuple[str, Callable[[], None]]] = [
    (area, _area(area)) for area in dict.fromkeys(area for area, *_ in WARMUP_TASKS)]


def task_groups(jobs: int) -> list[list[int]]:
    """The indices of ``WARMUP_TASKS`` dealt into at most ``jobs`` groups of about equal summed cost: the tasks
    by decreasing cost, each to the group of least cost so far (Graham's LPT rule: the largest group is within
    4/3 of the best split). Each group lists its tasks in ``WARMUP_TASKS`` order."""
    groups: list[list[int]] = [[] for _ in range(max(1, min(jobs, len(WARMUP_TASKS))))]
    load = [0.0] * len(groups)
    for t in sorted(range(len(WARMUP_TASKS)), key=lambda t: -WARMUP_TASKS[t][3]):
        g = load.index(min(load))
        groups[g].append(t)
        load[g] += WARMUP_TASKS[t][3]
    return [sorted(group) for group in groups if group]


_DONE = "colldet-warmup-done"


def _run_tasks(indices: list[int]) -> None:
    """Run the given tasks in this process, printing ``_DONE`` and each one's index on stdout when it is done
    (whatever a task prints goes to stderr)."""
    out = sys.stdout
    for t in indices:
        with contextlib.redirect_stdout(sys.stderr):
            WARMUP_TASKS[t][2]()
        print(_DONE, t, file=out, flush=True)


def _start_group(indices: list[int]) -> subprocess.Popen:
    """A fresh interpreter running ``_run_tasks(indices)``: the engine imported from where this one's was, the
    compile notice off (the parent shows the progress)."""
    root = str(Path(__file__).resolve().parent.parent)
    env = {**os.environ, "COLLDET_COMPILE_NOTICE": "0",
           "PYTHONPATH": os.pathsep.join(filter(None, [root, os.environ.get("PYTHONPATH")]))}
    return subprocess.Popen([sys.executable, "-m", "engine.warmup", *map(str, indices)], env=env,
                            stdout=subprocess.PIPE, text=True)


def _run_groups(groups: list[list[int]], done: Callable[[int], None]) -> None:
    """Run each group in its own process at once; ``done(t)`` as each task ends. RuntimeError if one fails."""
    events: queue.Queue = queue.Queue()

    def follow(proc: subprocess.Popen) -> None:
        assert proc.stdout is not None
        for line in proc.stdout:
            tag, _, index = line.partition(" ")
            if tag == _DONE:
                events.put(int(index))
        events.put(None)

    procs = [_start_group(group) for group in groups]
    for proc in procs:
        threading.Thread(target=follow, args=(proc,), daemon=True).start()
    running = len(procs)
    try:
        while running:
            t = events.get()
            if t is None:
                running -= 1
            else:
                done(t)
    except BaseException:  # interrupted: no process is left compiling behind
        for proc in procs:
            proc.kill()
        raise
    failed = [" ".join(map(str, g)) for g, proc in zip(groups, procs) if proc.wait() != 0]
    if failed:
        raise RuntimeError(f"the warm-up failed in the process of the tasks {'; '.join(failed)} (its error is above)")


def warm_up(progress: bool = True, stream=None, jobs: int | None = 1) -> float:
    """Run every task of ``WARMUP_TASKS`` (compiling, or loading from the cache, every kernel it reaches), with a
    progress bar on ``stream`` (stderr) when it is a terminal: in this process when ``jobs`` is 1, else in
    ``jobs`` processes at once (``task_groups``; None: one per CPU core). Returns the seconds it took."""
    from tqdm import tqdm

    from ._validate import as_count

    jobs = (os.cpu_count() or 1) if jobs is None else as_count(jobs, "jobs", minimum=1)
    start = time.perf_counter()
    stream = sys.stderr if stream is None else stream
    with tqdm(total=len(WARMUP_TASKS), desc="compiling", unit="task", file=stream,
              disable=None if progress else True) as bar:
        def done(t: int) -> None:
            bar.set_postfix_str(f"{WARMUP_TASKS[t][0]}: {WARMUP_TASKS[t][1]}")
            bar.update()

        if jobs == 1:
            for t, (_, _, step, _) in enumerate(WARMUP_TASKS):
                step()
                done(t)
        else:
            _run_groups(task_groups(jobs), done)
    return time.perf_counter() - start


if __name__ == "__main__":
    _run_tasks([int(arg) for arg in sys.argv[1:]])
