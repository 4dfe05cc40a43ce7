"""Ray-cast kernels (engine/narrowphase/ray_*.py) against oracles written here, sharing no code with them.

- The generic oracle: along a ray, a convex shape's signed distance s(t) (any convex function negative inside,
  zero on the surface) is convex in t, so the first t >= 0 with s(t) <= 0 is found by minimising s on
  [0, tmax] (ternary search) and bisecting on [0, argmin]. It serves every shape; the sphere also has the
  textbook quadratic solved in exact rational arithmetic (the square root to 50 digits).
- One checker, ``ray_problems``, lists what is wrong with a kernel's answer: a robust hit missed or a robust
  miss hit, t off the oracle's, the hit point off the surface, a normal that is not the outward normal of a
  face through the hit point, NaN in a hit, a miss not written (inf, nan, nan, nan), an origin inside without
  (0, −d). Cases within round-off of tangency or of tmax (the oracle's margin) only get the checks that hold
  either way; the grazing tests build exactly representable tangent rays and require the hit.
- Planted defects: the same checker reports a kernel's copy with one comparison or sign changed.
"""
from __future__ import annotations

import importlib
import inspect
import math
from decimal import Decimal, localcontext
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st

from engine import convex_hull
from engine.narrowphase import hull_planes, ray_box, ray_capsule, ray_halfspace, ray_hull, ray_sphere
from properties.strategies.narrow import point_clouds, rotations, sizes, unit_interval, vectors

INF, NAN = math.inf, math.nan
#: t and surface tolerances, relative to the scene's size (largest coordinate or extent)
REL = 1e-10
#: normals: unit to this, and equal to the oracle's to this
NORMAL_TOL = 1e-8


def tup(v):
    return tuple(float(x) for x in v)


def unit(v):
    v = np.asarray(v, dtype=np.float64)
    return tup(v / np.linalg.norm(v))


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def along(o, d, t):
    return (o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2])


# ---------------------------------------------------------------------------------------------------------------
# shapes: the kernel call, and the oracle's signed distance and face normals, in plain Python
# ---------------------------------------------------------------------------------------------------------------
class Shape:
    """A shape for the checker: ``cast(o, d, tmax)`` the kernel's answer; ``sdf(p)`` convex, <= 0 exactly on
    the solid; ``normals(p, tol)`` the outward unit normals of the faces within tol of p; ``centre`` a point
    inside and ``bound`` a radius about it holding the shape; ``scaled(k)`` the same scene scaled by k;
    ``horizon``: the largest t at which a ray can first meet the shape (unbounded shapes: 1e300)."""

    def __init__(self, cast, sdf, normals, centre, bound, scaled, horizon=None):
        self.cast, self.sdf, self.normals = cast, sdf, normals
        self.centre, self.bound, self.scaled = tup(centre), float(bound), scaled
        self.horizon = horizon or (lambda o: float(np.linalg.norm(np.subtract(o, self.centre))) + self.bound)


def sphere(c, r):
    c = tup(c)

    def normals(p, tol):  # none for a point (r = 0): any unit normal is right there
        v = np.subtract(p, c)
        n = np.linalg.norm(v)
        return [tup(v / n)] if n > 0 and r > 0 else []

    return Shape(lambda o, d, tmax: ray_sphere(o, d, tmax, c, r),
                 lambda p: float(np.linalg.norm(np.subtract(p, c))) - r, normals, c, r,
                 lambda k: sphere(np.multiply(c, k), r * k))


def box(c, R, h):
    c, h, R = tup(c), tup(h), np.ascontiguousarray(R, dtype=np.float64)

    def local(p):
        return R.T @ np.subtract(p, c)

    def sdf(p):
        q = np.abs(local(p)) - h
        return float(np.linalg.norm(np.maximum(q, 0.0)) + min(q.max(), 0.0))

    def normals(p, tol):
        x = local(p)
        return [tup(np.sign(x[k]) * R[:, k]) for k in range(3) if abs(x[k]) - h[k] >= -tol]

    shape = Shape(lambda o, d, tmax: ray_box(o, d, tmax, c, R, h), sdf, normals, c, float(np.linalg.norm(h)),
                  lambda k: box(np.multiply(c, k), R, np.multiply(h, k)))
    shape.parts = (c, R, h)
    return shape


