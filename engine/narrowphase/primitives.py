"""Narrow-phase tests between primitive shapes: the chapter's bounding-volume slides, one test per shape pair.

- sphere–sphere (slide "Bounding sphere": collision iff d < r_A + r_B; "11 opérations primitives": 3
  subtractions, 3 products, 2 sums for |c_A − c_B|², 1 sum and 1 product for (r_A + r_B)², 1 comparison — no
  square root). Touching counts as contact here (<=), like every closed test of the engine;
- AABB–AABB (slide "AABB": overlap of the projections on every axis), Ericson 4.2.1;
- sphere–AABB and sphere–OBB: the closest point of the box to the centre, Ericson 5.2.5 and 5.2.6;
- circle–segment (slide "une balle qui touche une raquette": circle against any segment) and sphere–capsule:
  the distance from the centre to the segment, Ericson 5.1.2;
- flat ground at altitude a (slide "sol plat": if the bottom of the bounding box is above a, no collision);
- curved ground y = f(x) (slide "Sol courbe": the bottom-middle point of the AABB against f, "il suffit de voir si
  f(x) > y") and the exact test of a box or a circle against the region under the curve.

"Up" is the y axis (column 1), as on the slides; 2-D shapes use (x, y) and 3-D shapes (x, y, z).

Every test has a single-pair form returning a bool and a ``*_batch`` form over arrays of pairs in one compiled
call. Batched forms share one convention (the one a dispatch table shape kind × shape kind calls): without index
arrays, pair p is row p of the A arrays against row p of the B arrays; with ``index_a``, ``index_b`` (k,) int,
pair p is row ``index_a[p]`` of A against row ``index_b[p]`` of B.
"""
from __future__ import annotations

import numpy as np

from .._config import njit
from .._validate import (
    as_count,
    as_float,
    as_float_array,
    as_nonnegative,
    as_radii,
    check_callable,
    pair_indices,
)
from ..bounding.aabb import aabbs_touch, overlap_aabb_aabb
from ..bounding.obb import OBB, as_obbs
from ..bounding.sphere import overlap_sphere_sphere, spheres_touch

__all__ = [
    "overlap_sphere_sphere", "overlap_sphere_sphere_batch",
    "overlap_aabb_aabb", "overlap_aabb_aabb_batch",
    "overlap_sphere_aabb", "overlap_sphere_aabb_batch",
    "overlap_sphere_obb", "overlap_sphere_obb_batch",
    "distance_point_segment", "overlap_circle_segment", "overlap_circle_segment_batch",
    "overlap_sphere_capsule", "overlap_sphere_capsule_batch",
    "overlap_aabb_ground", "overlap_aabb_ground_batch", "overlap_sphere_ground_batch",
    "overlap_aabb_curve_bottom_middle", "overlap_aabb_curve", "overlap_circle_curve", "max_on_intervals",
    "min_distance_to_curve",
]

UP = 1  # the y axis, "up" on the chapter's slides


# ---------------------------------------------------------------------------------------------------------------
# kernels (one per test, a batch loop beside each)
# ---------------------------------------------------------------------------------------------------------------

@njit
def _overlap_sphere_sphere_batch(ca, ra, cb, rb, ia, ib, out):
    for p in range(out.shape[0]):
        out[p] = spheres_touch(ca[ia[p]], ra[ia[p]], cb[ib[p]], rb[ib[p]])


@njit
def _overlap_aabb_aabb_batch(lo_a, hi_a, lo_b, hi_b, ia, ib, out):
    for p in range(out.shape[0]):
        out[p] = aabbs_touch(lo_a[ia[p]], hi_a[ia[p]], lo_b[ib[p]], hi_b[ib[p]])


@njit
def _sq_distance_point_aabb(c, lo, hi):
    """Ericson 5.1.3.1 SqDistPointAABB: squared distance from point c to the box [lo, hi]."""
    s = 0.0
    for k in range(c.shape[0]):
        v = c[k]
        if v < lo[k]:
            s += (lo[k] - v) * (lo[k] - v)
        elif v > hi[k]:
            s += (v - hi[k]) * (v - hi[k])
    return s


@njit
def _overlap_sphere_aabb_batch(c, r, lo, hi, ia, ib, out):
    # Ericson 5.2.5 TestSphereAABB
    for p in range(out.shape[0]):
        i = ia[p]
        out[p] = _sq_distance_point_aabb(c[i], lo[ib[p]], hi[ib[p]]) <= r[i] * r[i]


@njit
def _sq_distance_point_obb(c, bc, axes, half):
    """Ericson 5.1.4.2 SqDistPointOBB: project c − centre on each box axis, clamp, accumulate the excess."""
    dx = c[0] - bc[0]
    dy = c[1] - bc[1]
    dz = c[2] - bc[2]
    s = 0.0
    for k in range(3):
        d = dx * axes[k, 0] + dy * axes[k, 1] + dz * axes[k, 2]
        excess = 0.0
        if d < -half[k]:
            excess = d + half[k]
        elif d > half[k]:
            excess = d - half[k]
        s += excess * excess
    return s


