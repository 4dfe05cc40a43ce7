"""Penetration of two convex hulls: the chain GJK → EPA → exact fallback → rescaling, written once.

    scale the pair by a power of two when it is tiny or huge              (engine.narrowphase.rescale)
    GJK (engine.narrowphase.gjk):
        apart            -> signed distance d > 0, normal along the closest points
        touching, no full simplex -> 0, a normal of M's normal cone (engine.narrowphase.touching_normal)
        overlapping      -> EPA from GJK's simplex (engine.narrowphase.epa): −depth, M's face normal
    EPA broken by round-off (many coplanar support points, e.g. boxes sharing axes; about 1 pair in 10^4 of such
    adversarial inputs) -> the exact answer from Qhull on the Minkowski difference (``minkowski_fallback``)

``penetration_kernel`` is the compiled chain for one pair, ``penetration_pairs`` the batch (one compiled loop,
then the fallback in Python for the pairs EPA gave up on); ``epa_penetration``, ``epa_penetration_pairs`` and
``engine.narrowphase.contact_manifold`` all call the latter.

Van den Bergen, *Collision Detection in Interactive 3D Environments*, section 4.3.3; Ericson, *Real-Time
Collision Detection*, section 9.5.
"""
from __future__ import annotations

import numpy as np

from .._config import njit
from .._validate import as_float_array, as_max_iterations, check_offsets, check_pairs
from .epa import EPA_TOL, epa_kernel, epa_polytope
from .gjk import MAX_ITERATIONS, gjk_kernel, gjk_scratch
from .rescale import largest_coordinate, rescale_unit
from .status import EPA_NOT_CONVERGED, GJK_NOT_CONVERGED, OVERLAP, SEPARATED, raise_for_status
from .touching_normal import separated_normal_at_contact, touching_normal_at_vertex, unit_vector

__all__ = ["penetration_kernel", "penetration_pairs_kernel", "penetration_pairs", "minkowski_fallback", "ONE_PAIR",
           "epa_penetration", "epa_penetration_pairs"]


@njit
def _separated_normal(W, n_simplex, g):
    """The unit normal (A towards B) of a separated pair, from GJK's closest points g[0:3], g[3:6] and its final
    simplex W[:n_simplex] (support points of M = A − B). Along closest_b − closest_a its direction errs by about
    2^-52 × (the points' size) / d: at a distance near GJK's tolerance (1e-10 of 2-unit boxes) that is a tilt of
    5e-7, enough to pick a wrong feature. When GJK ended on a triangle of M (the origin's projection inside it),
    that triangle's plane normal e1 × e2 is the same direction, with an error of about 2^-52 |e1| |e2| / |e1 × e2|
    whatever d: the better conditioned of the two is returned (unit_vector rescales, so 1e-162 does not underflow)."""
    dx, dy, dz = g[3] - g[0], g[4] - g[1], g[5] - g[2]
    ux, uy, uz, _ = unit_vector(dx, dy, dz)
    if n_simplex != 3:
        return ux, uy, uz
    e1x, e1y, e1z = W[1, 0] - W[0, 0], W[1, 1] - W[0, 1], W[1, 2] - W[0, 2]
    e2x, e2y, e2z = W[2, 0] - W[0, 0], W[2, 1] - W[0, 1], W[2, 2] - W[0, 2]
    cx, cy, cz = e1y * e2z - e1z * e2y, e1z * e2x - e1x * e2z, e1x * e2y - e1y * e2x
    nx, ny, nz, ok = unit_vector(cx, cy, cz)
    size = max(abs(g[0]), abs(g[1]), abs(g[2]), abs(g[3]), abs(g[4]), abs(g[5]))
    d = abs(dx * ux + dy * uy + dz * uz)
    e1 = max(abs(e1x), abs(e1y), abs(e1z))
    e2 = max(abs(e2x), abs(e2y), abs(e2z))
    # |e1 × e2| >= |c · n| with n its unit direction; compare the two error estimates without dividing
    if not ok or e1 * e2 * d >= size * abs(cx * nx + cy * ny + cz * nz):
        return ux, uy, uz
    if nx * dx + ny * dy + nz * dz < 0.0:  # oriented from A towards B, as closest_b − closest_a
        return -nx, -ny, -nz
    return nx, ny, nz


