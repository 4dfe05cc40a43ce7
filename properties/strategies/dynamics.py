"""Strategies for the falling-body properties: heights, drags, masses, step sizes, bracketed functions."""
from __future__ import annotations

from hypothesis import strategies as st

finite = dict(allow_nan=False, allow_infinity=False)

heights = st.floats(0.05, 100.0, **finite)
masses = st.floats(0.1, 10.0, **finite)
step_sizes = st.floats(1e-3, 1e-2, **finite)
restitutions = st.floats(0.0, 1.0, **finite)


@st.composite
def linear_drag_scenes(draw):
    """(height, mass, drag, dt) with drag/mass <= 2 s^-1, where RK4 with dt <= 0.01 s is accurate to ~1e-9."""
    mass = draw(masses)
    drag = draw(st.floats(0.0, 2.0, **finite)) * mass
    return draw(heights), mass, drag, draw(step_sizes)


@st.composite
def shifted_cubics(draw):
    """(f, root, a, b): f(x) = s (x - root) ((x - root)^2 + q) with q >= 0, so root is its only real zero."""
    # |root| >= 1e-6 (or 0): for a root of 1e-193 the test function itself underflows to an exact 0 at x = 0
    root = draw(st.floats(-1e3, 1e3, **finite).filter(lambda r: r == 0.0 or abs(r) >= 1e-6))
    q = draw(st.floats(0.0, 10.0, **finite))
    scale = draw(st.sampled_from([1.0, -1.0, 1e-3, 7.5, -250.0]))
    left = draw(st.floats(1e-6, 50.0, **finite))
    right = draw(st.floats(1e-6, 50.0, **finite))

    def f(x):
        u = x - root
        return scale * u * (u * u + q)

    return f, root, root - left, root + right
