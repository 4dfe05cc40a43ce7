"""Bounding sphere (chapter slides "Sphère englobante" and "Volumes englobants: bounding sphere": the minimal
sphere holding the object; 4 scalars; collision iff d < r_A + r_B, about 11 primitive operations; trivial to
update under rotation). Ericson, *Real-Time Collision Detection*, sections 4.3 (fits) and 6.5.2 (merge).

Two fits:

- ``ritter_sphere`` — Ritter's fast approximate fit (Ericson 4.3.2), O(n), within ~5-20 % of minimal;
- ``min_bounding_sphere`` — Welzl's exact minimal sphere (Ericson 4.3.5), written as the iterative
  move-to-front form on a seeded random order (expected O(n)), with exact circumsphere formulas for 1 to 4
  support points and a fall-back for collinear / coplanar supports, so duplicates never produce NaN.

Points are (n, d) with d = 2 (circles) or 3. Both fits finish by setting the radius to the largest distance
from the centre to a point, raised by the ulps round-off needs, so that ``sphere_contains(center, radius, points)``
is True for every point of the cloud (its ``|p - c|^2 <= r^2`` rounds either way on a boundary point otherwise).
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .._config import njit
from .._validate import as_float_array, as_nonnegative, unit_scale_exponent
from .aabb import as_clouds, as_points, as_rigid_transform

__all__ = [
    "ritter_sphere",
    "ritter_spheres",
    "min_bounding_sphere",
    "overlap_sphere_sphere",
    "overlap_spheres",
    "merge_spheres",
    "sphere_contains",
    "transform_sphere",
]

#: a point is "outside" the current Welzl ball when |p - c|^2 > r^2 (1 + OUTSIDE_REL) + (OUTSIDE_ABS scale)^2
OUTSIDE_REL = 1e-12
OUTSIDE_ABS = 1e-15


# ---------------------------------------------------------------------------------------------------------
# Ritter (Ericson 4.3.2)
# ---------------------------------------------------------------------------------------------------------
@njit
def _ritter_kernel(points, center):
    """Ritter's sphere of points (n, d); writes the centre, returns the radius."""
    n, d = points.shape
    # 1. the most separated pair among the 2d extreme points along the axes
    best = -1.0
    ia = 0
    ib = 0
    for k in range(d):
        imin = 0
        imax = 0
        for i in range(1, n):
            if points[i, k] < points[imin, k]:
                imin = i
            if points[i, k] > points[imax, k]:
                imax = i
        dist2 = 0.0
        for m in range(d):
            dist2 += (points[imax, m] - points[imin, m]) ** 2
        if dist2 > best:
            best = dist2
            ia = imin
            ib = imax
    # 2. the sphere on that pair as diameter
    for m in range(d):
        center[m] = 0.5 * (points[ia, m] + points[ib, m])
    r = 0.5 * math.sqrt(best)
    # 3. one pass: grow the sphere just enough to hold each outside point
    for i in range(n):
        dist2 = 0.0
        for m in range(d):
            dist2 += (points[i, m] - center[m]) ** 2
        if dist2 > r * r:
            dist = math.sqrt(dist2)
            new_r = 0.5 * (r + dist)
            step = (new_r - r) / dist
            for m in range(d):
                center[m] += step * (points[i, m] - center[m])
            r = new_r
    # 4. the exact radius about that centre (never larger; holds every point despite round-off)
    r2 = 0.0
    for i in range(n):
        dist2 = 0.0
        for m in range(d):
            dist2 += (points[i, m] - center[m]) ** 2
        r2 = max(r2, dist2)
    return math.sqrt(r2)


@njit
def _ritter_batch_kernel(clouds, centers, radii):
    for c in range(clouds.shape[0]):
        radii[c] = _ritter_kernel(clouds[c], centers[c])


# ---------------------------------------------------------------------------------------------------------
# Welzl (Ericson 4.3.5), iterative move-to-front form, in 3-D (2-D input is embedded at z = 0)
# ---------------------------------------------------------------------------------------------------------
@njit
def _dist2(p, c):
    return (p[0] - c[0]) ** 2 + (p[1] - c[1]) ** 2 + (p[2] - c[2]) ** 2


