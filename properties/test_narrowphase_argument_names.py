"""Narrow-phase functions name the bad argument at the start of their error (README: errors start with the
argument's name), and refuse an array of the wrong shape or length instead of reading past its end.

The anchor matters: a message merely containing the name (``XXt_maxXX must be ...``, or ``RADIUS``) would pass a
plain search. Each case below is one a single argument makes wrong, the others being valid.
"""
from __future__ import annotations

import re

import numpy as np
import pytest

from engine.narrowphase import (
    gjk_distance_batch,
    overlap_sphere_capsule,
    overlap_sphere_capsule_batch,
    overlap_sphere_sphere_batch,
    time_of_impact,
    time_of_impact_pairs,
)
from engine.narrowphase.plane import contact_points_plane_pair
from engine.narrowphase.segment_segment import contact_segments_pair
from engine.narrowphase.sphere_box import contact_sphere_box_pair

CUBE = np.array([[x, y, z] for x in (0.0, 1.0) for y in (0.0, 1.0) for z in (0.0, 1.0)])
ORIGIN = np.zeros(3)
UNIT_X = np.array([1.0, 0.0, 0.0])


def check_names(call, pattern):
    """call() raises ValueError/TypeError whose message starts with the leading identifier of ``pattern`` (as a
    whole word, case included) and matches ``pattern`` somewhere."""
    with pytest.raises((ValueError, TypeError)) as info:
        call()
    message = str(info.value)
    name = re.match(r"[A-Za-z_0-9]+", pattern).group()
    assert re.match(rf"{name}\b", message), message
    assert re.search(pattern, message), message


@pytest.mark.parametrize("call, pattern", [
    # single-pair sphere-capsule: each radius by its own name
    (lambda: overlap_sphere_capsule(ORIGIN, -1.0, ORIGIN, UNIT_X, 0.5), "radius"),
    (lambda: overlap_sphere_capsule(ORIGIN, 1.0, ORIGIN, UNIT_X, -0.5), "capsule_radius"),
    # time of impact: the horizon and the radii
    (lambda: time_of_impact(CUBE, ORIGIN, CUBE + 3.0, ORIGIN, t_max=-1.0), "t_max"),
    (lambda: time_of_impact(CUBE, ORIGIN, CUBE + 3.0, ORIGIN, radius_a=-1.0), "radius_a"),
    (lambda: time_of_impact(CUBE, ORIGIN, CUBE + 3.0, ORIGIN, radius_b=-1.0), "radius_b"),
], ids=["sphere_capsule.radius", "sphere_capsule.capsule_radius", "toi.t_max", "toi.radius_a", "toi.radius_b"])
def test_errors_start_with_the_argument_name(call, pattern):
    check_names(call, pattern)


@pytest.mark.parametrize("side", ["a", "b"])
@pytest.mark.parametrize("bad", [np.zeros((1, 2)), np.zeros((1, 4)), np.zeros((1, 3, 1))], ids=["2", "4", "3-D"])
def test_sphere_sphere_batch_refuses_centres_that_are_not_3d_points(side, bad):
    """Centres must be (n, 3): a (1, 2) array would have the kernel read a third coordinate past each row."""
    good = np.zeros((1, 3))
    ca, cb = (bad, good) if side == "a" else (good, bad)
    check_names(lambda: overlap_sphere_sphere_batch(ca, 1.0, cb, 1.0), rf"centers_{side}")


@pytest.mark.parametrize("length", [0, 2, 3])
def test_sphere_capsule_batch_refuses_radii_of_the_wrong_length(length):
    """One radius per sphere (or a scalar): a radii array of another length than the centres is refused by
    name, for the aligned and the indexed form alike, rather than read past its end or partly ignored."""
    centers = np.zeros((1, 3))
    radii = np.full(length, 0.5)
    check_names(lambda: overlap_sphere_capsule_batch(centers, radii, ORIGIN[None], UNIT_X[None], 0.5), "radii")
    check_names(lambda: overlap_sphere_capsule_batch(centers, radii, ORIGIN[None], UNIT_X[None], 0.5,
                                                     index_a=[0], index_b=[0]), "radii")
    check_names(lambda: overlap_sphere_capsule_batch(centers, 0.5, ORIGIN[None], UNIT_X[None],
                                                     np.full(length, 0.5)), "capsule_radii")


