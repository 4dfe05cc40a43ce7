"""Convex hull (quickhull 3-D, monotone chain 2-D) and the convexity test.

Oracle: scipy.spatial.ConvexHull (Qhull) — same vertex set, volume and area on general-position input.
Degenerate input (duplicates, collinear, coplanar, too few points) gives a ValueError or, for duplicates, the
hull of the distinct points — never a wrong hull.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st
from scipy.spatial import ConvexHull as QhullHull

from engine.bounding.hull import convex_hull, is_convex
from properties.strategies.geometry import (
    convex_polygons,
    general_position_clouds,
    point_clouds,
    rigid_motions,
    seeds,
    star_polygons,
)

dims = st.sampled_from([2, 3])
gp_clouds = dims.flatmap(lambda d: general_position_clouds(d, max_size=120))


def scale_of(points) -> float:
    return float(np.abs(points).max() + np.ptp(points, axis=0).max())


@given(gp_clouds)
def test_hull_matches_qhull_on_general_position_input(pts):
    hull = convex_hull(pts)
    ref = QhullHull(pts)
    assert set(hull.vertices.tolist()) == set(ref.vertices.tolist())
    assert hull.volume == pytest.approx(ref.volume, rel=1e-9)
    assert hull.area == pytest.approx(ref.area, rel=1e-9)
    if pts.shape[1] == 3:
        assert len(hull.faces) == 2 * len(hull.vertices) - 4  # a closed triangulated sphere
        assert set(np.unique(hull.faces).tolist()) == set(hull.vertices.tolist())


@given(gp_clouds)
def test_faces_are_outward_and_every_point_is_inside(pts):
    hull = convex_hull(pts)
    tol = 1e-9 * scale_of(pts)
    dist = pts @ hull.normals.T - hull.offsets
    assert dist.max() <= tol
    # outward: the centroid of the vertices is strictly inside every face plane
    centroid = pts[hull.vertices].mean(axis=0)
    assert (hull.normals @ centroid - hull.offsets < 0).all()
    if pts.shape[1] == 3:
        a, b, c = (pts[hull.faces[:, i]] for i in range(3))
        cross = np.cross(b - a, c - a)
        assert (np.einsum("ij,ij->i", cross, hull.normals) > 0).all()  # counter-clockwise seen from outside
        assert is_convex(pts, hull.faces)
    else:
        ring = pts[hull.vertices]
        nxt = np.roll(ring, -1, axis=0)
        assert np.sum(ring[:, 0] * nxt[:, 1] - nxt[:, 0] * ring[:, 1]) > 0  # counter-clockwise
        assert is_convex(ring)
        assert np.array_equal(hull.faces[:, 1], np.roll(hull.faces[:, 0], -1))


@given(gp_clouds, st.data())
def test_hull_volume_is_invariant_under_rigid_motions(pts, data):
    rotation, translation = data.draw(rigid_motions(pts.shape[1]))
    hull = convex_hull(pts)
    moved = convex_hull(pts @ rotation.T + translation)
    assert moved.volume == pytest.approx(hull.volume, rel=1e-8)
    assert set(moved.vertices.tolist()) == set(hull.vertices.tolist())


@given(gp_clouds, seeds)
def test_duplicates_give_the_hull_of_the_distinct_points(pts, seed):
    rng = np.random.default_rng(seed)
    doubled = np.vstack([pts, pts[rng.integers(0, len(pts), size=len(pts))]])
    doubled = doubled[rng.permutation(len(doubled))]
    hull = convex_hull(doubled)
    ref = convex_hull(pts)
    got = {tuple(p) for p in doubled[hull.vertices]}
    assert got == {tuple(p) for p in pts[ref.vertices]}
    assert len(got) == len(hull.vertices)  # one index per distinct vertex
    assert hull.volume == pytest.approx(ref.volume, rel=1e-9)


@given(point_clouds(3, min_size=1, max_size=40), seeds, st.sampled_from(["equal", "collinear", "coplanar"]))
def test_lower_dimensional_input_raises_value_error(pts, seed, kind):
    rng = np.random.default_rng(seed)
    n = len(pts)
    if kind == "equal":
        flat = np.repeat(pts[:1], n + 4, axis=0)
    elif kind == "collinear":
        flat = pts[:1] + np.outer(rng.integers(-5, 6, size=n + 4), rng.integers(-3, 4, size=3))
    else:
        basis = rng.integers(-3, 4, size=(2, 3)).astype(float)
        flat = pts[:1] + rng.integers(-5, 6, size=(n + 4, 2)) @ basis
    with pytest.raises(ValueError, match="points"):
        convex_hull(flat)
    # the 2-D analogue: equal or collinear
    if kind != "coplanar":
        with pytest.raises(ValueError, match="points"):
            convex_hull(flat[:, :2])


@st.composite
def lattice_clouds(draw):
    """Degenerate but full-dimensional input: small-integer lattice points (many duplicates, and many points
    on the hull's faces and edges that are not corners), possibly far from the origin."""
    dim = draw(dims)
    n = draw(st.integers(dim + 1, 80))
    rng = np.random.default_rng(draw(seeds))
    width = draw(st.integers(1, 4))
    pts = rng.integers(-width, width + 1, size=(n, dim)).astype(float)
    if draw(st.booleans()):  # points on the surface of a box only
        axis = rng.integers(0, dim, size=n)
        pts[np.arange(n), axis] = rng.choice([-width, width], size=n)
    return pts * draw(st.sampled_from([1.0, 0.1, 1e3])) + draw(st.sampled_from([0.0, 1e3]))


@given(lattice_clouds())
def test_degenerate_lattice_input_gives_qhulls_corners_or_a_value_error(pts):
    """Points inside faces or on edges are never reported as vertices; flat input is rejected, as Qhull does."""
    try:
        ref = QhullHull(pts)
    except Exception:  # Qhull refuses flat input: so must we
        with pytest.raises(ValueError, match="points"):
            convex_hull(pts)
        return
    hull = convex_hull(pts)
    assert {tuple(p) for p in pts[hull.vertices]} == {tuple(p) for p in pts[ref.vertices]}
    assert len(hull.vertices) == len({tuple(p) for p in pts[ref.vertices]})
    assert hull.volume == pytest.approx(ref.volume, rel=1e-9)


@pytest.mark.parametrize("pts", [np.zeros((3, 3)), np.eye(3), np.zeros((2, 2)), np.ones((1, 2))])
def test_too_few_points_raise_value_error(pts):
    with pytest.raises(ValueError, match="at least"):
        convex_hull(pts)


# a sliver base triangle (area 2.5e3, 2e3 long) 1.4e6 from the apex's axis: the volume summed from the vertex
# centroid lost 1.3e-9 (relative) on input whose volume has a condition number of 8.8e5 (8.8e5 × 2^-53 = 1e-10)
@example(base2d=np.array([[999737.2257234898, 998907.8762778555], [1001192.9593793573, 998782.9197717906],
                          [999173.6405419064, 998959.6667821173]]), seed=2560917506)
@given(general_position_clouds(2, min_size=3, max_size=40), seeds)
def test_coplanar_base_plus_apex_is_a_pyramid(base2d, seed):
    """A degenerate-looking but full-dimensional input: many coplanar points and one apex."""
    rng = np.random.default_rng(seed)
    base = np.column_stack([base2d, np.zeros(len(base2d))])
    apex = np.array([[0.0, 0.0, rng.uniform(0.5, 2.0)]]) * scale_of(base2d)
    pts = np.vstack([base, apex])
    hull = convex_hull(pts)
    base_hull = convex_hull(base2d)
    assert hull.volume == pytest.approx(base_hull.volume * apex[0, 2] / 3.0, rel=1e-9)
    assert set(hull.vertices.tolist()) == set(base_hull.vertices.tolist()) | {len(base)}


def test_cube_with_interior_and_repeated_points():
    cube = np.array([[i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 1)], dtype=float)
    pts = np.vstack([cube, cube, cube * 0.5 + 0.25, [[0.5, 0.5, 1.0], [0.5, 0.0, 0.5]]])  # face points
    hull = convex_hull(pts)
    assert hull.volume == pytest.approx(1.0, rel=1e-12) and hull.area == pytest.approx(6.0, rel=1e-12)
    assert {tuple(p) for p in pts[hull.vertices]} == {tuple(p) for p in cube}
    assert len(hull.vertices) == 8


@pytest.mark.parametrize("bad", [np.array([[0, 0, 0], [1, 0, np.nan], [0, 1, 0], [0, 0, 1.0]]),
                                 np.array([[0, 0, 0, 0.0]] * 5), np.zeros((0, 3))])
def test_bad_hull_input_raises_value_error(bad):
    with pytest.raises(ValueError):
        convex_hull(bad)


# ------------------------------------------------------------------------------------------------------------
# convexity (slide "Objet convexe")
# ------------------------------------------------------------------------------------------------------------
@given(convex_polygons())
def test_convex_polygons_are_convex_in_either_orientation(poly):
    assert is_convex(poly)
    assert is_convex(poly[::-1])
    assert is_convex(np.roll(poly, 3, axis=0))


@given(star_polygons())
def test_polygon_convexity_agrees_with_qhull(poly):
    """Oracle: a simple polygon is (strictly) convex iff Qhull keeps all its vertices."""
    ref = len(QhullHull(poly).vertices) == len(poly)
    assume(ref or not _nearly_flat(poly))
    assert is_convex(poly) == ref


def _nearly_flat(poly) -> bool:
    prev, nxt = np.roll(poly, 1, axis=0), np.roll(poly, -1, axis=0)
    u, v = poly - prev, nxt - poly
    sine = (u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]) / (np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1))
    return bool((np.abs(sine) < 1e-6).any())


