"""Two documented sizes of SAP's internals (engine/broadphase/sweep_and_prune.py), called directly: the pairs do not
depend on them (any monotone key map and any column grid give brute force's pairs), so the pair properties cannot
see them change.

- ``sweep_keys``: the sort keys map the boxes' range [origin, top] on the sweep axis onto 0 .. KEY_STEPS − 1
  (key(origin) = 0, key(top) = KEY_STEPS − 1, linear in between to within a step), which is what makes the radix
  sort do the sorting (keys squeezed into a few values would leave it all to the runs of equal keys);
- ``_choose_columns``: a sparse grid keeps its column size, up to 2^30 columns per axis (tiny boxes far apart:
  the cap decides the grid), and every box's columns lie in the grid.

And the sweep's second try: its first buffer of pair keys has room for about one pair per (box, column) entry, a
thread's work array that earlier, larger sweeps may have grown; on a thread of its own (fresh work arrays), a
clique of m boxes has m (m − 1) / 2 pairs and must take the second try, with brute force's pairs as the answer.
"""
from __future__ import annotations

import threading
from unittest import mock

import numpy as np
from hypothesis import example, given
from hypothesis import strategies as st

from engine.broadphase import brute_force_pairs, sap_pairs, sweep_and_prune
from engine.broadphase.counting_sort import cell_of
from engine.broadphase.sweep_and_prune import (
    ENTRY_WIDTH,
    KEY_STEPS,
    SPARSE_MIN_BOXES,
    _box_bounds,
    _choose_columns,
    sorted_records,
    sweep_keys,
    sweep_order,
)

#: the per-axis cap of a sparse column grid (``_choose_columns``' docstring)
MAX_COLUMNS = 1 << 30


@example(origin=0.0, span=2.0)  # span 1 would not tell KEY_STEPS / span from KEY_STEPS · span
@example(origin=-3.0, span=0.25)
@given(origin=st.floats(-1e100, 1e100), span=st.floats(1e-100, 1e100))
def test_sweep_keys_map_the_range_onto_every_key(origin, span):
    top = origin + span
    if not top > origin:  # the span is below origin's round-off
        return
    keys = sweep_keys(origin, top)

    def key(v):
        return cell_of(v, keys.origin, keys.scale, KEY_STEPS)

    assert key(origin) == 0
    assert key(top) == KEY_STEPS - 1
    for f in (0.125, 0.25, 0.5, 0.75):
        v = origin + f * (top - origin)
        exact = (v - origin) / (top - origin) * KEY_STEPS  # where v lies in the range, in key steps
        assert abs(key(v) - exact) <= 1.001, (f, key(v), exact)  # floor, and a round-off far below a step


def far_apart_specks(seed, axis, n):
    """n boxes of extent 0 (one in 4) or below 1e-6 on the axes other than ``axis``, spread over 1e4 on those axes,
    in a few clusters along ``axis``: twice their mean extent is far below 1e4 / 2^30."""
    rng = np.random.default_rng(seed)
    lo = rng.uniform(0.0, 1e4, (n, 3))
    lo[:, axis] = rng.integers(0, 4, n) + rng.uniform(0.0, 0.5, n)
    size = rng.uniform(0.0, 1e-6, (n, 3))
    size[rng.random(n) < 0.25] = 0.0
    size[:, axis] = rng.uniform(0.0, 1.0, n)
    return lo, lo + size


@given(seed=st.integers(0, 2**32 - 1), axis=st.integers(0, 2), extra=st.integers(0, 100))
def test_sparse_column_grid_has_at_most_2_30_columns_per_axis(seed, axis, extra):
    n = SPARSE_MIN_BOXES + extra
    lo, hi = far_apart_specks(seed, axis, n)
    order = sweep_order(lo, hi, axis)
    box = np.empty((n, ENTRY_WIDTH))
    sorted_records(order, lo, hi, axis, box)
    ranges = np.empty((4, n), dtype=np.int64)
    grid, entries, sparse = _choose_columns(box, _box_bounds(box), ranges)
    assert sparse
    assert 1 <= grid.k1 <= MAX_COLUMNS and 1 <= grid.k2 <= MAX_COLUMNS, (grid.k1, grid.k2)
    assert grid.k1 == MAX_COLUMNS or grid.k2 == MAX_COLUMNS  # the cap decides: the specks want finer columns
    assert (ranges[0] >= 0).all() and (ranges[0] <= ranges[1]).all() and (ranges[1] < grid.k1).all()
    assert (ranges[2] >= 0).all() and (ranges[2] <= ranges[3]).all() and (ranges[3] < grid.k2).all()
    assert entries == int(((ranges[1] - ranges[0] + 1) * (ranges[3] - ranges[2] + 1)).sum())
    np.testing.assert_array_equal(sap_pairs(lo, hi, axis=axis), brute_force_pairs(lo, hi))


def on_a_fresh_thread(call):
    """call() run on a new thread (whose work arrays start empty), its result returned."""
    out = []
    worker = threading.Thread(target=lambda: out.append(call()))
    worker.start()
    worker.join()
    assert out, "the call raised (see the thread's traceback above)"
    return out[0]


@given(seed=st.integers(0, 2**32 - 1), m=st.integers(20, 80), threads=st.sampled_from([1, 2, 3]))
def test_pairs_outnumbering_the_first_buffer_take_the_second_try(seed, m, threads):
    """(m >= 20 boxes make at most 4 m entries, a first buffer of at most 5 m keys, and m (m − 1) / 2 >= 9.5 m
    pairs; threads > 1 split the columns whatever their work, each range with a fresh buffer of its own.)"""
    rng = np.random.default_rng(seed)
    lo = rng.uniform(0.0, 1.0, (m, 3))
    hi = lo + 2.0  # every box contains [1, 2]^3: a clique
    with mock.patch.object(sweep_and_prune, "MIN_ENTRIES_PER_THREAD", 1):
        pairs, tests = on_a_fresh_thread(lambda: sap_pairs(lo, hi, return_tests=True, threads=threads))
    np.testing.assert_array_equal(pairs, brute_force_pairs(lo, hi))
    assert pairs.shape[0] == m * (m - 1) // 2 and tests >= pairs.shape[0]