@njit
def _overlap_sphere_obb_batch(c, r, bc, axes, half, ia, ib, out):
    # Ericson 5.2.6 TestSphereOBB
    for p in range(out.shape[0]):
        i = ia[p]
        j = ib[p]
        out[p] = _sq_distance_point_obb(c[i], bc[j], axes[j], half[j]) <= r[i] * r[i]


@njit
def _sq_distance_point_segment(c, p0, p1):
    """Ericson 5.1.2.1 SqDistPointSegment, any dimension."""
    ab2 = 0.0
    acab = 0.0
    for k in range(c.shape[0]):
        ab = p1[k] - p0[k]
        ab2 += ab * ab
        acab += (c[k] - p0[k]) * ab
    t = 0.0
    if ab2 > 0.0:
        t = min(max(acab / ab2, 0.0), 1.0)
    s = 0.0
    for k in range(c.shape[0]):
        d = c[k] - (p0[k] + t * (p1[k] - p0[k]))
        s += d * d
    return s


@njit
def _overlap_sphere_segment_batch(c, r, p0, p1, rs, ia, ib, out):
    """Circle/sphere of radius r against the segment [p0, p1] swept by a ball of radius rs (capsule)."""
    for p in range(out.shape[0]):
        i = ia[p]
        j = ib[p]
        s = r[i] + rs[j]
        out[p] = _sq_distance_point_segment(c[i], p0[j], p1[j]) <= s * s


@njit
def _distance_point_segment_batch(c, p0, p1, out):
    for p in range(out.shape[0]):
        out[p] = np.sqrt(_sq_distance_point_segment(c[p], p0[p], p1[p]))


@njit
def _overlap_ground_batch(bottom, altitude, out):
    """Slide "sol plat": no collision iff the bottom of the bounding box is above the altitude a."""
    for p in range(out.shape[0]):
        out[p] = not (bottom[p] > altitude[p])


# ---------------------------------------------------------------------------------------------------------------
# validation helpers
# ---------------------------------------------------------------------------------------------------------------

def _boxes(lo, hi, name_lo: str, name_hi: str, dims=(1, 2, 3)):
    lo = as_float_array(lo, name_lo, ndim=2)
    hi = as_float_array(hi, name_hi, shape=lo.shape)
    if lo.shape[1] not in dims:
        raise ValueError(f"{name_lo} must have {' or '.join(map(str, dims))} columns, got shape {lo.shape}")
    if (lo > hi).any():
        i, k = (int(x) for x in np.argwhere(lo > hi)[0])
        raise ValueError(f"{name_lo} must be <= {name_hi}: {name_lo}[{i}, {k}] = {float(lo[i, k])!r} > "
                         f"{name_hi}[{i}, {k}] = {float(hi[i, k])!r}")
    return lo, hi


def _one(value, name, d=None):
    """A single point as a (1, d) array."""
    arr = as_float_array(value, name, ndim=1)
    if d is not None and arr.shape[0] not in ((d,) if isinstance(d, int) else d):
        raise ValueError(f"{name} must have shape ({d},), got {arr.shape}")
    return arr[None, :]


def _balls(centers, radii, d, names=("centers", "radii")):
    """Centres (n, d) (d None: any d) and their radii (n,) >= 0 (a scalar for all), checked."""
    c = as_float_array(centers, names[0], ndim=2) if d is None else as_float_array(centers, names[0], shape=(None, d))
    return c, as_radii(radii, names[1], c.shape[0])


def _pair_batch(kernel, a_arrays, b_arrays, index_a, index_b):
    """Pair the rows of the A and the B arrays (:ref:`batched-pairs`; the first array of each side gives its row
    count) and run ``kernel(*a_arrays, *b_arrays, ia, ib, out)`` into a fresh ``out`` (k,) bool, returned."""
    ia, ib = pair_indices(a_arrays[0].shape[0], b_arrays[0].shape[0], index_a, index_b)
    out = np.empty(ia.shape[0], np.bool_)
    kernel(*a_arrays, *b_arrays, ia, ib, out)
    return out


# ---------------------------------------------------------------------------------------------------------------
# sphere–sphere, AABB–AABB, sphere–AABB, sphere–OBB
# ---------------------------------------------------------------------------------------------------------------

