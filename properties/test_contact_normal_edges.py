"""Contact normals and points at the edges of the number line and of the feature cases (mutation issue 7).

- Two shapes apart along a coordinate axis: ``contact_feature``'s normal is that axis and its separation the gap,
  wherever the pair sits — in particular placed symmetrically about the origin (the closest points then have
  opposite coordinates, whose sum is 0) and with gaps down to 1e-150. The normal is the direction of
  closest_b − closest_a, rescaled by its largest component before it is squared
  (``engine.narrowphase.penetration.penetration_kernel``). (Below about 1e-154 GJK's own squared distance is
  subnormal: 1e-162 comes out as 2.2e-162 and 1e-300 as touching; see properties/MUTATION.md.)
- Two parallel edges that meet end to end across a gap h (edge–edge, the parallel branch of Ericson 5.1.9 with
  an overlap of zero length): one contact point, the shared end lifted to the mid-plane.
"""
from __future__ import annotations

import numpy as np
from hypothesis import assume, example, given
from hypothesis import strategies as st

from engine.narrowphase import contact_feature
from properties.strategies.narrow import rotations, vectors

AXES = np.eye(3)


@example(axis=1, gap=2.0, center=np.zeros(3), offset=0.0)
@example(axis=2, gap=2.0, center=np.zeros(3), offset=0.0)
@example(axis=0, gap=1e-150, center=np.array([0.0, 1.0, 0.0]), offset=0.0)
@given(st.integers(0, 2), st.floats(-150, 3).map(lambda e: 10.0**e),
       st.one_of(st.just(np.zeros(3)), vectors), st.sampled_from([0.0, 1.0]))
def test_apart_along_an_axis_the_normal_is_that_axis(axis, gap, center, offset):
    """A = a point at c − (g/2) e_k, B = a point at c + (g/2) e_k (as doubles; offset shifts c along e_k):
    the normal is e_k exactly, a unit vector, and the separation the gap of the two doubles."""
    c = center + offset * AXES[axis]
    gap = max(gap, 1e-12 * abs(c[axis]))  # off the origin, a gap below the doubles' spacing there would vanish
    a = c - 0.5 * gap * AXES[axis]
    b = c + 0.5 * gap * AXES[axis]
    true_gap = b[axis] - a[axis]
    assume(true_gap > 0.0)
    contact = contact_feature(a[None, :], b[None, :])
    assert np.all(np.isfinite(contact.normal))
    assert np.array_equal(contact.normal, AXES[axis]), (contact.normal, axis)
    assert contact.separation == true_gap
    # and the other way round: the normal flips
    back = contact_feature(b[None, :], a[None, :])
    assert np.array_equal(back.normal, -AXES[axis])


@example(length_a=1.0, length_b=1.0, gap=1.0, rot=np.eye(3), shift=np.zeros(3), flip_a=False, flip_b=True)
@example(length_a=1.0, length_b=1.0, gap=1.0, rot=np.eye(3), shift=np.zeros(3), flip_a=True, flip_b=False)
@given(st.floats(0.1, 3.0), st.floats(0.1, 3.0), st.floats(0.01, 2.0), rotations(), vectors, st.booleans(),
       st.booleans())
def test_parallel_edges_meeting_end_to_end_touch_at_the_shared_end(length_a, length_b, gap, rot, shift, flip_a,
                                                                      flip_b):
    """A = [0, L_a] along u, B = [L_a, L_a + L_b] along u lifted by h along n ⊥ u (then rotated and moved, each
    edge's two points in either order): the edges are parallel and their projections on the contact plane share
    one end only, so the contact is edge–edge with exactly one point, the shared end on the mid-plane, and the
    normal is n."""
    u, n = rot[:, 0], rot[:, 2]
    a = np.array([np.zeros(3), length_a * u]) + shift
    b = np.array([length_a * u + gap * n, (length_a + length_b) * u + gap * n]) + shift
    a = a[::-1] if flip_a else a
    b = b[::-1] if flip_b else b
    contact = contact_feature(a, b)
    size = 10.0
    assert contact.kind == "edge-edge"
    assert np.allclose(contact.normal, n, atol=1e-9)
    assert abs(contact.separation - gap) <= 1e-9 * size
    assert contact.points.shape == (1, 3)
    expected = shift + length_a * u + 0.5 * gap * n
    assert np.allclose(contact.points[0], expected, atol=1e-7 * size), (contact.points, expected)
