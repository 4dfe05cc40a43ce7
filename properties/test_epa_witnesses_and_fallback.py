"""EPA's witness points and its exact fallback (engine/narrowphase/epa.py), against independent oracles.

- Witnesses: for overlapping hulls, ``epa_penetration(..., witnesses=True)`` returns the deepest points
  p_A of A and p_B of B: p_A − p_B is the origin's projection on M's closest face, i.e. ``depth * normal``, and
  each lies on its own hull (Qhull's facet planes: signed distance <= round-off).
- The exact fallback (``minkowski_fallback``: Qhull on the Minkowski difference, what the public functions
  return where EPA folds on round-off) gives the same depth and normal as EPA on hulls in general position, and,
  when M is flat (two coplanar sets), depth 0 along the normal of their plane with witnesses taken from the
  inputs' rows. It is reached through the public functions only on rare degenerate inputs, hence tested here
  directly: the public answer on those inputs is this function's.
"""
from __future__ import annotations

import numpy as np
from hypothesis import assume, given
from hypothesis import strategies as st

from engine.narrowphase import epa_penetration
from engine.narrowphase.penetration import minkowski_fallback
from properties.strategies.narrow import exact_penetration_depth, hull_signed_distance, rotations, vectors

seeds = st.integers(0, 2**32 - 1)


def _overlapping_clouds(seed: int, n_a: int, n_b: int, offset: np.ndarray):
    rng = np.random.default_rng(seed)
    a = rng.normal(size=(n_a, 3))
    b = rng.normal(size=(n_b, 3)) * rng.uniform(0.3, 2.0) + 0.4 * offset
    return a, b


@given(seeds, st.integers(4, 16), st.integers(4, 16), st.tuples(*[st.floats(-1, 1)] * 3).map(np.array))
def test_witnesses_differ_by_depth_times_normal_and_lie_on_their_hulls(seed, n_a, n_b, offset):
    a, b = _overlapping_clouds(seed, n_a, n_b, offset)
    exact = exact_penetration_depth(a, b)
    assume(exact > 1e-3)
    depth, normal, wa, wb = epa_penetration(a, b, witnesses=True)
    scale = max(np.abs(a).max(), np.abs(b).max(), 1.0)
    assert abs(depth - exact) <= 1e-9 * scale
    assert np.allclose(wa - wb, depth * normal, atol=1e-9 * scale), (wa - wb, depth * normal)
    assert hull_signed_distance(a, wa) <= 1e-9 * scale
    assert hull_signed_distance(b, wb) <= 1e-9 * scale


@given(seeds, st.integers(4, 16), st.integers(4, 16), st.tuples(*[st.floats(-1, 1)] * 3).map(np.array))
def test_exact_fallback_agrees_with_epa_in_general_position(seed, n_a, n_b, offset):
    a, b = _overlapping_clouds(seed, n_a, n_b, offset)
    exact = exact_penetration_depth(a, b)
    assume(exact > 1e-3)
    depth, normal = epa_penetration(a, b)
    f_depth, f_normal, f_a, f_b = minkowski_fallback(a, b)
    assert abs(f_depth - depth) <= 1e-9 * max(np.abs(a).max(), np.abs(b).max(), 1.0)
    assert np.allclose(f_normal, normal, atol=1e-6)
    assert abs(np.linalg.norm(f_normal) - 1.0) <= 1e-12
    # the fallback's witnesses are the supporting vertices of A and B along the normal
    assert any(np.array_equal(f_a, p) for p in a) and any(np.array_equal(f_b, p) for p in b)
    assert np.isclose(f_a @ f_normal, (a @ f_normal).max()) and np.isclose(f_b @ f_normal, (b @ f_normal).min())


@given(seeds, st.integers(3, 10), st.integers(3, 10), rotations(), vectors)
def test_exact_fallback_on_coplanar_sets_is_touching_along_their_plane_normal(seed, n_a, n_b, rot, shift):
    """Two overlapping polygons in one plane: M is flat (Qhull refuses it), the origin lies on M's boundary,
    depth 0; the answer's normal is the plane's (either sign), and its witnesses are rows of A and B."""
    rng = np.random.default_rng(seed)
    flat_a = np.c_[rng.normal(size=(n_a, 2)), np.zeros(n_a)]
    flat_b = np.c_[rng.normal(size=(n_b, 2)) * 0.5, np.zeros(n_b)]
    a = flat_a @ rot.T + shift
    b = flat_b @ rot.T + shift
    depth, normal, wa, wb = minkowski_fallback(a, b)
    assert depth == 0.0
    assert abs(abs(normal @ rot[:, 2]) - 1.0) <= 1e-9, (normal, rot[:, 2])
    assert any(np.array_equal(wa, p) for p in a) and any(np.array_equal(wb, p) for p in b)