def overlap_sphere_sphere_batch(centers_a, radii_a, centers_b, radii_b, index_a=None, index_b=None):
    """Sphere–sphere overlap for k pairs: ``|c_a − c_b| <= r_a + r_b``, squared (no square root).

    The slide "Bounding sphere" test of ``overlap_sphere_sphere`` in one compiled call; the pair convention is
    :ref:`batched-pairs`.

    Parameters
    ----------
    centers_a : array_like, shape (n, 3), float64
        Centres of the A spheres.
    radii_a : array_like, shape (n,) or scalar
        Their radii, >= 0.
    centers_b : array_like, shape (m, 3), float64
        Centres of the B spheres.
    radii_b : array_like, shape (m,) or scalar
        Their radii, >= 0.
    index_a, index_b : array_like, shape (k,), int, optional
        Rows of A and of B paired (see :ref:`batched-pairs`).

    Returns
    -------
    numpy.ndarray, shape (k,), bool
        True where the spheres of pair p overlap or touch.
    """
    a = _balls(centers_a, radii_a, 3, ("centers_a", "radii_a"))
    b = _balls(centers_b, radii_b, 3, ("centers_b", "radii_b"))
    return _pair_batch(_overlap_sphere_sphere_batch, a, b, index_a, index_b)


def overlap_aabb_aabb_batch(lo_a, hi_a, lo_b, hi_b, index_a=None, index_b=None):
    """AABB–AABB overlap for k pairs: the projections overlap on every axis (Ericson 4.2.1, slide "AABB").

    Parameters
    ----------
    lo_a, hi_a : array_like, shape (n, d), float64
        Corners of the closed A boxes, d = 1, 2 or 3, ``lo_a <= hi_a``.
    lo_b, hi_b : array_like, shape (m, d), float64
        Corners of the B boxes, of the same dimension d.
    index_a, index_b : array_like, shape (k,), int, optional
        Rows paired, :ref:`batched-pairs`.

    Returns
    -------
    numpy.ndarray, shape (k,), bool
        True where the boxes of pair p overlap (touching counts).

    Raises
    ------
    ValueError
        Also when ``lo_a`` and ``lo_b`` differ in dimension.
    """
    la, ha = _boxes(lo_a, hi_a, "lo_a", "hi_a")
    lb, hb = _boxes(lo_b, hi_b, "lo_b", "hi_b")
    if la.shape[1] != lb.shape[1]:
        raise ValueError(f"lo_a and lo_b must have the same dimension, got {la.shape[1]} and {lb.shape[1]}")
    return _pair_batch(_overlap_aabb_aabb_batch, (la, ha), (lb, hb), index_a, index_b)


def overlap_sphere_aabb_batch(centers, radii, lo, hi, index_a=None, index_b=None):
    """Sphere–AABB overlap for k pairs: the squared distance from the centre to the box is <= r² (Ericson 5.2.5).

    Parameters
    ----------
    centers : array_like, shape (n, d), float64
        Sphere (d = 3) or circle (d = 2) centres.
    radii : array_like, shape (n,) or scalar
        Their radii, >= 0.
    lo, hi : array_like, shape (m, d), float64
        Corners of the closed boxes, ``lo <= hi``.
    index_a, index_b : array_like, shape (k,), int, optional
        Rows of ``centers`` and of ``lo`` paired; see :ref:`batched-pairs`.

    Returns
    -------
    numpy.ndarray, shape (k,), bool
        True where circle or sphere p reaches its box.

    Raises
    ------
    ValueError
        Also when ``centers`` and ``lo`` differ in dimension.
    """
    c, r = _balls(centers, radii, None)
    lo, hi = _boxes(lo, hi, "lo", "hi")
    if c.shape[1] != lo.shape[1]:
        raise ValueError(f"centers and lo must have the same dimension, got {c.shape[1]} and {lo.shape[1]}")
    return _pair_batch(_overlap_sphere_aabb_batch, (c, r), (lo, hi), index_a, index_b)


def overlap_sphere_aabb(center, radius, lo, hi) -> bool:
    """Whether a sphere (or circle) overlaps the closed box [lo, hi]: the single-pair ``overlap_sphere_aabb_batch``.

    Parameters
    ----------
    center : array_like, shape (d,)
        The centre, d = 2 or 3.
    radius : float
        >= 0.
    lo, hi : array_like, shape (d,)
        The box corners, ``lo <= hi``.

    Returns
    -------
    bool
        True when they overlap or touch.
    """
    return bool(overlap_sphere_aabb_batch(_one(center, "center"), [as_nonnegative(radius, "radius")],
                                          _one(lo, "lo"), _one(hi, "hi"))[0])


def overlap_sphere_obb_batch(centers, radii, box_centers, box_axes, box_half_extents, index_a=None, index_b=None):
    """Sphere–OBB overlap for k pairs: the closest point of the box to the centre is within r (Ericson 5.2.6).

    Parameters
    ----------
    centers : array_like, shape (n, 3), float64
        Sphere centres.
    radii : array_like, shape (n,) or scalar
        Radii, >= 0.
    box_centers : array_like, shape (m, 3), float64
        Centres of the oriented boxes.
    box_axes : array_like, shape (m, 3, 3), float64
        Their axes; the rows of ``box_axes[j]`` are box j's unit axes (orthonormal).
    box_half_extents : array_like, shape (m, 3), float64
        Half extents along those axes, >= 0.
    index_a, index_b : array_like, shape (k,), int, optional
        Sphere rows and box rows paired (:ref:`batched-pairs`).

    Returns
    -------
    numpy.ndarray, shape (k,), bool
        True where sphere and box of pair p overlap or touch.

    Raises
    ------
    ValueError
        Also for axes that are not orthonormal rows (named with the box index).
    """
    spheres = _balls(centers, radii, 3)
    boxes = as_obbs(box_centers, box_axes, box_half_extents, ("box_centers", "box_axes", "box_half_extents"))
    return _pair_batch(_overlap_sphere_obb_batch, spheres, boxes, index_a, index_b)


