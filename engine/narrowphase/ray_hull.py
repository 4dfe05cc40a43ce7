"""Ray against a solid convex polyhedron given by its face planes: clipping the ray by half-spaces (Ericson,
*Real-Time Collision Detection*, 5.3.8 "Intersecting ray or segment against convex polyhedron").

In the body's frame (world = c + R @ local) the ray is o' = Rᵀ(o − c), d' = Rᵀ d, and the solid is the
intersection of the half-spaces n_i·x <= e_i. Along the ray plane i gives s_i(t) = (n_i·o' − e_i) + t n_i·d':
with n_i·d' < 0 the ray enters its half-space at t = −s_i(0) / n_i·d', with n_i·d' > 0 it leaves there, with
n_i·d' == 0 it is inside for every t iff s_i(0) <= 0 (no 0/0). The ray is in the solid from the last entering t
(at least 0) to the first leaving t (at most tmax); the normal is the last entered plane's, rotated to the world.
Ties between planes entered at the same t (through an edge or a vertex) go to the lowest row.

``hull_planes`` turns a point set into such planes: the faces of ``engine.convex_hull`` (triangles), with the
triangles of one flat face merged into one row.

Ray conventions as in ``ray_sphere``.
"""
from __future__ import annotations

import math

import numpy as np

from .._config import njit
from ..bounding.hull import convex_hull

__all__ = ["ray_hull", "hull_planes", "COPLANAR_EPS"]

#: two hull triangles lie on one plane when their vertices are within COPLANAR_EPS times the diagonal of the
#: points' bounding box of each other's plane (and their normals point the same way)
COPLANAR_EPS = 1e-9


@njit
def ray_hull(o, d, tmax, c, R, planes, n_planes):
    """First hit of the ray o + t d, 0 <= t <= tmax, with the solid convex polyhedron ``planes`` placed at (c, R).

    Parameters
    ----------
    o, d : tuple of 3 float
        Origin and unit direction of the ray.
    tmax : float
        Largest t looked at, >= 0 (may be inf).
    c : tuple of 3 float
        Position of the body's origin in the world.
    R : numpy.ndarray, shape (3, 3), float64
        Rotation whose columns are the body's axes in the world (world = c + R @ local).
    planes : numpy.ndarray, shape (F, 4), float64
        Rows (nx, ny, nz, e) in the body's frame, n unit and outward: the solid is n·x <= e for every row used.
    n_planes : int
        The rows used, ``planes[:n_planes]``.

    Returns
    -------
    tuple of 4 float
        ``(t, nx, ny, nz)``: the distance to the hit and the outward unit normal of the entered face; (0, −d)
        for an origin in the closed solid; (inf, nan, nan, nan) for a miss.
    """
    mx, my, mz = o[0] - c[0], o[1] - c[1], o[2] - c[2]
    ox = mx * R[0, 0] + my * R[1, 0] + mz * R[2, 0]
    oy = mx * R[0, 1] + my * R[1, 1] + mz * R[2, 1]
    oz = mx * R[0, 2] + my * R[1, 2] + mz * R[2, 2]
    dx = d[0] * R[0, 0] + d[1] * R[1, 0] + d[2] * R[2, 0]
    dy = d[0] * R[0, 1] + d[1] * R[1, 1] + d[2] * R[2, 1]
    dz = d[0] * R[0, 2] + d[1] * R[1, 2] + d[2] * R[2, 2]
    t_in, t_out, best = 0.0, tmax, -1
    for i in range(n_planes):
        height = planes[i, 0] * ox + planes[i, 1] * oy + planes[i, 2] * oz - planes[i, 3]
        rate = planes[i, 0] * dx + planes[i, 1] * dy + planes[i, 2] * dz
        if rate == 0.0:  # parallel to the plane: inside it for every t, or never
            if height > 0.0:
                return math.inf, math.nan, math.nan, math.nan
            continue
        t = -height / rate
        if rate < 0.0:
            if t > t_in:
                t_in, best = t, i
        elif t < t_out:
            t_out = t
        if t_in > t_out:
            return math.inf, math.nan, math.nan, math.nan
    if best < 0:  # no plane entered after t = 0: the origin is in the closed solid
        return 0.0, -d[0], -d[1], -d[2]
    if t_in == math.inf:
        return math.inf, math.nan, math.nan, math.nan
    nx, ny, nz = planes[best, 0], planes[best, 1], planes[best, 2]
    return (t_in, R[0, 0] * nx + R[0, 1] * ny + R[0, 2] * nz, R[1, 0] * nx + R[1, 1] * ny + R[1, 2] * nz,
            R[2, 0] * nx + R[2, 1] * ny + R[2, 2] * nz)


def hull_planes(points) -> np.ndarray:
    """The outward unit face planes of the convex hull of ``points``, one row per flat face.

    Parameters
    ----------
    points : array_like, shape (n, 3), float64
        At least 4 finite points, not all coplanar (``engine.convex_hull``'s conditions).

    Returns
    -------
    numpy.ndarray, shape (F, 4), float64
        Rows (nx, ny, nz, e): the hull is {x : n·x <= e for every row}. The hull's triangles that lie on one
        plane — every vertex of one within ``COPLANAR_EPS`` × (the diagonal of the points' bounding box) of the
        other's plane, normals in the same half-space — give one row: n the area-weighted mean of their normals,
        e the largest n·v over the hull's vertices (the supporting plane: every point is in the solid). A cube
        gives 6 rows.

    Raises
    ------
    ValueError
        As ``engine.convex_hull`` for degenerate input.
    """
    hull = convex_hull(points)
    pts = np.asarray(hull.points, dtype=np.float64)
    # grouped on the points rescaled by a power of two (exact): the same rows at every magnitude, no underflow
    unit = np.ldexp(pts, -int(np.frexp(np.abs(pts).max())[1]))
    tri = unit[hull.faces]  # (m, 3 vertices, 3)
    areas = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    tol = COPLANAR_EPS * float(np.linalg.norm(np.ptp(unit, axis=0)))
    free = np.ones(len(tri), dtype=bool)
    rows = []
    for seed in np.argsort(-areas, kind="stable"):  # the largest triangle fixes its plane best
        if not free[seed]:
            continue
        n = hull.normals[seed]
        # distances of every triangle's vertices from the seed's plane, relative to a seed vertex (no cancellation)
        gap = np.abs(np.einsum("mvk,k->mv", tri - tri[seed, 0], n)).max(axis=1)
        group = free & (gap <= tol) & (hull.normals @ n > 0.0)
        group[seed] = True
        free &= ~group
        normal = (areas[group, None] * hull.normals[group]).sum(axis=0)
        normal /= np.linalg.norm(normal)
        rows.append([*normal, float((pts[hull.vertices] @ normal).max())])  # the supporting plane
    return np.array(rows, dtype=np.float64).reshape(-1, 4)
