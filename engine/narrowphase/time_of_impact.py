"""Time of impact: the "when" of the pipeline's last stage ("l'instant ... de contact").

``time_of_impact`` advances two convex shapes moving with constant linear and angular velocities (their motion:
engine.narrowphase.motion) by conservative advancement on the GJK distance (Mirtich 1996; Zhang, Lee, Kim 2006):
with d the distance and n the direction of the closest points, no contact can happen before d / μ where
μ = (v_A − v_B)·n + |ω_A| ρ_A + |ω_B| ρ_B bounds the closing speed (ρ = farthest vertex from the rotation centre).

    t <- 0
    repeat:
        d, n <- GJK distance (minus the radii) of the shapes posed at t
        if d <= tol: contact at t
        if μ <= 0 or t + d / μ > t_max: no contact before t_max
        t <- t + d / μ                        (never overshoots: the shapes cannot meet before)

Kernels (public within the package): ``toi_kernel`` (one pair, status of engine.narrowphase.status: OVERLAP for a
contact at t, SEPARATED for none before t_max, TOI_NOT_CONVERGED) and ``toi_pairs_kernel``.
"""
from __future__ import annotations

import math

import numpy as np

from .._config import njit
from .._validate import (
    as_float_array,
    as_max_iterations,
    as_nonnegative,
    as_positive,
    as_radii,
    check_offsets,
    check_pairs,
)
from .gjk import MAX_ITERATIONS, gjk_kernel, gjk_scratch
from .motion import pose_at
from .penetration import ONE_PAIR
from .status import GJK_NOT_CONVERGED, OVERLAP, SEPARATED, TOI_NOT_CONVERGED, TOINotConverged, raise_for_status

__all__ = ["TOINotConverged", "toi_kernel", "toi_pairs_kernel", "time_of_impact", "time_of_impact_pairs"]


@njit
def _spin_speed(points, center, spin):
    """|ω| ρ: the fastest a vertex of ``points`` (n, 3) moves by the rotation ``spin`` (3,) about ``center`` (3,)."""
    rho = 0.0
    for i in range(points.shape[0]):
        rho = max(rho, math.sqrt((points[i, 0] - center[0]) ** 2 + (points[i, 1] - center[1]) ** 2
                                 + (points[i, 2] - center[2]) ** 2))
    return math.sqrt(spin[0] ** 2 + spin[1] ** 2 + spin[2] ** 2) * rho


@njit
def toi_kernel(pa, ca, va, wa, ra, pb, cb, vb, wb, rb, t_max, tol, max_iter, scratch, poses, g, out):
    """Conservative advancement (Mirtich 1996) of hull(pa) ((n, 3) float64 at t = 0, swept by radius ``ra``,
    centre ``ca``, velocity ``va``, angular velocity ``wa``, all (3,)) against hull(pb) (likewise), over [0, t_max].

    Scratch: ``scratch`` from ``gjk_scratch`` and ``poses`` (2, >= max(n, m), 3) float64, ``g`` (7,). Writes
    ``out`` (4,): out[0] = t (inf when no contact), out[1:4] = the normal at t. Returns OVERLAP (contact at t),
    SEPARATED (none in [0, t_max]) or TOI_NOT_CONVERGED (its iteration cap, or that of the GJK it runs on)."""
    xa = poses[0, :pa.shape[0]]
    xb = poses[1, :pb.shape[0]]
    spin = _spin_speed(pa, ca, wa) + _spin_speed(pb, cb, wb)
    gjk_iterations = np.int64(MAX_ITERATIONS)  # an int64, not the literal 128: gjk_kernel is compiled once
    t = 0.0
    for _ in range(max_iter):
        pose_at(pa, ca, va, wa, t, xa)
        pose_at(pb, cb, vb, wb, t, xb)
        status, _ = gjk_kernel(xa, xb, gjk_iterations, scratch, g)
        if status == GJK_NOT_CONVERGED:
            return TOI_NOT_CONVERGED
        gap = g[6] - ra - rb
        for c in range(3):
            out[1 + c] = (g[3 + c] - g[c]) / g[6] if g[6] > 0.0 else 0.0
        if gap <= tol:
            out[0] = t
            return OVERLAP
        closing = spin
        for c in range(3):
            closing += (va[c] - vb[c]) * out[1 + c]
        if closing <= 0.0:
            out[0] = np.inf
            return SEPARATED
        t += gap / closing
        if t > t_max:
            out[0] = np.inf
            return SEPARATED
    out[0] = t
    return TOI_NOT_CONVERGED


