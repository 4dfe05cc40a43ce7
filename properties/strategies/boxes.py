"""Strategies for the broad phase: scenes of axis-aligned boxes and of spheres.

Box scenes deliberately contain the cases that break broad phases: exact touches and tied endpoints (small
integer coordinates), identical boxes, zero-size boxes, negative coordinates, coordinates near ±1e8, and one
huge box among tiny ones.
"""
from __future__ import annotations

import numpy as np
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

OFFSETS = (0.0, -37.0, 1e8, -1e8)


@st.composite
def box_scenes(draw, d=None, min_n=0, max_n=40, integer=False):
    """(lo, hi) float64 arrays of shape (n, d); ``integer=True`` keeps every coordinate an integer."""
    d = draw(st.integers(1, 3)) if d is None else d
    n = draw(st.integers(min_n, max_n))
    offset = draw(st.sampled_from(OFFSETS))
    scale = 1.0 if integer else draw(st.sampled_from([1.0, 0.25, 0.1]))
    span = draw(st.sampled_from([3, 10, 40]))
    corner = draw(arrays(np.int64, (n, d), elements=st.integers(-span, span)))
    extent = draw(arrays(np.int64, (n, d), elements=st.integers(0, 4)))
    lo = offset + scale * corner.astype(float)
    hi = offset + scale * (corner + extent).astype(float)
    if not integer and n and draw(st.booleans()):
        # some rows with arbitrary floats (no ties), still near the offset
        jitter = draw(arrays(np.float64, (n, d), elements=st.floats(-span, span, allow_nan=False)))
        size = draw(arrays(np.float64, (n, d), elements=st.floats(0.0, 5.0, allow_nan=False)))
        rows = draw(arrays(np.bool_, (n,)))
        lo[rows] = offset + jitter[rows]
        hi[rows] = lo[rows] + size[rows]
        hi = np.maximum(hi, lo)  # the sum can round below lo near 1e8
    if n >= 2 and draw(st.booleans()):  # identical boxes
        src = draw(st.integers(0, n - 1))
        dst = draw(st.integers(0, n - 1))
        lo[dst] = lo[src]
        hi[dst] = hi[src]
    if n >= 1 and draw(st.booleans()):  # zero-size boxes (points)
        k = draw(st.integers(0, n - 1))
        hi[k] = lo[k]
    if n >= 3 and draw(st.booleans()):  # one huge box among tiny ones
        k = draw(st.integers(0, n - 1))
        lo[k] = offset - 1000.0 * draw(st.sampled_from([1.0, 0.01]))
        hi[k] = offset + 1000.0
    return lo, hi


@st.composite
def sphere_scenes(draw, d=3, min_n=0, max_n=40, equal=None):
    """(centers (n, d), radii): radii a scalar when ``equal``, else an (n,) array (a few of them large)."""
    equal = draw(st.booleans()) if equal is None else equal
    n = draw(st.integers(min_n, max_n))
    offset = draw(st.sampled_from((0.0, -37.0, 1e5)))
    span = draw(st.sampled_from([2.0, 10.0, 40.0]))
    centers = offset + draw(arrays(np.float64, (n, d), elements=st.floats(-span, span, allow_nan=False)))
    if n >= 2 and draw(st.booleans()):
        centers[draw(st.integers(0, n - 1))] = centers[draw(st.integers(0, n - 1))]
    if equal:
        return centers, draw(st.floats(0.0, 3.0, allow_nan=False))
    radii = draw(arrays(np.float64, (n,), elements=st.floats(0.0, 3.0, allow_nan=False)))
    if n >= 3 and draw(st.booleans()):
        radii[draw(st.integers(0, n - 1))] = draw(st.sampled_from([20.0, 100.0]))
    return centers, radii
