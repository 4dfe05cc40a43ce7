"""Rays against static triangle surfaces (engine/narrowphase/ray_triangle.py, ray_mesh.py and the World's rows).

The oracle is independent of the kernel: exact integer arithmetic on the floats the kernel reads (every float is
an integer times 2^−1100), the ray meeting a triangle when the three signed volumes (Plücker side tests)
D·(C×B), D·(A×C), D·(B×A) of the corners A, B, C relative to the origin have no two opposite signs (an edge or a
vertex belongs to the triangle) and their sum is not 0 (a ray in the triangle's plane misses), at
t = n·A / n·D (n = (B − A) × (C − A)), in [0, t_max]. The kernel's nearest hit must be one of the exact hits, at
the exact smallest t to 1e-12 relative, with the stored face normal turned against the ray by the exact sign of
n·D; a miss must be an exact miss. Scenes: random soups and heightfields at scales 1e-3 to 1e3.

Also: a HeightField answers bit for bit as the TriangleMesh of its triangles (rays along its grid lines, through
its vertices, vertical and horizontal ones included); rays aimed at the shared edges and vertices of closed meshes
(icospheres, cubes, randomly turned, moved and scaled) always hit, and vertical rays down the grid lines of a
heightfield too (there the kernel's edge functions are exactly 0); a ray from far outside crosses a closed mesh
an even number of times; through the World, masks, sensors, max_distance, all_hits and threads behave as for
every kind.
"""
from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from engine import HeightField, Sphere, TriangleMesh, World
from engine.narrowphase.ray_mesh import ray_mesh
from engine.narrowphase.ray_sphere import ray_sphere
from engine.narrowphase.ray_triangle import ray_triangle, ray_triangle_side

seeds = st.integers(0, 2**32 - 1)
scales = st.sampled_from([1e-3, 1.0, 1e3])
_E = 1100  # every float64 is an integer times 2^-1074; times 2^1100 every one used here is an integer


def _unit(d):
    """The unit directions exactly as the kernels' callers compute them (engine.narrowphase.ray_mesh.as_rays)."""
    d = np.asarray(d, float)
    return d / np.sqrt((d * d).sum(axis=-1, keepdims=True))


# -- the exact oracle ------------------------------------------------------------------------------------------
def _int(x: float) -> int:
    num, den = float(x).as_integer_ratio()
    return num * ((1 << _E) // den)


def _vec(p):
    return [_int(x) for x in p]


def _sub(a, b):
    return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]


def _cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def exact_hit(o, d, t_max, a, b, c):
    """(t as a Fraction, side ±1) of the ray o + t·d with the closed two-sided triangle abc, exactly; None for a
    miss. side = −sign(n·d), n the right-hand normal."""
    oi, di = _vec(o), _vec(d)
    A, B, C = _sub(_vec(a), oi), _sub(_vec(b), oi), _sub(_vec(c), oi)
    u, v, w = _dot(di, _cross(C, B)), _dot(di, _cross(A, C)), _dot(di, _cross(B, A))
    if (u < 0 or v < 0 or w < 0) and (u > 0 or v > 0 or w > 0):
        return None
    n = _cross(_sub(B, A), _sub(C, A))
    nd = _dot(n, di)
    if nd == 0:  # the ray in the triangle's plane (u + v + w = −n·d = 0)
        return None
    t = Fraction(_dot(n, A), nd)
    if t < 0 or (np.isfinite(t_max) and t > Fraction(t_max)):
        return None
    return t, (-1 if nd > 0 else 1)


def exact_hits(mesh, o, d, t_max):
    """{triangle: (t, side)} of every triangle the ray meets, exactly."""
    found = {}
    for k, tri in enumerate(mesh.triangles):
        h = exact_hit(o, d, t_max, *(mesh.vertices[i] for i in tri))
        if h is not None:
            found[k] = h
    return found


def assert_nearest_is_exact(mesh, o, d, t_max, t, normal, tri):
    """The kernel's answer (t, normal, triangle) for one unit ray against the exact hits of every triangle."""
    hits = exact_hits(mesh, o, d, t_max)
    if not hits:
        assert tri == -1 and t == np.inf and np.isnan(normal).all(), (tri, t)
        return
    best = min(h[0] for h in hits.values())
    assert tri in hits, (tri, sorted(hits), float(best), t)
    assert abs(Fraction(t) - best) <= Fraction(1e-12) * best, (t, float(best))
    assert abs(hits[tri][0] - best) <= Fraction(1e-12) * best
    np.testing.assert_array_equal(normal, hits[tri][1] * mesh.normals[tri])


