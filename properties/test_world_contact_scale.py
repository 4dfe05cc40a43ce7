"""World's contact point ids do not depend on the scene's scale (engine.narrowphase.convex_cores.feature_point_ids).

A point's id names, for each shape, the support vertex nearest to the point among the vertices within
``FEATURE_TOL`` × the pair's size of the support plane (engine/narrowphase/convex_cores.py). The tolerance is
relative, so a scene scaled by a power of two (exact in floating point) has the same features, the same points
scaled, and the same ids. The scene: a small box pressed into the flat bottom face of a hull whose "shoulders" (four
vertices outside that face) stand 0.05 of the hull's height above it; each clipped point (a corner of the box's top
face) is nearer in the contact plane to a shoulder than to any corner of the bottom face, so a tolerance that is not
relative (one that reaches the shoulders at small scales) names other vertices.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import example, given
from hypothesis import strategies as st

from engine import Box, ConvexPolyhedron, World

#: the hull: a flat 2 × 2 bottom face at z = 0, four shoulders at z = 0.05 just outside it, an apex at z = 1
_HULL = np.array([[-1, -1, 0], [1, -1, 0], [-1, 1, 0], [1, 1, 0], [1.2, 0, 0.05], [-1.2, 0, 0.05],
                  [0, 1.2, 0.05], [0, -1.2, 0.05], [0, 0, 1.0]])


def _contacts(k: int, dx: float, dy: float):
    """The contacts of the box (half side 0.3, centre (dx, dy), top face 0.01 into the hull) and the hull, every
    length scaled by 2^k."""
    s = 2.0 ** k
    w = World()
    w.add(Box(np.array([dx, dy, -0.29]) * s, np.array([0.3, 0.3, 0.3]) * s))
    w.add(ConvexPolyhedron(_HULL * s))
    return w.contacts()


def _same_up_to_scale(k: int, dx: float, dy: float) -> None:
    ref, got = _contacts(0, dx, dy), _contacts(k, dx, dy)
    assert got.pairs.tolist() == ref.pairs.tolist() == [[0, 1]]
    assert got.point_ids.tolist() == ref.point_ids.tolist()
    np.testing.assert_allclose(got.points * 2.0 ** -k, ref.points, rtol=0, atol=1e-12)


@pytest.mark.parametrize("k", [-40, -24, -20, 20])
def test_point_ids_of_a_hull_contact_do_not_depend_on_the_scale(k):
    # the four points are the box's top corners; their ids are the same at every scale
    _same_up_to_scale(k, 0.0, 0.0)


@given(k=st.integers(-60, 60), dx=st.floats(-0.4, 0.4), dy=st.floats(-0.4, 0.4))
@example(k=-22, dx=0.1, dy=-0.2)
def test_point_ids_of_a_shifted_hull_contact_do_not_depend_on_the_scale(k, dx, dy):
    _same_up_to_scale(k, dx, dy)
