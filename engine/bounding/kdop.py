"""Discrete oriented polytopes, k-DOPs (chapter slide "Volumes englobants": the eight-direction DOP, 8-DOP).
Ericson, *Real-Time Collision Detection*, section 4.6.

A k-DOP is the intersection of k/2 slabs ``lo[i] <= n_i . x <= hi[i]`` along fixed directions n_i shared by
every DOP of the same k, so a DOP is just two arrays ``lo``, ``hi`` of shape (k/2,):

- 8-DOP (2-D): the axes x, y and the diagonals (1, 1), (1, -1);
- 14-DOP (3-D): the axes and the 4 cube diagonals (±1, ±1, 1);
- 18-DOP (3-D): the axes and the 6 face diagonals (1, ±1, 0), (1, 0, ±1), (0, 1, ±1);
- 26-DOP (3-D): the axes, the 4 cube diagonals and the 6 face diagonals.

As in Ericson 4.6.1 the directions are left unnormalised (integer components): the slabs are exact, the
projections cheaper. The first d slabs are the axes, so ``(lo[:d], hi[:d])`` is the object's AABB.
"""
from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .._config import njit
from .._validate import as_float_array
from .aabb import as_points, as_rigid_transform, check_ordered, inside_slabs, overlap_slabs_kernel

__all__ = [
    "KDOP_SIZES",
    "kdop_directions",
    "fit_kdop",
    "fit_kdops",
    "overlap_kdop_kdop",
    "overlap_kdops",
    "merge_kdop",
    "kdop_contains",
    "update_kdop",
    "transform_kdop",
]

_AXES_3D = [(1, 0, 0), (0, 1, 0), (0, 0, 1)]
_CORNERS_3D = [(1, 1, 1), (1, 1, -1), (1, -1, 1), (-1, 1, 1)]
_EDGES_3D = [(1, 1, 0), (1, -1, 0), (1, 0, 1), (1, 0, -1), (0, 1, 1), (0, 1, -1)]
_DIRECTIONS = {
    8: np.array([(1, 0), (0, 1), (1, 1), (1, -1)], dtype=np.float64),
    14: np.array(_AXES_3D + _CORNERS_3D, dtype=np.float64),
    18: np.array(_AXES_3D + _EDGES_3D, dtype=np.float64),
    26: np.array(_AXES_3D + _CORNERS_3D + _EDGES_3D, dtype=np.float64),
}
for _dirs in _DIRECTIONS.values():
    _dirs.setflags(write=False)

#: the supported k and the dimension of each: {8: 2, 14: 3, 18: 3, 26: 3}
KDOP_SIZES = {8: 2, 14: 3, 18: 3, 26: 3}


def _check_k(k: Any) -> int:
    if isinstance(k, bool) or not isinstance(k, int | np.integer):
        raise TypeError(f"k must be an integer, one of {sorted(KDOP_SIZES)}, got {type(k).__name__}")
    if int(k) not in KDOP_SIZES:
        raise ValueError(f"k must be one of {sorted(KDOP_SIZES)} (8 in 2-D; 14, 18, 26 in 3-D), got {k!r}")
    return int(k)


def kdop_directions(k: int) -> np.ndarray:
    """The k/2 slab directions n_s shared by every k-DOP: slab s is ``lo[s] <= n_s · x <= hi[s]``.

    Parameters
    ----------
    k : int
        8 (2-D), 14, 18 or 26 (3-D).

    Returns
    -------
    numpy.ndarray, shape (k/2, d), float64
        Read-only; unnormalised integer components; the first d rows are the axes.

    Raises
    ------
    ValueError
        For a k that is not 8, 14, 18 or 26.
    TypeError
        For a k that is not an int.
    """
    return _DIRECTIONS[_check_k(k)]


def _as_kdop(lo: ArrayLike, hi: ArrayLike, k: int,
             names: tuple[str, str] = ("lo", "hi")) -> tuple[np.ndarray, np.ndarray]:
    lo_name, hi_name = names
    half = k // 2
    lo = as_float_array(lo, lo_name)
    if lo.ndim not in (1, 2) or lo.shape[-1] != half:
        raise ValueError(f"{lo_name} must have shape ({half},) or (n, {half}) for a {k}-DOP, got {lo.shape}")
    hi = as_float_array(hi, hi_name, shape=lo.shape)
    check_ordered(lo, hi, names)
    return lo, hi


