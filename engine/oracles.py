"""Independent reference answers for the falling bodies, used by the properties and by the validation reports.

Each answer comes from closed-form physics or from a third-party integrator (scipy's ``solve_ivp``), never from
the engine's own kernels: this module imports nothing from the engine, so that it can judge it.

- ``free_fall_impacts(height, n_impacts)`` — no drag, e = 1: the k-th impact at sqrt(2h/g)(2k + 1);
- ``reference_impacts(height, mass, drag, restitution, n_impacts, ...)`` — impact times under linear and
  quadratic drag by ``solve_ivp`` (RK45, rtol = atol = 1e-12) with a terminal event at the ground.
"""
from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp

__all__ = ["free_fall_impacts", "reference_impacts"]

#: gravity, m/s²
G = 9.81


def reference_impacts(height: float, mass: float, drag: float, restitution: float, n_impacts: int,
                      quadratic_drag: float = 0.0, ground: float = 0.0, gravity: float = G) -> np.ndarray:
    """Impact times of a falling particle by an independent integrator.

    ``scipy.integrate.solve_ivp`` (RK45, rtol = atol = 1e-12) with a terminal event at y = ``ground``, restarted
    after each impact with v → −e·v: the physics of :func:`engine.drop_particle` through other code.

    Parameters
    ----------
    height, mass, drag, restitution : float
        As for :func:`engine.drop_particle`.
    n_impacts : int
        How many impacts to locate.
    quadratic_drag, ground, gravity : float, optional
        The quadratic drag coefficient, the ground's height, g.

    Returns
    -------
    numpy.ndarray, shape (n_impacts,), float64
        The impact times (s).
    """

    def rhs(t, Y):
        y, v = Y
        return [v, (-mass * gravity - drag * v - quadratic_drag * abs(v) * v) / mass]

    def hit(t, Y):
        return Y[0] - ground

    # solve_ivp reads these two attributes of an event function (stop at the first crossing, downwards only)
    hit.terminal, hit.direction = True, -1  # type: ignore[attr-defined]
    t0, state, times = 0.0, [height, 0.0], []
    for _ in range(n_impacts):
        sol = solve_ivp(rhs, (t0, t0 + 1e4), state, events=hit, rtol=1e-12, atol=1e-12)
        tc, (_, vc) = sol.t_events[0][0], sol.y_events[0][0]
        times.append(tc)
        t0, state = tc, [ground, -restitution * vc]
    return np.array(times)


def free_fall_impacts(height: float, n_impacts: int, gravity: float = G) -> np.ndarray:
    """Exact impact times without drag and with e = 1: the k-th impact (k = 0, 1, ...) at sqrt(2h/g)(2k + 1).

    Parameters
    ----------
    height : float
        The drop height above the ground, >= 0.
    n_impacts : int
        How many impacts to give.
    gravity : float, optional
        g, > 0.

    Returns
    -------
    numpy.ndarray, shape (n_impacts,), float64
        The impact times (s), increasing.
    """
    return np.sqrt(2.0 * height / gravity) * (2.0 * np.arange(n_impacts) + 1.0)
