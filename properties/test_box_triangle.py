"""The box–triangle kernel (engine/narrowphase/box_triangle.py) against independent answers.

- Separation: an independent numpy SAT on the 13 axes in world coordinates (the triangle's normal, the box's 3
  axes, the 9 cross products of box axes and triangle edges), each gap computed on the raw axis and divided by
  its length at the end: the largest gap over the axes is minus the penetration depth when all overlap, the
  kernel's separation. The touching decision must equal the oracle's wherever the oracle's answer is farther than
  the round-off bound from 0, at scales 1e-3 to 1e3; on exact just-touching poses (dyadic coordinates, signed
  permutation rotations: every product exact) both must say "touching", separation exactly 0.
- Depth: the EPA depth (``engine.epa_penetration``) of the box's 8 corners against the triangle's 3, within
  ``DEPTH_TOL`` × the scene's size; apart, the separation is a lower bound of the GJK distance.
- Manifold: 1 to MAX_TRIANGLE_POINTS points, each with a depth in [0, depth], each within depth / 2 (+ round-off)
  of both shapes (points lie halfway between the two surfaces); translating the triangle by (depth + margin) along
  the normal separates the pair (the normal runs from the box towards the triangle).
- A box lying flat on a triangle larger than its face, pressed in by any depth and turned by any yaw, in a scene
  turned by any rotation: 4 points, its bottom corners moved halfway up, normal = −(the triangle's normal).

The hull–triangle kernel (``convex_triangle`` of engine/narrowphase/mesh_contact.py, the World's, radius 0):

- Separation: overlapping, minus the least overlap of an independent numpy SAT whose axes come from Qhull
  (scipy's ConvexHull of the vertices: its facet normals, its edges × the triangle's edges, the triangle's
  normal) — the exact depth — within ``HULL_TOL`` × the scene's size (EPA's accuracy); apart, the GJK distance
  (``engine.gjk_distance``) and at least that SAT's largest gap. The touching decision equals the SAT's wherever
  it is farther than the tolerance from 0, at scales 1e-3 to 1e3.
- ``sat_hull_triangle`` (the fallback where GJK or EPA do not converge) equals that SAT's depth within round-off
  for overlapping pairs; apart, its gap (minus its best[0]) lies between that SAT's and the GJK distance.
- A hull that is a box (its 8 corners) gives box_triangle's separation (overlapping: the same depth; apart:
  box_triangle's lower bound is at most the distance), and lying flat on a large triangle, 4 points (its bottom
  corners halfway up) with normal −(the triangle's normal).
- Manifold: 1 to MAX_TRIANGLE_POINTS points with depths in [0, depth], each within depth / 2 (+ tolerance) of
  both shapes; translating the triangle by a little more than the depth along the normal separates them.
"""
from __future__ import annotations

import numpy as np
from hypothesis import assume, example, given
from hypothesis import strategies as st
from scipy.spatial import ConvexHull
from scipy.spatial.transform import Rotation

from engine import epa_penetration, gjk_distance
from engine.narrowphase.box_triangle import box_triangle
from engine.narrowphase.contacts import EDGE, FACE, kernel_scratch
from engine.narrowphase.mesh_contact import convex_triangle, mesh_work, sat_hull_triangle
from engine.narrowphase.triangle_contact import MAX_TRIANGLE_POINTS, triangle_contact
from engine.world.shapes import TriangleMesh

SIGNS = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
#: the kernel's separation against the oracle's, and its depth against EPA's, relative to the scene's size
SEP_TOL = 1e-9
DEPTH_TOL = 1e-7


