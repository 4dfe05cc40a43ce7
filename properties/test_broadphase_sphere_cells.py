"""The padded cell grid of sphere_pairs (engine.broadphase.sphere_cells): every one of the 26 neighbour directions
of a cell is met (its forward half stencil, five ranges of cells, plus the other half seen from the other side),
the grid is really the one used on these scenes, threads share its spheres bit for bit, and its layout refuses
grids with too many cells instead of overflowing."""
from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial import cKDTree

from engine.broadphase import sphere_pairs, spheres
from engine.broadphase.sphere_cells import MAX_CELLS_PER_SPHERE, cell_layout
from engine.workloads import w2_spheres
from properties.test_broadphase_spheres import brute_sphere_pairs

#: the 26 neighbour directions of a cell
OFFSETS = [o for o in itertools.product((-1, 0, 1), repeat=3) if o != (0, 0, 0)]


def uses_cells(centers, radius):
    """Whether sphere_pairs takes the padded cell grid on these equal spheres (its cells are a little wider
    than 2 · radius, so a grid of 2 · radius cells that is dense enough means the real one is too)."""
    c = np.asarray(centers, dtype=float)
    return cell_layout(c.min(axis=0), c.max(axis=0), 2.0 * radius, c.shape[0]).n_cells > 0


@pytest.mark.parametrize("offset", OFFSETS)
@settings(max_examples=8)
@given(st.floats(0.05, 2.0), st.floats(0.9, 0.999), st.integers(0, 2**32 - 1), st.sampled_from([0.0, -37.0, 1e5]))
def test_pairs_along_every_neighbour_direction_are_found(offset, radius, closeness, seed, shift):
    """100 touching pairs along one of the 26 directions, at random places: their segments cross the cell
    boundaries along that direction in every combination (all three at once for about 1 in 6 along a diagonal),
    so a stencil range that misses one neighbour cell loses pairs."""
    rng = np.random.default_rng(seed)
    u = np.array(offset, dtype=float) / np.linalg.norm(offset)
    first = shift + rng.uniform(0.0, 16.0 * radius, size=(100, 3))
    centers = np.concatenate([first, first + closeness * 2.0 * radius * u])
    assert uses_cells(centers, radius)
    got = sphere_pairs(centers, radius)
    np.testing.assert_array_equal(got, brute_sphere_pairs(centers, radius))
    assert len(got) >= 100  # the planted pairs at least


@pytest.mark.parametrize("eta", [0.05, 0.2, 0.45])
def test_w2_scenes_through_the_cells_match_ckdtree(eta):
    centres, radius = w2_spheres(20_000, eta)
    assert uses_cells(centres, radius)
    expected = cKDTree(centres).query_pairs(2 * radius, output_type="ndarray")
    expected = expected[np.lexsort((expected[:, 1], expected[:, 0]))]
    np.testing.assert_array_equal(sphere_pairs(centres, radius), expected)


@pytest.mark.parametrize("threads", [2, 3, 7])
@pytest.mark.parametrize("minimum", [1, spheres.MIN_SPHERES_PER_THREAD])
def test_threads_share_the_cells_bit_for_bit(threads, minimum, monkeypatch):
    """Equal and unequal radii (some spheres kept out of the grid), the work split among threads at the default
    minimum and at one sphere per thread."""
    centres, radius = w2_spheres(12_000, 0.2, seed=3)
    radii = np.random.default_rng(5).uniform(0.2, 0.5, size=len(centres))
    radii[::997] = 4.0  # larger than 4 x the median: tested against every sphere
    one = [sphere_pairs(centres, radius), sphere_pairs(centres, radii)]
    monkeypatch.setattr(spheres, "MIN_SPHERES_PER_THREAD", minimum)
    for single, r in zip(one, (radius, radii)):
        many = sphere_pairs(centres, r, threads=threads)
        assert many.dtype == np.int64
        np.testing.assert_array_equal(many, single)


@given(st.integers(1, 10**6), st.floats(1e-300, 1e3))
def test_cell_layout_is_refused_past_its_cell_budget(n, h):
    lo = np.zeros(3)
    hi = np.full(3, 100.0)
    layout = cell_layout(lo, hi, h, n)
    per_axis = np.floor(100.0 / h) + 1.0
    with np.errstate(over="ignore"):  # past 1e102 cells per axis the count is inf: refused all the same
        cells = (per_axis + 1.0) * (per_axis + 2.0) ** 2
    if cells <= MAX_CELLS_PER_SPHERE * n + 4096:
        assert layout.n_cells == int(cells)
        assert (layout.nx, layout.ny, layout.nz) == (int(per_axis),) * 3
    else:
        assert layout.n_cells == 0


@given(st.lists(st.floats(-1e3, 1e3), min_size=3, max_size=3), st.lists(st.floats(0.0, 1e3), min_size=3, max_size=3),
       st.floats(1e-9, 1e3), st.integers(1, 10_000))
def test_every_layout_has_its_documented_row_lengths(lo, span, h, n):
    """CellLayout's fields as documented, for the grids used and for the refused ones (n_cells = 0) alike: the
    padded row lengths are NX = nx + 2 and NZ = nz + 2 (integers), and n_cells is (ny + 1) · NX · NZ or 0."""
    lo = np.array(lo)
    layout = cell_layout(lo, lo + np.array(span), h, n)
    assert layout.row_x == layout.nx + 2 and layout.row_z == layout.nz + 2
    assert isinstance(layout.row_x, int) and isinstance(layout.row_z, int)
    assert layout.n_cells in (0, (layout.ny + 1) * layout.row_x * layout.row_z)
    assert layout.inv_h == 1.0 / h and (layout.x0, layout.y0, layout.z0) == tuple(lo)
