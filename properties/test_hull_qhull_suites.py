"""The 3-D convex hull (engine/bounding/hull.py) on the inputs that break floating-point quickhull, against Qhull.

Oracle: scipy.spatial.ConvexHull (Qhull, its default options). On every input Qhull builds, ``convex_hull`` builds
too (a refusal only for lower-dimensional input), with Qhull's vertex set — or, where Qhull merged nearly coplanar
facets (its vertex set then differs by vertices within its round-off of the others' hull), a volume within 1e-12
relative. And every hull is convex to round-off, checked in exact rational arithmetic (fractions.Fraction on the
float coordinates): every input point lies at most HULL_TOL × max|x| above the plane through each face's three
corners; ``is_convex`` of the hull's own faces is True.

The suites: float32-rounded clouds (coordinates on a coarse grid: many near-ties), sphere shells sampled on
latitude-longitude rings with a near-duplicate of a pole (float32: the rings near the pole are flat to one
float32 ulp), clouds with nearly collinear and nearly coplanar subsets, lattices; and the five points of parry's
float32 cloud on which floating-point quickhull could not build a horizon.
"""
from __future__ import annotations

from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial import ConvexHull as QhullHull

from engine.bounding.hull import HULL_TOL, MERGE_TOL, convex_hull, is_convex
from engine.bounding.predicates import accurate_cross, orient3d
from properties.strategies.geometry import seeds

# Five points of a 4,054-point float32 cloud of parry's convex-hull test (Qhull: all five are vertices, volume
# 3.014e-5): three of them nearly collinear (the sine of their angle is 8e-7)
PARRY_FIVE = np.array([
    [0.31705132126808167, -0.19096869230270386, -1.7293788194656372],
    [0.2970767319202423, -0.2197284996509552, -1.753007173538208],
    [0.3114270269870758, -0.2197284996509552, -1.7293788194656372],
    [0.32243916392326355, -0.2197284996509552, -1.7112468481063843],
    [0.32243913412094116, -0.21972858905792236, -1.4633204936981201],
])

_EPS = 2.0 ** -53
_O3D_BOUND = (7.0 + 56.0 * _EPS) * _EPS  # Shewchuk's stage-A bound of the float determinant, times its permanent


def _exact_height_excess(pts, faces, bound):
    """The (point, face) pairs where the point lies more than ``bound`` above the plane through the face's three
    corners, in exact rational arithmetic. A float determinant below minus its error bound (Shewchuk 1997) proves a
    pair inside; every other pair is decided with Fractions."""
    a, b, c = (pts[faces[:, k]] for k in range(3))
    u, v = b - a, c - a
    w = pts[:, None, :] - a[None, :, :]
    n = np.cross(u, v)
    det = np.einsum("fk,pfk->pf", n, w)
    minors = np.abs(u[:, [1, 2, 0]] * v[:, [2, 0, 1]]) + np.abs(u[:, [2, 0, 1]] * v[:, [1, 2, 0]])
    perm = np.einsum("fk,pfk->pf", minors, np.abs(w)) + np.abs(det)
    bad = []
    for i, f in np.argwhere(det >= -4 * _O3D_BOUND * perm):
        corners = [[Fraction(float(x)) for x in pts[faces[f, k]]] for k in range(3)]
        p = [Fraction(float(x)) for x in pts[i]]
        eu = [corners[1][k] - corners[0][k] for k in range(3)]
        ev = [corners[2][k] - corners[0][k] for k in range(3)]
        en = [eu[1] * ev[2] - eu[2] * ev[1], eu[2] * ev[0] - eu[0] * ev[2], eu[0] * ev[1] - eu[1] * ev[0]]
        height = sum(en[k] * (p[k] - corners[0][k]) for k in range(3))  # |n| × the signed distance
        if height > 0 and height * height > Fraction(bound) ** 2 * sum(x * x for x in en):
            bad.append((int(i), int(f), float(height) / float(np.linalg.norm(n[f]))))
    return bad


