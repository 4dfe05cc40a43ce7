"""GJK distance between the convex hulls of two point sets (the pipeline's narrow phase: "un test plus précis").

The Gilbert–Johnson–Keerthi algorithm works on the Minkowski difference M = A − B = {a − b}: the two hulls
overlap iff the origin lies in M, and their distance is the distance from the origin to M. GJK walks a simplex
(1 to 4 support points of M) towards the origin:

    v  <- any point of M                      (here a_0 − b_0)
    loop:
        w  <- s_A(−v) − s_B(v)                 (support point of M in direction −v)
        if |v|² − v·w <= eps·|v|²: stop        (no point of M is closer than v by more than round-off)
        W  <- W ∪ {w};  v <- closest point of hull(W) to the origin;  W <- smallest subset holding v
        if |W| = 4 (origin inside the tetrahedron) or |v| = 0: the hulls overlap

Ericson, *Real-Time Collision Detection*, section 9.5 (GJK) and sections 5.1.2, 5.1.5, 5.1.6 (closest point on a
segment, triangle, tetrahedron) — the sub-algorithm here is Ericson's Voronoi-region version, which also gives the
barycentric weights λ that turn v = Σ λ_i (a_i − b_i) into the closest points Σ λ_i a_i and Σ λ_i b_i.

Public functions:
- ``gjk_distance(points_a, points_b) -> (distance, closest_a, closest_b)``;
- ``gjk_distance_pairs(points, offsets, pairs)`` — many shapes packed in one vertex array (shape i owns rows
  ``offsets[i]:offsets[i+1]``), one compiled call over the (k, 2) pair-index array: the form a dispatch table
  (shape kind × shape kind → batched test over pair indices) calls;
- ``gjk_distance_batch(points_a, points_b)`` — k aligned pairs of equal-size point sets, (k, m, 3) and (k, p, 3).

Distances are reported as exactly 0.0 when the hulls overlap or touch to within ``OVERLAP_TOL`` times the size of
the Minkowski difference.
"""
from __future__ import annotations

import math

import numpy as np

from .._config import njit
from .._validate import as_float_array

__all__ = [
    "GJKNotConverged",
    "MAX_ITERATIONS",
    "OVERLAP_TOL",
    "gjk_distance",
    "gjk_distance_pairs",
    "gjk_distance_batch",
    "pack_point_sets",
]

#: default cap on GJK iterations; a polytope pair converges in a handful, so hitting it means bad input
MAX_ITERATIONS = 128
#: relative tolerance of GJK's stopping test |v|² − v·w <= REL_TOL·|v|²
REL_TOL = 1e-12
#: distances below OVERLAP_TOL × (size of the Minkowski difference) count as contact (distance 0)
OVERLAP_TOL = 1e-10

# kernel status codes
_SEPARATED = 0
_OVERLAP = 1
_NOT_CONVERGED = 2


class GJKNotConverged(RuntimeError):
    """GJK reached its iteration cap without meeting its stopping test."""


# ---------------------------------------------------------------------------------------------------------------
# kernels
# ---------------------------------------------------------------------------------------------------------------

@njit(inline="always")
def _support(points, dx, dy, dz):
    """Index of the vertex of ``points`` (n, 3) farthest along d (Ericson 9.5: the support mapping s(d))."""
    best = 0
    best_dot = points[0, 0] * dx + points[0, 1] * dy + points[0, 2] * dz
    for i in range(1, points.shape[0]):
        d = points[i, 0] * dx + points[i, 1] * dy + points[i, 2] * dz
        if d > best_dot:
            best_dot = d
            best = i
    return best


@njit(inline="always")
def _keep(W, IA, IB, lam, order, n_keep, weights, o):
    """Reduce the simplex to the vertices ``order[:n_keep]`` (ascending) with barycentric ``weights``.

    The order is ascending, so copying forward in place never overwrites a vertex still to be read.
    """
    for k in range(n_keep):
        i = order[o + k]
        W[k, 0] = W[i, 0]
        W[k, 1] = W[i, 1]
        W[k, 2] = W[i, 2]
        IA[k] = IA[i]
        IB[k] = IB[i]
        lam[k] = weights[o + k]
    return n_keep


