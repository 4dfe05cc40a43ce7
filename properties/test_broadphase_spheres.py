"""sphere_pairs: equals scipy's cKDTree.query_pairs for equal radii, brute force for unequal radii; the
broad phase of bounding boxes is a superset of the exact sphere pairs."""
from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from scipy.spatial import cKDTree

from engine.broadphase import BROAD_PHASES, find_pairs, sphere_pairs
from properties.strategies.boxes import sphere_scenes


def brute_sphere_pairs(centers, radii):
    """Independent reference: numpy all-pairs |c_i − c_j|² <= (r_i + r_j)² and |c_i − c_j|_inf <= r_i + r_j,
    each pair's difference and radius sum first scaled by the power of two that brings their largest magnitude
    into [0.5, 1) (exact), so that squares of tiny values (below ~1e-154) do not underflow to zero."""
    c = np.asarray(centers, dtype=float)
    n = c.shape[0]
    r = np.broadcast_to(np.asarray(radii, dtype=float), (n,))
    diff = c[:, None, :] - c[None, :, :]
    s = r[:, None] + r[None, :]
    exponent = np.frexp(np.maximum(np.abs(diff).max(axis=2, initial=0.0), s))[1]
    diff = np.ldexp(diff, -exponent[:, :, None])
    s = np.ldexp(s, -exponent)
    d2 = np.einsum("ijk,ijk->ij", diff, diff)
    close = np.all(np.abs(diff) <= s[:, :, None], axis=2)
    i, j = np.nonzero(np.triu((d2 <= s * s) & close, 1))
    return np.stack([i, j], axis=1).astype(np.int64)


def away_from_ties(centers, radius, rel=1e-9):
    """True when no pair distance is within round-off of the contact distance 2r (so cKDTree must agree)."""
    c = np.asarray(centers)
    if len(c) < 2:
        return True
    d = np.sqrt(((c[:, None, :] - c[None, :, :]) ** 2).sum(-1))
    return not np.any(np.abs(d - 2 * radius) <= rel * (1.0 + np.abs(c).max()))


@pytest.mark.parametrize("method", BROAD_PHASES)
@settings(max_examples=60)
@given(data=st.data())
def test_equal_radii_match_ckdtree(method, data):
    centers, radius = data.draw(sphere_scenes(d=3, equal=True))
    got = sphere_pairs(centers, radius, method=method)
    if away_from_ties(centers, radius):
        expected = cKDTree(centers).query_pairs(2 * radius, output_type="ndarray") if len(centers) else None
        expected = np.zeros((0, 2), np.int64) if expected is None else expected
        expected = expected[np.lexsort((expected[:, 1], expected[:, 0]))] if len(expected) else expected
        np.testing.assert_array_equal(got, expected.reshape(-1, 2))
    np.testing.assert_array_equal(got, brute_sphere_pairs(centers, radius))


@pytest.mark.parametrize("method", BROAD_PHASES)
@pytest.mark.parametrize("d", [1, 2, 3])
@settings(max_examples=40)
@given(data=st.data())
def test_unequal_radii_match_brute_force(method, d, data):
    centers, radii = data.draw(sphere_scenes(d=d, equal=False))
    np.testing.assert_array_equal(sphere_pairs(centers, radii, method=method), brute_sphere_pairs(centers, radii))


@st.composite
def touching_scenes(draw):
    """Spheres placed exactly at contact distance along an axis (integer data: exact arithmetic)."""
    n = draw(st.integers(2, 30))
    cells = draw(st.lists(st.tuples(st.integers(-5, 5), st.integers(-5, 5), st.integers(-5, 5)),
                          min_size=n, max_size=n))
    return np.array(cells, dtype=float) * 2.0, 1.0  # neighbours at distance 2 = r_i + r_j: touching


@settings(max_examples=40)
@given(touching_scenes())
def test_exact_contact_counts(scene):
    centers, radius = scene
    expected = brute_sphere_pairs(centers, radius)
    for method in BROAD_PHASES:
        np.testing.assert_array_equal(sphere_pairs(centers, radius, method=method), expected)


