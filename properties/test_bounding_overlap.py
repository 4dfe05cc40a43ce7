"""Overlap tests of bounding volumes: no false negative (whenever two convex shapes overlap, their bounding
volumes of every kind overlap), exactness of the AABB / k-DOP / sphere tests against independent oracles, closed
volumes (touching counts), and batched forms equal to one-at-a-time.

Oracle for "the convex hulls of A and B intersect": linear-programming feasibility (scipy.optimize.linprog) —
convex weights lambda, mu >= 0, sum lambda = 1, sum mu = 1, with A^T lambda = B^T mu. The LP solver works to a
tolerance, so its witness points x_a = A^T lambda and x_b = B^T mu are measured, and the volumes are asked to
overlap once grown by that measured gap (plus 1e-9 of the scale): a bounding volume holds its shape, so it lies
within that gap of the other.
"""
from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy.optimize import linprog

from engine.bounding.aabb import fit_aabb, overlap_aabb_aabb, overlap_aabbs
from engine.bounding.kdop import fit_kdop, kdop_directions, overlap_kdop_kdop, overlap_kdops
from engine.bounding.obb import fit_obb
from engine.bounding.sphere import (
    min_bounding_sphere,
    overlap_sphere_sphere,
    overlap_spheres,
    ritter_sphere,
)
from properties.strategies.geometry import cloud_pairs, seeds


def hull_witness(a, b):
    """(x_a, x_b) with x_a in hull(a), x_b in hull(b), equal up to the LP tolerance; None if infeasible."""
    na, nb = len(a), len(b)
    dim = a.shape[1]
    a_eq = np.zeros((dim + 2, na + nb))
    a_eq[:dim, :na] = a.T
    a_eq[:dim, na:] = -b.T
    a_eq[dim, :na] = 1.0
    a_eq[dim + 1, na:] = 1.0
    b_eq = np.zeros(dim + 2)
    b_eq[dim:] = 1.0
    res = linprog(np.zeros(na + nb), A_eq=a_eq, b_eq=b_eq, bounds=[(0, None)] * (na + nb), method="highs")
    if res.status != 0:
        return None
    lam = np.clip(res.x[:na], 0, None)
    mu = np.clip(res.x[na:], 0, None)
    return (lam / lam.sum()) @ a, (mu / mu.sum()) @ b


def scale_of(*clouds) -> float:
    pts = np.vstack(clouds)
    return float(np.abs(pts).max() + np.ptp(pts, axis=0).max())


def obb_overlap_lp(box_a, box_b, grow):
    """Oracle: the two boxes (half-extents grown by ``grow``) intersect, by LP on their corners."""
    def corners(box):
        signs = np.array(list(itertools.product([-1.0, 1.0], repeat=3)))
        return box.center + (signs * (box.half_extents + grow)) @ box.axes
    return hull_witness(corners(box_a), corners(box_b)) is not None


@settings(max_examples=120)
@given(st.sampled_from([2, 3]).flatmap(lambda d: cloud_pairs(d)))
def test_no_false_negative_when_shapes_overlap(pair):
    a, b = pair
    witness = hull_witness(a, b)
    assume(witness is not None)
    x_a, x_b = witness
    scale = scale_of(a, b)
    grow = float(np.linalg.norm(x_a - x_b)) + 1e-9 * scale
    assume(grow <= 1e-6 * scale)  # the LP found a genuine common point
    dim = a.shape[1]

    lo_a, hi_a = fit_aabb(a)
    lo_b, hi_b = fit_aabb(b)
    assert overlap_aabb_aabb(lo_a - grow, hi_a + grow, lo_b, hi_b)

    for fit in (ritter_sphere, min_bounding_sphere):
        (ca, ra), (cb, rb) = fit(a), fit(b)
        assert overlap_sphere_sphere(ca, ra + grow, cb, rb)

    for k in ((8,) if dim == 2 else (14, 18, 26)):
        lo_a, hi_a = fit_kdop(a, k)
        lo_b, hi_b = fit_kdop(b, k)
        slack = grow * np.linalg.norm(kdop_directions(k), axis=1)  # the directions are not unit vectors
        assert overlap_kdop_kdop(lo_a - slack, hi_a + slack, lo_b, hi_b, k)

    if dim == 3:
        assert obb_overlap_lp(fit_obb(a), fit_obb(b), grow)


