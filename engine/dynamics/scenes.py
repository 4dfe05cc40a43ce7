"""The chapter's two falling-body scenes: a particle falling on the ground, and a cube falling on the ground.

Slides "La particule qui chute sur le sol ... Application" (RK4 with drag, ground at Y = 0, detect and treat the
collision with V_après = -e V_avant) and the cube "Application" (RK4, detect Y <= 0, tc by bisection, stop the
cube with its position fixed on the ground and zero velocity).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._config import DEFAULT_TIME_TOL
from .._validate import MAX_STEPS, as_fraction, as_nonnegative, as_positive
from . import response as R
from .events import I_RESTS, I_T, I_V_AFTER, I_V_BEFORE, S_CONTACT_FORCE, S_T, S_V, S_Y, simulate_fall

__all__ = ["drop_particle", "drop_cube", "Impact", "FallResult", "CubeDrop"]


@dataclass(frozen=True)
class Impact:
    """One collision with the ground.

    Attributes
    ----------
    t : float
        The collision time tc (s), located by bisection.
    v_before, v_after : float
        The vertical velocity just before and just after the impact (m/s), v_after = −e·v_before.
    came_to_rest : bool
        The bounce was slower than ``rest_speed``: resting contact from tc on.
    """

    t: float
    v_before: float
    v_after: float
    came_to_rest: bool = False  #: the bounce was slower than rest_speed: resting contact from tc on


@dataclass(frozen=True)
class FallResult:
    """The falling particle's trajectory and impacts, as returned by :func:`drop_particle`.

    Samples are taken every ``dt`` and at every impact time.

    Attributes
    ----------
    t, y, v : numpy.ndarray, shape (m,), float64
        Times (s), heights (m) and vertical velocities (m/s) of the samples.
    contact_force : numpy.ndarray, shape (m,), float64
        The ground's force on the particle (N): 0 in flight, m·g while resting.
    impacts : list of Impact
        The collisions, in time order.
    rest_time : float or None
        When resting contact began (None if the particle never came to rest).
    bisection_iterations : int
        The trial re-integrations spent locating the impacts.
    """

    t: np.ndarray
    y: np.ndarray
    v: np.ndarray
    contact_force: np.ndarray
    impacts: list[Impact] = field(default_factory=list)
    rest_time: float | None = None
    bisection_iterations: int = 0


@dataclass(frozen=True)
class CubeDrop:
    """The falling cube, as returned by :func:`drop_cube`.

    Attributes
    ----------
    t_contact : float or None
        When the cube's lowest point reached the ground (None if not by ``t_end``).
    position, velocity : numpy.ndarray, shape (3,), float64
        The centre and the velocity after the cube is stopped (or at ``t_end``).
    t, y, v : numpy.ndarray, shape (m,), float64
        Trajectory samples: times, heights of the centre, vertical velocities.
    size : float
        The cube's edge.
    v_contact : float or None
        The vertical velocity at tc, just before the cube is stopped (m/s).
    """

    t_contact: float | None
    position: np.ndarray
    velocity: np.ndarray
    t: np.ndarray
    y: np.ndarray  #: height of the centre, (m,)
    v: np.ndarray  #: vertical velocity, (m,)
    size: float
    v_contact: float | None = None  #: vertical velocity of the cube at tc, just before it is stopped (m/s)


def _fall_params(*, mass, drag, quadratic_drag, restitution, gravity, ground, rest_speed, stop):
    params = np.zeros(R.N_PARAMS)
    params[R.P_GRAVITY] = gravity
    params[R.P_MASS] = mass
    params[R.P_LINEAR_DRAG] = drag
    params[R.P_QUADRATIC_DRAG] = quadratic_drag
    params[R.P_RESTITUTION] = restitution
    params[R.P_GROUND] = ground
    params[R.P_REST_SPEED] = rest_speed
    params[R.P_STOP_ON_CONTACT] = 1.0 if stop else 0.0
    return params


def _check_common(height, mass, drag, quadratic_drag, gravity, dt, t_end, tol):
    height = as_nonnegative(height, "height")
    mass = as_positive(mass, "mass")
    drag = as_nonnegative(drag, "drag")
    quadratic_drag = as_nonnegative(quadratic_drag, "quadratic_drag")
    gravity = as_nonnegative(gravity, "gravity")
    dt = as_positive(dt, "dt")
    t_end = as_positive(t_end, "t_end")
    tol = as_positive(tol, "tol")
    if tol >= dt:
        raise ValueError(f"tol must be smaller than dt, got tol = {tol!r} >= dt = {dt!r}")
    if t_end / dt > MAX_STEPS:
        raise ValueError(f"dt = {dt!r} asks for {t_end / dt:.3g} RK4 steps up to t_end = {t_end!r}; "
                         f"at most MAX_STEPS = {MAX_STEPS}")
    return height, mass, drag, quadratic_drag, gravity, dt, t_end, tol


def drop_particle(height: float, *, mass: float = 1.0, drag: float = 0.0, restitution: float = 1.0,
                  gravity: float = 9.81, dt: float = 0.01, t_end: float = 5.0, tol: float = DEFAULT_TIME_TOL,
                  quadratic_drag: float = 0.0, rest_speed: float | None = None) -> FallResult:
    """A particle released from rest at y = ``height`` falls onto the ground y = 0 and bounces.

    RK4 with time step ``dt`` on dY/dt = (v, F/m), F = −m·g − drag·v − quadratic_drag·abs(v)·v. Every impact is
    located by bisection (Algorithme 3, tolerance ``tol`` seconds on tc), the solver is stopped at tc and
    restarted from Y(tc)+ with v_after = −restitution·v_before. A bounce slower than ``rest_speed`` ends the
    bouncing: the particle rests on the ground held by the contact force N = m·g, with no further stop/restart.

    Parameters
    ----------
    height : float
        The initial height (m), >= 0.
    mass : float, optional
        Mass (kg), > 0.
    drag, quadratic_drag : float, optional
        Linear (F = −k·v) and quadratic (F = −c·abs(v)·v) drag coefficients, >= 0.
    restitution : float, optional
        e in [0, 1].
    gravity : float, optional
        g (m/s²), >= 0.
    dt : float, optional
        The RK4 step (s), > 0.
    t_end : float, optional
        The simulated time (s), > 0; at most ``MAX_STEPS`` steps.
    tol : float, optional
        The bisection's tolerance on tc (s), 0 < tol < dt.
    rest_speed : float, optional
        The bounce speed below which the particle comes to rest (m/s); default g·dt, a bounce too short to
        resolve with steps of dt.

    Returns
    -------
    FallResult

    Raises
    ------
    ValueError
        Naming the argument, for a negative or non-finite height, mass <= 0, negative drag, restitution outside
        [0, 1], dt <= 0, t_end <= 0, tol <= 0 or tol >= dt, rest_speed <= 0.
    """
    height, mass, drag, quadratic_drag, gravity, dt, t_end, tol = _check_common(
        height, mass, drag, quadratic_drag, gravity, dt, t_end, tol)
    restitution = as_fraction(restitution, "restitution")
    rest_speed = gravity * dt if rest_speed is None else as_positive(rest_speed, "rest_speed")
    if rest_speed <= 0.0:  # only when gravity == 0: the particle then never falls, any positive value does
        rest_speed = np.finfo(float).tiny
    params = _fall_params(mass=mass, drag=drag, quadratic_drag=quadratic_drag, restitution=restitution,
                          gravity=gravity, ground=0.0, rest_speed=rest_speed, stop=False)
    samples, impacts, iterations = simulate_fall(height, 0.0, t_end, dt, tol, params)
    impact_list = [Impact(float(r[I_T]), float(r[I_V_BEFORE]), float(r[I_V_AFTER]), bool(r[I_RESTS]))
                   for r in impacts]
    rest_time = next((imp.t for imp in impact_list if imp.came_to_rest), None)
    if rest_time is None and height == 0.0 and gravity > 0.0:
        rest_time = 0.0
    return FallResult(t=samples[:, S_T], y=samples[:, S_Y], v=samples[:, S_V],
                      contact_force=samples[:, S_CONTACT_FORCE], impacts=impact_list, rest_time=rest_time,
                      bisection_iterations=int(iterations))


def drop_cube(height: float, *, size: float = 1.0, mass: float = 1.0, drag: float = 0.0, gravity: float = 9.81,
              dt: float = 0.01, tol: float = DEFAULT_TIME_TOL, t_end: float = 60.0,
              quadratic_drag: float = 0.0) -> CubeDrop:
    """An axis-aligned cube of edge ``size``, centre at (0, height, 0), falls from rest onto the ground y = 0.

    RK4 on the centre; contact when the lowest point (y − size/2) reaches 0, tc found by bisection; the cube is
    then stopped: centre fixed at y = size/2, velocity zero (the slide's cube "Application").

    Parameters
    ----------
    height : float
        The initial height of the centre (m), >= size/2 (the cube starts above the ground).
    size : float, optional
        The cube's edge (m), > 0.
    mass, drag, gravity, dt, tol, t_end, quadratic_drag : float, optional
        As for :func:`drop_particle`.

    Returns
    -------
    CubeDrop
        ``t_contact`` is None if the cube has not reached the ground by ``t_end`` (then ``position`` and
        ``velocity`` are the state at t_end).

    Raises
    ------
    ValueError
        For a height below size/2, size <= 0, and the same bad inputs as :func:`drop_particle`.
    """
    size = as_positive(size, "size")
    height, mass, drag, quadratic_drag, gravity, dt, t_end, tol = _check_common(
        height, mass, drag, quadratic_drag, gravity, dt, t_end, tol)
    if height < size / 2.0:
        raise ValueError(f"height must be >= size/2 = {size / 2.0!r} (the cube's centre starts above the "
                         f"ground), got {height!r}")
    params = _fall_params(mass=mass, drag=drag, quadratic_drag=quadratic_drag, restitution=0.0,
                          gravity=gravity, ground=size / 2.0, rest_speed=np.inf, stop=True)
    samples, impacts, _ = simulate_fall(height, 0.0, t_end, dt, tol, params)
    t_contact = float(impacts[0, I_T]) if impacts.shape[0] else None
    v_contact = float(impacts[0, I_V_BEFORE]) if impacts.shape[0] else None
    y_last, v_last = float(samples[-1, S_Y]), float(samples[-1, S_V])
    return CubeDrop(t_contact=t_contact, position=np.array([0.0, y_last, 0.0]),
                    velocity=np.array([0.0, v_last, 0.0]), t=samples[:, S_T], y=samples[:, S_Y],
                    v=samples[:, S_V], size=size, v_contact=v_contact)


