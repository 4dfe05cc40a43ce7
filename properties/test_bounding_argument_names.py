"""Every public bounding-volume function refuses bad input by name: a ValueError or TypeError whose message
begins with one of the function's argument names and names the offending argument as a whole word (README's
validation contract: errors start with the argument name, arrays give the first bad index).

The anchors matter: a message that merely contains the name (``XXlo_bXX must be ...``, ``LO_B must be ...``)
passes a plain substring search, not these checks. The convex hull (``convex_hull``, ``is_convex``) has its own
file, ``test_hull.py``.
"""
from __future__ import annotations

import re

import numpy as np
import pytest

from engine.bounding import (
    OBB,
    aabb_contains,
    describe_bounding_volumes,
    describe_decomposition,
    fit_aabb,
    fit_aabbs,
    fit_kdop,
    fit_kdops,
    fit_obb,
    kdop_contains,
    kdop_directions,
    merge_aabb,
    merge_kdop,
    merge_obb,
    merge_spheres,
    min_bounding_sphere,
    overlap_aabb_aabb,
    overlap_aabbs,
    overlap_kdop_kdop,
    overlap_kdops,
    overlap_sphere_sphere,
    overlap_spheres,
    ritter_sphere,
    ritter_spheres,
    sphere_contains,
    transform_aabb,
    transform_aabbs,
    transform_kdop,
    transform_obb,
    transform_sphere,
    triangulate_polygon,
    update_kdop,
)
from engine.bounding import decompose_polygon as decompose_polygon_fn
from engine.bounding.aabb import as_rotation_matrix

RNG = np.random.default_rng(7)
P3 = RNG.normal(size=(6, 3))
P2 = RNG.normal(size=(6, 2))
LO3 = np.array([[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]])
HI3 = LO3 + 2.0
LO14, HI14 = fit_kdop(P3, 14)
SQUARE = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
BOX = OBB(np.zeros(3), np.eye(3), np.ones(3))
Z90 = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])


def _obb(center, axes, half_extents):
    return OBB(center, axes, half_extents)


