"""Checks that an answer is geometrically possible, shared by the property files (a library, not a test file).

Every function returning points or normals is held to the same few facts, each measured by an oracle that does
not share the engine's code (Qhull's facet planes, plain projections on a direction):

- ``assert_on_hull``: a witness or closest point lies on its shape;
- ``assert_in_depth_band``: contact points lie between the two support planes along the normal, and within half
  the band's width of both shapes;
- ``assert_witness_gap``: p_a − p_b = depth · n (EPA's deepest points);
- ``assert_closest_gap``: |p_a − p_b| = distance (GJK's closest points);
- ``assert_unit``: normals are unit vectors;
- ``assert_separated_after``: translated by the depth along the normal, the shapes touch and do not overlap
  (the overlap of their projections on n is the depth).

Tolerances, each relative to the pair's scale X = the largest |coordinate| of the two shapes (the size of the
round-off of any coordinate) or to size(M) = the largest |a − b| (the size of the Minkowski difference):

- ``ON_HULL`` = 1e-12: a point Σ λ_i v_i (λ_i >= 0, Σ λ_i = 1) is off its hull by a few u·X (u = 2^-53), and
  Qhull's unit plane equations by a few u·X more: 1e-12 leaves a factor 1000;
- ``GAP`` = 1e-12 (× X): p_a − p_b and depth·n are each a few roundings of numbers of size X;
- ``UNIT`` = 1e-12: a normalised vector is unit to about 3u; longer chains (rescaled cross products) stay
  far below 1e-12;
- depths: EPA stops when the support point beyond its closest face is within ``EPA_TOL`` × size(M) of it
  (engine.narrowphase.epa), so the projections' overlap along n exceeds the depth by at most that;
- the depth band's lateral allowance is ``FEATURE_TOL`` × the pair's extent (the contact manifold groups the
  vertices within that of a support plane into one feature: their projections may lie that far inside).
"""
from __future__ import annotations

import numpy as np

from engine.narrowphase.contact_manifold import FEATURE_TOL
from engine.narrowphase.epa import EPA_TOL
from properties.strategies.narrow import hull_signed_distance

__all__ = ["ON_HULL", "GAP", "UNIT", "pair_scale", "minkowski_size", "assert_on_hull", "assert_in_depth_band",
           "assert_witness_gap", "assert_closest_gap", "assert_unit", "assert_separated_after",
           "projection_overlap"]

ON_HULL = 1e-12
GAP = 1e-12
UNIT = 1e-12


def pair_scale(*shapes: np.ndarray) -> float:
    """X: the largest |coordinate| of the shapes (never 0: the smallest normal number for a pair at the origin)."""
    return max(max(float(np.abs(s).max()) for s in shapes), np.finfo(float).tiny)


def minkowski_size(a: np.ndarray, b: np.ndarray) -> float:
    """size(M): the largest |a − b| over the vertices of the two shapes."""
    return float(np.linalg.norm(a[:, None, :] - b[None, :, :], axis=2).max())


def _extent(a: np.ndarray, b: np.ndarray) -> float:
    both = np.concatenate([a, b])
    return float(np.ptp(both, axis=0).max())


def assert_on_hull(point, vertices, scale: float, radius: float = 0.0, what: str = "point") -> None:
    """``point`` (3,) is in the convex hull of ``vertices`` (n, 3) swept by ``radius``: no Qhull facet plane has it
    further than radius + ON_HULL × scale outside (the largest plane excess is a lower bound of the distance)."""
    excess = hull_signed_distance(np.asarray(vertices, float), np.asarray(point, float))
    assert excess <= radius + ON_HULL * scale, f"{what} {point!r} is {excess!r} outside its shape (scale {scale!r})"


def projection_overlap(a: np.ndarray, b: np.ndarray, normal) -> float:
    """max a·n − min b·n: how far A reaches beyond B's near side along n (> 0: overlap along n, < 0: a gap)."""
    n = np.asarray(normal, float)
    return float((a @ n).max() - (b @ n).min())


def assert_in_depth_band(points, a, b, normal, scale: float, feature_tol: float = FEATURE_TOL) -> None:
    """Contact ``points`` (m, 3) of hulls ``a``, ``b`` along the unit ``normal`` (A towards B) lie in the closed band
    between A's support plane max a·n and B's min b·n (to GAP × scale), and within half the band's width of both
    shapes (plus feature_tol × the pair's extent: the manifold's feature grouping)."""
    n = np.asarray(normal, float)
    top_a = float((a @ n).max())
    bot_b = float((b @ n).min())
    lo, hi = min(top_a, bot_b), max(top_a, bot_b)
    along = GAP * scale
    lateral = 0.5 * (hi - lo) + feature_tol * _extent(a, b) + ON_HULL * scale
    for i, p in enumerate(np.asarray(points, float)):
        h = float(p @ n)
        assert lo - along <= h <= hi + along, f"point {i} at {h!r} along n, outside the band [{lo!r}, {hi!r}]"
        for name, shape in (("A", a), ("B", b)):
            excess = hull_signed_distance(shape, p)
            assert excess <= lateral, f"point {i} {p!r} is {excess!r} outside {name} (allowed {lateral!r})"


def assert_witness_gap(point_a, point_b, depth: float, normal, scale: float) -> None:
    """EPA's deepest points: point_a − point_b = depth · normal, to GAP × scale per coordinate."""
    err = np.abs(np.asarray(point_a) - np.asarray(point_b) - depth * np.asarray(normal)).max()
    assert err <= GAP * scale, f"p_a - p_b is {err!r} away from depth * n (scale {scale!r})"


def assert_closest_gap(point_a, point_b, distance: float, scale: float) -> None:
    """GJK's closest points: |point_a − point_b| = distance, to GAP × scale."""
    err = abs(float(np.linalg.norm(np.asarray(point_a) - np.asarray(point_b))) - distance)
    assert err <= GAP * scale, f"|p_a - p_b| is {err!r} away from the distance {distance!r} (scale {scale!r})"


def assert_unit(normals) -> None:
    """Every row of ``normals`` (k, 3) (or one (3,) vector) is a unit vector to UNIT."""
    n = np.atleast_2d(np.asarray(normals, float))
    assert np.all(np.isfinite(n)), "a normal is not finite"
    err = np.abs(np.linalg.norm(n, axis=1) - 1.0)
    assert err.size == 0 or err.max() <= UNIT, f"normal {int(err.argmax())} has length 1 + {err.max()!r}"


def assert_separated_after(a, b, normal, depth: float, scale: float, slack: float = 0.0) -> None:
    """Moved by ``depth`` along ``normal`` (negative depth: a gap), B no longer overlaps A along n, and touches it:
    the projections' overlap max a·n − min b·n equals the depth, to EPA_TOL × size(M) + GAP × scale (+ ``slack``,
    an allowance of the caller's stated origin)."""
    overlap = projection_overlap(a, b, normal)
    tol = EPA_TOL * minkowski_size(a, b) + GAP * scale + slack
    assert overlap <= depth + tol, f"after moving by the depth {depth!r} the shapes still overlap by " \
                                   f"{overlap - depth!r} along n (allowed {tol!r})"
    assert overlap >= depth - tol, f"moving by the depth {depth!r} leaves a gap of {depth - overlap!r} along n " \
                                   f"(allowed {tol!r})"
