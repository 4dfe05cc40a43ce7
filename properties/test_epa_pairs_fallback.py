"""``epa_penetration_pairs`` on boxes that share their axes (rotated by one common rotation, integer sides in
their frame): many coplanar support points, where the expanding polytope may fold on round-off and the pair's
depth comes from the exact fallback (Qhull on the Minkowski difference). Every pair's depth equals the exact
depth (an independent Qhull oracle), and the batch equals the single-pair ``epa_penetration``, fallback pairs
included. The three explicit examples are pairs on which the EPA kernel gives up (found by a random search over
such boxes), so the fallback branch of the batch runs on every run of this property.
"""
from __future__ import annotations

import numpy as np
from hypothesis import example, given
from hypothesis import strategies as st

from engine.narrowphase import epa_penetration, epa_penetration_pairs, pack_point_sets
from properties.strategies.narrow import box_corners, exact_penetration_depth, rotations

FOLDING = [  # (lo_a, hi_a, lo_b, hi_b, rotation): EPA's kernel returns "not converged" on these
    ([-2.0, 1.0, 2.0], [0.0, 2.0, 5.0], [-2.0, 0.0, 1.0], [0.0, 3.0, 4.0],
     [[-0.3961321347511044, -0.8493551277238062, 0.3488197225312955],
      [-0.1886221994722323, -0.29651997778099093, -0.9362144885884954],
      [0.8986105929065106, -0.4366597872326208, -0.04274614052954914]]),
    ([-3.0, 0.0, 0.0], [0.0, 1.0, 2.0], [-1.0, 0.0, 1.0], [2.0, 1.0, 4.0],
     [[-0.8275286699412345, 0.5518428698901359, -0.10327510530960528],
      [-0.46199346480312387, -0.7738699372932234, -0.43322899098858497],
      [-0.3189958289766438, -0.3107969869628747, 0.8953473594032109]]),
    ([-1.0, -3.0, 2.0], [0.0, -2.0, 3.0], [-1.0, -3.0, 2.0], [1.0, -2.0, 3.0],
     [[-0.5500450753421446, -0.6113434829978095, -0.5689547968757811],
      [0.7081414468703926, -0.7025622379098786, 0.07029931071760154],
      [-0.442703180829053, -0.36423268340330206, 0.8193585576685392]]),
]

corner = st.tuples(*[st.integers(-3, 2)] * 3)
side = st.tuples(*[st.integers(1, 3)] * 3)


def _boxes(spec):
    lo_a, hi_a, lo_b, hi_b, rot = spec
    m = np.array(rot)
    return box_corners(np.array(lo_a), np.array(hi_a)) @ m.T, box_corners(np.array(lo_b), np.array(hi_b)) @ m.T


@st.composite
def axis_sharing_boxes(draw):
    (la, sa), (lb, sb) = draw(st.tuples(corner, side)), draw(st.tuples(corner, side))
    return (list(map(float, la)), [float(x + s) for x, s in zip(la, sa)],
            list(map(float, lb)), [float(x + s) for x, s in zip(lb, sb)], draw(rotations()).tolist())


@example(FOLDING)
@given(st.lists(axis_sharing_boxes(), min_size=1, max_size=4))
def test_pairs_depth_is_exact_and_equals_single_pair_on_axis_sharing_boxes(specs):
    shapes = [box for spec in specs for box in _boxes(spec)]
    points, offsets = pack_point_sets(shapes)
    pairs = np.array([[2 * i, 2 * i + 1] for i in range(len(specs))] + [[2 * i + 1, 2 * i] for i in range(len(specs))])
    depth, normal = epa_penetration_pairs(points, offsets, pairs)
    for p, (i, j) in enumerate(pairs):
        a, b = shapes[i], shapes[j]
        exact = max(exact_penetration_depth(a, b), 0.0)
        assert abs(depth[p] - exact) <= 1e-9 * 10.0, (p, depth[p], exact)
        one_depth, one_normal = epa_penetration(a, b)
        assert depth[p] == one_depth and np.array_equal(normal[p], one_normal)
        assert abs(np.linalg.norm(normal[p]) - 1.0) <= 1e-9