#: name -> (callable taking keyword arguments, valid keyword arguments); every array argument is corrupted below
VALID_CALLS = {
    "fit_aabb": (fit_aabb, dict(points=P3)),
    "fit_aabbs": (fit_aabbs, dict(clouds=np.stack([P3, P3 + 1.0]))),
    "overlap_aabbs": (overlap_aabbs, dict(lo_a=LO3, hi_a=HI3, lo_b=LO3 + 0.5, hi_b=HI3 + 0.5)),
    "overlap_aabb_aabb": (overlap_aabb_aabb, dict(lo_a=LO3[0], hi_a=HI3[0], lo_b=LO3[1], hi_b=HI3[1])),
    "merge_aabb": (merge_aabb, dict(lo_a=LO3, hi_a=HI3, lo_b=LO3 + 0.5, hi_b=HI3 + 0.5)),
    "aabb_contains": (aabb_contains, dict(lo=LO3[0], hi=HI3[0], points=P3)),
    "transform_aabbs": (transform_aabbs, dict(lo=LO3, hi=HI3, rotation=Z90, translation=np.ones(3))),
    "transform_aabb": (transform_aabb, dict(lo=LO3[0], hi=HI3[0], rotation=Z90, translation=np.ones(3))),
    "ritter_sphere": (ritter_sphere, dict(points=P3)),
    "ritter_spheres": (ritter_spheres, dict(clouds=np.stack([P2, P2 - 1.0]))),
    "min_bounding_sphere": (min_bounding_sphere, dict(points=P2)),
    "overlap_spheres": (overlap_spheres, dict(centers_a=P3[:3], radii_a=np.ones(3), centers_b=P3[3:],
                                              radii_b=np.full(3, 0.5))),
    "overlap_sphere_sphere": (overlap_sphere_sphere, dict(center_a=P3[0], radius_a=1.0, center_b=P3[1],
                                                          radius_b=0.5)),
    "merge_spheres": (merge_spheres, dict(center_a=P3[0], radius_a=1.0, center_b=P3[1], radius_b=0.5)),
    "sphere_contains": (sphere_contains, dict(center=P3[0], radius=1.0, points=P3)),
    "transform_sphere": (transform_sphere, dict(center=P3[0], radius=1.0, rotation=Z90,
                                                translation=np.ones(3))),
    "fit_kdop": (fit_kdop, dict(points=P3, k=14)),
    "fit_kdops": (fit_kdops, dict(clouds=np.stack([P2, P2 * 2.0]), k=8)),
    "overlap_kdops": (overlap_kdops, dict(lo_a=LO14, hi_a=HI14, lo_b=LO14 + 0.1, hi_b=HI14 + 0.1, k=14)),
    "overlap_kdop_kdop": (overlap_kdop_kdop, dict(lo_a=LO14, hi_a=HI14, lo_b=LO14 + 0.1, hi_b=HI14 + 0.1, k=14)),
    "merge_kdop": (merge_kdop, dict(lo_a=LO14, hi_a=HI14, lo_b=LO14 + 0.1, hi_b=HI14 + 0.1, k=14)),
    "kdop_contains": (kdop_contains, dict(lo=LO14, hi=HI14, points=P3, k=14)),
    "update_kdop": (update_kdop, dict(points=P3, k=14, rotation=Z90, translation=np.ones(3))),
    "transform_kdop": (transform_kdop, dict(lo=LO14, hi=HI14, k=14, rotation=Z90, translation=np.ones(3))),
    "OBB": (_obb, dict(center=np.zeros(3), axes=np.eye(3), half_extents=np.ones(3))),
    "OBB.from_aabb": (OBB.from_aabb, dict(lo=LO3[0], hi=HI3[0])),
    "OBB.contains": (BOX.contains, dict(points=P3)),
    "OBB.transformed": (BOX.transformed, dict(rotation=Z90, translation=np.ones(3))),
    "fit_obb": (fit_obb, dict(points=P3)),
    "transform_obb": (lambda rotation, translation: transform_obb(BOX, rotation, translation),
                      dict(rotation=Z90, translation=np.ones(3))),
    "triangulate_polygon": (triangulate_polygon, dict(polygon=SQUARE)),
    "decompose_polygon": (decompose_polygon_fn, dict(polygon=SQUARE)),
    "describe_bounding_volumes": (describe_bounding_volumes, dict(points=P3)),
    "describe_decomposition": (describe_decomposition, dict(polygon=SQUARE)),
    "as_rotation_matrix": (as_rotation_matrix, dict(rotation=Z90)),
}

ARRAY_ARGUMENTS = [(fn, name) for fn, (_, kwargs) in VALID_CALLS.items()
                   for name, value in kwargs.items() if isinstance(value, np.ndarray)]


def _word(name: str) -> str:
    return rf"(?<![A-Za-z0-9_]){re.escape(name)}(?![A-Za-z0-9_])"


def check_named(call, names, culprit):
    """call() raises ValueError/TypeError whose message starts with one of ``names`` and names ``culprit``."""
    with pytest.raises((ValueError, TypeError)) as info:
        call()
    message = str(info.value)
    assert re.match("|".join(_word(n) for n in names), message), message
    assert re.search(_word(culprit), message), message
    return message


@pytest.mark.parametrize("fn", sorted(VALID_CALLS))
def test_valid_calls_are_accepted(fn):
    call, kwargs = VALID_CALLS[fn]
    call(**kwargs)


@pytest.mark.parametrize("fn, name", ARRAY_ARGUMENTS, ids=[f"{f}-{n}" for f, n in ARRAY_ARGUMENTS])
def test_nan_is_named_with_its_first_index(fn, name):
    call, kwargs = VALID_CALLS[fn]
    bad = np.array(kwargs[name], dtype=np.float64)
    flat = bad.size - 1
    bad.flat[flat] = np.nan
    index = ", ".join(str(int(i)) for i in np.unravel_index(flat, bad.shape))
    with pytest.raises(ValueError) as info:
        call(**{**kwargs, name: bad})
    message = str(info.value)
    assert re.match(rf"{re.escape(name)} must be finite: {re.escape(name)}\[{index}\] = nan", message), message


