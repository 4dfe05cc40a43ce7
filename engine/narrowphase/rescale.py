"""Power-of-two rescaling of tiny or huge pairs of shapes, so that no squared length underflows or overflows.

The narrow-phase kernels compute quantities of degree up to 4 in the coordinates (squared cross products, the
triangle's Voronoi-region numerators, compared against tolerances as small as 1e-20 ≈ 2^-67 times such products).
For a pair whose largest |coordinate| lies outside [2^-160, 2^160] they work on copies scaled by a power of two,
``rescale_unit(big)``, and scale lengths back: multiplying by a power of two is exact, so the answers are the
unscaled ones to the bit (up to coordinates more than 2^1000 times smaller than the largest, far below its ulp).

The window follows from the arithmetic. Inside it, a coordinate difference still resolved by the largest
coordinate (at least 2^-53 of it, so >= 2^-213) raised to the 4th power and times 2^-67 is >= 2^-919, a normal
number (>= 2^-1022) with all its bits; and the largest degree-4 sum, 3·(2·2^160)^4 < 2^646, is far from overflow
(2^1024). (A window for squares alone, [2^-511, 2^511], would not do: 4th powers underflow below 2^-256.)
"""
from __future__ import annotations

import math

from .._config import njit

__all__ = ["RESCALE_ABOVE", "rescale_unit", "largest_coordinate"]

#: pairs whose largest |coordinate| lies outside [2^-160, 2^160] are solved on copies scaled by a power of two
RESCALE_ABOVE = 2.0**160


@njit
def rescale_unit(big):
    """1.0, or — when ``big``, the largest |coordinate| of a pair of shapes, lies outside [2^-160, 2^160] — the
    power of two that brings it into [0.5, 1) (between 2^-1000 and 2^1000, so that the factor itself is finite)."""
    if big > 0.0 and (big * RESCALE_ABOVE < 1.0 or big > RESCALE_ABOVE):
        return math.ldexp(1.0, max(-1000, min(-math.frexp(big)[1], 1000)))
    return 1.0


@njit
def largest_coordinate(pa, pb):
    """The largest |coordinate| of the rows of ``pa`` (n, 3) and ``pb`` (m, 3) float64."""
    big = 0.0
    for i in range(pa.shape[0]):
        big = max(big, abs(pa[i, 0]), abs(pa[i, 1]), abs(pa[i, 2]))
    for i in range(pb.shape[0]):
        big = max(big, abs(pb[i, 0]), abs(pb[i, 1]), abs(pb[i, 2]))
    return big