@njit(inline="always")
def _segment_weights(W, i0, i1, out_order, out_weights, o):
    """Closest point to the origin on segment [W[i0], W[i1]] (Ericson 5.1.2): supporting vertices and weights."""
    ax, ay, az = W[i0, 0], W[i0, 1], W[i0, 2]
    abx, aby, abz = W[i1, 0] - ax, W[i1, 1] - ay, W[i1, 2] - az
    denom = abx * abx + aby * aby + abz * abz
    t = -(ax * abx + ay * aby + az * abz)
    if t <= 0.0 or denom <= 0.0:
        out_order[o + 0] = i0
        out_weights[o + 0] = 1.0
        return 1
    if t >= denom:
        out_order[o + 0] = i1
        out_weights[o + 0] = 1.0
        return 1
    t = t / denom
    out_order[o + 0] = i0
    out_order[o + 1] = i1
    out_weights[o + 0] = 1.0 - t
    out_weights[o + 1] = t
    return 2


@njit(inline="always")
def _triangle_weights(W, i0, i1, i2, out_order, out_weights, o):
    """Ericson 5.1.5 ClosestPtPointTriangle with p = origin: Voronoi regions of vertices, edges, face.

    Writes the supporting vertices (ascending) and their barycentric weights; returns how many there are, or
    -1 for a zero-area triangle.
    """
    ax, ay, az = W[i0, 0], W[i0, 1], W[i0, 2]
    bx, by, bz = W[i1, 0], W[i1, 1], W[i1, 2]
    cx, cy, cz = W[i2, 0], W[i2, 1], W[i2, 2]
    abx, aby, abz = bx - ax, by - ay, bz - az
    acx, acy, acz = cx - ax, cy - ay, cz - az
    # ap = -a
    d1 = -(abx * ax + aby * ay + abz * az)
    d2 = -(acx * ax + acy * ay + acz * az)
    if d1 <= 0.0 and d2 <= 0.0:  # vertex region A
        out_order[o + 0] = i0
        out_weights[o + 0] = 1.0
        return 1
    # bp = -b
    d3 = -(abx * bx + aby * by + abz * bz)
    d4 = -(acx * bx + acy * by + acz * bz)
    if d3 >= 0.0 and d4 <= d3:  # vertex region B
        out_order[o + 0] = i1
        out_weights[o + 0] = 1.0
        return 1
    vc = d1 * d4 - d3 * d2
    if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:  # edge region AB
        v = d1 / (d1 - d3)
        out_order[o + 0] = i0
        out_order[o + 1] = i1
        out_weights[o + 0] = 1.0 - v
        out_weights[o + 1] = v
        return 2
    # cp = -c
    d5 = -(abx * cx + aby * cy + abz * cz)
    d6 = -(acx * cx + acy * cy + acz * cz)
    if d6 >= 0.0 and d5 <= d6:  # vertex region C
        out_order[o + 0] = i2
        out_weights[o + 0] = 1.0
        return 1
    vb = d5 * d2 - d1 * d6
    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:  # edge region AC
        w = d2 / (d2 - d6)
        out_order[o + 0] = i0
        out_order[o + 1] = i2
        out_weights[o + 0] = 1.0 - w
        out_weights[o + 1] = w
        return 2
    va = d3 * d6 - d5 * d4
    if va <= 0.0 and (d4 - d3) >= 0.0 and (d5 - d6) >= 0.0:  # edge region BC
        w = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        out_order[o + 0] = i1
        out_order[o + 1] = i2
        out_weights[o + 0] = 1.0 - w
        out_weights[o + 1] = w
        return 2
    denom = va + vb + vc
    if not denom > 0.0:  # degenerate (zero-area) triangle
        return -1
    v = vb / denom
    w = vc / denom
    out_order[o + 0] = i0
    out_order[o + 1] = i1
    out_order[o + 2] = i2
    out_weights[o + 0] = 1.0 - v - w
    out_weights[o + 1] = v
    out_weights[o + 2] = w
    return 3


@njit(inline="always")
def _weights_distance2(W, order, weights, n, o):
    x = 0.0
    y = 0.0
    z = 0.0
    for k in range(n):
        i = order[o + k]
        x += weights[o + k] * W[i, 0]
        y += weights[o + k] * W[i, 1]
        z += weights[o + k] * W[i, 2]
    return x * x + y * y + z * z


