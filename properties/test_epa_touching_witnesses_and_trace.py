"""EPA's answers for hulls that only touch, and ``trace_epa`` (engine/narrowphase/epa.py).

- **Touching witnesses.** When GJK ends with the origin on the boundary of M = A − B (a shared vertex, edge or
  face; or flat hulls in one plane), ``epa_penetration(..., witnesses=True)`` returns depth 0 and witness points
  that are the same point (p_A − p_B = depth · normal = 0) lying on both hulls: the origin's barycentric
  weights in GJK's final simplex applied to the simplex's vertices of A and of B. Checked on hulls with small
  integer coordinates sharing points, in 3-D and all in the plane z = 0; membership of a hull by non-negative
  least squares (scipy's ``nnls``), independent of the engine.
- **trace_epa** shows the polytope EPA stops on: its last step's distance and normal are the depth and normal it
  returns, the same as ``epa_penetration``'s; every vertex of every step is a point of M (a difference of a
  point of A and a point of B); the distances of the closest faces never decrease (each expansion replaces the
  closest face by faces farther from the origin, Ericson 9.5 / van den Bergen 4.3.3).
"""
from __future__ import annotations

import numpy as np
from hypothesis import assume, given
from hypothesis import strategies as st
from scipy.optimize import nnls
from scipy.spatial.transform import Rotation

from engine.narrowphase import epa_penetration
from engine.narrowphase.epa import trace_epa


def hull_distance(points: np.ndarray, q: np.ndarray) -> float:
    """Distance from q to the convex hull of points (n, 3): min |Σ λ_k p_k − q| over λ >= 0, Σ λ = 1 (the sum
    enforced by a heavily weighted row)."""
    w = 1e3 * (1.0 + np.abs(points).max())
    matrix = np.vstack([points.T, np.full(points.shape[0], w)])
    _, residual = nnls(matrix, np.append(q, w))
    return residual


coordinate = st.integers(-3, 3).map(float)
point = st.lists(coordinate, min_size=3, max_size=3)


@given(shared=st.lists(point, min_size=1, max_size=3), rest_a=st.lists(point, min_size=1, max_size=3),
       rest_b=st.lists(point, min_size=1, max_size=3), flat=st.booleans(), shared_first=st.booleans())
def test_touching_witnesses_are_one_point_on_both_hulls(shared, rest_a, rest_b, flat, shared_first):
    a = np.array(shared + rest_a if shared_first else rest_a + shared)
    b = np.array(rest_b + shared)
    if flat:  # every point in the plane z = 0: M is flat, the origin on its boundary
        a[:, 2] = 0.0
        b[:, 2] = 0.0
    depth, normal, pa, pb = epa_penetration(a, b, witnesses=True)
    assume(depth == 0.0)  # they share points: touching or overlapping; keep the touching ones
    assert np.isclose(np.linalg.norm(normal), 1.0)
    assert np.abs(pa - pb).max() <= 1e-12, (pa, pb)
    assert hull_distance(a, pa) <= 1e-8 and hull_distance(b, pb) <= 1e-8, (pa, pb)


# hulls touching along a shared edge and a shared face: GJK's final simplex is then a segment or a triangle
EDGE_AND_FACE = [
    ([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [1.0, 1.0, 0.0], [1.0, 0.5, 1.0]],
     [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [1.0, -1.0, 0.0], [1.0, -0.5, 1.0]]),
    ([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.5, 0.5, 1.0]],
     [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.5, 0.5, -1.0]]),
    ([[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], [[0.0, 0.0, 0.0], [1.0, -1.0, 0.0], [-1.0, -1.0, 0.0]]),
]


@given(case=st.sampled_from(EDGE_AND_FACE), seed=st.integers(0, 2**32 - 1), shift=st.integers(-4, 4),
       swap=st.booleans())
def test_witnesses_of_hulls_sharing_an_edge_or_a_face(case, seed, shift, swap):
    a, b = (np.array(case[1]), np.array(case[0])) if swap else (np.array(case[0]), np.array(case[1]))
    q = Rotation.random(random_state=seed).as_matrix()
    a, b = a @ q.T + shift, b @ q.T + shift
    depth, normal, pa, pb = epa_penetration(a, b, witnesses=True)
    assert depth <= 1e-12
    assert np.abs(pa - pb).max() <= 1e-9, (pa, pb)
    assert hull_distance(a, pa) <= 1e-8 and hull_distance(b, pb) <= 1e-8, (pa, pb)


@given(seed=st.integers(0, 2**32 - 1), n_a=st.integers(4, 12), n_b=st.integers(4, 12),
       offset=st.tuples(*[st.floats(-0.6, 0.6)] * 3))
def test_trace_epa_ends_on_the_answer_of_epa_penetration(seed, n_a, n_b, offset):
    rng = np.random.default_rng(seed)
    a = rng.normal(size=(n_a, 3))
    b = rng.normal(size=(n_b, 3)) + offset
    depth, normal = epa_penetration(a, b)
    assume(depth > 1e-6)
    try:
        steps, traced_depth, traced_normal = trace_epa(a, b)
    except ValueError:  # the hulls only touch for GJK (no polytope): nothing to trace
        assume(False)
    assert traced_depth == depth and np.array_equal(traced_normal, normal)
    last = steps[-1]
    assert abs(last.distance - depth) <= 1e-12 * (1.0 + depth) and np.allclose(last.normal, normal, atol=1e-12)
    m = (a[:, None, :] - b[None, :, :]).reshape(-1, 3)
    for step in steps:
        gaps = np.abs(step.vertices[:, None, :] - m[None, :, :]).max(axis=2).min(axis=1)
        assert gaps.max() <= 1e-12, gaps
        assert 0 <= step.closest_face < step.faces.shape[0]
        assert np.isclose(np.linalg.norm(step.normal), 1.0)
    distances = [s.distance for s in steps]
    assert all(d1 >= d0 - 1e-12 for d0, d1 in zip(distances, distances[1:])), distances
