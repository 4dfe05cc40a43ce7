"""The event-driven gas with neighbour lists (``EventDrivenGas(search="neighbour_lists")``) against the cell-list
search: the same collisions at the same times, in the same order, and the same final state within round-off;
the lists' own guarantees (complete, symmetric, every sphere within its skin); and the lists growing when a
rebuild needs room.

The two searches answer the same exact dynamics with different bookkeeping (cell crossings against list
rebuilds), so over a short run every checkpoint sees the same number of collisions and every sphere the same
number of velocity changes; positions differ only by the round-off of advancing at different event times.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from engine.gas import EventDrivenGas, radius_for_packing
from engine.gas.event_state import RADIUS, X, Z
from engine.gas.initial import draw_velocities, place_spheres
from engine.gas.neighbour_list import REBUILDS, SKIN
from properties.strategies.gas import INTERPRETED

L = 10.0


def _scene(n, eta, boundary, seed, spread):
    """n spheres at packing η, radii spread over [1 − spread, 1] times the common one, random masses."""
    rng = np.random.default_rng(seed)
    r = radius_for_packing(n, eta, L, boundary) * rng.uniform(1.0 - spread, 1.0, n)
    m = rng.uniform(0.5, 2.0, n)
    try:
        p = place_spheres(n, r, L, boundary, rng)
    except ValueError:  # too dense for random placement of unequal spheres: not a scene of this test
        assume(False)
    v = draw_velocities(m, 1.0, boundary, rng)
    return p, v, r, m


def _velocity_changes(gas):
    """Each sphere's count of velocity changes (collisions and wall hits), in the caller's order."""
    out = np.empty(gas.n, dtype=np.int64)
    out[gas.order] = gas.state.book["count"]
    return out


def _lists_fit(r, periodic):
    return not periodic or 3.0 * (1.0 + SKIN) * 2.0 * r.max() <= L


@settings(max_examples=40)
@given(st.integers(8, 120), st.floats(0.02, 0.4), st.sampled_from(["walls", "periodic"]), st.integers(0, 2**16),
       st.sampled_from([0.0, 0.5]), st.floats(0.2, 2.0))
def test_neighbour_lists_answer_the_same_collisions_as_the_cell_lists(n, eta, boundary, seed, spread, skin):
    """Both searches, from the same start, over about one collision per sphere: equal collision counts at 20
    checkpoints, equal per-sphere velocity-change counts, equal virial and final state within round-off."""
    periodic = boundary == "periodic"
    p, v, r, m = _scene(n, eta, boundary, seed, spread)
    assume(_lists_fit(r * (1.0 + skin) / (1.0 + SKIN), periodic))
    cells = EventDrivenGas(p, v, r, m, L, periodic)
    lists = EventDrivenGas(p, v, r, m, L, periodic, search="neighbour_lists", skin=skin)
    mean_free_time = 1.0 / max(1.0, n * (2.0 * r.mean()) ** 2 * 4.0 / L**3)
    for t in np.linspace(0.05, 1.0, 20) * mean_free_time:
        cells.run(t)
        lists.run(t)
        assert lists.collisions == cells.collisions, t
        assert lists.wall_hits == cells.wall_hits, t
    assert (_velocity_changes(lists) == _velocity_changes(cells)).all()
    np.testing.assert_allclose(lists.virial, cells.virial, rtol=1e-9, atol=1e-12)
    d = lists.positions - cells.positions
    if periodic:
        d -= L * np.round(d / L)
    assert np.abs(d).max() <= 1e-8
    np.testing.assert_allclose(lists.velocities, cells.velocities, rtol=0, atol=1e-8)
    if periodic:
        q = lists.positions
        assert (q >= -L / 2).all() and (q < L / 2).all()


@settings(max_examples=30)
@given(st.integers(8, 150), st.floats(0.05, 0.45), st.sampled_from(["walls", "periodic"]), st.integers(0, 2**16),
       st.floats(0.5, 4.0))
def test_the_neighbour_lists_stay_complete_and_symmetric(n, eta, boundary, seed, duration):
    """After a run (stopped between events): every sphere lies within α r of its list centre, every pair of list
    centres closer than (1 + α)(r_i + r_j) is in both lists, the lists are symmetric and hold no duplicates."""
    periodic = boundary == "periodic"
    p, v, r, m = _scene(n, eta, boundary, seed, 0.5)
    assume(_lists_fit(r, periodic))
    gas = EventDrivenGas(p, v, r, m, L, periodic, search="neighbour_lists")
    gas.run(duration)
    nl, st_ = gas.lists, gas.st
    rad = st_[:, RADIUS]
    drift = np.sqrt(((st_[:, X:Z + 1] - nl.centre[:, 0:3]) ** 2).sum(axis=1))
    assert (drift <= nl.skin * rad * (1.0 + 1e-12)).all()
    d = nl.centre[:, None, 0:3] - nl.centre[None, :, 0:3]
    if periodic:
        d -= L * np.round(d / L)
    close = ((d * d).sum(-1) < ((1.0 + nl.skin) * (rad[:, None] + rad[None, :])) ** 2)
    np.fill_diagonal(close, False)
    listed = np.zeros_like(close)
    for i in range(gas.n):
        row = nl.ids[i, : nl.sizes[i]]
        assert len(set(row.tolist())) == len(row)
        listed[i, row] = True
    assert (listed == listed.T).all()
    assert (listed[close]).all()


def test_the_lists_grow_when_a_rebuild_needs_room():
    """Small spheres crowding around big ones: more neighbours than the lists' first capacity (16), at the start
    and during the run; the run still answers the cell lists' collisions. Interpreted (the mutation run), the same
    crowd in a smaller box: 150 spheres, one of them big, at about the same packing."""
    rng = np.random.default_rng(3)
    n, box, big = (150, 1.5, 1) if INTERPRETED else (1200, 3.0, 10)
    r = np.where(np.arange(n) < big, 0.35, 0.1)
    m = np.ones(n)
    p = place_spheres(n, r, box, "walls", rng)
    v = draw_velocities(m, 1.0, "walls", rng)
    cells = EventDrivenGas(p, v, r, m, box, False)
    lists = EventDrivenGas(p, v, r, m, box, False, search="neighbour_lists")
    assert lists.lists.ids.shape[1] > 16
    for t in np.linspace(0.005, 0.1, 20):
        cells.run(t)
        lists.run(t)
        assert lists.collisions == cells.collisions
    assert lists.lists.sizes.max() > 16
    assert lists.lists.tally[REBUILDS] > 0  # the long lists were made again during the run


@pytest.mark.parametrize("kwargs, name", [({"search": "verlet"}, "search"), ({"search": 3}, "search"),
                                          ({"skin": 0.0}, "skin"), ({"skin": float("nan")}, "skin")])
def test_bad_search_arguments_are_named(kwargs, name):
    p = np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0]])
    with pytest.raises((ValueError, TypeError), match=name):
        EventDrivenGas(p, np.ones((2, 3)), 0.5, 1.0, L, False, **kwargs)


def test_a_periodic_box_too_small_for_the_lists_is_refused():
    p = np.array([[0.0, 0.0, 0.0], [-3.0, 0.0, 0.0]])
    EventDrivenGas(p, np.ones((2, 3)), 1.5, 1.0, L, True)  # the cell lists need 3 diameters: accepted
    with pytest.raises(ValueError, match="neighbour_lists"):
        EventDrivenGas(p, np.ones((2, 3)), 1.5, 1.0, L, True, search="neighbour_lists")


def test_the_lists_grow_during_a_run():
    """A lattice of small spheres (6 neighbours each: the first capacity of 16 suffices at the start) and one big
    sphere (100 times heavier) thrown into it: its rebuilds inside the lattice need more room, the lists grow in
    the middle of the run, and the collisions stay those of the cell lists. Interpreted (the mutation run), a
    5 × 5 × 5 lattice with the same front face (x = 0.4) instead of 9 × 13 × 13: the big sphere still ploughs in."""
    box = 3.0
    (nx, x0), (ny, y0) = ((5, -0.48), (5, -0.44)) if INTERPRETED else ((9, -1.36), (13, -1.32))
    axis = np.arange(ny) * 0.22 + y0
    g = np.stack(np.meshgrid(np.arange(nx) * 0.22 + x0, axis, axis, indexing="ij"), axis=-1).reshape(-1, 3)
    p = np.vstack([g, [[1.05, 0.0, 0.0]]])
    n = p.shape[0]
    r = np.full(n, 0.1)
    r[-1] = 0.35
    m = np.ones(n)
    m[-1] = 100.0
    v = np.random.default_rng(5).normal(size=(n, 3)) * 0.1
    v[-1] = [-3.0, 0.0, 0.0]
    cells = EventDrivenGas(p, v, r, m, box, False)
    lists = EventDrivenGas(p, v, r, m, box, False, search="neighbour_lists")
    assert lists.lists.ids.shape[1] == 16
    for t in np.linspace(0.02, 0.4, 20):
        cells.run(t)
        lists.run(t)
        assert lists.collisions == cells.collisions
    assert lists.lists.ids.shape[1] > 16 and lists.lists.sizes.max() > 16