def _check_against_qhull(pts, exact_input=False):
    """Qhull builds ⇒ we build; the same vertex set or (Qhull merged) a volume within 1e-12; convex to round-off.
    ``exact_input``: the points are exactly where they are meant to be (no round-off to merge): the same vertex
    set, always."""
    try:
        ref = QhullHull(pts)
    except Exception:  # Qhull finds the input flat: no claim here (test_hull.py covers the refusals)
        return None
    hull = convex_hull(pts)  # never a ValueError on input Qhull builds
    same = {tuple(p) for p in pts[hull.vertices]} == {tuple(p) for p in pts[ref.vertices]}
    assert same or (not exact_input and hull.volume == pytest.approx(ref.volume, rel=1e-12)), (hull.volume, ref.volume)
    assert len(hull.faces) == 2 * len(hull.vertices) - 4
    scale = float(np.abs(pts).max())
    assert _exact_height_excess(pts, hull.faces, HULL_TOL * scale) == []
    assert is_convex(hull.points, hull.faces)
    assert (pts @ hull.normals.T - hull.offsets).max() <= 2 * HULL_TOL * scale  # the reported planes, in floats
    return hull


def _f32(x):
    return np.asarray(x, dtype=np.float32).astype(np.float64)


@st.composite
def float32_clouds(draw):
    """Normal, uniform or clustered clouds rounded to float32 (a grid of 2^-24 relative: many near-ties)."""
    rng = np.random.default_rng(draw(seeds))
    n = draw(st.integers(5, 150))
    kind = draw(st.sampled_from(["normal", "cube", "clusters"]))
    if kind == "normal":
        pts = rng.normal(size=(n, 3))
    elif kind == "cube":
        pts = rng.uniform(-1.0, 1.0, size=(n, 3))
    else:
        centres = rng.normal(size=(3, 3))
        pts = centres[rng.integers(0, 3, size=n)] + rng.normal(size=(n, 3)) * 10.0 ** rng.uniform(-6, -2)
    return _f32(pts * draw(st.sampled_from([1.0, 1e-3, 1e3])) + draw(st.sampled_from([0.0, 1.0, 100.0])))


@st.composite
def sphere_shells(draw):
    """float32 points on rings of latitude of a unit sphere (ring 1 of m is 1 − cos(π/m) below the pole: one or a
    few float32 ulps for large m), the north pole and a near-duplicate of it 3e-7 to 2e-6 away, the south pole, and
    points inside."""
    rng = np.random.default_rng(draw(seeds))
    m = draw(st.integers(20, 3000))
    k = draw(st.integers(6, 30))
    rings = np.concatenate([[1], rng.choice(np.arange(2, m), size=min(m - 2, draw(st.integers(1, 5))), replace=False)])
    theta, phi = np.meshgrid(np.pi * rings / m, 2.0 * np.pi * np.arange(k) / k + rng.uniform(0.0, 1.0))
    shell = np.column_stack([np.sin(theta).ravel() * np.cos(phi).ravel(), np.sin(theta).ravel() * np.sin(phi).ravel(),
                             np.cos(theta).ravel()])
    angle = rng.uniform(0.0, 2.0 * np.pi)
    near = np.array([0.0, 0.0, 1.0]) + rng.uniform(3e-7, 2e-6) * np.array([np.cos(angle), np.sin(angle), 0.0])
    pts = np.vstack([shell, [[0.0, 0.0, 1.0], near / np.linalg.norm(near), [0.0, 0.0, -1.0]],
                     rng.normal(size=(10, 3)) * 0.3])
    return _f32(pts[rng.permutation(len(pts))])


