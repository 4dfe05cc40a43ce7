"""Uniform grids with more cells than one counting pass handles: the two-pass (MSD radix) sort by cell number.

``counting_sort.radix_split`` cuts the cell numbers into at most ``MAX_BUCKETS`` (2048) buckets; the box grid
(``grid_pairs``, at most ~8n cells) sorts in two passes as soon as it has more than 2048 cells, and the sphere
grid (``sphere_pairs``, at most ~32n cells) when it has more than 2^19. The other properties' scenes are small,
so they only reach the one-pass case. Here: sparse scenes along a line (a rod: one cell across, many along)
with about 2 500 to 5 000 grid cells for boxes and about 600 000 for spheres, against independent oracles (numpy
all-pairs for boxes; scipy's cKDTree plus the exact sphere test for spheres).
"""
from __future__ import annotations

import numpy as np
from hypothesis import example, given, settings
from hypothesis import strategies as st
from scipy.spatial import cKDTree

from engine.broadphase import grid_pairs, sphere_pairs
from engine.broadphase.counting_sort import MAX_BUCKETS, radix_split


@example(1)
@example(2048)
@example(2049)
@example(4096)
@example(4097)
@example(2**40 + 1)
@given(st.one_of(st.integers(1, 2**45),
                 st.builds(lambda k, d: max(1, (MAX_BUCKETS << k) + d), st.integers(0, 30), st.integers(-2, 2))))
def test_radix_split_makes_at_most_max_buckets_and_no_more_shift_than_needed(n_cells):
    shift, n_buckets = (int(v) for v in radix_split(n_cells))
    assert shift >= 0
    assert 1 <= n_buckets <= MAX_BUCKETS  # the first pass's counters stay in cache
    assert n_buckets == ((n_cells - 1) >> shift) + 1  # every cell c < n_cells in a bucket c >> shift, none empty
    # the second pass's window (2^shift cells) is as small as the bucket cap allows
    assert shift == 0 or ((n_cells - 1) >> (shift - 1)) + 1 > MAX_BUCKETS


def brute_box_pairs(lo, hi):
    """numpy all-pairs of closed boxes (n, d): canonical (i < j), sorted."""
    overlap = np.all((lo[:, None, :] <= hi[None, :, :]) & (lo[None, :, :] <= hi[:, None, :]), axis=2)
    i, j = np.nonzero(np.triu(overlap, 1))
    return np.stack([i, j], axis=1).astype(np.int64)


def rod_of_boxes(seed, n):
    """n boxes along x over [0, 40 n], at most 0.6 wide in y and z (one cell across), a third of them near
    another box (so there are pairs), x sides up to 6 (across cell borders)."""
    rng = np.random.default_rng(seed)
    lo = np.column_stack([rng.uniform(0.0, 40.0 * n, n), rng.uniform(0.0, 0.3, (n, 2))])
    near = rng.random(n) < 1.0 / 3.0
    lo[near, 0] = lo[rng.integers(0, n, int(near.sum())), 0] + rng.uniform(-2.0, 2.0, int(near.sum()))
    side = np.column_stack([rng.uniform(0.0, 6.0, n), rng.uniform(0.0, 0.3, (n, 2))])
    return lo, lo + side


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(520, 700), st.sampled_from([None, 1.0]))
def test_grid_pairs_over_more_cells_than_one_counting_pass(seed, n, cell_size):
    """n >= 520 boxes over 40 n along x: with the default cell size (2 × the mean side, about 6: about 6.7 n
    cells) or 1.0 (doubled until at most 8 n cells, each doubling halving a rod's count: 5 n), the grid has more
    than 2048 cells."""
    lo, hi = rod_of_boxes(seed, n)
    np.testing.assert_array_equal(grid_pairs(lo, hi, cell_size), brute_box_pairs(lo, hi))


def exact_sphere_pairs(centers, radius):
    """cKDTree candidates within 2r (+ a relative 1e-9), kept when |d|² <= (2r)² and |d|_inf <= 2r."""
    s = 2.0 * radius
    candidates = cKDTree(centers).query_pairs(s * (1.0 + 1e-9), output_type="ndarray").reshape(-1, 2)
    candidates = np.sort(candidates, axis=1)
    diff = centers[candidates[:, 0]] - centers[candidates[:, 1]]
    keep = (np.einsum("ij,ij->i", diff, diff) <= s * s) & np.all(np.abs(diff) <= s, axis=1)
    kept = candidates[keep]
    return kept[np.lexsort((kept[:, 1], kept[:, 0]))].astype(np.int64)


@settings(max_examples=4, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(20_000, 20_400))
def test_sphere_pairs_over_more_cells_than_one_counting_pass(seed, n):
    """n >= 20 000 spheres of radius 0.5 along x over [0, 6e5], y and z in [0, 0.25]: cells of side 1 (the
    diameter; 0.7 × the mean spacing is below it), 600 000 cells along x, one across — above the 2^19 cells of
    the one-pass sort and below the grid's cap of 32 n, so the sphere grid sorts in two radix passes."""
    rng = np.random.default_rng(seed)
    centers = np.column_stack([rng.uniform(0.0, 6e5, n), rng.uniform(0.0, 0.25, (n, 2))])
    near = rng.random(n) < 0.2  # some spheres close to another one: pairs in the same and in adjacent cells
    centers[near, 0] = centers[rng.integers(0, n, int(near.sum())), 0] + rng.uniform(-1.5, 1.5, int(near.sum()))
    centers[:, 0] = np.clip(centers[:, 0], 0.0, 6e5)
    centers[0] = (0.0, 0.0, 0.0)  # the scene's extent: [0, 6e5] × [0, 0.25]²
    centers[1] = (6e5, 0.25, 0.25)
    got = sphere_pairs(centers, 0.5)
    expected = exact_sphere_pairs(centers, 0.5)
    assert expected.shape[0] > 100  # the scene has pairs to find
    np.testing.assert_array_equal(got, expected)
