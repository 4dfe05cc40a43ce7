"""Rays against a curved ground, solid below y = f(x) (slide "Sol courbe"), f a Python callable: the first t where
the height gap g(t) = y(t) − f(x(t)) of the ray o + t·d reaches 0.

The gap is sampled at ``samples`` evenly spaced t in [0, t_max] (one call of f for the whole batch); the first
sampled step where it turns <= 0 brackets the hit, which the chapter's bisection (Algorithme 3, as in
engine.dynamics.bisection) then narrows until the bracket no longer shrinks — the hit to round-off, on the closed
solid's side (g <= 0). As every sampled test of a curved ground, a bump of f thinner than a step between two
samples may be missed. A ray starting in the solid (g(0) <= 0) hits at t = 0 with normal −d; the normal of a hit
is the curve's, (−f'(x), 1, 0) normalised.
"""
from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = ["ray_curve_batch"]

#: bisection steps: enough to shrink any float64 bracket to adjacent floats
_HALVINGS = 1100


def _gap(height: Callable, o: np.ndarray, d: np.ndarray, t: np.ndarray) -> np.ndarray:
    """g = y − f(x) at parameters t ((k,) or (k, s)) of the rays o + t·d."""
    t2 = t if t.ndim == 2 else t[:, None]
    g = o[:, 1, None] + t2 * d[:, 1, None] - height(o[:, 0, None] + t2 * d[:, 0, None])
    return g if t.ndim == 2 else g[:, 0]


def _bisect(height, o, d, lo, hi):
    """Narrow brackets [lo, hi] with g(lo) > 0 >= g(hi) until they stop shrinking; returns hi."""
    for _ in range(_HALVINGS):
        mid = lo + 0.5 * (hi - lo)
        moving = (mid > lo) & (mid < hi)
        if not moving.any():
            break
        below = _gap(height, o, d, mid) <= 0.0
        hi = np.where(moving & below, mid, hi)
        lo = np.where(moving & ~below, mid, lo)
    return hi


def ray_curve_batch(height: Callable, slope: Callable, samples: int, origins: np.ndarray, directions: np.ndarray,
                    t_max: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The first hit of each ray on the ground y <= f(x).

    Parameters
    ----------
    height, slope : callable
        f(x) and f'(x), vectorised (a HeightCurve's ``height`` and ``slope``).
    samples : int
        Gap samples along each ray, >= 2.
    origins, directions : numpy.ndarray, shape (k, 3), float64
        The rays; directions of unit length.
    t_max : numpy.ndarray, shape (k,), float64
        Finite search lengths, >= 0.

    Returns
    -------
    t : numpy.ndarray, shape (k,), float64
        The hit's distance, inf for a miss.
    normal : numpy.ndarray, shape (k, 3), float64
        The outward unit normal (−d for a ray starting in the solid), NaN for a miss.
    """
    k = origins.shape[0]
    t = np.full(k, np.inf)
    normal = np.full((k, 3), np.nan)
    if k == 0:
        return t, normal
    inside = _gap(height, origins, directions, np.zeros(k)) <= 0.0
    t[inside] = 0.0
    normal[inside] = -directions[inside]
    rest = np.flatnonzero(~inside & (t_max > 0.0))
    if rest.size == 0:
        return t, normal
    o, d = origins[rest], directions[rest]
    ts = t_max[rest, None] * (np.arange(1, samples + 1) / samples)[None, :]
    below = _gap(height, o, d, ts) <= 0.0
    hit = below.any(axis=1)
    first = np.argmax(below, axis=1)[hit]
    rows = np.flatnonzero(hit)
    lo = np.where(first > 0, ts[rows, np.maximum(first - 1, 0)], 0.0)
    th = _bisect(height, o[rows], d[rows], lo, ts[rows, first])
    x = o[rows, 0] + th * d[rows, 0]
    n = np.stack([-slope(x), np.ones_like(x), np.zeros_like(x)], axis=1)
    t[rest[rows]] = th
    normal[rest[rows]] = n / np.linalg.norm(n, axis=1, keepdims=True)
    return t, normal
