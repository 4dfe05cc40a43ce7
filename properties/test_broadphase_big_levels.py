"""Big levels: dense clusters far apart, a few huge boxes among many small ones, everything on one plane.

The grids cap the cells they store in a table (8n boxes, 32n spheres); before, far-apart clusters made the cells
so coarse that a whole cluster shared one cell and the work became quadratic in the cluster's size. Now the
grids and the sweep-and-prune columns keep fine cells and store only the occupied ones. Here: every method's
pairs equal brute force on those scenes (``engine.workloads``' generators, small and seeded by Hypothesis), and
the deterministic work count (``return_tests=True``) stays linear — far below the quadratic cliff's n²/8.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from engine.broadphase import BROAD_PHASES, find_pairs, sphere_pairs
from engine.broadphase.sphere_columns import column_layout
from engine.workloads import big_level_boxes, clustered_spheres, huge_among_small_boxes, planar_spheres


def brute_sphere_pairs(c, r):
    d2 = ((c[:, None, :] - c[None, :, :]) ** 2).sum(axis=2)
    i, j = np.nonzero(np.triu(d2 <= (2 * r) ** 2, k=1))
    return np.stack([i, j], axis=1).astype(np.int64)


@st.composite
def big_level_spheres(draw):
    kind = draw(st.sampled_from(["clusters", "plane"]))
    n = draw(st.integers(2, 600))
    seed = draw(st.integers(0, 2**16))
    if kind == "plane":
        return planar_spheres(n, draw(st.sampled_from([0.1, 0.3, 0.6])), seed=seed)
    return clustered_spheres(n, draw(st.sampled_from([0.05, 0.2, 0.4])), clusters=draw(st.integers(1, 4)),
                             separation=draw(st.sampled_from([3.0, 1e3, 1e6, 1e7])), seed=seed)


@settings(max_examples=40)
@given(big_level_spheres(), st.sampled_from(BROAD_PHASES))
def test_box_methods_equal_brute_force_on_big_levels(scene, method):
    centres, radius = scene
    lo, hi = centres - radius, centres + radius
    np.testing.assert_array_equal(find_pairs(lo, hi, method), find_pairs(lo, hi, "brute"))


@settings(max_examples=40)
@given(big_level_spheres())
def test_sphere_pairs_equal_brute_force_on_big_levels(scene):
    centres, radius = scene
    np.testing.assert_array_equal(sphere_pairs(centres, radius), brute_sphere_pairs(centres, radius))


@settings(max_examples=20)
@given(st.integers(10, 800), st.integers(1, 6), st.integers(0, 2**16))
def test_huge_boxes_among_small_ones_equal_brute_force(n, huge, seed):
    lo, hi = huge_among_small_boxes(n, huge=min(huge, n), seed=seed)
    expected = find_pairs(lo, hi, "brute")
    for method in BROAD_PHASES:
        np.testing.assert_array_equal(find_pairs(lo, hi, method), expected)


#: box tests per box allowed on the 4,000-box big-level scenes (measured: sap <= 7, grid <= 15, octree and tree
#: <= 70 on all three; the quadratic cliff of two clusters in one cell each makes about n / 4 = 1,000 per box)
TESTS_PER_BOX = {"sap": 25.0, "grid": 45.0, "octree": 150.0, "tree": 150.0}


@pytest.mark.parametrize("scene", ["clusters", "huge", "plane"])
@pytest.mark.parametrize("method", sorted(TESTS_PER_BOX))
def test_work_stays_linear_on_big_levels(scene, method):
    n = 4_000
    lo, hi = big_level_boxes(scene, n)
    pairs, tests = find_pairs(lo, hi, method, return_tests=True)
    assert tests <= TESTS_PER_BOX[method] * n
    assert len(pairs) > 0


@pytest.mark.parametrize("separation", [1e3, 1e6])
def test_sphere_columns_stay_fine_for_far_apart_clusters(separation):
    # the columns keep the asked side (one diameter) instead of growing until a cluster fits in one column
    centres, radius = clustered_spheres(5_000, clusters=2, separation=separation)
    layout = column_layout(centres.min(axis=0), centres.max(axis=0), 2 * radius, centres.shape[0])
    assert 1.0 / layout.inv_h == 2 * radius
    assert not layout.dense
