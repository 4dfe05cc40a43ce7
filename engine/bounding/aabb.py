"""Axis-aligned bounding box (chapter slide "Volumes englobants": AABB — 6 values, min and max of each
dimension; the test compares the projections; not invariant under rotation). Ericson, *Real-Time Collision
Detection*, section 4.2.

A box is a pair ``(lo, hi)`` of arrays of shape (d,), d = 2 or 3, with ``lo <= hi``; boxes are CLOSED, so two
boxes that touch overlap. Batched forms take (n, d) arrays and answer for every row in one compiled call.

This module also holds the argument checks shared by the other bounding-volume modules (point clouds and
rotations in 2-D or 3-D).
"""
from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .._config import njit
from .._validate import as_float_array

__all__ = [
    "fit_aabb",
    "fit_aabbs",
    "overlap_aabb_aabb",
    "overlap_aabbs",
    "merge_aabb",
    "aabb_contains",
    "transform_aabb",
    "transform_aabbs",
    "aabbs_touch",
    "enclose_aabbs",
    "overlap_slabs_kernel",
    "inside_slabs",
]

#: how far ``R @ R.T`` may be from the identity before a rotation is rejected
ROTATION_TOL = 1e-9


# ---------------------------------------------------------------------------------------------------------
# shared argument checks (private to engine.bounding)
# ---------------------------------------------------------------------------------------------------------
def as_points(points: ArrayLike, name: str = "points", *, min_rows: int = 1,
              dims: Sequence[int] = (2, 3)) -> np.ndarray:
    """A finite (n, d) float64 copy of a point cloud, d in ``dims``, n >= ``min_rows``."""
    arr = as_float_array(points, name, ndim=2, min_rows=min_rows)
    if arr.shape[1] not in dims:
        raise ValueError(f"{name} must have shape (n, d) with d in {tuple(dims)}, got {arr.shape}")
    return arr


def as_clouds(clouds: ArrayLike) -> np.ndarray:
    """A finite (m, n, d) float64 copy of m point clouds of n >= 1 points each, d in (2, 3): the batched fits'
    argument check."""
    arr = as_float_array(clouds, "clouds", ndim=3)
    if arr.shape[1] < 1 or arr.shape[2] not in (2, 3):
        raise ValueError(f"clouds must have shape (m, n, d) with n >= 1 and d in (2, 3), got {arr.shape}")
    return arr


def as_box(lo: ArrayLike, hi: ArrayLike, *, names: tuple[str, str] = ("lo", "hi"),
           dims: Sequence[int] = (2, 3)) -> tuple[np.ndarray, np.ndarray]:
    """Checked (lo, hi) boxes of shape (d,) or batched (n, d); ValueError naming the first row with lo > hi."""
    lo_name, hi_name = names
    lo = as_float_array(lo, lo_name)
    hi = as_float_array(hi, hi_name)
    if lo.ndim not in (1, 2) or lo.shape[-1] not in dims:
        raise ValueError(f"{lo_name} must have shape (d,) or (n, d) with d in {tuple(dims)}, got {lo.shape}")
    if hi.shape != lo.shape:
        raise ValueError(f"{hi_name} must have the shape of {lo_name} {lo.shape}, got {hi.shape}")
    check_ordered(lo, hi, names)
    return lo, hi


def check_ordered(lo: np.ndarray, hi: np.ndarray, names: tuple[str, str] = ("lo", "hi")) -> None:
    """ValueError naming the first entry (index, or (row, column)) where lo > hi, for (m,) or (n, m) float64
    arrays of the same shape (box corners, or k-DOP slab bounds); ``names`` are the argument names quoted."""
    lo_name, hi_name = names
    bad = lo > hi
    if bad.any():
        index = tuple(int(i) for i in np.argwhere(bad)[0])
        where = ", ".join(str(i) for i in index)
        raise ValueError(f"{lo_name} must be <= {hi_name}: {lo_name}[{where}] = {float(lo[index])!r} > "
                         f"{hi_name}[{where}] = {float(hi[index])!r}")