# -- scenes ----------------------------------------------------------------------------------------------------
def random_soup(rng, scale):
    """A soup of 4-40 random triangles (some sharing vertices) about a random centre."""
    nv = int(rng.integers(4, 30))
    v = rng.normal(size=(nv, 3)) * scale + rng.normal(size=3) * scale
    t = np.array([rng.choice(nv, 3, replace=False) for _ in range(int(rng.integers(4, 40)))])
    return TriangleMesh(v, t)


def random_field(rng, scale):
    nx, nz = (int(k) for k in rng.integers(2, 9, size=2))
    h = rng.uniform(-1.0, 1.0, size=(nx, nz)) * scale
    if rng.uniform() < 0.2:
        h[:] = h[0, 0]  # flat: rays in its plane, along its grid lines
    return HeightField(h, rng.uniform(0.2, 2.0, size=2) * scale, rng.normal(size=2) * scale)


def random_rays(rng, mesh, k, scale):
    """k rays about the surface: half aimed at a random point of a random triangle, half random; lengths inf or
    random."""
    lo, hi = mesh.vertices.min(axis=0), mesh.vertices.max(axis=0)
    span = np.maximum(hi - lo, scale)
    o = lo - span + rng.uniform(size=(k, 3)) * 3 * span
    tri = mesh.vertices[mesh.triangles[rng.integers(0, mesh.triangles.shape[0], k)]]
    w = rng.dirichlet(np.ones(3), size=k)
    d = (w[:, :, None] * tri).sum(axis=1) - o
    d[1::2] = rng.normal(size=(d[1::2].shape[0], 3))
    t_max = np.where(rng.uniform(size=k) < 0.3, rng.uniform(0, 3, k) * np.linalg.norm(span), np.inf)
    return o, _unit(d), t_max


def icosphere(subdivisions=1):
    """A closed convex icosphere of radius 1 (20·4^s triangles wound outwards)."""
    g = (1 + 5 ** 0.5) / 2
    v = [(-1, g, 0), (1, g, 0), (-1, -g, 0), (1, -g, 0), (0, -1, g), (0, 1, g), (0, -1, -g), (0, 1, -g),
         (g, 0, -1), (g, 0, 1), (-g, 0, -1), (-g, 0, 1)]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2), (10, 7, 6),
         (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10),
         (8, 6, 7), (9, 8, 1)]
    verts = [np.array(p, float) / np.linalg.norm(p) for p in v]
    for _ in range(subdivisions):
        mid: dict = {}
        faces = []
        for a, b, c in f:
            ab, bc, ca = (_middle(verts, mid, i, j) for i, j in ((a, b), (b, c), (c, a)))
            faces += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        f = faces
    return np.array(verts), np.array(f, np.int64)


def _middle(verts, mid, i, j):
    """The index of the vertex halfway along edge ij pushed onto the unit sphere (added once)."""
    key = (min(i, j), max(i, j))
    if key not in mid:
        m = verts[i] + verts[j]
        verts.append(m / np.linalg.norm(m))
        mid[key] = len(verts) - 1
    return mid[key]


def cube():
    """A closed cube [-1, 1]^3, each face split into two triangles along a random-free diagonal."""
    v = np.array([[x, y, z] for x in (-1.0, 1.0) for y in (-1.0, 1.0) for z in (-1.0, 1.0)])
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    return v, np.array([t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))], np.int64)


def placed(vertices, rng, scale):
    """The vertices turned by a random rotation, scaled and moved: (vertices, centre)."""
    center = rng.normal(size=3) * scale * 3
    return Rotation.random(random_state=rng).apply(vertices) * scale + center, center


# -- the nearest hit against the exact oracle ------------------------------------------------------------------
@given(seed=seeds, scale=scales)
def test_soup_nearest_hit_is_the_exact_nearest(seed, scale):
    rng = np.random.default_rng(seed)
    mesh = random_soup(rng, scale).mesh
    o, d, t_max = random_rays(rng, mesh, 12, scale)
    t, n, tri = ray_mesh(mesh, o, d, t_max)
    for r in range(o.shape[0]):
        assert_nearest_is_exact(mesh, o[r], _unit(d[r]), t_max[r], t[r], n[r], tri[r])