def overlap_sphere_obb(center, radius, box: OBB) -> bool:
    """Whether a sphere overlaps an oriented box (Ericson 5.2.6, TestSphereOBB).

    Parameters
    ----------
    center : array_like, shape (3,)
        The sphere's centre.
    radius : float
        Its radius, >= 0.
    box : engine.bounding.OBB
        The box.

    Returns
    -------
    bool
        True when they overlap or touch.

    Raises
    ------
    TypeError
        When ``box`` is not an ``OBB``.
    """
    if not isinstance(box, OBB):
        raise TypeError(f"box must be an engine.bounding.obb.OBB, got {type(box).__name__}")
    return bool(overlap_sphere_obb_batch(_one(center, "center", 3), [as_nonnegative(radius, "radius")],
                                         box.center[None], box.axes[None], box.half_extents[None])[0])


# ---------------------------------------------------------------------------------------------------------------
# ball and paddle: circle–segment, sphere–capsule
# ---------------------------------------------------------------------------------------------------------------

def distance_point_segment(points, p0, p1) -> np.ndarray:
    """Distance from each point to its segment, row by row (Ericson 5.1.2.1, SqDistPointSegment, then a square root).

    Parameters
    ----------
    points : array_like, shape (n, d), float64
        The points, d = 2 or 3.
    p0, p1 : array_like, shape (n, d), float64
        The segments' end points; a segment with p0 == p1 is a point.

    Returns
    -------
    numpy.ndarray, shape (n,), float64
        ``min over t in [0, 1] of |points[i] − (p0[i] + t (p1[i] − p0[i]))|``.

    Raises
    ------
    ValueError
        For NaN or ±inf, or ``p0``, ``p1`` not of the shape of ``points``.
    """
    c = as_float_array(points, "points", ndim=2)
    a = as_float_array(p0, "p0", shape=c.shape)
    b = as_float_array(p1, "p1", shape=c.shape)
    out = np.empty(c.shape[0])
    _distance_point_segment_batch(c, a, b, out)
    return out


def _segments(p0, p1, d):
    a = as_float_array(p0, "p0", shape=(None, d))
    b = as_float_array(p1, "p1", shape=a.shape)
    return a, b


def overlap_circle_segment_batch(centers, radii, p0, p1, index_a=None, index_b=None):
    """Circle–segment overlap for k pairs, the slide's ball and paddle: the centre is within r of the segment.

    Parameters
    ----------
    centers : array_like, shape (n, 2), float64
        Circle centres (the balls).
    radii : array_like, shape (n,) or scalar
        The balls' radii, >= 0.
    p0, p1 : array_like, shape (m, 2), float64
        Segment end points.
    index_a, index_b : array_like, shape (k,), int, optional
        Circle rows and segment rows paired; :ref:`batched-pairs`.

    Returns
    -------
    numpy.ndarray, shape (k,), bool
    """
    a, b = _segments(p0, p1, 2)
    return _pair_batch(_overlap_sphere_segment_batch, _balls(centers, radii, 2), (a, b, np.zeros(a.shape[0])),
                       index_a, index_b)


def overlap_circle_segment(center, radius, p0, p1) -> bool:
    """Whether a circle meets the segment [p0, p1], e.g. a ball and a paddle.

    Parameters
    ----------
    center : array_like, shape (2,)
        Centre (x, y) of the ball.
    radius : float
        The ball's radius, >= 0 (0 for a point).
    p0, p1 : array_like, shape (2,)
        The segment's end points.

    Returns
    -------
    bool
        True when the distance from ``center`` to the segment is <= ``radius``.
    """
    return bool(overlap_circle_segment_batch(_one(center, "center", 2), [as_nonnegative(radius, "radius")],
                                             _one(p0, "p0", 2), _one(p1, "p1", 2))[0])


