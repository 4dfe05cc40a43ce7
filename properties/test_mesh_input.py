"""Level geometry's input and arrays: bad meshes and heightfields are refused by name and index, good ones give
the arrays the kernels read.

- Bad input: NaN or infinite vertices or heights, indices out of range, zero-area triangles (repeated or
  collinear corners), fewer than 2 × 2 samples, a non-positive spacing, non-integer indices → ValueError/TypeError
  naming the argument and the first offending index; thin triangles (aspect 1e-12) are kept. The caller's arrays
  are never modified.
- ``candidate_triangles`` (the BVH descent of a soup, the cells of a heightfield) equals the brute force over every
  triangle's AABB, for random boxes, surfaces and scales.
- A ``HeightField``'s arrays are those of the ``TriangleMesh`` of its triangles (vertices, triangles, normals,
  active edges), and its normals point up.
- Active edges: every internal edge of a flat tessellation (any diagonals) is inactive and every boundary edge
  active; a convex fold sharper than the threshold is active, a gentler one or a concave one inactive.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from engine import HeightField, TriangleMesh, World
from engine.narrowphase.triangle_mesh import ACTIVE_EDGE_COS, candidate_triangles

_GRID = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 1.0]])


@pytest.mark.parametrize("vertices, triangles, match", [
    ([[0, 0, 0], [1, 0, np.nan], [0, 0, 1]], [[0, 1, 2]], r"vertices\[1, 2\] = nan"),
    ([[0, 0, 0], [1, 0, 0], [0, 0, np.inf]], [[0, 1, 2]], r"vertices\[2, 2\] = inf"),
    (_GRID, [[0, 1, 2], [1, 3, 4]], r"triangles\[1\] = \[1, 3, 4\] has an index out of range \[0, 4\)"),
    (_GRID, [[0, 1, 2], [-1, 3, 2]], r"triangles\[1\] .* out of range"),
    (_GRID, [[0, 1, 2], [1, 1, 3]], r"triangles\[1\] = \[1, 1, 3\] is degenerate"),
    ([[0, 0, 0], [1, 1, 1], [2, 2, 2], [0, 0, 1]], [[0, 1, 3], [0, 1, 2]], r"triangles\[1\] .* degenerate"),
    (_GRID, np.zeros((0, 3), np.int64), "at least one triangle"),
    (_GRID, [[0, 1]], r"shape \(nt, 3\)"),
    ([[0, 0, 0], [1, 0, 0]], [[0, 1, 1]], "vertices needs at least 3"),
])
def test_bad_meshes_are_refused_by_name_and_index(vertices, triangles, match):
    v, t = np.array(vertices, dtype=float), np.array(triangles)
    v0, t0 = v.copy(), t.copy()
    with pytest.raises(ValueError, match=match):
        TriangleMesh(v, t)
    assert np.array_equal(v, v0, equal_nan=True) and np.array_equal(t, t0)


def test_non_integer_or_non_numeric_mesh_input_is_a_type_error():
    with pytest.raises(TypeError, match="triangles must be an integer array"):
        TriangleMesh(_GRID, [[0.0, 1.5, 2.0]])
    with pytest.raises(TypeError, match="vertices"):
        TriangleMesh([["a", "b", "c"]] * 3, [[0, 1, 2]])
    assert TriangleMesh(_GRID, np.array([[0.0, 1.0, 2.0]])).triangles.dtype == np.int64  # integral floats pass


@pytest.mark.parametrize("heights, spacing, origin, match", [
    (np.zeros((1, 5)), 1.0, (0, 0), r"at least 2 x 2 samples"),
    (np.zeros((5, 1)), 1.0, (0, 0), r"at least 2 x 2 samples"),
    (np.zeros(5), 1.0, (0, 0), "heights must have 2 dimension"),
    (np.where(np.arange(12).reshape(3, 4) == 6, np.nan, 0.0), 1.0, (0, 0), r"heights\[1, 2\] = nan"),
    (np.zeros((3, 3)), 0.0, (0, 0), "spacing must be positive"),
    (np.zeros((3, 3)), (1.0, -2.0), (0, 0), "spacing must be positive"),
    (np.zeros((3, 3)), (1.0, 2.0, 3.0), (0, 0), "spacing must be a scalar or"),
    (np.zeros((3, 3)), np.inf, (0, 0), "spacing must be finite"),
    (np.zeros((3, 3)), 1.0, (0, np.nan), r"origin\[1\] = nan"),
])
def test_bad_heightfields_are_refused_by_name_and_index(heights, spacing, origin, match):
    h0 = np.array(heights, copy=True)
    with pytest.raises(ValueError, match=match):
        HeightField(heights, spacing, origin)
    assert np.array_equal(heights, h0, equal_nan=True)


def test_thin_triangles_are_kept_and_a_surface_is_static():
    thin = TriangleMesh([[0, 0, 0], [1, 0, 0], [0.5, 1e-12, 0]], [[0, 1, 2]])
    assert np.allclose(np.abs(thin.mesh.normals[0]), [0, 0, 1])
    w = World()
    body = w.add(thin)
    assert w.is_static(body) and w.kind(body) == "mesh"
    lo, hi = w.aabb(body)
    assert np.array_equal(lo, [0, 0, 0]) and np.array_equal(hi, [1, 1e-12, 0])
    with pytest.raises(ValueError):
        w.add(HeightField(np.zeros((2, 2)), 1.0), velocity=[1.0, 0.0, 0.0])


def _random_field(rng, scale):
    nx, nz = (int(x) for x in rng.integers(2, 12, size=2))
    h = rng.uniform(-1, 1, (nx, nz)) * scale * rng.choice([0.0, 0.1, 1.0])
    spacing = tuple(rng.uniform(0.2, 1.5, 2) * scale)
    return HeightField(h, spacing, tuple(rng.uniform(-3, 3, 2) * scale))


@settings(max_examples=60)
@given(seed=st.integers(0, 2**32 - 1), scale=st.sampled_from([1e-3, 1.0, 1e3]), soup=st.booleans())
def test_candidate_triangles_equal_the_brute_force(seed, scale, soup):
    rng = np.random.default_rng(seed)
    field = _random_field(rng, scale)
    surface = TriangleMesh.random(rng, rng.uniform(-2, 2, 3) * scale, 4 * scale) if soup else field
    mesh = surface.mesh
    corners = mesh.vertices[mesh.triangles]
    tri_lo, tri_hi = corners.min(axis=1), corners.max(axis=1)
    lo_all, hi_all = mesh.vertices.min(axis=0), mesh.vertices.max(axis=0)
    stack = np.empty(mesh.node_lo.shape[0] + 1, np.int64)
    for _ in range(20):
        # boxes about the surface, some exactly on triangle box faces (closed test)
        c = rng.uniform(lo_all - scale, hi_all + scale)
        if rng.random() < 0.3:
            t = rng.integers(mesh.triangles.shape[0])
            c = np.where(rng.random(3) < 0.5, tri_lo[t], tri_hi[t])
        half = rng.uniform(0, 1.5, 3) * scale * rng.choice([0.0, 0.1, 1.0])
        lo, hi = c - half, c + half
        out, count = candidate_triangles(mesh, lo, hi, stack, np.empty(1, np.int64))
        brute = np.flatnonzero(((tri_lo <= hi) & (tri_hi >= lo)).all(axis=1))
        assert np.array_equal(out[:count], brute)


@settings(max_examples=40)
@given(seed=st.integers(0, 2**32 - 1), scale=st.sampled_from([1e-3, 1.0, 1e3]))
def test_a_heightfield_has_the_arrays_of_the_mesh_of_its_triangles(seed, scale):
    field = _random_field(np.random.default_rng(seed), scale)
    mesh = TriangleMesh(field.vertices, field.triangles).mesh
    f = field.mesh
    for name in ("vertices", "triangles", "normals", "active"):
        assert np.array_equal(getattr(f, name), getattr(mesh, name)), name
    assert (f.normals[:, 1] > 0).all()
    nx, nz = field.heights.shape
    assert f.triangles.shape == (2 * (nx - 1) * (nz - 1), 3)
    # every triangle lies in its cell: corners (i, k), (i + 1, k + 1) and one of the other two
    cell = np.repeat(np.arange((nx - 1) * (nz - 1)), 2)
    i, k = cell // (nz - 1), cell % (nz - 1)
    rows = np.arange(cell.shape[0])
    assert (f.triangles[:, 0] == i * nz + k).all()
    assert (f.triangles[rows, 2 - rows % 2] == (i + 1) * nz + k + 1).all()


def _edge_flags(surface):
    """{sorted corner pair: [active flag per triangle holding it]}."""
    flags: dict = {}
    for t, tri in enumerate(surface.mesh.triangles):
        for e in range(3):
            key = tuple(sorted((int(tri[e]), int(tri[(e + 1) % 3]))))
            flags.setdefault(key, []).append(bool(surface.mesh.active[t, e]))
    return flags


@settings(max_examples=40)
@given(seed=st.integers(0, 2**32 - 1))
def test_flat_tessellations_have_no_active_internal_edge(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 7))
    x, z = np.meshgrid(np.arange(n + 1.0), np.arange(n + 1.0), indexing="ij")
    v = np.stack([x.ravel(), np.full(x.size, 0.25), z.ravel()], axis=1)
    tris = []
    for i in range(n):
        for k in range(n):
            a, b, c, d = i * (n + 1) + k, i * (n + 1) + k + 1, (i + 1) * (n + 1) + k + 1, (i + 1) * (n + 1) + k
            if rng.random() < 0.5:
                tris += [[a, b, c], [a, c, d]]
            else:
                tris += [[a, b, d], [b, c, d]]
    tris = np.array(tris)
    flip = rng.random(len(tris)) < 0.3  # winding does not matter on a flat floor
    tris[flip] = tris[flip][:, ::-1]
    for surface in (TriangleMesh(v, tris), HeightField(np.full((n + 1, n + 1), 0.25), 1.0)):
        for key, active in _edge_flags(surface).items():
            assert active == ([True] if len(active) == 1 else [False, False]), key


@pytest.mark.parametrize("degrees, convex, active", [
    (4.0, True, False), (6.0, True, True), (30.0, True, True), (4.0, False, False), (30.0, False, False)])
def test_a_fold_is_active_only_when_convex_and_sharper_than_the_threshold(degrees, convex, active):
    # two triangles sharing the edge x = 0 along z, the second folded down (convex) or up (concave) by `degrees`
    s = math.sin(math.radians(degrees)) * (-1.0 if convex else 1.0)
    c = math.cos(math.radians(degrees))
    v = [[0, 0, 0], [0, 0, 1], [-1, 0, 0.5], [c, s, 0.5]]
    mesh = TriangleMesh(v, [[1, 0, 2], [0, 1, 3]])  # both wound with their normals up
    assert (mesh.mesh.normals[:, 1] > 0).all()
    assert mesh.mesh.active[0, 0] == active and mesh.mesh.active[1, 0] == active
    assert abs(mesh.mesh.normals[0] @ mesh.mesh.normals[1] - c) < 1e-12 and (c < ACTIVE_EDGE_COS) == (degrees > 5)