@pytest.mark.parametrize("fn, name", ARRAY_ARGUMENTS, ids=[f"{f}-{n}" for f, n in ARRAY_ARGUMENTS])
def test_two_extra_axes_are_refused_by_name(fn, name):
    call, kwargs = VALID_CALLS[fn]
    check_named(lambda: call(**{**kwargs, name: np.asarray(kwargs[name])[None, None]}), list(kwargs), name)


@pytest.mark.parametrize("fn, name", ARRAY_ARGUMENTS, ids=[f"{f}-{n}" for f, n in ARRAY_ARGUMENTS])
def test_text_is_refused_by_name(fn, name):
    call, kwargs = VALID_CALLS[fn]
    text = np.full(np.shape(kwargs[name]), "a")
    check_named(lambda: call(**{**kwargs, name: text}), list(kwargs), name)


@pytest.mark.parametrize("call, names, culprit", [
    # boxes with lo > hi: the row (and column) of the first bad entry
    (lambda: overlap_aabbs(LO3, HI3, HI3, LO3), ["lo_b"], r"lo_b\[0, 0\]"),
    (lambda: overlap_aabbs(HI3, LO3, LO3, HI3), ["lo_a"], r"lo_a\[0, 0\]"),
    (lambda: overlap_aabb_aabb([0.0, 2.0], [1.0, 1.0], [0.0, 0.0], [1.0, 1.0]), ["lo_a"], r"lo_a\[1\]"),
    (lambda: overlap_aabb_aabb([0.0], [1.0], [2.0], [1.0]), ["lo_b"], r"lo_b\[0\]"),
    (lambda: merge_aabb(LO3, HI3, [[0, 0, 0], [1, 5, 1]], HI3), ["lo_b"], r"lo_b\[1, 1\]"),
    (lambda: merge_aabb(LO3, [[2, 2, 2], [1, 5, 0]], LO3, HI3), ["lo_a"], r"hi_a\[1, 2\]"),
    (lambda: transform_aabb([0, 0, 1], [1, 1, 0], np.eye(3), np.zeros(3)), ["lo"], r"lo\[2\]"),
    (lambda: aabb_contains([0, 1], [1, 0], P2), ["lo"], r"hi\[1\]"),
    (lambda: OBB.from_aabb([0, 0, 1], [1, 1, 0]), ["lo"], r"lo\[2\]"),
    (lambda: merge_kdop(LO14, HI14, HI14 + 1.0, HI14, 14), ["lo_b"], r"lo_b\[0\]"),
    (lambda: overlap_kdops(LO14, HI14, HI14 + 1.0, HI14, 14), ["lo_b"], r"lo_b\[0\]"),
    (lambda: overlap_kdop_kdop(HI14 + 1.0, HI14, LO14, HI14, 14), ["lo_a"], r"hi_a\[0\]"),
    (lambda: kdop_contains(HI14 + 1.0, HI14, P3, 14), ["lo"], r"lo\[0\]"),
    (lambda: transform_kdop(HI14 + 1.0, HI14, 14, np.eye(3), np.zeros(3)), ["lo"], r"lo\[0\]"),
    # a's and b's shapes must agree
    (lambda: overlap_aabbs(LO3, HI3, LO3[:1], HI3[:1]), ["lo_b"], "lo_a"),
    (lambda: merge_aabb(LO3, HI3, LO3[0], HI3[0]), ["lo_b"], "lo_a"),
    (lambda: overlap_kdops(LO14, HI14, np.stack([LO14, LO14]), np.stack([HI14, HI14]), 14), ["lo_b"], "lo_a"),
    (lambda: merge_kdop(LO14, HI14, np.stack([LO14, LO14]), np.stack([HI14, HI14]), 14), ["lo_b"], "lo_a"),
    (lambda: overlap_spheres(P3[:3], np.ones(3), P3[:2], np.ones(3)), ["centers_b"], "centers_b"),
    (lambda: overlap_spheres(P3[:3], np.ones(2), P3[3:], np.ones(3)), ["radii_a"], "radii_a"),
    (lambda: overlap_spheres(P3[:3], np.ones(3), P3[3:], np.ones(4)), ["radii_b"], "radii_b"),
    (lambda: overlap_sphere_sphere(P3[0], 1.0, P2[0], 1.0), ["center_b"], "center_b"),
    (lambda: merge_spheres(P3[0], 1.0, P2[0], 1.0), ["center_b"], "center_b"),
    # negative radii, with the index in a batch
    (lambda: overlap_spheres(P3[:3], [1.0, -1.0, 1.0], P3[3:], np.ones(3)), ["radii_a"], r"radii_a\[1\]"),
    (lambda: overlap_spheres(P3[:3], np.ones(3), P3[3:], [1.0, 1.0, -2.0]), ["radii_b"], r"radii_b\[2\]"),
    (lambda: overlap_sphere_sphere(P3[0], -1.0, P3[1], 1.0), ["radius_a"], "radius_a"),
    (lambda: overlap_sphere_sphere(P3[0], 1.0, P3[1], -1.0), ["radius_b"], "radius_b"),
    (lambda: merge_spheres(P3[0], -1.0, P3[1], 1.0), ["radius_a"], "radius_a"),
    (lambda: merge_spheres(P3[0], 1.0, P3[1], -1.0), ["radius_b"], "radius_b"),
    (lambda: sphere_contains(P3[0], -1.0, P3), ["radius"], "radius"),
    (lambda: transform_sphere(P3[0], -1.0, np.eye(3), np.zeros(3)), ["radius"], "radius"),
    (lambda: OBB(np.zeros(3), np.eye(3), [1.0, -1.0, 1.0]), ["half_extents"], r"half_extents\[1\]"),
    # points of the wrong dimension for the volume
    (lambda: sphere_contains(P3[0], 1.0, P2), ["points"], "points"),
    (lambda: aabb_contains(LO3[0], HI3[0], P2), ["points"], "points"),
    (lambda: kdop_contains(LO14, HI14, P2, 14), ["points"], "points"),
    (lambda: fit_kdop(P2, 14), ["points"], "points"),
    (lambda: update_kdop(P2, 14, np.eye(3), np.zeros(3)), ["points"], "points"),
    (lambda: fit_aabb(np.zeros((3, 4))), ["points"], "points"),
    (lambda: fit_aabb(np.zeros((0, 3))), ["points"], "points"),
    (lambda: fit_obb(P2), ["points"], "points"),
    (lambda: OBB(np.zeros(3), np.eye(3), np.ones(3)).contains(P2), ["points"], "points"),
    (lambda: fit_kdops(np.zeros((2, 4, 3)), 8), ["clouds"], "clouds"),
    # clouds with no point, or of the wrong dimension
    (lambda: fit_aabbs(np.zeros((2, 0, 3))), ["clouds"], "clouds"),
    (lambda: fit_aabbs(np.zeros((2, 3, 4))), ["clouds"], "clouds"),
    (lambda: fit_aabbs(P3), ["clouds"], "clouds"),
    (lambda: ritter_spheres(np.zeros((2, 0, 3))), ["clouds"], "clouds"),
    (lambda: ritter_spheres(P3), ["clouds"], "clouds"),
    (lambda: fit_kdops(np.zeros((2, 0, 3)), 14), ["clouds"], "clouds"),
    # rotations: orthonormal, of the volume's dimension; translations of that dimension
    (lambda: transform_aabb(LO3[0], HI3[0], 2.0 * np.eye(3), np.zeros(3)), ["rotation"], "rotation"),
    (lambda: transform_aabb(LO3[0], HI3[0], np.eye(2), np.zeros(3)), ["rotation"], "rotation"),
    (lambda: transform_aabb(LO3[0], HI3[0], np.eye(3), np.zeros(2)), ["translation"], "translation"),
    (lambda: transform_sphere(P3[0], 1.0, np.eye(2), np.zeros(3)), ["rotation"], "rotation"),
    (lambda: transform_sphere(P3[0], 1.0, np.eye(3), np.zeros(2)), ["translation"], "translation"),
    (lambda: transform_sphere(P3[:1], 1.0, np.eye(3), np.zeros(3)), ["center"], "center"),
    (lambda: update_kdop(P3, 14, 2.0 * np.eye(3), np.zeros(3)), ["rotation"], "rotation"),
    (lambda: transform_kdop(LO14, HI14, 14, np.eye(3), np.zeros(2)), ["translation"], "translation"),
    (lambda: OBB(np.zeros(3), [[1, 0, 0], [1, 0, 0], [0, 0, 1]], np.ones(3)), ["axes"], "axes"),
    (lambda: BOX.transformed(np.eye(2), np.zeros(3)), ["rotation"], "rotation"),
    (lambda: BOX.transformed(np.eye(3), np.zeros(2)), ["translation"], "translation"),
    (lambda: as_rotation_matrix([2.0, 0.0, 0.0, 0.0]), ["rotation"], "rotation"),
    (lambda: as_rotation_matrix(np.diag([1.0, 1.0, -1.0])), ["rotation"], "rotation"),
    (lambda: as_rotation_matrix(2.0 * np.eye(3)), ["rotation"], "rotation"),
    (lambda: as_rotation_matrix(np.eye(2)), ["rotation"], "rotation"),
    (lambda: as_rotation_matrix(np.eye(2), "orientation"), ["orientation"], "orientation"),
    # k, seed, kinds, OBB arguments
    (lambda: fit_kdop(P3, 10), ["k"], "k"),
    (lambda: fit_kdop(P3, 14.0), ["k"], "k"),
    (lambda: kdop_directions(True), ["k"], "k"),
    (lambda: min_bounding_sphere(P3, seed=1.5), ["seed"], "seed"),
    (lambda: min_bounding_sphere(P3, seed=True), ["seed"], "seed"),
    (lambda: merge_obb(BOX, "box"), ["b"], "b"),
    (lambda: merge_obb(None, BOX), ["a"], "a"),
    (lambda: transform_obb(np.eye(3), np.eye(3), np.zeros(3)), ["box"], "box"),
    (lambda: describe_bounding_volumes(P3, kinds=["kdop8"]), ["kind"], "kind"),
    (lambda: describe_bounding_volumes(P2, kinds=["obb"]), ["kind"], "kind"),
    # polygons: at least 3 vertices in 2-D, simple
    (lambda: triangulate_polygon(SQUARE[:2]), ["polygon"], "polygon"),
    (lambda: decompose_polygon_fn(np.zeros((4, 3))), ["polygon"], "polygon"),
    (lambda: describe_decomposition(SQUARE[:2]), ["polygon"], "polygon"),
    (lambda: describe_decomposition(np.zeros((4, 3))), ["polygon"], "polygon"),
    (lambda: describe_decomposition(SQUARE[[0, 2, 1, 3]]), ["polygon"], "polygon"),
])
def test_bad_arguments_are_named(call, names, culprit):
    with pytest.raises((ValueError, TypeError)) as info:
        call()
    message = str(info.value)
    plain = re.match(r"[A-Za-z_0-9]+", culprit).group()
    assert re.match("|".join(_word(n) for n in names), message), message
    assert re.search(rf"(?<![A-Za-z0-9_]){culprit}", message) and re.search(_word(plain), message), message
    assert "np." not in message and "float64(" not in message, message  # values as plain numbers, no numpy repr


