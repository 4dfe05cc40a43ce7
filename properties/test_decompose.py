"""Convex decomposition of simple polygons (ear clipping + Hertel–Mehlhorn) and of meshes (coacd, if installed).

Oracles: exact area bookkeeping (shoelace), matplotlib's point-in-polygon (``Path.contains_points``) for "every
piece lies in the polygon", Qhull for "every piece is convex", and the Hertel–Mehlhorn bound of 2r + 1 pieces.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from matplotlib.path import Path
from scipy.spatial import ConvexHull as QhullHull

from engine.bounding.decompose import decompose_mesh, decompose_polygon, triangulate_polygon
from engine.bounding.hull import convex_hull, is_convex
from properties.strategies.geometry import convex_polygons, seeds, star_polygons

polygons = st.one_of(star_polygons(), convex_polygons())


def signed_area(poly) -> float:
    rel = poly - poly[0]
    nxt = np.roll(rel, -1, axis=0)
    return 0.5 * float(np.sum(rel[:, 0] * nxt[:, 1] - nxt[:, 0] * rel[:, 1]))


def reflex_count(poly) -> int:
    sign = np.sign(signed_area(poly))
    prev, nxt = np.roll(poly, 1, axis=0), np.roll(poly, -1, axis=0)
    turn = (poly[:, 0] - prev[:, 0]) * (nxt[:, 1] - poly[:, 1]) - (poly[:, 1] - prev[:, 1]) * (nxt[:, 0] - poly[:, 0])
    return int((sign * turn < 0).sum())


def interior_probe(piece_points) -> np.ndarray:
    """Points strictly inside a convex piece: its centroid and points pulled from each vertex towards it."""
    centroid = piece_points.mean(axis=0)
    return np.vstack([centroid, 0.9 * centroid + 0.1 * piece_points])


@given(polygons)
def test_triangulation_tiles_the_polygon(poly):
    tris = triangulate_polygon(poly)
    n = len(poly)
    area = abs(signed_area(poly))
    assert tris.shape == (n - 2, 3)
    assert ((tris >= 0) & (tris < n)).all()
    areas = np.array([signed_area(poly[t]) for t in tris])
    assert (areas > 0).all()  # counter-clockwise, non-degenerate
    assert areas.sum() == pytest.approx(area, rel=1e-9)
    path = Path(poly)
    for t in tris:
        assert path.contains_points(interior_probe(poly[t])).all()
    # every polygon edge is a triangle edge
    edges = {frozenset((int(t[i]), int(t[(i + 1) % 3]))) for t in tris for i in range(3)}
    assert all(frozenset((i, (i + 1) % n)) in edges for i in range(n))


@given(polygons)
def test_hertel_mehlhorn_pieces_are_convex_tile_the_polygon_and_are_few(poly):
    pieces = decompose_polygon(poly)
    area = abs(signed_area(poly))
    total = 0.0
    path = Path(poly)
    for piece in pieces:
        pts = poly[piece]
        assert signed_area(pts) > 0  # counter-clockwise
        assert is_convex(pts)
        assert len(QhullHull(pts).vertices) == len(pts) or len(pts) == 3  # Qhull: every vertex is a corner
        assert path.contains_points(interior_probe(pts)).all()
        total += signed_area(pts)
    assert total == pytest.approx(area, rel=1e-9)
    used = np.concatenate(pieces)
    assert set(used.tolist()) == set(range(len(poly)))
    r = reflex_count(poly)
    assert len(pieces) <= 2 * r + 1
    assert len(pieces) >= -(-r // 2) + 1 if r else len(pieces) == 1  # no decomposition has fewer than ceil(r/2)+1


@given(convex_polygons(), st.booleans())
def test_a_convex_polygon_is_one_piece(poly, reverse):
    poly = poly[::-1] if reverse else poly
    pieces = decompose_polygon(poly)
    assert len(pieces) == 1 and sorted(pieces[0].tolist()) == list(range(len(poly)))


def test_known_shapes():
    l_shape = np.array([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]], dtype=float)
    pieces = decompose_polygon(l_shape)
    assert len(pieces) == 2
    comb = np.array([[0, 0], [5, 0], [5, 2], [4, 2], [4, 1], [3, 1], [3, 2], [2, 2], [2, 1], [1, 1], [1, 2],
                     [0, 2]], dtype=float)
    assert 3 <= len(decompose_polygon(comb)) <= 2 * 4 + 1
    with_flat_vertex = np.array([[0, 0], [1, 0], [2, 0], [2, 1], [0, 1]], dtype=float)
    assert len(decompose_polygon(with_flat_vertex)) == 1


@given(star_polygons(min_size=5), seeds)
def test_non_simple_polygons_raise_value_error(poly, seed):
    rng = np.random.default_rng(seed)
    i, j = sorted(rng.choice(len(poly), size=2, replace=False))
    assert j > i
    crossed = poly.copy()
    crossed[[i, j]] = crossed[[j, i]]  # swapping two vertices usually makes edges cross
    edges = [(crossed[k], crossed[(k + 1) % len(crossed)]) for k in range(len(crossed))]
    if not _any_crossing(edges):
        return
    with pytest.raises(ValueError, match="simple"):
        decompose_polygon(crossed)
    with pytest.raises(ValueError, match="simple"):
        triangulate_polygon(crossed)


def _any_crossing(edges) -> bool:
    """Numpy oracle: two non-adjacent edges properly cross."""
    n = len(edges)

    def orient(a, b, c):
        return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])

    for i in range(n):
        for j in range(i + 2, n):
            if i == 0 and j == n - 1:
                continue
            (a, b), (c, d) = edges[i], edges[j]
            if orient(a, b, c) * orient(a, b, d) < 0 and orient(c, d, a) * orient(c, d, b) < 0:
                return True
    return False


@pytest.mark.parametrize("bad", [
    np.array([[0, 0], [1, 1], [1, 0], [0, 1]], dtype=float),      # bow tie
    np.array([[0, 0], [1, 0], [1, 0], [0, 1]], dtype=float),      # zero-length edge
    np.array([[0, 0], [2, 0], [1, 0], [1, 1]], dtype=float),      # folds back on itself
    np.array([[0, 0], [1, 0]], dtype=float),                      # too few vertices
    np.array([[0, 0], [1, np.nan], [0, 1]], dtype=float),         # NaN
    np.zeros((4, 3)),                                             # not 2-D
])
def test_bad_polygons_raise_value_error(bad):
    with pytest.raises(ValueError):
        decompose_polygon(bad)


def test_mesh_decomposition_without_coacd_says_how_to_install_it():
    try:
        import coacd  # noqa: F401
    except ImportError:
        cube = convex_hull(np.array([[i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 1)], dtype=float))
        with pytest.raises(ImportError, match="pip install"):
            decompose_mesh(cube.points, cube.faces)
    else:
        pytest.skip("coacd is installed: see test_mesh_decomposition_with_coacd")


def extruded_prism(poly, height=1.0):
    """A closed, outward-oriented triangle mesh of the polygon (counter-clockwise) extruded along z."""
    n = len(poly)
    vertices = np.vstack([np.column_stack([poly, np.zeros(n)]), np.column_stack([poly, np.full(n, height)])])
    caps = triangulate_polygon(poly)
    faces = [caps[:, ::-1], caps + n]  # bottom faces down, top faces up
    for i in range(n):
        j = (i + 1) % n
        faces.append(np.array([[i, j, j + n], [i, j + n, i + n]]))
    return vertices, np.vstack(faces)


def test_mesh_decomposition_with_coacd():
    pytest.importorskip("coacd")
    l_shape = np.array([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]], dtype=float)
    vertices, faces = extruded_prism(l_shape)
    parts = decompose_mesh(vertices, faces, threshold=0.05)
    assert len(parts) >= 2  # the L is not convex
    total = 0.0
    for part_vertices, part_faces in parts:
        assert is_convex(part_vertices, part_faces, tol=1e-6)
        total += convex_hull(part_vertices).volume
    assert total == pytest.approx(3.0, rel=0.1)
