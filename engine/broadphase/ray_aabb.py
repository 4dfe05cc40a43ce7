"""The interval of a ray inside an axis-aligned box: the slab test that every ray traversal of a broad phase runs
on its nodes and cells.

Ericson, *Real-Time Collision Detection* 5.3.3 (intersecting a ray against a box): the ray o + t·d meets the box
[lo, hi] on the intersection, over the three axes, of the intervals where it lies between the two planes of each
slab. Each slab is widened by a few ulps of its bounds (``SLAB_SLACK``: never stricter than the exact kernels
behind it). An axis the ray runs parallel to (d_k = 0) is handled apart — the ray is inside that slab for every t or for
none — so no 0·∞ ever makes a NaN. The box is closed: a ray grazing a face or an edge meets it.
"""
from __future__ import annotations

import numpy as np

from engine._config import njit

__all__ = ["ray_aabb_interval", "ray_row_interval", "inverse_direction", "SLAB_SLACK"]


@njit(inline="always")
def inverse_direction(d):
    """(1/d_x, 1/d_y, 1/d_z), ±inf on an axis where d is 0 (``ray_aabb_interval`` tests those axes apart)."""
    ix = 1.0 / d[0] if d[0] != 0.0 else np.inf
    iy = 1.0 / d[1] if d[1] != 0.0 else np.inf
    iz = 1.0 / d[2] if d[2] != 0.0 else np.inf
    return ix, iy, iz


#: the slab's widening, in units of abs(lo) + abs(hi): a body's exact ray kernel works on o − c (c its centre), whose
#: rounding (half an ulp of the larger of abs(o) and abs(c)) can put an origin a hair outside the box inside the body;
#: the box test must not be stricter than the kernel it guards (2 ε covers o − c and the box's own c ± r)
SLAB_SLACK = 4.0 * np.finfo(np.float64).eps


@njit(inline="always")
def _slab_row(o, d, inv, lo, hi, t0, t1):
    """Clip [t0, t1] to the slab lo <= o + t·d <= hi of one axis, widened by ``SLAB_SLACK`` (|lo| + |hi|) (an empty
    result has t0 > t1): the plane the ray meets first by the sign of d, an axis it runs parallel to apart."""
    slack = SLAB_SLACK * (abs(lo) + abs(hi))
    lo, hi = lo - slack, hi + slack
    if d == 0.0:
        if o < lo or o > hi:
            return 1.0, 0.0
        return t0, t1
    if d > 0.0:
        return max(t0, (lo - o) * inv), min(t1, (hi - o) * inv)
    return max(t0, (hi - o) * inv), min(t1, (lo - o) * inv)


@njit(inline="always")
def ray_aabb_interval(o, d, inv, lo, hi, t_max):
    """The part [t_enter, t_exit] of [0, t_max] where the ray o + t·d lies in the closed box [lo, hi]
    (``inv`` = ``inverse_direction(d)``; o, d, inv 3-tuples, lo, hi (3,) arrays); empty when t_enter > t_exit."""
    t0, t1 = _slab_row(o[0], d[0], inv[0], lo[0], hi[0], 0.0, t_max)
    t0, t1 = _slab_row(o[1], d[1], inv[1], lo[1], hi[1], t0, t1)
    t0, t1 = _slab_row(o[2], d[2], inv[2], lo[2], hi[2], t0, t1)
    return t0, t1


@njit(inline="always")
def ray_row_interval(o, d, inv, lo, hi, i, t_max):
    """``ray_aabb_interval`` for the box in row i of lo, hi ((n, 3) arrays), read element by element (a tree walk
    tests two rows per node)."""
    t0, t1 = _slab_row(o[0], d[0], inv[0], lo[i, 0], hi[i, 0], 0.0, t_max)
    t0, t1 = _slab_row(o[1], d[1], inv[1], lo[i, 1], hi[i, 1], t0, t1)
    t0, t1 = _slab_row(o[2], d[2], inv[2], lo[i, 2], hi[i, 2], t0, t1)
    return t0, t1
