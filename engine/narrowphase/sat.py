"""Separating axis theorem (chapter slide "Oriented bounding box OBB": « Théorème de l'axe séparateur »).

Two convex shapes are disjoint iff some axis L separates their projections. For two boxes the candidates are
the 15 axes: the 3 face normals of A, the 3 of B, and the 9 cross products of an edge of A with an edge of B.
Ericson, *Real-Time Collision Detection*, section 4.4.1 (TestOBBOBB): work in A's frame, R = rotation of B in A's
frame, t = translation; on each axis compare |t·L| with the projected radii r_A + r_B. When an edge of A is
parallel to an edge of B, their cross product is (near) zero and every term of that test is round-off; adding a
small epsilon to |R| (``PARALLEL_EPS``) makes such degenerate axes report overlap, never a false separation.

The tests are closed: touching boxes overlap. For convex polyhedra the candidate axes are the face normals of
both hulls and the cross products of their edges (Ericson 5.2.1 and Gottschalk's OBBTree paper). Touching means
what it means for ``gjk_distance`` (distance exactly 0): an axis separates two hulls only when the gap between
their projections exceeds ``OVERLAP_TOL`` × R, with R = max|a − c| + max|b − c| (c the mean of the two centroids)
an upper bound of the size of the Minkowski difference that GJK scales its own tolerance by, plus the round-off
of the projections (``SAT_ROUNDOFF`` × the largest |coordinate|). Any unit axis L that separates the exact
projections proves disjointness, however L was computed, so the axes' own round-off needs no allowance.

Public functions:
- ``obb_overlap(a, b) -> bool`` on two ``engine.bounding.obb.OBB``;
- ``overlap_obb_obb_batch(centers_a, axes_a, half_extents_a, centers_b, axes_b, half_extents_b,
  index_a=None, index_b=None) -> bool (k,)`` — one compiled call; with index arrays, pair p tests box
  ``index_a[p]`` of the A arrays against box ``index_b[p]`` of the B arrays (the dispatch-table form);
- ``overlap_convex_sat(points_a, points_b) -> bool`` on the convex hulls of two point sets;
- ``overlap_convex_sat_pairs(points, offsets, pairs) -> bool (k,)`` — the same over packed shapes (as in
  ``gjk_distance_pairs``), each hull's axes computed once, one compiled call over the pairs.
"""
from __future__ import annotations

import math

import numpy as np

from .._config import njit
from .._validate import as_float_array, check_offsets, check_pairs, pair_indices
from ..bounding.obb import OBB, as_obbs
from .gjk import OVERLAP_TOL

__all__ = ["PARALLEL_EPS", "SAT_ROUNDOFF", "obb_overlap", "overlap_obb_obb_batch", "overlap_convex_sat",
           "overlap_convex_sat_pairs", "convex_axes"]

#: added to |R| in the OBB test (Ericson 4.4.1) to absorb round-off on near-parallel edge pairs
PARALLEL_EPS = 1e-9
#: bound on the round-off of a gap between two computed projections p·L (|L| = 1), relative to the largest
#: |coordinate| X: each dot product is off by at most γ3·Σ|p_k||L_k| <= 3u·√3·X (u = 2^-53), two of them 10.4u·X
SAT_ROUNDOFF = 16.0 * 2.0 ** -53


@njit(inline="always")
def _face_axes_separate(t0, t1, t2, ea, eb, R, AbsR):
    """Whether one of the 6 face normals separates the boxes (Ericson 4.4.1, L = A0, A1, A2, then B0, B1, B2).

    The six tests are or-ed without short-circuit: one well-predicted branch per pair instead of six
    unpredictable ones (most pairs that are apart are separated by some face normal)."""
    # L = A_i: |t_i| > e_A[i] + Σ_j e_B[j] |R[i][j]|
    sep = (abs(t0) > ea[0] + (eb[0] * AbsR[0, 0] + eb[1] * AbsR[0, 1] + eb[2] * AbsR[0, 2])) \
        | (abs(t1) > ea[1] + (eb[0] * AbsR[1, 0] + eb[1] * AbsR[1, 1] + eb[2] * AbsR[1, 2])) \
        | (abs(t2) > ea[2] + (eb[0] * AbsR[2, 0] + eb[1] * AbsR[2, 1] + eb[2] * AbsR[2, 2]))
    # L = B_j: |t · B_j| > Σ_i e_A[i] |R[i][j]| + e_B[j]
    for j in range(3):
        sep |= abs(t0 * R[0, j] + t1 * R[1, j] + t2 * R[2, j]) > \
            (ea[0] * AbsR[0, j] + ea[1] * AbsR[1, j] + ea[2] * AbsR[2, j]) + eb[j]
    return sep


