"""``closest_on_triangle`` (engine/narrowphase/simplex.py, Ericson 5.1.5) when the origin lies on an edge.

Ericson's Voronoi regions are closed: a point on the boundary between an edge's region and the face's region
belongs to the edge, so the answer is the edge's two vertices (the smallest simplex holding the closest point,
which GJK keeps), not the triangle with a zero weight. With integer vertices and the origin strictly inside edge
AB (a = −p u, b = q u) or AC, the region tests are exact: the answer must be m = 2, those two vertices, and the
weights q / (p + q), p / (p + q) that put the point at the origin.
"""
from __future__ import annotations

import numpy as np
from hypothesis import assume, given
from hypothesis import strategies as st

from engine.narrowphase.simplex import closest_on_triangle

small = st.integers(-4, 4)


@given(u=st.tuples(small, small, small), p=st.integers(1, 4), q=st.integers(1, 4),
       third=st.tuples(small, small, small), edge=st.sampled_from(["ab", "ac"]))
def test_the_origin_on_an_edge_is_supported_by_that_edge_alone(u, p, q, third, edge):
    u, third = np.array(u, float), np.array(third, float)
    assume(np.any(u != 0) and np.any(np.cross(u, third) != 0))  # a real edge, a triangle of non-zero area
    first, second = -p * u, q * u  # the origin = (q first + p second) / (p + q), strictly inside the edge
    a, b, c = (first, second, third) if edge == "ab" else (first, third, second)
    m, s0, s1, s2, l0, l1, l2 = closest_on_triangle(*a, *b, *c)
    other = 1 if edge == "ab" else 2
    assert (m, s0, s1) == (2, 0, other), (m, s0, s1, s2, l0, l1, l2)
    assert np.isclose(l0, q / (p + q)) and np.isclose(l1, p / (p + q)) and l2 == 0.0
    assert np.abs(l0 * a + l1 * (b if edge == "ab" else c)).max() <= 1e-12
