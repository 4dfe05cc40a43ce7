"""The bounding-volume functions give the same answer whatever form their (valid) input takes: float64 arrays,
nested lists, integer arrays, Fortran-ordered or strided views, one row (d,) or a batch (n, d); and they answer
with the documented shapes and dtypes (bool (n,) for overlap and containment tests, float64 volumes shaped like
their input).

The overlap tests have a fast path for C-contiguous float64 batches and a checked path for everything else;
both must give the same booleans, and the result of each is compared with an independent numpy answer.
"""
from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from engine.bounding import (
    aabb_contains,
    fit_kdop,
    kdop_contains,
    kdop_directions,
    merge_aabb,
    merge_kdop,
    overlap_aabb_aabb,
    overlap_aabbs,
    overlap_kdop_kdop,
    overlap_kdops,
    overlap_sphere_sphere,
    overlap_spheres,
    sphere_contains,
    transform_aabbs,
)
from properties.strategies.geometry import seeds

FORMS = ("array", "list", "int", "fortran", "strided")


def as_form(value, form):
    """``value`` (integer-valued float64) in another valid form; the numbers are unchanged."""
    value = np.asarray(value, dtype=np.float64)
    if form == "list":
        return value.tolist()
    if form == "int":
        return value.astype(np.int64)
    if form == "fortran":
        return np.asfortranarray(value)
    if form == "strided":  # a non-contiguous view of the same numbers
        wide = np.repeat(value, 2, axis=-1) if value.ndim else value
        return wide[..., ::2] if value.ndim else wide
    return value


@st.composite
def integer_boxes(draw, n, d):
    rng = np.random.default_rng(draw(seeds))
    lo = rng.integers(-6, 6, size=(n, d)).astype(np.float64)
    return lo, lo + rng.integers(0, 5, size=(n, d))


def boxes_meet(lo_a, hi_a, lo_b, hi_b):
    return ((lo_a <= hi_b) & (lo_b <= hi_a)).all(axis=-1)


@given(st.integers(1, 12), st.sampled_from([1, 2, 3]), st.data(), st.lists(st.sampled_from(FORMS), min_size=4,
                                                                             max_size=4))
def test_aabb_overlap_is_the_same_for_every_input_form(n, d, data, forms):
    lo_a, hi_a = data.draw(integer_boxes(n, d))
    lo_b, hi_b = data.draw(integer_boxes(n, d))
    expected = boxes_meet(lo_a, hi_a, lo_b, hi_b)
    args = [as_form(v, f) for v, f in zip((lo_a, hi_a, lo_b, hi_b), forms)]
    out = overlap_aabbs(*args)
    assert out.dtype == np.bool_ and out.shape == (n,)
    assert np.array_equal(out, expected)
    assert np.array_equal(overlap_aabbs(lo_a, hi_a, lo_b, hi_b), expected)
    for i in range(n):
        row = [as_form(v[i], f) for v, f in zip((lo_a, hi_a, lo_b, hi_b), forms)]
        assert overlap_aabb_aabb(*row) is bool(expected[i])
        assert np.array_equal(overlap_aabbs(*row), expected[i:i + 1])
    if d > 1:  # merge_aabb takes 2-D and 3-D boxes
        lo, hi = merge_aabb(*args)
        assert np.array_equal(lo, np.minimum(lo_a, lo_b)) and np.array_equal(hi, np.maximum(hi_a, hi_b))


@given(st.integers(1, 12), st.sampled_from([2, 3]), seeds, st.lists(st.sampled_from(FORMS), min_size=4,
                                                                    max_size=4))
def test_sphere_overlap_is_the_same_for_every_input_form(n, d, seed, forms):
    rng = np.random.default_rng(seed)
    ca = rng.integers(-5, 6, size=(n, d)).astype(np.float64)
    cb = rng.integers(-5, 6, size=(n, d)).astype(np.float64)
    ra = rng.integers(0, 5, size=n).astype(np.float64)
    rb = rng.integers(0, 5, size=n).astype(np.float64)
    expected = ((ca - cb) ** 2).sum(axis=1) <= (ra + rb) ** 2  # exact: small integers
    out = overlap_spheres(*[as_form(v, f) for v, f in zip((ca, ra, cb, rb), forms)])
    assert out.dtype == np.bool_ and out.shape == (n,)
    assert np.array_equal(out, expected)
    assert np.array_equal(overlap_spheres(ca, ra, cb, rb), expected)
    for i in range(n):
        assert overlap_sphere_sphere(as_form(ca[i], forms[0]), ra[i], as_form(cb[i], forms[2]), rb[i]) \
            is bool(expected[i])