def overlap_sphere_capsule_batch(centers, radii, p0, p1, capsule_radii, index_a=None, index_b=None):
    """Sphere–capsule overlap for k pairs: ``distance(c, [p0, p1]) <= r + capsule_radius`` (Ericson 5.1.2).

    Parameters
    ----------
    centers : array_like, shape (n, 3), float64
        Centres of the spheres.
    radii : array_like, shape (n,) or scalar
        Sphere radii, >= 0.
    p0, p1 : array_like, shape (m, 3), float64
        End points of the capsules' axes.
    capsule_radii : array_like, shape (m,) or scalar
        The radius of the ball that sweeps each axis, >= 0.
    index_a, index_b : array_like, shape (k,), int, optional
        Sphere and capsule rows paired (see :ref:`batched-pairs`).

    Returns
    -------
    numpy.ndarray, shape (k,), bool
    """
    spheres = _balls(centers, radii, 3)
    a, b = _segments(p0, p1, 3)
    rc = as_radii(capsule_radii, "capsule_radii", a.shape[0])
    return _pair_batch(_overlap_sphere_segment_batch, spheres, (a, b, rc), index_a, index_b)


def overlap_sphere_capsule(center, radius, p0, p1, capsule_radius) -> bool:
    """Whether a sphere meets the capsule of axis [p0, p1] and radius ``capsule_radius``.

    Parameters
    ----------
    center : array_like, shape (3,)
        The sphere's centre.
    radius : float
        The sphere's radius, >= 0.
    p0, p1 : array_like, shape (3,)
        The capsule's axis end points.
    capsule_radius : float
        The capsule's radius, >= 0.

    Returns
    -------
    bool
    """
    return bool(overlap_sphere_capsule_batch(_one(center, "center", 3), [as_nonnegative(radius, "radius")],
                                             _one(p0, "p0", 3), _one(p1, "p1", 3),
                                             [as_nonnegative(capsule_radius, "capsule_radius")])[0])


# ---------------------------------------------------------------------------------------------------------------
# flat ground
# ---------------------------------------------------------------------------------------------------------------

def overlap_aabb_ground_batch(lo, hi, altitude):
    """Boxes against the flat ground y = altitude (slide "sol plat": a box whose bottom is above it does not touch).

    Parameters
    ----------
    lo, hi : array_like, shape (n, d), float64
        Box corners, d = 2 or 3, ``lo <= hi``; y is column 1.
    altitude : float or array_like, shape (n,)
        The ground's height, one for all boxes or one per box; finite.

    Returns
    -------
    numpy.ndarray, shape (n,), bool
        ``lo[:, 1] <= altitude``: True where the box reaches the ground (the region y <= altitude).

    Raises
    ------
    ValueError
        For NaN or ±inf, ``lo > hi``, or ``altitude`` of the wrong length.
    """
    lo, hi = _boxes(lo, hi, "lo", "hi", dims=(2, 3))
    alt = np.asarray(altitude)
    alt = np.full(lo.shape[0], as_float(altitude, "altitude")) if alt.ndim == 0 else \
        as_float_array(alt, "altitude", shape=(lo.shape[0],))
    out = np.empty(lo.shape[0], np.bool_)
    _overlap_ground_batch(np.ascontiguousarray(lo[:, UP]), alt, out)
    return out


def overlap_aabb_ground(lo, hi, altitude) -> bool:
    """Whether one box reaches the flat ground y = altitude.

    Parameters
    ----------
    lo, hi : array_like, shape (2,) or (3,)
        The box corners, ``lo <= hi``.
    altitude : float
        The ground's height.

    Returns
    -------
    bool
        True unless the box's bottom ``lo[1]`` is above ``altitude``.
    """
    return bool(overlap_aabb_ground_batch(_one(lo, "lo", (2, 3)), _one(hi, "hi", (2, 3)), altitude)[0])


def overlap_sphere_ground_batch(centers, radii, altitude):
    """Spheres or circles against the flat ground y = altitude: the lowest point ``c_y − r`` is not above it.

    Parameters
    ----------
    centers : array_like, shape (n, d), float64
        Centres, d = 2 or 3; y is column 1.
    radii : array_like, shape (n,) or scalar
        Radii, >= 0.
    altitude : float or array_like, shape (n,)
        The ground's height, one for all or one per shape.

    Returns
    -------
    numpy.ndarray, shape (n,), bool
        True where the shape reaches the region y <= altitude.

    Raises
    ------
    ValueError
        For NaN or ±inf, a negative radius, ``centers`` without 2 or 3 columns, or ``altitude`` of the wrong
        length.
    """
    c = as_float_array(centers, "centers", ndim=2)
    if c.shape[1] not in (2, 3):
        raise ValueError(f"centers must have 2 or 3 columns, got shape {c.shape}")
    r = as_radii(radii, "radii", c.shape[0])
    alt = np.asarray(altitude)
    alt = np.full(c.shape[0], as_float(altitude, "altitude")) if alt.ndim == 0 else \
        as_float_array(alt, "altitude", shape=(c.shape[0],))
    out = np.empty(c.shape[0], np.bool_)
    _overlap_ground_batch(c[:, UP] - r, alt, out)
    return out