@njit(inline="always")
def _closest_triangle_any(W, i0, i1, i2, wi, wf, o, tmp):
    """Closest point of triangle (W[i0], W[i1], W[i2]) to the origin, degenerate triangles included.

    Result in ``wi[o:o+n]`` (vertices) and ``wf[o:o+n]`` (weights); ``wi[tmp:tmp+3]``, ``wf[tmp:tmp+3]`` scratch.
    """
    n = _triangle_weights(W, i0, i1, i2, wi, wf, o)
    if n > 0:
        return n
    # zero-area triangle: the closest point lies on one of its three edges
    best_n = 0
    best_d = np.inf
    for e in range(3):
        if e == 0:
            m = _segment_weights(W, i0, i1, wi, wf, tmp)
        elif e == 1:
            m = _segment_weights(W, i1, i2, wi, wf, tmp)
        else:
            m = _segment_weights(W, i0, i2, wi, wf, tmp)
        d = _weights_distance2(W, wi, wf, m, tmp)
        if d < best_d:
            best_d = d
            best_n = m
            for k in range(m):
                wi[o + k] = wi[tmp + k]
                wf[o + k] = wf[tmp + k]
    return best_n


@njit(inline="always")
def _solve_simplex(W, IA, IB, lam, n, wi, wf):
    """Closest point of hull(W[:n]) to the origin; reduces the simplex in place and returns its new size.

    A return of 4 means the origin lies inside the tetrahedron (the hulls overlap); λ are then the barycentric
    coordinates of the origin. Ericson 5.1.6 (ClosestPtPointTetrahedron) for n = 4. ``wi`` (12,) int and
    ``wf`` (13,) float are scratch space (no allocation in the loop): slots 0-2 the current candidate, 3-5
    scratch, 6-8 the best face so far, wf[9:13] the tetrahedron's barycentric coordinates.
    """
    if n == 1:
        lam[0] = 1.0
        return 1
    if n == 2:
        m = _segment_weights(W, 0, 1, wi, wf, 0)
        return _keep(W, IA, IB, lam, wi, m, wf, 0)
    if n == 3:
        m = _closest_triangle_any(W, 0, 1, 2, wi, wf, 0, 3)
        return _keep(W, IA, IB, lam, wi, m, wf, 0)
    # tetrahedron: the origin is outside face (i, j, k) when it is on the other side of it from vertex l
    abx, aby, abz = W[1, 0] - W[0, 0], W[1, 1] - W[0, 1], W[1, 2] - W[0, 2]
    acx, acy, acz = W[2, 0] - W[0, 0], W[2, 1] - W[0, 1], W[2, 2] - W[0, 2]
    adx, ady, adz = W[3, 0] - W[0, 0], W[3, 1] - W[0, 1], W[3, 2] - W[0, 2]
    det = abx * (acy * adz - acz * ady) + aby * (acz * adx - acx * adz) + abz * (acx * ady - acy * adx)
    scale = max(abx * abx + aby * aby + abz * abz, acx * acx + acy * acy + acz * acz,
                adx * adx + ady * ady + adz * adz)
    flat = abs(det) <= 1e-12 * scale * math.sqrt(scale)
    best_d = np.inf
    best_n = -1
    inside = True
    for f in range(4):
        # face (i, j, k) opposite vertex l, with i < j < k
        if f == 0:
            i, j, k, l = 0, 1, 2, 3
        elif f == 1:
            i, j, k, l = 0, 1, 3, 2
        elif f == 2:
            i, j, k, l = 0, 2, 3, 1
        else:
            i, j, k, l = 1, 2, 3, 0
        px, py, pz = W[i, 0], W[i, 1], W[i, 2]
        e1x, e1y, e1z = W[j, 0] - px, W[j, 1] - py, W[j, 2] - pz
        e2x, e2y, e2z = W[k, 0] - px, W[k, 1] - py, W[k, 2] - pz
        nx = e1y * e2z - e1z * e2y
        ny = e1z * e2x - e1x * e2z
        nz = e1x * e2y - e1y * e2x
        sign_origin = -(px * nx + py * ny + pz * nz)
        sign_other = (W[l, 0] - px) * nx + (W[l, 1] - py) * ny + (W[l, 2] - pz) * nz
        if not flat:
            wf[9 + l] = sign_origin / sign_other
        if flat or sign_origin * sign_other < 0.0:
            inside = False
            m = _closest_triangle_any(W, i, j, k, wi, wf, 0, 3)
            d = _weights_distance2(W, wi, wf, m, 0)
            if d < best_d:
                best_d = d
                best_n = m
                for t in range(m):
                    wi[6 + t] = wi[t]
                    wf[6 + t] = wf[t]
    if inside:
        # origin inside (or on) the tetrahedron: barycentric coordinates by signed volumes
        for t in range(4):
            lam[t] = wf[9 + t]
        return 4
    return _keep(W, IA, IB, lam, wi, best_n, wf, 6)