@njit(inline="always")
def _edge_axes_separate(t0, t1, t2, ea, eb, R, AbsR):
    """Whether one of the 9 axes L = A_i x B_j separates the boxes (Ericson 4.4.1, the nine cross-product tests),
    or-ed without short-circuit (the loops unroll at compile time)."""
    # with i1, i2 = i+1, i+2 and j1, j2 = j+1, j+2 (mod 3), |t·L| = |t[i2] R[i1][j] − t[i1] R[i2][j]|,
    # r_A = e_A[i1] |R[i2][j]| + e_A[i2] |R[i1][j]|, r_B = e_B[j1] |R[i][j2]| + e_B[j2] |R[i][j1]|. The sums run over
    # the lower index first, as the book's unrolled lines do, so the rounding is the same as in those lines.
    t = (t0, t1, t2)
    sep = False
    for i in range(3):
        i1 = (i + 1) % 3
        i2 = (i + 2) % 3
        ilo = min(i1, i2)
        ihi = max(i1, i2)
        for j in range(3):
            j1 = (j + 1) % 3
            j2 = (j + 2) % 3
            jlo = min(j1, j2)
            jhi = max(j1, j2)
            sep |= abs(t[i2] * R[i1, j] - t[i1] * R[i2, j]) > ea[ilo] * AbsR[ihi, j] + ea[ihi] * AbsR[ilo, j] \
                + eb[jlo] * AbsR[i, jhi] + eb[jhi] * AbsR[i, jlo]
    return sep


@njit(inline="always")
def _overlap_obb_obb(ca, Aa, ea, cb, Ab, eb, R, AbsR):
    """Ericson 4.4.1 TestOBBOBB. Axes are ROWS of Aa, Ab; ea, eb half extents; R, AbsR (3, 3) scratch.
    True when the boxes overlap (no separating axis among the 15)."""
    # rotation expressing B in A's frame: R[i][j] = A_i · B_j
    for i in range(3):
        for j in range(3):
            R[i, j] = Aa[i, 0] * Ab[j, 0] + Aa[i, 1] * Ab[j, 1] + Aa[i, 2] * Ab[j, 2]
            # common subexpressions, plus epsilon against a null cross product of parallel edges
            AbsR[i, j] = abs(R[i, j]) + PARALLEL_EPS
    # translation, in A's frame
    dx = cb[0] - ca[0]
    dy = cb[1] - ca[1]
    dz = cb[2] - ca[2]
    t0 = dx * Aa[0, 0] + dy * Aa[0, 1] + dz * Aa[0, 2]
    t1 = dx * Aa[1, 0] + dy * Aa[1, 1] + dz * Aa[1, 2]
    t2 = dx * Aa[2, 0] + dy * Aa[2, 1] + dz * Aa[2, 2]
    if _face_axes_separate(t0, t1, t2, ea, eb, R, AbsR):
        return False
    return not _edge_axes_separate(t0, t1, t2, ea, eb, R, AbsR)


@njit
def _overlap_obb_obb_batch(ca, Aa, ea, cb, Ab, eb, index_a, index_b, out):
    R = np.empty((3, 3))
    AbsR = np.empty((3, 3))
    for p in range(out.shape[0]):
        i = index_a[p]
        j = index_b[p]
        out[p] = _overlap_obb_obb(ca[i], Aa[i], ea[i], cb[j], Ab[j], eb[j], R, AbsR)


@njit
def _touching_tolerance(pa, pb):
    """The gap along a unit axis below which two hulls touch: OVERLAP_TOL × R + SAT_ROUNDOFF × X, where
    R = max|a − c| + max|b − c| >= |a − b| for every a, b (c the mean of the two centroids: R does not change when
    both shapes move) bounds the size of the Minkowski difference, and X is the largest |coordinate|."""
    cx, cy, cz = 0.0, 0.0, 0.0
    for pts in (pa, pb):
        for i in range(pts.shape[0]):
            cx += pts[i, 0] / (2 * pts.shape[0])
            cy += pts[i, 1] / (2 * pts.shape[0])
            cz += pts[i, 2] / (2 * pts.shape[0])
    big = 0.0
    size = 0.0
    for pts in (pa, pb):
        r2 = 0.0
        for i in range(pts.shape[0]):
            dx, dy, dz = pts[i, 0] - cx, pts[i, 1] - cy, pts[i, 2] - cz
            r2 = max(r2, dx * dx + dy * dy + dz * dz)
            big = max(big, abs(pts[i, 0]), abs(pts[i, 1]), abs(pts[i, 2]))
        size += math.sqrt(r2)
    return OVERLAP_TOL * size + SAT_ROUNDOFF * big


