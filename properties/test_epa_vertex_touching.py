"""Polytopes touching at one shared vertex (engine/narrowphase/epa.py): GJK ends on the origin as a one-point
simplex of the Minkowski difference (or "apart" at distance exactly 0), and EPA's touching branch answers. Depth
is 0 (to round-off) and the normal a unit vector along which M = A − B does not extend (max over every a − b of
(a − b)·n <= tol: a normal of a plane through the common vertex that separates the two hulls), from
``epa_penetration``, ``epa_penetration_pairs`` and ``contact_feature`` alike. The oracle is that definition,
evaluated on all n·m differences.

The pinned examples are pairs (found by a random search) on which none of the cheap candidate normals of
``_touching_normal_at_vertex`` (centroid direction, the six axes) applies, so the normal comes from the normal
cone search (``_normal_cone_direction``); before it, such pairs got an arbitrary (1, 0, 0).

Crossing segments (a flat Minkowski difference) get the normal of their common plane at every scale, down to
2^-200 (the flatness test once compared an area with a length, and tiny segments got an in-plane normal).
"""
from __future__ import annotations

import numpy as np
from hypothesis import example, given
from hypothesis import strategies as st

from engine.narrowphase import contact_feature, epa_penetration, epa_penetration_pairs, pack_point_sets
from engine.narrowphase.epa import EPA_TOL

PINNED = [
    ([[0.48194538850678587, -0.2385536065733667, 0.9577587029597641],
      [0.12856194339207694, -0.4989121804696033, 0.7107033767162413],
      [-1.1690703118103714, -1.3793621954925337, 0.5819956154484254]],
     [[0.48194538850678587, -0.2385536065733667, 0.9577587029597641],
      [0.7380992313199981, -0.163580752355007, 0.6298005703088336],
      [0.3621238688909334, -0.47291219537382756, 0.28203494639624116]]),
    ([[0.0, 0.0, 0.0], [-0.0039361289997376855, 0.10880457014049609, -0.5528164436811371],
      [0.5443835585316767, -0.48040806601906694, 0.8058257586738125], [-1.4226609829743, 0.8411887484820266,
      0.1239432935454555], [1.1935159979948902, -0.5663104363678635, -0.8331769706475417]],
     [[0.0, 0.0, 0.0], [1.0817002874810455, -0.5592375916399077, -0.5160200642245345],
      [0.524849709104812, -0.19504606737245336, -0.6583736155500676],
      [-0.45800880023538926, 0.2967648627917175, -0.1112096091234319]]),
    ([[0.0, 0.0, 0.0], [0.58462766567171, 0.0007145431080237971, 0.186176468910681],
      [-0.09204497347559823, -0.3655750761554443, -0.1395126776152098],
      [0.12523895453112052, 0.2500880178785869, -0.04558635911339709]],
     [[0.0, 0.0, 0.0], [-1.1438370695506328, -1.2420893028641775, -0.492377148346423],
      [-0.4117295413266132, 0.9500990469692288, -0.03523452868401293]]),
]


@st.composite
def vertex_touching_pairs(draw):
    """A and B share the vertex 0 and lie on either side of a random plane through it (then both shifted)."""
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    u = rng.normal(size=3)
    u /= np.linalg.norm(u)
    e = np.linalg.svd(u[None, :])[2][1:]
    na, nb = draw(st.integers(1, 5)), draw(st.integers(1, 5))
    eps = draw(st.floats(1e-3, 1.0))
    a = np.r_[[np.zeros(3)], rng.normal(size=(na, 2)) @ e - eps * np.abs(rng.normal(size=(na, 1))) * u]
    b = np.r_[[np.zeros(3)], rng.normal(size=(nb, 2)) @ e + eps * np.abs(rng.normal(size=(nb, 1))) * u]
    shift = np.array(draw(st.tuples(*[st.integers(-3, 3)] * 3)), dtype=np.float64)
    return (a + shift).tolist(), (b + shift).tolist()


def _extent_along(a, b, normal):
    """max over the Minkowski difference of (a − b)·n: <= 0 (to tolerance) iff M does not extend along n."""
    return float(((a[:, None, :] - b[None, :, :]) @ normal).max())


@example(PINNED[0])
@example(PINNED[1])
@example(PINNED[2])
@given(vertex_touching_pairs())
def test_vertex_touching_pairs_have_depth_zero_and_a_touching_normal(pair):
    a, b = (np.array(x) for x in pair)
    scale = max(np.abs(a).max(), np.abs(b).max(), 1.0)
    tol = 10 * EPA_TOL * scale
    depth, normal = epa_penetration(a, b)
    assert 0.0 <= depth <= 1e-12 * scale  # 0 up to EPA's round-off
    assert np.all(np.isfinite(normal)) and abs(np.linalg.norm(normal) - 1.0) <= 1e-12, normal
    assert _extent_along(a, b, normal) <= tol, normal
    points, offsets = pack_point_sets([a, b])
    depths, normals = epa_penetration_pairs(points, offsets, [[0, 1]])
    assert depths[0] == depth and np.array_equal(normals[0], normal)
    contact = contact_feature(a, b)
    assert abs(contact.separation) <= 1e-12 * scale
    assert abs(np.linalg.norm(contact.normal) - 1.0) <= 1e-12, contact.normal
    assert _extent_along(a, b, contact.normal) <= tol, contact.normal


@given(st.integers(-200, 40), st.integers(0, 2**32 - 1))
def test_crossing_segments_touch_along_their_plane_normal_at_every_scale(k, seed):
    """Two segments crossing at their midpoints, scaled by 2^k: M is a flat parallelogram around the origin,
    depth 0, and the normal is ± the unit normal of the segments' plane (the only direction along which M does
    not extend), whatever the scale."""
    rng = np.random.default_rng(seed)
    u, w = rng.normal(size=(2, 3))
    plane = np.cross(u, w)
    plane /= np.linalg.norm(plane)
    s = 2.0 ** k
    a = s * np.array([-u, u])
    b = s * np.array([-w, w])
    depth, normal = epa_penetration(a, b)
    assert depth <= 1e-12 * s
    assert abs(abs(normal @ plane) - 1.0) <= 1e-9, (normal, plane)
    assert abs(abs(contact_feature(a, b).normal @ plane) - 1.0) <= 1e-9