def capsule(p0, p1, r):
    p0, p1 = tup(p0), tup(p1)
    a = np.subtract(p1, p0)

    def closest(p):
        L2 = float(a @ a)
        s = 0.0 if L2 == 0 else min(max(float(np.subtract(p, p0) @ a) / L2, 0.0), 1.0)
        return np.add(p0, s * a)

    def normals(p, tol):
        v = np.subtract(p, closest(p))
        n = np.linalg.norm(v)
        return [tup(v / n)] if n > 0 else []

    return Shape(lambda o, d, tmax: ray_capsule(o, d, tmax, p0, p1, r),
                 lambda p: float(np.linalg.norm(np.subtract(p, closest(p)))) - r, normals,
                 np.add(p0, 0.5 * a), 0.5 * np.linalg.norm(a) + r,
                 lambda k: capsule(np.multiply(p0, k), np.multiply(p1, k), r * k))


def halfspace(p, n, centre, bound):
    """The half-space; centre/bound: the region the rays look at (the shape itself is unbounded)."""
    p, n = tup(p), tup(n)
    return Shape(lambda o, d, tmax: ray_halfspace(o, d, tmax, p, n), lambda x: dot(n, np.subtract(x, p)),
                 lambda x, tol: [n], centre, bound,
                 lambda k: halfspace(np.multiply(p, k), n, np.multiply(centre, k), bound * k), lambda o: 1e300)


def hull(c, R, planes, inner, bound):
    """The polyhedron of ``planes`` rows (n, e) placed at (c, R); ``inner`` a local point inside it, ``bound``
    the largest distance from it to the solid's points."""
    c, R, planes = tup(c), np.ascontiguousarray(R, dtype=np.float64), np.ascontiguousarray(planes)
    N, E = planes[:, :3], planes[:, 3]

    def normals(p, tol):
        x = R.T @ np.subtract(p, c)
        return [tup(R @ N[i]) for i in range(len(E)) if N[i] @ x - E[i] >= -tol]

    return Shape(lambda o, d, tmax: ray_hull(o, d, tmax, c, R, planes, len(E)),
                 lambda p: float(np.max(N @ (R.T @ np.subtract(p, c)) - E)), normals, np.add(c, R @ inner), bound,
                 lambda k: hull(np.multiply(c, k), R, np.column_stack([N, E * k]), np.multiply(inner, k), bound * k))


# ---------------------------------------------------------------------------------------------------------------
# oracles
# ---------------------------------------------------------------------------------------------------------------
def convex_first_hit(s, tmax, horizon):
    """(t, margin): the first t in [0, tmax] with s(t) <= 0 (inf if none) for a convex s, and the minimum of
    s on [0, min(tmax, horizon)] (s(0) when the origin is inside): how far the answer is from flipping."""
    s0 = s(0.0)
    if s0 <= 0.0:
        return 0.0, s0
    lo, hi = 0.0, min(tmax, horizon)
    for _ in range(120):  # ternary search of the minimum of a convex function
        m1, m2 = lo + (hi - lo) / 3.0, hi - (hi - lo) / 3.0
        if s(m1) < s(m2):
            hi = m2
        else:
            lo = m1
    tm = min(max(0.5 * (lo + hi), 0.0), min(tmax, horizon))
    smin = s(tm)
    if smin > 0.0:
        return INF, smin
    # s(lo) > 0 >= s(hi): bisect to the crossing on the bit patterns (ordered as the floats >= 0): exact in 64 steps
    lo, hi = _bits(0.0), _bits(tm)
    while hi - lo > 1:
        mid = (lo + hi) // 2
        lo, hi = (lo, mid) if s(_float(mid)) <= 0.0 else (mid, hi)
    return _float(hi), smin


def _bits(x):
    return int(np.float64(x).view(np.int64))


def _float(i):
    return float(np.int64(i).view(np.float64))