def touching_offset(a, b, u):
    """The smallest t such that hull(a) and hull(b + t u) intersect, with the LP's witness weights: b + t u
    then just touches a (first contact when b slides in along +u). b is assumed centred on a's centroid, so
    the line of translations meets the Minkowski difference and the LP is feasible and bounded."""
    na, nb = len(a), len(b)
    dim = a.shape[1]
    a_eq = np.zeros((dim + 2, na + nb + 1))
    a_eq[:dim, :na] = a.T
    a_eq[:dim, na:na + nb] = -b.T
    a_eq[:dim, -1] = -u
    a_eq[dim, :na] = 1.0
    a_eq[dim + 1, na:na + nb] = 1.0
    b_eq = np.zeros(dim + 2)
    b_eq[dim:] = 1.0
    cost = np.zeros(na + nb + 1)
    cost[-1] = 1.0
    bounds = [(0, None)] * (na + nb) + [(None, None)]
    res = linprog(cost, A_eq=a_eq, b_eq=b_eq, bounds=bounds, method="highs")
    assert res.status == 0
    lam = np.clip(res.x[:na], 0, None)
    mu = np.clip(res.x[na:na + nb], 0, None)
    return res.x[-1], lam / lam.sum(), mu / mu.sum()


@st.composite
def touching_pairs(draw):
    """Two convex clouds that just touch: B slides along a direction u until first contact with A. The
    directions include the world axes, the k-DOP diagonals and A's PCA axes, along which the volumes are tight,
    so a fit or an overlap test that is too small by any margin shows up as a false negative."""
    dim = draw(st.sampled_from([2, 3]))
    a, b = draw(cloud_pairs(dim))
    b = b - b.mean(axis=0) + a.mean(axis=0)
    kind = draw(st.sampled_from(["axis", "diagonal", "pca", "random"]))
    rng = np.random.default_rng(draw(seeds))
    if kind == "axis":
        u = np.eye(dim)[rng.integers(dim)]
    elif kind == "diagonal":
        dirs = kdop_directions(8 if dim == 2 else 26)[dim:]
        u = dirs[rng.integers(len(dirs))]
    elif kind == "pca" and dim == 3:
        u = fit_obb(a).axes[rng.integers(3)]
    else:
        u = rng.normal(size=dim)
    u = u / np.linalg.norm(u) * (1 if rng.integers(2) else -1)
    t, lam, mu = touching_offset(a, b, u)
    b = b + t * u
    return a, b, lam @ a, mu @ b


@settings(max_examples=150)
@given(touching_pairs())
def test_no_false_negative_when_shapes_just_touch(case):
    a, b, x_a, x_b = case
    scale = scale_of(a, b)
    grow = float(np.linalg.norm(x_a - x_b)) + 1e-9 * scale
    assert grow <= 1e-6 * scale  # the LP found a genuine contact point
    dim = a.shape[1]
    lo_a, hi_a = fit_aabb(a)
    lo_b, hi_b = fit_aabb(b)
    assert overlap_aabb_aabb(lo_a - grow, hi_a + grow, lo_b, hi_b)
    for fit in (ritter_sphere, min_bounding_sphere):
        (ca, ra), (cb, rb) = fit(a), fit(b)
        assert overlap_sphere_sphere(ca, ra + grow, cb, rb)
    for k in ((8,) if dim == 2 else (14, 18, 26)):
        lo_a, hi_a = fit_kdop(a, k)
        lo_b, hi_b = fit_kdop(b, k)
        slack = grow * np.linalg.norm(kdop_directions(k), axis=1)
        assert overlap_kdop_kdop(lo_a - slack, hi_a + slack, lo_b, hi_b, k)
    if dim == 3:
        assert obb_overlap_lp(fit_obb(a), fit_obb(b), grow)


# ------------------------------------------------------------------------------------------------------------
# each overlap test is exact for its own volume
# ------------------------------------------------------------------------------------------------------------
small_ints = st.integers(-6, 6)


