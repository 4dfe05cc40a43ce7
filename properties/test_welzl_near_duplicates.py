"""Welzl's minimal sphere when two boundary points nearly coincide: a point p and a copy q = p + delta t of it,
delta 2e-11 to 5e-11 of the cloud's size.

The three-point ball of (q, p, x) then has no usable circumcircle (|u x v|^2 <= 1e-20 |u|^2 |v|^2 with u, v the
edges from x) and ``_ball3`` falls back on the diametral ball of the farthest pair. In exact arithmetic Welzl
never asks for a ball on three collinear points; with its acceptance (a point is inside when
|x - c|^2 <= r^2 (1 + 1e-12) + (1e-15 size)^2) it does, in this configuration:

    p = (1, 0), y = (-1, 0), x above them (outside the unit circle), q just beyond p along t, where t points out
    of the circle through p, y, x (so q escapes it) and towards x (t . (x - p) > 0, so p escapes the diametral
    ball of q and x)

visited in the order p, y, x, q (x is forced, then p inside x's level; when q is forced the list starts x, p,
and Welzl builds the balls (q, x), then (q, p), then (q, p, x)). Every input order of the four points is tried,
so that whatever the seed's shuffle, that visiting order occurs. Oracle: the circle through p, y, x (x above the
unit circle: all three on the minimal ball, the brute force of properties.test_bounding_fits); q moves the radius by at
most delta, far inside the 1e-9 tolerance.
"""
from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from engine.bounding.sphere import min_bounding_sphere
from properties.strategies.geometry import seeds
from properties.test_bounding_fits import brute_force_min_sphere


@st.composite
def near_duplicate_on_the_boundary(draw):
    """(p, y, x, q) in the plane as above, then scaled, moved and (3-D) turned into a random plane."""
    rng = np.random.default_rng(draw(seeds))
    p, y = np.array([1.0, 0.0]), np.array([-1.0, 0.0])
    x = np.array([rng.uniform(-0.5, 0.5), rng.uniform(1.5, 2.0)])  # the arc below is never empty there
    # the circle through p, y, x: centre (0, c0) on the bisector of p y
    c0 = (x @ x - 1.0) / (2.0 * x[1])
    outward = np.array([1.0, -c0]) / np.hypot(1.0, c0)  # its outward normal at p
    towards_x = (x - p) / np.linalg.norm(x - p)
    # directions t with t . outward >= 0.1 and t . towards_x >= 0.1: the arc between the two bounds
    angles = np.linspace(0.0, 2.0 * np.pi, 3600, endpoint=False)
    dirs = np.column_stack([np.cos(angles), np.sin(angles)])
    ok = (dirs @ outward >= 0.1) & (dirs @ towards_x >= 0.1)
    t = dirs[rng.choice(np.flatnonzero(ok))]
    q = p + rng.uniform(2e-11, 5e-11) * t
    plane = np.array([p, y, x, q])
    if draw(st.booleans()):
        frame, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        plane = plane @ frame[:2]  # the same four points in a random plane of 3-D
    scale = draw(st.sampled_from([1.0, 1e3, 1e-3, 1e6]))
    shift = draw(st.sampled_from([0.0, 1.0, -40.0]))
    return plane * scale + shift * scale


@settings(max_examples=30)
@given(near_duplicate_on_the_boundary())
def test_a_near_duplicate_on_the_boundary_leaves_the_minimal_sphere_as_it_is(pts):
    c_ref, r_ref = brute_force_min_sphere(pts[:3])
    size = float(np.abs(pts).max() + np.ptp(pts, axis=0).max())
    for order in itertools.permutations(range(4)):
        cloud = pts[list(order)]
        center, radius = min_bounding_sphere(cloud)
        assert np.isfinite(center).all()
        assert radius == pytest.approx(r_ref, rel=1e-9), order
        assert np.linalg.norm(center - c_ref) <= 1e-7 * size, order
        assert (np.linalg.norm(cloud - center, axis=1) <= radius * (1 + 1e-12) + 1e-15 * size).all()
