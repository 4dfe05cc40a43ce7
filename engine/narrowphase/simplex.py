"""Closest point of a simplex to the origin — GJK's sub-algorithm (Ericson, *Real-Time Collision Detection*, 5.1.2
ClosestPtPointSegment, 5.1.5 ClosestPtPointTriangle, 5.1.6 ClosestPtPointTetrahedron, with the query point p at
the origin; section 9.5 for their use in GJK).

Each kernel takes the simplex's vertices as scalars and returns the smallest sub-simplex that holds the closest
point — its m supporting vertices s0 < s1 < s2 (indices into the simplex, ascending) and their barycentric
weights λ — so that v = Σ λ_k W_{s_k} and the caller can keep W[s0], W[s1], W[s2] in place. They take and return
scalars only, so a call costs no reference counting. The small ones are ``inline="always"``; the two large ones,
``closest_on_triangle_any`` and ``closest_on_tetrahedron`` (which holds four triangle cases), are plain calls:
inlined, they would make numba type and LLVM optimise GJK's loop with five copies of the triangle code; as
calls, that code is compiled once, and a call costs little beside the triangle cases' own arithmetic
(bench/compile_times.py measures each kernel's compile time, bench/test_bench_narrowphase.py the GJK batches).

The kernels are compiled with numba's ``error_model="numpy"``: every division here has a denominator tested
non-zero first (a length or area tested > 0, a signed volume tested non-zero by the flatness test), so the
Python error model's zero test before each division, and the exception path it keeps alive, never fires.
"""
from __future__ import annotations

import math

import numpy as np

from .._config import njit

__all__ = ["closest_on_segment", "closest_on_triangle", "closest_on_triangle_any", "closest_on_tetrahedron",
           "pick4", "refine_on_edge", "refine_on_face", "refine_on_simplex",
           "closest_on_simplex"]


@njit(inline="always", error_model="numpy")
def closest_on_segment(ax, ay, az, bx, by, bz):
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


@njit(inline="always", error_model="numpy")
def closest_on_triangle(ax, ay, az, bx, by, bz, cx, cy, cz):
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


@njit(inline="always", error_model="numpy")
def _pick3(s, a, b, c):
    """Component ``s`` (0, 1, 2) of (a, b, c)."""
    if s == 0:
        return a
    if s == 1:
        return b
    return c


@njit(inline="always", error_model="numpy")
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


@njit(error_model="numpy")
def closest_on_triangle_any(ax, ay, az, bx, by, bz, cx, cy, cz):
    """Closest point of triangle (a, b, c) to the origin, degenerate triangles included.

    Returns ``(m, s0, s1, s2, l0, l1, l2)`` as ``closest_on_triangle`` (never -1: a zero-area triangle falls back
    on the best of its three edges).
    """
    m, s0, s1, s2, l0, l1, l2 = closest_on_triangle(ax, ay, az, bx, by, bz, cx, cy, cz)
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
            k, t0, t1, w0, w1 = closest_on_segment(ax, ay, az, bx, by, bz)
        elif e == 1:
            i0, i1 = 1, 2
            k, t0, t1, w0, w1 = closest_on_segment(bx, by, bz, cx, cy, cz)
        else:
            i0, i1 = 0, 2
            k, t0, t1, w0, w1 = closest_on_segment(ax, ay, az, cx, cy, cz)
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


@njit(inline="always", error_model="numpy")
def _face_sides(px, py, pz, qx, qy, qz, rx, ry, rz, lx, ly, lz):
    """Signed volumes (times 6) of the origin and of vertex l against the plane of face (p, q, r):
    ``(-(p · n), (l − p) · n)`` with n = (q − p) × (r − p) (Ericson 5.1.6, PointOutsideOfPlane)."""
    e1x, e1y, e1z = qx - px, qy - py, qz - pz
    e2x, e2y, e2z = rx - px, ry - py, rz - pz
    nx = e1y * e2z - e1z * e2y
    ny = e1z * e2x - e1x * e2z
    nz = e1x * e2y - e1y * e2x
    return -(px * nx + py * ny + pz * nz), (lx - px) * nx + (ly - py) * ny + (lz - pz) * nz


@njit(inline="always", error_model="numpy")
def _opposite_signs(u, v):
    """u and v are non-zero with opposite signs. (Not ``u * v < 0``: the product of two signed volumes is of degree
    6 in the coordinates and underflows to 0 for coordinates near 2^-170, long before either volume does.)"""
    return (u < 0.0 and v > 0.0) or (u > 0.0 and v < 0.0)


@njit(inline="always", error_model="numpy")
def pick4(s, a, b, c, d):
    """Component ``s`` (0, 1, 2, 3) of (a, b, c, d)."""
    if s == 0:
        return a
    if s == 1:
        return b
    if s == 2:
        return c
    return d


