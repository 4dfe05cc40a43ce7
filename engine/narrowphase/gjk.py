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
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from .._config import njit
from .._validate import MAX_MAGNITUDE, as_count, as_float_array, as_max_iterations, check_offsets, check_pairs

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
#: pairs whose largest |coordinate| lies outside [2^-200, 2^200] are solved on copies scaled by a power of two
#: (``rescale_unit``): squared lengths and squared cross products (degree 4) then neither underflow nor overflow
RESCALE_ABOVE = 2.0**200

# kernel status codes
_SEPARATED = 0
_OVERLAP = 1
_NOT_CONVERGED = 2
_INVALID = 3  # a coordinate of the pair is NaN, ±inf or above MAX_MAGNITUDE (checked while copying)


class GJKNotConverged(RuntimeError):
    """GJK reached its iteration cap without meeting its stopping test."""


# ---------------------------------------------------------------------------------------------------------------
# kernels
#
# The per-pair loop holds no reference counting (numba's NRT incref/decref are atomic operations): the one kernel
# ``_gjk_loop`` runs the pair loop and the GJK loop in one function body, takes every array once as an argument,
# and addresses shapes by (index, row range) rather than by slices or views; the Voronoi-region helpers below
# take and return scalars only (no arrays, no tuple-of-arrays).
# ---------------------------------------------------------------------------------------------------------------

@njit
def rescale_unit(big):
    """1.0, or — when ``big``, the largest |coordinate| of a pair of shapes, lies outside [2^-200, 2^200] — the
    power of two that brings it into [0.5, 1) (between 2^-1000 and 2^1000, so that the factor itself is finite).
    Scaling by it is exact (up to coordinates more than 2^1000 times smaller than the largest, far below its ulp)."""
    if big > 0.0 and (big * RESCALE_ABOVE < 1.0 or big > RESCALE_ABOVE):
        return math.ldexp(1.0, max(-1000, min(-math.frexp(big)[1], 1000)))
    return 1.0


@njit
def _copy_shape(P, s, r0, n, S, row):
    """Copy rows ``P[s, r0:r0 + n]`` into the scratch rows ``S[row:row + 3, :n]`` (x, y, z: unit-stride support
    scans) and return ``(ok, centroid, big)``: ok is False when a coordinate is NaN, ±inf or above MAX_MAGNITUDE;
    big is the largest |coordinate|. The
    sums run over even and odd rows: two short addition chains, not one long one. (A plain ``@njit``, not
    ``inline="always"``: numba's IR inlining of a function with array arguments adds reference counting to the
    caller's pair loop; LLVM inlines this one without it.)"""
    ok = True
    big = 0.0
    x0 = 0.0
    y0 = 0.0
    z0 = 0.0
    x1 = 0.0
    y1 = 0.0
    z1 = 0.0
    for i in range(n):
        x = P[s, r0 + i, 0]
        y = P[s, r0 + i, 1]
        z = P[s, r0 + i, 2]
        ok &= (abs(x) <= MAX_MAGNITUDE) & (abs(y) <= MAX_MAGNITUDE) & (abs(z) <= MAX_MAGNITUDE)
        m = max(abs(x), abs(y), abs(z))  # off the loop-carried chain, which gets one max per row
        big = max(big, m)
        S[row, i] = x
        S[row + 1, i] = y
        S[row + 2, i] = z
        if i % 2 == 0:
            x0 += x
            y0 += y
            z0 += z
        else:
            x1 += x
            y1 += y
            z1 += z
    return ok, (x0 + x1) / n, (y0 + y1) / n, (z0 + z1) / n, big


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
def _segment(ax, ay, az, bx, by, bz):
    """Closest point to the origin on segment [a, b] (Ericson 5.1.2).

    Returns ``(m, s0, s1, l0, l1)``: the m supporting vertices (0 = a, 1 = b, ascending) and their weights.
    """
    abx, aby, abz = bx - ax, by - ay, bz - az
    denom = abx * abx + aby * aby + abz * abz
    t = -(ax * abx + ay * aby + az * abz)
    if t <= 0.0 or denom <= 0.0:
        return 1, 0, 0, 1.0, 0.0
    if t >= denom:
        return 1, 1, 0, 1.0, 0.0
    t = t / denom
    return 2, 0, 1, 1.0 - t, t


