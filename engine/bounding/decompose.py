"""Convex decomposition (chapter slide "Objet convexe": "Décomposition en objets convexes" — a concave object is
handled as a union of convex pieces, each of which the narrow phase can test).

- 2-D, exact: a simple polygon is triangulated by ear clipping (Meisters' two-ears theorem; O'Rourke,
  *Computational Geometry in C*, section 1.6), then Hertel–Mehlhorn (1983) removes every diagonal whose removal
  keeps both of its end vertices convex. The result has at most 2r + 1 convex pieces (r = reflex vertices),
  never more than 4 times the minimum.
- 3-D, approximate: meshes go to the well-kept ``coacd`` library (Wei et al., SIGGRAPH 2022), an optional extra:
  ``pip install "colldet[decompose]"``.
"""
from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .._config import njit
from .._validate import as_float_array
from .aabb import as_points

__all__ = ["triangulate_polygon", "decompose_polygon", "decompose_mesh"]


# ---------------------------------------------------------------------------------------------------------
# kernels
# ---------------------------------------------------------------------------------------------------------
@njit
def _orient(a, b, c):
    """Twice the signed area of (a, b, c): > 0 for a left (counter-clockwise) turn."""
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])


@njit
def _on_segment(a, b, p):
    return min(a[0], b[0]) <= p[0] <= max(a[0], b[0]) and min(a[1], b[1]) <= p[1] <= max(a[1], b[1])


@njit
def _segments_meet(a, b, c, d):
    """Whether the closed segments [a, b] and [c, d] share a point (exact orientation tests)."""
    o1 = _orient(a, b, c)
    o2 = _orient(a, b, d)
    o3 = _orient(c, d, a)
    o4 = _orient(c, d, b)
    if ((o1 > 0 and o2 < 0) or (o1 < 0 and o2 > 0)) and ((o3 > 0 and o4 < 0) or (o3 < 0 and o4 > 0)):
        return True
    if o1 == 0 and _on_segment(a, b, c):
        return True
    if o2 == 0 and _on_segment(a, b, d):
        return True
    if o3 == 0 and _on_segment(c, d, a):
        return True
    if o4 == 0 and _on_segment(c, d, b):
        return True
    return False


@njit
def _first_crossing(poly):
    """-1 if the polygon is simple, else the index of the first edge that meets a non-adjacent edge (or folds
    back on its neighbour). Edge i runs from vertex i to vertex i + 1 (mod n). O(n^2)."""
    n = poly.shape[0]
    for i in range(n):
        a = poly[i]
        b = poly[(i + 1) % n]
        if a[0] == b[0] and a[1] == b[1]:
            return i
        # the next edge must not fold back along this one
        c = poly[(i + 2) % n]
        if _orient(a, b, c) == 0 and (c[0] - b[0]) * (a[0] - b[0]) + (c[1] - b[1]) * (a[1] - b[1]) > 0:
            return i
        for j in range(i + 2, n):
            if i == 0 and j == n - 1:
                continue  # adjacent through vertex 0
            if _segments_meet(a, b, poly[j], poly[(j + 1) % n]):
                return i
    return -1


@njit
def _in_triangle(a, b, c, p):
    """p in the closed counter-clockwise triangle (a, b, c)."""
    return _orient(a, b, p) >= 0 and _orient(b, c, p) >= 0 and _orient(c, a, p) >= 0


@njit
def _ear_clipping_kernel(poly):
    """Triangles (m, 3) of the counter-clockwise simple polygon poly (n, 2), and a status (0 ok, 1 stuck).

    O'Rourke 1.6: vertex i is an ear when it is convex and the triangle (prev, i, next) holds no other polygon
    vertex; clipping an ear leaves a simple polygon with one vertex fewer (two-ears theorem), so n - 3 clips
    and the last triangle finish. Only reflex or flat vertices can lie in a candidate ear, so only they are
    tested. A flat vertex (180 degrees) that blocks every ear is dropped without a triangle (no area lost).
    """
    n = poly.shape[0]
    prev = np.empty(n, dtype=np.int64)
    nxt = np.empty(n, dtype=np.int64)
    for i in range(n):
        prev[i] = (i - 1) % n
        nxt[i] = (i + 1) % n
    triangles = np.empty((n, 3), dtype=np.int64)
    m = 0
    remaining = n
    i = 0
    misses = 0  # consecutive vertices found not to be ears
    while remaining > 3:
        a = prev[i]
        c = nxt[i]
        ear = _orient(poly[a], poly[i], poly[c]) > 0
        if ear:
            j = nxt[c]
            while j != a:
                if _orient(poly[prev[j]], poly[j], poly[nxt[j]]) <= 0 and \
                        _in_triangle(poly[a], poly[i], poly[c], poly[j]):
                    ear = False
                    break
                j = nxt[j]
        if ear:
            triangles[m, 0] = a
            triangles[m, 1] = i
            triangles[m, 2] = c
            m += 1
        if ear or (misses >= remaining and _orient(poly[a], poly[i], poly[c]) == 0):
            nxt[a] = c
            prev[c] = a
            remaining -= 1
            misses = 0
            i = a  # the neighbours' ear status changed: look at them first
            continue
        misses += 1
        if misses > 2 * remaining:
            return triangles[:m], 1
        i = c
    a = prev[i]
    c = nxt[i]
    if _orient(poly[a], poly[i], poly[c]) > 0:
        triangles[m, 0] = a
        triangles[m, 1] = i
        triangles[m, 2] = c
        m += 1
    return triangles[:m], 0