@st.composite
def int_boxes(draw, dim):
    lo = np.array([draw(small_ints) for _ in range(dim)], dtype=float)
    size = np.array([draw(st.integers(0, 4)) for _ in range(dim)], dtype=float)
    return lo, lo + size


@given(st.sampled_from([1, 2, 3]).flatmap(lambda d: st.tuples(int_boxes(d), int_boxes(d))))
def test_aabb_overlap_is_exact_on_integer_boxes(boxes):
    (lo_a, hi_a), (lo_b, hi_b) = boxes
    if lo_a.shape[0] == 1:  # 1-D boxes are not supported (d = 2 or 3): pad to 2-D with a common interval
        lo_a, hi_a, lo_b, hi_b = (np.append(x, 0.0) for x in (lo_a, hi_a, lo_b, hi_b))
    # oracle: the closed boxes share a lattice point of the half-integer grid iff they overlap
    common_lo = np.maximum(lo_a, lo_b)
    common_hi = np.minimum(hi_a, hi_b)
    expected = bool((common_lo <= common_hi).all())
    assert overlap_aabb_aabb(lo_a, hi_a, lo_b, hi_b) == expected
    assert overlap_aabb_aabb(lo_b, hi_b, lo_a, hi_a) == expected  # symmetric
    if expected:  # a witness point lies in both
        x = (common_lo + common_hi) / 2
        assert (lo_a <= x).all() and (x <= hi_a).all() and (lo_b <= x).all() and (x <= hi_b).all()


@given(st.sampled_from([8, 14, 18, 26]), seeds, st.floats(0.0, 3.0))
def test_kdop_overlap_agrees_with_slab_projections_and_separates_when_a_slab_does(k, seed, distance):
    rng = np.random.default_rng(seed)
    dim = 2 if k == 8 else 3
    a = rng.normal(size=(12, dim))
    direction = rng.normal(size=dim)
    b = rng.normal(size=(12, dim)) + distance * 2 * direction / np.linalg.norm(direction)
    (lo_a, hi_a), (lo_b, hi_b) = fit_kdop(a, k), fit_kdop(b, k)
    pa, pb = a @ kdop_directions(k).T, b @ kdop_directions(k).T
    separated_on_some_slab = ((pa.max(axis=0) < pb.min(axis=0)) | (pb.max(axis=0) < pa.min(axis=0))).any()
    assert overlap_kdop_kdop(lo_a, hi_a, lo_b, hi_b, k) == (not separated_on_some_slab)


@given(seeds, st.integers(1, 50), st.sampled_from([2, 3]))
def test_sphere_overlap_matches_distance_and_batches_match(seed, n, dim):
    rng = np.random.default_rng(seed)
    ca, cb = rng.integers(-5, 6, size=(2, n, dim)).astype(float)
    ra, rb = rng.integers(0, 4, size=(2, n)).astype(float)
    got = overlap_spheres(ca, ra, cb, rb)
    expected = np.linalg.norm(ca - cb, axis=1) <= ra + rb  # integer data: exact, touching included
    assert np.array_equal(got, expected)
    for i in range(n):
        assert overlap_sphere_sphere(ca[i], ra[i], cb[i], rb[i]) == expected[i]
    lo_a, hi_a = ca - ra[:, None], ca + ra[:, None]
    lo_b, hi_b = cb - rb[:, None], cb + rb[:, None]
    boxes = overlap_aabbs(lo_a, hi_a, lo_b, hi_b)
    assert (boxes | ~expected).all()  # the spheres' boxes overlap whenever the spheres do
    for i in range(n):
        assert overlap_aabb_aabb(lo_a[i], hi_a[i], lo_b[i], hi_b[i]) == boxes[i]



