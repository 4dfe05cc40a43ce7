"""World's contacts carry each pair's own rounding radii: ``radius_a`` is the radius of the pair's first body and
``radius_b`` of its second (a Sphere's or Capsule's radius, 0 for a Box or a ConvexPolyhedron), so that the
feature names of the first body are "sphere"/"cylinder"/"face" exactly when it is rounded
(engine.narrowphase.contacts.feature_name).

The scene: a row of bodies of every kind and of distinct radii, each one overlapping the next, in an order drawn
by Hypothesis, so that pairs of every combination of a rounded and a flat body, either one first, touch.
"""
from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from engine import Box, Capsule, ConvexPolyhedron, Sphere, World
from engine.narrowphase.contacts import FEATURE_NAMES, ROUND_FEATURE_NAMES

_TETRA = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]) - 0.25


def _body(kind: str, x: float, radius: float):
    """A body of ``kind`` centred at (x, 0, 0) reaching about 0.55 along x; its rounding radius."""
    c = np.array([x, 0.0, 0.0])
    if kind == "sphere":
        return Sphere(c, radius), radius
    if kind == "capsule":
        return Capsule(c - [0, 0, 0.5], c + [0, 0, 0.5], radius), radius
    if kind == "box":
        return Box(c, [0.55, 0.4, 0.4]), 0.0
    return ConvexPolyhedron(_TETRA * 1.6 + c), 0.0


@given(kinds=st.lists(st.sampled_from(["sphere", "capsule", "box", "hull"]), min_size=2, max_size=5),
       radii=st.lists(st.floats(0.5, 0.6), min_size=5, max_size=5, unique=True))
def test_contacts_carry_the_radii_of_each_pairs_own_bodies(kinds, radii):
    w = World()
    radius = {}
    for k, kind in enumerate(kinds):
        shape, r = _body(kind, 0.9 * k, radii[k])
        radius[w.add(shape)] = r
    cs = w.contacts()
    assert len(cs) >= 1
    for p, (i, j) in enumerate(cs.pairs.tolist()):
        assert cs.radius_a[p] == radius[i] and cs.radius_b[p] == radius[j]
        names_a = ROUND_FEATURE_NAMES if radius[i] > 0 else FEATURE_NAMES
        names_b = ROUND_FEATURE_NAMES if radius[j] > 0 else FEATURE_NAMES
        assert cs.names_a[p] == names_a[int(cs.feature_a[p])]
        assert cs.names_b[p] == names_b[int(cs.feature_b[p])]
