"""Strategies for the narrow phase: rotations, oriented boxes, point clouds (convex hulls), spheres, segments.

Coordinates are kept in a moderate range (|x| <= 10, sizes 0.05..3) so that "gap well above round-off" filters
(1e-6 of the scale) keep most examples.
"""
from __future__ import annotations

import numpy as np
from hypothesis import assume
from hypothesis import strategies as st

from engine.bounding.obb import OBB

finite = st.floats(min_value=-10.0, max_value=10.0, allow_nan=False, allow_infinity=False)
sizes = st.floats(min_value=0.05, max_value=3.0, allow_nan=False, allow_infinity=False)
unit_interval = st.floats(min_value=-1.0, max_value=1.0, allow_nan=False, allow_infinity=False)

vectors = st.tuples(finite, finite, finite).map(lambda t: np.array(t, dtype=np.float64))


@st.composite
def rotations(draw) -> np.ndarray:
    """A proper rotation matrix (3, 3) from a random unit quaternion; a third of the time a rotation about a
    coordinate axis (so that some edges of two boxes are exactly parallel)."""
    kind = draw(st.integers(0, 2))
    if kind == 0:
        axis = draw(st.integers(0, 2))
        angle = draw(st.floats(min_value=-np.pi, max_value=np.pi, allow_nan=False))
        c, s = np.cos(angle), np.sin(angle)
        i, j = [k for k in range(3) if k != axis]
        m = np.eye(3)
        m[i, i] = c
        m[j, j] = c
        m[i, j] = -s
        m[j, i] = s
        return m
    q = np.array(draw(st.tuples(unit_interval, unit_interval, unit_interval, unit_interval)))
    norm = np.linalg.norm(q)
    assume(norm > 0.1)
    w, x, y, z = q / norm
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


@st.composite
def obbs(draw, spread: float = 3.0) -> OBB:
    """An oriented box with centre in [-spread, spread]^3."""
    center = np.array(draw(st.tuples(*[st.floats(-spread, spread, allow_nan=False)] * 3)))
    half = np.array(draw(st.tuples(sizes, sizes, sizes)))
    return OBB(center, draw(rotations()).T, half)


