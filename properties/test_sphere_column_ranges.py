"""``sweep_columns`` (engine/broadphase/sphere_columns.py) sweeps the home columns col_ids[first:last] and only
those: sphere_pairs' threads each sweep a disjoint range of columns, so the ranges of a split record every pair of
the whole sweep exactly once between them. sphere_pairs canonicalises (and so deduplicates) the merged records,
so a range that swept the columns before its own too would give the same pairs at up to ``threads`` times the work:
here the ranges' records are compared with the whole sweep's directly.
"""
from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from engine.broadphase.sphere_columns import column_layout, home_columns, sort_into_columns, sweep_columns


def column_grid(c, radius):
    """The grid arguments of sweep_columns for equal spheres of ``radius`` at the centres c (n, 3), built as
    sphere_pairs builds its sorted columns (columns a little wider than a diameter)."""
    n = c.shape[0]
    layout = column_layout(c.min(axis=0), c.max(axis=0), 2.0 * radius * (1.0 + 1e-9), n)
    key_type = np.int32 if layout.dense else np.int64
    keys, keys_tmp = np.empty(n + 1, dtype=key_type), np.empty(n + 1, dtype=key_type)
    index, index_tmp = np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64)
    sorted_arrays = [np.empty(n) for _ in range(4)]
    radii = np.full(n, radius)
    large = np.zeros(n, dtype=np.bool_)
    m, skeys, sid = sort_into_columns(c, radii, large, layout, keys, index, keys_tmp, index_tmp, *sorted_arrays,
                                      np.iinfo(key_type).max)
    col_ids, col_start = home_columns(skeys, m, layout)
    return (layout, skeys, m, *sorted_arrays, sid, col_ids, col_start), col_ids.shape[0]


def swept(grid, first, last):
    """The pairs (rows (i, j) as recorded, sorted) of the sweeps from home columns first .. last − 1."""
    buf = np.empty((16, 2), dtype=np.int64)
    count = sweep_columns(*grid, first, last, buf, 0)
    if count > buf.shape[0]:
        buf = np.empty((count, 2), dtype=np.int64)
        count = sweep_columns(*grid, first, last, buf, 0)
    rows = np.sort(buf[:count], axis=1)
    return rows[np.lexsort((rows[:, 1], rows[:, 0]))]


@given(seed=st.integers(0, 2**32 - 1), n=st.integers(20, 300), dense=st.booleans(), cuts=st.integers(1, 4))
def test_column_ranges_of_a_split_record_the_whole_sweep_once(seed, n, dense, cuts):
    rng = np.random.default_rng(seed)
    radius = 0.5
    # a dense grid (spheres packed in a slab) or a sparse one (clusters 1e6 apart)
    c = rng.uniform(0.0, 12.0, (n, 3))
    if not dense:
        c[:, 1:] += 1e6 * rng.integers(0, 3, (n, 2))
    grid, columns = column_grid(c, radius)
    whole = swept(grid, 0, columns)
    d = np.linalg.norm(c[whole[:, 0]] - c[whole[:, 1]], axis=1) if whole.size else np.empty(0)
    assert (d <= 2.0 * radius).all()
    bounds = sorted({0, columns, *rng.integers(0, columns + 1, cuts).tolist()})
    parts = [swept(grid, a, b) for a, b in zip(bounds[:-1], bounds[1:])]
    merged = np.concatenate(parts)
    assert merged.shape == whole.shape, (bounds, [p.shape[0] for p in parts], whole.shape[0])
    merged = merged[np.lexsort((merged[:, 1], merged[:, 0]))]
    np.testing.assert_array_equal(merged, whole)
