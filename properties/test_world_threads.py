"""``World(threads=N)``: every answer is the same bit for bit whatever the thread count.

Random mixed worlds (every registered bounded kind, compounds, static bodies, the grounds, filters, sensors and
an exclusion; every broad phase) are run through the same frames by worlds of 1, 2, 3 and 5 threads: the
answers of ``pairs``, ``contacts`` (every field), ``time_of_impact``, ``events``, ``closest_points``,
``pairs_within`` and ``cast_rays`` must agree to the bit (dtype, shape and bytes; an error must be the same
error). The split thresholds of engine/world/split.py are lowered for the run, so that these small worlds
really take the threaded paths — the property checks that some batch was split.
"""
from __future__ import annotations

import contextlib

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from engine import BROAD_PHASES, World
from engine.narrowphase import TOINotConverged
from engine.world import split

from .strategies.world import composite_kinds, convex_kinds, ground_kinds, shape_class

THREADS = (1, 2, 3, 5)
FRAMES = 2
GROUND_NAMES = {kind.name for kind in ground_kinds()}
CONTACT_FIELDS = ("pairs", "separation", "depth", "normal", "feature_a", "feature_b", "points", "point_offsets",
                  "radius_a", "radius_b", "point_ids", "persists", "part_a", "part_b")


@contextlib.contextmanager
def _small_splits(calls: list):
    """Split every batch of two rows or more, and count the batches run in several ranges (``calls``)."""
    names = ("MIN_CANDIDATES_PER_THREAD", "MIN_PAIRS_PER_THREAD", "MIN_RECORD_ROWS_PER_THREAD")
    saved = {name: getattr(split, name) for name in names}
    run = split.run_ranges

    def counting(work, spans):
        calls.append(len(spans))
        return run(work, spans)
    try:
        for name in names:
            setattr(split, name, 1)
        split.run_ranges = counting
        yield
    finally:
        for name, value in saved.items():
            setattr(split, name, value)
        split.run_ranges = run


def _shape(rng, kinds, side):
    kind = kinds[int(rng.integers(len(kinds)))]
    return shape_class(kind).random(rng, rng.uniform(0.0, side, 3), float(rng.uniform(0.4, 1.0)))


def _world(threads, broad, seed, n, statics, with_grounds, filtered):
    """A world of ``n`` moving bodies (a third compounds when there are composite kinds), ``statics`` static
    ones, the grounds, and (``filtered``) categories, masks, sensors and an exclusion — the same for every
    thread count (one seed)."""
    rng = np.random.default_rng(seed)
    side = 1.3 * n ** (1 / 3) + 1.0
    world = World(broad, threads=threads)
    movable = convex_kinds() + composite_kinds()
    ids = [world.add(_shape(rng, movable, side), sensor=bool(filtered and rng.random() < 0.1)) for _ in range(n)]
    for _ in range(statics):
        world.add(_shape(rng, convex_kinds(), side), static=True)
    if with_grounds:
        for kind in ground_kinds():
            world.add(shape_class(kind).random(rng, np.array([0.0, 0.5, 0.0]), 1.0))
    if filtered:
        world.set_filter(ids[::3], category=2, mask=int(rng.integers(1, 4)))
        world.set_filter(ids[1::4], group=-1)
        world.exclude(ids[0], ids[1])
    return world, np.array(ids, np.int64), rng, side


def _try(answers: list, call) -> None:
    """The answer's arrays, or the error it raised (type and message)."""
    try:
        out = call()
    except TOINotConverged as exc:
        answers.append(f"{type(exc).__name__}: {exc}")
        return
    answers.extend(out if isinstance(out, tuple) else [out])


def _frames(world, ids, rng, side) -> list:
    answers: list = []
    for _ in range(FRAMES):
        k = ids.shape[0]
        q = rng.normal(size=(k, 4))
        world.update(ids, rng.uniform(0.0, side, (k, 3)), rotations=q / np.linalg.norm(q, axis=1)[:, None],
                     velocities=rng.normal(size=(k, 3)))
        answers.append(world.pairs())
        contacts = world.contacts()
        answers.extend(getattr(contacts, name) for name in CONTACT_FIELDS)
        _try(answers, lambda: tuple(world.time_of_impact(0.25).__dict__.values()))
        answers.extend(world.events())
        live = world.ids()
        ground = np.array([world.kind(i) in GROUND_NAMES for i in live.tolist()])
        a, b = rng.integers(0, live.shape[0], (2, 40))
        keep = (a != b) & ~(ground[a] & ground[b])  # a body with itself, or two grounds, have no distance
        answers.extend(world.closest_points(live[a[keep]], live[b[keep]]))
        answers.extend(world.pairs_within(0.2))
        hits = world.cast_rays(rng.uniform(-1.0, side + 1.0, (60, 3)), rng.normal(size=(60, 3)))
        answers.extend(hits.__dict__.values())
    return answers


def _same(a, b) -> bool:
    if isinstance(a, str) or isinstance(b, str):
        return a == b
    a, b = np.asarray(a), np.asarray(b)
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


@settings(max_examples=25)
@given(broad=st.sampled_from(BROAD_PHASES), seed=st.integers(0, 2**32 - 1), n=st.integers(12, 48),
       statics=st.integers(0, 6), with_grounds=st.booleans(), filtered=st.booleans())
def test_thread_counts_answer_alike(broad, seed, n, statics, with_grounds, filtered):
    calls: list = []
    answers = {}
    with _small_splits(calls):
        for threads in THREADS:
            answers[threads] = _frames(*_world(threads, broad, seed, n, statics, with_grounds, filtered))
    assert any(parts > 1 for parts in calls), "no batch took the threaded path"
    for threads in THREADS[1:]:
        assert len(answers[threads]) == len(answers[1])
        for at, (one, many) in enumerate(zip(answers[1], answers[threads])):
            assert _same(one, many), f"answer {at} differs with {threads} threads"