@given(st.integers(1, 6), st.sampled_from([8, 14, 18, 26]), seeds, st.lists(st.sampled_from(FORMS), min_size=4,
                                                                             max_size=4))
def test_kdop_overlap_and_merge_are_the_same_for_every_input_form(n, k, seed, forms):
    rng = np.random.default_rng(seed)
    d = 2 if k == 8 else 3
    dops = [fit_kdop(rng.integers(-4, 5, size=(5, d)).astype(np.float64), k) for _ in range(2 * n)]
    lo_a, hi_a = (np.array([dops[i][j] for i in range(n)]) for j in (0, 1))
    lo_b, hi_b = (np.array([dops[n + i][j] for i in range(n)]) for j in (0, 1))
    expected = boxes_meet(lo_a, hi_a, lo_b, hi_b)
    args = [as_form(v, f) for v, f in zip((lo_a, hi_a, lo_b, hi_b), forms)]
    out = overlap_kdops(*args, k)
    assert out.dtype == np.bool_ and out.shape == (n,)
    assert np.array_equal(out, expected)
    lo, hi = merge_kdop(*args, k)
    assert np.array_equal(lo, np.minimum(lo_a, lo_b)) and np.array_equal(hi, np.maximum(hi_a, hi_b))
    for i in range(n):
        row = [as_form(v[i], f) for v, f in zip((lo_a, hi_a, lo_b, hi_b), forms)]
        assert overlap_kdop_kdop(*row, k) is bool(expected[i])
        lo, hi = merge_kdop(*row, k)
        assert np.array_equal(lo, np.minimum(lo_a[i], lo_b[i])) and np.array_equal(hi, np.maximum(hi_a[i], hi_b[i]))


@given(st.integers(0, 15), st.sampled_from([2, 3]), seeds, st.sampled_from(FORMS))
def test_containment_is_a_boolean_per_point_equal_to_the_definition(n, d, seed, form):
    rng = np.random.default_rng(seed)
    pts = rng.integers(-4, 5, size=(n, d)).astype(np.float64)
    if n == 0 and form == "list":  # [] has no second dimension: an empty cloud must be an (0, d) array
        form = "array"
    lo = rng.integers(-3, 1, size=d).astype(np.float64)
    hi = lo + rng.integers(0, 4, size=d)
    inside = aabb_contains(lo, hi, as_form(pts, form))
    assert inside.dtype == np.bool_ and inside.shape == (n,)
    assert np.array_equal(inside, ((pts >= lo) & (pts <= hi)).all(axis=1))
    center, radius = pts[0] if n else np.zeros(d), 2.0
    inside = sphere_contains(center, radius, as_form(pts, form))
    assert inside.dtype == np.bool_ and inside.shape == (n,)
    assert np.array_equal(inside, ((pts - center) ** 2).sum(axis=1) <= radius**2)
    k = 8 if d == 2 else 26
    klo, khi = fit_kdop(rng.integers(-3, 4, size=(4, d)).astype(np.float64), k)
    inside = kdop_contains(klo, khi, as_form(pts, form), k)
    proj = pts @ kdop_directions(k).T
    assert inside.dtype == np.bool_ and inside.shape == (n,)
    assert np.array_equal(inside, ((proj >= klo) & (proj <= khi)).all(axis=1))


@given(st.integers(1, 5), st.sampled_from([2, 3]), seeds, st.sampled_from(FORMS))
def test_transformed_boxes_keep_the_shape_of_their_input(n, d, seed, form):
    rng = np.random.default_rng(seed)
    lo = rng.integers(-4, 4, size=(n, d)).astype(np.float64)
    hi = lo + rng.integers(0, 3, size=(n, d))
    rotation = np.eye(d)[::-1] * np.array([1.0] * (d - 1) + [-1.0])[:, None]  # a signed permutation
    shift = np.arange(1.0, d + 1.0)
    new_lo, new_hi = transform_aabbs(as_form(lo, form), as_form(hi, form), rotation, shift)
    assert new_lo.shape == (n, d) and new_hi.shape == (n, d)
    corners_lo, corners_hi = lo @ rotation.T + shift, hi @ rotation.T + shift  # exact: a signed permutation
    assert np.array_equal(new_lo, np.minimum(corners_lo, corners_hi))
    assert np.array_equal(new_hi, np.maximum(corners_lo, corners_hi))
    one_lo, one_hi = transform_aabbs(lo[0], hi[0], rotation, shift)
    assert one_lo.shape == (d,) and one_hi.shape == (d,)
    assert np.array_equal(one_lo, new_lo[0]) and np.array_equal(one_hi, new_hi[0])
