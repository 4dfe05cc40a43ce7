"""Ray against a solid oriented box: the slab test (Ericson, *Real-Time Collision Detection*, 5.3.3
"Intersecting ray or segment against box"), in the box's frame.

In the frame of the box (centre c, axes u_k = the columns of R, half extents h_k) the ray is o'_k = (o − c)·u_k,
d'_k = d·u_k, and the box is the intersection of three slabs |x_k| <= h_k. Along axis k the ray is inside its
slab for t between (−σ h_k − o'_k)/d'_k and (σ h_k − o'_k)/d'_k, σ = sign d'_k; the ray meets the box on the
intersection of these intervals with [0, tmax], and enters it through the face of the slab entered last, whose
outward normal is −σ u_k. A direction with d'_k == 0 never crosses that slab: the ray is in it for every t
iff |o'_k| <= h_k (a ray running along a face or an edge hits), so no 0/0 arises. Ties between slabs entered at
the same t (a ray entering through an edge or a corner) go to the lowest axis.

Ray conventions as in ``ray_sphere``: the answer is ``(t, nx, ny, nz)``; (0, −d) from inside or on the surface;
(inf, nan, nan, nan) for a miss.
"""
from __future__ import annotations

import math

from .._config import njit

__all__ = ["ray_box"]


@njit
def ray_box(o, d, tmax, c, R, h):
    """First hit of the ray o + t d, 0 <= t <= tmax, with the solid oriented box (c, R, h).

    Parameters
    ----------
    o, d : tuple of 3 float
        Origin and unit direction of the ray.
    tmax : float
        Largest t looked at, >= 0 (may be inf).
    c : tuple of 3 float
        Centre of the box.
    R : numpy.ndarray, shape (3, 3), float64
        Rotation whose columns are the box's axes in the world (world = c + R @ local).
    h : tuple of 3 float
        Half extents, >= 0.

    Returns
    -------
    tuple of 4 float
        ``(t, nx, ny, nz)``: the distance to the hit and the outward unit normal of the entered face; (0, −d)
        for an origin in the closed box; (inf, nan, nan, nan) for a miss.
    """
    mx, my, mz = o[0] - c[0], o[1] - c[1], o[2] - c[2]
    t_in, t_out = 0.0, tmax
    axis, side = -1, 0.0
    for k in range(3):
        ok = mx * R[0, k] + my * R[1, k] + mz * R[2, k]
        dk = d[0] * R[0, k] + d[1] * R[1, k] + d[2] * R[2, k]
        if dk == 0.0:  # parallel to the slab: inside it for every t, or never
            if abs(ok) > h[k]:
                return math.inf, math.nan, math.nan, math.nan
            continue
        s = 1.0 if dk > 0.0 else -1.0
        near = (-s * h[k] - ok) / dk  # divisions, not a reciprocal: 0 * inf cannot appear
        far = (s * h[k] - ok) / dk
        if near > t_in:
            t_in, axis, side = near, k, -s
        t_out = min(t_out, far)
        if t_in > t_out:
            return math.inf, math.nan, math.nan, math.nan
    if axis < 0:  # no slab entered after t = 0: the origin is in the closed box
        return 0.0, -d[0], -d[1], -d[2]
    if t_in == math.inf:  # entering beyond the float range
        return math.inf, math.nan, math.nan, math.nan
    return t_in, side * R[0, axis], side * R[1, axis], side * R[2, axis]