@njit(inline="always")
def _projection(pts, lx, ly, lz):
    """The interval [min, max] of p · L over the rows p of ``pts`` (n, 3), L = (lx, ly, lz)."""
    lo = np.inf
    hi = -np.inf
    for i in range(pts.shape[0]):
        d = pts[i, 0] * lx + pts[i, 1] * ly + pts[i, 2] * lz
        lo = min(lo, d)
        hi = max(hi, d)
    return lo, hi


@njit
def _overlap_along_axes(pa, pb, axes):
    """SAT on given candidate axes (k, 3): False as soon as one axis separates the projections by more than
    ``_touching_tolerance`` (closed test: touching hulls overlap, as GJK's distance 0)."""
    tol = _touching_tolerance(pa, pb)
    for k in range(axes.shape[0]):
        min_a, max_a = _projection(pa, axes[k, 0], axes[k, 1], axes[k, 2])
        min_b, max_b = _projection(pb, axes[k, 0], axes[k, 1], axes[k, 2])
        if min_b - max_a > tol or min_a - max_b > tol:
            return False
    return True


# ---------------------------------------------------------------------------------------------------------------

def obb_overlap(a: OBB, b: OBB) -> bool:
    """Whether two oriented boxes overlap or touch: the separating axis theorem on 15 axes (Ericson 4.4.1).

    The candidate axes are the 3 face normals of each box and the 9 cross products of an edge of A with an edge of
    B; the boxes are disjoint iff on some axis L, ``|t·L| > r_A + r_B`` (t the centre offset, r the projected
    half sizes). ``PARALLEL_EPS`` added to ``|R|`` keeps near-parallel edge pairs from reporting a false separation.

    Parameters
    ----------
    a, b : engine.bounding.OBB
        The two boxes (``OBB(center, axes, half_extents)``, rows of ``axes`` the unit axes).

    Returns
    -------
    bool
        True when the closed boxes share a point.

    Raises
    ------
    TypeError
        When ``a`` or ``b`` is not an ``OBB`` (named).

    Examples
    --------
    >>> import numpy as np
    >>> from engine import OBB, obb_overlap
    >>> a = OBB([0.0, 0.0, 0.0], np.eye(3), [1.0, 1.0, 1.0])
    >>> obb_overlap(a, OBB([1.9, 0.0, 0.0], np.eye(3), [1.0, 1.0, 1.0]))
    True
    >>> obb_overlap(a, OBB([2.1, 0.0, 0.0], np.eye(3), [1.0, 1.0, 1.0]))
    False
    """
    for name, box in (("a", a), ("b", b)):
        if not isinstance(box, OBB):
            raise TypeError(f"{name} must be an engine.bounding.obb.OBB, got {type(box).__name__}")
    return bool(_overlap_obb_obb(a.center, a.axes, a.half_extents, b.center, b.axes, b.half_extents,
                                 np.empty((3, 3)), np.empty((3, 3))))


