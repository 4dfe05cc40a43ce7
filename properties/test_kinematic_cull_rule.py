"""The kinematic culls keep exactly the pairs of their documented rule (engine/broadphase/kinematic.py), on
integer scenes where every product and sum is exact, so touching (|p| = r_i + r_j) and a relative velocity
that neither closes nor opens (p·w = 0) occur exactly and often:

- ``cull_separating_sphere_pairs`` drops (i, j) exactly when |p|² > (r_i + r_j)² and p·w > 0 (p = c_j − c_i,
  w = v_j − v_i): touching spheres are kept whatever their motion, apart spheres whose p·w is 1 are dropped;
- ``cull_separating_box_pairs`` drops a pair exactly when on some axis one box lies strictly above the other
  and their relative velocity along it does not bring them closer (touching boxes are kept).

The oracle is the rule written in numpy on all pairs; the culls get every pair in a shuffled, mixed order.
"""
from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from engine.broadphase import cull_separating_box_pairs, cull_separating_sphere_pairs


@st.composite
def integer_scenes(draw, d=3):
    n = draw(st.integers(2, 8))
    ints = st.integers(-3, 3)
    centers = draw(arrays(np.int64, (n, d), elements=ints)).astype(float)
    velocities = draw(arrays(np.int64, (n, d), elements=st.integers(-2, 2))).astype(float)
    radii = draw(arrays(np.int64, (n,), elements=st.integers(0, 2))).astype(float)
    i, j = np.triu_indices(n, 1)
    pairs = np.stack([i, j], axis=1)
    order = draw(st.permutations(range(len(pairs))))
    flip = draw(arrays(np.bool_, (len(pairs),)))
    shown = pairs[list(order)]
    shown[flip] = shown[flip][:, ::-1]
    return centers, velocities, radii, pairs, shown


@given(integer_scenes())
def test_sphere_cull_keeps_exactly_the_pairs_not_apart_and_separating(scene):
    c, v, r, pairs, shown = scene
    i, j = pairs[:, 0], pairs[:, 1]
    p, w = c[j] - c[i], v[j] - v[i]
    apart = np.einsum("ij,ij->i", p, p) > (r[i] + r[j]) ** 2
    dropped = apart & (np.einsum("ij,ij->i", p, w) > 0.0)
    np.testing.assert_array_equal(cull_separating_sphere_pairs(shown, c, r, v), pairs[~dropped])


@given(integer_scenes(), st.sampled_from([1, 2, 3]))
def test_box_cull_keeps_exactly_the_pairs_not_apart_and_opening_on_an_axis(scene, d):
    c, v, r, pairs, shown = scene
    lo, hi, v = c[:, :d] - r[:, None], c[:, :d] + r[:, None], v[:, :d]
    i, j = pairs[:, 0], pairs[:, 1]
    w = v[j] - v[i]
    dropped = np.any(((lo[j] > hi[i]) & (w >= 0.0)) | ((lo[i] > hi[j]) & (w <= 0.0)), axis=1)
    np.testing.assert_array_equal(cull_separating_box_pairs(shown, lo, hi, v), pairs[~dropped])