# ---------------------------------------------------------------------------------------------------------
# public functions
# ---------------------------------------------------------------------------------------------------------
def _as_simple_polygon(polygon: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Checked polygon (n, 2) and the vertex order that makes it counter-clockwise."""
    poly = as_points(polygon, "polygon", min_rows=3, dims=(2,))
    bad = _first_crossing(poly)
    if bad >= 0:
        raise ValueError(f"polygon must be simple: edge {bad} (vertex {bad} to {(bad + 1) % len(poly)}) meets "
                         "another edge, folds back, or has zero length")
    nxt = np.roll(poly, -1, axis=0)
    area2 = float(np.sum(poly[:, 0] * nxt[:, 1] - nxt[:, 0] * poly[:, 1]))
    if area2 == 0.0:
        raise ValueError("polygon has zero area")
    order = np.arange(len(poly)) if area2 > 0 else np.arange(len(poly))[::-1].copy()
    return poly, order


def triangulate_polygon(polygon: ArrayLike) -> np.ndarray:
    """Ear-clipping triangulation of a simple polygon (O'Rourke 1.6, Meisters' two-ears theorem).

    Parameters
    ----------
    polygon : array_like, shape (n, 2)
        The vertices in boundary order (either orientation), n >= 3, finite.

    Returns
    -------
    numpy.ndarray, shape (m, 3), int64
        Indices into ``polygon``, each triangle counter-clockwise; m = n − 2 unless some vertices are flat
        (180 degrees), which may be left out.

    Raises
    ------
    ValueError
        When the polygon has fewer than 3 vertices, is not (n, 2), holds NaN or ±inf, is not simple (the
        message names the first edge that meets another edge, folds back or has zero length), or has zero area.
    TypeError
        For a non-numeric polygon.
    """
    poly, order = _as_simple_polygon(polygon)
    local = poly[order] - poly.mean(axis=0)
    triangles, status = _ear_clipping_kernel(local)
    if status != 0:
        raise ValueError("polygon: ear clipping found no ear (the polygon is numerically not simple)")
    return order[triangles]


def _merge_if_convex(pieces: dict[int, list[int]], p: int, q: int, u: int, v: int,
                     poly: np.ndarray) -> list[int] | None:
    """Hertel–Mehlhorn step: glue piece p (holding the edge u -> v) and piece q (holding v -> u) along the
    diagonal; return the merged counter-clockwise piece if u and v stay convex, else None."""
    a = pieces[p]
    b = pieces[q]
    k = a.index(v)
    a = a[k:] + a[:k]          # v ... u
    k = b.index(u)
    b = b[k:] + b[:k]          # u ... v
    merged = a + b[1:-1]       # v ... u ... (back to v)

    def turn(o, x, y):
        return ((poly[x, 0] - poly[o, 0]) * (poly[y, 1] - poly[o, 1])
                - (poly[x, 1] - poly[o, 1]) * (poly[y, 0] - poly[o, 0]))

    size = len(merged)
    for vertex in (u, v):
        i = merged.index(vertex)
        if turn(merged[i - 1], vertex, merged[(i + 1) % size]) < 0:
            return None
    return merged


def decompose_polygon(polygon: ArrayLike) -> list[np.ndarray]:
    """Convex pieces of a simple polygon: triangulation by ear clipping, then Hertel–Mehlhorn removal of the
    inessential diagonals (those whose removal keeps both of their end vertices convex).

    Parameters
    ----------
    polygon : array_like, shape (n, 2)
        As for :func:`triangulate_polygon`.

    Returns
    -------
    list of numpy.ndarray, int64
        Index arrays into ``polygon``, each a convex piece in counter-clockwise order; the pieces tile the
        polygon (disjoint interiors, areas summing to its area). At most 2r + 1 pieces for r reflex vertices,
        never more than 4 times the minimum (1 piece for a convex polygon).

    Raises
    ------
    ValueError, TypeError
        As :func:`triangulate_polygon`.

    Examples
    --------
    An L-shaped hexagon (one reflex vertex, index 3) splits into two convex pieces:

    >>> from engine.bounding import decompose_polygon
    >>> pieces = decompose_polygon([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]])
    >>> len(pieces)
    2
    """
    poly, _ = _as_simple_polygon(polygon)
    triangles = triangulate_polygon(poly)
    local = poly - poly.mean(axis=0)
    pieces: dict[int, list[int]] = {t: [int(x) for x in tri] for t, tri in enumerate(triangles)}
    owner: dict[tuple[int, int], int] = {}
    for t, tri in pieces.items():
        for e in range(3):
            owner[(tri[e], tri[(e + 1) % 3])] = t
    diagonals = [(u, v) for (u, v) in owner if (v, u) in owner and u < v]
    for u, v in diagonals:
        p = owner[(u, v)]
        q = owner[(v, u)]
        merged = _merge_if_convex(pieces, p, q, u, v, local)
        if merged is None:
            continue
        del pieces[q]
        pieces[p] = merged
        del owner[(u, v)], owner[(v, u)]
        for e in range(len(merged)):
            owner[(merged[e], merged[(e + 1) % len(merged)])] = p
    return [np.asarray(piece, dtype=np.int64) for piece in pieces.values()]


def decompose_mesh(vertices: ArrayLike, faces: ArrayLike, *, threshold: float = 0.05, seed: int = 0,
                   **options: Any) -> list[tuple[np.ndarray, np.ndarray]]:
    """Approximate convex decomposition of a 3-D triangle mesh with ``coacd`` (Wei et al., SIGGRAPH 2022).

    ``coacd`` is an optional extra: ``pip install "colldet[decompose]"``.

    Parameters
    ----------
    vertices : array_like, shape (n, 3)
        The mesh's vertices, n >= 4, finite.
    faces : array_like of int, shape (m, 3)
        Triangles as vertex indices in [0, n), m >= 4.
    threshold : float, optional
        coacd's concavity threshold, in (0, 1]: lower gives more, finer pieces.
    seed : int, optional
        coacd's random seed.
    **options
        Passed on to ``coacd.run_coacd``.

    Returns
    -------
    list of (numpy.ndarray, numpy.ndarray)
        The convex pieces, each ``(vertices (k, 3) float64, faces (l, 3) int64)``.

    Raises
    ------
    ImportError
        When coacd is not installed.
    ValueError
        For invalid vertices (NaN, ±inf, fewer than 4, not (n, 3)), faces that are not an (m, 3) integer array
        with m >= 4 or that index past the vertices, or a threshold outside (0, 1].
    TypeError
        For non-numeric vertices.
    """
    try:
        import coacd
    except ImportError as exc:
        raise ImportError("decompose_mesh needs the optional 'coacd' package: pip install 'colldet[decompose]' "
                          "(or pip install coacd); 2-D polygons need nothing extra: use decompose_polygon") from exc
    verts = as_float_array(vertices, "vertices", shape=(None, 3), min_rows=4)
    tri = np.asarray(faces)
    if tri.dtype.kind not in "iu" or tri.ndim != 2 or tri.shape[1] != 3 or tri.shape[0] < 4:
        raise ValueError(f"faces must be an (m, 3) integer array with m >= 4, got {tri.dtype} {tri.shape}")
    bad = (tri < 0) | (tri >= verts.shape[0])
    if bad.any():
        f, e = (int(i) for i in np.argwhere(bad)[0])
        raise ValueError(f"faces[{f}, {e}] = {tri[f, e]} is not a vertex index in [0, {verts.shape[0]})")
    if not 0.0 < float(threshold) <= 1.0:
        raise ValueError(f"threshold must lie in (0, 1], got {threshold!r}")
    mesh = coacd.Mesh(verts, tri.astype(np.int32))
    parts = coacd.run_coacd(mesh, threshold=float(threshold), seed=int(seed), **options)
    return [(np.asarray(v, dtype=np.float64), np.asarray(f, dtype=np.int64)) for v, f in parts]