# ---------------------------------------------------------------------------------------------------------
# kernels
# ---------------------------------------------------------------------------------------------------------
@njit
def _fit_kdop_kernel(points, directions, lo, hi):
    # Ericson 4.6.2: project every point on every direction, keep the min and the max
    n, d = points.shape
    for s in range(directions.shape[0]):
        lo[s] = np.inf
        hi[s] = -np.inf
    for i in range(n):
        for s in range(directions.shape[0]):
            t = 0.0
            for m in range(d):
                t += directions[s, m] * points[i, m]
            if t < lo[s]:
                lo[s] = t
            if t > hi[s]:
                hi[s] = t


@njit
def _fit_kdops_kernel(clouds, directions, lo, hi):
    for c in range(clouds.shape[0]):
        _fit_kdop_kernel(clouds[c], directions, lo[c], hi[c])


@njit
def _contains_kernel(lo, hi, directions, points, out):
    # a point is inside when its projection on every slab direction lies in the slab's interval
    n, d = points.shape
    projection = np.empty(directions.shape[0])
    for i in range(n):
        for s in range(directions.shape[0]):
            t = 0.0
            for m in range(d):
                t += directions[s, m] * points[i, m]
            projection[s] = t
        out[i] = inside_slabs(lo, hi, projection)


@njit
def _update_kdop_kernel(points, rotation, translation, directions, lo, hi):
    # refit of the moved object: project R p + t without building the moved copy (Ericson 4.6.2 on the
    # transformed points: n_s . (R p + t) = (R^T n_s) . p + n_s . t)
    half, d = directions.shape
    w = np.empty((half, d))
    shift = np.empty(half)
    for s in range(half):
        shift[s] = 0.0
        for m in range(d):
            w[s, m] = 0.0
            for j in range(d):
                w[s, m] += rotation[j, m] * directions[s, j]
            shift[s] += directions[s, m] * translation[m]
    _fit_kdop_kernel(points, w, lo, hi)
    for s in range(half):
        lo[s] += shift[s]
        hi[s] += shift[s]


@njit
def _transform_kdop_kernel(lo, hi, rotation, translation, directions, new_lo, new_hi):
    # conservative update from the DOP alone (no points): the moved object lies in the moved AABB slabs
    # (the first d slabs), so n_s . (R p + t) = w . p + n_s . t with w = R^T n_s is bounded by the support of
    # the AABB [lo[:d], hi[:d]] in direction w (Ericson 4.2.6 applied to each DOP direction)
    half, d = directions.shape
    for s in range(half):
        top = 0.0
        bottom = 0.0
        shift = 0.0
        for m in range(d):
            w = 0.0
            for j in range(d):
                w += rotation[j, m] * directions[s, j]
            top += max(w * lo[m], w * hi[m])
            bottom += min(w * lo[m], w * hi[m])
            shift += directions[s, m] * translation[m]
        new_lo[s] = bottom + shift
        new_hi[s] = top + shift


