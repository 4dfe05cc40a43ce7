"""The registry of shape kinds (``engine.world.KINDS``) and the dispatch table (``engine.world.TABLE``).

- every (kind, kind, question) cell holds a ``Kernel``, the same both ways round: a real kernel, ``PARTS`` for a
  composite kind, or an explicit ``unsupported(...)`` for two static-only kinds (never paired); running an
  unsupported cell raises ``UnsupportedQuery`` naming both kinds, through ``answer`` as well;
- every registered kind has one shape class, whose ``example()`` and ``random(...)`` build shapes of that kind
  that a World takes (static when the kind is static-only);
- a World holding examples of every kind answers ``pairs()``, ``contacts()``, ``time_of_impact()``,
  ``pairs_within()`` and ``closest_points()``, and its
  queries reach every reachable cell of the table (two of each bounded kind, one of each ground kind, all
  overlapping);
- a convex kind registered after the grounds gets real rows against them, and a body of it rests on a Plane.
"""
from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

from engine import World
from engine.narrowphase.contacts import kernel_scratch
from engine.world import KINDS, QUESTIONS, TABLE, UnsupportedQuery
from engine.world.dispatch import PARTS, DispatchTable, Kernel, NarrowContext, answer, answer_rows, unsupported
from engine.world.kinds import ShapeKind, kind_named
from properties.strategies.world import shape_class
from properties.world_reference import every_pair, reference_pairs

CELLS = [(a, b, q) for q in QUESTIONS for a in KINDS for b in KINDS]


def _is_unsupported(kernel) -> bool:
    return kernel.name.startswith("unsupported")


def reachable(a: ShapeKind, b: ShapeKind) -> bool:
    """Whether a query can pair a body of kind a with one of kind b (two static-only shapes are never paired)."""
    return not (a.static_only and b.static_only)


@pytest.mark.parametrize("a, b, question", CELLS, ids=[f"{a.name}-{b.name}-{q}" for a, b, q in CELLS])
def test_every_cell_holds_a_kernel(a, b, question):
    kernel = TABLE.cell(a, b, question)
    assert isinstance(kernel, Kernel) and callable(kernel.run)
    assert TABLE.cell(b, a, question) is kernel  # symmetric: the kernel orients the pair itself
    assert kernel in TABLE.kernels[question]
    assert TABLE.index[question][a.code, b.code] == TABLE.kernels[question].index(kernel)
    if a.composite or b.composite:
        assert kernel is PARTS
    elif not reachable(a, b):
        assert _is_unsupported(kernel) and a.name in kernel.name and b.name in kernel.name
    else:
        assert kernel is not PARTS and not _is_unsupported(kernel), kernel


def test_the_table_has_every_kind_and_question_and_no_idle_kernel():
    n = len(KINDS)
    assert [k.code for k in KINDS] == list(range(n))
    for q in QUESTIONS:
        index = TABLE.index[q]
        assert index.shape == (n, n) and (index >= 0).all() and (index == index.T).all()
        assert sorted(set(index.ravel().tolist())) == list(range(len(TABLE.kernels[q])))  # every kernel is used


def test_a_table_with_a_missing_cell_is_refused():
    from engine.world.rows import ROWS

    rows = dict(ROWS)
    del rows[KINDS[0], KINDS[0]]
    with pytest.raises(ValueError, match=f"no 'overlap' cell for \\({KINDS[0].name}, {KINDS[0].name}\\)"):
        DispatchTable(rows)


def _unsupported_cells():
    return [(a, b, q) for a, b, q in CELLS if a.code <= b.code and _is_unsupported(TABLE.cell(a, b, q))]


@pytest.mark.parametrize("a, b, question", _unsupported_cells(),
                         ids=[f"{a.name}-{b.name}-{q}" for a, b, q in _unsupported_cells()])