@given(seed=seeds, scale=scales)
def test_field_nearest_hit_is_the_exact_nearest(seed, scale):
    rng = np.random.default_rng(seed)
    mesh = random_field(rng, scale).mesh
    o, d, t_max = random_rays(rng, mesh, 12, scale)
    d[::5] = [0.0, -1.0, 0.0]  # vertical rays, from above
    o[::5, 1] = mesh.vertices[:, 1].max() + scale
    t, n, tri = ray_mesh(mesh, o, d, t_max)
    for r in range(o.shape[0]):
        assert_nearest_is_exact(mesh, o[r], _unit(d[r]), t_max[r], t[r], n[r], tri[r])


@given(seed=seeds, scale=scales)
def test_single_triangle_is_two_sided_with_the_normal_against_the_ray(seed, scale):
    rng = np.random.default_rng(seed)
    a, b, c = rng.normal(size=(3, 3)) * scale
    for _ in range(10):
        o = rng.normal(size=3) * 3 * scale
        w = rng.dirichlet(np.ones(3))
        d = tuple(_unit(w[0] * a + w[1] * b + w[2] * c - o))
        t, nx, ny, nz = ray_triangle(tuple(o), d, np.inf, tuple(a), tuple(b), tuple(c))
        h = exact_hit(o, d, np.inf, a, b, c)
        assert h is not None and abs(Fraction(t) - h[0]) <= Fraction(1e-12) * h[0]
        n = np.cross(b - a, c - a)
        assert np.dot([nx, ny, nz], d) < 0.0 and h[1] == -np.sign(np.dot(n, d))
        np.testing.assert_allclose([nx, ny, nz], h[1] * n / np.linalg.norm(n), rtol=0, atol=1e-14)
        # the same ray from beyond the triangle, reversed: hit from the other side
        back = tuple(np.array(o) + 2 * t * np.array(d))
        t2, *n2 = ray_triangle(back, tuple(-np.array(d)), np.inf, tuple(a), tuple(b), tuple(c))
        assert abs(t2 - t) <= 1e-9 * t and np.dot(n2, [nx, ny, nz]) < 0.0


def test_an_origin_on_the_surface_hits_at_zero():
    field = HeightField(np.array([[0.0, 1.0], [2.0, 0.5]]), 1.0)
    v = field.mesh.vertices
    for p in (v[0], v[3], (v[0] + v[1]) / 2):
        for d in ([0.0, -1.0, 0.0], [0.3, 1.0, 0.2]):
            t, n, tri = ray_mesh(field.mesh, [p], [d])
            assert t[0] == 0.0 and tri[0] >= 0 and np.dot(n[0], d) < 0.0
    t, _, tri = ray_mesh(field.mesh, [[0.5, 5.0, 0.5]], [[1.0, 0.0, 0.0]])  # above it, level: no hit
    assert tri[0] == -1 and t[0] == np.inf


# -- HeightField == TriangleMesh, bit for bit ------------------------------------------------------------------
def field_special_rays(rng, field, k, scale):
    """Rays along the grid: vertical ones through vertices and down grid lines, level ones along grid lines,
    ones aimed at vertices, random ones; some with a finite length."""
    v = field.mesh.vertices
    nx, nz = field.mesh.grid_n
    top = v[:, 1].max() + scale
    o, d, t_max = random_rays(rng, field.mesh, k, scale)
    for r in range(k):
        p = v[rng.integers(0, v.shape[0])]
        q = v[rng.integers(0, v.shape[0])]
        kind = r % 6
        if kind == 0:  # vertical, through a vertex
            o[r], d[r] = [p[0], top, p[2]], [0.0, -1.0, 0.0]
        elif kind == 1:  # vertical, down a grid line
            o[r], d[r] = [p[0], top, q[2] + rng.uniform() * 0.1 * scale], [0.0, -1.0, 0.0]
        elif kind == 2:  # level, along a grid line at the height of a vertex
            o[r], d[r] = [p[0], p[1], v[:, 2].min() - scale], [0.0, 0.0, 1.0]
        elif kind == 3:  # in the vertical plane of a grid line, slanted
            o[r] = [p[0], top, v[:, 2].min() - scale]
            d[r] = _unit(np.array([0.0, p[1] - top, p[2] - o[r][2]]))
        elif kind == 4:  # aimed at a vertex
            d[r] = _unit(p - o[r])
    return o, d, t_max