def oracle(shape, o, d, tmax):
    return convex_first_hit(lambda t: shape.sdf(along(o, d, t)), tmax, shape.horizon(o))


def sphere_exact(o, d, tmax, c, r):
    """The first hit of the ray with the ball, from t² (d·d) + 2 t b + c' = 0 in exact rationals (the float
    inputs read exactly; the square root to 50 digits): (t, discriminant / (d·d)² = r² − (distance from c to
    the line)², |o − c|² − r²), the last two rounded."""
    m = [Fraction(o[i]) - Fraction(c[i]) for i in range(3)]
    dd = [Fraction(x) for x in d]
    a = sum(x * x for x in dd)
    b = sum(x * y for x, y in zip(m, dd))
    cc = sum(x * x for x in m) - Fraction(r) ** 2
    if cc <= 0:
        return 0.0, -1.0, float(cc)
    disc = b * b - a * cc
    rel = float(disc / (a * a))
    if b >= 0 or disc < 0:
        return INF, rel, float(cc)
    with localcontext() as ctx:
        ctx.prec = 50
        root = Decimal(disc.numerator) / Decimal(disc.denominator)
        t = (-Decimal(b.numerator) / Decimal(b.denominator) - root.sqrt()) / (
            Decimal(a.numerator) / Decimal(a.denominator))
    t = float(t)
    return (t if t <= tmax else INF), rel, float(cc)


# ---------------------------------------------------------------------------------------------------------------
# the checker
# ---------------------------------------------------------------------------------------------------------------
def scene_size(shape, o):
    return max(max(abs(x) for x in o), max(abs(x) for x in shape.centre), shape.bound, 1e-300)


def ray_problems(shape, o, d, tmax, out, hit_at=None):
    """What is wrong with the kernel's answer ``out`` for the ray (o, d, tmax); ``hit_at``: the exact first hit
    of a constructed ray (grazing, on the boundary), required whatever the oracle's margin."""
    size = scene_size(shape, o)
    tol = REL * size
    if 0.0 < out[0] < INF:  # far hits (a ray nearly parallel to a half-space): round-off relative to t
        tol = REL * max(size, out[0])
    if hit_at is None:
        t_o, margin = oracle(shape, o, d, tmax)
        robust = abs(margin) > tol
    else:
        t_o, robust = hit_at, True
    if len(out) != 4:
        return ["not a 4-tuple"]
    t, n = out[0], out[1:]
    if t == INF:
        if not all(math.isnan(x) for x in n):
            return [f"a miss with a normal {n}"]
        return [f"missed the hit at t={t_o!r}"] if robust and t_o < INF else []
    problems = []
    if any(math.isnan(x) for x in out):
        return [f"NaN in a hit {out}"]
    if not 0.0 <= t <= tmax:
        problems.append(f"t={t!r} outside [0, {tmax!r}]")
    if abs(math.sqrt(dot(n, n)) - 1.0) > 1e-12:
        problems.append(f"normal {n} not unit")
    if robust and t_o == INF:
        problems.append(f"hit at t={t!r} where the oracle misses")
    if t == 0.0:
        if n != (-d[0], -d[1], -d[2]):
            problems.append(f"t = 0 with normal {n}, not -d")
        if shape.sdf(o) > tol:
            problems.append(f"t = 0 from an origin outside (sdf {shape.sdf(o)!r})")
        return problems
    p = along(o, d, t)
    if abs(shape.sdf(p)) > tol:
        problems.append(f"hit point off the surface by {shape.sdf(p)!r}")
    faces = shape.normals(p, tol)
    if faces and min(max(abs(a - b) for a, b in zip(n, f)) for f in faces) > NORMAL_TOL:
        problems.append(f"normal {n} is none of the faces' {faces} at the hit point")
    if dot(n, d) > NORMAL_TOL:
        problems.append(f"normal {n} faces away from the ray (d·n = {dot(n, d)!r})")
    if robust and t_o < INF:
        faces_o = shape.normals(along(o, d, t_o), tol)
        slope = -max((dot(d, f) for f in faces_o), default=-1.0)
        if abs(t - t_o) > tol / max(slope, 1e-3):
            problems.append(f"t={t!r}, the oracle's {t_o!r} (slope {slope!r})")
    return problems