def test_sphere_capsule_batch_reads_one_radius_per_sphere():
    """The radii of several spheres are theirs, in order (distance 2 to the axis, capsule radius 0.25: 0.5 misses,
    1.8 reaches it); the check above is not a refusal of every array."""
    centers = np.array([[0.0, 2.0, 0.0], [0.0, 2.0, 0.0]])
    got = overlap_sphere_capsule_batch(centers, [0.5, 1.8], np.zeros((2, 3)), np.tile(UNIT_X, (2, 1)), 0.25)
    assert got.tolist() == [False, True]


def test_batched_gjk_names_the_pair_that_did_not_converge():
    """GJKNotConverged from ``gjk_distance_batch`` says which row of ``points_a`` failed: pair 0 (two single
    points, solved at the first iteration) converges, pair 1 (two clouds of 30 points) cannot in 1 iteration."""
    from engine.narrowphase import GJKNotConverged

    rng = np.random.default_rng(0)
    a = rng.normal(size=(2, 30, 3))
    b = rng.normal(size=(2, 30, 3)) + [5.0, 0.0, 0.0]
    a[0], b[0] = 0.0, UNIT_X
    with pytest.raises(GJKNotConverged, match=r"max_iterations=1 iterations for points_a\[1\]$"):
        gjk_distance_batch(a, b, max_iterations=1)
    assert gjk_distance_batch(a[:1], b[:1], max_iterations=1)[0][0] == 1.0


@pytest.mark.parametrize("bad", [np.zeros((16, 2)), np.zeros((16, 4)), np.zeros(48)], ids=["2", "4", "flat"])
def test_batched_time_of_impact_refuses_points_that_are_not_3d(bad):
    """``time_of_impact_pairs``' packed points must be (N, 3): (16, 2) would have the kernel read a third
    coordinate past each row."""
    check_names(lambda: time_of_impact_pairs(bad, [0, 8, 16], np.zeros((2, 3)), [[0, 1]]), "points")


def _segments_call(bad_name):
    args = {"a0": ORIGIN, "a1": UNIT_X, "radius_a": 0.5, "b0": ORIGIN + 3.0, "b1": UNIT_X + 3.0, "radius_b": 0.5}
    args[bad_name] = -1.0 if bad_name.startswith("radius") else np.zeros(2)
    return lambda: contact_segments_pair(**args)


def _sphere_box_call(bad_name):
    args = {"center": ORIGIN + 3.0, "radius": 0.5, "box_center": ORIGIN, "box_rotation": np.eye(3),
            "half_extents": np.ones(3)}
    args[bad_name] = {"radius": 0.0, "half_extents": np.array([1.0, 0.0, 1.0]), "box_rotation": np.ones((2, 2))}.get(
        bad_name, np.zeros(2))
    return lambda: contact_sphere_box_pair(**args)


@pytest.mark.parametrize("call, pattern", [
    *[(_segments_call(name), name) for name in ("a0", "a1", "radius_a", "b0", "b1", "radius_b")],
    *[(_sphere_box_call(name), name) for name in ("center", "radius", "box_center", "box_rotation")],
    (_sphere_box_call("half_extents"), r"half_extents\[1\]"),
    (lambda: contact_points_plane_pair(np.zeros((2, 2)), 0.0, 0.0), "points"),
    (lambda: contact_points_plane_pair(np.zeros((2, 3)), -1.0, 0.0), "radius"),
])
def test_closed_form_contact_pairs_name_the_bad_argument(call, pattern):
    """The single-pair forms of the closed-form contact kernels World calls (segment cores, sphere-box, plane)."""
    check_names(call, pattern)