def as_rigid_transform(rotation: ArrayLike, translation: ArrayLike, d: int) -> tuple[np.ndarray, np.ndarray]:
    """A checked orthonormal (d, d) ``rotation`` and a (d,) ``translation`` (x -> rotation @ x + translation)."""
    rotation = as_float_array(rotation, "rotation", shape=(d, d))
    translation = as_float_array(translation, "translation", shape=(d,))
    err = np.abs(rotation @ rotation.T - np.eye(d)).max()
    if err > ROTATION_TOL:
        raise ValueError(f"rotation must be orthonormal (max |R R^T - I| = {err:.3g} > {ROTATION_TOL})")
    return rotation, translation


def as_rotation_matrix(rotation: ArrayLike | None, name: str = "rotation", *, tol: float = ROTATION_TOL,
                       normalise: bool = False) -> np.ndarray:
    """A proper rotation (3, 3) from None (identity), a 3x3 matrix (columns = the body's axes in the world) or a
    quaternion (w, x, y, z). ValueError naming ``name`` unless the matrix is orthonormal with det +1, or the
    quaternion has unit norm, to ``tol``. ``normalise``: divide a quaternion accepted within ``tol`` by its norm
    (JSON files carry rounded digits); otherwise it is used as given."""
    if rotation is None:
        return np.eye(3)
    arr = as_float_array(rotation, name)
    if arr.shape == (4,):
        norm = float(np.sqrt(arr @ arr))
        if abs(norm - 1.0) > tol:
            raise ValueError(f"{name} quaternion must have unit norm, got |q| = {norm!r} (normalise it first)")
        w, x, y, z = arr / norm if normalise else arr
        return np.array([
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ])
    if arr.shape != (3, 3):
        raise ValueError(f"{name} must be a (3, 3) matrix or a (4,) quaternion, got shape {arr.shape}")
    err = float(np.abs(arr.T @ arr - np.eye(3)).max())
    if err > tol:
        raise ValueError(f"{name} must be orthonormal (max |R^T R - I| = {err:.3g})")
    if np.linalg.det(arr) < 0.0:
        raise ValueError(f"{name} must be a proper rotation (det = -1: a reflection)")
    return arr


# ---------------------------------------------------------------------------------------------------------
# kernels
# ---------------------------------------------------------------------------------------------------------
@njit
def _fit_aabb_kernel(points, lo, hi):
    # Ericson 4.2.1: the box is the min and max of the points along each world axis
    n, d = points.shape
    for k in range(d):
        lo[k] = points[0, k]
        hi[k] = points[0, k]
    for i in range(1, n):
        for k in range(d):
            x = points[i, k]
            if x < lo[k]:
                lo[k] = x
            if x > hi[k]:
                hi[k] = x


@njit
def _fit_aabbs_kernel(clouds, lo, hi):
    # one box per cloud: clouds (m, n, d) -> lo, hi (m, d)
    for c in range(clouds.shape[0]):
        _fit_aabb_kernel(clouds[c], lo[c], hi[c])


@njit
def enclose_aabbs(lo, hi, members, box_lo, box_hi, centre_lo, centre_hi):
    """The box enclosing the boxes ``members`` ((m,) int64 rows of lo, hi (n, 3) float64) and the box enclosing
    their centres 0.5·lo + 0.5·hi, written into box_lo, box_hi, centre_lo, centre_hi ((3,) float64 each);
    m = 0 leaves them [inf, −inf]. The fit of a node of a hierarchy to its objects (Ericson 6.2.1)."""
    for k in range(3):
        box_lo[k] = np.inf
        box_hi[k] = -np.inf
        centre_lo[k] = np.inf
        centre_hi[k] = -np.inf
    for p in range(members.shape[0]):
        o = members[p]
        for k in range(3):
            box_lo[k] = min(box_lo[k], lo[o, k])
            box_hi[k] = max(box_hi[k], hi[o, k])
            centre = 0.5 * lo[o, k] + 0.5 * hi[o, k]
            centre_lo[k] = min(centre_lo[k], centre)
            centre_hi[k] = max(centre_hi[k], centre)