@njit(inline="always")
def _triangle(ax, ay, az, bx, by, bz, cx, cy, cz):
    """Ericson 5.1.5 ClosestPtPointTriangle with p = origin: Voronoi regions of vertices, edges, face.

    Returns ``(m, s0, s1, s2, l0, l1, l2)``: the m supporting vertices (0 = a, 1 = b, 2 = c, ascending) and their
    barycentric weights, or m = -1 for a zero-area triangle.
    """
    abx, aby, abz = bx - ax, by - ay, bz - az
    acx, acy, acz = cx - ax, cy - ay, cz - az
    # a needle triangle (sin of the angle at a below 1e-10) is left to the edge fallback: the region tests below
    # cancel catastrophically there, and its closest point is within 1e-10 × its size of one of its edges
    nx = aby * acz - abz * acy
    ny = abz * acx - abx * acz
    nz = abx * acy - aby * acx
    ab2 = abx * abx + aby * aby + abz * abz
    ac2 = acx * acx + acy * acy + acz * acz
    if not (nx * nx + ny * ny + nz * nz > 1e-20 * ab2 * ac2):
        return -1, 0, 0, 0, 0.0, 0.0, 0.0
    # ap = -a
    d1 = -(abx * ax + aby * ay + abz * az)
    d2 = -(acx * ax + acy * ay + acz * az)
    if d1 <= 0.0 and d2 <= 0.0:  # vertex region A
        return 1, 0, 0, 0, 1.0, 0.0, 0.0
    # bp = -b
    d3 = -(abx * bx + aby * by + abz * bz)
    d4 = -(acx * bx + acy * by + acz * bz)
    if d3 >= 0.0 and d4 <= d3:  # vertex region B
        return 1, 1, 0, 0, 1.0, 0.0, 0.0
    vc = d1 * d4 - d3 * d2
    # (each edge region also needs a non-zero-length edge: a zero-length one falls through to the degenerate case)
    if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0 and d1 - d3 > 0.0:  # edge region AB
        v = d1 / (d1 - d3)
        return 2, 0, 1, 0, 1.0 - v, v, 0.0
    # cp = -c
    d5 = -(abx * cx + aby * cy + abz * cz)
    d6 = -(acx * cx + acy * cy + acz * cz)
    if d6 >= 0.0 and d5 <= d6:  # vertex region C
        return 1, 2, 0, 0, 1.0, 0.0, 0.0
    vb = d5 * d2 - d1 * d6
    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0 and d2 - d6 > 0.0:  # edge region AC
        w = d2 / (d2 - d6)
        return 2, 0, 2, 0, 1.0 - w, w, 0.0
    va = d3 * d6 - d5 * d4
    if va <= 0.0 and (d4 - d3) >= 0.0 and (d5 - d6) >= 0.0 and (d4 - d3) + (d5 - d6) > 0.0:  # edge region BC
        w = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        return 2, 1, 2, 0, 1.0 - w, w, 0.0
    denom = va + vb + vc
    if not denom > 0.0:  # degenerate (zero-area) triangle
        return -1, 0, 0, 0, 0.0, 0.0, 0.0
    v = vb / denom
    w = vc / denom
    return 3, 0, 1, 2, 1.0 - v - w, v, w


@njit(inline="always")
def _pick3(s, a, b, c):
    """Component ``s`` (0, 1, 2) of (a, b, c)."""
    if s == 0:
        return a
    if s == 1:
        return b
    return c