def check(shape, o, d, tmax, hit_at=None):
    out = shape.cast(o, d, tmax)
    problems = ray_problems(shape, o, d, tmax, out, hit_at)
    assert not problems, (out, problems)
    return out


# ---------------------------------------------------------------------------------------------------------------
# strategies
# ---------------------------------------------------------------------------------------------------------------
triples = st.tuples(unit_interval, unit_interval, unit_interval).map(np.array)


def directions():
    return triples.filter(lambda v: np.linalg.norm(v) > 0.1).map(unit)


@st.composite
def rays(draw, shape, kinds=("aimed", "aimed", "aimed", "inside", "random", "away")):
    """A ray about ``shape``: aimed at a point in or near it (most hit), from inside, random, or pointing away;
    tmax inf, 0, or random (shorter or longer than the hit)."""
    c, b = np.array(shape.centre), max(shape.bound, 0.5)
    kind = draw(st.sampled_from(kinds))
    o = c + (0.4 if kind == "inside" else 4.0) * b * draw(triples)
    if kind == "random":
        d = draw(directions())
    else:
        target = o - c if kind == "away" else c + 0.8 * b * draw(triples) - o
        assume(np.linalg.norm(target) > 1e-6 * b)
        d = unit(target)
    tmax = draw(st.one_of(st.just(INF), st.just(INF), st.just(0.0), st.floats(0.0, 8.0 * b)))
    return tup(o), d, tmax




def flush(v):
    """v with components below 1e-150 set to 0: products of such numbers stay normal floats (the exact scaling
    by powers of two holds for normal floats only)."""
    return tuple(0.0 if abs(x) < 1e-150 else float(x) for x in v)


centres = vectors.map(flush)
radii = st.one_of(sizes, sizes, sizes, st.just(0.0))  # a quarter points


@st.composite
def spheres(draw):
    return sphere(draw(centres), draw(radii))


@st.composite
def boxes(draw):
    return box(draw(centres), draw(rotations()), draw(st.tuples(sizes, sizes, sizes)))


@st.composite
def capsules(draw):
    p0 = np.array(draw(centres))
    length = draw(st.one_of(st.just(0.0), sizes))
    return capsule(p0, p0 + length * np.array(draw(directions())), draw(sizes))


@st.composite
def halfspaces(draw):
    p = draw(centres)
    return halfspace(p, unit(flush(draw(directions()))), p, 3.0)


@st.composite
def hulls(draw):
    pts = draw(point_clouds(max_points=12))
    inner = pts.mean(axis=0)
    bound = float(np.linalg.norm(pts - inner, axis=1).max())
    return hull(draw(centres), draw(rotations()), hull_planes(pts), inner, bound)


SHAPES = {"sphere": spheres(), "box": boxes(), "capsule": capsules(), "halfspace": halfspaces(), "hull": hulls()}


# ---------------------------------------------------------------------------------------------------------------
# properties
# ---------------------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("kind", sorted(SHAPES))
@given(data=st.data())
def test_kernel_equals_the_convex_oracle(kind, data):
    shape = data.draw(SHAPES[kind], label="shape")
    o, d, tmax = data.draw(rays(shape), label="ray")
    check(shape, o, d, tmax)


@given(c=centres, r=radii, data=st.data())
def test_sphere_equals_the_exact_quadratic(c, r, data):
    shape = sphere(c, r)
    o, d, tmax = data.draw(rays(shape), label="ray")
    t, *n = ray_sphere(o, d, tmax, c, r)
    t_exact, gap2, outside = sphere_exact(o, d, tmax, c, r)
    size = scene_size(shape, o)
    assume(abs(gap2) > 1e-9 * size**2 and abs(outside) > 1e-9 * size**2)  # not within round-off of tangency,
    assume(tmax == INF or abs(t_exact - tmax) > 1e-9 * size or t_exact == INF)  # of the surface, of tmax
    if t_exact == INF:
        assert t == INF and all(math.isnan(x) for x in n)
        return
    slope = math.sqrt(max(gap2, 0.0)) / max(r, 1e-300) if t_exact > 0 else 1.0  # cosine of the incidence
    assert abs(t - t_exact) <= 1e-11 * size / max(slope, 1e-3), (t, t_exact)