@given(seed=seeds, scale=scales)
def test_heightfield_answers_as_the_mesh_of_its_triangles_bit_for_bit(seed, scale):
    rng = np.random.default_rng(seed)
    field = random_field(rng, scale)
    mesh = TriangleMesh(field.mesh.vertices, field.mesh.triangles)
    o, d, t_max = field_special_rays(rng, field, 24, scale)
    for a, b in zip(ray_mesh(field.mesh, o, d, t_max), ray_mesh(mesh.mesh, o, d, t_max)):
        np.testing.assert_array_equal(a, b)
    one, other = World(), World()
    one.add(field)
    other.add(mesh)
    for every in (False, True):
        a, b = one.cast_rays(o, d, t_max, all_hits=every), other.cast_rays(o, d, t_max, all_hits=every)
        for f in ("ray", "body", "distance", "point", "normal", "part"):
            np.testing.assert_array_equal(getattr(a, f), getattr(b, f))


# -- watertight --------------------------------------------------------------------------------------------------
def _edges(triangles):
    return sorted({(min(a, b), max(a, b)) for t in triangles for a, b in ((t[0], t[1]), (t[1], t[2]),
                                                                             (t[2], t[0]))})


@pytest.mark.parametrize("shape", ["icosphere", "cube"])
@given(seed=seeds, scale=scales)
def test_rays_at_shared_edges_and_vertices_of_a_closed_mesh_always_hit(shape, seed, scale):
    """A ray from outside aimed through the centre at an edge's midpoint or a vertex enters the convex shell
    there: it must hit (no gap between the triangles sharing the edge or the vertex)."""
    rng = np.random.default_rng(seed)
    v, f = icosphere(1) if shape == "icosphere" else cube()
    v, center = placed(v, rng, scale)
    mesh = TriangleMesh(v, f)
    targets = [(v[a] + v[b]) / 2 for a, b in _edges(f)] + list(v)
    p = np.array(targets)
    o = center + (p - center) * rng.uniform(1.5, 4.0)
    d = _unit(center - o)
    t, n, tri = ray_mesh(mesh.mesh, o, d)
    assert (tri >= 0).all(), np.flatnonzero(tri < 0)
    np.testing.assert_allclose(t, np.linalg.norm(p - o, axis=1), rtol=1e-9)
    assert ((n * d).sum(axis=1) < 0).all()
    world = World()
    world.add(mesh)
    hits = world.cast_rays(o, d)
    np.testing.assert_array_equal(hits.distance, t)
    np.testing.assert_array_equal(hits.part, tri)


@given(seed=seeds, scale=scales)
def test_vertical_rays_down_the_grid_lines_of_a_heightfield_always_hit(seed, scale):
    """Straight down a grid line or a vertex the kernel's edge functions are exactly 0: the ray must still hit
    (an edge counts for the triangles on both sides), at the height of the surface there."""
    rng = np.random.default_rng(seed)
    field = random_field(rng, scale)
    v = field.mesh.vertices
    top = v[:, 1].max() + scale
    along_z = [[p[0], top, p[2] + rng.uniform() * field.spacing[1]] for p in v]
    along_x = [[p[0] + rng.uniform() * field.spacing[0], top, p[2]] for p in v]
    o = np.array([[p[0], top, p[2]] for p in v] + along_z + along_x)
    inside = ((o[:, 0] <= v[:, 0].max()) & (o[:, 2] <= v[:, 2].max()))
    o = o[inside]
    d = np.tile([0.0, -1.0, 0.0], (o.shape[0], 1))
    t, n, tri = ray_mesh(field.mesh, o, d)
    assert (tri >= 0).all()
    nv = v.shape[0]
    np.testing.assert_allclose(t[:nv], top - v[:, 1], rtol=1e-12)  # through the vertices: at their heights
    for r in range(o.shape[0]):
        assert_nearest_is_exact(field.mesh, o[r], d[r], np.inf, t[r], n[r], tri[r])


def _crossings(mesh, o, d):
    """The distinct distances (to 1e-9 of the mesh's size) at which the ray meets a triangle, by the kernel run on
    every triangle."""
    ts = sorted(ray_triangle_side(tuple(o), tuple(d), np.inf, *(tuple(mesh.vertices[i]) for i in tri))[0]
                for tri in mesh.triangles)
    ts = [t for t in ts if t < np.inf]
    size = np.ptp(mesh.vertices, axis=0).max()
    return [t for k, t in enumerate(ts) if k == 0 or t - ts[k - 1] > 1e-9 * size]