@njit
def aabbs_touch(lo_a, hi_a, lo_b, hi_b):
    """Whether the closed boxes [lo_a, hi_a] and [lo_b, hi_b] ((d,) each) overlap: the engine's one AABB test.

    Ericson 4.2.1 (slide "tester le recouvrement des projections"): two boxes overlap iff their projections
    overlap on every axis; closed intervals, so touching counts.
    """
    for k in range(lo_a.shape[0]):
        if hi_a[k] < lo_b[k] or hi_b[k] < lo_a[k]:
            return False
    return True


@njit
def overlap_slabs_kernel(lo_a, hi_a, lo_b, hi_b, out):
    """out[i] (bool (n,)) = whether the closed intervals [lo_a[i, s], hi_a[i, s]] and [lo_b[i, s], hi_b[i, s]]
    overlap on every slab s of the (n, m) float64 arrays: the AABB test on its m = d axes, and the k-DOP test on
    its m = k/2 directions (Ericson 4.2.1, 4.6.1: one separating slab proves the volumes disjoint)."""
    for i in range(lo_a.shape[0]):
        out[i] = aabbs_touch(lo_a[i], hi_a[i], lo_b[i], hi_b[i])


@njit
def inside_slabs(lo, hi, values):
    """Whether lo[s] <= values[s] <= hi[s] for every slab s ((m,) float64 each): a point inside an AABB (its
    coordinates), or inside a k-DOP (its projections on the k/2 directions)."""
    for s in range(values.shape[0]):
        if values[s] < lo[s] or values[s] > hi[s]:
            return False
    return True


@njit
def _contains_kernel(lo, hi, points, out):
    for i in range(points.shape[0]):
        out[i] = inside_slabs(lo, hi, points[i])


@njit
def _transform_aabbs_kernel(lo, hi, rotation, translation, new_lo, new_hi):
    # Ericson 4.2.6 "AABB recomputed from rotated AABB": with centre c and half-widths e, the rotated box
    # R·box + t has centre R c + t and half-widths e'_i = sum_j |R_ij| e_j (the exact AABB of the rotated box)
    n, d = lo.shape
    for b in range(n):
        for i in range(d):
            c = translation[i]
            e = 0.0
            for j in range(d):
                cj = 0.5 * (lo[b, j] + hi[b, j])
                ej = 0.5 * (hi[b, j] - lo[b, j])
                c += rotation[i, j] * cj
                e += abs(rotation[i, j]) * ej
            new_lo[b, i] = c - e
            new_hi[b, i] = c + e


@njit
def _boxes_valid_kernel(lo, hi):
    """Compiled check of batched boxes: all finite and lo <= hi (the slow path then names the culprit)."""
    n, d = lo.shape
    for i in range(n):
        for k in range(d):
            a = lo[i, k]
            b = hi[i, k]
            if not (math.isfinite(a) and math.isfinite(b) and a <= b):
                return False
    return True


def _is_plain_batch(*arrays: Any) -> bool:
    """All arrays are C-contiguous float64 (n, d) of one shape, d in (2, 3): no copy is needed to read them."""
    first = arrays[0]
    return all(isinstance(a, np.ndarray) and a.dtype == np.float64 and a.ndim == 2 and a.flags.c_contiguous
               and a.shape == first.shape for a in arrays) and first.shape[1] in (2, 3)


