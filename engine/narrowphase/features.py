"""The supporting feature of a convex shape along a contact normal (the chapter's "vertex, côtés, faces").

The vertices of a shape within a tolerance of its support plane (max x·n for A, min x·n for B), projected on the
plane orthogonal to n, reduce to one of three shapes: one point (a *vertex*), a segment (an *edge*: its two
extreme points along the set's principal direction, or two points), or a convex polygon (a *face*: the 2-D convex
hull, the engine's monotone chain from engine.bounding.hull, counter-clockwise).

Kernels: ``plane_basis`` (the contact plane's 2-D frame), ``support_set`` (the projected support set) and
``feature_polygon`` (its reduction). Points are (n, 2) float64 in the plane's coordinates.
"""
from __future__ import annotations

import math

import numpy as np

from .._config import njit
from ..bounding.hull import HULL_EPS, monotone_chain

__all__ = ["plane_basis", "support_set", "feature_polygon", "adjacent_face"]


@njit
def plane_basis(nx, ny, nz, basis):
    """Two unit vectors u = basis[0], v = basis[1] ((2, 3) float64) with (u, v, n) orthonormal: u = n × e_k, e_k the
    coordinate axis least aligned with n, v = n × u."""
    ax, ay, az = abs(nx), abs(ny), abs(nz)
    if ax <= ay and ax <= az:  # e_x: n × e_x = (0, nz, -ny)
        ux, uy, uz = 0.0, nz, -ny
    elif ay <= az:  # e_y: n × e_y = (-nz, 0, nx)
        ux, uy, uz = -nz, 0.0, nx
    else:  # e_z: n × e_z = (ny, -nx, 0)
        ux, uy, uz = ny, -nx, 0.0
    length = math.sqrt(ux * ux + uy * uy + uz * uz)
    ux, uy, uz = ux / length, uy / length, uz / length
    basis[0, 0], basis[0, 1], basis[0, 2] = ux, uy, uz
    basis[1, 0] = ny * uz - nz * uy
    basis[1, 1] = nz * ux - nx * uz
    basis[1, 2] = nx * uy - ny * ux


@njit
def support_set(points, nx, ny, nz, level, tol, side, basis, S):
    """The rows x of ``points`` (n, 3) within ``tol`` of the support plane x·n = ``level`` — x·n >= level − tol for
    ``side`` = +1 (A's top), x·n <= level + tol for ``side`` = −1 (B's bottom) — projected on ``basis`` (2, 3) into
    ``S`` (>= n, 2). Returns their count."""
    m = 0
    for i in range(points.shape[0]):
        h = points[i, 0] * nx + points[i, 1] * ny + points[i, 2] * nz
        if (h >= level - tol) if side > 0 else (h <= level + tol):
            S[m, 0] = points[i, 0] * basis[0, 0] + points[i, 1] * basis[0, 1] + points[i, 2] * basis[0, 2]
            S[m, 1] = points[i, 0] * basis[1, 0] + points[i, 1] * basis[1, 1] + points[i, 2] * basis[1, 2]
            m += 1
    return m


@njit
def _principal_extremes(P, m):
    """The extreme points of P[:m] along its principal direction (the covariance's main axis of the centred set,
    ½ atan2(2 sxy, sxx − syy)) and the largest distance across it: (i_min, i_max, across)."""
    mx = 0.0
    my = 0.0
    for i in range(m):
        mx += P[i, 0]
        my += P[i, 1]
    mx /= m
    my /= m
    sxx = 0.0
    sxy = 0.0
    syy = 0.0
    for i in range(m):
        dx = P[i, 0] - mx
        dy = P[i, 1] - my
        sxx += dx * dx
        sxy += dx * dy
        syy += dy * dy
    theta = 0.5 * math.atan2(2.0 * sxy, sxx - syy)
    ux = math.cos(theta)
    uy = math.sin(theta)
    i_min = 0
    i_max = 0
    lo = np.inf
    hi = -np.inf
    across = 0.0
    for i in range(m):
        dx = P[i, 0] - mx
        dy = P[i, 1] - my
        t = dx * ux + dy * uy
        if t < lo:
            lo = t
            i_min = i
        if t > hi:
            hi = t
            i_max = i
        across = max(across, abs(-dx * uy + dy * ux))
    return i_min, i_max, across


@njit
def _collinear_hull(pts, verts):
    """Whether the 2-D hull ``verts`` of ``pts`` (m, 2) is collinear to round-off: fewer than 3 vertices, or twice
    its area below HULL_EPS × extent × (|x| + extent), the collinearity test of engine.bounding.hull."""
    k = verts.shape[0]
    if k < 3:
        return True
    big = 0.0
    for i in range(pts.shape[0]):
        big = max(big, abs(pts[i, 0]), abs(pts[i, 1]))
    area2 = 0.0
    vx = pts[verts[0], 0]
    vy = pts[verts[0], 1]
    for i in range(k):
        a = verts[i]
        b = verts[(i + 1) % k]
        area2 += (pts[a, 0] - vx) * (pts[b, 1] - vy) - (pts[b, 0] - vx) * (pts[a, 1] - vy)
    xmin = np.inf
    xmax = -np.inf
    ymin = np.inf
    ymax = -np.inf
    for i in range(pts.shape[0]):
        xmin = min(xmin, pts[i, 0])
        xmax = max(xmax, pts[i, 0])
        ymin = min(ymin, pts[i, 1])
        ymax = max(ymax, pts[i, 1])
    extent = max(xmax - xmin, ymax - ymin)
    return area2 <= HULL_EPS * extent * (big + extent)