@pytest.mark.parametrize("shape", ["icosphere", "cube", "star"])
@given(seed=seeds, scale=scales)
def test_rays_from_far_outside_cross_a_closed_mesh_an_even_number_of_times(shape, seed, scale):
    rng = np.random.default_rng(seed)
    v, f = icosphere(2) if shape != "cube" else cube()
    if shape == "star":  # star-shaped about its centre, not convex
        v = v * rng.uniform(0.6, 1.4, size=(v.shape[0], 1))
    v, center = placed(v, rng, scale)
    mesh = TriangleMesh(v, f).mesh
    for _ in range(6):
        o = center + _unit(rng.normal(size=3)) * 10 * scale
        target = v[f[rng.integers(0, f.shape[0])]].mean(axis=0) if rng.uniform() < 0.7 else center
        d = _unit(target - o)
        count = len(_crossings(mesh, o, d))
        assert count % 2 == 0 and count >= 2, count


# -- through the World ---------------------------------------------------------------------------------------------
def _brute(world, o, d, t_max, mask):
    """Every hit (t, body, part, normal) by the kernels, body by body (a surface triangle by triangle)."""
    found = []
    for b in world.ids().tolist():
        if world.bodies().sensor[b] or int(world.bodies().category[b]) & mask == 0:
            continue
        shape = world.shape(b)
        if world.kind(b) in ("mesh", "field"):
            m = shape.mesh
            per = [(ray_triangle_side(tuple(o), tuple(d), t_max, *(tuple(m.vertices[i]) for i in tri)), k)
                   for k, tri in enumerate(m.triangles)]
            (t, side), k = min(per, key=lambda h: (h[0][0], h[1]))
            if t < np.inf:
                found.append((t, b, k, side * m.normals[k]))
        else:
            t, *n = ray_sphere(tuple(o), tuple(d), t_max, tuple(shape.center), shape.radius)
            if t < np.inf:
                found.append((t, b, 0, np.array(n)))
    return sorted(found, key=lambda h: (h[0], h[1]))


@given(seed=seeds, scale=scales, threads=st.integers(1, 3), mask=st.integers(1, 7), data=st.data())
def test_world_rays_with_surfaces_equal_the_brute_force(seed, scale, threads, mask, data):
    """Surfaces and spheres in one world, with categories, sensors, finite lengths: nearest and every hit equal
    the kernels' brute force, on any number of threads."""
    rng = np.random.default_rng(seed)
    world = World(data.draw(st.sampled_from(["tree", "grid", "brute"])), threads=threads)
    shapes = [random_field(rng, scale), random_soup(rng, scale), random_field(rng, scale)]
    shapes += [Sphere(rng.normal(size=3) * scale, rng.uniform(0.2, 1.0) * scale) for _ in range(3)]
    for k, s in enumerate(shapes):
        world.add(s, category=int(rng.integers(1, 8)), sensor=bool(k == 5))
    mesh = shapes[int(rng.integers(0, 3))].mesh
    o, d, t_max = random_rays(rng, mesh, 10, scale)
    hits = world.cast_rays(o, d, t_max, mask=mask)
    every = world.cast_rays(o, d, t_max, mask=mask, all_hits=True)
    expected_every = []
    for r in range(o.shape[0]):
        du = _unit(d[r])  # as the World's rays (engine.narrowphase.ray_mesh.as_rays)
        want = _brute(world, o[r], du, t_max[r], mask)
        expected_every += [(r, h[1], h[0], h[2]) for h in want]
        if not want:
            assert hits.body[r] == -1 and hits.distance[r] == np.inf
            continue
        t, b, part, n = want[0]
        assert (hits.body[r], hits.distance[r], hits.part[r]) == (b, t, part)
        np.testing.assert_array_equal(hits.normal[r], n)
        np.testing.assert_array_equal(hits.point[r], o[r] + t * du)
    got = list(zip(every.ray.tolist(), every.body.tolist(), every.distance.tolist(), every.part.tolist()))
    assert got == expected_every


@pytest.mark.parametrize("kwargs, name", [
    ({"origins": [[0, 0, np.nan]], "directions": [[1, 0, 0]]}, "origins"),
    ({"origins": [[0, 0, 0]], "directions": [[0, 0, 0]]}, "directions"),
    ({"origins": [[0, 0, 0]], "directions": [[1, 0, 0], [1, 0, 0]]}, "directions"),
    ({"origins": [[0, 0, 0]], "directions": [[1, 0, 0]], "max_distance": -1.0}, "max_distance"),
    ({"origins": [[0, 0, 0]] * 2, "directions": [[1, 0, 0]] * 2, "max_distance": [1.0]}, "max_distance"),
])
def test_bad_rays_are_refused_by_name(kwargs, name):
    field = HeightField(np.zeros((2, 2)), 1.0)
    with pytest.raises(ValueError, match=name):
        ray_mesh(field.mesh, **kwargs)