@njit
def _gjk(pa, pb, max_iter, W, IA, IB, lam, out, work_i, work_f):
    """GJK (Ericson 9.5) between hull(pa) and hull(pb), (n, 3) and (m, 3).

    Fills ``out[0:3]`` with the closest point on A, ``out[3:6]`` on B, ``out[6]`` with the distance, and leaves
    the final simplex (support points W, their vertex indices IA, IB, weights λ) for EPA. ``work_i`` (12,) int
    and ``work_f`` (13,) float are scratch space, allocated once by the caller. Returns (status, simplex size).
    """
    # start from a support point of M (so that every simplex vertex lies on M's boundary, as EPA assumes), in
    # the direction of M's centroid: the first support point is then already close to the answer
    dx = 0.0
    dy = 0.0
    dz = 0.0
    for i in range(pa.shape[0]):
        dx += pa[i, 0]
        dy += pa[i, 1]
        dz += pa[i, 2]
    dx /= pa.shape[0]
    dy /= pa.shape[0]
    dz /= pa.shape[0]
    ex = 0.0
    ey = 0.0
    ez = 0.0
    for i in range(pb.shape[0]):
        ex += pb[i, 0]
        ey += pb[i, 1]
        ez += pb[i, 2]
    dx -= ex / pb.shape[0]
    dy -= ey / pb.shape[0]
    dz -= ez / pb.shape[0]
    if dx == 0.0 and dy == 0.0 and dz == 0.0:
        dx = 1.0
    ia = _support(pa, -dx, -dy, -dz)
    ib = _support(pb, dx, dy, dz)
    W[0, 0] = pa[ia, 0] - pb[ib, 0]
    W[0, 1] = pa[ia, 1] - pb[ib, 1]
    W[0, 2] = pa[ia, 2] - pb[ib, 2]
    IA[0] = ia
    IB[0] = ib
    lam[0] = 1.0
    n = 1
    vx, vy, vz = W[0, 0], W[0, 1], W[0, 2]
    vv = vx * vx + vy * vy + vz * vz
    size2 = vv
    status = _NOT_CONVERGED
    for _ in range(max_iter):
        if vv <= (OVERLAP_TOL * OVERLAP_TOL) * size2:
            status = _OVERLAP
            break
        ia = _support(pa, -vx, -vy, -vz)
        ib = _support(pb, vx, vy, vz)
        wx = pa[ia, 0] - pb[ib, 0]
        wy = pa[ia, 1] - pb[ib, 1]
        wz = pa[ia, 2] - pb[ib, 2]
        ww = wx * wx + wy * wy + wz * wz
        if ww > size2:
            size2 = ww
        vw = vx * wx + vy * wy + vz * wz
        # stopping test: w is no closer to the origin along v than v itself (to round-off)
        if vv - vw <= REL_TOL * vv + 1e-15 * size2:
            status = _SEPARATED
            break
        duplicate = False
        for k in range(n):
            if IA[k] == ia and IB[k] == ib:
                duplicate = True
        if duplicate:
            status = _SEPARATED
            break
        W[n, 0] = wx
        W[n, 1] = wy
        W[n, 2] = wz
        IA[n] = ia
        IB[n] = ib
        n += 1
        n = _solve_simplex(W, IA, IB, lam, n, work_i, work_f)
        if n == 4:
            status = _OVERLAP
            break
        nx = 0.0
        ny = 0.0
        nz = 0.0
        for k in range(n):
            nx += lam[k] * W[k, 0]
            ny += lam[k] * W[k, 1]
            nz += lam[k] * W[k, 2]
        nvv = nx * nx + ny * ny + nz * nz
        if nvv >= vv:
            # no progress: round-off has the last word; v is as close as this simplex gets
            vx, vy, vz, vv = nx, ny, nz, nvv
            status = _SEPARATED
            break
        vx, vy, vz, vv = nx, ny, nz, nvv
    if status == _NOT_CONVERGED and vv <= (OVERLAP_TOL * OVERLAP_TOL) * size2:
        status = _OVERLAP
    # closest points from the barycentric weights of the final simplex
    for c in range(6):
        out[c] = 0.0
    for k in range(n):
        for c in range(3):
            out[c] += lam[k] * pa[IA[k], c]
            out[3 + c] += lam[k] * pb[IB[k], c]
    if status == _OVERLAP:
        out[6] = 0.0
        # one common point: the two barycentric sums agree to round-off; report their mean on both sides
        for c in range(3):
            m = 0.5 * (out[c] + out[3 + c])
            out[c] = m
            out[3 + c] = m
    else:
        out[6] = math.sqrt(vv)
    return status, n


