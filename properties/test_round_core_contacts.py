"""Contacts of shapes whose cores are points or segments (spheres, capsules: engine/narrowphase/segment_segment.py)
in the cases where the closest points do not fix the normal, and the feature of a segment touched inside.

- Cores that meet (coincident centres; collinear overlapping segments): the normal is a unit vector
  perpendicular to the cores (any such direction separates them by ra + rb), the separation −(ra + rb).
- A sphere beside the inside of a segment core touches its cylinder (feature 2, "sphere-cylinder"), at either
  end its end sphere ("sphere-sphere"), whatever the segment's direction — the axis directions included.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from engine.narrowphase.segment_segment import contact_segments_pair

radii = st.floats(0.05, 2.0)


@given(st.tuples(*[st.floats(-5.0, 5.0)] * 3).map(np.array), radii, radii)
def test_spheres_with_one_centre_touch_along_a_unit_normal(center, ra, rb):
    cs = contact_segments_pair(center, center, ra, center, center, rb)
    assert abs(np.linalg.norm(cs.normal[0]) - 1.0) <= 1e-12, cs.normal
    assert abs(cs.separation[0] + ra + rb) <= 1e-12 * (1.0 + ra + rb)


@pytest.mark.parametrize("smallest", [0, 1, 2])
@given(big=st.tuples(st.floats(0.5, 2.0), st.floats(0.5, 2.0)), small=st.floats(-0.4, 0.4),
       start=st.floats(0.1, 0.9), ra=radii, rb=radii)
def test_collinear_overlapping_cores_get_a_normal_across_them(smallest, big, small, start, ra, rb):
    """Direction d with its smallest component on axis ``smallest`` (each branch of the perpendicular chosen);
    B's core is A's shifted along d by ``start`` of its length, so that they overlap."""
    d = np.empty(3)
    d[smallest] = small
    d[[k for k in range(3) if k != smallest]] = big
    a0 = np.array([0.25, -0.5, 0.75])
    cs = contact_segments_pair(a0, a0 + d, ra, a0 + start * d, a0 + (1.0 + start) * d, rb)
    n = cs.normal[0]
    assert abs(np.linalg.norm(n) - 1.0) <= 1e-12 and abs(n @ d) <= 1e-12 * np.linalg.norm(d), (n, d)
    assert abs(cs.separation[0] + ra + rb) <= 1e-12 * (1.0 + ra + rb)


@pytest.mark.parametrize("axis", [0, 1, 2])
@given(u=st.floats(0.1, 0.9), gap=st.floats(-0.2, 0.2), ra=radii, rb=radii)
def test_a_sphere_beside_a_segment_touches_its_cylinder(axis, u, gap, ra, rb):
    """B's core is the unit segment along an axis; the sphere sits beside parameter u, at distance
    ra + rb + gap from the axis (apart or overlapping)."""
    d = np.zeros(3)
    d[axis] = 1.0
    side = np.zeros(3)
    side[(axis + 1) % 3] = ra + rb + gap
    center = u * d + side
    cs = contact_segments_pair(center, center, ra, np.zeros(3), d, rb)
    assert cs.kind == ["sphere-cylinder"] and cs.feature_b[0] == 2, (cs.kind, cs.feature_b)
    end = contact_segments_pair(d * 1.5, d * 1.5, ra, np.zeros(3), d, rb)
    assert end.kind == ["sphere-sphere"]


@given(center=st.tuples(*[st.floats(-5.0, 5.0).filter(lambda x: abs(x) > 0.1)] * 3).map(np.array),
       axis=st.integers(0, 2), sign=st.sampled_from([-1.0, 1.0]), ulps=st.integers(1, 40), ra=radii, rb=radii)
def test_spheres_a_round_off_apart_get_the_normal_towards_b(center, axis, sign, ulps, ra, rb):
    """B's centre a few ulps from A's along one axis (below the round-off threshold, so the closest points give
    no reliable direction): the normal still points from A to B, n · (c_b − c_a) > 0 — the side B is on,
    whichever axis and sign (a fixed +x would be wrong for five of the six)."""
    cb = center.copy()
    cb[axis] = center[axis] + sign * ulps * np.spacing(abs(center[axis]))
    offset = cb - center  # exact: the two are within a factor 2 (Sterbenz)
    cs = contact_segments_pair(center, center, ra, cb, cb, rb)
    n = cs.normal[0]
    assert abs(np.linalg.norm(n) - 1.0) <= 1e-12, n
    assert n @ offset > 0.0, (n, offset)
    assert abs(cs.separation[0] + ra + rb) <= 1e-12 * (1.0 + ra + rb)
