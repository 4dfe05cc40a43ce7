"""Quickhull on hulls with many faces: the per-face arrays outgrow their first capacity and are grown in the middle
of the run (``_grown_mesh``: every array copied into a bigger one, the search scratch included).

Quickhull never reuses a face slot, so a hull of v vertices on a sphere (every point a vertex, 2v - 4 faces at the
end) creates several times 2v - 4 slots along the way: 300 points or more outgrow the 256 slots the kernel starts
with, at least once. Oracle: scipy.spatial.ConvexHull (Qhull) — the same vertex set, volume and area; and the
hull's own planes hold every input point.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial import ConvexHull as QhullHull

from engine.bounding.hull import convex_hull
from properties.strategies.geometry import seeds


@st.composite
def spheres_with_insides(draw):
    """n points on a sphere (all of them hull vertices, in general position with probability 1) and as many
    inside it, shuffled, at a drawn centre and scale."""
    rng = np.random.default_rng(draw(seeds))
    n = draw(st.integers(300, 420))
    on = rng.normal(size=(n, 3))
    on /= np.linalg.norm(on, axis=1)[:, None]
    inside = on[rng.permutation(n)] * rng.uniform(0.0, 0.9, size=(n, 1))
    pts = np.vstack([on, inside])[rng.permutation(2 * n)]
    scale = draw(st.sampled_from([1.0, 1e-3, 1e4]))
    centre = np.array(draw(st.lists(st.sampled_from([0.0, 2.5, -1e3]), min_size=3, max_size=3)))
    return pts * scale + centre * scale, n


@settings(max_examples=10)
@given(spheres_with_insides())
def test_hull_of_many_points_on_a_sphere_matches_qhull(cloud):
    pts, n_on = cloud
    hull = convex_hull(pts)
    ref = QhullHull(pts)
    assert len(ref.vertices) == n_on  # the input really has that many corners (no point on the sphere is hidden)
    assert set(hull.vertices.tolist()) == set(ref.vertices.tolist())
    assert len(hull.faces) == 2 * n_on - 4
    assert set(np.unique(hull.faces).tolist()) == set(hull.vertices.tolist())
    assert hull.volume == pytest.approx(ref.volume, rel=1e-9)
    assert hull.area == pytest.approx(ref.area, rel=1e-9)
    extent = float(np.abs(pts).max() + np.ptp(pts, axis=0).max())
    assert (pts @ hull.normals.T - hull.offsets).max() <= 1e-9 * extent
    a, b, c = (pts[hull.faces[:, i]] for i in range(3))
    assert (np.einsum("ij,ij->i", np.cross(b - a, c - a), hull.normals) > 0).all()  # outward, counter-clockwise
