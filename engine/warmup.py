"""Compile every kernel ahead of time: ``colldet warmup`` (or ``engine.warmup.warm_up()``).

The engine's kernels are compiled by numba on their first call (tens of seconds in all on a cold machine) and
cached on disk; a later process loads them in milliseconds. ``warm_up`` calls every public entry point once on
small inputs, area by area, so that an installation (a Docker image build, a CI cache, a lab machine) starts warm.
"""
from __future__ import annotations

import sys
import time
from collections.abc import Callable

import numpy as np

__all__ = ["WARMUP_STEPS", "warm_up"]


def _dynamics() -> None:
    from engine import bisect, drop_cube, drop_particle, rk4_step

    rk4_step(lambda t, y: -y, 0.0, [1.0, 2.0], 0.1)
    bisect(lambda x: x**3 - 2.0, 0.0, 2.0, 1e-6)
    drop_particle(1.0, drag=0.2, restitution=0.8, t_end=1.0)
    drop_cube(1.0)


def _bounding() -> None:
    from engine import bounding

    pts = np.random.default_rng(0).normal(size=(24, 3))
    bounding.describe_bounding_volumes(pts)
    bounding.describe_bounding_volumes(pts[:, :2])
    for k in (2, 3, 4):
        bounding.circumsphere(pts[:k])
    bounding.describe_hull(pts)
    bounding.describe_hull(pts[:, :2])
    bounding.describe_decomposition(np.array([[0, 0], [4, 0], [4, 3], [2, 1], [0, 3.0]]))


def _broad_phase() -> None:
    from engine import BROAD_PHASES, find_pairs, sphere_pairs, sweep_intervals
    from engine.broadphase import DynamicAABBTree, IncrementalSAP

    rng = np.random.default_rng(1)
    for d in (1, 2, 3):
        lo = rng.uniform(0, 10, (40, d))
        for method in BROAD_PHASES:
            find_pairs(lo, lo + 1.0, method)
    centres = rng.uniform(0, 10, (40, 3))
    for method in BROAD_PHASES:
        sphere_pairs(centres, 0.5, method)
    sweep_intervals([3.0, 7.7, 1.0], [7.0, 18.0, 8.0])
    lo = rng.uniform(0, 10, (40, 3))
    IncrementalSAP(lo, lo + 1.0).update(lo + 0.1, lo + 1.1)
    tree = DynamicAABBTree.from_boxes(lo, lo + 1.0)
    tree.update(lo + 0.1, lo + 1.1)
    tree.pairs()
    tree.query(lo[0], lo[0] + 2.0)
    tree.move(tree.insert(lo[1], lo[1] + 1.0), lo[1] + 0.5, lo[1] + 1.5)


def _narrow_phase() -> None:
    from engine import OBB, contact_feature, epa_penetration, gjk_distance, obb_overlap, time_of_impact
    from engine import narrowphase as npf

    a = OBB([0, 0, 0], np.eye(3), [1, 1, 1])
    b = OBB([1.5, 0.2, 0], np.eye(3), [1, 1, 1])
    obb_overlap(a, b)
    gjk_distance(a.corners(), b.corners())
    epa_penetration(a.corners(), b.corners())
    contact_feature(a.corners(), b.corners())
    time_of_impact(a.corners(), [1.0, 0, 0], b.corners() + [3.0, 0, 0], [0, 0, 0], t_max=2.0)
    pts, off = npf.pack_point_sets([a.corners(), b.corners()])
    pairs = np.array([[0, 1]])
    npf.gjk_distance_pairs(pts, off, pairs)
    npf.epa_penetration_pairs(pts, off, pairs)
    npf.contact_feature_pairs(pts, off, pairs)
    npf.overlap_convex_sat_pairs(pts, off, pairs)


def _world() -> None:
    """Two examples of every registered shape kind (engine.world.KINDS), all near the origin, so that every cell
    of the dispatch table that a scene can reach meets its pairs and is compiled, under each broad phase and for
    every question; then the same bodies as static level geometry, sensors and filtered bodies, and every
    query (rays, shapes, distances)."""
    from engine.world import KINDS, World

    examples = [(kind, kind.shape.example()) for kind in KINDS for _ in range(2)]
    for broad_phase in ("tree", "sap", "grid"):
        world = World(broad_phase=broad_phase)
        moving = [body for kind, shape in examples if not kind.static_only
                  for body in [world.add(shape, velocity=[0.0, -1.0, 0.0])]]
        statics = [world.add(shape, static=True, sensor=k == 0, category=2) for k, (kind, shape) in enumerate(examples)
                   if not kind.static_only]
        statics += [world.add(shape) for kind, shape in examples[::2] if kind.static_only]
        world.exclude(moving[0], statics[-1])
        world.update(moving, [world.pose(b)[0] + 0.01 for b in moving])
        world.pairs()
        world.contacts()
        world.time_of_impact(1.0)
        world.events()
        _queries(world, examples)


def _queries(world, examples) -> None:
    """Every query of the World once: rays (nearest, every hit), region, overlap, shape cast, distances."""
    import numpy as np

    rays = np.array([[0.0, 5.0, 0.0], [3.0, 0.5, 0.2]]), np.array([[0.0, -1.0, 0.0], [-1.0, 0.0, 0.0]])
    world.cast_rays(*rays)
    world.cast_rays(*rays, 10.0, all_hits=True)
    world.query_aabb([-1.0, -1.0, -1.0], [1.0, 1.0, 1.0])
    for kind, shape in examples[::2]:
        if not kind.static_only:
            world.overlap(shape)
            world.cast_shape(shape, [0.0, -1.0, 0.0])
    ids = world.ids()
    bounded = [b for b in ids.tolist() if world.kind(b) not in ("plane", "curve")]
    world.closest_points(bounded[:-1], bounded[1:])
    world.pairs_within(0.5)


def _gas() -> None:
    from engine import simulate_gas

    for method in ("events", "stepped"):
        for boundary in ("walls", "periodic"):
            simulate_gas(16, radius=0.3, method=method, boundary=boundary, t_equilibrate=0.05, t_measure=0.1,
                         dt=0.01, blocks=2)


#: (area, step) in the order ``warm_up`` runs them
WARMUP_STEPS: list[tuple[str, Callable[[], None]]] = [
    ("falling bodies", _dynamics),
    ("bounding volumes", _bounding),
    ("broad phase", _broad_phase),
    ("narrow phase", _narrow_phase),
    ("pipeline (World)", _world),
    ("gas", _gas),
]


def warm_up(progress: bool = True, stream=None) -> float:
    """Run every step of ``WARMUP_STEPS`` (compiling, or loading from the cache, every kernel it reaches), with a
    progress bar on ``stream`` (stderr) when it is a terminal. Returns the seconds it took."""
    from tqdm import tqdm

    start = time.perf_counter()
    stream = sys.stderr if stream is None else stream
    with tqdm(WARMUP_STEPS, desc="compiling", unit="area", file=stream, disable=None if progress else True) as bar:
        for area, step in bar:
            bar.set_postfix_str(area)
            step()
    return time.perf_counter() - start
