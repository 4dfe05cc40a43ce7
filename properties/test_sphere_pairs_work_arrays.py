"""sphere_pairs reuses its work arrays between calls (engine.broadphase.pairs' work arrays: keys, index, sorted
centres): a call must not see what an earlier, larger call left in them. A sequence of scenes of decreasing and
increasing size, the larger ones with their spheres in decreasing order along every axis (so the sorted work
arrays start with the largest ids), each answer equal to the numpy oracle's."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from engine.broadphase import sphere_pairs
from properties.test_broadphase_spheres import brute_sphere_pairs


def _scene(rng, n):
    centers = rng.uniform(0.0, 2.0 * n ** (1 / 3), (n, 3))
    centers = centers[np.argsort(-centers.sum(axis=1))]  # the first sorted keys belong to the largest ids
    return centers, rng.uniform(0.2, 0.6, n)


@pytest.mark.parametrize("method", ["grid", "sap", "tree", "octree", "brute"])
@settings(max_examples=5, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), sizes=st.lists(st.integers(2, 300), min_size=2, max_size=4))
def test_sphere_pairs_do_not_depend_on_earlier_calls(method, seed, sizes):
    rng = np.random.default_rng(seed)
    for n in sorted(sizes, reverse=True) + sorted(sizes):
        centers, radii = _scene(rng, n)
        np.testing.assert_array_equal(sphere_pairs(centers, radii, method=method), brute_sphere_pairs(centers, radii))
