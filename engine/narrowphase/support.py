"""Support mappings (Ericson, *Real-Time Collision Detection*, 9.5): the vertex of a convex hull farthest along a
direction d, s(d) = argmax over the vertices x of x·d, and that of the Minkowski difference M = A − B,
s_M(d) = s_A(d) − s_B(−d). Ties go to the lowest row, so that the answers are deterministic.
"""
from __future__ import annotations

import numpy as np

from .._config import njit

__all__ = ["support_index", "support_index_rows", "support_minkowski"]


@njit(inline="always")
def support_index(points, dx, dy, dz):
    """Row of ``points`` (n, 3) float64, n >= 1, farthest along d = (dx, dy, dz)."""
    best = 0
    best_dot = points[0, 0] * dx + points[0, 1] * dy + points[0, 2] * dz
    for i in range(1, points.shape[0]):
        d = points[i, 0] * dx + points[i, 1] * dy + points[i, 2] * dz
        if d > best_dot:
            best_dot = d
            best = i
    return best


@njit
def support_index_rows(S, row, n, dx, dy, dz):
    """Column i < n of the coordinate rows ``S[row:row + 3]`` ((x, y, z) of n points, unit stride) farthest along
    d. One plain scan with the running maximum: it compiles to a branch-free max/cmov loop. (A plain ``@njit``:
    numba's IR inlining of a function with array arguments adds reference counting to its caller's loop; LLVM
    inlines this one without it.)"""
    best = 0
    hi = -np.inf
    for i in range(n):
        d = S[row, i] * dx + S[row + 1, i] * dy + S[row + 2, i] * dz
        if d > hi:
            hi = d
            best = i
    return best


@njit(inline="always")
def support_minkowski(pa, pb, dx, dy, dz):
    """The support point of M = A − B along d: ``(ia, ib, wx, wy, wz)`` with ia = s_A(d), ib = s_B(−d) (rows of
    ``pa`` (n, 3), ``pb`` (m, 3)) and w = pa[ia] − pb[ib]."""
    ia = support_index(pa, dx, dy, dz)
    ib = support_index(pb, -dx, -dy, -dz)
    return ia, ib, pa[ia, 0] - pb[ib, 0], pa[ia, 1] - pb[ib, 1], pa[ia, 2] - pb[ib, 2]