@njit(error_model="numpy")
def closest_on_tetrahedron(ax, ay, az, bx, by, bz, cx, cy, cz, dx, dy, dz):
    """Ericson 5.1.6 ClosestPtPointTetrahedron with p = origin: the origin is outside face (i, j, k) when it lies
    on the other side of that face's plane from the fourth vertex l; the closest point is on the closest of those
    faces, or the origin itself when it is outside none (inside or on the tetrahedron). A flat tetrahedron
    (|det| <= 1e-12 × its size³) counts as outside every face. The faces are tried in the order (a, b, c),
    (a, b, d), (a, c, d), (b, c, d); in a well-shaped tetrahedron (|det| > 1e-3 × its size³) a face whose closest
    point is inside it (m = 3) ends the search: it is the origin's projection on a plane with the whole
    tetrahedron on its far side, so no later face is closer. (In a thin one, round-off in the face tests can make
    that point not the closest: there every face the origin is outside of is solved.)

    Returns ``(m, s0, s1, s2, l0, l1, l2, l3)``: m = 4 with the four barycentric weights of the origin (signed
    volumes) when it is inside, else the closest face's m <= 3 supporting vertices (0 = a … 3 = d, ascending)
    and weights l0, l1, l2 (l3 = 0).
    """
    abx, aby, abz = bx - ax, by - ay, bz - az
    acx, acy, acz = cx - ax, cy - ay, cz - az
    adx, ady, adz = dx - ax, dy - ay, dz - az
    det = abx * (acy * adz - acz * ady) + aby * (acz * adx - acx * adz) + abz * (acx * ady - acy * adx)
    scale = max(abx * abx + aby * aby + abz * abz, acx * acx + acy * acy + acz * acz,
                adx * adx + ady * ady + adz * adz)
    flat = abs(det) <= 1e-12 * scale * math.sqrt(scale)
    solid = abs(det) > 1e-3 * scale * math.sqrt(scale)  # well-shaped: its face tests are well conditioned
    # signed volumes (times 6) of the origin and of the fourth vertex l against each face (i, j, k): the origin is
    # outside face (i, j, k) when the two have opposite signs
    so0, sl0 = _face_sides(ax, ay, az, bx, by, bz, cx, cy, cz, dx, dy, dz)
    so1, sl1 = _face_sides(ax, ay, az, bx, by, bz, dx, dy, dz, cx, cy, cz)
    so2, sl2 = _face_sides(ax, ay, az, cx, cy, cz, dx, dy, dz, bx, by, bz)
    so3, sl3 = _face_sides(bx, by, bz, cx, cy, cz, dx, dy, dz, ax, ay, az)
    out0 = flat or _opposite_signs(so0, sl0)
    out1 = flat or _opposite_signs(so1, sl1)
    out2 = flat or _opposite_signs(so2, sl2)
    out3 = flat or _opposite_signs(so3, sl3)
    if not (out0 or out1 or out2 or out3):
        # the weight of vertex l is the origin's volume over l's against the face opposite l
        return 4, 0, 1, 2, so3 / sl3, so2 / sl2, so1 / sl1, so0 / sl0
    best_d = np.inf
    m = -1
    s0 = 0
    s1 = 0
    s2 = 0
    l0 = 0.0
    l1 = 0.0
    l2 = 0.0
    for f in range(4):
        # face (i, j, k) opposite vertex l, i < j < k
        if not (out0 if f == 0 else (out1 if f == 1 else (out2 if f == 2 else out3))):
            continue
        i = 1 if f == 3 else 0
        j = 1 if f <= 1 else 2
        k = 2 if f == 0 else 3
        px, py, pz = pick4(i, ax, bx, cx, dx), pick4(i, ay, by, cy, dy), pick4(i, az, bz, cz, dz)
        qx, qy, qz = pick4(j, ax, bx, cx, dx), pick4(j, ay, by, cy, dy), pick4(j, az, bz, cz, dz)
        rx, ry, rz = pick4(k, ax, bx, cx, dx), pick4(k, ay, by, cy, dy), pick4(k, az, bz, cz, dz)
        fm, t0, t1, t2, w0, w1, w2 = closest_on_triangle_any(px, py, pz, qx, qy, qz, rx, ry, rz)
        d = _triangle_distance2(fm, t0, t1, t2, w0, w1, w2, px, py, pz, qx, qy, qz, rx, ry, rz)
        if d < best_d:
            # face vertex 0 / 1 / 2 -> simplex vertex i / j / k (ascending stays ascending)
            best_d = d
            m = fm
            s0, s1, s2 = _pick3(t0, i, j, k), _pick3(t1, i, j, k), _pick3(t2, i, j, k)
            l0, l1, l2 = w0, w1, w2
        if fm == 3 and solid:
            # an inner point of a face the origin is outside of is the closest point of the whole tetrahedron
            # (which lies on the other side of that face's plane): the faces after it cannot be closer
            break
    return m, s0, s1, s2, l0, l1, l2, 0.0