def overlap_obb_obb_batch(centers_a, axes_a, half_extents_a, centers_b, axes_b, half_extents_b,
                          index_a=None, index_b=None) -> np.ndarray:
    """The 15-axis SAT of ``obb_overlap`` on k box pairs, in one compiled call.

    float64 C-contiguous arrays are checked in one compiled pass and read in place (never copied, never
    written); other array-likes are copied first.

    Parameters
    ----------
    centers_a : array_like, shape (n, 3), float64
        Centres of the A boxes.
    axes_a : array_like, shape (n, 3, 3), float64
        Their axes: the ROWS of ``axes_a[i]`` are box i's unit axes (orthonormal to 1e-9).
    half_extents_a : array_like, shape (n, 3), float64
        Half extents along those axes, >= 0.
    centers_b, axes_b, half_extents_b : array_like, shapes (m, 3), (m, 3, 3), (m, 3)
        The B boxes, likewise.
    index_a, index_b : array_like, shape (k,), int, optional
        Box rows paired, :ref:`batched-pairs`.

    Returns
    -------
    numpy.ndarray, shape (k,), bool
        True where the boxes of pair p overlap or touch.

    Raises
    ------
    ValueError
        Also for non-orthonormal axes or a negative half extent (named with the box index).
    """
    # the kernel only reads the boxes: float64 C-contiguous arrays are checked in place, not copied
    ca, ra, ea = as_obbs(centers_a, axes_a, half_extents_a, ("centers_a", "axes_a", "half_extents_a"), copy=False)
    cb, rb, eb = as_obbs(centers_b, axes_b, half_extents_b, ("centers_b", "axes_b", "half_extents_b"), copy=False)
    ia, ib = pair_indices(ca.shape[0], cb.shape[0], index_a, index_b)
    out = np.empty(ia.shape[0], np.bool_)
    if out.shape[0]:
        _overlap_obb_obb_batch(ca, ra, ea, cb, rb, eb, ia, ib, out)
    return out


def convex_axes(points):
    """Candidate separating axes of one hull: ``(face_normals (f, 3), edge_directions (e, 3))``, unit vectors.

    Faces and edges come from the engine's quickhull (``engine.bounding.hull.convex_hull``: outward unit normals,
    triangulated faces; the extra diagonals of non-triangular faces are harmless extra axes). Point sets that span
    less than 3-D have no 3-D hull and use the directions of the set itself.
    """
    from ..bounding.hull import convex_hull

    pts = np.asarray(points, dtype=np.float64)
    try:
        hull = convex_hull(pts)
    except ValueError:
        return _flat_axes(pts)
    normals = np.array(hull.normals)
    simplices = hull.faces
    edges = np.concatenate([pts[simplices[:, 1]] - pts[simplices[:, 0]],
                            pts[simplices[:, 2]] - pts[simplices[:, 1]],
                            pts[simplices[:, 0]] - pts[simplices[:, 2]]])
    lengths = np.linalg.norm(edges, axis=1)
    edges = edges[lengths > 0] / lengths[lengths > 0, None]
    return normals, _unique_directions(edges)


def _unique_directions(dirs: np.ndarray) -> np.ndarray:
    """Drop repeated directions (u and -u count once), rounding to 12 decimals."""
    if dirs.shape[0] == 0:
        return dirs
    sign = np.where(dirs[np.arange(dirs.shape[0]), np.argmax(np.abs(dirs), axis=1)] < 0, -1.0, 1.0)
    canon = dirs * sign[:, None]
    _, keep = np.unique(np.round(canon, 12), axis=0, return_index=True)
    return canon[np.sort(keep)]


def _flat_axes(pts: np.ndarray):
    """Axes of a point set of dimension < 3: its principal directions and the segment directions between points."""
    centered = pts - pts.mean(axis=0)
    _, _, vt = np.linalg.svd(centered, full_matrices=True)
    diff = (pts[:, None, :] - pts[None, :, :]).reshape(-1, 3)
    n = np.linalg.norm(diff, axis=1)
    return vt, _unique_directions(diff[n > 0] / n[n > 0, None])


@njit
def _overlap_convex_pairs(points, offsets, normals, normal_off, edges, edge_off, pairs, out):
    """SAT over k pairs of packed hulls (Ericson 5.2.1): pair p = (i, j) is tested on the face normals of i, then
    of j, then on every cross product of an edge direction of i with one of j (unit, skipped when the edges are
    parallel: |e_i × e_j| <= 1e-9, whose plane's normal is among the face normals). Closed: touching overlaps."""
    n_axes = 1
    for s in range(normal_off.shape[0] - 1):
        n_axes = max(n_axes, normal_off[s + 1] - normal_off[s])
    big_e = 1
    for s in range(edge_off.shape[0] - 1):
        big_e = max(big_e, edge_off[s + 1] - edge_off[s])
    axes = np.empty((2 * n_axes + big_e * big_e, 3))
    for p in range(pairs.shape[0]):
        i = pairs[p, 0]
        j = pairs[p, 1]
        k = 0
        for s in (i, j):
            for f in range(normal_off[s], normal_off[s + 1]):
                axes[k, 0] = normals[f, 0]
                axes[k, 1] = normals[f, 1]
                axes[k, 2] = normals[f, 2]
                k += 1
        for a in range(edge_off[i], edge_off[i + 1]):
            for b in range(edge_off[j], edge_off[j + 1]):
                cx = edges[a, 1] * edges[b, 2] - edges[a, 2] * edges[b, 1]
                cy = edges[a, 2] * edges[b, 0] - edges[a, 0] * edges[b, 2]
                cz = edges[a, 0] * edges[b, 1] - edges[a, 1] * edges[b, 0]
                length = math.sqrt(cx * cx + cy * cy + cz * cz)
                if length > 1e-9:  # parallel edges give no new axis
                    axes[k, 0] = cx / length
                    axes[k, 1] = cy / length
                    axes[k, 2] = cz / length
                    k += 1
        out[p] = _overlap_along_axes(points[offsets[i]:offsets[i + 1]], points[offsets[j]:offsets[j + 1]],
                                     axes[:k])