@njit(inline="always")
def _triangle_distance2(m, s0, s1, s2, l0, l1, l2, ax, ay, az, bx, by, bz, cx, cy, cz):
    """|Σ λ_k p_{s_k}|² over the m supporting vertices of triangle (a, b, c)."""
    x = 0.0
    y = 0.0
    z = 0.0
    if m >= 1:
        x += l0 * _pick3(s0, ax, bx, cx)
        y += l0 * _pick3(s0, ay, by, cy)
        z += l0 * _pick3(s0, az, bz, cz)
    if m >= 2:
        x += l1 * _pick3(s1, ax, bx, cx)
        y += l1 * _pick3(s1, ay, by, cy)
        z += l1 * _pick3(s1, az, bz, cz)
    if m >= 3:
        x += l2 * _pick3(s2, ax, bx, cx)
        y += l2 * _pick3(s2, ay, by, cy)
        z += l2 * _pick3(s2, az, bz, cz)
    return x * x + y * y + z * z


@njit(inline="always")
def _triangle_any(ax, ay, az, bx, by, bz, cx, cy, cz):
    """Closest point of triangle (a, b, c) to the origin, degenerate triangles included.

    Returns ``(m, s0, s1, s2, l0, l1, l2)`` as ``_triangle`` (never -1: a zero-area triangle falls back on the
    best of its three edges).
    """
    m, s0, s1, s2, l0, l1, l2 = _triangle(ax, ay, az, bx, by, bz, cx, cy, cz)
    if m > 0:
        return m, s0, s1, s2, l0, l1, l2
    # zero-area triangle: the closest point lies on one of its three edges
    best_n = 0
    b0 = 0
    b1 = 0
    bl0 = 0.0
    bl1 = 0.0
    best_d = np.inf
    for e in range(3):
        if e == 0:
            i0, i1 = 0, 1
            k, t0, t1, w0, w1 = _segment(ax, ay, az, bx, by, bz)
        elif e == 1:
            i0, i1 = 1, 2
            k, t0, t1, w0, w1 = _segment(bx, by, bz, cx, cy, cz)
        else:
            i0, i1 = 0, 2
            k, t0, t1, w0, w1 = _segment(ax, ay, az, cx, cy, cz)
        # segment vertex 0 / 1 -> triangle vertex i0 / i1
        g0 = i1 if t0 == 1 else i0
        g1 = i1 if t1 == 1 else i0
        d = _triangle_distance2(k, g0, g1, 0, w0, w1, 0.0, ax, ay, az, bx, by, bz, cx, cy, cz)
        if d < best_d:
            best_d = d
            best_n = k
            b0 = g0
            b1 = g1
            bl0 = w0
            bl1 = w1
    return best_n, b0, b1, 0, bl0, bl1, 0.0


@njit(inline="always")
def _face_sides(W, i, j, k, l):
    """Signed volumes (times 6) of the origin and of vertex ``W[l]`` against the plane of face (W[i], W[j], W[k]):
    ``(-(p · n), (W[l] − p) · n)`` with p = W[i], n = (W[j] − p) × (W[k] − p) (Ericson 5.1.6, PointOutsideOfPlane)."""
    px, py, pz = W[i, 0], W[i, 1], W[i, 2]
    e1x, e1y, e1z = W[j, 0] - px, W[j, 1] - py, W[j, 2] - pz
    e2x, e2y, e2z = W[k, 0] - px, W[k, 1] - py, W[k, 2] - pz
    nx = e1y * e2z - e1z * e2y
    ny = e1z * e2x - e1x * e2z
    nz = e1x * e2y - e1y * e2x
    return -(px * nx + py * ny + pz * nz), (W[l, 0] - px) * nx + (W[l, 1] - py) * ny + (W[l, 2] - pz) * nz


#: stands for "no pair list" in ``_gjk_loop`` (batch and single-pair calls address shapes by pair index)
_NO_PAIRS = np.zeros((0, 2), np.int64)
_NO_OFFSETS = np.zeros(1, np.int64)


