"""World's time of impact and curved-ground contacts at their edges: one body, a touch exactly at t = dt, the
stats of the query, and the depth of a body sunk into a straight HeightCurve (closed forms)."""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from engine.world import Box, HeightCurve, Plane, Sphere, World


@settings(max_examples=10)
@given(height=st.floats(0.6, 5.0), speed=st.floats(0.5, 4.0))
def test_one_body_over_a_plane_impacts_at_the_closed_form_time(height, speed):
    world = World()
    ball = world.add(Sphere([0.0, height, 0.0], 0.5), velocity=[0.0, -speed, 0.0])
    ground = world.add(Plane(0.0))
    dt = 2.0 * (height - 0.5) / speed
    impacts = world.time_of_impact(dt)
    assert impacts.pairs.shape == (1, 2) and impacts.pairs.tolist() == [sorted([ball, ground])]
    assert impacts.times[0] == pytest.approx((height - 0.5) / speed, rel=1e-12)
    s = world.stats
    # the overlap test at the start (apart), then the impact test
    assert (s.query, s.bodies, s.impacts, s.narrow_tests) == ("time_of_impact", 1, 1, 2)


def test_one_body_alone_has_no_impact_pairs_of_the_documented_shape():
    world = World()
    world.add(Box([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]), velocity=[1.0, 0.0, 0.0])
    impacts = world.time_of_impact(1.0)
    assert impacts.pairs.shape == (0, 2) and impacts.pairs.dtype == np.int64 and impacts.times.shape == (0,)
    assert (world.stats.query, world.stats.bodies, world.stats.impacts) == ("time_of_impact", 1, 0)


@pytest.mark.parametrize("gap, speed", [(2.0, 2.0), (1.0, 0.5), (3.0, 1.5), (0.5, 0.25)])
def test_two_spheres_touching_exactly_at_dt_are_reported(gap, speed):
    """Spheres of radius 0.5 whose surfaces are ``gap`` apart, closing at ``speed``: contact at t = gap / speed,
    exactly representable here (and the closed form's roots too); [0, dt] includes dt."""
    world = World()
    a = world.add(Sphere([0.0, 0.0, 0.0], 0.5))
    b = world.add(Sphere([1.0 + gap, 0.0, 0.0], 0.5), velocity=[-speed, 0.0, 0.0])
    dt = gap / speed
    impacts = world.time_of_impact(dt)
    assert impacts.pairs.tolist() == [[a, b]] and impacts.times.tolist() == [dt]
    assert len(world.time_of_impact(dt * (1 - 2 ** -40))) == 0


@settings(max_examples=20)
@given(slope=st.floats(-0.8, 0.8), sink=st.floats(1e-3, 0.2), x0=st.floats(-3.0, 3.0),
       half=st.tuples(*[st.floats(0.1, 1.0)] * 3))
def test_a_box_sunk_into_a_straight_curve_has_the_closed_form_depth_and_normal(slope, sink, x0, half):
    """An axis-aligned box whose lowest corner is ``sink`` below y = slope · x vertically: depth = sink · n_y with
    n = (−slope, 1, 0) / √(1 + slope²), the normal from the first id of the pair to the second."""
    world = World()
    ground = world.add(HeightCurve(lambda x: slope * np.asarray(x, dtype=float), samples=64))
    lowest = -half[1] - abs(slope) * half[0]  # the corner of least y − slope · x, relative to the centre
    box = world.add(Box([x0, slope * x0 - lowest - sink, 0.0], half))
    contacts = world.contacts()
    assert contacts.pairs.tolist() == [sorted([box, ground])]
    n = np.array([-slope, 1.0, 0.0]) / math.hypot(slope, 1.0)
    assert contacts.depth[0] == pytest.approx(sink * n[1], rel=1e-9)
    assert contacts.separation[0] == pytest.approx(-sink * n[1], rel=1e-9)
    sign = 1.0 if contacts.pairs[0, 0] == ground else -1.0  # from the first shape to the second
    np.testing.assert_allclose(contacts.normal[0], sign * n, atol=1e-9)


@pytest.mark.parametrize("velocities", [[[1.0, 2.0]], [[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]], [1.0, 2.0, 3.0, 4.0]])
def test_update_refuses_velocities_of_the_wrong_shape_by_name(velocities):
    world = World()
    body = world.add(Sphere([0.0, 0.0, 0.0], 0.5))
    before = world.pose(body)
    with pytest.raises(ValueError, match="^velocities"):
        world.update([body], [[1.0, 1.0, 1.0]], velocities=velocities)
    assert all(np.array_equal(x, y) for x, y in zip(world.pose(body), before))


@settings(max_examples=20)
@given(slope=st.floats(-0.8, 0.8), gap=st.floats(0.05, 2.0), x0=st.floats(-3.0, 3.0),
       half=st.tuples(*[st.floats(0.1, 1.0)] * 3), vx=st.floats(-1.0, 1.0), fall=st.floats(0.5, 3.0))
def test_a_box_falling_onto_a_straight_curve_impacts_at_the_closed_form_time(slope, gap, x0, half, vx, fall):
    """An axis-aligned box translating with v = (vx, vy) whose lowest corner (least y − slope · x) is ``gap`` above
    y = slope · x vertically: that corner's vertical gap closes at −(vy − slope · vx), so the impact is at
    gap / (slope · vx − vy); a window shorter than that has no impact, and a box starting sunk has time 0."""
    world = World()
    ground = world.add(HeightCurve(lambda x: slope * np.asarray(x, dtype=float), samples=64))
    lowest = -half[1] - abs(slope) * half[0]
    vy = slope * vx - fall  # the closing rate of the gap is ``fall``
    box = world.add(Box([x0, slope * x0 - lowest + gap, 0.0], half), velocity=[vx, vy, 0.0])
    t_hit = gap / fall
    impacts = world.time_of_impact(2.0 * t_hit)
    assert impacts.pairs.tolist() == [sorted([box, ground])]
    assert impacts.times[0] == pytest.approx(t_hit, rel=1e-9, abs=1e-12)
    assert len(world.time_of_impact(0.9 * t_hit)) == 0
    sunk = world.add(Box([x0 + 50.0, slope * (x0 + 50.0) - lowest - 0.5 * gap, 0.0], half), velocity=[vx, vy, 0.0])
    impacts = world.time_of_impact(2.0 * t_hit)
    assert impacts.pairs.tolist() == sorted([sorted([box, ground]), sorted([sunk, ground])])
    times = dict(zip(map(tuple, impacts.pairs.tolist()), impacts.times.tolist()))
    assert times[tuple(sorted([sunk, ground]))] == 0.0
    assert times[tuple(sorted([box, ground]))] == pytest.approx(t_hit, rel=1e-9, abs=1e-12)


def test_a_height_curve_is_shown_by_its_function_name():
    def valley(x):
        return 0.1 * np.asarray(x, dtype=float) ** 2

    assert repr(HeightCurve(valley)) == "HeightCurve(valley)"
    assert repr(HeightCurve(lambda x: np.asarray(x, dtype=float))) == "HeightCurve(<lambda>)"