@njit
def _ball2(a, b, c):
    """Smallest ball with a and b on its boundary (the diametral ball); writes c, returns r^2."""
    for m in range(3):
        c[m] = 0.5 * (a[m] + b[m])
    return max(_dist2(a, c), _dist2(b, c))


@njit
def _cross(u, v):
    return np.array([u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]])


@njit
def _ball3(a, b, p, c):
    """Smallest ball with a, b, p on its boundary: the triangle's circumsphere, centre in its plane.

    c = p + ((|u|^2 v - |v|^2 u) x (u x v)) / (2 |u x v|^2) with u = a - p, v = b - p. For a (near-)collinear
    triple the circumcircle does not exist: return the diametral ball of the farthest pair, which is then
    the smallest ball holding all three (no NaN).
    """
    u = a - p
    v = b - p
    w = _cross(u, v)
    w2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2]
    uu = u[0] * u[0] + u[1] * u[1] + u[2] * u[2]
    vv = v[0] * v[0] + v[1] * v[1] + v[2] * v[2]
    if w2 <= 1e-20 * uu * vv:
        tmp = np.empty(3)
        best = -1.0
        pairs = ((a, b), (a, p), (b, p))
        for q in pairs:
            r2 = _ball2(q[0], q[1], tmp)
            if r2 > best:
                best = r2
                c[:] = tmp
        return best
    num = _cross(uu * v - vv * u, w)
    for m in range(3):
        c[m] = p[m] + num[m] / (2.0 * w2)
    return max(_dist2(a, c), _dist2(b, c), _dist2(p, c))


@njit
def _holds(q, c, r2):
    return _dist2(q, c) <= r2 * (1.0 + 1e-10)


@njit
def _best_conditioned_corner(pts):
    """The corner i of the tetrahedron pts (4, 3) with the smallest product of its three edge lengths.

    The volume u.(v x w) is the same from every corner; dividing by the product |u||v||w| of the edges that
    leave the chosen corner, the circumcentre formula of _ball4 is best conditioned from the corner whose
    edges are shortest (an apex far above a tiny triangle: one of the triangle's corners, not the apex).
    """
    best = 0
    best_product = np.inf
    for i in range(4):
        product = 1.0
        for j in range(4):
            if j != i:
                product *= math.sqrt(_dist2(pts[j], pts[i]))
        if product < best_product:
            best_product = product
            best = i
    return best


@njit
def _ball4(a, b, p, q, c):
    """Smallest ball with a, b, p, q on its boundary: the tetrahedron's circumsphere.

    Relative to the best-conditioned corner o, with u, v, w the edges to the other three:
    x = o + (|u|^2 (v x w) + |v|^2 (w x u) + |w|^2 (u x v)) / (2 u.(v x w)). For a (near-)coplanar quadruple
    the circumsphere does not exist: return the smallest of the 2- and 3-point balls that holds all four.
    """
    pts = np.empty((4, 3))
    pts[0] = a
    pts[1] = b
    pts[2] = p
    pts[3] = q
    o = _best_conditioned_corner(pts)
    u = pts[(o + 1) % 4] - pts[o]
    v = pts[(o + 2) % 4] - pts[o]
    w = pts[(o + 3) % 4] - pts[o]
    vw = _cross(v, w)
    det = u[0] * vw[0] + u[1] * vw[1] + u[2] * vw[2]
    lu = math.sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2])
    lv = math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    lw = math.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
    if abs(det) > 1e-10 * lu * lv * lw:
        wu = _cross(w, u)
        uv = _cross(u, v)
        for m in range(3):
            c[m] = pts[o, m] + (lu * lu * vw[m] + lv * lv * wu[m] + lw * lw * uv[m]) / (2.0 * det)
        return max(_dist2(a, c), _dist2(b, c), _dist2(p, c), _dist2(q, c))
    # degenerate: try every ball on 2 or 3 of the points, keep the smallest holding all four
    tmp = np.empty(3)
    best = np.inf
    for i in range(4):
        for j in range(i + 1, 4):
            for k in range(j, 4):
                if k == j:
                    r2 = _ball2(pts[i], pts[j], tmp)
                else:
                    r2 = _ball3(pts[i], pts[j], pts[k], tmp)
                if r2 < best and _holds(a, tmp, r2) and _holds(b, tmp, r2) and _holds(p, tmp, r2) \
                        and _holds(q, tmp, r2):
                    best = r2
                    c[:] = tmp
    if best == np.inf:  # cannot happen for 4 coplanar points (their minimal disc has 2 or 3 support points)
        _ball3(a, b, p, c)
    # r^2 about the centre kept: the largest of the four (_holds let a point sit outside by round-off)
    return max(_dist2(a, c), _dist2(b, c), _dist2(p, c), _dist2(q, c))