# ---------------------------------------------------------------------------------------------------------
# public functions
# ---------------------------------------------------------------------------------------------------------
def fit_kdop(points: ArrayLike, k: int) -> tuple[np.ndarray, np.ndarray]:
    """The tightest k-DOP of a point cloud: the min and max of the points' projections on each direction.

    Parameters
    ----------
    points : array_like, shape (n, d)
        The cloud, see :ref:`bounding-arguments`.
    k : int
        8 (2-D), 14, 18 or 26 (3-D).

    Returns
    -------
    lo, hi : numpy.ndarray, shape (k/2,), float64
        The slab bounds along ``kdop_directions(k)``; ``(lo[:d], hi[:d])`` is the AABB.
    """
    k = _check_k(k)
    pts = as_points(points, dims=(KDOP_SIZES[k],))
    directions = _DIRECTIONS[k]
    lo = np.empty(k // 2)
    hi = np.empty(k // 2)
    _fit_kdop_kernel(pts, directions, lo, hi)
    return lo, hi


def fit_kdops(clouds: ArrayLike, k: int) -> tuple[np.ndarray, np.ndarray]:
    """Batched :func:`fit_kdop`: one k-DOP per cloud, in one compiled call.

    Parameters
    ----------
    clouds : array_like, shape (m, n, d)
        See :ref:`bounding-arguments`.
    k : int
        8 (2-D), 14, 18 or 26 (3-D).

    Returns
    -------
    lo, hi : numpy.ndarray, shape (m, k/2), float64
    """
    k = _check_k(k)
    arr = as_float_array(clouds, "clouds", ndim=3)
    if arr.shape[1] < 1 or arr.shape[2] != KDOP_SIZES[k]:
        raise ValueError(f"clouds must have shape (m, n, {KDOP_SIZES[k]}) with n >= 1 for a {k}-DOP, "
                         f"got {arr.shape}")
    lo = np.empty((arr.shape[0], k // 2))
    hi = np.empty((arr.shape[0], k // 2))
    _fit_kdops_kernel(arr, _DIRECTIONS[k], lo, hi)
    return lo, hi


def overlap_kdops(lo_a: ArrayLike, hi_a: ArrayLike, lo_b: ArrayLike, hi_b: ArrayLike, k: int) -> np.ndarray:
    """Row-wise overlap of closed k-DOPs: whether DOP a_i meets DOP b_i on every slab, for every row i.

    One separating slab proves two DOPs disjoint (Ericson 4.6.1); overlapping on all k/2 slabs is the
    conservative answer (the DOPs may still be apart along a direction that is not a slab).

    Parameters
    ----------
    lo_a, hi_a, lo_b, hi_b : array_like, shape (n, k/2) or (k/2,)
        The slab bounds of the DOPs a_i and b_i, all of one shape, ``lo <= hi``, finite.
    k : int
        8 (2-D), 14, 18 or 26 (3-D).

    Returns
    -------
    numpy.ndarray, shape (n,), bool
        Shape (1,) for (k/2,) inputs.
    """
    k = _check_k(k)
    lo_a, hi_a = _as_kdop(lo_a, hi_a, k, ("lo_a", "hi_a"))
    lo_b, hi_b = _as_kdop(lo_b, hi_b, k, ("lo_b", "hi_b"))
    if lo_b.shape != lo_a.shape:
        raise ValueError(f"lo_b must have the shape of lo_a {lo_a.shape}, got {lo_b.shape}")
    half = k // 2
    out = np.empty(lo_a.reshape(-1, half).shape[0], dtype=np.bool_)
    # Ericson 4.6.1: two k-DOPs overlap only if their intervals overlap on all k/2 directions (as for the AABB,
    # a separating slab direction proves them disjoint; overlap on all slabs is the conservative answer)
    overlap_slabs_kernel(lo_a.reshape(-1, half), hi_a.reshape(-1, half), lo_b.reshape(-1, half),
                         hi_b.reshape(-1, half), out)
    return out


def overlap_kdop_kdop(lo_a: ArrayLike, hi_a: ArrayLike, lo_b: ArrayLike, hi_b: ArrayLike, k: int) -> bool:
    """Whether two closed k-DOPs overlap on all k/2 slab directions (as :func:`overlap_kdops`).

    Parameters
    ----------
    lo_a, hi_a, lo_b, hi_b : array_like, shape (k/2,)
        The slab bounds of DOPs a and b, ``lo <= hi``, finite; one DOP each (a batch is a ValueError: use
        :func:`overlap_kdops`).
    k : int
        8 (2-D), 14, 18 or 26 (3-D).

    Returns
    -------
    bool
    """
    k = _check_k(k)
    lo_a, hi_a = _as_kdop(lo_a, hi_a, k, ("lo_a", "hi_a"))
    if lo_a.ndim != 1:
        raise ValueError(f"lo_a must have shape ({k // 2},), got {lo_a.shape}; use overlap_kdops for batches")
    return bool(overlap_kdops(lo_a, hi_a, lo_b, hi_b, k)[0])


def merge_kdop(lo_a: ArrayLike, hi_a: ArrayLike, lo_b: ArrayLike, hi_b: ArrayLike,
               k: int) -> tuple[np.ndarray, np.ndarray]:
    """The smallest k-DOP holding both (row-wise for batches): the slab-wise min of ``lo``, max of ``hi``.

    Parameters
    ----------
    lo_a, hi_a, lo_b, hi_b : array_like, shape (k/2,) or (n, k/2)
        The slab bounds of the DOPs a and b, all of one shape, ``lo <= hi``, finite.
    k : int
        8 (2-D), 14, 18 or 26 (3-D).

    Returns
    -------
    lo, hi : numpy.ndarray, float64
        Of the inputs' shape.
    """
    k = _check_k(k)
    lo_a, hi_a = _as_kdop(lo_a, hi_a, k, ("lo_a", "hi_a"))
    lo_b, hi_b = _as_kdop(lo_b, hi_b, k, ("lo_b", "hi_b"))
    if lo_b.shape != lo_a.shape:
        raise ValueError(f"lo_b must have the shape of lo_a {lo_a.shape}, got {lo_b.shape}")
    return np.minimum(lo_a, lo_b), np.maximum(hi_a, hi_b)


def kdop_contains(lo: ArrayLike, hi: ArrayLike, points: ArrayLike, k: int) -> np.ndarray:
    """Which points lie in a closed k-DOP: their projection on every direction lies in its slab.

    Parameters
    ----------
    lo, hi : array_like, shape (k/2,)
        The DOP's slab bounds, ``lo <= hi``, finite.
    points : array_like, shape (n, d)
        The points (n may be 0), finite; d = 2 for k = 8, d = 3 otherwise.
    k : int
        8 (2-D), 14, 18 or 26 (3-D).

    Returns
    -------
    numpy.ndarray, shape (n,), bool
    """
    k = _check_k(k)
    lo, hi = _as_kdop(lo, hi, k)
    if lo.ndim != 1:
        raise ValueError(f"lo must have shape ({k // 2},), got {lo.shape}")
    pts = as_points(points, min_rows=0, dims=(KDOP_SIZES[k],))
    out = np.empty(pts.shape[0], dtype=np.bool_)
    _contains_kernel(lo, hi, _DIRECTIONS[k], pts, out)
    return out


def update_kdop(points: ArrayLike, k: int, rotation: ArrayLike,
                translation: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """The tight k-DOP of a point cloud after x -> rotation @ x + translation: an exact re-fit.

    The moved points are never built: n_s · (R p + t) = (Rᵀ n_s) · p + n_s · t.

    Parameters
    ----------
    points : array_like, shape (n, d)
        The object's points in its rest pose, n >= 1; d = 2 for k = 8, d = 3 otherwise.
    k : int
        8 (2-D), 14, 18 or 26 (3-D).
    rotation, translation : array_like, shapes (d, d) and (d,)
        The motion x -> R x + t, see :ref:`bounding-arguments`.

    Returns
    -------
    lo, hi : numpy.ndarray, shape (k/2,), float64
        Equal to ``fit_kdop(points @ rotation.T + translation, k)`` up to round-off.
    """
    k = _check_k(k)
    d = KDOP_SIZES[k]
    pts = as_points(points, dims=(d,))
    rotation, translation = as_rigid_transform(rotation, translation, d)
    lo = np.empty(k // 2)
    hi = np.empty(k // 2)
    _update_kdop_kernel(pts, rotation, translation, _DIRECTIONS[k], lo, hi)
    return lo, hi


def transform_kdop(lo: ArrayLike, hi: ArrayLike, k: int, rotation: ArrayLike,
                   translation: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """A k-DOP holding the moved object, from the DOP alone (no points): conservative, via its AABB slabs.

    The moved object lies in the moved AABB ``(lo[:d], hi[:d])``, so each new slab is bounded by that box's
    support along Rᵀ n_s (Ericson 4.2.6 applied to each direction). Use :func:`update_kdop` when the points are
    at hand (tight); this one is for when only the DOP is stored.

    Parameters
    ----------
    lo, hi : array_like, shape (k/2,)
        The DOP's slab bounds, ``lo <= hi``, finite.
    k, rotation, translation : int, array_like (d, d), array_like (d,)
        The DOP's kind and the motion x -> R x + t, as for :func:`update_kdop`.

    Returns
    -------
    lo, hi : numpy.ndarray, shape (k/2,), float64
        A DOP holding the moved object; looser than the re-fit.
    """
    k = _check_k(k)
    d = KDOP_SIZES[k]
    lo, hi = _as_kdop(lo, hi, k)
    if lo.ndim != 1:
        raise ValueError(f"lo must have shape ({k // 2},), got {lo.shape}")
    rotation, translation = as_rigid_transform(rotation, translation, d)
    new_lo = np.empty(k // 2)
    new_hi = np.empty(k // 2)
    _transform_kdop_kernel(lo, hi, rotation, translation, _DIRECTIONS[k], new_lo, new_hi)
    return new_lo, new_hi