@njit
def _gjk_pairs(points, offsets, pairs, max_iter, dist, closest_a, closest_b, status):
    """One compiled loop over k pairs of packed shapes (shape s = points[offsets[s]:offsets[s+1]])."""
    W = np.empty((4, 3))
    IA = np.empty(4, np.int64)
    IB = np.empty(4, np.int64)
    lam = np.empty(4)
    out = np.empty(7)
    work_i = np.empty(12, np.int64)
    work_f = np.empty(13)
    for p in range(pairs.shape[0]):
        i = pairs[p, 0]
        j = pairs[p, 1]
        pa = points[offsets[i]:offsets[i + 1]]
        pb = points[offsets[j]:offsets[j + 1]]
        st, _ = _gjk(pa, pb, max_iter, W, IA, IB, lam, out, work_i, work_f)
        status[p] = st
        for c in range(3):
            closest_a[p, c] = out[c]
            closest_b[p, c] = out[3 + c]
        dist[p] = out[6]


@njit
def _gjk_batch(points_a, points_b, max_iter, dist, closest_a, closest_b, status):
    W = np.empty((4, 3))
    IA = np.empty(4, np.int64)
    IB = np.empty(4, np.int64)
    lam = np.empty(4)
    out = np.empty(7)
    work_i = np.empty(12, np.int64)
    work_f = np.empty(13)
    for p in range(points_a.shape[0]):
        st, _ = _gjk(points_a[p], points_b[p], max_iter, W, IA, IB, lam, out, work_i, work_f)
        status[p] = st
        for c in range(3):
            closest_a[p, c] = out[c]
            closest_b[p, c] = out[3 + c]
        dist[p] = out[6]


# ---------------------------------------------------------------------------------------------------------------
# public functions
# ---------------------------------------------------------------------------------------------------------------

def _as_max_iterations(max_iterations) -> int:
    if isinstance(max_iterations, bool) or not isinstance(max_iterations, int | np.integer):
        raise TypeError(f"max_iterations must be an int, got {type(max_iterations).__name__}")
    if max_iterations < 1:
        raise ValueError(f"max_iterations must be >= 1, got {max_iterations}")
    return int(max_iterations)


def gjk_distance(points_a, points_b, *, max_iterations: int = MAX_ITERATIONS):
    """Distance between the convex hulls of ``points_a`` (n, 3) and ``points_b`` (m, 3), n, m >= 1.

    Returns ``(distance, closest_a, closest_b)``: a float >= 0 (0.0 when the hulls overlap or touch) and the two
    closest points (3,), one on each hull, with |closest_a − closest_b| = distance. When the hulls overlap, both
    points are the same point common to the two hulls. Raises ``GJKNotConverged`` after ``max_iterations``.
    """
    pa = as_float_array(points_a, "points_a", shape=(None, 3), min_rows=1)
    pb = as_float_array(points_b, "points_b", shape=(None, 3), min_rows=1)
    max_iter = _as_max_iterations(max_iterations)
    W = np.empty((4, 3))
    IA = np.empty(4, np.int64)
    IB = np.empty(4, np.int64)
    lam = np.empty(4)
    out = np.empty(7)
    status, _ = _gjk(pa, pb, max_iter, W, IA, IB, lam, out, np.empty(12, np.int64), np.empty(13))
    if status == _NOT_CONVERGED:
        raise GJKNotConverged(f"GJK did not converge in max_iterations={max_iter} iterations")
    return float(out[6]), out[0:3].copy(), out[3:6].copy()


def pack_point_sets(point_sets):
    """Pack a list of (n_i, 3) point sets into ``(points (N, 3), offsets (len + 1,))`` for ``gjk_distance_pairs``."""
    if len(point_sets) == 0:
        return np.empty((0, 3)), np.zeros(1, np.int64)
    arrays = [as_float_array(p, f"point_sets[{i}]", shape=(None, 3), min_rows=1) for i, p in enumerate(point_sets)]
    offsets = np.zeros(len(arrays) + 1, np.int64)
    offsets[1:] = np.cumsum([a.shape[0] for a in arrays])
    return np.concatenate(arrays, axis=0), offsets