# One step of iterative refinement (Higham, *Accuracy and Stability of Numerical Algorithms*, 12.1) of the weights
# of the closest point x = Σ λ_k p_k on the affine hull of the supporting vertices p_0, p_1 (, p_2). There x is
# orthogonal to the edges e_j = p_j − p_0: the residuals r_j = x·e_j and the Gram matrix G_jk = e_j·e_k give the
# correction G δ = −r of (λ_1, λ_2), λ_0 taking −Σ δ. The closed forms above (Ericson's ratios of products of dot
# products, degree 4 in the coordinates) leave errors of 10–100 u in λ; near touching (|x| << size) that error
# times the size tilts x by λ_err · size / |x|, which misleads the support search and the closest points'
# direction. The residuals are of degree 2, so one step brings λ to a few u. A weight pushed below 0 (the origin
# on the border of its Voronoi region, to round-off) keeps the closed form's value.
@njit(inline="always", error_model="numpy")
def refine_on_edge(l0, l1, px, py, pz, qx, qy, qz):
    """Refined weights (l0, l1) of the closest point of the line through p, q to the origin."""
    ex, ey, ez = qx - px, qy - py, qz - pz
    ee = ex * ex + ey * ey + ez * ez
    if not ee > 0.0:
        return l0, l1
    xx, xy, xz = l0 * px + l1 * qx, l0 * py + l1 * qy, l0 * pz + l1 * qz
    d = (xx * ex + xy * ey + xz * ez) / ee
    if l0 + d >= 0.0 and l1 - d >= 0.0:
        return l0 + d, l1 - d
    return l0, l1


@njit(inline="always", error_model="numpy")
def refine_on_face(l0, l1, l2, px, py, pz, qx, qy, qz, rx, ry, rz):
    """Refined weights (l0, l1, l2) of the closest point of the plane through p, q, r to the origin."""
    e1x, e1y, e1z = qx - px, qy - py, qz - pz
    e2x, e2y, e2z = rx - px, ry - py, rz - pz
    xx = l0 * px + l1 * qx + l2 * rx
    xy = l0 * py + l1 * qy + l2 * ry
    xz = l0 * pz + l1 * qz + l2 * rz
    r1 = xx * e1x + xy * e1y + xz * e1z
    r2 = xx * e2x + xy * e2y + xz * e2z
    g11 = e1x * e1x + e1y * e1y + e1z * e1z
    g12 = e1x * e2x + e1y * e2y + e1z * e2z
    g22 = e2x * e2x + e2y * e2y + e2z * e2z
    nx, ny, nz = e1y * e2z - e1z * e2y, e1z * e2x - e1x * e2z, e1x * e2y - e1y * e2x
    det = nx * nx + ny * ny + nz * nz  # = g11 g22 − g12², without its cancellation
    if not det > 0.0:
        return l0, l1, l2
    d1 = (g12 * r2 - g22 * r1) / det
    d2 = (g12 * r1 - g11 * r2) / det
    m0, m1, m2 = l0 - d1 - d2, l1 + d1, l2 + d2
    if m0 >= 0.0 and m1 >= 0.0 and m2 >= 0.0:
        return m0, m1, m2
    return l0, l1, l2


@njit(error_model="numpy")
def refine_on_simplex(m, s0, s1, s2, l0, l1, l2, ax, ay, az, bx, by, bz, cx, cy, cz, dx, dy, dz):
    """The weights (l0, l1, l2) of ``closest_on_simplex``'s answer (m supporting vertices s0 < s1 < s2 among a, b,
    c, d), refined by ``refine_on_edge`` (m = 2) or ``refine_on_face`` (m = 3); unchanged for m = 1 or 4."""
    if m == 2 or m == 3:
        px, py, pz = pick4(s0, ax, bx, cx, dx), pick4(s0, ay, by, cy, dy), pick4(s0, az, bz, cz, dz)
        qx, qy, qz = pick4(s1, ax, bx, cx, dx), pick4(s1, ay, by, cy, dy), pick4(s1, az, bz, cz, dz)
        if m == 2:
            l0, l1 = refine_on_edge(l0, l1, px, py, pz, qx, qy, qz)
        else:
            rx, ry, rz = pick4(s2, ax, bx, cx, dx), pick4(s2, ay, by, cy, dy), pick4(s2, az, bz, cz, dz)
            l0, l1, l2 = refine_on_face(l0, l1, l2, px, py, pz, qx, qy, qz, rx, ry, rz)
    return l0, l1, l2


@njit(inline="always", error_model="numpy")
def closest_on_simplex(n, ax, ay, az, bx, by, bz, cx, cy, cz, dx, dy, dz):
    """The closest point to the origin of the simplex of the first n (2, 3 or 4) of the vertices a, b, c, d (the
    others are ignored): ``(m, s0, s1, s2, l0, l1, l2, l3)`` as ``closest_on_tetrahedron`` (m = 4: the origin is
    inside the tetrahedron). ``refine_on_simplex`` refines the weights of an edge or face point."""
    if n == 2:
        m, s0, s1, l0, l1 = closest_on_segment(ax, ay, az, bx, by, bz)
        return m, s0, s1, 0, l0, l1, 0.0, 0.0
    if n == 3:
        m, s0, s1, s2, l0, l1, l2 = closest_on_triangle_any(ax, ay, az, bx, by, bz, cx, cy, cz)
        return m, s0, s1, s2, l0, l1, l2, 0.0
    return closest_on_tetrahedron(ax, ay, az, bx, by, bz, cx, cy, cz, dx, dy, dz)