@st.composite
def nearly_degenerate_subsets(draw):
    """A cloud with, on its hull, a nearly collinear triple (the middle point off the segment by a sine of 1e-9 to
    1e-5) or a nearly coplanar patch (points off a plane by 1e-15 to 1e-9 of their spread), float32 or float64."""
    rng = np.random.default_rng(draw(seeds))
    pts = rng.normal(size=(draw(st.integers(4, 60)), 3))
    a, b = rng.normal(size=3) * 3.0, rng.normal(size=3) * 3.0
    off = rng.normal(size=3)
    if draw(st.booleans()):  # a nearly collinear triple, pushed outwards
        t = rng.uniform(0.1, 0.9, size=draw(st.integers(1, 3)))
        extra = a + np.outer(t, b - a) + np.outer(10.0 ** rng.uniform(-9, -5, size=t.size), off) * np.linalg.norm(b - a)
        extra = np.vstack([a, b, extra])
    else:  # a nearly coplanar patch on a far plane
        e1, e2 = rng.normal(size=3), rng.normal(size=3)
        normal = np.cross(e1, e2)
        patch = rng.uniform(-1.0, 1.0, size=(draw(st.integers(4, 12)), 2)) @ np.vstack([e1, e2])
        height = 10.0 ** rng.uniform(-15, -9, size=(len(patch), 1)) * rng.choice([-1.0, 1.0], size=(len(patch), 1))
        extra = patch + normal * (3.0 + height)
    pts = np.vstack([pts, extra])[rng.permutation(len(pts) + len(extra))]
    return _f32(pts) if draw(st.booleans()) else pts


@st.composite
def lattices(draw):
    """Small-integer lattice points (a box's surface or its volume), scaled by a decimal (inexact) and moved,
    possibly float32-rounded: many points within round-off of faces and edges."""
    rng = np.random.default_rng(draw(seeds))
    n = draw(st.integers(4, 80))
    width = draw(st.integers(1, 4))
    pts = rng.integers(-width, width + 1, size=(n, 3)).astype(float)
    if draw(st.booleans()):
        pts[np.arange(n), rng.integers(0, 3, size=n)] = rng.choice([-width, width], size=n)
    scale, shift = draw(st.sampled_from([1.0, 0.1, 0.3, 1e3])), draw(st.sampled_from([0.0, 0.7, 1e3]))
    exact = scale in (1.0, 1e3) and shift in (0.0, 1e3)  # integers: the lattice is exact, no round-off
    pts = pts * scale + shift
    return (_f32(pts) if draw(st.booleans()) else pts), exact


def test_parrys_five_points_have_qhulls_hull():
    hull = _check_against_qhull(PARRY_FIVE)
    assert set(hull.vertices.tolist()) == {0, 1, 2, 3, 4}
    assert hull.volume == pytest.approx(3.0140356175970085e-05, rel=1e-12)


def test_parrys_whole_cloud_has_qhulls_hull():
    """The whole 4,054-point float32 cloud of parry's convex-hull test (crates/parry3d/tests/geometry/convex_hull.rs,
    ``test_complex_convex_hull``; exact duplicates included): Qhull's 190 vertices (by coordinates) and volume."""
    pts = np.load(Path(__file__).parent / "data" / "parry_convex_hull_cloud.npy").astype(np.float64)
    hull = _check_against_qhull(pts, exact_input=True)
    assert len(hull.vertices) == 190
    assert hull.volume == pytest.approx(0.18355884532196826, rel=1e-12)


@given(float32_clouds())
def test_float32_clouds_match_qhull(pts):
    _check_against_qhull(pts)


@settings(max_examples=60)
@given(sphere_shells())
def test_sphere_shells_with_a_pole_duplicate_match_qhull(pts):
    _check_against_qhull(pts)


@given(nearly_degenerate_subsets())
def test_nearly_collinear_and_coplanar_subsets_match_qhull(pts):
    _check_against_qhull(pts)


@given(lattices())
def test_lattices_match_qhull(lattice):
    """Exact lattices: Qhull's vertex set (no point inside a face or on an edge is a vertex); rounded ones: or its
    volume."""
    pts, exact = lattice
    _check_against_qhull(pts, exact_input=exact)