@given(convex_polygons(min_size=3, max_size=12))
def test_a_line_meets_a_convex_polygon_boundary_at_most_twice(poly):
    """The slide's literal criterion, checked on lines through random pairs of boundary points."""
    assume(is_convex(poly))
    rng = np.random.default_rng(len(poly))
    n = len(poly)
    for _ in range(10):
        p = poly[rng.integers(n)] * 0.3 + poly[rng.integers(n)] * 0.7
        d = rng.normal(size=2)
        crossings = 0
        for i in range(n):
            a, b = poly[i], poly[(i + 1) % n]
            sa = d[0] * (a[1] - p[1]) - d[1] * (a[0] - p[0])
            sb = d[0] * (b[1] - p[1]) - d[1] * (b[0] - p[0])
            if (sa > 0) != (sb > 0):
                crossings += 1
        assert crossings <= 2


def test_polygon_traversed_twice_or_self_crossing_is_not_convex():
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    assert is_convex(square)
    assert not is_convex(np.vstack([square, square]))
    assert not is_convex(square[[0, 2, 1, 3]])  # a bow tie
    assert not is_convex(np.array([[0, 0], [2, 0], [1, 0.2], [2, 2], [0, 2.0]]))
    pentagram = np.array([[np.cos(a), np.sin(a)] for a in np.arange(5) * 4 * np.pi / 5])
    assert not is_convex(pentagram)