def oracle_separation(c, R, h, tri) -> float:
    """The largest gap over the 13 SAT axes (> 0 apart; else minus the least overlap: the depth)."""
    normal = np.cross(tri[1] - tri[0], tri[2] - tri[0])
    edges = [tri[(j + 1) % 3] - tri[j] for j in range(3)]
    axes = [normal] + [R[:, k] for k in range(3)] + [np.cross(R[:, a], f) for a in range(3) for f in edges]
    longest = max(np.linalg.norm(f) for f in edges)
    best = -np.inf
    for L in axes:
        length = np.linalg.norm(L)
        if length <= 1e-12 * longest:  # parallel edges: no axis
            continue
        r = np.abs(R.T @ L) @ h
        mid = c @ L
        proj = tri @ L
        best = max(best, max(proj.min() - (mid + r), (mid - r) - proj.max()) / length)
    return float(best)


def run_kernel(c, R, h, tri, n=None):
    out = triangle_contact()
    if n is None:
        n = np.cross(tri[1] - tri[0], tri[2] - tri[0])
        n = n / np.linalg.norm(n)
    sep = box_triangle(np.asarray(c, float), np.ascontiguousarray(R, float), np.asarray(h, float),
                       tuple(map(float, tri[0])), tuple(map(float, tri[1])), tuple(map(float, tri[2])),
                       tuple(map(float, n)), out, kernel_scratch())
    assert sep == out.separation[0]
    return out


def box_distance(c, R, h, p) -> float:
    q = R.T @ (p - c)
    return float(np.linalg.norm(np.maximum(np.abs(q) - h, 0.0)))


def scene(seed: int, scale: float):
    """A box of half extents in scale·[0.1, 1] turned at random, and a triangle of corners within 2·scale of
    its centre (about half the draws overlap), or None for a sliver triangle."""
    rng = np.random.default_rng(seed)
    h = scale * rng.uniform(0.1, 1.0, 3)
    R = Rotation.random(random_state=rng).as_matrix()
    c = scale * rng.uniform(-1.0, 1.0, 3)
    tri = c + scale * rng.uniform(-2.0, 2.0, (3, 3)) * rng.choice([0.5, 1.0, 3.0])
    area = np.linalg.norm(np.cross(tri[1] - tri[0], tri[2] - tri[0]))
    edge = max(np.linalg.norm(tri[(j + 1) % 3] - tri[j]) for j in range(3))
    if area < 1e-3 * edge * edge:
        return None
    return c, R, h, tri


scales = st.floats(-3.0, 3.0).map(lambda e: 10.0 ** e)
seeds = st.integers(0, 2**32 - 1)


def size_of(c, h, tri) -> float:
    return float(np.abs(h).sum() + np.abs(tri - c).max())


@given(seeds, scales)
def test_separation_and_touching_decision_equal_an_independent_sat(seed, scale):
    drawn = scene(seed, scale)
    assume(drawn is not None)
    c, R, h, tri = drawn
    out = run_kernel(c, R, h, tri)
    expected = oracle_separation(c, R, h, tri)
    tol = SEP_TOL * size_of(c, h, tri)
    assert abs(out.separation[0] - expected) <= tol, (out.separation[0], expected)
    if abs(expected) > tol:
        assert (out.separation[0] <= 0.0) == (expected <= 0.0)


@given(seeds, scales)
def test_depth_equals_epa_and_apart_is_a_lower_bound_of_gjk(seed, scale):
    drawn = scene(seed, scale)
    assume(drawn is not None)
    c, R, h, tri = drawn
    out = run_kernel(c, R, h, tri)
    corners = c + (SIGNS * h) @ R.T
    size = size_of(c, h, tri)
    if out.separation[0] <= 0.0:
        depth, _ = epa_penetration(corners, tri)
        assert abs(-out.separation[0] - depth) <= DEPTH_TOL * size, (out.separation[0], depth)
    else:
        dist = gjk_distance(corners, tri)[0]
        assert out.separation[0] <= dist + SEP_TOL * size