@njit
def _gjk_loop(PA, PB, pairs, offsets, k_pairs, max_iter, W, IA, IB, lam, dist, closest_a, closest_b, status_out, S):
    """GJK (Ericson 9.5) over k pairs of shapes, in one compiled loop.

    ``PA``, ``PB`` are (S, N, 3). With a pair list (``pairs`` (k, 2), ``offsets``), pair p is shape
    ``pairs[p, 0]`` of A = rows ``offsets[s]:offsets[s + 1]`` of ``PA[0]`` against shape ``pairs[p, 1]`` of B, the
    same way; without one (``pairs`` empty), pair p is ``PA[p]`` against ``PB[p]``. Shapes are addressed by
    (index, row range), never by slices: the loop creates no array views and assigns no array variable, so it
    holds no reference counting. ``S`` (6, n_max) is scratch: each pair's two shapes are copied there as x, y, z
    rows (unit-stride support scans; the copy also checks the values and sums the centroids: status ``_INVALID``
    for a NaN, ±inf or a magnitude above MAX_MAGNITUDE). Writes ``dist[p]``, ``closest_a[p]``, ``closest_b[p]``,
    ``status_out[p]`` and leaves the last pair's final simplex in W (4, 3), IA, IB (row indices into PA[sa],
    PB[sb]), λ (for EPA). Returns the last pair's (status, simplex size).
    """
    use_pairs = pairs.shape[0] > 0
    status = _NOT_CONVERGED
    n = 0
    for p in range(k_pairs):
        if use_pairs:
            sa = 0
            sb = 0
            a0 = offsets[pairs[p, 0]]
            a1 = offsets[pairs[p, 0] + 1]
            b0 = offsets[pairs[p, 1]]
            b1 = offsets[pairs[p, 1] + 1]
        else:
            sa = p
            sb = p
            a0 = 0
            a1 = PA.shape[1]
            b0 = 0
            b1 = PB.shape[1]
        # copy both shapes into the scratch rows (x, y, z of A, then of B) for unit-stride support scans
        na = a1 - a0
        nb = b1 - b0
        ok_a, cax, cay, caz, big_a = _copy_shape(PA, sa, a0, na, S, 0)
        ok_b, cbx, cby, cbz, big_b = _copy_shape(PB, sb, b0, nb, S, 3)
        ok = ok_a and ok_b
        if not ok:  # NaN, ±inf or a magnitude above MAX_MAGNITUDE: the caller raises
            status = _INVALID
            n = 0
            dist[p] = np.nan
            status_out[p] = status
            continue
        # tiny or huge shapes: the copies are scaled by a power of two (exact) so that squared lengths stay normal
        # numbers (squared distances below ~1e-154 turn subnormal and lose their digits)
        unit = rescale_unit(max(big_a, big_b))
        if unit != 1.0:
            for i in range(na):
                S[0, i] *= unit
                S[1, i] *= unit
                S[2, i] *= unit
            for i in range(nb):
                S[3, i] *= unit
                S[4, i] *= unit
                S[5, i] *= unit
        # start from a support point of M (so that every simplex vertex lies on M's boundary, as EPA assumes), in
        # the direction of M's centroid: the first support point is then already close to the answer
        dx = cax - cbx
        dy = cay - cby
        dz = caz - cbz
        if dx == 0.0 and dy == 0.0 and dz == 0.0:
            dx = 1.0
        vx, vy, vz = dx, dy, dz
        n = 0
        vv = 0.0
        size2 = 0.0
        status = _NOT_CONVERGED
        # iteration -1 takes the first support point as the simplex, unconditionally
        for it in range(-1, max_iter):
            if it >= 0 and vv <= (OVERLAP_TOL * OVERLAP_TOL) * size2:
                status = _OVERLAP
                break
            # w <- s_A(-v) - s_B(v): the first vertex of A with the least a·v and of B with the greatest b·v;
            # one plain scan per shape, the tie going to the lower row (it compiles to a branch-free min/cmov loop;
            # an even/odd two-chain scan measured slower)
            ia = 0
            lo = np.inf
            for i in range(na):
                d = S[0, i] * vx + S[1, i] * vy + S[2, i] * vz
                if d < lo:
                    lo = d
                    ia = i
            ib = 0
            hi = -np.inf
            for i in range(nb):
                d = S[3, i] * vx + S[4, i] * vy + S[5, i] * vz
                if d > hi:
                    hi = d
                    ib = i
            wx = S[0, ia] - S[3, ib]
            wy = S[1, ia] - S[4, ib]
            wz = S[2, ia] - S[5, ib]
            ia += a0
            ib += b0
            if it < 0:
                W[0, 0] = wx
                W[0, 1] = wy
                W[0, 2] = wz
                IA[0] = ia
                IB[0] = ib
                lam[0] = 1.0
                n = 1
                vx, vy, vz = wx, wy, wz
                vv = vx * vx + vy * vy + vz * vz
                size2 = vv
                continue
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
            # W <- smallest subset of W holding the closest point of hull(W) to the origin (Ericson 5.1.2, 5.1.5,
            # 5.1.6): m supporting vertices s0 < s1 < s2 with weights l0, l1, l2
            m = 0
            s0 = 0
            s1 = 0
            s2 = 0
            l0 = 0.0
            l1 = 0.0
            l2 = 0.0
            if n == 2:
                m, s0, s1, l0, l1 = _segment(W[0, 0], W[0, 1], W[0, 2], W[1, 0], W[1, 1], W[1, 2])
            elif n == 3:
                m, s0, s1, s2, l0, l1, l2 = _triangle_any(W[0, 0], W[0, 1], W[0, 2], W[1, 0], W[1, 1], W[1, 2],
                                                         W[2, 0], W[2, 1], W[2, 2])
            else:
                # tetrahedron: the origin is outside face (i, j, k) when it is on the other side of it from vertex l
                abx, aby, abz = W[1, 0] - W[0, 0], W[1, 1] - W[0, 1], W[1, 2] - W[0, 2]
                acx, acy, acz = W[2, 0] - W[0, 0], W[2, 1] - W[0, 1], W[2, 2] - W[0, 2]
                adx, ady, adz = W[3, 0] - W[0, 0], W[3, 1] - W[0, 1], W[3, 2] - W[0, 2]
                det = abx * (acy * adz - acz * ady) + aby * (acz * adx - acx * adz) + abz * (acx * ady - acy * adx)
                scale = max(abx * abx + aby * aby + abz * abz, acx * acx + acy * acy + acz * acz,
                            adx * adx + ady * ady + adz * adz)
                flat = abs(det) <= 1e-12 * scale * math.sqrt(scale)
                # signed volumes (times 6) of the origin and of the fourth vertex l against each face (i, j, k):
                # the origin is outside face (i, j, k) when the two have opposite signs
                so0, sl0 = _face_sides(W, 0, 1, 2, 3)
                so1, sl1 = _face_sides(W, 0, 1, 3, 2)
                so2, sl2 = _face_sides(W, 0, 2, 3, 1)
                so3, sl3 = _face_sides(W, 1, 2, 3, 0)
                out0 = flat or so0 * sl0 < 0.0
                out1 = flat or so1 * sl1 < 0.0
                out2 = flat or so2 * sl2 < 0.0
                out3 = flat or so3 * sl3 < 0.0
                if not (out0 or out1 or out2 or out3):
                    # origin inside (or on) the tetrahedron: barycentric coordinates by signed volumes (the weight of
                    # vertex l is the origin's volume over l's against the face opposite l)
                    lam[0] = so3 / sl3
                    lam[1] = so2 / sl2
                    lam[2] = so1 / sl1
                    lam[3] = so0 / sl0
                    n = 4
                    status = _OVERLAP
                    break
                # otherwise the closest point lies on a face the origin is outside of: the best of those faces
                best_d = np.inf
                m = -1
                for f in range(4):
                    # face (i, j, k) opposite vertex l, with i < j < k
                    if f == 0:
                        if not out0:
                            continue
                        i, j, k = 0, 1, 2
                    elif f == 1:
                        if not out1:
                            continue
                        i, j, k = 0, 1, 3
                    elif f == 2:
                        if not out2:
                            continue
                        i, j, k = 0, 2, 3
                    else:
                        if not out3:
                            continue
                        i, j, k = 1, 2, 3
                    px, py, pz = W[i, 0], W[i, 1], W[i, 2]
                    qx, qy, qz = W[j, 0], W[j, 1], W[j, 2]
                    rx, ry, rz = W[k, 0], W[k, 1], W[k, 2]
                    fm, t0, t1, t2, w0, w1, w2 = _triangle_any(px, py, pz, qx, qy, qz, rx, ry, rz)
                    d = _triangle_distance2(fm, t0, t1, t2, w0, w1, w2, px, py, pz, qx, qy, qz, rx, ry, rz)
                    if d < best_d:
                        best_d = d
                        m = fm
                        # face vertex 0 / 1 / 2 -> simplex vertex i / j / k (ascending stays ascending)
                        s0 = _pick3(t0, i, j, k)
                        s1 = _pick3(t1, i, j, k)
                        s2 = _pick3(t2, i, j, k)
                        l0 = w0
                        l1 = w1
                        l2 = w2
            # keep W[s0], W[s1], W[s2] (ascending, so copying forward in place never overwrites one still to read)
            if m >= 1:
                W[0, 0] = W[s0, 0]
                W[0, 1] = W[s0, 1]
                W[0, 2] = W[s0, 2]
                IA[0] = IA[s0]
                IB[0] = IB[s0]
                lam[0] = l0
            if m >= 2:
                W[1, 0] = W[s1, 0]
                W[1, 1] = W[s1, 1]
                W[1, 2] = W[s1, 2]
                IA[1] = IA[s1]
                IB[1] = IB[s1]
                lam[1] = l1
            if m >= 3:
                W[2, 0] = W[s2, 0]
                W[2, 1] = W[s2, 1]
                W[2, 2] = W[s2, 2]
                IA[2] = IA[s2]
                IB[2] = IB[s2]
                lam[2] = l2
            n = m
            # v <- Σ λ_k W_k
            nx = 0.0
            ny = 0.0
            nz = 0.0
            if n >= 1:
                nx += lam[0] * W[0, 0]
                ny += lam[0] * W[0, 1]
                nz += lam[0] * W[0, 2]
            if n >= 2:
                nx += lam[1] * W[1, 0]
                ny += lam[1] * W[1, 1]
                nz += lam[1] * W[1, 2]
            if n >= 3:
                nx += lam[2] * W[2, 0]
                ny += lam[2] * W[2, 1]
                nz += lam[2] * W[2, 2]
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
        qx = 0.0
        qy = 0.0
        qz = 0.0
        rx = 0.0
        ry = 0.0
        rz = 0.0
        for k in range(n):
            qx += lam[k] * PA[sa, IA[k], 0]
            rx += lam[k] * PB[sb, IB[k], 0]
            qy += lam[k] * PA[sa, IA[k], 1]
            ry += lam[k] * PB[sb, IB[k], 1]
            qz += lam[k] * PA[sa, IA[k], 2]
            rz += lam[k] * PB[sb, IB[k], 2]
        if status == _OVERLAP:
            dist[p] = 0.0
            # one common point: the two barycentric sums agree to round-off; report their mean on both sides
            qx = 0.5 * (qx + rx)
            qy = 0.5 * (qy + ry)
            qz = 0.5 * (qz + rz)
            rx, ry, rz = qx, qy, qz
        else:
            dist[p] = math.sqrt(vv) / unit
        if unit != 1.0:  # the simplex is handed on (to EPA) in the shapes' own coordinates
            for k in range(n):
                W[k, 0] /= unit
                W[k, 1] /= unit
                W[k, 2] /= unit
        closest_a[p, 0] = qx
        closest_a[p, 1] = qy
        closest_a[p, 2] = qz
        closest_b[p, 0] = rx
        closest_b[p, 1] = ry
        closest_b[p, 2] = rz
        status_out[p] = status
    return status, n


