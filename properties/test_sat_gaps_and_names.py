"""The separating-axis tests (engine/narrowphase/sat.py, engine/narrowphase/box_box.py) on gaps far above their
round-off allowance, and the names of their arguments.

- ``overlap_convex_sat``'s touching allowance is relative: OVERLAP_TOL × (the size of the Minkowski difference,
  measured about the pair's own centre) plus a few ulps of the coordinates. Two cubes of edge s apart by 1e-7 s
  are therefore apart at every scale s (2^-300 … 2^300) and wherever the pair sits (offsets up to 1e4 s along
  any axis): the verdict does not depend on the unit or the origin.
- ``contact_box_box_pair`` of two boxes apart whose only separating axes are edge–edge axes (an edge above an
  edge, crossing at right angles): the separation is the gap between the edges and the normal is the unit edge
  axis, from A towards B.
- ``overlap_obb_obb_batch`` names each bad array (README: errors start with the argument's name).
- ``convex_axes`` (the candidate axes of ``overlap_convex_sat``) lists every edge direction of a hull once, up to
  sign: for points in general position, exactly the edge directions of scipy's hull.
"""
from __future__ import annotations

import re

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from engine.narrowphase import overlap_convex_sat, overlap_obb_obb_batch
from engine.narrowphase.box_box import contact_box_box_pair

CUBE = np.array([[x, y, z] for x in (0.0, 1.0) for y in (0.0, 1.0) for z in (0.0, 1.0)])


@given(power=st.integers(-300, 300), axis=st.integers(0, 2), offset=st.tuples(*[st.floats(-1e4, 1e4)] * 3),
       along=st.integers(0, 2))
def test_cubes_apart_by_1e_7_of_their_edge_are_apart_at_any_scale_and_place(power, axis, offset, along):
    s = 2.0 ** power
    gap = np.zeros(3)
    gap[along] = 1.0 + 1e-7  # B is A moved by its edge plus 1e-7 of it along one axis
    where = np.array(offset) * s
    a = CUBE * s + where
    b = (CUBE + gap) * s + where
    assert not overlap_convex_sat(a, b), (s, where)
    # and the same pair pressed together by 1e-7 s overlaps
    assert overlap_convex_sat(a, (CUBE + gap - 2e-7 * (gap > 0)) * s + where)


@given(gap=st.floats(1e-6, 0.5), h=st.floats(0.5, 2.0), slide=st.floats(-0.5, 0.5), seed=st.integers(0, 2**32 - 1))
def test_boxes_apart_across_crossing_edges_are_separated_along_the_edge_axis(gap, h, slide, seed):
    """A turned 45° about z (its top edge along z at height √2 h), B turned 45° about x above it (its bottom edge
    along x at height y_B − √2 h): the edges cross at right angles, and every face axis sees the boxes overlap
    when the gap is below (√2 − 1) h; the scene is turned by a random rotation q."""
    q = Rotation.random(random_state=seed).as_matrix()
    half = np.full(3, h)
    ra = Rotation.from_euler("z", 45, degrees=True).as_matrix()
    rb = Rotation.from_euler("x", 45, degrees=True).as_matrix()
    top = np.sqrt(2.0) * h
    g = gap * (np.sqrt(2.0) - 1.0) * h * 0.9
    cb = np.array([slide * h, 2 * top + g, slide * h])
    cs = contact_box_box_pair(np.zeros(3), q @ ra, half, q @ cb, q @ rb, half)
    assert abs(cs.separation[0] - g) <= 1e-12 * h, (cs.separation, g)
    assert np.allclose(cs.normal[0], q @ [0.0, 1.0, 0.0], atol=1e-12), (cs.normal, q @ [0.0, 1.0, 0.0])
    assert cs.points_of(0).shape[0] == 0


GOOD = (np.zeros((1, 3)), np.eye(3)[None], np.ones((1, 3)))


@pytest.mark.parametrize("position, name", [(0, "centers_a"), (1, "axes_a"), (2, "half_extents_a"),
                                            (3, "centers_b"), (4, "axes_b"), (5, "half_extents_b")])
def test_overlap_obb_obb_batch_names_the_bad_array(position, name):
    args = [*GOOD, *GOOD]
    bad = {0: np.full((1, 3), np.nan), 1: 2.0 * np.eye(3)[None], 2: -np.ones((1, 3))}[position % 3]
    args[position] = bad
    with pytest.raises(ValueError) as info:
        overlap_obb_obb_batch(*args)
    assert re.match(rf"{name}\b", str(info.value)), str(info.value)


def _same_direction_sets(got, expected, tol):
    """Every row of each is ±(a row of the other) within tol."""
    def covered(x, y):
        return all(min(np.abs(y - v).max(axis=1).min(), np.abs(y + v).max(axis=1).min()) <= tol for v in x)
    return covered(got, expected) and covered(expected, got)


@given(seed=st.integers(0, 2**32 - 1), n=st.integers(4, 16))
def test_convex_axes_lists_each_edge_direction_of_the_hull_once(seed, n):
    """For points in general position (a hull of triangles only, the same for any quickhull), the edge
    directions are those of scipy's hull, each once up to sign; the face normals are scipy's."""
    from scipy.spatial import ConvexHull

    from engine.narrowphase.sat import convex_axes

    pts = np.random.default_rng(seed).normal(size=(n, 3))
    hull = ConvexHull(pts)
    edges = np.concatenate([pts[hull.simplices[:, k]] - pts[hull.simplices[:, (k + 1) % 3]] for k in range(3)])
    edges /= np.linalg.norm(edges, axis=1)[:, None]
    normals, directions = convex_axes(pts)
    assert _same_direction_sets(directions, edges, 1e-9)
    # no direction twice (u and -u count once)
    for i in range(directions.shape[0]):
        others = np.delete(directions, i, axis=0)
        if others.shape[0]:
            assert min(np.abs(others - directions[i]).max(axis=1).min(),
                       np.abs(others + directions[i]).max(axis=1).min()) > 1e-9
    assert np.allclose(np.linalg.norm(directions, axis=1), 1.0) and np.allclose(np.linalg.norm(normals, axis=1), 1.0)
    unique_normals = hull.equations[:, :3]
    assert all(np.abs(unique_normals - v).max(axis=1).min() <= 1e-9 for v in normals)
