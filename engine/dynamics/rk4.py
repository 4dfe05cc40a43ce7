"""Classical fourth-order Runge–Kutta on the state vector Y(t) = (position, velocity).

Chapter: "Reprendre le code de la chute libre avec frottements (avec RK4)" and the cube "Application":
"Utilisez la méthode d'intégration RK4 pour mettre à jour la position et la vitesse à chaque frame".
"""
from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .._validate import as_float, as_float_array, check_callable

__all__ = ["rk4_step", "state_vector", "split_state"]


def state_vector(position: ArrayLike, velocity: ArrayLike) -> np.ndarray:
    """The state Y = (position, velocity) as one flat vector.

    Parameters
    ----------
    position, velocity : array_like, shape (d,)
        A scalar counts as d = 1.

    Returns
    -------
    numpy.ndarray, shape (2d,), float64
        ``position`` then ``velocity``.
    """
    p = as_float_array(np.atleast_1d(position), "position", ndim=1)
    v = as_float_array(np.atleast_1d(velocity), "velocity", ndim=1)
    if p.shape != v.shape:
        raise ValueError(f"position and velocity must have the same shape, got {p.shape} and {v.shape}")
    return np.concatenate([p, v])


def split_state(y: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """The inverse of ``state_vector``.

    Parameters
    ----------
    y : array_like, shape (2d,)
        A flat state vector of even length.

    Returns
    -------
    position, velocity : numpy.ndarray, shape (d,), float64
        The two halves of ``y`` (copies).
    """
    y = as_float_array(y, "y", ndim=1)
    if y.shape[0] % 2:
        raise ValueError(f"y must be a flat state vector of even length, got shape {y.shape}")
    d = y.shape[0] // 2
    return y[:d], y[d:]


def rk4_step(f: Callable[[float, Any], Any], t: float, y: ArrayLike, dt: float) -> np.ndarray | float:
    """One classical RK4 step of dY/dt = f(t, Y).

    The scheme::

        k1 = f(t, Y)
        k2 = f(t + dt/2, Y + dt/2 k1)
        k3 = f(t + dt/2, Y + dt/2 k2)
        k4 = f(t + dt,   Y + dt k3)
        Y(t + dt) = Y + dt/6 (k1 + 2 k2 + 2 k3 + k4)

    Parameters
    ----------
    f : callable
        ``f(t, y)`` returns the derivative, an array of ``y``'s shape.
    t : float
        The time at the start of the step.
    y : array_like, any shape, or float
        The state at ``t``; never modified.
    dt : float
        The step; may be negative (integration backwards) or zero.

    Returns
    -------
    numpy.ndarray (float64, shaped like ``y``) or float
        Y(t + dt); a float when ``y`` is a scalar.

    Raises
    ------
    ValueError
        When ``t``, ``dt`` or ``y`` are not finite, when ``f`` returns the wrong shape, or when the step
        produces a non-finite state (so no NaN escapes).
    TypeError
        When ``f`` is not callable.
    """
    check_callable(f, "f", "callable f(t, y)")
    t = as_float(t, "t")
    dt = as_float(dt, "dt")
    scalar = np.ndim(y) == 0
    y0 = as_float_array(np.atleast_1d(y), "y")

    def slope(ti, yi, stage):
        k = np.asarray(f(ti, yi[0] if scalar else yi), dtype=np.float64)
        if scalar:
            k = np.atleast_1d(k)
        if k.shape != y0.shape:
            raise ValueError(f"f returned shape {k.shape} at stage {stage}; expected the shape of y, {y0.shape}")
        return k

    half = 0.5 * dt
    k1 = slope(t, y0, "k1")
    k2 = slope(t + half, y0 + half * k1, "k2")
    k3 = slope(t + half, y0 + half * k2, "k3")
    k4 = slope(t + dt, y0 + dt * k3, "k4")
    y1 = y0 + (dt / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
    if not np.isfinite(y1).all():
        raise ValueError("the RK4 step produced a non-finite state (f returned NaN/inf or the step overflowed)")
    return float(y1[0]) if scalar else y1