def check_manifold(c, R, h, tri, out):
    """The contact's points and normal, for a touching pair."""
    depth = -out.separation[0]
    size = size_of(c, h, tri)
    tol = 1e-9 * size
    count = int(out.count[0])
    assert 1 <= count <= MAX_TRIANGLE_POINTS
    assert abs(np.linalg.norm(out.normal) - 1.0) <= 1e-12
    for p, d in zip(out.points[:count], out.depths[:count]):
        assert 0.0 <= d <= depth
        assert box_distance(c, R, h, p) <= 0.5 * depth + tol, (p, depth)
        assert gjk_distance(p[None, :], tri)[0] <= 0.5 * depth + tol, (p, depth)
    # translating the triangle by a little more than the depth along the normal separates them
    moved = tri + (depth + 1e-6 * size) * out.normal
    assert oracle_separation(c, R, h, moved) > 0.0


@given(seeds, scales)
def test_contact_points_lie_in_both_shapes_and_the_normal_separates(seed, scale):
    drawn = scene(seed, scale)
    assume(drawn is not None)
    c, R, h, tri = drawn
    out = run_kernel(c, R, h, tri)
    if out.separation[0] > 0.0:
        assert out.count[0] == 0
        return
    check_manifold(c, R, h, tri, out)


#: exact rotations: the 48 signed permutation matrices
def signed_permutation(code: int) -> np.ndarray:
    perm = [(0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)][code % 6]
    signs = SIGNS[(code // 6) % 8]
    return np.eye(3)[:, perm] * signs


dyadic = st.integers(-64, 64).map(lambda k: k / 16.0)
halves = st.integers(1, 32).map(lambda k: k / 16.0)
powers = st.integers(-10, 10).map(lambda e: 2.0 ** e)


@given(st.integers(0, 47), halves, halves, halves, dyadic, dyadic, dyadic, st.lists(dyadic, min_size=6, max_size=6),
       powers)
def test_a_triangle_flush_on_a_box_face_touches_exactly(code, hx, hy, hz, cx, cy, cz, xy, unit):
    """Triangle corners on the plane of the box's top face (local z = h_z), anywhere in that plane meeting the
    face: separation exactly 0 (the kernel and the oracle both say touching), points on the common face."""
    h = np.array([hx, hy, hz]) * unit
    c = np.array([cx, cy, cz]) * unit
    R = signed_permutation(code)
    local = np.array([[xy[0], xy[1], 0.0], [xy[2], xy[3], 0.0], [xy[4], xy[5], 0.0]]) * unit + [0.0, 0.0, h[2]]
    area = np.cross(local[1] - local[0], local[2] - local[0])[2]
    assume(area != 0.0)
    # the triangle must meet the face: its footprint overlaps [−h_x, h_x] × [−h_y, h_y] (decided by the 2-D SAT)
    tri = c + local @ R.T
    expected = oracle_separation(c, R, h, tri)
    assume(expected == 0.0)
    out = run_kernel(c, R, h, tri)
    assert out.separation[0] == 0.0
    check_manifold(c, R, h, tri, out)


@given(st.integers(0, 47), halves, halves, halves, dyadic, st.integers(-15, 15), halves, halves, dyadic, powers)
def test_a_triangle_edge_resting_on_a_box_edge_touches_exactly(code, hx, hy, hz, cx, x0, d, u, dx, unit):
    """The triangle's edge through the box's edge (y = h_y, z = h_z) along (0, 1, −1), its third corner on the far
    side of the plane y + z = h_y + h_z: they touch at one point of the box's edge; separation exactly 0, one
    edge–edge point there."""
    h = np.array([hx, hy, hz]) * unit
    c = np.array([cx, 0.0, 0.0]) * unit
    R = signed_permutation(code)
    x = x0 / 16.0 * hx * unit
    local = np.array([[x, h[1] - d * unit, h[2] + d * unit], [x, h[1] + d * unit, h[2] - d * unit],
                      [x + dx * unit, h[1] + u * unit, h[2] + u * unit]])
    assume(dx != 0.0)
    tri = c + local @ R.T
    assert oracle_separation(c, R, h, tri) == 0.0
    out = run_kernel(c, R, h, tri)
    assert out.separation[0] == 0.0
    check_manifold(c, R, h, tri, out)
    assert out.count[0] == 1 and out.body_feature[0] == EDGE and out.tri_feature[0] == EDGE
    np.testing.assert_allclose(out.points[0], c + np.array([x, h[1], h[2]]) @ R.T, atol=1e-12 * unit)


yaws = st.one_of(st.just(0.0), st.floats(-np.pi, np.pi))


@given(yaws, st.floats(0.05, 1.0), st.floats(0.05, 1.0), st.floats(0.05, 1.0), st.floats(0.0, 0.9),
       st.none() | seeds, scales, st.booleans())
@example(0.0, 0.5, 0.5, 0.5, 0.0, None, 1.0, False)
@example(0.3, 0.5, 0.25, 0.5, 0.0, None, 1.0, True)
def test_a_box_lying_flat_on_a_large_triangle_touches_at_its_four_bottom_corners(yaw, hx, hy, hz, press, seed,
                                                                                 scale, below):
    """Turned about the triangle's normal only (seed None), the heights are exact and the box may rest at depth
    0; in a scene turned at random the depth is at least 1e-9 × the box (touching is decided by round-off)."""
    h = scale * np.array([hx, hy, hz])
    Q = np.eye(3) if seed is None else Rotation.random(random_state=seed).as_matrix()
    if seed is not None:
        press = max(press, 1e-9)
    # built from cos and sin: its third row and column are exactly e_z (scipy's may round the 1)
    turn = np.array([[np.cos(yaw), -np.sin(yaw), 0.0], [np.sin(yaw), np.cos(yaw), 0.0], [0.0, 0.0, 1.0]])
    depth = press * h[2]
    c_local = np.array([0.1 * scale, -0.2 * scale, h[2] - depth])
    tri_local = 10.0 * scale * np.array([[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [0.0, 1.5, 0.0]])
    if below:  # the triangle wound the other way: its normal points away from the box
        tri_local = tri_local[::-1].copy()
    c, R, tri = Q @ c_local, Q @ turn, tri_local @ Q.T
    n = np.cross(tri[1] - tri[0], tri[2] - tri[0])
    n /= np.linalg.norm(n)
    out = run_kernel(c, R, h, tri, n)
    assert out.count[0] == 4
    np.testing.assert_allclose(out.normal, -Q[:, 2], atol=1e-12)  # from the box down into the triangle
    np.testing.assert_allclose(out.normal, -n if not below else n, atol=1e-12)
    assert abs(-out.separation[0] - depth) <= 1e-12 * scale
    bottom = c + (SIGNS[SIGNS[:, 2] < 0] * h) @ R.T - 0.5 * depth * out.normal
    got = out.points[:4]
    for p in bottom:
        assert np.abs(got - p).max(axis=1).min() <= 1e-12 * scale
    assert out.body_feature[0] == FACE and out.tri_feature[0] == FACE
    assert np.all(out.depths[:4] >= depth - 1e-12 * scale)


# ---------------------------------------------------------------------------------------------------------------
# convex_triangle (a hull against one triangle)
# ---------------------------------------------------------------------------------------------------------------

#: EPA's depth (epa.EPA_TOL = 1e-10 relative) and GJK's distance against the oracles, × the scene's size
HULL_TOL = 1e-7
#: the kernel's work space: mesh_work sizes its BVH stack by a surface, here a single triangle's
WORK = mesh_work(TriangleMesh(np.eye(3), np.array([[0, 1, 2]])).mesh, 16)


def hull_oracle(points, tri) -> float:
    """The SAT answer on Qhull's axes: the largest gap (> 0 apart), else minus the least overlap (the depth)."""
    hull = ConvexHull(points)
    edges = {tuple(sorted((s[i], s[(i + 1) % 3]))) for s in hull.simplices for i in range(3)}
    tri_edges = [tri[(j + 1) % 3] - tri[j] for j in range(3)]
    axes = [np.cross(tri_edges[0], tri_edges[1])] + list(hull.equations[:, :3])
    axes += [np.cross(points[j] - points[i], f) / (np.linalg.norm(points[j] - points[i]) * np.linalg.norm(f))
             for i, j in edges for f in tri_edges]
    best = -np.inf
    for L in axes:  # cross products of unit vectors: parallel ones (sine below 1e-12) make no axis
        length = np.linalg.norm(L)
        if length <= 1e-12:
            continue
        a, t = points @ L, tri @ L
        best = max(best, max(t.min() - a.max(), a.min() - t.max()) / length)
    return float(best)


def run_hull(points, tri):
    out = triangle_contact()
    n = np.cross(tri[1] - tri[0], tri[2] - tri[0])
    n = n / np.linalg.norm(n)
    sep = convex_triangle(np.ascontiguousarray(points, float), 0.0, tuple(map(float, tri[0])),
                          tuple(map(float, tri[1])), tuple(map(float, tri[2])), tuple(map(float, n)), out, WORK)
    assert sep == out.separation[0]
    return out


def hull_scene(seed: int, scale: float):
    """4 to 16 points about a centre (a hull with volume) and a triangle within reach; None for slivers."""
    rng = np.random.default_rng(seed)
    m = int(rng.integers(4, 17))
    c = scale * rng.uniform(-1.0, 1.0, 3)
    points = c + scale * rng.normal(size=(m, 3)) * rng.uniform(0.2, 1.0, 3)
    tri = c + scale * rng.uniform(-2.0, 2.0, (3, 3)) * rng.choice([0.5, 1.0, 3.0])
    area = np.linalg.norm(np.cross(tri[1] - tri[0], tri[2] - tri[0]))
    edge = max(np.linalg.norm(tri[(j + 1) % 3] - tri[j]) for j in range(3))
    if area < 1e-3 * edge * edge or ConvexHull(points).volume < 1e-3 * scale**3:
        return None
    return points, tri


def hull_size(points, tri) -> float:
    both = np.vstack([points, tri])
    return float((both.max(axis=0) - both.min(axis=0)).max())


@given(seeds, scales)
def test_hull_separation_equals_the_sat_depth_or_the_gjk_distance(seed, scale):
    drawn = hull_scene(seed, scale)
    assume(drawn is not None)
    points, tri = drawn
    out = run_hull(points, tri)
    expected = hull_oracle(points, tri)
    tol = HULL_TOL * hull_size(points, tri)
    if abs(expected) > tol:
        assert (out.separation[0] <= 0.0) == (expected <= 0.0), (out.separation[0], expected)
    if out.separation[0] <= 0.0:
        assert abs(out.separation[0] - expected) <= tol, (out.separation[0], expected)
    else:
        assert abs(out.separation[0] - gjk_distance(points, tri)[0]) <= tol
        assert out.separation[0] >= expected - tol


@given(seeds, scales)
def test_the_sat_fallback_equals_the_qhull_sat(seed, scale):
    drawn = hull_scene(seed, scale)
    assume(drawn is not None)
    points, tri = drawn
    n = np.cross(tri[1] - tri[0], tri[2] - tri[0])
    best = np.empty(4)
    sat_hull_triangle(points, tri, n / np.linalg.norm(n), best)
    best[0] = -best[0]  # the kernel writes the depth (minus the largest gap apart), the oracle the separation
    expected = hull_oracle(points, tri)
    tol = 1e-9 * hull_size(points, tri)
    if expected <= 0.0:  # the least overlap over a superset of Qhull's axes: the same exact depth
        assert abs(best[0] - expected) <= tol, (best[0], expected)
    else:  # apart: the largest gap over more axes, still a lower bound of the distance
        assert expected - tol <= best[0] <= gjk_distance(points, tri)[0] + tol, (best[0], expected)
    assert abs(np.linalg.norm(best[1:]) - 1.0) <= 1e-12
    # the axis is oriented from the hull towards the triangle: moving the triangle along it by more than the
    # overlap separates them
    if best[0] <= 0.0:
        moved = tri + (-best[0] + 1e-6 * hull_size(points, tri)) * best[1:]
        assert hull_oracle(points, moved) > 0.0


def check_hull_manifold(points, tri, out):
    depth = -out.separation[0]
    size = hull_size(points, tri)
    tol = 1e-7 * size
    count = int(out.count[0])
    assert 1 <= count <= MAX_TRIANGLE_POINTS
    assert abs(np.linalg.norm(out.normal) - 1.0) <= 1e-9
    for p, d in zip(out.points[:count], out.depths[:count]):
        assert 0.0 <= d <= depth
        # a hull's points come from contact_manifold.contact_points: within both shapes grown by the depth (a
        # nearly flush face keeps its face manifold, whose points follow the tilted faces: not depth / 2)
        assert gjk_distance(p[None, :], points)[0] <= depth + tol, (p, depth)
        assert gjk_distance(p[None, :], tri)[0] <= depth + tol, (p, depth)
    moved = tri + (depth + 1e-6 * size) * out.normal
    assert hull_oracle(points, moved) > 0.0


@given(seeds, scales)
def test_hull_contact_points_lie_in_both_shapes_and_the_normal_separates(seed, scale):
    drawn = hull_scene(seed, scale)
    assume(drawn is not None)
    points, tri = drawn
    out = run_hull(points, tri)
    if out.separation[0] > 0.0:  # apart: the points (where contact would begin) have no depth
        assert np.all(out.depths[:out.count[0]] == 0.0)
        return
    check_hull_manifold(points, tri, out)


@given(seeds, scales)
def test_a_hull_that_is_a_box_gives_box_triangles_separation(seed, scale):
    drawn = scene(seed, scale)
    assume(drawn is not None)
    c, R, h, tri = drawn
    corners = c + (SIGNS * h) @ R.T
    out = run_hull(corners, tri)
    box = run_kernel(c, R, h, tri)
    tol = HULL_TOL * hull_size(corners, tri)
    if box.separation[0] <= 0.0 or out.separation[0] <= 0.0:
        assert abs(out.separation[0] - box.separation[0]) <= tol, (out.separation[0], box.separation[0])
    else:
        assert box.separation[0] <= out.separation[0] + tol
    if abs(oracle_separation(c, R, h, tri)) > tol:
        assert (out.separation[0] <= 0.0) == (box.separation[0] <= 0.0)


@given(st.floats(-np.pi, np.pi), st.floats(0.05, 1.0), st.floats(0.05, 1.0), st.floats(0.05, 1.0),
       st.floats(1e-3, 0.9), seeds, scales)
def test_a_box_hull_lying_flat_on_a_large_triangle_touches_at_its_four_bottom_corners(yaw, hx, hy, hz, press, seed,
                                                                                      scale):
    h = scale * np.array([hx, hy, hz])
    Q = Rotation.random(random_state=seed).as_matrix()
    turn = Rotation.from_euler("z", yaw).as_matrix()
    depth = press * h[2]
    c_local = np.array([0.1 * scale, -0.2 * scale, h[2] - depth])
    tri_local = 10.0 * scale * np.array([[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [0.0, 1.5, 0.0]])
    c, R, tri = Q @ c_local, Q @ turn, tri_local @ Q.T
    corners = c + (SIGNS * h) @ R.T
    out = run_hull(corners, tri)
    assert out.count[0] == 4
    np.testing.assert_allclose(out.normal, -Q[:, 2], atol=1e-9)
    assert abs(-out.separation[0] - depth) <= HULL_TOL * scale
    bottom = c + (SIGNS[SIGNS[:, 2] < 0] * h) @ R.T - 0.5 * depth * out.normal
    got = out.points[:4]
    for p in bottom:
        assert np.abs(got - p).max(axis=1).min() <= HULL_TOL * scale
    check_hull_manifold(corners, tri, out)