def _pack_axes(pts, off, shapes):
    """convex_axes of every shape in ``shapes`` (once each), packed: (normals, normal offsets, edges, edge
    offsets) over all S shapes (shapes not listed get none)."""
    s = off.shape[0] - 1
    normals = [np.empty((0, 3))] * s
    edges = [np.empty((0, 3))] * s
    for i in shapes:
        normals[i], edges[i] = convex_axes(pts[off[i]:off[i + 1]])
    normal_off = np.zeros(s + 1, np.int64)
    np.cumsum([n.shape[0] for n in normals], out=normal_off[1:])
    edge_off = np.zeros(s + 1, np.int64)
    np.cumsum([e.shape[0] for e in edges], out=edge_off[1:])
    return _stack(normals), normal_off, _stack(edges), edge_off


def _stack(arrays) -> np.ndarray:
    return np.ascontiguousarray(np.concatenate(arrays), dtype=np.float64) if arrays else np.empty((0, 3))


def _overlap_convex_batch(pts, off, pr) -> np.ndarray:
    out = np.empty(pr.shape[0], np.bool_)
    if pr.shape[0]:
        normals, normal_off, edges, edge_off = _pack_axes(pts, off, np.unique(pr))
        _overlap_convex_pairs(pts, off, normals, normal_off, edges, edge_off, pr, out)
    return out


def overlap_convex_sat_pairs(points, offsets, pairs) -> np.ndarray:
    """SAT over k pairs of packed convex hulls, in one compiled call.

    Each shape's face normals and edge directions (``convex_axes``, the engine's quickhull) are computed once,
    however many pairs it is in; then one kernel tests every pair on its candidate axes: the face normals of both
    hulls and the cross products of their edges (Ericson 5.2.1).

    Parameters
    ----------
    points, offsets, pairs
        The shapes, each the hull of its points, and the pairs: :ref:`packed-point-sets`.

    Returns
    -------
    numpy.ndarray, shape (k,), bool
        True where the hulls of ``pairs[p]`` overlap or touch.
    """
    pts = as_float_array(points, "points", shape=(None, 3))
    off = check_offsets(offsets, pts.shape[0])
    pr = check_pairs(pairs, off.shape[0] - 1)
    return _overlap_convex_batch(pts, off, pr)


def overlap_convex_sat(points_a, points_b) -> bool:
    """Whether the convex hulls of two point sets overlap or touch, by the separating axis theorem.

    Candidate axes: the face normals of both hulls and the cross products of every edge pair (Ericson 5.2.1).
    Flat or degenerate sets (segments, polygons) are accepted. ``overlap_convex_sat_pairs`` on one pair.

    Parameters
    ----------
    points_a : array_like, shape (n, 3), float64
        Points whose hull is A, n >= 1, finite.
    points_b : array_like, shape (m, 3), float64
        Points whose hull is B, m >= 1.

    Returns
    -------
    bool
        True when no candidate axis separates the hulls.

    Raises
    ------
    ValueError
        For an empty set, a shape other than (n, 3), NaN or ±inf (named with the argument and index).
    """
    pa = as_float_array(points_a, "points_a", shape=(None, 3), min_rows=1)
    pb = as_float_array(points_b, "points_b", shape=(None, 3), min_rows=1)
    off = np.array([0, pa.shape[0], pa.shape[0] + pb.shape[0]], np.int64)
    return bool(_overlap_convex_batch(np.concatenate([pa, pb]), off, np.array([[0, 1]], np.int64))[0])