@pytest.mark.parametrize("call, message", [
    (lambda: overlap_spheres(P3[:3], [1.0, -1.0, 1.0], P3[3:], np.ones(3)), "radii_a must be >= 0: radii_a[1] = -1.0"),
    (lambda: overlap_spheres(P3[:3], np.ones(3), P3[3:], np.array([1.0, 1.0, -2.5])),
     "radii_b must be >= 0: radii_b[2] = -2.5"),
    (lambda: OBB.from_aabb([0, 0, 1], [1, 1, 0]), "lo must be <= hi: lo[2] = 1.0 > hi[2] = 0.0"),
    (lambda: OBB.from_aabb(np.array([0.0, 3.5, 0.0]), np.array([1.0, -1.0, 1.0])),
     "lo must be <= hi: lo[1] = 3.5 > hi[1] = -1.0"),
    (lambda: OBB(np.zeros(3), np.eye(3), [1.0, -1.0, 1.0]), "half_extents must be >= 0: half_extents[1] = -1.0"),
])
def test_offending_values_are_printed_as_plain_numbers(call, message):
    """The whole message: the argument, the first bad index, and the value as Python prints a float (not numpy's
    ``np.float64(-1.0)``)."""
    with pytest.raises(ValueError) as info:
        call()
    assert str(info.value) == message