@pytest.mark.parametrize("kind", sorted(SHAPES))
@given(data=st.data())
def test_from_the_centre_is_zero_and_minus_d_and_away_misses(kind, data):
    shape = data.draw(SHAPES[kind], label="shape")
    d = data.draw(directions(), label="d")
    tmax = data.draw(st.one_of(st.just(INF), st.just(0.0), st.floats(0.0, 10.0)))
    assert shape.cast(shape.centre, d, tmax) == (0.0, -d[0], -d[1], -d[2])
    # from outside, moving away from a point inside: a convex shape is never met
    o = tup(np.add(shape.centre, np.multiply(d, 3.0 * shape.bound)))
    if kind != "halfspace" and shape.sdf(o) > 0.0:
        out = shape.cast(o, d, tmax)
        assert out[0] == INF and all(math.isnan(x) for x in out[1:])


@pytest.mark.parametrize("kind", sorted(SHAPES))
@given(data=st.data())
def test_tmax_zero_hits_only_from_the_closed_solid(kind, data):
    shape = data.draw(SHAPES[kind], label="shape")
    o, d, _ = data.draw(rays(shape), label="ray")
    inside = shape.sdf(o)
    assume(abs(inside) > REL * scene_size(shape, o))
    out = shape.cast(o, d, 0.0)
    if inside < 0.0:
        assert out == (0.0, -d[0], -d[1], -d[2])
    else:
        assert out[0] == INF and all(math.isnan(x) for x in out[1:])


@pytest.mark.parametrize("kind", sorted(SHAPES))
@given(data=st.data())
def test_tmax_short_of_the_hit_misses(kind, data):
    shape = data.draw(SHAPES[kind], label="shape")
    o, d, _ = data.draw(rays(shape, kinds=("aimed",)), label="ray")
    t, *_ = shape.cast(o, d, INF)
    assume(0.0 < t < INF)
    short = shape.cast(o, d, t * (1.0 - 1e-9))
    assert short[0] == INF and all(math.isnan(x) for x in short[1:])
    assert shape.cast(o, d, t) == shape.cast(o, d, INF)  # tmax at the hit: hit


@pytest.mark.parametrize("kind", sorted(SHAPES))
@pytest.mark.parametrize("k", [2.0**-20, 2.0**20])
@given(data=st.data())
def test_power_of_two_scaling_is_exact(kind, k, data):
    shape = data.draw(SHAPES[kind], label="shape")
    o, d, tmax = data.draw(rays(shape), label="ray")
    assume(flush(d) == d and flush(o) == o)  # exact while no product leaves the normal floats
    t, *n = shape.cast(o, d, tmax)
    ts, *ns = shape.scaled(k).cast(tup(np.multiply(o, k)), d, tmax * k)
    assert ts == t * k and (np.array_equal(ns, n, equal_nan=True))


@pytest.mark.parametrize("kind", sorted(SHAPES))
@pytest.mark.parametrize("k", [1e-6, 1e6])
@given(data=st.data())
def test_tiny_and_huge_scenes(kind, k, data):
    shape = data.draw(SHAPES[kind], label="shape")
    o, d, tmax = data.draw(rays(shape), label="ray")
    big = shape.scaled(k)
    ob, tb = tup(np.multiply(o, k)), tmax * k
    out = check(big, ob, d, tb)
    t_o, margin = oracle(shape, o, d, tmax)
    if 0.0 < out[0] < INF and abs(margin) > 1e-6 * scene_size(shape, o):  # robust: same face, same normal
        t, *n = shape.cast(o, d, tmax)
        assert math.isclose(out[0] / k, t, rel_tol=1e-9, abs_tol=1e-9 * scene_size(shape, o))
        assert np.allclose(out[1:], n, atol=1e-9)