@settings(max_examples=60)
@given(general_position_clouds(3, min_size=6, max_size=40), seeds)
def test_polyhedron_convexity_detects_a_dented_vertex(pts, seed):
    hull = convex_hull(pts)
    vertices = pts.copy()
    assert is_convex(vertices, hull.faces)
    assert is_convex(vertices, hull.faces[:, ::-1])  # all faces inward: same answer
    # push one hull vertex to the centroid: the surface gets a dent
    rng = np.random.default_rng(seed)
    v = hull.vertices[rng.integers(len(hull.vertices))]
    dented = vertices.copy()
    dented[v] = pts[hull.vertices].mean(axis=0) * 0.9 + vertices[v] * 0.1
    assume(len(QhullHull(dented[hull.vertices]).vertices) < len(hull.vertices))  # oracle: really dented
    assert not is_convex(dented, hull.faces)


def test_is_convex_rejects_bad_arguments():
    with pytest.raises(ValueError):
        is_convex(np.zeros((2, 2)))
    with pytest.raises(ValueError):
        is_convex(np.eye(3))  # 3-D needs faces
    with pytest.raises(ValueError):
        is_convex(np.eye(4)[:, :3], np.array([[0, 1, 5], [0, 1, 2], [0, 2, 3], [1, 2, 3]]))
    with pytest.raises(ValueError):
        is_convex(np.zeros((3, 2)), tol=-1.0)