@njit
def _gjk(pa, pb, max_iter, W, IA, IB, lam, out, work_i, work_f):
    """GJK (Ericson 9.5) between hull(pa) and hull(pb), (n, 3) and (m, 3).

    Fills ``out[0:3]`` with the closest point on A, ``out[3:6]`` on B, ``out[6]`` with the distance, and leaves
    the final simplex (support points W, their vertex indices IA, IB, weights λ) for EPA. ``work_i`` (>= 1,) int
    receives the status; ``work_f`` is kept for callers' compatibility. Returns (status, simplex size).
    """
    return _gjk_loop(pa[np.newaxis], pb[np.newaxis], _NO_PAIRS, _NO_OFFSETS, 1, max_iter, W, IA, IB, lam,
                     out[6:7], out[np.newaxis, 0:3], out[np.newaxis, 3:6], work_i,
                     np.empty((6, max(pa.shape[0], pb.shape[0]))))


@njit
def _gjk_pairs(points, offsets, pairs, max_iter, dist, closest_a, closest_b, status):
    """One compiled loop over k pairs of packed shapes (shape s = rows offsets[s]:offsets[s+1] of points)."""
    W = np.empty((4, 3))
    IA = np.empty(4, np.int64)
    IB = np.empty(4, np.int64)
    lam = np.empty(4)
    P = points[np.newaxis]  # (1, N, 3): one view for the whole loop, shapes addressed by row offsets
    n_max = 1
    for s in range(offsets.shape[0] - 1):
        n_max = max(n_max, offsets[s + 1] - offsets[s])
    _gjk_loop(P, P, pairs, offsets, pairs.shape[0], max_iter, W, IA, IB, lam, dist, closest_a, closest_b, status,
              np.empty((6, n_max)))