# ---------------------------------------------------------------------------------------------------------------
# curved ground y = f(x), f a vectorised callable: the region y <= f(x) is solid
#
# The exact tests minimise, for every shape i at once, an objective g_i over an interval [lo_i, hi_i]: dense
# sampling (one call of f on the whole grid), then golden-section refinement of the bracket around the best sample
# (one call of f per iteration, on both interior points of every bracket). The bracket bookkeeping runs in the
# @njit kernels below; with a Python f the loop over iterations calls f between them, with a numba-jitted f
# (a numba dispatcher) ``_search_jit`` runs the whole search, f included, in one compiled call.
# ---------------------------------------------------------------------------------------------------------------

_GOLDEN = (np.sqrt(5.0) - 1.0) / 2.0
#: golden-section iterations after the sampling: the bracket shrinks by 0.618^60 ≈ 3e-13 of the sample spacing
GOLDEN_ITERATIONS = 60

_MAXIMIZE = 0  # g(x) = −f(x): max of f over the interval
_DISTANCE = 1  # g(x) = (x − p_x)² + (f(x) − p_y)²: squared distance from p to the graph


def _evaluate(f, x: np.ndarray) -> np.ndarray:
    """f on an array of abscissae, checked: same shape, real, finite (no NaN escapes)."""
    check_callable(f, "f", "a vectorised callable")
    y = np.asarray(f(x))
    if y.shape != x.shape:
        y = np.broadcast_to(y, x.shape) if y.ndim == 0 else y
    if y.shape != x.shape:
        raise ValueError(f"f must be vectorised: f(x) for x of shape {x.shape} returned shape {y.shape}")
    y = np.asarray(y, dtype=np.float64)
    if not np.isfinite(y).all():
        i = np.argwhere(~np.isfinite(y))[0]
        raise ValueError(f"f returned a non-finite value {float(y[tuple(i)])!r} at x = {float(x[tuple(i)])!r}")
    return y


@njit
def _objective(mode, x, y, px, py):
    if mode == _MAXIMIZE:
        return -y
    return (x - px) ** 2 + (y - py) ** 2


@njit
def _sample_grid(lo, hi, t, xs):
    """xs[i * s + j] = lo_i + (hi_i − lo_i) t_j: the s = len(t) samples of every interval, flat."""
    s = t.shape[0]
    for i in range(lo.shape[0]):
        for j in range(s):
            xs[i * s + j] = lo[i] + (hi[i] - lo[i]) * t[j]


@njit
def _best_samples(mode, xs, ys, px, py, s, best_x, best, a, b, cd):
    """Per interval: the best sample (first of the smallest g), the bracket [a, b] = its two neighbours, and the
    bracket's golden-section points c = b − φ(b − a), d = a + φ(b − a) into cd = (c (n), d (n))."""
    n = best.shape[0]
    for i in range(n):
        k = 0
        v = _objective(mode, xs[i * s], ys[i * s], px[i], py[i])
        for j in range(1, s):
            g = _objective(mode, xs[i * s + j], ys[i * s + j], px[i], py[i])
            if g < v:
                v = g
                k = j
        best_x[i] = xs[i * s + k]
        best[i] = v
        a[i] = xs[i * s + max(k - 1, 0)]
        b[i] = xs[i * s + min(k + 1, s - 1)]
        cd[i] = b[i] - _GOLDEN * (b[i] - a[i])
        cd[n + i] = a[i] + _GOLDEN * (b[i] - a[i])


@njit
def _golden_step(mode, cd, ycd, px, py, a, b, gc, gd, last):
    """One golden-section iteration on every bracket (Kiefer 1953): g at c and d (f already evaluated into ycd);
    keep [a, d] if g(c) <= g(d) else [c, b]; new c, d into cd — unless this was the ``last`` evaluation."""
    n = a.shape[0]
    for i in range(n):
        c = cd[i]
        d = cd[n + i]
        gc[i] = _objective(mode, c, ycd[i], px[i], py[i])
        gd[i] = _objective(mode, d, ycd[n + i], px[i], py[i])
        if last:
            continue
        if gc[i] <= gd[i]:
            b[i] = d
        else:
            a[i] = c
        cd[i] = b[i] - _GOLDEN * (b[i] - a[i])
        cd[n + i] = a[i] + _GOLDEN * (b[i] - a[i])


@njit
def _golden_finish(cd, gc, gd, best_x, best, x_out, v_out):
    """The better of the refined point and the best sample."""
    n = gc.shape[0]
    for i in range(n):
        if gc[i] <= gd[i]:
            x, v = cd[i], gc[i]
        else:
            x, v = cd[n + i], gd[i]
        if v < best[i]:
            x_out[i] = x
            v_out[i] = v
        else:
            x_out[i] = best_x[i]
            v_out[i] = best[i]


@njit
def _first_non_finite(y):
    for i in range(y.shape[0]):
        if not (y[i] - y[i]) == 0.0:
            return i
    return -1


@njit(cache=False)  # f is an argument, as in _search_jit
def _evaluate_jit(f, x, bad):
    """f(x) as float64, and whether every value is finite; if not, the first bad (x, f(x)) goes to bad[0:2]."""
    y = np.asarray(f(x), dtype=np.float64)
    i = _first_non_finite(y)
    if i >= 0:
        bad[0] = x[i]
        bad[1] = y[i]
    return y, i < 0


