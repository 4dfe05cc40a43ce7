"""The cell list's occupancy bits (engine/gas/cell_list.py, ``CellList.occupied``) against its heads.

The partner scan of the event-driven gas skips a cell whose occupancy bit is clear without reading its ``head``
entry, so the bits must say exactly which cells hold a sphere, after every insertion and removal: bit k set iff
``head[k] >= 0``, and the padding bits of the last word clear. Checked through the gas's own runs (cell
crossings move spheres between cells at every step; a capped run stops between events), with both searches
(the neighbour lists' rebuilds move spheres too), walls and periodic boxes; and the lists themselves are checked
to hold every sphere once, in the cell of its ``links`` record.
"""
from __future__ import annotations

import numpy as np
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from engine.gas import EventDrivenGas, radius_for_packing
from engine.gas.cell_list import cell_fill, cell_occupied, new_cell_list
from engine.gas.initial import draw_velocities, place_spheres

L = 10.0


def _bits(cells):
    """The occupancy bits as one bool per cell (flat index), read from the words."""
    words = cells.occupied.view(np.uint64)
    k = np.arange(cells.ncell**3)
    return ((words[k >> 6] >> (k & 63).astype(np.uint64)) & np.uint64(1)).astype(bool)


def _check_cells(gas):
    cells = gas.cells
    nc = cells.ncell**3
    bits = _bits(cells)
    assert np.array_equal(bits, cells.head >= 0), "occupancy bits disagree with the cell heads"
    padding = cells.occupied.view(np.uint64)[-1] >> np.uint64(nc % 64) if nc % 64 else np.uint64(0)
    assert padding == 0, "bits set beyond the last cell"
    for k in np.flatnonzero(cells.head >= 0)[:50]:  # the public test, on a sample of cells
        assert cell_occupied(cells, np.int64(k))
    for k in np.flatnonzero(cells.head < 0)[:50]:
        assert not cell_occupied(cells, np.int64(k))
    seen = np.zeros(gas.n, dtype=np.int64)
    links = cells.links
    for k in np.flatnonzero(cells.head >= 0):
        j = int(cells.head[k])
        while j >= 0:
            c = links[j]["cell"].astype(np.int64)
            assert (c[0] * cells.ncell + c[1]) * cells.ncell + c[2] == k, "a sphere in another cell's list"
            seen[j] += 1
            j = int(links[j]["next"])
    assert np.all(seen == 1), "a sphere missing from the lists or listed twice"


@settings(max_examples=30)
@given(st.integers(1, 150), st.floats(0.01, 0.35), st.sampled_from(["walls", "periodic"]),
       st.sampled_from(["cells", "neighbour_lists"]), st.integers(0, 2**16), st.integers(1, 400))
def test_occupancy_bits_follow_the_cells_through_a_run(n, eta, boundary, search, seed, cap):
    """After the start and after every checkpoint of a run (some stopped by an event cap between events), bit k
    is set exactly when cell k holds a sphere, and every sphere is listed once, in its own cell."""
    rng = np.random.default_rng(seed)
    r = np.full(n, radius_for_packing(n, eta, L, boundary))
    m = rng.uniform(0.5, 2.0, n)
    try:
        p = place_spheres(n, r, L, boundary, rng)
    except ValueError:
        assume(False)
    v = draw_velocities(m, 1.0, boundary, rng)
    periodic = boundary == "periodic"
    if periodic and 3.0 * 2.0 * r.max() * (1.5 if search == "neighbour_lists" else 1.0) > L:
        assume(False)
    gas = EventDrivenGas(p, v, r, m, L, periodic, search=search)
    _check_cells(gas)
    for t in (0.05, 0.2, 0.6):
        gas.run(t, max_events=cap)
        _check_cells(gas)
        gas.run(t)
        _check_cells(gas)


@settings(max_examples=30)
@given(st.integers(1, 200), st.integers(3, 12), st.sampled_from([False, True]), st.integers(0, 2**16))
def test_refilling_a_cell_list_resets_its_bits(n, ncell, periodic, seed):
    """``cell_fill`` on a list already filled with other centres: the bits of the cells it emptied are cleared."""
    rng = np.random.default_rng(seed)
    cells = new_cell_list(n, L, ncell, periodic)
    for _ in range(2):
        centres = rng.uniform(-L / 2, L / 2, (n, 3)) * rng.uniform(0.0, 1.0)  # crowded in the middle, or spread
        cell_fill(cells, centres)
        bits = _bits(cells)
        assert np.array_equal(bits, cells.head >= 0)
        assert bits.sum() == len({tuple(c) for c in cells.links["cell"].tolist()})