# --- grazing rays and origins on the boundary: exactly representable, must hit -----------------------------------
dyadic = st.integers(-64, 64).map(lambda i: i / 8.0)
dyadic_size = st.integers(1, 24).map(lambda i: i / 8.0)
axes = st.integers(0, 2)
signs = st.sampled_from([-1.0, 1.0])


def e(k, s=1.0):
    v = [0.0, 0.0, 0.0]
    v[k] = s
    return tuple(v)


def signed_permutation(draw):
    perm = draw(st.permutations([0, 1, 2]))
    R = np.zeros((3, 3))
    for col, row in enumerate(perm):
        R[row, col] = draw(signs)
    return R


@given(st.tuples(dyadic, dyadic, dyadic), dyadic_size, dyadic_size, st.permutations([0, 1, 2]), signs, signs)
def test_sphere_tangent_ray_hits(c, r, L, ax, si, sj):
    i, j, _ = ax  # the ray runs along ±e_i, touching the ball at c + sj r e_j
    o = tup(np.add(c, np.multiply(e(j, sj), r)) - np.multiply(e(i, si), L))
    t_out = check(sphere(c, r), o, e(i, si), INF, hit_at=L)
    assert t_out[1:] == e(j, sj)
    boundary = tup(np.add(c, np.multiply(e(j, sj), r)))  # on the sphere, leaving it: (0, -d)
    assert check(sphere(c, r), boundary, e(j, sj), 0.0, hit_at=0.0) == (0.0, *e(j, -sj))


@st.composite
def axis_boxes(draw):
    return (draw(st.tuples(dyadic, dyadic, dyadic)), signed_permutation(draw),
            draw(st.tuples(dyadic_size, dyadic_size, dyadic_size)))


def _face_grazing_ray(draw, c, R, h, edge):
    """A ray along a world axis R e_i on the plane of one face (two faces for ``edge``), entering through the
    face across slab i: (o, d, t of the entry, the entering face's outward normal)."""
    i, j, k = draw(st.permutations([0, 1, 2]))
    si, sj, sk = draw(signs), draw(signs), draw(signs)
    L = draw(dyadic_size)
    local = np.zeros(3)
    local[i] = -si * (h[i] + L)  # L before the entering face
    local[j] = sj * h[j]  # on face j
    local[k] = sk * h[k] if edge else draw(st.integers(-4, 4)) / 4.0 * h[k]
    o = tup(np.add(c, R @ local))
    return o, tup(si * R[:, i]), L, tup(-si * R[:, i])


@pytest.mark.parametrize("edge", [False, True])
@given(axis_boxes(), st.data())
def test_box_and_hull_rays_along_a_face_or_an_edge_hit(edge, b, data):
    c, R, h = b
    o, d, L, n = _face_grazing_ray(data.draw, c, R, h, edge)
    assert check(box(c, R, h), o, d, INF, hit_at=L)[1:] == n
    corners = np.array([[x, y, z] for x in (-h[0], h[0]) for y in (-h[1], h[1]) for z in (-h[2], h[2])])
    shape = hull(c, R, hull_planes(corners), np.zeros(3), float(np.linalg.norm(h)))
    assert check(shape, o, d, INF, hit_at=L)[1:] == n


@given(st.tuples(dyadic, dyadic, dyadic), dyadic_size, dyadic_size, dyadic_size, st.permutations([0, 1, 2]), signs)
def test_capsule_grazing_rays_hit(p0, length, r, L, ax, s):
    i, j, k = ax  # the segment along e_i
    p1 = tup(np.add(p0, np.multiply(e(i), length)))
    shape = capsule(p0, p1, r)
    side = np.multiply(e(j, s), r)
    # parallel to the axis at distance r: tangent to the end ball at p0's equator
    o = tup(np.add(p0, side) - np.multiply(e(i), L))
    assert np.allclose(check(shape, o, e(i), INF, hit_at=L)[1:], e(j, s), rtol=0.0, atol=1e-15)
    # across the axis at distance r, over the middle: tangent to the cylinder
    mid = np.add(p0, np.multiply(e(i), length / 2.0))
    o = tup(mid + side - np.multiply(e(k), L))
    assert np.allclose(check(shape, o, e(k), INF, hit_at=L)[1:], e(j, s), rtol=0.0, atol=1e-15)


