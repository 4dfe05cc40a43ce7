"""Oriented bounding box (chapter slide "Oriented bounding box OBB": 15 values — position (3),
orientation (9), extent (3)). Ericson, *Real-Time Collision Detection*, section 4.4.

The fit is the PCA box (the eigenvectors of the points' covariance); two OBBs are tested by the separating axis
theorem (``engine.obb_overlap``, in the narrow phase).
"""
from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from .._config import njit
from .._validate import MAX_MAGNITUDE, as_float_array, as_half_extents, check_orthonormal_rows, orthonormal_error
from .aabb import check_ordered

#: how far ``axes @ axes.T`` may be from the identity before the axes are rejected as not orthonormal
ORTHONORMAL_TOL = 1e-9


class OBB:
    """An oriented box in 3-D: a centre, three orthonormal axes and the half extents along them.

    A point p lies in the (closed) box iff ``|axes[k] @ (p - center)| <= half_extents[k]`` for k = 0, 1, 2.
    The arrays are copied and made read-only, so an OBB never aliases the caller's arrays.

    Parameters
    ----------
    center : array_like, shape (3,)
        The box's centre, finite.
    axes : array_like, shape (3, 3)
        The box's unit axes as ROWS, orthonormal to ``ORTHONORMAL_TOL`` (1e-9); a left-handed frame is
        accepted (it spans the same box).
    half_extents : array_like, shape (3,)
        The half widths along the three axes, >= 0.

    Attributes
    ----------
    center : numpy.ndarray, shape (3,), float64
        Read-only.
    axes : numpy.ndarray, shape (3, 3), float64
        Read-only; row k is the box's k-th axis.
    half_extents : numpy.ndarray, shape (3,), float64
        Read-only.

    Raises
    ------
    ValueError
        For NaN or ±inf, wrong shapes, a negative half extent (named with its index), or axes that are not
        orthonormal.
    TypeError
        For non-numeric arrays.

    Examples
    --------
    >>> import numpy as np
    >>> from engine.bounding import OBB
    >>> c, s = np.cos(np.pi / 4), np.sin(np.pi / 4)
    >>> box = OBB([0, 0, 0], [[c, s, 0], [-s, c, 0], [0, 0, 1]], [2.0, 0.5, 0.5])  # turned 45° about z
    >>> box.contains([[1.0, 1.0, 0.0], [1.0, -1.0, 0.0]]).tolist()
    [True, False]
    """

    __slots__ = ("center", "axes", "half_extents")

    def __init__(self, center: ArrayLike, axes: ArrayLike, half_extents: ArrayLike):
        center = as_float_array(center, "center", shape=(3,))
        axes = as_float_array(axes, "axes", shape=(3, 3))
        half_extents = as_half_extents(half_extents, "half_extents", zero=True)
        err = np.abs(axes @ axes.T - np.eye(3)).max()
        if err > ORTHONORMAL_TOL:
            raise ValueError(f"axes must be orthonormal rows (max |A A^T - I| = {err:.3g} > {ORTHONORMAL_TOL})")
        for arr in (center, axes, half_extents):
            arr.setflags(write=False)
        self.center = center
        self.axes = axes
        self.half_extents = half_extents

    @classmethod
    def from_aabb(cls, lo: ArrayLike, hi: ArrayLike) -> OBB:
        """The OBB equal to an axis-aligned box: centre (lo + hi)/2, the world axes, half extents (hi − lo)/2.

        Parameters
        ----------
        lo, hi : array_like, shape (3,)
            The box's corners, ``lo <= hi``, finite.

        Returns
        -------
        OBB

        Raises
        ------
        ValueError
            For NaN or ±inf, shapes other than (3,), or ``lo > hi`` (named with its index).
        TypeError
            For non-numeric arrays.
        """
        lo = as_float_array(lo, "lo", shape=(3,))
        hi = as_float_array(hi, "hi", shape=(3,))
        check_ordered(lo, hi)
        return cls((lo + hi) / 2.0, np.eye(3), (hi - lo) / 2.0)

    def corners(self) -> np.ndarray:
        """The box's 8 corners.

        Returns
        -------
        numpy.ndarray, shape (8, 3), float64
            Corner i is ``center + Σ_k s_k half_extents[k] axes[k]`` with s_k = +1 when bit k of i is set, else
            −1: the sign patterns (−,−,−), (+,−,−), (−,+,−), (+,+,−), ...
        """
        signs = np.array([[(i >> 0) & 1, (i >> 1) & 1, (i >> 2) & 1] for i in range(8)], dtype=np.float64)
        signs = 2.0 * signs - 1.0
        return self.center + (signs * self.half_extents) @ self.axes

    def contains(self, points: ArrayLike) -> np.ndarray:
        """Which points lie in the closed box (the boundary included).

        Parameters
        ----------
        points : array_like, shape (n, 3)
            The points (n may be 0), finite.

        Returns
        -------
        numpy.ndarray, shape (n,), bool

        Raises
        ------
        ValueError
            For NaN, ±inf or a shape other than (n, 3).
        TypeError
            For non-numeric points.
        """
        pts = as_float_array(points, "points", shape=(None, 3))
        local = (pts - self.center) @ self.axes.T
        return (np.abs(local) <= self.half_extents).all(axis=1)

    def transformed(self, rotation: ArrayLike, translation: ArrayLike) -> OBB:
        """The box moved by x -> rotation @ x + translation: an exact update (the axes rotate with the box).

        Parameters
        ----------
        rotation : array_like, shape (3, 3)
            Orthonormal (a rotation, or a reflection).
        translation : array_like, shape (3,)
            The translation t.

        Returns
        -------
        OBB
            A new box; this one is unchanged.

        Raises
        ------
        ValueError
            For NaN, ±inf or wrong shapes, or a rotation that is not orthonormal (reported as non-orthonormal
            ``axes`` of the moved box).
        TypeError
            For non-numeric arrays.
        """
        rotation = as_float_array(rotation, "rotation", shape=(3, 3))
        translation = as_float_array(translation, "translation", shape=(3,))
        return OBB(rotation @ self.center + translation, self.axes @ rotation.T, self.half_extents)

    def __repr__(self) -> str:
        return (f"OBB(center={self.center.tolist()}, axes={self.axes.tolist()}, "
                f"half_extents={self.half_extents.tolist()})")