@given(seeds, st.integers(1, 20), st.sampled_from([2, 3]), st.sampled_from([-560, -520, 495]))
def test_sphere_overlap_does_not_depend_on_the_scale(seed, n, dim, power):
    """Scaling every centre and radius by 2^power (exact in binary) keeps the answers. At 2^-520 and below the
    squared distances underflow to subnormals or 0, at 2^495 the differences of centres exceed 1e150: the test is
    then made on values divided by their largest magnitude. That division rounds, so exact ties (touching
    spheres, |c_a - c_b|^2 = (r_a + r_b)^2 in integers) are left out; every other case has a relative margin of
    at least 1 / 1200 on these integer inputs, far beyond rounding."""
    rng = np.random.default_rng(seed)
    ca, cb = rng.integers(-9, 10, size=(2, n, dim)).astype(float)
    ra, rb = rng.integers(0, 10, size=(2, n)).astype(float)
    d2, s2 = ((ca - cb) ** 2).sum(axis=1), (ra + rb) ** 2  # exact: small integers
    keep = d2 != s2
    assume(keep.any())
    expected = (d2 < s2)[keep]
    scale = 2.0 ** power
    got = overlap_spheres(ca * scale, ra * scale, cb * scale, rb * scale)
    assert np.array_equal(got[keep], expected)
    for i in np.flatnonzero(keep):
        assert overlap_sphere_sphere(ca[i] * scale, ra[i] * scale, cb[i] * scale, rb[i] * scale) == (d2[i] < s2[i])

def test_touching_volumes_overlap():
    assert overlap_aabb_aabb([0, 0, 0], [1, 1, 1], [1, 0, 0], [2, 1, 1])
    assert not overlap_aabb_aabb([0, 0, 0], [1, 1, 1], [1 + 1e-12, 0, 0], [2, 1, 1])
    assert overlap_sphere_sphere([0, 0, 0], 1.0, [2, 0, 0], 1.0)
    assert not overlap_sphere_sphere([0, 0, 0], 1.0, [2.0000001, 0, 0], 1.0)
    lo_a, hi_a = fit_kdop(np.array([[0.0, 0.0], [1.0, 1.0]]), 8)
    lo_b, hi_b = fit_kdop(np.array([[1.0, 1.0], [2.0, 0.5]]), 8)
    assert overlap_kdop_kdop(lo_a, hi_a, lo_b, hi_b, 8)


def test_batched_kdop_overlap_equals_one_at_a_time():
    rng = np.random.default_rng(5)
    clouds = rng.normal(size=(40, 10, 3)) + rng.uniform(-3, 3, size=(40, 1, 3))
    fits = [fit_kdop(c, 18) for c in clouds]
    lo = np.array([f[0] for f in fits])
    hi = np.array([f[1] for f in fits])
    got = overlap_kdops(lo[:20], hi[:20], lo[20:], hi[20:], 18)
    for i in range(20):
        assert got[i] == overlap_kdop_kdop(lo[i], hi[i], lo[20 + i], hi[20 + i], 18)
    assert got.any() and not got.all()


@pytest.mark.parametrize("call", [
    lambda: overlap_spheres(np.zeros((2, 3)), [1.0, -1.0], np.zeros((2, 3)), [1.0, 1.0]),
    lambda: overlap_spheres(np.zeros((2, 3)), [1.0, np.nan], np.zeros((2, 3)), [1.0, 1.0]),
    lambda: overlap_aabbs(np.zeros((2, 3)), np.ones((2, 3)), np.zeros((3, 3)), np.ones((3, 3))),
    lambda: overlap_aabb_aabb([0, 0, 2], [1, 1, 1], [0, 0, 0], [1, 1, 1]),
    lambda: overlap_kdop_kdop(np.zeros(7), np.ones(7), np.zeros(7), np.ones(7), 18),
    lambda: overlap_kdop_kdop(np.zeros(9), np.ones(9), np.ones(9), np.zeros(9), 18),
    # the same faults in plain float64 arrays, which take the compiled (copy-free) check
    lambda: overlap_spheres(np.zeros((2, 3)), np.array([1.0, -1.0]), np.zeros((2, 3)), np.ones(2)),
    lambda: overlap_spheres(np.zeros((2, 3)), np.ones(2), np.array([[0, 0, 0], [0, np.inf, 0.0]]), np.ones(2)),
    lambda: overlap_aabbs(np.zeros((2, 3)), np.array([[1, 1, 1], [1, -1, 1.0]]), np.zeros((2, 3)), np.ones((2, 3))),
    lambda: overlap_aabbs(np.zeros((2, 3)), np.ones((2, 3)), np.array([[0, 0, 0], [np.nan, 0, 0]]),
                          np.ones((2, 3))),
])
def test_bad_overlap_arguments_raise_value_error(call):
    with pytest.raises(ValueError):
        call()
