"""The chapter's "Algorithme 3 bissection" (slide "Méthode de la Dichotomie (Bisection)")::

    définir a, b réels { avec f(a) * f(b) < 0 }
    tantque |a - b| > ε
        x' <- (a + b) / 2
        si f(x') * f(a) < 0 alors b <- x'  sinon a <- x'
    fintantque

Two repairs of the textbook loop, both needed for a robust root finder:

- the sign test compares signs instead of multiplying values, so f(a) = 1e-200 and f(x') = -1e-200 (whose
  product underflows to 0) still move the right end;
- when f(x') is exactly 0 the root is returned at once (the textbook loop would then move ``a`` past the root,
  because f(x') * f(a) = 0 is never < 0 again).

The loop also stops when the bracket can no longer shrink in floating point (tol below the spacing of doubles).
"""
from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from .._validate import as_float, as_positive, check_callable

__all__ = ["bisect", "BisectionResult", "max_bisection_iterations"]


@dataclass(frozen=True)
class BisectionResult:
    """What ``bisect(..., full_output=True)`` reports besides the root.

    Attributes
    ----------
    root : float
        The midpoint of the final bracket.
    a, b : float
        The final bracket, ``a <= root <= b``.
    iterations : int
        The number of halvings (evaluations of f at a midpoint).
    converged : bool
        ``b - a <= tol``, or an exact zero of f was hit.
    """

    root: float
    a: float  #: final bracket, a <= root <= b
    b: float
    iterations: int  #: number of halvings (evaluations of f at a midpoint)
    converged: bool  #: ``|b - a| <= tol``, or an exact zero was hit


def max_bisection_iterations(a: float, b: float, tol: float) -> int:
    """The bound ceil(log2((b − a)/tol)) + 1 on the number of halvings of the bracket [a, b].

    Parameters
    ----------
    a, b : float
        The bracket's ends.
    tol : float
        The width at which the bisection stops, > 0.

    Returns
    -------
    int
        At least 1.
    """
    width = abs(b - a)
    if width <= tol:
        return 1
    ratio = width / tol
    if math.isinf(ratio):  # a denormal tol: width / tol overflows, the difference of the logarithms does not
        return math.ceil(math.log2(width) - math.log2(tol)) + 1
    return math.ceil(math.log2(ratio)) + 1


def _sign(value: float, x: float) -> int:
    if math.isnan(value):
        raise ValueError(f"f returned NaN at x = {x!r}")
    return (value > 0.0) - (value < 0.0)


def bisect(f: Callable[[float], float], a: float, b: float, tol: float, *,
           full_output: bool = False) -> float | tuple[float, BisectionResult]:
    """Root of a continuous scalar function on a bracket, by the chapter's Algorithme 3.

    The result lies within ``tol`` of a root (it is the midpoint of a final bracket of width <= tol, so within
    tol/2), after at most ``ceil(log2(|b − a|/tol)) + 1`` evaluations of f at midpoints.

    Parameters
    ----------
    f : callable
        ``f(x) -> float``; ``f(a)`` and ``f(b)`` must have opposite signs, or one of them be exactly 0 (that end
        is then returned exactly).
    a, b : float
        The bracket's ends, in either order; finite.
    tol : float
        The width of the final bracket, > 0.
    full_output : bool, optional
        Also return a :class:`BisectionResult`.

    Returns
    -------
    root : float
        Or ``(root, BisectionResult)`` with ``full_output=True``.

    Raises
    ------
    ValueError
        When [a, b] does not bracket a sign change, when ``tol <= 0``, when a bound is not finite, or when f
        returns NaN.
    TypeError
        When ``f`` is not callable.
    """
    check_callable(f, "f", "callable f(x) -> float")
    a = as_float(a, "a")
    b = as_float(b, "b")
    tol = as_positive(tol, "tol")
    if a > b:
        a, b = b, a
    fa = float(f(a))
    sa = _sign(fa, a)
    if sa == 0:
        return _finish(a, a, a, 0, True, full_output)
    fb = float(f(b))
    sb = _sign(fb, b)
    if sb == 0:
        return _finish(b, b, b, 0, True, full_output)
    if sa == sb:
        raise ValueError(f"[a, b] = [{a!r}, {b!r}] does not bracket a root: f(a) = {fa!r} and f(b) = {fb!r} "
                         "have the same sign")
    iterations = 0
    limit = max_bisection_iterations(a, b, tol)
    while b - a > tol and iterations < limit:  # tantque |a - b| > ε
        x = 0.5 * a + 0.5 * b  # x' <- (a + b)/2, written so that it cannot overflow
        if x <= a or x >= b:  # no double strictly inside: the bracket is as small as it gets
            break
        iterations += 1
        sx = _sign(float(f(x)), x)
        if sx == 0:
            return _finish(x, x, x, iterations, True, full_output)
        if sx != sa:  # si f(x') f(a) < 0
            b = x
        else:
            a, sa = x, sx
    root = 0.5 * a + 0.5 * b
    return _finish(root, a, b, iterations, b - a <= tol or root in (a, b), full_output)


def _finish(root, a, b, iterations, converged, full_output):
    if full_output:
        return root, BisectionResult(root, a, b, iterations, bool(converged))
    return root