# ---------------------------------------------------------------------------------------------------------
# fit, merge, update (Ericson 4.4.3: OBB from the covariance of the points, i.e. principal component analysis)
# ---------------------------------------------------------------------------------------------------------
@njit
def _obbs_pass_checks(c, r, e, tol):
    """Whether n stacked boxes, c (n, 3), r (n, 3, 3), e (n, 3) float64, pass every value check of ``as_obbs``
    (each |value| <= MAX_MAGNITUDE, which NaN and ±inf fail; e >= 0; the rows of r[i] orthonormal to tol)."""
    for i in range(c.shape[0]):
        for k in range(3):
            if not (abs(c[i, k]) <= MAX_MAGNITUDE and abs(e[i, k]) <= MAX_MAGNITUDE and e[i, k] >= 0.0):
                return False
            for m in range(3):
                if not abs(r[i, k, m]) <= MAX_MAGNITUDE:
                    return False
        if orthonormal_error(r, i) > tol:
            return False
    return True


def _stacked_float64(arr, shape) -> bool:
    return (type(arr) is np.ndarray and arr.dtype == np.float64 and arr.flags.c_contiguous
            and arr.shape == shape)


def as_obbs(centers: ArrayLike, axes: ArrayLike, half_extents: ArrayLike,
            names: tuple[str, str, str] = ("centers", "axes", "half_extents"), *,
            copy: bool = True) -> tuple[np.ndarray, ...]:
    """n oriented boxes as stacked arrays, checked as :class:`OBB` checks one: the batched boxes' argument check.

    Parameters
    ----------
    centers : array_like, shape (n, 3)
        The boxes' centres, finite.
    axes : array_like, shape (n, 3, 3)
        Each box's unit axes as ROWS, orthonormal to ``ORTHONORMAL_TOL``.
    half_extents : array_like, shape (n, 3)
        The half widths, >= 0.
    names : tuple of 3 str, optional
        The argument names the errors quote, in the order above.
    copy : bool, default True
        False for a caller that only reads the boxes: arrays that are already float64, C-contiguous and of
        these shapes are checked in one compiled pass and returned themselves (no copy); anything else is
        copied and checked as with True.

    Returns
    -------
    centers, axes, half_extents : numpy.ndarray, float64
        Fresh C-contiguous copies (or, with ``copy=False``, possibly the arguments), shapes (n, 3), (n, 3, 3),
        (n, 3).

    Raises
    ------
    ValueError
        For a wrong shape, NaN or ±inf, a negative half extent (naming its index [i, k]), or the first box whose
        axes are not orthonormal.
    TypeError
        For non-numeric arrays.
    """
    if (not copy and isinstance(centers, np.ndarray) and isinstance(axes, np.ndarray)
            and isinstance(half_extents, np.ndarray) and centers.ndim == 2):
        n = centers.shape[0]
        if (_stacked_float64(centers, (n, 3)) and _stacked_float64(axes, (n, 3, 3))
                and _stacked_float64(half_extents, (n, 3))
                and _obbs_pass_checks(centers, axes, half_extents, ORTHONORMAL_TOL)):
            return centers, axes, half_extents
    c = as_float_array(centers, names[0], shape=(None, 3))
    r = as_float_array(axes, names[1], shape=(c.shape[0], 3, 3))
    e = as_half_extents(half_extents, names[2], shape=(c.shape[0], 3), zero=True)
    check_orthonormal_rows(r, names[1], ORTHONORMAL_TOL)
    return c, r, e