def test_running_an_unsupported_cell_raises(a, b, question):
    """The kernel itself, and ``answer`` over a pair of the two kinds in a World's store."""
    kernel = TABLE.cell(a, b, question)
    out = answer_rows(question, 1)
    with pytest.raises(UnsupportedQuery, match=f"{a.name}.*{b.name}"):
        kernel.run(None, np.zeros((1, 2), np.int64), np.zeros(1, np.int64), out)
    world = World()
    i = world.add(shape_class(a).example(), static=True)
    j = world.add(shape_class(b).example(), static=True)
    store = world._store.view()
    grounds = {g: world.shape(g) for g in (i, j) if not world.bodies().bounded[g]}
    ctx = NarrowContext(store, grounds, kernel_scratch(store.points.shape[1]), 1.0, True)
    with pytest.raises(UnsupportedQuery, match="never paired"):
        answer(TABLE, question, ctx, np.array([[i, j]], np.int64))
    assert world.pairs().shape == (0, 2)  # the World itself never asks


def test_unsupported_says_why():
    assert issubclass(UnsupportedQuery, NotImplementedError)
    kernel = unsupported("a cloud against a rainbow: no kernel yet")
    with pytest.raises(UnsupportedQuery, match="a cloud against a rainbow: no kernel yet"):
        kernel.run(None, np.zeros((0, 2), np.int64), np.zeros(0, np.int64), np.zeros(0))


@pytest.mark.parametrize("kind", KINDS, ids=[k.name for k in KINDS])
def test_every_kind_has_a_shape_class_that_builds_and_is_added(kind):
    cls = shape_class(kind)
    assert kind_named(kind.name) is kind
    assert not (kind.composite and kind.convex)
    assert kind.bounded or callable(kind.candidates)
    rng = np.random.default_rng(1)
    for shape in (cls.example(), cls.random(rng, np.array([0.5, -0.25, 1.0]), 0.7)):
        assert type(shape) is cls and shape.kind is kind
        world = World()
        i = world.add(shape, static=kind.static_only)
        assert world.kind(i) == kind.name and world.is_static(i) == kind.static_only
        assert world.bodies().kind[i] == kind.code
        if kind.bounded:
            lo, hi = world.aabb(i)
            assert np.isfinite(lo).all() and np.isfinite(hi).all() and (lo <= hi).all()
        if kind.composite:
            assert len(shape.parts) >= 1 and all(p.kind.convex for p, _, _ in shape.parts)
            for k in range(len(shape.parts)):
                assert np.isfinite(world.world_points(i, part=k)).all()
        world.remove(i)
        assert world.ids().shape == (0,)


def _world_of_every_kind():
    """Two examples of each bounded kind (the second turned and shifted a little), one of each ground kind, the
    bounded ones moving at a small speed: every body overlaps every other one."""
    world = World()
    kinds = {}
    rng = np.random.default_rng(5)
    for kind in KINDS:
        cls = shape_class(kind)
        copies = 1 if kind.static_only else 2
        for c in range(copies):
            i = world.add(cls.example(), static=kind.static_only)
            kinds[i] = kind
            if not kind.static_only:
                q = rng.normal(size=4)
                world.move(i, center=np.array([0.1, 0.2, -0.1]) * c, rotation=q / np.linalg.norm(q),
                           velocity=rng.normal(size=3) * 0.1)
    return world, kinds


