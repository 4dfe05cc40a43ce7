"""``drop_flat_vertices`` (engine/narrowphase/clipping.py): clipping a face on a face that shares an edge leaves
points on the polygon's edges; removing every vertex that lies on the line through its two neighbours must give
back the polygon's true corners, each once, in their cyclic order, wherever the flat points were."""
from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from engine.narrowphase.clipping import drop_flat_vertices


def _corners(n, gaps, radii, phase):
    """A strictly convex counter-clockwise polygon: n points on an ellipse, consecutive angles at least
    2π · 0.2 / 9 = 0.14 rad apart (the n gaps and the closing one make a full turn)."""
    angles = phase + 2.0 * np.pi * np.cumsum(gaps[:n]) / np.sum(gaps[:n + 1])
    return np.column_stack([radii[0] * np.cos(angles), radii[1] * np.sin(angles)])


def _same_cycle(a, b):
    """a and b list the same points in the same cyclic order (the starting point may differ)."""
    if a.shape != b.shape:
        return False
    return any(np.array_equal(np.roll(a, -s, axis=0), b) for s in range(a.shape[0]))


@given(n=st.integers(3, 8), gaps=st.lists(st.floats(0.2, 1.0), min_size=9, max_size=9),
       radii=st.tuples(st.floats(0.5, 3.0), st.floats(0.5, 3.0)), phase=st.floats(0.0, 6.0),
       inserted=st.lists(st.tuples(st.integers(0, 7), st.floats(0.05, 0.95)), min_size=1, max_size=6),
       start=st.integers(0, 13))
def test_points_on_the_edges_are_dropped_and_the_corners_kept_in_order(n, gaps, radii, phase, inserted, start):
    corners = _corners(n, np.array(gaps), radii, phase)
    # the polygon with extra points on its edges (at fraction t along edge e), listed from any starting point
    rows = [[corners[v]] for v in range(n)]
    for e, t in inserted:
        e %= n
        rows[e].append(corners[e] + t * (corners[(e + 1) % n] - corners[e]))
    for e in range(n):  # along each edge, the extra points in the order the edge runs
        origin, extra = rows[e][0], rows[e][1:]
        extra.sort(key=lambda p, o=origin: float(np.hypot(*(p - o))))
        rows[e] = [origin, *extra]
    polygon = np.roll(np.array([p for edge in rows for p in edge]), -start % (n + len(inserted)), axis=0)
    S = np.vstack([polygon, np.full((2, 2), 7.0)])  # spare rows past the count stay untouched
    count = drop_flat_vertices(S, polygon.shape[0], 1e-9)
    assert count == n, (count, n, polygon)
    assert _same_cycle(S[:count], corners), (S[:count], corners)
    assert np.array_equal(S[-2:], np.full((2, 2), 7.0))


def test_a_flat_point_before_the_last_two_vertices_is_dropped():
    # a unit square with the midpoint of its first edge: the four corners come back in order
    square = np.array([[0.0, 0.0], [0.5, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    S = square.copy()
    assert drop_flat_vertices(S, 5, 1e-12) == 4
    assert np.array_equal(S[:4], [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