def _axis_rotation(axis: int, angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    i, j = [k for k in range(3) if k != axis]
    m = np.eye(3)
    m[i, i] = c
    m[j, j] = c
    m[i, j] = -s
    m[j, i] = s
    return m


@st.composite
def edge_edge_obb_pairs(draw):
    """Two boxes whose closest features are crossing edges: A's edge along its axis i lies horizontal (world x)
    on top of A, B's edge along its axis j lies along world y under B, B above A by a gap (possibly negative),
    the whole scene turned by a random rotation. Only the edge–edge axis (x × y) separates them when the gap is
    small and positive: the 9 cross-product axes of the OBB test are exercised one by one."""
    i = draw(st.integers(0, 2))
    j = draw(st.integers(0, 2))
    ha = np.array(draw(st.tuples(sizes, sizes, sizes)))
    hb = np.array(draw(st.tuples(sizes, sizes, sizes)))
    tilt_a = draw(st.floats(0.3, 1.27))  # keeps a single top edge (away from 0 and 90 degrees)
    tilt_b = draw(st.floats(0.3, 1.27))
    # a gap small against the boxes, so that no face axis separates them
    gap = draw(st.floats(-0.1, 0.1, allow_nan=False)) * min(ha.min(), hb.min())
    # frames: columns = world images of the local axes; A's axis i -> world x, then tilt about x
    perm_a = np.zeros((3, 3))
    others_a = [k for k in range(3) if k != i]
    perm_a[0, i] = 1.0
    perm_a[1, others_a[0]] = 1.0
    perm_a[2, others_a[1]] = 1.0
    rot_a = _axis_rotation(0, tilt_a) @ perm_a
    perm_b = np.zeros((3, 3))
    others_b = [k for k in range(3) if k != j]
    perm_b[1, j] = 1.0
    perm_b[0, others_b[0]] = 1.0
    perm_b[2, others_b[1]] = 1.0
    rot_b = _axis_rotation(1, tilt_b) @ perm_b
    top_a = np.abs(rot_a[2]) @ ha
    bottom_b = np.abs(rot_b[2]) @ hb
    # the middle of A's top edge and of B's bottom edge, relative to each centre
    sign_a = np.sign(rot_a[2])
    sign_a[i] = 0.0
    mid_top_a = rot_a @ (sign_a * ha)
    sign_b = -np.sign(rot_b[2])
    sign_b[j] = 0.0
    mid_bottom_b = rot_b @ (sign_b * hb)
    # B placed so that its bottom edge (along y) crosses A's top edge (along x), within both edges' lengths
    dx = draw(st.floats(-0.9, 0.9)) * ha[i]
    dy = draw(st.floats(-0.9, 0.9)) * hb[j]
    center_b = np.array([dx - mid_bottom_b[0], mid_top_a[1] + dy, top_a + bottom_b + gap])
    turn = draw(rotations())
    shift = np.array(draw(st.tuples(*[st.floats(-3.0, 3.0, allow_nan=False)] * 3)))
    a = OBB(shift, (turn @ rot_a).T, ha)
    b = OBB(shift + turn @ center_b, (turn @ rot_b).T, hb)
    return a, b


@st.composite
def obb_pairs(draw):
    """Two boxes: independent, or sharing a rotation (all edges parallel), or face-separated along one of A's
    axes (separation only on that axis, the hardest case for the epsilon of Ericson 4.4.1), or crossing edges
    (separation only on an edge-edge axis)."""
    kind = draw(st.integers(0, 3))
    if kind == 3:
        return draw(edge_edge_obb_pairs())
    a = draw(obbs())
    if kind == 0:
        return a, draw(obbs())
    if kind == 1:
        b = draw(obbs())
        return a, OBB(b.center, a.axes, b.half_extents)
    # B has A's axes, shifted along A's axis k by the sum of the half extents plus a gap (possibly negative)
    k = draw(st.integers(0, 2))
    half_b = np.array(draw(st.tuples(sizes, sizes, sizes)))
    gap = draw(st.floats(-0.5, 0.5, allow_nan=False))
    lateral = np.array(draw(st.tuples(*[st.floats(-1.0, 1.0, allow_nan=False)] * 3)))
    lateral[k] = 0.0
    offset = lateral.copy()
    offset[k] = a.half_extents[k] + half_b[k] + gap
    center = a.center + offset @ a.axes
    return a, OBB(center, a.axes, half_b)


@st.composite
def point_clouds(draw, min_points: int = 4, max_points: int = 20, spread: float = 3.0) -> np.ndarray:
    """(n, 3) points: a random cloud (its hull is a convex polyhedron), scaled and shifted."""
    n = draw(st.integers(min_points, max_points))
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    scale = draw(sizes)
    shift = np.array(draw(st.tuples(*[st.floats(-spread, spread, allow_nan=False)] * 3)))
    kind = draw(st.integers(0, 2))
    if kind == 0:
        pts = rng.normal(size=(n, 3))
    elif kind == 1:
        pts = rng.uniform(-1.0, 1.0, size=(n, 3))
    else:  # points on a sphere: every point is a hull vertex
        pts = rng.normal(size=(n, 3))
        pts /= np.linalg.norm(pts, axis=1)[:, None]
    return pts * scale + shift


@st.composite
def aabbs(draw, spread: float = 3.0):
    lo = np.array(draw(st.tuples(*[st.floats(-spread, spread, allow_nan=False)] * 3)))
    size = np.array(draw(st.tuples(sizes, sizes, sizes)))
    return lo, lo + size


def box_corners(lo, hi) -> np.ndarray:
    """The 8 corners of the box [lo, hi], (8, 3)."""
    return np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])


def aabb_distance(lo_a, hi_a, lo_b, hi_b) -> float:
    """Exact distance between two axis-aligned boxes: the norm of the per-axis interval gaps."""
    gap = np.maximum(0.0, np.maximum(lo_b - hi_a, lo_a - hi_b))
    return float(np.sqrt((gap * gap).sum()))


def aabb_depth(lo_a, hi_a, lo_b, hi_b) -> float:
    """Exact penetration depth of two overlapping axis-aligned boxes: the shortest push along one axis, in either
    direction (min over axes of min(hi_a − lo_b, hi_b − lo_a))."""
    push = np.minimum(hi_a - lo_b, hi_b - lo_a)
    return float(push.min())


def hull_signed_distance(points: np.ndarray, query: np.ndarray) -> float:
    """max over Qhull's facet planes of n·q + offset: <= 0 inside the hull (scipy.spatial.ConvexHull)."""
    from scipy.spatial import ConvexHull

    hull = ConvexHull(points)
    return float((hull.equations[:, :3] @ query + hull.equations[:, 3]).max())


def exact_penetration_depth(points_a: np.ndarray, points_b: np.ndarray) -> float:
    """Depth by Qhull on the Minkowski difference A − B: the distance from the origin to its boundary (<= 0 means
    the origin is outside: no penetration). An oracle independent of EPA."""
    from scipy.spatial import ConvexHull

    md = (points_a[:, None, :] - points_b[None, :, :]).reshape(-1, 3)
    hull = ConvexHull(md)
    return float((-hull.equations[:, 3]).min())