@njit(cache=False)  # f is an argument: one specialisation per f, not cached across sessions
def _search_jit(f, mode, lo, hi, t, px, py, iterations, x_out, v_out, bad_x):
    """The whole search with a numba-jitted f, in one compiled call. Returns 0, or 1 when f returned a non-finite
    value (the abscissa in bad_x[0])."""
    n = lo.shape[0]
    s = t.shape[0]
    xs = np.empty(n * s)
    _sample_grid(lo, hi, t, xs)
    ys, ok = _evaluate_jit(f, xs, bad_x)
    if not ok:
        return 1
    best_x = np.empty(n)
    best = np.empty(n)
    a = np.empty(n)
    b = np.empty(n)
    cd = np.empty(2 * n)
    gc = np.empty(n)
    gd = np.empty(n)
    _best_samples(mode, xs, ys, px, py, s, best_x, best, a, b, cd)
    for it in range(iterations + 1):
        ycd, ok = _evaluate_jit(f, cd, bad_x)
        if not ok:
            return 1
        _golden_step(mode, cd, ycd, px, py, a, b, gc, gd, it == iterations)
    _golden_finish(cd, gc, gd, best_x, best, x_out, v_out)
    return 0


def _is_jitted(f) -> bool:
    from numba.core.registry import CPUDispatcher

    return isinstance(f, CPUDispatcher)


def _minimize_on_intervals(f, mode, lo, hi, px, py, samples: int, iterations: int = GOLDEN_ITERATIONS):
    """min over x in [lo_i, hi_i] of g_i(x) for every i (g by ``mode``, from f): ``(x (n,), g (n,))``."""
    n = lo.shape[0]
    t = np.linspace(0.0, 1.0, samples)
    x_out = np.empty(n)
    v_out = np.empty(n)
    if _is_jitted(f):
        bad = np.empty(2)
        if _search_jit(f, mode, lo, hi, t, px, py, iterations, x_out, v_out, bad):
            raise ValueError(f"f returned a non-finite value {float(bad[1])!r} at x = {float(bad[0])!r}")
        return x_out, v_out
    xs = np.empty(n * samples)
    _sample_grid(lo, hi, t, xs)
    ys = _evaluate(f, xs)
    best_x, best, a, b = np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    cd = np.empty(2 * n)
    gc, gd = np.empty(n), np.empty(n)
    _best_samples(mode, xs, ys, px, py, samples, best_x, best, a, b, cd)
    for it in range(iterations + 1):  # one vectorised call of f per iteration, for every bracket at once
        _golden_step(mode, cd, _evaluate(f, cd.copy()), px, py, a, b, gc, gd, it == iterations)
    _golden_finish(cd, gc, gd, best_x, best, x_out, v_out)
    return x_out, v_out


#: the most samples per interval of the curve searches (each shape gets a grid of this many points)
MAX_SAMPLES = 2**20


def _check_samples(samples) -> int:
    return as_count(samples, "samples", 2, MAX_SAMPLES)


def max_on_intervals(f, lo_x, hi_x, *, samples: int = 64):
    """The maximum of f over each interval [lo_x[i], hi_x[i]], for every i at once.

    Robust for continuous f: ``samples`` evenly spaced evaluations per interval (one vectorised call of f for all
    intervals), then a golden-section refinement (Kiefer 1953, ``GOLDEN_ITERATIONS`` iterations) around the best
    sample, one vectorised call per iteration; with a numba-jitted f the whole search is one compiled call. A peak
    narrower than the sample spacing may be missed: raise ``samples`` for wiggly curves.

    Parameters
    ----------
    f : callable
        Vectorised: ``f(x)`` for a float64 array x returns finite values of x's shape (or a scalar). A numba
        ``@njit`` function is called from compiled code.
    lo_x, hi_x : array_like, shape (n,), float64
        The intervals, ``lo_x <= hi_x``.
    samples : int, default 64
        Evaluations per interval, 2 to ``MAX_SAMPLES``.

    Returns
    -------
    x_at_max : numpy.ndarray, shape (n,), float64
        Where the maximum is reached (the first best sample on ties).
    f_max : numpy.ndarray, shape (n,), float64
        The maximum, ``f(x_at_max)``.

    Raises
    ------
    TypeError
        When ``f`` is not callable.
    ValueError
        For ``lo_x > hi_x`` (named with its index), ``samples`` out of range, or f returning a wrong shape or a
        non-finite value (named with its x).
    """
    lo_x = as_float_array(lo_x, "lo_x", ndim=1)
    hi_x = as_float_array(hi_x, "hi_x", shape=lo_x.shape)
    samples = _check_samples(samples)
    check_callable(f, "f", "a vectorised callable")
    if (lo_x > hi_x).any():
        i = int(np.argmax(lo_x > hi_x))
        raise ValueError(f"lo_x must be <= hi_x: lo_x[{i}] = {float(lo_x[i])!r} > hi_x[{i}] = {float(hi_x[i])!r}")
    if lo_x.shape[0] == 0:
        return np.empty(0), np.empty(0)
    zero = np.zeros(lo_x.shape[0])
    x, v = _minimize_on_intervals(f, _MAXIMIZE, lo_x, hi_x, zero, zero, samples)
    return x, -v


