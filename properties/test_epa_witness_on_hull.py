"""EPA's witness points lie on their own shapes (issue 18, part 1), on boxes whose axes are parallel.

When several triangles of the Minkowski difference M share the closest plane (two boxes with a common axis: M's
face along that axis is a rectangle split into triangles), the origin's projection on that plane may fall outside
the triangle EPA stopped on; its barycentric weights are then negative and the witnesses, extrapolated from them,
leave A and B. The invariants checked, for ``epa_penetration(A, B, witnesses=True)`` on overlapping hulls:

- point_a lies in hull(A), point_b in hull(B) (Qhull's facet planes, within 1e-12 × the pair's scale);
- point_a − point_b = depth · normal (the origin's projection on M's closest face), the normal a unit vector.
"""
from __future__ import annotations

import numpy as np
from hypothesis import assume, given
from hypothesis import strategies as st

from engine.narrowphase import epa_penetration
from properties.geometry_checks import assert_on_hull, assert_unit, assert_witness_gap, pair_scale

SIGNS = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)


def _rot_z(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _check_witnesses(a: np.ndarray, b: np.ndarray) -> None:
    depth, normal, point_a, point_b = epa_penetration(a, b, witnesses=True)
    scale = pair_scale(a, b)
    assert_unit(normal)
    assert_on_hull(point_a, a, scale, what="point_a")
    assert_on_hull(point_b, b, scale, what="point_b")
    assert_witness_gap(point_a, point_b, depth, normal, scale)


def test_witness_inside_a_on_the_issue_boxes():
    """The reported pair: depth 0.04 along +z was right, but point_a had x = 0.02520 against A's half width 0.025."""
    a = SIGNS * [0.025, 0.245, 0.105]
    b = (SIGNS * [0.02, 0.06, 0.015]) @ _rot_z(0.6).T + [0.03, -0.08, 0.08]
    _check_witnesses(a, b)


quarter_turns = st.integers(0, 3).map(lambda k: k * np.pi / 2)
angles = st.one_of(st.floats(-np.pi, np.pi),
                   st.tuples(quarter_turns, st.sampled_from([0.0, 1e-9, -1e-9])).map(sum))
halves = st.tuples(*[st.floats(0.01, 0.3)] * 3).map(np.array)
fractions = st.tuples(*[st.floats(-1.0, 1.0)] * 3).map(np.array)


@given(halves, halves, angles, fractions, st.integers(-6, 6))
def test_witnesses_on_their_boxes_with_a_shared_axis(half_a, half_b, angle, where, exponent):
    """B turned about A's z axis (any angle, or a quarter turn ± 1e-9): their z faces are parallel, often the
    closest face of M, split into several coplanar triangles; shapes scaled from 1e-6 to 1e6."""
    scale = 10.0 ** exponent
    a = SIGNS * half_a
    centre = where * (half_a + half_b) * 0.9
    b = (SIGNS * half_b) @ _rot_z(angle).T + centre
    assume(epa_penetration(a, b)[0] > 1e-6 * half_a.max())
    _check_witnesses(a * scale, b * scale)