@njit
def _chain(pa, pb, max_iter, scratch, poly, g, out):
    """The chain on one pair already in range (see ``penetration_kernel``)."""
    status, n_simplex = gjk_kernel(pa, pb, max_iter, scratch, g)
    if status == GJK_NOT_CONVERGED:
        return status
    d = g[6]
    for c in range(3):
        out[4 + c] = g[c]
        out[7 + c] = g[3 + c]
    if d > 0.0:
        out[0] = d
        nx, ny, nz = _separated_normal(scratch.W, n_simplex, g)
        out[1], out[2], out[3] = separated_normal_at_contact(pa, pb, nx, ny, nz, d, EPA_TOL, g[0], g[1], g[2])
        return SEPARATED
    if status != OVERLAP:  # touching at distance exactly 0 without a full simplex: depth 0, a touching normal
        out[0] = 0.0
        out[1], out[2], out[3], _ = touching_normal_at_vertex(pa, pb, EPA_TOL, g[0], g[1], g[2])
        return SEPARATED
    if epa_kernel(pa, pb, scratch.W, scratch.IA, scratch.IB, n_simplex, max_iter, poly, out) != OVERLAP:
        return EPA_NOT_CONVERGED
    out[0] = -out[0]
    return OVERLAP


@njit
def penetration_kernel(pa, pb, max_iter, scratch, poly, g, out):
    """The chain for hull(pa), hull(pb) ((n, 3), (m, 3) float64), with ``scratch`` from ``gjk_scratch`` (at least
    max(n, m) columns), ``poly`` from ``epa_polytope`` and ``g`` (7,) float64 scratch. Writes ``out`` (10,): the
    signed distance s (> 0 apart, 0 touching, −depth overlapping), the unit normal (A towards B), the closest
    (or deepest) point of A and of B. Returns SEPARATED (s >= 0), OVERLAP, GJK_NOT_CONVERGED or
    EPA_NOT_CONVERGED. Tiny or huge pairs are solved on copies scaled by a power of two (``rescale_unit``)."""
    unit = rescale_unit(largest_coordinate(pa, pb))
    if unit == 1.0:
        return _chain(pa, pb, max_iter, scratch, poly, g, out)
    status = _chain(pa * unit, pb * unit, max_iter, scratch, poly, g, out)
    out[0] /= unit
    for c in range(4, 10):
        out[c] /= unit
    return status


@njit
def penetration_pairs_kernel(points, offsets, pairs, max_iter, signed, normal, point_a, point_b, status):
    """``penetration_kernel`` over k pairs of packed shapes (shape s = rows ``offsets[s]:offsets[s + 1]`` of
    ``points`` (N, 3); ``pairs`` (k, 2) int64), in one compiled loop: writes signed (k,), normal, point_a,
    point_b (k, 3) and status (k,) int64."""
    n_max = np.int64(1)  # typed int64 from the start: gjk_scratch is compiled for one size type
    for s in range(offsets.shape[0] - 1):
        n_max = max(n_max, offsets[s + 1] - offsets[s])
    scratch = gjk_scratch(n_max)
    poly = epa_polytope()
    g = np.empty(7)
    out = np.empty(10)
    for p in range(pairs.shape[0]):
        i = pairs[p, 0]
        j = pairs[p, 1]
        pa = points[offsets[i]:offsets[i + 1]]
        pb = points[offsets[j]:offsets[j + 1]]
        # pairs in range go straight to the chain: one call fewer per pair (each call reference-counts the ~25
        # arrays it is passed, scratch and polytope included)
        if rescale_unit(largest_coordinate(pa, pb)) == 1.0:
            status[p] = _chain(pa, pb, max_iter, scratch, poly, g, out)
        else:
            status[p] = penetration_kernel(pa, pb, max_iter, scratch, poly, g, out)
        signed[p] = out[0]
        for c in range(3):
            normal[p, c] = out[1 + c]
            point_a[p, c] = out[4 + c]
            point_b[p, c] = out[7 + c]