@given(st.tuples(dyadic, dyadic, dyadic), st.tuples(dyadic, dyadic, dyadic), axes, signs)
def test_halfspace_boundary_and_parallel(p, shift, k, s):
    n = e(k, s)
    shape = halfspace(p, n, p, 3.0)
    on = list(np.add(p, shift))
    on[k] = p[k]  # on the boundary plane
    on = tup(on)
    assert check(shape, on, n, INF, hit_at=0.0) == (0.0, *e(k, -s))  # leaving from the surface: (0, -d)
    above = tup(np.add(on, n))
    tangent = e((k + 1) % 3)
    assert shape.cast(above, tangent, INF)[0] == INF  # parallel above the surface: never enters
    assert check(shape, above, e(k, -s), INF, hit_at=1.0)[1:] == n


# --- hull_planes --------------------------------------------------------------------------------------------------
def test_hull_planes_of_a_cube_has_six_rows():
    cube = np.array([[x, y, z] for x in (-1.0, 1.0) for y in (-1.0, 1.0) for z in (-1.0, 1.0)]) * 3.0 + 7.0
    rows = hull_planes(cube)
    assert rows.shape == (6, 4)
    assert {tuple(r) for r in rows} == {(*e(k, s), 7.0 * s + 3.0) for k in range(3) for s in (-1.0, 1.0)}


@given(point_clouds(max_points=16), st.sampled_from([1.0, 1e-6, 1e6]))
def test_hull_planes_bound_the_hull_one_row_per_plane(pts, k):
    pts = pts * k
    rows = hull_planes(pts)
    scale = np.abs(pts).max()
    N, E = rows[:, :3], rows[:, 3]
    assert np.allclose(np.linalg.norm(N, axis=1), 1.0, atol=1e-12)
    gaps = pts @ N.T - E  # every point inside, every row touching the hull
    assert gaps.max() <= 1e-12 * scale and np.allclose(gaps.max(axis=0), 0.0, atol=1e-12 * scale)
    for a in range(len(rows)):  # distinct planes
        for b in range(a + 1, len(rows)):
            assert N[a] @ N[b] < 1.0 - 1e-12 or abs(E[a] - E[b]) > 1e-9 * scale
    ref = convex_hull(pts)
    q = pts.mean(axis=0) + (pts - pts.mean(axis=0)) * 1.3  # queries about the boundary: same solid
    for x in q:
        inside_rows, inside_hull = np.max(N @ x - E), np.max(ref.normals @ x - ref.offsets)
        if abs(inside_hull) > 1e-9 * scale:
            assert (inside_rows <= 0) == (inside_hull <= 0)


@given(b=boxes(), data=st.data())
def test_hull_of_the_box_corners_agrees_with_ray_box(b, data):
    o, d, tmax = data.draw(rays(b), label="ray")
    c, R, h = b.parts
    corners = np.array([[x, y, z] for x in (-h[0], h[0]) for y in (-h[1], h[1]) for z in (-h[2], h[2])])
    rows = hull_planes(corners)
    assert len(rows) == 6
    tb, *nb = ray_box(o, d, tmax, c, R, h)
    th, *nh = ray_hull(o, d, tmax, c, R, rows, 6)
    size = scene_size(b, o)
    t_o, margin = oracle(b, o, d, tmax)
    if abs(margin) > REL * size:
        assert (tb == INF) == (th == INF)
    if tb < INF and th < INF:
        assert abs(tb - th) <= REL * size / 1e-3
        faces = b.normals(along(o, d, tb), REL * size)
        if len(faces) == 1 and th > 0:  # away from edges: the same face
            assert np.allclose(nb, nh, atol=NORMAL_TOL)