# spheres near 1e-323 (denormal radii and centres) and one far away: the grid's cells are denormal-sized and the
# cell count along z reached 2^63, past int64 (the grid then missed the touching pair 0-1)
DENORMAL_SCENE = (np.array([[-5e-324, 1e-310, -1e-323], [-5e-324, 1e-310, -5e-324], [5e-324, 0.0, -1.0]]),
                  np.array([0.0, 1e-323, 0.0]))


# spheres whose distance exceeds their radius sum by 2.2e-311, which the sphere test's subtraction rounds away:
# they are reported touching, and their boxes c ± r are exactly 2.2e-311 apart (found by the mutation run)
ROUNDOFF_SCENE = (np.array([[-2.22507386e-311, 1.13823417, -2.22507386e-311], [-2.22507386e-311] * 3]),
                  np.array([1.13823417, 0.0]))


@pytest.mark.parametrize("method", BROAD_PHASES)
@settings(max_examples=40)
@example(scene=DENORMAL_SCENE)
@example(scene=ROUNDOFF_SCENE)
@given(scene=sphere_scenes(d=3))
def test_box_broad_phase_is_a_superset_of_sphere_pairs(method, scene):
    centers, radii = scene
    r = np.broadcast_to(np.asarray(radii, dtype=float), (len(centers),))
    boxes = find_pairs(centers - r[:, None], centers + r[:, None], method)
    exact = sphere_pairs(centers, radii)
    box_set = {tuple(p) for p in boxes.tolist()}
    missed = [(i, j) for i, j in exact.tolist() if (i, j) not in box_set]
    # c ± r rounds monotonically, so spheres that truly touch have overlapping boxes; a pair the sphere test
    # calls touching may still be truly apart by its round-off (its distance rounded down to the radius sum)
    assert all(_truly_apart(centers[i], centers[j], r[i] + r[j]) for i, j in missed), missed


def _truly_apart(ci, cj, s):
    """True when |ci − cj| > s in exact arithmetic (rationals) and by no more than the round-off of the sphere
    test (1e-14 of the coordinates' magnitude)."""
    d2 = sum((Fraction(a) - Fraction(b)) ** 2 for a, b in zip(ci.tolist(), cj.tolist()))
    gap = float(np.linalg.norm(ci - cj)) - s
    return d2 > Fraction(s) ** 2 and gap <= 1e-14 * (np.abs(ci).max() + np.abs(cj).max() + s)


def test_sphere_validation():
    c = np.zeros((3, 3))
    with pytest.raises(ValueError, match=r"radii\[1\]"):
        sphere_pairs(c, np.array([1.0, -1.0, 1.0]))
    with pytest.raises(ValueError, match="radii"):
        sphere_pairs(c, -1.0)
    with pytest.raises(ValueError, match="radii"):
        sphere_pairs(c, np.ones(2))
    bad = c.copy()
    bad[2, 1] = np.inf
    with pytest.raises(ValueError, match=r"centers\[2, 1\]"):
        sphere_pairs(bad, 1.0)
    with pytest.raises(ValueError, match="method"):
        sphere_pairs(c, 1.0, method="kd")
    assert sphere_pairs(np.zeros((0, 3)), 1.0).shape == (0, 2)
    assert sphere_pairs(c, 0.0).tolist() == [[0, 1], [0, 2], [1, 2]]  # identical points touch


@st.composite
def dense_scenes(draw):
    """Many spheres (up to 300) packed so that every neighbour direction of the grid holds touching pairs."""
    n = draw(st.integers(2, 300))
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    side = draw(st.sampled_from([3.0, 8.0, 15.0]))
    centers = rng.uniform(-side, side, size=(n, 3)) + draw(st.sampled_from([0.0, -1e4, 1e6]))
    if draw(st.booleans()):
        return centers, draw(st.floats(0.05, 1.5))
    return centers, rng.uniform(0.0, draw(st.floats(0.1, 2.0)), size=n)


