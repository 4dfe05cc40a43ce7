"""GJK distance between the convex hulls of two point sets (the pipeline's narrow phase: "un test plus précis").

The Gilbert–Johnson–Keerthi algorithm works on the Minkowski difference M = A − B = {a − b}: the two hulls
overlap iff the origin lies in M, and their distance is the distance from the origin to M. GJK walks a simplex
(1 to 4 support points of M) towards the origin:

    v  <- any point of M                      (here a support point of M towards the centroid of M)
    loop:
        w  <- s_A(−v) − s_B(v)                 (support point of M in direction −v)
        if |v|² − v·w <= eps·|v|²: stop        (no point of M is closer than v by more than round-off)
        W  <- W ∪ {w};  v <- closest point of hull(W) to the origin;  W <- smallest subset holding v
        if |W| = 4 (origin inside the tetrahedron) or |v| = 0: the hulls overlap

Ericson, *Real-Time Collision Detection*, section 9.5 (GJK); the sub-algorithm (closest point of a segment,
triangle, tetrahedron: Ericson 5.1.2, 5.1.5, 5.1.6) is engine.narrowphase.simplex, whose barycentric weights λ
turn v = Σ λ_i (a_i − b_i) into the closest points Σ λ_i a_i and Σ λ_i b_i.

Kernels (public within the package; shapes and dtypes in each docstring): ``gjk_scratch`` (the one allocation of
GJK's scratch, ``GJKScratch``), ``gjk_pairs_kernel`` (k pairs in one compiled loop, shapes addressed by row ranges
of (S, N, 3) arrays), ``gjk_walk`` (GJK's loop on one pair), ``gjk_kernel`` (one pair of (n, 3) arrays),
``copy_shape``, ``scale_rows``.

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
from collections import namedtuple
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from .._config import MAX_THREADS, njit
from .._validate import MAX_MAGNITUDE, as_count, as_float_array, as_max_iterations, check_offsets, check_pairs
from .float_bits import abs_bits, bits_float
from .rescale import rescale_unit
from .simplex import closest_on_simplex, pick4, refine_on_simplex
from .status import GJK_NOT_CONVERGED, INVALID_INPUT, OVERLAP, SEPARATED, GJKNotConverged, raise_for_status

__all__ = [
    "GJKNotConverged",
    "MAX_ITERATIONS",
    "MAX_STALLS",
    "NEAR",
    "OVERLAP_TOL",
    "REL_TOL",
    "GJKScratch",
    "gjk_scratch",
    "copy_shape",
    "scale_rows",
    "start_direction",
    "gjk_kernel",
    "gjk_walk",
    "gjk_pairs_kernel",
    "gjk_distance",
    "gjk_distance_pairs",
    "gjk_distance_batch",
    "pack_point_sets",
    "run_in_chunks",
]

#: default cap on GJK iterations; a polytope pair converges in a handful, so hitting it means bad input
MAX_ITERATIONS = 128
#: relative tolerance of GJK's stopping test |v|² − v·w <= REL_TOL·|v|²
REL_TOL = 1e-12
#: distances below OVERLAP_TOL × (size of the Minkowski difference) count as contact (distance 0)
OVERLAP_TOL = 1e-10
#: below NEAR × size(M)², |v|² is near touching: the weights of v are refined (see ``gjk_walk``)
NEAR = 1e-2
#: GJK steps allowed that do not decrease |v| (round-off hides the progress; see ``gjk_walk``)
MAX_STALLS = 8


#: the bit pattern of MAX_MAGNITUDE (see float_bits: |x| <= MAX_MAGNITUDE iff abs_bits(x) <= this)
MAX_MAGNITUDE_BITS = int(np.float64(MAX_MAGNITUDE).view(np.int64))

# ---------------------------------------------------------------------------------------------------------------
# kernels
#
# Compiled with numba's ``error_model="numpy"``: the divisions (by a shape's point count, by the power-of-two unit,
# and those of engine.narrowphase.simplex) never have a zero denominator, so the Python error model's zero test
# before each of them (a compare and a branch to an exception path) is dead weight on the walk. The two models
# differ only on a zero denominator, so the answers are the same bit for bit (bench/test_bench_narrowphase.py, the
# hull20 GJK batch, times the walk).
#
# The per-pair loop holds no reference counting (numba's NRT incref/decref are atomic operations, one pair per
# array argument of every call, and numba's own inlining of an array-taking helper adds them too): shapes are
# addressed by (index, row range), never by slices or views, the loop assigns no array variable, and the helpers
# called inside it take and return scalars (``closest_on_simplex``, ``rescale_unit``, ``start_direction``), but
# for the two ``copy_shape`` calls per pair.
# ---------------------------------------------------------------------------------------------------------------

#: GJK's scratch (see ``gjk_scratch``)
GJKScratch = namedtuple("GJKScratch", ["W", "IA", "IB", "lam", "S", "status", "no_pairs", "no_offsets"])


@njit(error_model="numpy")
def gjk_scratch(n_max):
    """GJK's scratch, allocated here and nowhere else, for shapes of up to ``n_max`` points: the simplex ``W``
    (4, 3) float64 (support points of M), ``IA``, ``IB`` (4,) int64 (their rows in A's and B's arrays), ``lam`` (4,)
    float64 (the barycentric weights of v), and ``S`` (8, n_max) float64: the pair's two shapes copied as x, y, z
    rows (A in rows 0–2, B in rows 3–5) for unit-stride support scans, rows 6 and 7 their products with the search
    direction; ``status`` (1,) int64 (``gjk_kernel``'s answer); ``no_pairs`` (0, 2) and ``no_offsets`` (1,) int64,
    the empty pair list that tells ``gjk_pairs_kernel`` its pairs are aligned. After a call, W, IA, IB and lam
    hold the final simplex (what EPA starts from)."""
    return GJKScratch(np.empty((4, 3)), np.empty(4, np.int64), np.empty(4, np.int64), np.empty(4),
                      np.empty((8, max(n_max, 1))), np.empty(1, np.int64), np.empty((0, 2), np.int64),
                      np.zeros(1, np.int64))


# Without numba's runtime, like gjk_walk: it allocates nothing, and its two arrays then cost no reference counting.
@njit(_nrt=False, error_model="numpy")
def copy_shape(F, o, n, S, row):
    """Copy the n points ``F[o:o + 3 * n]`` (x, y, z of point i at o + 3i) of the flat array ``F`` into the scratch
    rows ``S[row:row + 3, :n]`` and return ``(ok, cx, cy, cz, big)``: ok is False when a coordinate is NaN, ±inf or
    above MAX_MAGNITUDE; (cx, cy, cz) the centroid; big the largest |coordinate|. The check is one integer maximum
    over the coordinates' bit patterns (``float_bits``; a loop LLVM vectorises); the sums run over even and odd
    points: two short addition chains, not one long one."""
    u = np.uint64(o)  # unsigned indices: no negative-index wraparound in the loops
    top = 0
    for k in range(np.uint64(3 * n)):
        top = max(top, abs_bits(F[u + k]))
    x0, y0, z0, x1, y1, z1 = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    for j in range(n // 2):
        i, k = 2 * j, u + np.uint64(6 * j)
        xa, ya, za, xb, yb, zb = F[k], F[k + 1], F[k + 2], F[k + 3], F[k + 4], F[k + 5]
        S[row, i], S[row + 1, i], S[row + 2, i] = xa, ya, za
        S[row, i + 1], S[row + 1, i + 1], S[row + 2, i + 1] = xb, yb, zb
        x0, y0, z0, x1, y1, z1 = x0 + xa, y0 + ya, z0 + za, x1 + xb, y1 + yb, z1 + zb
    if n % 2 == 1:
        k = u + np.uint64(3 * (n - 1))
        xa, ya, za = F[k], F[k + 1], F[k + 2]
        S[row, n - 1], S[row + 1, n - 1], S[row + 2, n - 1] = xa, ya, za
        x0, y0, z0 = x0 + xa, y0 + ya, z0 + za
    return top <= MAX_MAGNITUDE_BITS, (x0 + x1) / n, (y0 + y1) / n, (z0 + z1) / n, bits_float(top)


@njit(error_model="numpy")
def scale_rows(S, na, nb, unit):
    """Multiply the scratch copies S (8, n) of A (rows 0–2, na points) and B (rows 3–5, nb points) by ``unit``."""
    for i in range(na):
        S[0, i] *= unit
        S[1, i] *= unit
        S[2, i] *= unit
    for i in range(nb):
        S[3, i] *= unit
        S[4, i] *= unit
        S[5, i] *= unit


@njit(inline="always", error_model="numpy")
def start_direction(dx, dy, dz):
    """GJK's first search direction: the centroid difference d, or +x when it is zero."""
    if dx == 0.0 and dy == 0.0 and dz == 0.0:
        return 1.0, 0.0, 0.0
    return dx, dy, dz


# During the walk the simplex lives in scalars (tuples, which LLVM keeps in registers), not in the scratch arrays,
# which the walk writes once at its end: written and read back at every step, the arrays would put stores,
# reloads and spills on the iteration's dependency chain. The scalars hold the same values the arrays would, so the
# answers are the same bit for bit (bench/test_bench_narrowphase.py, the hull20 GJK batch, times the walk). P holds
# the vertices (x, y, z of vertex k at 3k..3k+2), R their rows in A (0..3) and B (4..7), L their weights.
@njit(inline="always", error_model="numpy")
def _with_vertex(P, R, k, wx, wy, wz, ia, ib):
    """P, R with vertex k (0..3) replaced by w = (wx, wy, wz) and its rows ia, ib."""
    return ((wx if k == 0 else P[0]), (wy if k == 0 else P[1]), (wz if k == 0 else P[2]),
            (wx if k == 1 else P[3]), (wy if k == 1 else P[4]), (wz if k == 1 else P[5]),
            (wx if k == 2 else P[6]), (wy if k == 2 else P[7]), (wz if k == 2 else P[8]),
            (wx if k == 3 else P[9]), (wy if k == 3 else P[10]), (wz if k == 3 else P[11])), \
        ((ia if k == 0 else R[0]), (ia if k == 1 else R[1]), (ia if k == 2 else R[2]), (ia if k == 3 else R[3]),
         (ib if k == 0 else R[4]), (ib if k == 1 else R[5]), (ib if k == 2 else R[6]), (ib if k == 3 else R[7]))


@njit(inline="always", error_model="numpy")
def _kept(P, R, s0, s1, s2):
    """The simplex reduced to its vertices s0, s1, s2 (in that order; vertex 3 is left as it was)."""
    return (pick4(s0, P[0], P[3], P[6], P[9]), pick4(s0, P[1], P[4], P[7], P[10]), pick4(s0, P[2], P[5], P[8], P[11]),
            pick4(s1, P[0], P[3], P[6], P[9]), pick4(s1, P[1], P[4], P[7], P[10]), pick4(s1, P[2], P[5], P[8], P[11]),
            pick4(s2, P[0], P[3], P[6], P[9]), pick4(s2, P[1], P[4], P[7], P[10]), pick4(s2, P[2], P[5], P[8], P[11]),
            P[9], P[10], P[11]), \
        (pick4(s0, R[0], R[1], R[2], R[3]), pick4(s1, R[0], R[1], R[2], R[3]), pick4(s2, R[0], R[1], R[2], R[3]), R[3],
         pick4(s0, R[4], R[5], R[6], R[7]), pick4(s1, R[4], R[5], R[6], R[7]), pick4(s2, R[4], R[5], R[6], R[7]), R[7])


@njit(inline="always", error_model="numpy")
def _repeats(R, n, ia, ib):
    """Whether one of the first n vertices has the rows (ia, ib)."""
    return (((n > 0) & (R[0] == ia) & (R[4] == ib)) | ((n > 1) & (R[1] == ia) & (R[5] == ib))
            | ((n > 2) & (R[2] == ia) & (R[6] == ib)))


@njit(inline="always", error_model="numpy")
def _combination(P, L, n):
    """v = Σ_{k < n} λ_k P_k, summed in the order k = 0, 1, 2 from 0.0 (n = 1, 2 or 3)."""
    x, y, z = 0.0 + L[0] * P[0], 0.0 + L[0] * P[1], 0.0 + L[0] * P[2]
    if n > 1:
        x, y, z = x + L[1] * P[3], y + L[1] * P[4], z + L[1] * P[5]
    if n > 2:
        x, y, z = x + L[2] * P[6], y + L[2] * P[7], z + L[2] * P[8]
    return x, y, z


@njit(inline="always", error_model="numpy")
def _store_simplex(P, R, L, W, IA, IB, lam):
    """The simplex's scalars into the scratch arrays W (4, 3), IA, IB (4,) and lam (4,)."""
    for k in range(4):
        W[k, 0], W[k, 1], W[k, 2] = P[3 * k], P[3 * k + 1], P[3 * k + 2]
        IA[k], IB[k], lam[k] = R[k], R[4 + k], L[k]


# Compiled without numba's runtime (NRT): it allocates nothing, and its five array arguments then cost no reference
# counting per call (a plain call makes an atomic increment and decrement of each array argument's count, once per
# pair; bench/test_bench_narrowphase.py, the GJK batches, times the per-pair loop).
@njit(_nrt=False, error_model="numpy")
def gjk_walk(S, na, nb, a0, b0, vx, vy, vz, max_iter, W, IA, IB, lam):
    """GJK's loop (Ericson 9.5) on the scratch copies ``S`` (8, n) of A (rows 0–2, ``na`` points) and B (rows 3–5,
    ``nb`` points; rows 6 and 7 are overwritten), from the search direction v: the final simplex in ``W`` (4, 3),
    ``IA``, ``IB`` (4,) int64 (rows offset by ``a0``, ``b0``: those of the caller's arrays) and ``lam`` (4,).
    Returns ``(n, vv, status)``: the simplex size, |v|² (in S's units) and OVERLAP, SEPARATED or
    GJK_NOT_CONVERGED."""
    # iteration -1 takes the support point towards the centroids unconditionally (then every simplex vertex lies
    # on M's boundary, as EPA assumes, and the first point is already close to the answer)
    n, vv, size2, stalls, status = 0, 0.0, 0.0, 0, GJK_NOT_CONVERGED
    P, R, L = (0.0,) * 12, (0,) * 8, (1.0, 0.0, 0.0, 0.0)
    for it in range(-1, max_iter):
        if it >= 0 and vv <= (OVERLAP_TOL * OVERLAP_TOL) * size2:
            status = OVERLAP
            break
        # w <- s_A(-v) - s_B(v): the first vertex of A with the least a·v, of B with the greatest b·v, the tie going
        # to the lower row. Two passes: the products a·v, b·v into rows 6 and 7 (a loop without a reduction, which
        # LLVM vectorises), then branch-free min/max scans over them (the scan alone is a shorter chain per point)
        for i in range(na):
            S[6, i] = S[0, i] * vx + S[1, i] * vy + S[2, i] * vz
        for i in range(nb):
            S[7, i] = S[3, i] * vx + S[4, i] * vy + S[5, i] * vz
        ia, lo = 0, np.inf
        for i in range(na):
            d = S[6, i]
            if d < lo:
                ia, lo = i, d
        ib, hi = 0, -np.inf
        for i in range(nb):
            d = S[7, i]
            if d > hi:
                ib, hi = i, d
        wx, wy, wz = S[0, ia] - S[3, ib], S[1, ia] - S[4, ib], S[2, ia] - S[5, ib]
        ia, ib = ia + a0, ib + b0
        if it >= 0:
            size2 = max(size2, wx * wx + wy * wy + wz * wz)
            # stop: w is no closer to the origin along v than v itself (to round-off), or w repeats a vertex
            if vv - (vx * wx + vy * wy + vz * wz) <= REL_TOL * vv + 1e-15 * size2 or _repeats(R, n, ia, ib):
                status = SEPARATED
                break
        P, R = _with_vertex(P, R, n, wx, wy, wz, ia, ib)
        L = (1.0 if n == 0 else L[0], 1.0 if n == 1 else L[1], 1.0 if n == 2 else L[2], 1.0 if n == 3 else L[3])
        n += 1
        if n > 1:
            # W <- the smallest subset of W holding its closest point to the origin, with its weights λ
            m, s0, s1, s2, l0, l1, l2, l3 = closest_on_simplex(n, P[0], P[1], P[2], P[3], P[4], P[5], P[6], P[7],
                                                               P[8], P[9], P[10], P[11])
            if m == 4:  # the origin is inside (or on) the tetrahedron
                n, L, status = 4, (l0, l1, l2, l3), OVERLAP
                break
            if vv < NEAR * size2:  # near touching, λ's round-off times size(M) / |v| would tilt v: refined
                l0, l1, l2 = refine_on_simplex(m, s0, s1, s2, l0, l1, l2, P[0], P[1], P[2], P[3], P[4], P[5], P[6],
                                               P[7], P[8], P[9], P[10], P[11])
            P, R = _kept(P, R, s0, s1, s2)
            L = (l0, l1 if m > 1 else L[1], l2 if m > 2 else L[2], L[3])
            n = m
        # v <- Σ λ_k W_k. |v| not decreasing means round-off hides the progress, not that there is none: the new
        # simplex may still turn v (near touching, by far more than |v| changes), and the next support point
        # judges it. GJK stops when v no longer moves, or after MAX_STALLS such steps.
        nx, ny, nz = _combination(P, L, n)
        if it >= 0 and nx * nx + ny * ny + nz * nz >= vv:
            stalls += 1
            if (nx == vx and ny == vy and nz == vz) or stalls > MAX_STALLS:
                vv, status = nx * nx + ny * ny + nz * nz, SEPARATED
                break
        vx, vy, vz, vv = nx, ny, nz, nx * nx + ny * ny + nz * nz
        size2 = vv if it < 0 else size2
    if status == GJK_NOT_CONVERGED and vv <= (OVERLAP_TOL * OVERLAP_TOL) * size2:
        status = OVERLAP
    _store_simplex(P, R, L, W, IA, IB, lam)
    return n, vv, status


# One body holds the loop over pairs (a call that passes arrays costs reference counting). Every caller passes
# C-contiguous, writeable arrays of the documented ranks (views made by ``reshape``, never by ``np.newaxis`` or a
# strided slice), so numba compiles this kernel once, not once per caller.
@njit(error_model="numpy")
def gjk_pairs_kernel(PA, PB, pairs, offsets, max_iter, scratch, dist, closest_a, closest_b, status):
    """GJK (Ericson 9.5) over k = ``status.shape[0]`` pairs in one compiled loop: dist (k,) (0.0 for overlapping or
    touching hulls, NaN for invalid input), closest_a, closest_b (k, 3) (one common point when they overlap), status
    (k,) int64. ``PA``, ``PB`` (S, N, 3) float64: with a pair list (``pairs`` (k, 2), ``offsets`` (S' + 1,) int64) pair
    p is shape ``pairs[p, 0]`` = rows ``offsets[s]:offsets[s + 1]`` of ``PA[0]`` against shape ``pairs[p, 1]`` of
    ``PB[0]``; without (``scratch.no_pairs``, ``scratch.no_offsets``) ``PA[p]`` against ``PB[p]``. ``scratch``
    (``gjk_scratch``, largest shape) keeps the last pair's final simplex (for EPA), whose size is returned."""
    W, IA, IB, lam, S = scratch[:5]
    FA, FB = PA.reshape(-1), PB.reshape(-1)  # flat views, made once (C-contiguous), for copy_shape
    n = 0
    for p in range(status.shape[0]):
        if pairs.shape[0] > 0:
            sa, sb = 0, 0
            a0, na = offsets[pairs[p, 0]], offsets[pairs[p, 0] + 1] - offsets[pairs[p, 0]]
            b0, nb = offsets[pairs[p, 1]], offsets[pairs[p, 1] + 1] - offsets[pairs[p, 1]]
        else:
            sa, sb, a0, na, b0, nb = p, p, 0, PA.shape[1], 0, PB.shape[1]
        # both shapes as x, y, z rows (unit-stride support scans), their values checked and centroids summed
        ok_a, cax, cay, caz, big_a = copy_shape(FA, 3 * (sa * PA.shape[1] + a0), na, S, np.int64(0))
        ok_b, cbx, cby, cbz, big_b = copy_shape(FB, 3 * (sb * PB.shape[1] + b0), nb, S, np.int64(3))
        if not (ok_a and ok_b):  # NaN, ±inf or a magnitude above MAX_MAGNITUDE: the caller raises
            dist[p], status[p], n = np.nan, INVALID_INPUT, 0
            continue
        # tiny or huge shapes: solved on copies scaled by a power of two (squared distances stay normal numbers)
        unit = rescale_unit(max(big_a, big_b))
        if unit != 1.0:
            scale_rows(S, na, nb, unit)
        vx, vy, vz = start_direction(cax - cbx, cay - cby, caz - cbz)
        n, vv, st = gjk_walk(S, na, nb, a0, b0, vx, vy, vz, max_iter, W, IA, IB, lam)
        # the closest points Σ λ_k a_k, Σ λ_k b_k (Σ λ_k = 1) as offsets from the first vertex: their round-off is
        # that of the offsets (the shapes' size), not that of the coordinates; overlapping, both get their mean
        ax, ay, az = PA[sa, IA[0], 0], PA[sa, IA[0], 1], PA[sa, IA[0], 2]
        bx, by, bz = PB[sb, IB[0], 0], PB[sb, IB[0], 1], PB[sb, IB[0], 2]
        qx, qy, qz, rx, ry, rz = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
        for k in range(1, n):
            ia, ib, lk = IA[k], IB[k], lam[k]
            qx, qy, qz = qx + lk * (PA[sa, ia, 0] - ax), qy + lk * (PA[sa, ia, 1] - ay), qz + lk * (PA[sa, ia, 2] - az)
            rx, ry, rz = rx + lk * (PB[sb, ib, 0] - bx), ry + lk * (PB[sb, ib, 1] - by), rz + lk * (PB[sb, ib, 2] - bz)
        qx, qy, qz, rx, ry, rz = ax + qx, ay + qy, az + qz, bx + rx, by + ry, bz + rz
        if st == OVERLAP:
            qx, qy, qz = 0.5 * (qx + rx), 0.5 * (qy + ry), 0.5 * (qz + rz)
            rx, ry, rz = qx, qy, qz
        closest_a[p, 0], closest_a[p, 1], closest_a[p, 2] = qx, qy, qz
        closest_b[p, 0], closest_b[p, 1], closest_b[p, 2] = rx, ry, rz
        if unit != 1.0:  # the simplex goes on (to EPA) in the shapes' own units
            for k in range(n):
                W[k, 0], W[k, 1], W[k, 2] = W[k, 0] / unit, W[k, 1] / unit, W[k, 2] / unit
        dist[p] = 0.0 if st == OVERLAP else math.sqrt(vv) / unit
        status[p] = st
    return n


@njit(error_model="numpy")
def gjk_kernel(pa, pb, max_iter, scratch, out):
    """GJK between hull(pa) and hull(pb), (n, 3) and (m, 3) float64, with ``scratch`` from ``gjk_scratch`` (at
    least max(n, m) columns). Fills ``out`` (7,): ``out[0:3]`` the closest point on A, ``out[3:6]`` on B,
    ``out[6]`` the distance; the final simplex stays in ``scratch``. Returns (status, simplex size)."""
    n = gjk_pairs_kernel(pa.reshape((1, pa.shape[0], 3)), pb.reshape((1, pb.shape[0], 3)), scratch.no_pairs,
                         scratch.no_offsets, max_iter, scratch, out[6:7], out[0:3].reshape((1, 3)),
                         out[3:6].reshape((1, 3)), scratch.status)
    return scratch.status[0], n


@njit(error_model="numpy")
def _largest_shape(offsets):
    n_max = 1
    for s in range(offsets.shape[0] - 1):
        n_max = max(n_max, offsets[s + 1] - offsets[s])
    return n_max


@njit(error_model="numpy")
def _gjk_pairs(points, offsets, pairs, max_iter, dist, closest_a, closest_b, status):
    """One compiled loop over k pairs of packed shapes (shape s = rows offsets[s]:offsets[s+1] of points)."""
    P = points.reshape((1, points.shape[0], 3))  # one view for the whole loop, shapes addressed by row offsets
    gjk_pairs_kernel(P, P, pairs, offsets, max_iter, gjk_scratch(_largest_shape(offsets)), dist, closest_a,
                     closest_b, status)


@njit(error_model="numpy")
def _gjk_batch(points_a, points_b, max_iter, dist, closest_a, closest_b, status):
    """One compiled loop over k aligned pairs (points_a[p], points_b[p]), addressed by index, not by view."""
    scratch = gjk_scratch(max(points_a.shape[1], points_b.shape[1]))
    gjk_pairs_kernel(points_a, points_b, scratch.no_pairs, scratch.no_offsets, max_iter, scratch, dist, closest_a,
                     closest_b, status)


# ---------------------------------------------------------------------------------------------------------------
# public functions
# ---------------------------------------------------------------------------------------------------------------

@njit(error_model="numpy")
def _within_magnitude(x):
    """True when every entry of the flat array ``x`` has |x| <= MAX_MAGNITUDE (False for NaN and ±inf)."""
    ok = True
    for i in range(x.shape[0]):
        ok &= abs(x[i]) <= MAX_MAGNITUDE
    return ok


def _as_points(value, name: str, shape: tuple, *, scan_values: bool = True) -> np.ndarray:
    """``as_float_array(value, name, shape=shape)`` without its copy when ``value`` already is an aligned, writeable,
    C-contiguous float64 ndarray of that shape: the kernels only read their input, so the copy (a third of a
    batch's time for 20-vertex hulls) buys nothing there. Its values are then checked here (``scan_values``) or,
    when every point is read by the kernel anyway, by the kernel while it copies each shape (status ``INVALID_INPUT``,
    see ``_raise_invalid``). Anything else goes through ``as_float_array``, with its checks and messages."""
    if (type(value) is np.ndarray and value.dtype == np.float64 and value.ndim == len(shape)
            and value.flags.c_contiguous and value.flags.aligned and value.flags.writeable
            and all(want is None or want == got for want, got in zip(shape, value.shape))
            and (not scan_values or _within_magnitude(value.reshape(-1)))):
        return value
    return as_float_array(value, name, shape=shape)


def _raise_invalid(status, arrays: dict, shape: tuple):
    """When the kernel flagged a pair ``INVALID_INPUT``, raise the boundary's own error (``as_float_array`` names the
    argument and the first offending index)."""
    bad = np.flatnonzero(status == INVALID_INPUT)
    if bad.size:
        for name, value in arrays.items():
            as_float_array(value, name, shape=shape)
        raise ValueError(f"{' or '.join(arrays)} hold a NaN, ±inf or a magnitude above {MAX_MAGNITUDE:g} "
                         f"(pair {bad[0]})")


def gjk_distance(points_a, points_b, *, max_iterations: int = MAX_ITERATIONS):
    """Distance between the convex hulls of two point sets, and a closest point on each (GJK).

    Gilbert–Johnson–Keerthi (Ericson 9.5): the distance from the origin to the Minkowski difference
    M = A − B = {a − b}, found by walking a simplex of at most 4 support points of M towards the origin; the
    closest points are the same barycentric combination of the supporting vertices of A and of B. Inputs whose
    largest coordinate is tiny or huge are solved on copies scaled by a power of two, so squared distances never
    underflow or overflow.

    Parameters
    ----------
    points_a : array_like, shape (n, 3), float64
        The points whose convex hull is A, n >= 1 (duplicates and interior points are allowed); finite, magnitude
        at most 1e150.
    points_b : array_like, shape (m, 3), float64
        The points of B, m >= 1.
    max_iterations : int, default 128
        GJK's iteration cap, >= 1.

    Returns
    -------
    distance : float
        >= 0; 0.0 when the hulls overlap or touch.
    closest_a : numpy.ndarray, shape (3,), float64
        A point of hull(A) closest to B.
    closest_b : numpy.ndarray, shape (3,), float64
        A point of hull(B) with ``|closest_a − closest_b| = distance``; when the hulls overlap, both are one point
        common to the two hulls.

    Raises
    ------
    ValueError
        For an empty point set, a shape other than (n, 3), NaN, ±inf or a magnitude above 1e150 (named
        ``points_a`` or ``points_b`` with the index), or ``max_iterations < 1``.
    TypeError
        For non-numeric points or a non-integer ``max_iterations``.
    GJKNotConverged
        When GJK reaches ``max_iterations`` before its stopping test.

    See Also
    --------
    epa_penetration : the depth and normal of overlapping hulls.
    gjk_distance_pairs : k pairs of packed shapes in one call.

    Examples
    --------
    Two unit cubes, the second 3 along x:

    >>> import numpy as np
    >>> import engine
    >>> cube = np.array([[x, y, z] for x in (0.0, 1.0) for y in (0.0, 1.0) for z in (0.0, 1.0)])
    >>> distance, closest_a, closest_b = engine.gjk_distance(cube, cube + [3.0, 0.0, 0.0])
    >>> distance
    2.0
    >>> closest_a, closest_b
    (array([1., 0., 0.]), array([3., 0., 0.]))
    """
    pa = as_float_array(points_a, "points_a", shape=(None, 3), min_rows=1)
    pb = as_float_array(points_b, "points_b", shape=(None, 3), min_rows=1)
    max_iter = as_max_iterations(max_iterations)
    out = np.empty(7)
    status, _ = gjk_kernel(pa, pb, max_iter, gjk_scratch(max(pa.shape[0], pb.shape[0])), out)
    raise_for_status(status, max_iter)
    return float(out[6]), out[0:3].copy(), out[3:6].copy()


def pack_point_sets(point_sets):
    """Pack a list of point sets into the ``(points, offsets)`` arrays of :ref:`packed-point-sets`.

    Parameters
    ----------
    point_sets : sequence of array_like, each of shape (n_i, 3)
        The shapes' vertices, n_i >= 1, finite.

    Returns
    -------
    points : numpy.ndarray, shape (N, 3), float64
        The sets one after the other, N = sum of the n_i.
    offsets : numpy.ndarray, shape (len(point_sets) + 1,), int64
        Shape s owns ``points[offsets[s]:offsets[s + 1]]``; ``[0]`` and an empty (0, 3) array for an empty list.

    Raises
    ------
    ValueError
        For an empty set, a wrong shape, NaN or ±inf (named ``point_sets[i]``).
    """
    if len(point_sets) == 0:
        return np.empty((0, 3)), np.zeros(1, np.int64)
    arrays = [as_float_array(p, f"point_sets[{i}]", shape=(None, 3), min_rows=1) for i, p in enumerate(point_sets)]
    offsets = np.zeros(len(arrays) + 1, np.int64)
    offsets[1:] = np.cumsum([a.shape[0] for a in arrays])
    return np.concatenate(arrays, axis=0), offsets


#: a thread gets at least this many pairs (below that, starting threads costs more than it saves)
MIN_PAIRS_PER_THREAD = 512


def run_in_chunks(run, k: int, threads: int) -> None:
    """Call ``run(lo, hi)`` on contiguous chunks of ``range(k)``, one per thread of a thread pool.

    The kernels are compiled with ``nogil=True``, so the chunks run in parallel; each chunk writes its own slice
    of the outputs, so the answers are the same, bit for bit, as one call over the whole batch. With
    ``threads == 1``, or fewer than ``MIN_PAIRS_PER_THREAD`` pairs per thread, it is one call on this thread.
    """
    n = min(threads, max(1, k // MIN_PAIRS_PER_THREAD))
    if n <= 1:
        run(0, k)
        return
    bounds = [k * i // n for i in range(n + 1)]
    with ThreadPoolExecutor(max_workers=n) as pool:
        for future in [pool.submit(run, bounds[i], bounds[i + 1]) for i in range(n)]:
            future.result()


def _solve_in_chunks(k: int, threads: int, solve):
    """The outputs of k pairs, distance (k,), closest_a, closest_b (k, 3) float64 and status (k,) int64, filled by
    ``solve(lo, hi, distance[lo:hi], closest_a[lo:hi], closest_b[lo:hi], status[lo:hi])`` on each chunk of
    ``run_in_chunks``."""
    dist = np.empty(k)
    ca = np.empty((k, 3))
    cb = np.empty((k, 3))
    status = np.empty(k, np.int64)
    if k:
        run_in_chunks(lambda lo, hi: solve(lo, hi, dist[lo:hi], ca[lo:hi], cb[lo:hi], status[lo:hi]), k, threads)
    return dist, ca, cb, status


def gjk_distance_pairs(points, offsets, pairs, *, max_iterations: int = MAX_ITERATIONS, threads: int = 1):
    """GJK for k pairs of packed convex shapes, in one compiled call (or one per thread).

    The algorithm of ``gjk_distance``, pair p being ``pairs[p]`` of :ref:`packed-point-sets`.

    Parameters
    ----------
    points, offsets, pairs
        The shapes and the pairs, see :ref:`packed-point-sets`.
    max_iterations : int, default 128
        GJK's iteration cap per pair, >= 1.
    threads : int, default 1
        With more than 1 (at most 256), the pairs are split into contiguous chunks run on that many threads (the
        kernels release the GIL); the answers are the same, bit for bit.

    Returns
    -------
    distance : numpy.ndarray, shape (k,), float64
        Distance of each pair's hulls, 0.0 where they overlap or touch.
    closest_a, closest_b : numpy.ndarray, shape (k, 3), float64
        The closest points on the first and on the second shape of each pair.

    Raises
    ------
    GJKNotConverged
        For the first pair (named ``pairs[p]``) that reaches ``max_iterations``.
    ValueError, TypeError
        For a bad argument, as in :ref:`packed-point-sets`, or ``threads`` out of range.
    """
    pts = _as_points(points, "points", (None, 3))
    off = check_offsets(offsets, pts.shape[0])
    pr = check_pairs(pairs, off.shape[0] - 1)
    max_iter = as_max_iterations(max_iterations)
    n_threads = as_count(threads, "threads", minimum=1, maximum=MAX_THREADS)
    dist, ca, cb, status = _solve_in_chunks(pr.shape[0], n_threads,
                                            lambda lo, hi, *out: _gjk_pairs(pts, off, pr[lo:hi], max_iter, *out))
    if status.size:
        _raise_invalid(status, {"points": points}, (None, 3))
        raise_for_status(status, max_iter, "pairs")
    return dist, ca, cb


def gjk_distance_batch(points_a, points_b, *, max_iterations: int = MAX_ITERATIONS, threads: int = 1):
    """GJK for k aligned pairs of equally sized point sets: ``points_a[p]`` against ``points_b[p]``.

    Parameters
    ----------
    points_a : array_like, shape (k, n, 3), float64
        The k first shapes, n >= 1 points each (when k > 0).
    points_b : array_like, shape (k, m, 3), float64
        The k second shapes, m >= 1 points each.
    max_iterations : int, default 128
        Iteration cap per pair, >= 1.
    threads : int, default 1
        Threads that share the pairs (at most 256); the same answers bit for bit.

    Returns
    -------
    distance : numpy.ndarray, shape (k,), float64
        The distance of each pair, 0.0 for overlapping or touching hulls.
    closest_a, closest_b : numpy.ndarray, shape (k, 3), float64
        A closest point on each hull of pair p.

    Raises
    ------
    ValueError
        For different numbers of pairs, an empty shape, NaN, ±inf or a magnitude above 1e150 (named with the
        argument and index).
    GJKNotConverged
        For the first pair (``points_a[p]``) that reaches ``max_iterations``.
    """
    # every point of a batch is read by the kernel, which checks the values as it copies them (INVALID_INPUT)
    pa = _as_points(points_a, "points_a", (None, None, 3), scan_values=False)
    pb = _as_points(points_b, "points_b", (None, None, 3), scan_values=False)
    if pa.shape[0] != pb.shape[0]:
        raise ValueError(f"points_a and points_b must hold the same number of pairs, got {pa.shape[0]} and "
                         f"{pb.shape[0]}")
    if pa.shape[0] and (pa.shape[1] < 1 or pb.shape[1] < 1):
        raise ValueError("every shape needs at least one point")
    max_iter = as_max_iterations(max_iterations)
    n_threads = as_count(threads, "threads", minimum=1, maximum=MAX_THREADS)
    dist, ca, cb, status = _solve_in_chunks(pa.shape[0], n_threads,
                                            lambda lo, hi, *out: _gjk_batch(pa[lo:hi], pb[lo:hi], max_iter, *out))
    if status.size:
        _raise_invalid(status, {"points_a": points_a, "points_b": points_b}, (None, None, 3))
        raise_for_status(status, max_iter, "points_a")
    return dist, ca, cb