# ---------------------------------------------------------------------------------------------------------
# public functions
# ---------------------------------------------------------------------------------------------------------
def fit_aabb(points: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """The tightest AABB of a point cloud: the min and max of the points along each axis (Ericson 4.2.1).

    Parameters
    ----------
    points : array_like, shape (n, d)
        The cloud, see :ref:`bounding-arguments`.

    Returns
    -------
    lo, hi : numpy.ndarray, shape (d,), float64
        The box's corners.
    """
    pts = as_points(points)
    lo = np.empty(pts.shape[1])
    hi = np.empty(pts.shape[1])
    _fit_aabb_kernel(pts, lo, hi)
    return lo, hi


def fit_aabbs(clouds: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Batched :func:`fit_aabb`: one box per cloud of ``clouds`` (m, n, d) (see :ref:`bounding-arguments`), in
    one compiled call.

    Returns
    -------
    lo, hi : numpy.ndarray, shape (m, d), float64
        Row c is the box of cloud c.
    """
    arr = as_clouds(clouds)
    lo = np.empty((arr.shape[0], arr.shape[2]))
    hi = np.empty((arr.shape[0], arr.shape[2]))
    _fit_aabbs_kernel(arr, lo, hi)
    return lo, hi


def overlap_aabbs(lo_a: ArrayLike, hi_a: ArrayLike, lo_b: ArrayLike, hi_b: ArrayLike) -> np.ndarray:
    """Row-wise overlap of closed boxes: whether box a_i meets box b_i, for every row i, in one compiled call.

    Two boxes overlap iff their intervals overlap on every axis (Ericson 4.2.1); touching counts. C-contiguous
    float64 inputs are read without a copy (and never written).

    Parameters
    ----------
    lo_a, hi_a, lo_b, hi_b : array_like, shape (n, d) or (d,)
        The corners of the boxes a_i and b_i, all of one shape, d = 1, 2 or 3, ``lo <= hi``, finite.

    Returns
    -------
    numpy.ndarray, shape (n,), bool
        Shape (1,) for (d,) inputs.
    """
    if _is_plain_batch(lo_a, hi_a, lo_b, hi_b) and _boxes_valid_kernel(lo_a, hi_a) \
            and _boxes_valid_kernel(lo_b, hi_b):
        # fast path: the arrays are read, never written, so the checked inputs are used without a copy
        out = np.empty(np.shape(lo_a)[0], dtype=np.bool_)
        overlap_slabs_kernel(lo_a, hi_a, lo_b, hi_b, out)
        return out
    lo_a, hi_a = as_box(lo_a, hi_a, names=("lo_a", "hi_a"), dims=(1, 2, 3))
    lo_b, hi_b = as_box(lo_b, hi_b, names=("lo_b", "hi_b"), dims=(1, 2, 3))
    if lo_a.shape != lo_b.shape:
        raise ValueError(f"lo_b must have the shape of lo_a {lo_a.shape}, got {lo_b.shape}")
    out = np.empty(lo_a.reshape(-1, lo_a.shape[-1]).shape[0], dtype=np.bool_)
    d = lo_a.shape[-1]
    overlap_slabs_kernel(lo_a.reshape(-1, d), hi_a.reshape(-1, d), lo_b.reshape(-1, d), hi_b.reshape(-1, d), out)
    return out


def overlap_aabb_aabb(lo_a: ArrayLike, hi_a: ArrayLike, lo_b: ArrayLike, hi_b: ArrayLike) -> bool:
    """Whether two closed boxes overlap (touching counts): their intervals overlap on every axis.

    Parameters
    ----------
    lo_a, hi_a, lo_b, hi_b : array_like, shape (d,)
        The corners of boxes a and b, d = 1, 2 or 3, ``lo <= hi``, finite; one box each (a batch is a
        ValueError: use :func:`overlap_aabbs`).

    Returns
    -------
    bool
    """
    lo_a, hi_a = as_box(lo_a, hi_a, names=("lo_a", "hi_a"), dims=(1, 2, 3))
    if lo_a.ndim != 1:
        raise ValueError(f"lo_a must have shape (d,), got {lo_a.shape}; use overlap_aabbs for batches")
    return bool(overlap_aabbs(lo_a, hi_a, lo_b, hi_b)[0])


def merge_aabb(lo_a: ArrayLike, hi_a: ArrayLike, lo_b: ArrayLike, hi_b: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """The smallest AABB holding both boxes (row-wise for batches): the min of the lows, the max of the highs.

    Parameters
    ----------
    lo_a, hi_a, lo_b, hi_b : array_like, shape (d,) or (n, d)
        The corners of the boxes a and b, all of one shape, d = 2 or 3, ``lo <= hi``, finite.

    Returns
    -------
    lo, hi : numpy.ndarray, float64
        Of the inputs' shape.
    """
    lo_a, hi_a = as_box(lo_a, hi_a, names=("lo_a", "hi_a"))
    lo_b, hi_b = as_box(lo_b, hi_b, names=("lo_b", "hi_b"))
    if lo_a.shape != lo_b.shape:
        raise ValueError(f"lo_b must have the shape of lo_a {lo_a.shape}, got {lo_b.shape}")
    return np.minimum(lo_a, lo_b), np.maximum(hi_a, hi_b)


def aabb_contains(lo: ArrayLike, hi: ArrayLike, points: ArrayLike) -> np.ndarray:
    """Which points lie in a closed box (the boundary included).

    Parameters
    ----------
    lo, hi : array_like, shape (d,)
        The box's corners, d = 2 or 3, ``lo <= hi``, finite.
    points : array_like, shape (n, d)
        The points (n may be 0), finite.

    Returns
    -------
    numpy.ndarray, shape (n,), bool
    """
    lo, hi = as_box(lo, hi)
    if lo.ndim != 1:
        raise ValueError(f"lo must have shape (d,), got {lo.shape}")
    pts = as_points(points, min_rows=0, dims=(lo.shape[0],))
    out = np.empty(pts.shape[0], dtype=np.bool_)
    _contains_kernel(lo, hi, pts, out)
    return out


def transform_aabbs(lo: ArrayLike, hi: ArrayLike, rotation: ArrayLike,
                    translation: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Batched fast re-fit (Ericson 4.2.6): the AABBs of the boxes moved by x -> R x + t, without the points.

    The result is the exact AABB of each moved box: with centre c and half-widths e, the moved box has centre
    R c + t and half-widths ``e'_i = Σ_j |R_ij| e_j``. It contains the moved object, and is at most sqrt(d) times
    wider than the object's own re-fit.

    Parameters
    ----------
    lo, hi : array_like, shape (n, d) or (d,)
        The boxes, d = 2 or 3, ``lo <= hi``, finite.
    rotation, translation : array_like, shapes (d, d) and (d,)
        The motion x -> R x + t, see :ref:`bounding-arguments`.

    Returns
    -------
    lo, hi : numpy.ndarray, float64
        The moved boxes' AABBs, of the inputs' shape.
    """
    lo, hi = as_box(lo, hi)
    d = lo.shape[-1]
    rotation, translation = as_rigid_transform(rotation, translation, d)
    lo2, hi2 = lo.reshape(-1, d), hi.reshape(-1, d)
    new_lo = np.empty_like(lo2)
    new_hi = np.empty_like(hi2)
    _transform_aabbs_kernel(lo2, hi2, rotation, translation, new_lo, new_hi)
    return new_lo.reshape(lo.shape), new_hi.reshape(hi.shape)


def transform_aabb(lo: ArrayLike, hi: ArrayLike, rotation: ArrayLike,
                   translation: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """The AABB of one box after x -> rotation @ x + translation (Ericson 4.2.6), as :func:`transform_aabbs`.

    Parameters
    ----------
    lo, hi : array_like, shape (d,)
        The box, d = 2 or 3, ``lo <= hi``, finite.
    rotation, translation : array_like, shapes (d, d) and (d,)
        The motion x -> R x + t, see :ref:`bounding-arguments`.

    Returns
    -------
    lo, hi : numpy.ndarray, shape (d,), float64

    Raises
    ------
    ValueError
        For a batch of boxes: use :func:`transform_aabbs`.
    """
    lo, hi = as_box(lo, hi)
    if lo.ndim != 1:
        raise ValueError(f"lo must have shape (d,), got {lo.shape}; use transform_aabbs for batches")
    return transform_aabbs(lo, hi, rotation, translation)