@st.composite
def gentle_caps(draw):
    """Points in a unit disk lifted onto a paraboloid z = -c (x² + y²) so flat that neighbouring faces are within
    MERGE_TOL of each other's planes while the cap's middle is 10 to 1,000 times that above its rim, and an apex
    below: a merge of nearly coplanar faces must not flatten the cap (its middle points would be left outside)."""
    rng = np.random.default_rng(draw(seeds))
    n = draw(st.integers(20, 60))
    r, t = np.sqrt(rng.uniform(0.0, 1.0, size=n)), rng.uniform(0.0, 2.0 * np.pi, size=n)
    c = MERGE_TOL * 10.0 ** rng.uniform(1.0, 3.0)
    cap = np.column_stack([r * np.cos(t), r * np.sin(t), -c * r * r])
    return np.vstack([cap, [[0.0, 0.0, -1.0]]])


@given(gentle_caps())
def test_gentle_caps_keep_every_point_inside(pts):
    _check_against_qhull(pts)


@st.composite
def nearly_coplanar_quadruples(draw):
    """Four points, the fourth within 0 to 1e-12 (relative) of the plane of the first three, or exactly on it
    (small integers times a power of two), or the first three nearly collinear."""
    rng = np.random.default_rng(draw(seeds))
    kind = draw(st.sampled_from(["near", "exact", "sliver"]))
    if kind == "exact":
        base = rng.integers(-8, 9, size=(3, 3)).astype(float)
        w = rng.integers(-3, 4, size=2).astype(float)
        p = base[0] + w[0] * (base[1] - base[0]) + w[1] * (base[2] - base[0])
        return np.ldexp(np.vstack([base, p]), int(rng.integers(-30, 30)))
    base = rng.normal(size=(3, 3)) * 10.0 ** rng.uniform(-3, 3)
    if kind == "sliver":
        base[2] = base[0] + rng.uniform(-2, 3) * (base[1] - base[0]) + 10.0 ** rng.uniform(-16, -8) * rng.normal(size=3)
    w = rng.uniform(-2, 3, size=2)
    p = base[0] + w[0] * (base[1] - base[0]) + w[1] * (base[2] - base[0])
    p = p + rng.normal(size=3) * 10.0 ** rng.uniform(-20, -12) * np.abs(p).max()
    return np.vstack([base, p])[:, :] + draw(st.sampled_from([0.0, 1.0, 1e3]))


def _exact_cross(pts):
    a, b, c = ([Fraction(float(x)) for x in row] for row in pts[:3])
    u = [b[k] - a[k] for k in range(3)]
    v = [c[k] - a[k] for k in range(3)]
    return [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]], a


@given(nearly_coplanar_quadruples())
def test_orient3d_has_the_exact_sign(pts):
    """Shewchuk's predicate: the sign of ((b − a) × (c − a)) · (p − a), with zero, equals the rational one's, in
    every order of the four points."""
    n, a = _exact_cross(pts)
    p = [Fraction(float(x)) for x in pts[3]]
    exact = sum(n[k] * (p[k] - a[k]) for k in range(3))
    sign = (exact > 0) - (exact < 0)
    assert np.sign(orient3d(pts, 0, 1, 2, 3)) == sign
    assert np.sign(orient3d(pts, 1, 2, 0, 3)) == sign  # a cyclic turn of the triangle keeps the sign
    assert np.sign(orient3d(pts, 0, 2, 1, 3)) == -sign  # reversing it flips the sign
    assert np.sign(orient3d(pts, 3, 1, 2, 0)) == -sign  # swapping two points flips it too


@given(nearly_coplanar_quadruples())
def test_accurate_cross_is_within_a_few_ulps_of_the_exact_cross_product(pts):
    n, _ = _exact_cross(pts)
    got = accurate_cross(pts, 0, 1, 2, np.empty(3))
    dropped = 16 * Fraction(2.0 ** -106) * Fraction(float(np.abs(pts[:3] - pts[0]).max())) ** 2  # ~ ε² |u| |v|
    for k in range(3):  # a few ulps of the component, or of the dropped terms when it cancels
        assert abs(Fraction(float(got[k])) - n[k]) <= Fraction(4 * 2.0 ** -53) * abs(n[k]) + dropped, k