@njit
def _move_to_front(order, k):
    """Move order[k] to position 0, shifting order[0:k] one step right (Gärtner's move-to-front)."""
    x = order[k]
    for m in range(k, 0, -1):
        order[m] = order[m - 1]
    order[0] = x


@njit
def _welzl_kernel(points, tol_abs2):
    """Exact minimal ball of points (n, 3), visited in the given (already shuffled) order.

    Welzl's recursion unrolled into four nested loops, as in de Berg et al.'s MiniDisc extended to 3-D:
        for i: if p_i outside B:  B = ball({p_i});           for j < i: if p_j outside B:
               B = ball(p_i, p_j);  for k < j: if p_k outside B:  B = ball(p_i, p_j, p_k);
               for l < k: if p_l outside B: B = ball(p_i, p_j, p_k, p_l)
    Each level moves the point that forced a new ball to the front of the list (move-to-front).
    Returns (centre (3,), radius^2 before the final exact re-measure).
    """
    n = points.shape[0]
    order = np.arange(n)
    c = points[0].copy()
    r2 = 0.0
    for i in range(1, n):
        pi = points[order[i]]
        if _dist2(pi, c) <= r2 * (1.0 + 1e-12) + tol_abs2:
            continue
        c[:] = pi
        r2 = 0.0
        for j in range(i):
            pj = points[order[j]]
            if _dist2(pj, c) <= r2 * (1.0 + 1e-12) + tol_abs2:
                continue
            r2 = _ball2(pi, pj, c)
            for k in range(j):
                pk = points[order[k]]
                if _dist2(pk, c) <= r2 * (1.0 + 1e-12) + tol_abs2:
                    continue
                r2 = _ball3(pi, pj, pk, c)
                for m in range(k):
                    pm = points[order[m]]
                    if _dist2(pm, c) <= r2 * (1.0 + 1e-12) + tol_abs2:
                        continue
                    r2 = _ball4(pi, pj, pk, pm, c)
                    _move_to_front(order, m)
                _move_to_front(order, k)
            _move_to_front(order, j)
        _move_to_front(order, i)
    return c, r2


@njit
def _max_dist(points, c):
    r2 = 0.0
    for i in range(points.shape[0]):
        r2 = max(r2, _dist2(points[i], c))
    return math.sqrt(r2)


# ---------------------------------------------------------------------------------------------------------
# overlap, containment
# ---------------------------------------------------------------------------------------------------------
@njit
def spheres_touch(ca, ra, cb, rb):
    """Whether the closed spheres (ca (d,), ra) and (cb (d,), rb) overlap: the engine's one sphere–sphere test.

    Slide "Bounding sphere — tester: collision ssi d < r_A + r_B" (closed here: touching counts), the square
    root avoided: ``|c_a - c_b|² <= (r_a + r_b)²`` — in 3-D 3 subtractions, 3 products, 3 additions, 1 addition,
    1 product and 1 comparison: the slide's ~11 operations. Squares of magnitudes below ~1e-154 underflow and
    above ~1e154 overflow, so when the largest of the components of c_a − c_b and r_a + r_b lies outside
    [1e-150, 1e150] the same test is made on values divided by the power of two that brings that largest
    magnitude into [0.5, 1) (exact: a pair exactly touching touches at every scale).
    """
    s = ra + rb
    dist2 = 0.0
    big = s
    for m in range(ca.shape[0]):
        dx = ca[m] - cb[m]
        dist2 += dx * dx
        big = max(big, abs(dx))
    if big == 0.0 or 1e-150 < big < 1e150:
        return dist2 <= s * s
    # divided by a power of two near big (exact), so the test decides as it would without underflow / overflow
    e = -math.frexp(big)[1]
    scaled = 0.0
    for m in range(ca.shape[0]):
        dx = math.ldexp(ca[m] - cb[m], e)
        scaled += dx * dx
    t = math.ldexp(s, e)
    return scaled <= t * t