def minkowski_fallback(pa: np.ndarray, pb: np.ndarray):
    """Exact depth and normal from Qhull on the Minkowski difference {a − b} (scipy.spatial.ConvexHull) of
    ``pa`` (n, 3) and ``pb`` (m, 3).

    Used only where the expanding polytope breaks down on round-off (many coplanar support points, e.g. boxes
    sharing axes); O(n m) points, so meant for the small shapes of a narrow phase. Returns
    (depth, normal, point_a, point_b) — the points are the supporting vertices of A and B along the normal — or
    None when there are too many points.
    """
    from scipy.spatial import ConvexHull, QhullError

    if pa.shape[0] * pb.shape[0] > 200_000:
        return None
    md = (pa[:, None, :] - pb[None, :, :]).reshape(-1, 3)
    try:
        hull = ConvexHull(md)
    except (QhullError, ValueError):
        # M is flat: the origin lies on its boundary; depth 0 along the normal of its plane
        _, _, vt = np.linalg.svd(md - md.mean(axis=0))
        normal = vt[-1]
        return 0.0, normal, pa[int(np.argmax(pa @ normal))], pb[int(np.argmin(pb @ normal))]
    distances = -hull.equations[:, 3]
    k = int(np.argmin(distances))
    normal = hull.equations[k, :3].copy()
    depth = max(float(distances[k]), 0.0)
    return depth, normal, pa[int(np.argmax(pa @ normal))], pb[int(np.argmin(pb @ normal))]


def penetration_pairs(pts: np.ndarray, off: np.ndarray, pr: np.ndarray, max_iter: int, where: str = "pairs"):
    """The chain over validated packed shapes (``pts`` (N, 3) float64, ``off`` (S + 1,), ``pr`` (k, 2) int64):
    ``penetration_pairs_kernel``, then the exact fallback where EPA gave up; raises ``GJKNotConverged`` /
    ``EPANotConverged`` for the first pair left unsolved (named ``where[p]``). Returns ``(signed (k,), normal (k, 3),
    point_a (k, 3), point_b (k, 3), status (k,), exact_fallback (k,) bool)``."""
    k = pr.shape[0]
    signed = np.empty(k)
    normal = np.empty((k, 3))
    point_a = np.empty((k, 3))
    point_b = np.empty((k, 3))
    status = np.empty(k, np.int64)
    if k:
        penetration_pairs_kernel(pts, off, pr, max_iter, signed, normal, point_a, point_b, status)
    fallback = status == EPA_NOT_CONVERGED
    # rare: EPA folded on round-off; Qhull's exact answer instead
    for p in np.flatnonzero(fallback) if fallback.any() else ():
        i, j = pr[p]
        exact = minkowski_fallback(pts[off[i]:off[i + 1]], pts[off[j]:off[j + 1]])
        if exact is not None:
            signed[p], normal[p], point_a[p], point_b[p] = -exact[0], exact[1], exact[2], exact[3]
            status[p] = OVERLAP
    raise_for_status(status, max_iter, where)
    return signed, normal, point_a, point_b, status, fallback


def _packed_pair(points_a, points_b):
    pa = as_float_array(points_a, "points_a", shape=(None, 3), min_rows=1)
    pb = as_float_array(points_b, "points_b", shape=(None, 3), min_rows=1)
    off = np.array([0, pa.shape[0], pa.shape[0] + pb.shape[0]], np.int64)
    return np.concatenate([pa, pb]), off


ONE_PAIR = np.array([[0, 1]], np.int64)