def test_a_world_of_every_kind_answers_every_question():
    world, kinds = _world_of_every_kind()
    ids = world.ids()
    assert [(i, j) for x, i in enumerate(ids) for j in ids[x + 1:] if reachable(kinds[i], kinds[j])] \
        == [tuple(p) for p in every_pair(world).tolist()]
    want = reference_pairs(world)
    got = world.pairs()
    np.testing.assert_array_equal(got, want)
    # every reachable pair of kinds meets (the compound's rows included), and every reachable cell of the
    # convex kinds and grounds is tested
    met = {tuple(sorted((kinds[i].code, kinds[j].code))) for i, j in got.tolist()}
    assert met == {(a.code, b.code) for a in KINDS for b in KINDS[a.code:] if reachable(a, b)}
    cells = {f"{a.name}-{b.name}" for a in KINDS for b in KINDS[a.code:]
             if reachable(a, b) and not (a.composite or b.composite)}
    assert cells <= set(world.stats.groups)
    contacts = world.contacts()
    assert {tuple(p) for p in contacts.pairs.tolist()} == {tuple(p) for p in got.tolist()}
    assert cells <= set(world.stats.groups)
    assert np.isfinite(contacts.depth).all() and (contacts.depth >= 0).all()
    impacts = world.time_of_impact(1.0)
    np.testing.assert_array_equal(impacts.pairs, got)  # all touching now: each at time 0
    np.testing.assert_array_equal(impacts.times, np.zeros(len(got)))
    assert cells <= set(world.stats.groups)
    within, distance = world.pairs_within(0.0)  # every pair overlaps: the distance cells, each at most 0
    np.testing.assert_array_equal(within, got)
    assert cells <= set(world.stats.groups)
    assert np.isfinite(distance).all() and (distance <= 0).all()
    d, pa, pb = world.closest_points(got[:, 1], got[:, 0])  # the other way round: the kernels orient the pair
    np.testing.assert_allclose(d, distance, rtol=0, atol=1e-7)
    np.testing.assert_allclose(np.linalg.norm(pb - pa, axis=1), -d, rtol=0, atol=1e-7)
    begin, end = world.events()
    np.testing.assert_array_equal(begin, got)
    assert end.shape == (0, 2)


_LATE_KIND = """
import importlib
import numpy as np
import engine.world.dispatch
import engine.world.rows
import engine.world.world
from engine.world.kinds import KINDS, shape_kind
from engine.world.shapes import Plane, Sphere

@shape_kind("late_convex")  # a convex kind registered after the grounds, as a new kind would be
class Late(Sphere):
    pass

table = importlib.reload(engine.world.rows).TABLE  # the rows built again over the registry
engine.world.world.TABLE = table
late = Late.kind
print([(a.name, b.name, q) for q in engine.world.dispatch.QUESTIONS for a in KINDS for b in KINDS
       if late in (a, b) and not (a.static_only and b.static_only)
       and table.cell(a, b, q).name.startswith("unsupported")])
world = engine.world.world.World()
ground = world.add(Plane(0.0))
body = world.add(Late([0.0, 0.4, 0.0], 0.5), velocity=[0.0, -1.0, 0.0])
contacts = world.contacts()
print(contacts.pairs.tolist(), contacts.depth.round(12).tolist(), contacts.normal.round(12).tolist())
world.update([body], [[0.0, 2.5, 0.0]])
print(world.time_of_impact(3.0).times.round(12).tolist())
"""


def test_a_convex_kind_registered_after_the_grounds_gets_real_rows():
    """kinds.py: "A new kind is its class and its entry here, its rows in engine/world/rows.py"; rows.py fills every
    other pair of convex kinds with the GJK rows and a convex kind against a ground with the ground's rows.

    Was an engine bug (at 245dac2): rows.py's loop over (a, b), lower code first, gives the ground rows only when the
    convex kind comes first (``_a.convex and _b is PLANE``); a convex kind registered after PLANE and CURVE (the
    next code: where a new kind lands) gets ``unsupported("... two static shapes are never paired")`` against
    both grounds, and a body of that kind on a Plane would raise UnsupportedQuery. Run in a subprocess: the
    registry and the table are module state.
    """
    run = subprocess.run([sys.executable, "-c", _LATE_KIND], capture_output=True, text=True, timeout=300,
                         env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)})
    assert run.returncode == 0, run.stderr
    cells, contact, impact = run.stdout.strip().splitlines()
    assert cells == "[]", f"cells of the new convex kind left unsupported: {cells}"
    # a body of the new kind 0.1 deep in a Plane: the ground's kernel, with the body as the body whatever the codes
    assert contact == "[[0, 1]] [0.1] [[-0.0, 1.0, -0.0]]" or contact == "[[0, 1]] [0.1] [[0.0, 1.0, 0.0]]", contact
    assert impact == "[2.0]", impact