@pytest.mark.parametrize("method", BROAD_PHASES)
@settings(max_examples=40)
@given(dense_scenes())
def test_dense_scenes_match_brute_force(method, scene):
    centers, radii = scene
    np.testing.assert_array_equal(sphere_pairs(centers, radii, method=method), brute_sphere_pairs(centers, radii))


@settings(max_examples=60)
@given(sphere_scenes(d=3, min_n=2))
def test_incremental_sap_then_exact_filter_equals_sphere_pairs(scene):
    # the gas's per-frame path: incremental SAP on the spheres' boxes, then the exact sphere test
    from engine.broadphase import IncrementalSAP, spheres_overlap_pairs

    centers, radii = scene
    r = np.broadcast_to(np.asarray(radii, dtype=float), (len(centers),))
    sap = IncrementalSAP(centers - r[:, None] * (1 + 1e-12) - 1e-9, centers + r[:, None] * (1 + 1e-12) + 1e-9)
    np.testing.assert_array_equal(spheres_overlap_pairs(centers, radii, sap.pairs()), sphere_pairs(centers, radii))


@pytest.mark.parametrize("method", BROAD_PHASES)
@pytest.mark.parametrize("exponent", [-690, -1000, 0, 400])
def test_spheres_far_below_one_are_tested_at_scale(method, exponent):
    """Squared distances of spheres near 1e-206 underflow to 0: the test is made at scale. A 3-4-5 triangle
    scaled by 2^exponent: radii 2.5 + 2.5 touch at distance 5; radii 2.4 + 2.5 do not (a found pair there is
    the underflow bug)."""
    c = np.ldexp(np.array([[0.0, 0.0, 0.0], [3.0, 4.0, 0.0]]), exponent)
    touching = np.ldexp(np.array([2.5, 2.5]), exponent)
    apart = np.ldexp(np.array([2.4, 2.5]), exponent)
    assert sphere_pairs(c, touching, method=method).tolist() == [[0, 1]]
    assert sphere_pairs(c, apart, method=method).tolist() == []
    assert brute_sphere_pairs(c, apart).tolist() == [] and brute_sphere_pairs(c, touching).tolist() == [[0, 1]]


# integer points at distance exactly s (a² + b² + c² = s²) whose at-scale test, divided by s itself, rounds to
# "apart" (1/17, 12/17 are not dyadic); divided by a power of two the test is exact again
PYTHAGOREAN_QUADRUPLES = [(1, 12, 12, 17), (0, 8, 15, 17), (2, 5, 14, 15), (1, 32, 8, 33)]


@pytest.mark.parametrize("method", BROAD_PHASES)
@pytest.mark.parametrize("exponent", [-1000, -690, -541, -540, -520, 0, 400])
def test_spheres_exactly_touching_touch_at_every_scale(method, exponent):
    """Spheres whose centres are exactly r_0 + r_1 apart touch, at every scale: the at-scale test (magnitudes
    below 1e-150; above 1e150 sphere_pairs refuses its input) decides as the plain one does at unit scale, and
    as the numpy oracle (which scales by powers of two)."""
    for a, b, c, s in PYTHAGOREAN_QUADRUPLES:
        centers = np.ldexp(np.array([[0.0, 0.0, 0.0], [a, b, c]]), exponent)
        for r0 in (s // 2, 0):
            touching = np.ldexp(np.array([float(r0), float(s - r0)]), exponent)
            apart = np.ldexp(np.array([float(r0), (s - r0) * (1.0 - 2.0 ** -40)]), exponent)
            assert brute_sphere_pairs(centers, touching).tolist() == [[0, 1]]
            assert sphere_pairs(centers, touching, method=method).tolist() == [[0, 1]], (a, b, c, s, r0)
            assert sphere_pairs(centers, apart, method=method).tolist() == [], (a, b, c, s, r0)