@njit
def toi_pairs_kernel(points, offsets, centers, velocities, spins, radii, pairs, t_max, tol, max_iter, times, status):
    """``toi_kernel`` over k pairs of packed shapes (``points`` (N, 3), ``offsets`` (S + 1,); per shape ``centers``,
    ``velocities``, ``spins`` (S, 3) and ``radii`` (S,); ``pairs`` (k, 2)) in one compiled loop: times (k,) (inf for
    no contact before t_max) and status (k,) int64."""
    n_max = np.int64(1)  # typed int64 from the start: gjk_scratch is compiled for one size type
    for s in range(offsets.shape[0] - 1):
        n_max = max(n_max, offsets[s + 1] - offsets[s])
    scratch = gjk_scratch(n_max)
    poses = np.empty((2, n_max, 3))
    g = np.empty(7)
    out = np.empty(4)
    for p in range(pairs.shape[0]):
        i = pairs[p, 0]
        j = pairs[p, 1]
        status[p] = toi_kernel(points[offsets[i]:offsets[i + 1]], centers[i], velocities[i], spins[i], radii[i],
                               points[offsets[j]:offsets[j + 1]], centers[j], velocities[j], spins[j], radii[j],
                               t_max, tol, max_iter, scratch, poses, g, out)
        times[p] = out[0]


def _toi_batch(pts, off, cen, vel, spin, rad, pr, tm, tol, max_iter):
    """toi_pairs_kernel on validated arrays: (times (k,), status (k,))."""
    times = np.empty(pr.shape[0])
    status = np.empty(pr.shape[0], np.int64)
    if pr.shape[0]:
        toi_pairs_kernel(pts, off, cen, vel, spin, rad, pr, tm, tol, max_iter, times, status)
    return times, status


def _vec(value, name):
    """An optional (3,) vector (angular velocity, centre): None means zero."""
    return as_float_array(np.zeros(3) if value is None else value, name, shape=(3,))


def time_of_impact(points_a, velocity_a, points_b, velocity_b, *, t_max: float = 1.0,
                   angular_velocity_a=None, angular_velocity_b=None, center_a=None, center_b=None,
                   radius_a: float = 0.0, radius_b: float = 0.0, tol: float | None = None,
                   max_iterations: int = 256):
    """First time t in [0, t_max] at which two moving convex shapes touch, or None (conservative advancement).

    Mirtich's conservative advancement (1996): at the current t, GJK gives the gap d between the shapes and its
    direction n; no point of either shape can close the gap faster than the bound
    ``(v_a − v_b)·n + |ω_a| ρ_a + |ω_b| ρ_b`` (ρ: the farthest vertex from the rotation centre), so advancing t
    by d / bound never steps past the contact.
    It stops when the gap is below ``tol``, or when the shapes move apart or t passes ``t_max``.

    Parameters
    ----------
    points_a : array_like, shape (n, 3), float64
        The core of A at t = 0 (its convex hull), n >= 1, finite.
    velocity_a : array_like, shape (3,)
        A's constant linear velocity (required; no default of zero).
    points_b : array_like, shape (m, 3), float64
        The core of B at t = 0.
    velocity_b : array_like, shape (3,)
        B's constant linear velocity.
    t_max : float, default 1.0
        The end of the time window, >= 0.
    angular_velocity_a, angular_velocity_b : array_like, shape (3,), optional
        Constant angular velocities (rad per unit time, axis times rate); default zero.
    center_a, center_b : array_like, shape (3,), optional
        The points each shape spins about; default the mean of its points.
    radius_a, radius_b : float, default 0.0
        Each core is swept by a ball of this radius (a sphere is one point with a radius), >= 0.
    tol : float, optional
        The contact distance, > 0; default 1e-9 times the size of the shapes.
    max_iterations : int, default 256
        The cap on advancement steps, >= 1.

    Returns
    -------
    float or None
        t with the shapes at most ``tol`` apart and not touching before (up to that tolerance); None when they do
        not meet in [0, t_max].

    Raises
    ------
    ValueError
        For an empty or non-finite point set, a vector not of shape (3,), a negative radius or ``t_max``, or
        ``tol <= 0`` (each named).
    TOINotConverged
        After ``max_iterations`` advancement steps (or when the GJK it runs on does not converge).

    Examples
    --------
    A unit cube moving at speed 1 along x towards a cube whose near face is 2 away:

    >>> import numpy as np
    >>> import engine
    >>> cube = np.array([[x, y, z] for x in (0.0, 1.0) for y in (0.0, 1.0) for z in (0.0, 1.0)])
    >>> engine.time_of_impact(cube, [1.0, 0.0, 0.0], cube + [3.0, 0.0, 0.0], [0.0, 0.0, 0.0], t_max=5.0)
    2.0
    >>> engine.time_of_impact(cube, [1.0, 0.0, 0.0], cube + [3.0, 0.0, 0.0], [0.0, 0.0, 0.0], t_max=1.0) is None
    True
    """
    pa = as_float_array(points_a, "points_a", shape=(None, 3), min_rows=1)
    pb = as_float_array(points_b, "points_b", shape=(None, 3), min_rows=1)
    va = as_float_array(velocity_a, "velocity_a", shape=(3,))  # required: None is refused, not taken as zero
    vb = as_float_array(velocity_b, "velocity_b", shape=(3,))
    wa = _vec(angular_velocity_a, "angular_velocity_a")
    wb = _vec(angular_velocity_b, "angular_velocity_b")
    ca = pa.mean(axis=0) if center_a is None else _vec(center_a, "center_a")
    cb = pb.mean(axis=0) if center_b is None else _vec(center_b, "center_b")
    ra = as_nonnegative(radius_a, "radius_a")
    rb = as_nonnegative(radius_b, "radius_b")
    tm = as_nonnegative(t_max, "t_max")
    max_iter = as_max_iterations(max_iterations)
    if tol is None:
        size = max(np.ptp(pa, axis=0).max(), np.ptp(pb, axis=0).max(), ra, rb, 1e-300)
        tol = 1e-9 * size
    tol = as_positive(tol, "tol")
    off = np.array([0, pa.shape[0], pa.shape[0] + pb.shape[0]], np.int64)
    times, status = _toi_batch(np.concatenate([pa, pb]), off, np.stack([ca, cb]), np.stack([va, vb]),
                               np.stack([wa, wb]), np.array([ra, rb]), ONE_PAIR, tm, tol, max_iter)
    raise_for_status(status, max_iter)
    return None if status[0] == SEPARATED else float(times[0])


