"""Stopping the ODE solver at the collision time tc and restarting it from Y(tc)+ (slide "La solution ?").

The integrator advances Y = (y, v) with RK4 from t0 to t0 + Dt. When the state at t0 + Dt is below the ground,
the step is thrown away: the solver "goes back to t0" and the collision time is located by the chapter's
Algorithme 3 on g(τ) = height(Y after an RK4 step of length τ from Y(t0)) — trial steps Dt/2, then Dt/4 or 3Dt/4,
and so on — until the bracket is narrower than the tolerance ε. The solver is stopped at tc (the end of the
final bracket that is still above the ground, so the body never penetrates), Y(tc)+ is built with
V_après = -e V_avant, and integration restarts from tc. Several bounces per run.

A bounce slower than ``rest_speed`` ends in resting contact (slide "Autre problème"): the body stays on the
ground, held by the contact force, and the solver goes on without stop/restart.
"""
from __future__ import annotations

import numpy as np

from .._config import njit
from .response import (
    P_GROUND,
    P_MASS,
    P_REST_SPEED,
    P_STOP_ON_CONTACT,
    external_force,
    resting_contact_force,
    velocity_after_impact,
)

# Column layout of the samples array returned by the kernel.
S_T, S_Y, S_V, S_CONTACT_FORCE = 0, 1, 2, 3
# Column layout of the impacts array.
I_T, I_V_BEFORE, I_V_AFTER, I_RESTS = 0, 1, 2, 3
#: explicit cap on the number of impacts of one run (a guard: a Zeno cascade cannot hang the kernel)
MAX_IMPACTS = 1_000_000


@njit
def fall_derivative(y, v, resting, params):
    """dY/dt = (v, F/m) with F the external force plus, when resting, the contact force."""
    force = external_force(v, params)
    if resting:
        force += resting_contact_force(v, params)
    return v, force / params[P_MASS]


@njit
def rk4_fall_step(y, v, dt, resting, params):
    """One classical RK4 step (the formula of ``rk4_step``) of the falling-body ODE, returns (y, v)."""
    k1y, k1v = fall_derivative(y, v, resting, params)
    k2y, k2v = fall_derivative(y + 0.5 * dt * k1y, v + 0.5 * dt * k1v, resting, params)
    k3y, k3v = fall_derivative(y + 0.5 * dt * k2y, v + 0.5 * dt * k2v, resting, params)
    k4y, k4v = fall_derivative(y + dt * k3y, v + dt * k3v, resting, params)
    y_next = y + (dt / 6.0) * (k1y + 2.0 * k2y + 2.0 * k3y + k4y)
    v_next = v + (dt / 6.0) * (k1v + 2.0 * k2v + 2.0 * k3v + k4v)
    return y_next, v_next


@njit
def locate_impact(y0, v0, dt, tol, params):
    """Algorithme 3 on g(τ) = y(t0 + τ) - ground, re-integrating from Y(t0) for each trial τ.

    Requires g(0) >= 0 > g(dt). Returns (τ_a, iterations) with τ_a the end of the final bracket [τ_a, τ_b],
    τ_b - τ_a <= tol, at which the body is still at or above the ground; the true root lies in [τ_a, τ_b].
    """
    ground = params[P_GROUND]
    a = 0.0
    b = dt
    iterations = 0
    while b - a > tol:  # tantque |a - b| > ε
        x = 0.5 * a + 0.5 * b  # x' <- (a + b) / 2
        if x <= a or x >= b:
            break
        iterations += 1
        yx, _ = rk4_fall_step(y0, v0, x, False, params)
        if yx - ground < 0.0:  # f(x') f(a) < 0: the sign changed between a and x'
            b = x
        else:
            a = x
    return a, iterations


@njit
def _grow(buffer):
    bigger = np.empty((2 * buffer.shape[0], buffer.shape[1]), dtype=buffer.dtype)
    bigger[: buffer.shape[0]] = buffer
    return bigger


@njit
def simulate_fall(y0, v0, t_end, dt, tol, params):
    """Integrate a body falling onto the ground y = P_GROUND from (y0, v0) over [0, t_end].

    Returns (samples (m, 4): t, y, v, contact force; impacts (k, 4): tc, v_before, v_after, came_to_rest;
    bisection iterations in total).
    """
    ground = params[P_GROUND]
    samples = np.empty((256, 4))
    impacts = np.empty((16, 4))
    n_samples = 0
    n_impacts = 0
    total_iterations = 0
    t = 0.0
    y = y0
    v = v0
    # A body that starts on the ground without upward speed is resting from the start.
    resting = y - ground <= 0.0 and v <= 0.0 and resting_contact_force(v, params) > 0.0
    stopped = False
    while True:
        if n_samples == samples.shape[0]:
            samples = _grow(samples)
        samples[n_samples, S_T] = t
        samples[n_samples, S_Y] = y
        samples[n_samples, S_V] = v
        samples[n_samples, S_CONTACT_FORCE] = resting_contact_force(v, params) if resting else 0.0
        n_samples += 1
        if t >= t_end or stopped:
            break
        h = min(dt, t_end - t)
        y_next, v_next = rk4_fall_step(y, v, h, resting, params)
        if resting:
            if resting_contact_force(v_next, params) <= 0.0:  # the net external force lifts the body off
                resting = False
            t, y, v = t + h, y_next, v_next
            continue
        if y_next - ground >= 0.0:  # no interpenetration at t0 + Dt: accept the step
            t, y, v = t + h, y_next, v_next
            continue
        # Interpenetration at t0 + Dt: go back to t0, locate tc, stop there, restart from Y(tc)+.
        tau, iterations = locate_impact(y, v, h, tol, params)
        total_iterations += iterations
        y_c, v_c = rk4_fall_step(y, v, tau, False, params)
        # the body at tc is at most |v| tol above the ground; the bracket's other end is below it
        v_after = velocity_after_impact(v_c, params)
        comes_to_rest = params[P_STOP_ON_CONTACT] > 0.0 or abs(v_after) < params[P_REST_SPEED]
        if n_impacts == MAX_IMPACTS:
            raise RuntimeError("more than MAX_IMPACTS impacts: raise rest_speed or shorten t_end")
        if n_impacts == impacts.shape[0]:
            impacts = _grow(impacts)
        impacts[n_impacts, I_T] = t + tau
        impacts[n_impacts, I_V_BEFORE] = v_c
        impacts[n_impacts, I_V_AFTER] = v_after
        impacts[n_impacts, I_RESTS] = 1.0 if comes_to_rest else 0.0
        n_impacts += 1
        t = t + tau
        if comes_to_rest:
            # the slide's cube: "fixer sa position à Y = 0 et sa vitesse à zéro"; then resting contact
            y, v = ground, 0.0
            resting = resting_contact_force(0.0, params) > 0.0
            stopped = params[P_STOP_ON_CONTACT] > 0.0
        else:
            y, v = y_c, v_after
    return samples[:n_samples].copy(), impacts[:n_impacts].copy(), total_iterations