@njit
def _extents_kernel(points, axes, lo, hi):
    # project every point on the three axes; the box spans [lo, hi] along each (Ericson 4.4.3, last step)
    for k in range(3):
        lo[k] = np.inf
        hi[k] = -np.inf
    for i in range(points.shape[0]):
        for k in range(3):
            t = axes[k, 0] * points[i, 0] + axes[k, 1] * points[i, 1] + axes[k, 2] * points[i, 2]
            if t < lo[k]:
                lo[k] = t
            if t > hi[k]:
                hi[k] = t


def fit_obb(points: ArrayLike) -> OBB:
    """The PCA bounding box of a 3-D point cloud: its axes are the eigenvectors of the covariance matrix.

    Ericson 4.4.3: the covariance C = (1/n) Σ (p − mean)(p − mean)ᵀ is symmetric, its eigenvectors
    (``numpy.linalg.eigh``) are orthonormal; the box spans the points' projections on them. Not the minimal
    box, but rotation-covariant: the fit of R p + t is the fit of p moved by (R, t) when the covariance has
    distinct eigenvalues. Every point lies in the box (the extents are re-measured).

    Parameters
    ----------
    points : array_like, shape (n, 3)
        n >= 1 points, finite.

    Returns
    -------
    OBB
        Right-handed axes, largest spread first.
    """
    pts = as_float_array(points, "points", shape=(None, 3), min_rows=1)
    mean = pts.mean(axis=0)
    centred = pts - mean
    cov = centred.T @ centred / pts.shape[0]
    _, vectors = np.linalg.eigh(cov)
    axes = np.ascontiguousarray(vectors.T[::-1])  # rows, largest spread first
    if np.linalg.det(axes) < 0:
        axes[2] = -axes[2]
    lo = np.empty(3)
    hi = np.empty(3)
    _extents_kernel(centred, axes, lo, hi)
    center = mean + ((lo + hi) / 2.0) @ axes
    half = (hi - lo) / 2.0
    # the centre moved by round-off: widen so that every point is inside the closed box
    local = np.abs((pts - center) @ axes.T)
    half = np.maximum(half, local.max(axis=0))
    return OBB(center, axes, half)


def merge_obb(a: OBB, b: OBB) -> OBB:
    """An OBB holding both boxes: the PCA fit of their 16 corners (Ericson 4.4.3 applied to the corners).

    Parameters
    ----------
    a, b : OBB
        The two boxes.

    Returns
    -------
    OBB
        It holds both boxes; not the smallest such box.

    Raises
    ------
    TypeError
        When ``a`` or ``b`` is not an OBB.
    """
    for name, box in (("a", a), ("b", b)):
        if not isinstance(box, OBB):
            raise TypeError(f"{name} must be an OBB, got {type(box).__name__}")
    return fit_obb(np.vstack([a.corners(), b.corners()]))


def transform_obb(box: OBB, rotation: ArrayLike, translation: ArrayLike) -> OBB:
    """The box moved by x -> rotation @ x + translation (the update is exact: the axes rotate with it).

    Parameters
    ----------
    box : OBB
        The box to move; unchanged.
    rotation : array_like, shape (3, 3)
        Orthonormal.
    translation : array_like, shape (3,)
        The translation t.

    Returns
    -------
    OBB
        ``box.transformed(rotation, translation)``.

    Raises
    ------
    TypeError
        When ``box`` is not an OBB, or for non-numeric arrays.
    ValueError
        As :meth:`OBB.transformed`.
    """
    if not isinstance(box, OBB):
        raise TypeError(f"box must be an OBB, got {type(box).__name__}")
    return box.transformed(rotation, translation)