@njit
def _gjk_batch(points_a, points_b, max_iter, dist, closest_a, closest_b, status):
    """One compiled loop over k aligned pairs (points_a[p], points_b[p]), addressed by index, not by view."""
    W = np.empty((4, 3))
    IA = np.empty(4, np.int64)
    IB = np.empty(4, np.int64)
    lam = np.empty(4)
    _gjk_loop(points_a, points_b, _NO_PAIRS, _NO_OFFSETS, points_a.shape[0], max_iter, W, IA, IB, lam, dist,
              closest_a, closest_b, status, np.empty((6, max(points_a.shape[1], points_b.shape[1]))))


# ---------------------------------------------------------------------------------------------------------------
# public functions
# ---------------------------------------------------------------------------------------------------------------

@njit
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
    when every point is read by the kernel anyway, by the kernel while it copies each shape (status ``_INVALID``,
    see ``_raise_invalid``). Anything else goes through ``as_float_array``, with its checks and messages."""
    if (type(value) is np.ndarray and value.dtype == np.float64 and value.ndim == len(shape)
            and value.flags.c_contiguous and value.flags.aligned and value.flags.writeable
            and all(want is None or want == got for want, got in zip(shape, value.shape))
            and (not scan_values or _within_magnitude(value.reshape(-1)))):
        return value
    return as_float_array(value, name, shape=shape)


def _raise_invalid(status, arrays: dict, shape: tuple):
    """When the kernel flagged a pair ``_INVALID``, raise the boundary's own error (``as_float_array`` names the
    argument and the first offending index)."""
    bad = np.flatnonzero(status == _INVALID)
    if bad.size:
        for name, value in arrays.items():
            as_float_array(value, name, shape=shape)
        raise ValueError(f"{' or '.join(arrays)} hold a NaN, ±inf or a magnitude above {MAX_MAGNITUDE:g} "
                         f"(pair {bad[0]})")


def gjk_distance(points_a, points_b, *, max_iterations: int = MAX_ITERATIONS):
    """Distance between the convex hulls of ``points_a`` (n, 3) and ``points_b`` (m, 3), n, m >= 1.

    Returns ``(distance, closest_a, closest_b)``: a float >= 0 (0.0 when the hulls overlap or touch) and the two
    closest points (3,), one on each hull, with |closest_a − closest_b| = distance. When the hulls overlap, both
    points are the same point common to the two hulls. Raises ``GJKNotConverged`` after ``max_iterations``.
    """
    pa = as_float_array(points_a, "points_a", shape=(None, 3), min_rows=1)
    pb = as_float_array(points_b, "points_b", shape=(None, 3), min_rows=1)
    max_iter = as_max_iterations(max_iterations)
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


def _raise_first_failure(status, what: str, max_iter: int):
    bad = np.flatnonzero(status == _NOT_CONVERGED)
    if bad.size:
        raise GJKNotConverged(f"GJK did not converge in max_iterations={max_iter} iterations for {what}[{bad[0]}]")


#: a thread gets at least this many pairs (below that, starting threads costs more than it saves)
MIN_PAIRS_PER_THREAD = 512
#: the most threads a batch call may ask for
MAX_THREADS = 256


def _run_in_chunks(run, k: int, threads: int) -> None:
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


def gjk_distance_pairs(points, offsets, pairs, *, max_iterations: int = MAX_ITERATIONS, threads: int = 1):
    """GJK over k pairs of packed shapes, in one compiled call (or one per thread: ``threads``).

    ``points`` (N, 3) holds every shape's vertices; shape s owns ``points[offsets[s]:offsets[s + 1]]``
    (``offsets`` (S + 1,), increasing, from 0 to N; see ``pack_point_sets``). ``pairs`` (k, 2) int lists
    (shape_a, shape_b). Returns ``(distance (k,), closest_a (k, 3), closest_b (k, 3))``. ``threads`` > 1 splits
    the pairs among that many threads (``_run_in_chunks``; the same answers, bit for bit).
    """
    pts = _as_points(points, "points", (None, 3))
    off = check_offsets(offsets, pts.shape[0])
    pr = check_pairs(pairs, off.shape[0] - 1)
    max_iter = as_max_iterations(max_iterations)
    n_threads = as_count(threads, "threads", minimum=1, maximum=MAX_THREADS)
    k = pr.shape[0]
    dist = np.empty(k)
    ca = np.empty((k, 3))
    cb = np.empty((k, 3))
    status = np.empty(k, np.int64)
    if k:
        _run_in_chunks(lambda lo, hi: _gjk_pairs(pts, off, pr[lo:hi], max_iter, dist[lo:hi], ca[lo:hi], cb[lo:hi],
                                                status[lo:hi]), k, n_threads)
        _raise_invalid(status, {"points": points}, (None, 3))
        _raise_first_failure(status, "pairs", max_iter)
    return dist, ca, cb


def gjk_distance_batch(points_a, points_b, *, max_iterations: int = MAX_ITERATIONS, threads: int = 1):
    """GJK over k aligned pairs: ``points_a`` (k, n, 3) against ``points_b`` (k, m, 3), one compiled call (or one
    per thread: ``threads`` > 1 splits the pairs among that many threads, with the same answers bit for bit).

    Returns ``(distance (k,), closest_a (k, 3), closest_b (k, 3))``.
    """
    # every point of a batch is read by the kernel, which checks the values as it copies them (_INVALID)
    pa = _as_points(points_a, "points_a", (None, None, 3), scan_values=False)
    pb = _as_points(points_b, "points_b", (None, None, 3), scan_values=False)
    if pa.shape[0] != pb.shape[0]:
        raise ValueError(f"points_a and points_b must hold the same number of pairs, got {pa.shape[0]} and "
                         f"{pb.shape[0]}")
    if pa.shape[0] and (pa.shape[1] < 1 or pb.shape[1] < 1):
        raise ValueError("every shape needs at least one point")
    max_iter = as_max_iterations(max_iterations)
    n_threads = as_count(threads, "threads", minimum=1, maximum=MAX_THREADS)
    k = pa.shape[0]
    dist = np.empty(k)
    ca = np.empty((k, 3))
    cb = np.empty((k, 3))
    status = np.empty(k, np.int64)
    if k:
        _run_in_chunks(lambda lo, hi: _gjk_batch(pa[lo:hi], pb[lo:hi], max_iter, dist[lo:hi], ca[lo:hi], cb[lo:hi],
                                                status[lo:hi]), k, n_threads)
        _raise_invalid(status, {"points_a": points_a, "points_b": points_b}, (None, None, 3))
        _raise_first_failure(status, "points_a", max_iter)
    return dist, ca, cb
