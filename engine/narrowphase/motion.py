"""The motion of a rigid body with constant linear and angular velocity (what time of impact advances): its vertices
at time t, x(t) = c + v t + R(ω t)(x0 − c), with R(ω t) the rotation by the angle |ω| t about ω / |ω|
(Rodrigues' formula)."""
from __future__ import annotations

import math

from .._config import njit

__all__ = ["pose_at"]


@njit
def pose_at(p0, center, v, w, t, out):
    """The vertices ``p0`` (n, 3) float64 of a body at t = 0, moved to time t into ``out`` (n, 3): x(t) = c + v t
    + R(ω t)(x0 − c) for the centre c (3,), linear velocity v (3,) and angular velocity ω (3,), rad per unit time;
    R by Rodrigues' formula."""
    wn = math.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
    theta = wn * t
    if wn > 0.0:
        kx, ky, kz = w[0] / wn, w[1] / wn, w[2] / wn
    else:
        kx, ky, kz = 0.0, 0.0, 1.0
    cs = math.cos(theta)
    sn = math.sin(theta)
    for i in range(p0.shape[0]):
        x = p0[i, 0] - center[0]
        y = p0[i, 1] - center[1]
        z = p0[i, 2] - center[2]
        kdx = kx * x + ky * y + kz * z
        cx = ky * z - kz * y
        cy = kz * x - kx * z
        cz = kx * y - ky * x
        out[i, 0] = center[0] + v[0] * t + x * cs + cx * sn + kx * kdx * (1.0 - cs)
        out[i, 1] = center[1] + v[1] * t + y * cs + cy * sn + ky * kdx * (1.0 - cs)
        out[i, 2] = center[2] + v[2] * t + z * cs + cz * sn + kz * kdx * (1.0 - cs)