@njit
def _overlap_spheres_kernel(ca, ra, cb, rb, out):
    for i in range(ca.shape[0]):
        out[i] = spheres_touch(ca[i], ra[i], cb[i], rb[i])


# ---------------------------------------------------------------------------------------------------------
# public functions
# ---------------------------------------------------------------------------------------------------------
def _scaled_square_gaps(points: np.ndarray, centers: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """|p - c|^2 / 4^e for clouds (m, n, d) about centres (m, d), and the exponents e (m,) with
    |p - c| / 2^e < 1 (_validate.unit_scale_exponent): the squares neither underflow nor overflow, and the
    containment test |p - c|^2 <= r^2 on them is the same at every scale (:func:`sphere_contains`)."""
    gaps = points - centers[:, None, :]
    e = unit_scale_exponent(gaps, axis=(1, 2))
    return (np.ldexp(gaps, -e[:, None, None]) ** 2).sum(axis=2), e


def _radii_holding(clouds: np.ndarray, centers: np.ndarray, radii: np.ndarray) -> np.ndarray:
    """The radii (m,) raised by the fewest ulps with which :func:`sphere_contains` holds every point of each
    cloud (m, n, d) about its centre (m, d): re-measured in the cloud's own frame, a radius rounds either way.

    On the scaled squares (the largest in [1/4, 3)), r is raised to the square root of the next target until
    r * r reaches the largest square: one or two ulps."""
    squares, e = _scaled_square_gaps(clouds, centers)
    need = squares.max(axis=1, initial=0.0)
    scaled = np.ldexp(radii, -e)
    target = need.copy()
    short = scaled * scaled < need
    while short.any():
        scaled[short] = np.maximum(scaled[short], np.sqrt(target[short]))
        target[short] = np.nextafter(target[short], np.inf)
        short = scaled * scaled < need
    return np.ldexp(scaled, e)


def _radius_holding(points: np.ndarray, center: np.ndarray, radius: float) -> float:
    """:func:`_radii_holding` for one cloud (n, d)."""
    return float(_radii_holding(points[None], center[None], np.array([radius]))[0])


def _unit_local_frame(pts: np.ndarray) -> tuple[np.ndarray, np.ndarray, int]:
    """The points (n, d) as the 3-D rows (n, 3) the Welzl kernels take (2-D at z = 0), scaled by 2^-e to
    |coordinates| < 1 (exact: see _validate.unit_scale_exponent) and taken relative to their centroid
    ``origin`` (better conditioned circumsphere formulas): a point x is ``2^e (local[:d] + origin)``."""
    n, d = pts.shape
    e = int(unit_scale_exponent(pts))
    unit = np.ldexp(pts, -e)
    origin = unit.mean(axis=0)
    local = np.zeros((n, 3))
    local[:, :d] = unit - origin
    return local, origin, e


def ritter_sphere(points: ArrayLike) -> tuple[np.ndarray, float]:
    """Ritter's fast bounding sphere (Ericson 4.3.2): O(n), typically 5-20 % larger than the minimal one.

    The most separated pair among the extreme points along the axes gives a first sphere, grown in one pass
    just enough to hold each point outside it; the radius is then re-measured about the final centre, so every
    point lies in the sphere: :func:`sphere_contains` is True for every point (the radius is raised by an ulp
    or two where round-off needs it). The answer scales exactly: for a cloud scaled by a power of two 2^k
    (coordinates and their squares kept normal floats) the centre and radius are the original ones times 2^k,
    bit for bit.

    Parameters
    ----------
    points : array_like, shape (n, d)
        The cloud, d = 2 (a circle) or 3, see :ref:`bounding-arguments`.

    Returns
    -------
    center : numpy.ndarray, shape (d,), float64
    radius : float
    """
    pts = as_points(points)
    e = int(unit_scale_exponent(pts))
    center = np.empty(pts.shape[1])
    r = _ritter_kernel(np.ldexp(pts, -e), center)
    center = np.ldexp(center, e)
    return center, _radius_holding(pts, center, float(np.ldexp(r, e)))


def ritter_spheres(clouds: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Batched :func:`ritter_sphere`: one sphere per cloud of ``clouds`` (m, n, d), in one compiled call.

    ``clouds`` as in :ref:`bounding-arguments`.

    Returns
    -------
    centers : numpy.ndarray, shape (m, d), float64
    radii : numpy.ndarray, shape (m,), float64
    """
    arr = as_clouds(clouds)
    e = unit_scale_exponent(arr, axis=(1, 2))
    centers = np.empty((arr.shape[0], arr.shape[2]))
    radii = np.empty(arr.shape[0])
    _ritter_batch_kernel(np.ldexp(arr, -e[:, None, None]), centers, radii)
    centers = np.ldexp(centers, e[:, None])
    return centers, _radii_holding(arr, centers, np.ldexp(radii, e))


def min_bounding_sphere(points: ArrayLike, *, seed: int = 0) -> tuple[np.ndarray, float]:
    """The exact smallest sphere (circle in 2-D) holding a point cloud: Welzl's algorithm (Ericson 4.3.5).

    The iterative move-to-front form, expected O(n) on a random order. Duplicates, collinear and coplanar
    points are fine (no NaN); the radius is re-measured about the centre found, so every point lies in the
    sphere: :func:`sphere_contains` is True for every point (the radius is raised by an ulp or two where
    round-off needs it). The answer scales exactly: for a cloud scaled by a power of two 2^k (coordinates and
    their squares kept normal floats) the centre and radius are the original ones times 2^k, bit for bit.

    Parameters
    ----------
    points : array_like, shape (n, d)
        The cloud, see :ref:`bounding-arguments`.
    seed : int, optional
        Seeds the random visiting order; fixed by default, so results are deterministic.

    Returns
    -------
    center : numpy.ndarray, shape (d,), float64
    radius : float

    Raises
    ------
    TypeError
        For a ``seed`` that is not an int.

    Examples
    --------
    >>> from engine.bounding import min_bounding_sphere
    >>> center, radius = min_bounding_sphere([[0.0, 0.0], [2.0, 0.0], [1.0, 0.5]])
    >>> center.tolist(), radius
    ([1.0, 0.0], 1.0)
    """
    pts = as_points(points)
    if not isinstance(seed, int | np.integer) or isinstance(seed, bool):
        raise TypeError(f"seed must be an integer, got {type(seed).__name__}")
    n, d = pts.shape
    local, origin, e = _unit_local_frame(pts)
    local = local[np.random.default_rng(seed).permutation(n)]
    scale = float(np.abs(local).max()) if n else 0.0
    c, _ = _welzl_kernel(local, (OUTSIDE_ABS * scale) ** 2)
    # exact radius about the centre found: every point is inside by construction
    r = _max_dist(local, c)
    center = np.ldexp(c[:d] + origin, e)
    return center, _radius_holding(pts, center, float(np.ldexp(r, e)))


def circumsphere(points: ArrayLike) -> tuple[np.ndarray, float]:
    """The smallest sphere (circle in 2-D) with every one of 2 to 4 points on its boundary: the balls Welzl's
    algorithm is built from (Ericson 4.3.5).

    Two points give the sphere on them as diameter; three, the circumsphere of their triangle (centre in its
    plane: the circumcircle in 2-D); four, the circumsphere of their tetrahedron. Degenerate points have no
    such sphere: for three collinear points (or a triangle flat to round-off, sin of its angles ~1e-10) and
    four coplanar ones (in 2-D, any four) the answer is instead the smallest sphere holding them all, which
    then has 2 or 3 of them on its boundary. Never NaN; the answer scales exactly with a power of two, as
    :func:`min_bounding_sphere`'s.

    Parameters
    ----------
    points : array_like, shape (k, d)
        2 <= k <= 4 points, d = 2 or 3, see :ref:`bounding-arguments`; duplicates are allowed.

    Returns
    -------
    center : numpy.ndarray, shape (d,), float64
    radius : float
        The distance from ``center`` to the farthest of the points, raised by an ulp or two where round-off
        needs it, so that :func:`sphere_contains` is True for every point.

    Examples
    --------
    >>> from engine.bounding import circumsphere
    >>> center, radius = circumsphere([[0.0, 0.0], [2.0, 0.0], [0.0, 2.0]])
    >>> center.tolist(), round(radius, 12)
    ([1.0, 1.0], 1.414213562373)
    """
    pts = as_points(points, min_rows=2)
    if pts.shape[0] > 4:
        raise ValueError(f"points must have 2 to 4 rows (the sphere's boundary points), got {pts.shape[0]}")
    local, origin, e = _unit_local_frame(pts)
    c = np.empty(3)
    if pts.shape[0] == 2:
        r2 = _ball2(local[0], local[1], c)
    elif pts.shape[0] == 3:
        r2 = _ball3(local[0], local[1], local[2], c)
    else:
        r2 = _ball4(local[0], local[1], local[2], local[3], c)
    center = np.ldexp(c[:pts.shape[1]] + origin, e)
    return center, _radius_holding(pts, center, float(np.ldexp(math.sqrt(r2), e)))


def overlap_spheres(centers_a: ArrayLike, radii_a: ArrayLike, centers_b: ArrayLike,
                    radii_b: ArrayLike) -> np.ndarray:
    """Row-wise overlap of closed spheres: ``|c_a - c_b| <= r_a + r_b`` for every row, in one compiled call.

    The slide's test with the square root avoided (touching counts); C-contiguous float64 inputs are read
    without a copy (and never written).

    Parameters
    ----------
    centers_a : array_like, shape (n, d)
        The centres of the spheres a_i, finite.
    radii_a : array_like, shape (n,)
        Their radii, >= 0.
    centers_b : array_like, shape (n, d)
        The centres of the spheres b_i, of the shape of ``centers_a``.
    radii_b : array_like, shape (n,)
        Their radii, >= 0.

    Returns
    -------
    numpy.ndarray, shape (n,), bool
    """
    if _is_plain_spheres(centers_a, radii_a, centers_b, radii_b):
        # fast path: checked in a compiled loop and read without a copy (the kernel never writes its inputs)
        out = np.empty(np.shape(centers_a)[0], dtype=np.bool_)
        _overlap_spheres_kernel(centers_a, radii_a, centers_b, radii_b, out)
        return out
    ca = as_float_array(centers_a, "centers_a", ndim=2)
    cb = as_float_array(centers_b, "centers_b", shape=ca.shape)
    ra = as_float_array(radii_a, "radii_a", shape=(ca.shape[0],))
    rb = as_float_array(radii_b, "radii_b", shape=(ca.shape[0],))
    for name, r in (("radii_a", ra), ("radii_b", rb)):
        if (r < 0).any():
            k = int(np.argmax(r < 0))
            raise ValueError(f"{name} must be >= 0: {name}[{k}] = {float(r[k])!r}")
    out = np.empty(ca.shape[0], dtype=np.bool_)
    _overlap_spheres_kernel(ca, ra, cb, rb, out)
    return out


@njit
def _spheres_valid_kernel(centers, radii):
    n, d = centers.shape
    for i in range(n):
        if not (math.isfinite(radii[i]) and radii[i] >= 0.0):
            return False
        for m in range(d):
            if not math.isfinite(centers[i, m]):
                return False
    return True


def _is_plain_spheres(ca: Any, ra: Any, cb: Any, rb: Any) -> bool:
    plain = all(isinstance(a, np.ndarray) and a.dtype == np.float64 and a.flags.c_contiguous
                for a in (ca, ra, cb, rb))
    return (plain and ca.ndim == 2 and cb.shape == ca.shape and ra.shape == (ca.shape[0],)
            and rb.shape == ra.shape and _spheres_valid_kernel(ca, ra) and _spheres_valid_kernel(cb, rb))


def _two_spheres(center_a: ArrayLike, radius_a: float, center_b: ArrayLike,
                 radius_b: float) -> tuple[np.ndarray, float, np.ndarray, float]:
    """The checked spheres a and b of the two-sphere functions (centres (d,) of one shape, radii >= 0)."""
    ca = as_float_array(center_a, "center_a", ndim=1)
    cb = as_float_array(center_b, "center_b", shape=ca.shape)
    return ca, as_nonnegative(radius_a, "radius_a"), cb, as_nonnegative(radius_b, "radius_b")


def overlap_sphere_sphere(center_a: ArrayLike, radius_a: float, center_b: ArrayLike, radius_b: float) -> bool:
    """Whether two closed spheres a and b overlap (touching counts), as :func:`overlap_spheres`.

    The spheres' arguments are those of every two-sphere function: :ref:`bounding-arguments`.

    Returns
    -------
    bool
    """
    ca, ra, cb, rb = _two_spheres(center_a, radius_a, center_b, radius_b)
    out = np.empty(1, dtype=np.bool_)
    _overlap_spheres_kernel(ca[None], np.array([ra]), cb[None], np.array([rb]), out)
    return bool(out[0])


def merge_spheres(center_a: ArrayLike, radius_a: float, center_b: ArrayLike,
                  radius_b: float) -> tuple[np.ndarray, float]:
    """The smallest sphere holding spheres a and b (Ericson 6.5.2); one of them when it holds the other.

    ``center_a, radius_a, center_b, radius_b`` as in :ref:`bounding-arguments`.

    Returns
    -------
    center : numpy.ndarray, shape (d,), float64
    radius : float
        Widened by round-off if needed, so that it holds both spheres. Computed on the spheres scaled by a power
        of two, so the merge of spheres far below unit size is not lost to underflow.
    """
    ca, ra, cb, rb = _two_spheres(center_a, radius_a, center_b, radius_b)
    # on the spheres scaled by an exact power of two (|values| < 1): |cb - ca|^2 does not underflow
    e = int(unit_scale_exponent(np.concatenate([ca, cb, [ra, rb]])))
    ca, ra, cb, rb = np.ldexp(ca, -e), math.ldexp(ra, -e), np.ldexp(cb, -e), math.ldexp(rb, -e)
    delta = cb - ca
    dist = float(np.sqrt(delta @ delta))
    if dist + rb <= ra:  # b inside a
        c, r = ca, ra
    elif dist + ra <= rb:  # a inside b
        c, r = cb, rb
    else:
        r = 0.5 * (dist + ra + rb)
        c = ca + ((r - ra) / dist) * delta
        # guard against round-off: the result must hold both spheres
        r = max(r, float(np.linalg.norm(c - ca)) + ra, float(np.linalg.norm(c - cb)) + rb)
    return np.ldexp(c, e), math.ldexp(r, e)


def sphere_contains(center: ArrayLike, radius: float, points: ArrayLike) -> np.ndarray:
    """Which points lie in a closed sphere (the boundary included): ``|p - c|² <= r²``.

    Evaluated on the gaps p - c and r scaled by a power of two (the largest gap below 1), so no square
    underflows or overflows and the answer is the same at every scale. The fits (:func:`min_bounding_sphere`,
    :func:`ritter_sphere`, :func:`circumsphere`) return spheres that this test says hold all their points.

    Parameters
    ----------
    center, radius : array_like, float
        The sphere, see :ref:`bounding-arguments`.
    points : array_like, shape (n, d)
        The points (n may be 0), finite.

    Returns
    -------
    numpy.ndarray, shape (n,), bool
    """
    c = as_float_array(center, "center", ndim=1)
    r = as_nonnegative(radius, "radius")
    pts = as_points(points, min_rows=0, dims=(c.shape[0],))
    squares, e = _scaled_square_gaps(pts[None], c[None])
    # on the scale of the gaps: a radius beyond 2^500 of it holds every point (its square would overflow)
    scaled = min(float(np.ldexp(r, -e[0])), 2.0**500)
    return squares[0] <= scaled * scaled


def transform_sphere(center: ArrayLike, radius: float, rotation: ArrayLike,
                     translation: ArrayLike) -> tuple[np.ndarray, float]:
    """The sphere after x -> rotation @ x + translation: only the centre moves (slide: "trivial to update").

    Parameters
    ----------
    center, radius : array_like, float
        The sphere, see :ref:`bounding-arguments`.
    rotation, translation : array_like, shapes (d, d) and (d,)
        The motion x -> R x + t, see :ref:`bounding-arguments`.

    Returns
    -------
    center : numpy.ndarray, shape (d,), float64
        ``rotation @ center + translation``.
    radius : float
        Unchanged.
    """
    c = as_float_array(center, "center", ndim=1)
    r = as_nonnegative(radius, "radius")
    rotation, translation = as_rigid_transform(rotation, translation, c.shape[0])
    return rotation @ c + translation, r