def time_of_impact_pairs(points, offsets, velocities, pairs, *, t_max: float = 1.0, angular_velocities=None,
                         centers=None, radii=None, tol: float = 1e-9, max_iterations: int = 256):
    """``time_of_impact`` for k pairs of packed moving shapes, in one compiled call.

    Parameters
    ----------
    points, offsets, pairs
        Shape s at t = 0 and the pairs: :ref:`packed-point-sets`.
    velocities : array_like, shape (S, 3), float64
        Linear velocity of each shape.
    t_max : float, default 1.0
        End of the window, >= 0.
    angular_velocities : array_like, shape (S, 3), optional
        Angular velocities; default zero.
    centers : array_like, shape (S, 3), optional
        Rotation centres; default each shape's mean point.
    radii : array_like, shape (S,), optional
        Sweeping radii, >= 0; default 0.
    tol : float, default 1e-9
        The contact distance (absolute), > 0.
    max_iterations : int, default 256
        Advancement steps per pair, >= 1.

    Returns
    -------
    numpy.ndarray, shape (k,), float64
        The time of impact of each pair; ``inf`` where it does not meet before ``t_max``.

    Raises
    ------
    TOINotConverged
        For the first pair (``pairs[p]``) that reaches ``max_iterations``.
    """
    pts = as_float_array(points, "points", shape=(None, 3))
    off = check_offsets(offsets, pts.shape[0])
    s = off.shape[0] - 1
    vel = as_float_array(velocities, "velocities", shape=(s, 3))
    spin = np.zeros((s, 3)) if angular_velocities is None else as_float_array(angular_velocities,
                                                                              "angular_velocities", shape=(s, 3))
    if centers is None:
        cen = np.add.reduceat(pts, off[:-1], axis=0) / np.diff(off)[:, None] if s else np.empty((0, 3))
    else:
        cen = as_float_array(centers, "centers", shape=(s, 3))
    rad = np.zeros(s) if radii is None else as_radii(radii, "radii", s, scalar=False)
    pr = check_pairs(pairs, s)
    tm = as_nonnegative(t_max, "t_max")
    tol = as_positive(tol, "tol")
    max_iter = as_max_iterations(max_iterations)
    times, status = _toi_batch(pts, off, cen, vel, spin, rad, pr, tm, tol, max_iter)
    raise_for_status(status, max_iter, "pairs")
    return times