# --- planted defects: the checker reports a copy of a kernel with one change -------------------------------------
def mutant(module_name, names, old, new):
    """The kernel ``names[-1]`` of ``module_name``, interpreted, with ``old`` replaced by ``new`` once in the
    source of ``names`` (helpers it calls first, kernel last)."""
    module = importlib.import_module(module_name)
    namespace = dict(vars(module))
    hits = 0
    for name in names:
        src = inspect.getsource(vars(module)[name].py_func)
        hits += src.count(old)
        src = "\n".join(line for line in src.replace(old, new).splitlines() if not line.startswith("@"))
        exec(compile(src, f"<mutant of {name}>", "exec"), namespace)
    assert hits == 1, f"{old!r} occurs {hits} times"
    return namespace[names[-1]]


def _with_cast(shape, cast):
    return Shape(cast, shape.sdf, shape.normals, shape.centre, shape.bound, shape.scaled, shape.horizon)


def _reports(shape, cast, o, d, tmax, hit_at=None):
    """The real kernel passes the check and the mutant ``cast`` fails it."""
    assert not ray_problems(shape, o, d, tmax, shape.cast(o, d, tmax), hit_at)
    return ray_problems(_with_cast(shape, cast), o, d, tmax, cast(o, d, tmax), hit_at)


def test_planted_defects_are_reported():
    src = "engine.narrowphase."
    # sphere: the tangent ray missed (discr == 0 taken as a miss)
    bad = mutant(src + "ray_sphere", ["ray_sphere"], "if discr < 0.0:", "if discr <= 0.0:")
    assert _reports(sphere((0.0, 0.0, 0.0), 1.0), lambda o, d, tmax: bad(o, d, tmax, (0.0, 0.0, 0.0), 1.0),
                    (-3.0, 1.0, 0.0), (1.0, 0.0, 0.0), INF, hit_at=3.0)
    # box: a ray along a face missed (the closed slab taken open)
    c, R, h = (0.5, -1.0, 2.0), np.eye(3), (1.0, 2.0, 0.5)
    bad = mutant(src + "ray_box", ["ray_box"], "if abs(ok) > h[k]:", "if abs(ok) >= h[k]:")
    assert _reports(box(c, R, h), lambda o, d, tmax: bad(o, d, tmax, c, R, h), (-3.0, 1.0, 2.5), (1.0, 0.0, 0.0),
                    INF, hit_at=2.5)
    # capsule: the cylinder's normal mirrored (its x negated)
    p0, p1 = (0.0, 0.0, 0.0), (0.0, 2.0, 0.0)
    bad = mutant(src + "ray_capsule", ["_ray_cylinder_side", "ray_capsule"], "return t, nx / length,",
                 "return t, -nx / length,")
    assert _reports(capsule(p0, p1, 0.5), lambda o, d, tmax: bad(o, d, tmax, p0, p1, 0.5),
                    (-3.0, 1.0, 0.1), unit((1.0, 0.1, 0.0)), INF)
    # half-space: an origin on the surface taken as outside
    bad = mutant(src + "ray_halfspace", ["ray_halfspace"], "if height <= 0.0:", "if height < 0.0:")
    p, n = (0.0, 1.0, 0.0), (0.0, 1.0, 0.0)
    assert _reports(halfspace(p, n, p, 3.0), lambda o, d, tmax: bad(o, d, tmax, p, n),
                    (2.0, 1.0, -1.0), (0.0, 1.0, 0.0), INF, hit_at=0.0)
    # hull: the sign of the crossing time flipped
    rows = hull_planes(np.array([[x, y, z] for x in (-1.0, 1.0) for y in (-1.0, 1.0) for z in (-1.0, 1.0)]))
    bad = mutant(src + "ray_hull", ["ray_hull"], "t = -height / rate", "t = height / rate")
    shape = hull((0.0, 0.0, 0.0), np.eye(3), rows, np.zeros(3), math.sqrt(3.0))
    assert _reports(shape, lambda o, d, tmax: bad(o, d, tmax, (0.0, 0.0, 0.0), np.eye(3), rows, 6),
                    (-5.0, 0.2, 0.3), unit((1.0, 0.05, 0.0)), INF)