def overlap_aabb_curve_bottom_middle(lo, hi, f):
    """The slide's test of boxes against the ground y <= f(x): only the bottom-middle point is tested.

    Slide "Sol courbe": at x = (lo_x + hi_x) / 2, contact iff ``f(x) >= lo_y``. One vectorised call of f; fast, but
    it misses a box whose corner dips under a bump of the curve (``overlap_aabb_curve`` is exact).

    Parameters
    ----------
    lo, hi : array_like, shape (n, d), float64
        Box corners, d = 2 or 3, ``lo <= hi``.
    f : callable
        The ground's height, vectorised (see ``max_on_intervals``).

    Returns
    -------
    numpy.ndarray, shape (n,), bool
    """
    lo, hi = _boxes(lo, hi, "lo", "hi", dims=(2, 3))
    x = 0.5 * (lo[:, 0] + hi[:, 0])
    return _evaluate(f, x) >= lo[:, UP]


def overlap_aabb_curve(lo, hi, f, *, samples: int = 64):
    """Exact test of boxes against the solid region y <= f(x): contact iff ``lo_y <= max f over [lo_x, hi_x]``.

    Parameters
    ----------
    lo, hi : array_like, shape (n, d), float64
        Box corners, d = 2 or 3, ``lo <= hi``.
    f : callable
        The ground's height, vectorised and continuous (see ``max_on_intervals``).
    samples : int, default 64
        Samples per box before the refinement.

    Returns
    -------
    numpy.ndarray, shape (n,), bool
    """
    lo, hi = _boxes(lo, hi, "lo", "hi", dims=(2, 3))
    samples = _check_samples(samples)
    if lo.shape[0] == 0:
        return np.empty(0, np.bool_)
    _, fmax = max_on_intervals(f, lo[:, 0], hi[:, 0], samples=samples)
    return fmax >= lo[:, UP]


def min_distance_to_curve(points, f, half_width, *, samples: int = 64):
    """Smallest distance from each point to the graph of f over the window ``|x − p_x| <= half_width``.

    Minimises ``(x − p_x)² + (f(x) − p_y)²`` by sampling and golden-section refinement, every point at once (the
    search of ``max_on_intervals``).

    Parameters
    ----------
    points : array_like, shape (n, 2), float64
        The points (x, y).
    f : callable
        The curve y = f(x), vectorised.
    half_width : float or array_like, shape (n,)
        Half the width of each point's search window, >= 0.
    samples : int, default 64
        Samples per window.

    Returns
    -------
    distance : numpy.ndarray, shape (n,), float64
        The smallest distance found.
    x_closest : numpy.ndarray, shape (n,), float64
        The abscissa of the closest point of the curve.

    Raises
    ------
    TypeError
        When ``f`` is not callable.
    ValueError
        For a negative ``half_width``, ``samples`` out of range, or a non-finite value of f.
    """
    p = as_float_array(points, "points", shape=(None, 2))
    w = as_radii(half_width, "half_width", p.shape[0])
    samples = _check_samples(samples)
    check_callable(f, "f", "a vectorised callable")
    if p.shape[0] == 0:
        return np.empty(0), np.empty(0)
    px = np.ascontiguousarray(p[:, 0])
    py = np.ascontiguousarray(p[:, 1])
    x, d2 = _minimize_on_intervals(f, _DISTANCE, px - w, px + w, px, py, samples)
    return np.sqrt(d2), x


def overlap_circle_curve(centers, radii, f, *, samples: int = 64):
    """Exact test of circles against the solid region y <= f(x), f continuous.

    Contact iff the centre is under the curve, or the curve passes within the radius; the closest point then has
    ``|x − c_x| <= r``, so the minimum of the true distance over that window decides (``min_distance_to_curve``).

    Parameters
    ----------
    centers : array_like, shape (n, 2), float64
        Circle centres (x, y).
    radii : array_like, shape (n,) or scalar
        Their radii, >= 0 (one for all, or one each).
    f : callable
        The ground's height, vectorised.
    samples : int, default 64
        Samples per circle.

    Returns
    -------
    numpy.ndarray, shape (n,), bool
    """
    c, r = _balls(centers, radii, 2)
    samples = _check_samples(samples)
    if c.shape[0] == 0:
        return np.empty(0, np.bool_)
    below = _evaluate(f, c[:, 0].copy()) >= c[:, UP]
    dist, _ = min_distance_to_curve(c, f, r, samples=samples)
    return below | (dist <= r)