def _check_offsets(offsets, n_points: int) -> np.ndarray:
    off = np.asarray(offsets)
    if off.dtype.kind not in "iu":
        raise TypeError(f"offsets must be an integer array, got dtype {off.dtype}")
    if off.ndim != 1 or off.shape[0] < 1:
        raise ValueError(f"offsets must have shape (n_shapes + 1,), got {off.shape}")
    off = off.astype(np.int64)
    if off[0] != 0 or off[-1] != n_points:
        raise ValueError(f"offsets must start at 0 and end at len(points) = {n_points}, got {off[0]}..{off[-1]}")
    steps = np.diff(off)
    if (steps < 1).any():
        s = int(np.argmax(steps < 1))
        raise ValueError(f"offsets must be strictly increasing (every shape needs a point): offsets[{s}] = "
                         f"{off[s]} >= offsets[{s + 1}] = {off[s + 1]}")
    return off


def check_pairs(pairs, n_shapes: int, name: str = "pairs") -> np.ndarray:
    """A (k, 2) int64 array of shape indices in [0, n_shapes); ValueError naming the first bad row."""
    arr = np.asarray(pairs)
    if arr.size == 0:
        return np.empty((0, 2), np.int64)
    if arr.dtype.kind not in "iu":
        raise TypeError(f"{name} must be an integer array, got dtype {arr.dtype}")
    if arr.ndim != 2 or arr.shape[1] != 2:
        raise ValueError(f"{name} must have shape (k, 2), got {arr.shape}")
    arr = np.ascontiguousarray(arr, dtype=np.int64)
    bad = (arr < 0) | (arr >= n_shapes)
    if bad.any():
        r = int(np.argwhere(bad)[0][0])
        raise ValueError(f"{name}[{r}] = {arr[r].tolist()} holds an index outside [0, {n_shapes})")
    return arr


def _raise_first_failure(status, what: str, max_iter: int):
    bad = np.flatnonzero(status == _NOT_CONVERGED)
    if bad.size:
        raise GJKNotConverged(f"GJK did not converge in max_iterations={max_iter} iterations for {what}[{bad[0]}]")


def gjk_distance_pairs(points, offsets, pairs, *, max_iterations: int = MAX_ITERATIONS):
    """GJK over k pairs of packed shapes, in one compiled call.

    ``points`` (N, 3) holds every shape's vertices; shape s owns ``points[offsets[s]:offsets[s + 1]]``
    (``offsets`` (S + 1,), increasing, from 0 to N; see ``pack_point_sets``). ``pairs`` (k, 2) int lists
    (shape_a, shape_b). Returns ``(distance (k,), closest_a (k, 3), closest_b (k, 3))``.
    """
    pts = as_float_array(points, "points", shape=(None, 3))
    off = _check_offsets(offsets, pts.shape[0])
    pr = check_pairs(pairs, off.shape[0] - 1)
    max_iter = _as_max_iterations(max_iterations)
    k = pr.shape[0]
    dist = np.empty(k)
    ca = np.empty((k, 3))
    cb = np.empty((k, 3))
    status = np.empty(k, np.int64)
    if k:
        _gjk_pairs(pts, off, pr, max_iter, dist, ca, cb, status)
        _raise_first_failure(status, "pairs", max_iter)
    return dist, ca, cb


def gjk_distance_batch(points_a, points_b, *, max_iterations: int = MAX_ITERATIONS):
    """GJK over k aligned pairs: ``points_a`` (k, n, 3) against ``points_b`` (k, m, 3), one compiled call.

    Returns ``(distance (k,), closest_a (k, 3), closest_b (k, 3))``.
    """
    pa = as_float_array(points_a, "points_a", shape=(None, None, 3))
    pb = as_float_array(points_b, "points_b", shape=(None, None, 3))
    if pa.shape[0] != pb.shape[0]:
        raise ValueError(f"points_a and points_b must hold the same number of pairs, got {pa.shape[0]} and "
                         f"{pb.shape[0]}")
    if pa.shape[0] and (pa.shape[1] < 1 or pb.shape[1] < 1):
        raise ValueError("every shape needs at least one point")
    max_iter = _as_max_iterations(max_iterations)
    k = pa.shape[0]
    dist = np.empty(k)
    ca = np.empty((k, 3))
    cb = np.empty((k, 3))
    status = np.empty(k, np.int64)
    if k:
        _gjk_batch(pa, pb, max_iter, dist, ca, cb, status)
        _raise_first_failure(status, "points_a", max_iter)
    return dist, ca, cb