@njit
def feature_polygon(P, m, tol, F):
    """The support set P[:m] ((>= m, 2) float64, projected on the contact plane) reduced to its shape, written into
    F (>= m, 2): returns 1 (a vertex), 2 (an edge: its two extreme points along the set's principal direction) or
    k >= 3 (a convex polygon, counter-clockwise: the engine's monotone chain)."""
    x0 = P[0, 0]
    y0 = P[0, 1]
    spread = 0.0
    for i in range(m):
        spread = max(spread, abs(P[i, 0] - x0), abs(P[i, 1] - y0))
    if spread <= tol:
        F[0, 0] = x0
        F[0, 1] = y0
        return 1
    i_min, i_max, across = _principal_extremes(P, m)
    if m > 2 and across > tol:
        # Andrew's monotone chain on the points in lexicographic (x, then y) order
        pts = P[:m]
        by_y = np.argsort(pts[:, 1].copy(), kind="mergesort")
        order = by_y[np.argsort(pts[by_y, 0].copy(), kind="mergesort")]
        verts = monotone_chain(pts, order)
        if not _collinear_hull(pts, verts):
            for i in range(verts.shape[0]):
                F[i, 0] = pts[verts[i], 0]
                F[i, 1] = pts[verts[i], 1]
            return verts.shape[0]
    # an edge (two points, or collinear to round-off)
    F[0, 0], F[0, 1] = P[i_min, 0], P[i_min, 1]
    F[1, 0], F[1, 1] = P[i_max, 0], P[i_max, 1]
    return 2


@njit
def adjacent_face(points, nx, ny, nz, min_cos, tol, verts):
    """The face of hull(``points``) (n, 3) through its support vertex v along the unit direction (nx, ny, nz)
    whose outward unit normal m is nearest to it, if m·n >= ``min_cos``: the plane through v and two more points
    p_i, p_j (m ∝ (p_i − v) × (p_j − v), turned towards n) with every point at most ``tol`` above it, the largest
    m·n first (the first found among equals). Its vertices (the points within ``tol`` of the plane) go into
    ``verts`` (>= n,) int64. Returns (count, cos, mx, my, mz, level): count 0 when no such face exists (fewer
    than 3 points off a line through v, or every face farther than ``min_cos``); level = max over the face's
    vertices of x·m.

    A face through v at angle φ from n has its vertices x within |x − v| |m − n| = |x − v| √(2 (1 − cos φ)) of
    v's support plane, so only those points are tried as p_i, p_j when ``min_cos`` > 0 (|x − v| at most the
    diagonal of the points' bounding box)."""
    n = points.shape[0]
    top = -np.inf
    s = 0
    diagonal2 = 0.0
    for i in range(n):
        h = points[i, 0] * nx + points[i, 1] * ny + points[i, 2] * nz
        if h > top:
            top, s = h, i
    for c in range(3):
        lo, hi = np.inf, -np.inf
        for i in range(n):
            lo, hi = min(lo, points[i, c]), max(hi, points[i, c])
        diagonal2 += (hi - lo) ** 2
    diagonal = math.sqrt(diagonal2)
    reach = diagonal * math.sqrt(2.0 * (1.0 - min_cos)) + tol if min_cos > 0.0 else np.inf
    vx, vy, vz = points[s, 0], points[s, 1], points[s, 2]
    best, mx, my, mz = min_cos, 0.0, 0.0, 0.0
    found = False
    for i in range(n):
        ax, ay, az = points[i, 0] - vx, points[i, 1] - vy, points[i, 2] - vz
        if i == s or -(ax * nx + ay * ny + az * nz) > reach:
            continue
        for j in range(i + 1, n):
            bx, by, bz = points[j, 0] - vx, points[j, 1] - vy, points[j, 2] - vz
            if j == s or -(bx * nx + by * ny + bz * nz) > reach:
                continue
            cx, cy, cz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
            length = math.sqrt(cx * cx + cy * cy + cz * cz)
            # v, p_i, p_j on one line to 1e-6 rad: no plane (another triple of the same face gives it)
            if not length > 1e-6 * math.sqrt((ax * ax + ay * ay + az * az) * (bx * bx + by * by + bz * bz)):
                continue
            sign = 1.0 if cx * nx + cy * ny + cz * nz >= 0.0 else -1.0
            cx, cy, cz = sign * cx / length, sign * cy / length, sign * cz / length
            c = cx * nx + cy * ny + cz * nz
            if c < best or (found and c == best) or not _supports(points, vx, vy, vz, cx, cy, cz, tol):
                continue
            best, mx, my, mz, found = c, cx, cy, cz, True
    if not found:
        return 0, best, 0.0, 0.0, 0.0, top
    level = vx * mx + vy * my + vz * mz
    count = 0
    for k in range(n):
        h = points[k, 0] * mx + points[k, 1] * my + points[k, 2] * mz
        if abs(h - level) <= tol:
            verts[count] = k
            count += 1
    top_m = -np.inf
    for k in range(count):
        top_m = max(top_m, points[verts[k], 0] * mx + points[verts[k], 1] * my + points[verts[k], 2] * mz)
    return count, best, mx, my, mz, top_m


@njit
def _supports(points, vx, vy, vz, mx, my, mz, tol):
    """Whether every point lies at most ``tol`` above the plane through v with unit normal m."""
    for k in range(points.shape[0]):
        if (points[k, 0] - vx) * mx + (points[k, 1] - vy) * my + (points[k, 2] - vz) * mz > tol:
            return False
    return True