def epa_penetration(points_a, points_b, *, max_iterations: int = MAX_ITERATIONS, witnesses: bool = False):
    """Penetration depth and normal of two overlapping convex hulls (GJK, then EPA).

    GJK (Ericson 9.5) decides whether the origin lies in the Minkowski difference M = A − B; if so, the expanding
    polytope algorithm (van den Bergen 2001, Ericson 9.5's companion) grows GJK's simplex inside M until it reaches
    the face of M nearest to the origin: its distance is the depth, its outward normal the direction. Where EPA
    breaks down on round-off (many coplanar support points), the exact hull of M (Qhull) answers instead.

    Parameters
    ----------
    points_a : array_like, shape (n, 3), float64
        The points whose convex hull is A, n >= 1, finite.
    points_b : array_like, shape (m, 3), float64
        The points of B, m >= 1.
    max_iterations : int, default 128
        The cap of GJK's and of EPA's iterations, >= 1.
    witnesses : bool, default False
        Also return the deepest points of A and of B.

    Returns
    -------
    depth : float
        >= 0: the length of the shortest translation that separates the hulls; 0.0 when they only touch or do
        not overlap at all.
    normal : numpy.ndarray, shape (3,), float64
        Unit vector from A towards B: moving B by ``depth * normal`` leaves the hulls touching. For separated
        hulls, the direction of GJK's closest points.
    point_a, point_b : numpy.ndarray, shape (3,), float64
        Only with ``witnesses=True``: the deepest point of A along ``normal`` and of B against it.

    Raises
    ------
    ValueError
        For an empty point set, a wrong shape, NaN or ±inf (named ``points_a`` / ``points_b``), or
        ``max_iterations < 1``.
    TypeError
        For non-numeric points or a non-integer ``max_iterations``.
    GJKNotConverged, EPANotConverged
        When GJK or EPA reaches ``max_iterations`` and the exact fallback has no answer either.

    See Also
    --------
    gjk_distance : the distance of separated hulls.
    contact_feature : the contact points and features as well.

    Examples
    --------
    Two unit cubes overlapping by 0.25 along x:

    >>> import numpy as np
    >>> import engine
    >>> cube = np.array([[x, y, z] for x in (0.0, 1.0) for y in (0.0, 1.0) for z in (0.0, 1.0)])
    >>> depth, normal = engine.epa_penetration(cube, cube + [0.75, 0.0, 0.0])
    >>> depth
    0.25
    >>> bool(np.allclose(normal, [1.0, 0.0, 0.0]))
    True
    """
    pts, off = _packed_pair(points_a, points_b)
    max_iter = as_max_iterations(max_iterations)
    signed, normal, point_a, point_b, _, _ = penetration_pairs(pts, off, ONE_PAIR, max_iter, where="")
    depth = 0.0 if signed[0] >= 0.0 else float(-signed[0])
    if witnesses:
        return depth, normal[0], point_a[0], point_b[0]
    return depth, normal[0]


def epa_penetration_pairs(points, offsets, pairs, *, max_iterations: int = MAX_ITERATIONS):
    """``epa_penetration`` for k pairs of packed convex shapes, in one compiled call.

    Parameters
    ----------
    points, offsets, pairs
        The shapes and the pairs (:ref:`packed-point-sets`).
    max_iterations : int, default 128
        GJK's and EPA's iteration cap per pair, >= 1.

    Returns
    -------
    depth : numpy.ndarray, shape (k,), float64
        The penetration depth of each pair, >= 0; 0.0 for separated or touching pairs.
    normal : numpy.ndarray, shape (k, 3), float64
        Unit normals from the first shape towards the second (GJK's direction for separated pairs).

    Raises
    ------
    GJKNotConverged, EPANotConverged
        For the first pair left unsolved (named ``pairs[p]``).
    """
    pts = as_float_array(points, "points", shape=(None, 3))
    off = check_offsets(offsets, pts.shape[0])
    pr = check_pairs(pairs, off.shape[0] - 1)
    max_iter = as_max_iterations(max_iterations)
    signed, normal, _, _, _, _ = penetration_pairs(pts, off, pr, max_iter)
    return np.where(signed < 0.0, -signed, 0.0), normal
