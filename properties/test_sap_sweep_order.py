"""SAP's sweep order (engine/broadphase/sweep_and_prune.py, ``sweep_order``): the boxes are radix-sorted by
31-bit integer keys of their lower ends on the sweep axis, a monotone map that is not one to one, then every run
of equal keys is put in the exact order of its values. The sweep relies on that exact order: it runs while
b_q <= e_p and makes no test on the sweep axis. Here a cluster of boxes far narrower than one key step (an
outlier 1e6 away stretches the key range) shares a single key; the order must be the exact stable order of the
values and the pairs must be brute force's.
"""
from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from engine.broadphase import brute_force_pairs, sap_pairs
from engine.broadphase.sweep_and_prune import sweep_order


def narrow_cluster(seed, axis, n):
    """n − 1 boxes whose lower ends on ``axis`` lie within 1e-7 (one key step is about 5e-4 here), of lengths up
    to 1e-7 on that axis, spread over [0, 3] on the others, and one outlier box at 1e6 on ``axis``."""
    rng = np.random.default_rng(seed)
    lo = rng.uniform(0.0, 3.0, (n, 3))
    lo[:, axis] = rng.uniform(0.0, 1e-7, n)
    lo[rng.random(n) < 0.2, axis] = 5e-8  # exact ties among the distinct values
    lo[-1, axis] = 1e6
    size = rng.uniform(0.0, 1.0, (n, 3))
    size[:, axis] = rng.uniform(0.0, 1e-7, n)
    return lo, lo + size


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), axis=st.integers(0, 2), n=st.integers(3, 400))
def test_sweep_order_is_exact_inside_a_run_of_equal_keys(seed, axis, n):
    lo, hi = narrow_cluster(seed, axis, n)
    order = sweep_order(lo, hi, axis)
    np.testing.assert_array_equal(order, np.argsort(lo[:, axis], kind="stable"))
    np.testing.assert_array_equal(sap_pairs(lo, hi, axis=axis), brute_force_pairs(lo, hi))
