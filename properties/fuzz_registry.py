"""The fuzz registry: one entry per public callable of the engine, with a strategy for VALID arguments.

``properties/test_fuzz_public_api.py`` draws valid keyword arguments from an entry, corrupts one argument with a
hostile value (NaN/inf at a random index, complex/object/str/None, wrong rank, empty, huge magnitudes, integer
dtype ...) and checks the validation contract of README ("Validation contract"). Every public name of
``engine`` and its subpackages is either here or in ``NOT_CALLABLE_API`` with the reason.

Entries call the public function through a small lambda when the function takes objects built from arrays
(an OBB, a list of point clouds, a stateful index), so that the corruption reaches the arrays themselves.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

import engine
import engine.bounding as bounding
import engine.broadphase as broadphase
import engine.contact_io as contact_io
import engine.gas as gas
import engine.narrowphase as narrow

# ---------------------------------------------------------------------------------------------------------------
# strategies of valid values
# ---------------------------------------------------------------------------------------------------------------

_coord = st.floats(-10.0, 10.0, allow_nan=False, allow_infinity=False)


def points(n_min=1, n_max=12, d=3, *, lo=-10.0, hi=10.0):
    return st.integers(n_min, n_max).flatmap(
        lambda n: hnp.arrays(np.float64, (n, d), elements=st.floats(lo, hi, allow_nan=False, allow_infinity=False)))


def vec(d=3, lo=-10.0, hi=10.0):
    return hnp.arrays(np.float64, (d,), elements=st.floats(lo, hi, allow_nan=False, allow_infinity=False))


def pos(lo=0.01, hi=10.0):
    return st.floats(lo, hi, allow_nan=False, allow_infinity=False)


@st.composite
def rotation(draw, d=3):
    """A random proper rotation matrix (d, d) from a Gaussian QR."""
    a = draw(hnp.arrays(np.float64, (d, d), elements=st.floats(-1.0, 1.0)))
    a = a + np.eye(d) * 2.5  # well conditioned
    q, r = np.linalg.qr(a)
    q = q * np.sign(np.diag(r))
    if np.linalg.det(q) < 0:
        q[:, 0] = -q[:, 0]
    return q


@st.composite
def boxes(draw, n_min=0, n_max=12, d=3):
    n = draw(st.integers(n_min, n_max))
    lo = draw(hnp.arrays(np.float64, (n, d), elements=st.floats(-10, 10)))
    ext = draw(hnp.arrays(np.float64, (n, d), elements=st.floats(0, 3)))
    return lo, lo + ext


@st.composite
def general_points(draw, n_min=5, n_max=14, d=3):
    """Points in general position (random, jittered on a well-spread cloud)."""
    n = draw(st.integers(n_min, n_max))
    seed = draw(st.integers(0, 2**31 - 1))
    return np.random.default_rng(seed).uniform(-3.0, 3.0, size=(n, d))


@st.composite
def convex_polygon(draw, n_min=3, n_max=9):
    n = draw(st.integers(n_min, n_max))
    angles = np.sort(np.random.default_rng(draw(st.integers(0, 2**31 - 1))).uniform(0, 2 * np.pi, n))
    angles = np.unique(np.round(angles, 3))
    if angles.size < 3:
        angles = np.array([0.0, 2.0, 4.0])
    r = draw(pos(0.5, 5.0))
    return np.stack([r * np.cos(angles), r * np.sin(angles)], axis=1)


def _rotations(draw, n):
    """(n, 3, 3) box axes (rows), n >= 0."""
    return np.array([draw(rotation()).T for _ in range(n)]).reshape(n, 3, 3)


def obb(draw):
    return engine.OBB(draw(vec()), draw(rotation()).T, draw(hnp.arrays(np.float64, (3,), elements=pos(0.1, 3.0))))


def kdop_pair(draw, k):
    pts = draw(points(1, 8))
    return bounding.fit_kdop(pts, k)


# ---------------------------------------------------------------------------------------------------------------
# the registry
# ---------------------------------------------------------------------------------------------------------------

@dataclass
class Api:
    """One public callable: ``call(**kwargs)`` with kwargs drawn from ``valid``."""

    name: str
    call: object
    valid: st.SearchStrategy
    max_examples: int | None = None          # cap for slow callables
    nan_fields: frozenset = field(default_factory=frozenset)  # result attributes documented to be NaN
    optional: frozenset = field(default_factory=frozenset)    # arguments for which None is a valid value
    aliases: dict = field(default_factory=dict)  # kwarg -> the argument name the engine's message uses
    indexed: bool = True  # the call passes the array itself (not its rows), so the message can give its index


REGISTRY: list[Api] = []


def api(name, call, max_examples=None, nan_fields=(), optional=(), aliases=None, indexed=True):
    def register(builder):
        REGISTRY.append(Api(name, call, st.composite(builder)(), max_examples, frozenset(nan_fields),
                            frozenset(optional), dict(aliases or {}), indexed))
        return builder
    return register


def _decay(t, y):
    return -0.5 * y


# --- dynamics ---------------------------------------------------------------------------------------------------
@api("rk4_step", lambda y, t, dt: engine.rk4_step(_decay, t, y, dt))
def _(draw):
    return dict(y=draw(vec(draw(st.integers(1, 6)))), t=draw(_coord), dt=draw(pos(1e-4, 0.5)))


@api("state_vector", engine.state_vector)
def _(draw):
    return dict(position=draw(vec()), velocity=draw(vec()))


@api("split_state", engine.split_state)
def _(draw):
    return dict(y=draw(vec(6)))


@api("bisect", lambda root, a, b, tol: engine.bisect(lambda x: x - root, a, b, tol), aliases=dict(root="f"))
def _(draw):
    root = draw(_coord)
    return dict(root=root, a=root - draw(pos(0.01, 5)), b=root + draw(pos(0.01, 5)), tol=draw(pos(1e-12, 1e-3)))


@api("drop_particle", engine.drop_particle, max_examples=30)
def _(draw):
    return dict(height=draw(pos(0.1, 3.0)), mass=draw(pos(0.1, 5)), drag=draw(pos(0.0, 1.0)),
                restitution=draw(st.floats(0.0, 1.0)), dt=draw(pos(0.005, 0.05)), t_end=draw(pos(0.1, 2.0)))


@api("drop_cube", engine.drop_cube, max_examples=30)
def _(draw):
    return dict(height=draw(pos(1.0, 5.0)), size=draw(pos(0.1, 1.0)), mass=draw(pos(0.1, 5)),
                drag=draw(pos(0.0, 1.0)), dt=draw(pos(0.005, 0.05)))


# --- bounding volumes -------------------------------------------------------------------------------------------
@api("OBB", engine.OBB)
def _(draw):
    return dict(center=draw(vec()), axes=draw(rotation()).T,
                half_extents=draw(hnp.arrays(np.float64, (3,), elements=pos(0.0, 3.0))))


for _name, _fn in [("fit_obb", engine.fit_obb), ("min_bounding_sphere", engine.min_bounding_sphere),
                   ("ritter_sphere", bounding.ritter_sphere), ("fit_aabb", bounding.fit_aabb),
                   ("describe_bounding_volumes", bounding.describe_bounding_volumes)]:
    api(_name, _fn)(lambda draw: dict(points=draw(points(1, 12))))

api("circumsphere", bounding.circumsphere)(lambda draw: dict(points=draw(points(2, 4))))
api("convex_hull", engine.convex_hull)(lambda draw: dict(points=draw(general_points())))
api("hull_planes", narrow.hull_planes)(lambda draw: dict(points=draw(general_points())))
api("describe_hull", bounding.describe_hull)(lambda draw: dict(points=draw(general_points())))
api("is_convex", engine.is_convex)(lambda draw: dict(vertices=draw(convex_polygon())))
api("triangulate_polygon", bounding.triangulate_polygon)(lambda draw: dict(polygon=draw(convex_polygon())))
api("decompose_polygon", bounding.decompose_polygon)(lambda draw: dict(polygon=draw(convex_polygon())))
api("describe_decomposition", bounding.describe_decomposition)(lambda draw: dict(polygon=draw(convex_polygon())))


@api("ritter_spheres", bounding.ritter_spheres)
def _(draw):
    m, n = draw(st.integers(1, 4)), draw(st.integers(1, 6))
    return dict(clouds=draw(hnp.arrays(np.float64, (m, n, 3), elements=_coord)))


@api("fit_aabbs", bounding.fit_aabbs)
def _(draw):
    m, n = draw(st.integers(1, 4)), draw(st.integers(1, 6))
    return dict(clouds=draw(hnp.arrays(np.float64, (m, n, 3), elements=_coord)))


@api("overlap_sphere_sphere", bounding.overlap_sphere_sphere)
def _(draw):
    return dict(center_a=draw(vec()), radius_a=draw(pos(0, 5)), center_b=draw(vec()), radius_b=draw(pos(0, 5)))


api("merge_spheres", bounding.merge_spheres)(
    lambda draw: dict(center_a=draw(vec()), radius_a=draw(pos(0, 5)), center_b=draw(vec()), radius_b=draw(pos(0, 5))))


@api("overlap_spheres", bounding.overlap_spheres)
def _(draw):
    n = draw(st.integers(0, 6))
    r = hnp.arrays(np.float64, (n,), elements=pos(0, 5))
    c = hnp.arrays(np.float64, (n, 3), elements=_coord)
    return dict(centers_a=draw(c), radii_a=draw(r), centers_b=draw(c), radii_b=draw(r))


api("sphere_contains", bounding.sphere_contains)(
    lambda draw: dict(center=draw(vec()), radius=draw(pos(0, 5)), points=draw(points(0, 8))))
api("transform_sphere", bounding.transform_sphere)(
    lambda draw: dict(center=draw(vec()), radius=draw(pos(0, 5)), rotation=draw(rotation()), translation=draw(vec())))


@api("overlap_aabb_aabb", bounding.overlap_aabb_aabb)
def _(draw):
    (la, ha), (lb, hb) = draw(boxes(1, 1)), draw(boxes(1, 1))
    return dict(lo_a=la[0], hi_a=ha[0], lo_b=lb[0], hi_b=hb[0])


api("merge_aabb", bounding.merge_aabb)(lambda draw: _one_box_pair(draw))


def _one_box_pair(draw):
    (la, ha), (lb, hb) = draw(boxes(1, 1)), draw(boxes(1, 1))
    return dict(lo_a=la[0], hi_a=ha[0], lo_b=lb[0], hi_b=hb[0])


@api("overlap_aabbs", bounding.overlap_aabbs)
def _(draw):
    n = draw(st.integers(0, 6))
    (la, ha), (lb, hb) = draw(boxes(n, n)), draw(boxes(n, n))
    return dict(lo_a=la, hi_a=ha, lo_b=lb, hi_b=hb)


@api("aabb_contains", bounding.aabb_contains)
def _(draw):
    lo, hi = draw(boxes(1, 1))
    return dict(lo=lo[0], hi=hi[0], points=draw(points(0, 8)))


@api("transform_aabb", bounding.transform_aabb)
def _(draw):
    lo, hi = draw(boxes(1, 1))
    return dict(lo=lo[0], hi=hi[0], rotation=draw(rotation()), translation=draw(vec()))


@api("transform_aabbs", bounding.transform_aabbs)
def _(draw):
    lo, hi = draw(boxes(0, 6))
    return dict(lo=lo, hi=hi, rotation=draw(rotation()), translation=draw(vec()))


@api("merge_obb", lambda ca, axa, ea, cb, axb, eb: bounding.merge_obb(engine.OBB(ca, axa, ea), engine.OBB(cb, axb, eb)),
     aliases=dict(ca="center", axa="axes", ea="half_extents", cb="center", axb="axes", eb="half_extents"))
def _(draw):
    e = hnp.arrays(np.float64, (3,), elements=pos(0.1, 3))
    return dict(ca=draw(vec()), axa=draw(rotation()).T, ea=draw(e), cb=draw(vec()), axb=draw(rotation()).T,
                eb=draw(e))


@api("transform_obb", lambda c, ax, e, rotation, translation: bounding.transform_obb(engine.OBB(c, ax, e), rotation,
                                                                                     translation),
     aliases=dict(c="center", ax="axes", e="half_extents"))
def _(draw):
    return dict(c=draw(vec()), ax=draw(rotation()).T, e=draw(hnp.arrays(np.float64, (3,), elements=pos(0.1, 3))),
                rotation=draw(rotation()), translation=draw(vec()))


@api("obb_overlap",
     lambda ca, axa, ea, cb, axb, eb: engine.obb_overlap(engine.OBB(ca, axa, ea), engine.OBB(cb, axb, eb)),
     aliases=dict(ca="center", axa="axes", ea="half_extents", cb="center", axb="axes", eb="half_extents"))
def _(draw):
    e = hnp.arrays(np.float64, (3,), elements=pos(0.1, 3))
    return dict(ca=draw(vec()), axa=draw(rotation()).T, ea=draw(e), cb=draw(vec()), axb=draw(rotation()).T,
                eb=draw(e))


_K = st.sampled_from(sorted(k for k in bounding.KDOP_SIZES))

api("kdop_directions", bounding.kdop_directions)(lambda draw: dict(k=draw(_K)))
api("fit_kdop", bounding.fit_kdop)(lambda draw: dict(points=draw(points(1, 8, d=2 if (k := draw(_K)) == 8 else 3)),
                                                     k=k))


@api("fit_kdops", bounding.fit_kdops)
def _(draw):
    k = draw(_K)
    m, n = draw(st.integers(1, 4)), draw(st.integers(1, 6))
    return dict(clouds=draw(hnp.arrays(np.float64, (m, n, 2 if k == 8 else 3), elements=_coord)), k=k)


def _kdop_two(draw):
    k = draw(_K)
    d = 2 if k == 8 else 3
    la, ha = bounding.fit_kdop(draw(points(1, 6, d=d)), k)
    lb, hb = bounding.fit_kdop(draw(points(1, 6, d=d)), k)
    return dict(lo_a=la, hi_a=ha, lo_b=lb, hi_b=hb, k=k)


api("overlap_kdop_kdop", bounding.overlap_kdop_kdop)(_kdop_two)
api("merge_kdop", bounding.merge_kdop)(_kdop_two)


@api("overlap_kdops", bounding.overlap_kdops)
def _(draw):
    k = draw(_K)
    d = 2 if k == 8 else 3
    m = draw(st.integers(1, 4))
    la, ha = bounding.fit_kdops(draw(hnp.arrays(np.float64, (m, 3, d), elements=_coord)), k)
    lb, hb = bounding.fit_kdops(draw(hnp.arrays(np.float64, (m, 3, d), elements=_coord)), k)
    return dict(lo_a=la, hi_a=ha, lo_b=lb, hi_b=hb, k=k)


@api("kdop_contains", bounding.kdop_contains)
def _(draw):
    k = draw(_K)
    d = 2 if k == 8 else 3
    lo, hi = bounding.fit_kdop(draw(points(1, 6, d=d)), k)
    return dict(lo=lo, hi=hi, points=draw(points(0, 6, d=d)), k=k)


@api("update_kdop", bounding.update_kdop)
def _(draw):
    k = draw(_K)
    d = 2 if k == 8 else 3
    return dict(points=draw(points(1, 6, d=d)), k=k, rotation=draw(rotation(d)), translation=draw(vec(d)))


@api("transform_kdop", bounding.transform_kdop)
def _(draw):
    k = draw(_K)
    d = 2 if k == 8 else 3
    lo, hi = bounding.fit_kdop(draw(points(1, 6, d=d)), k)
    return dict(lo=lo, hi=hi, k=k, rotation=draw(rotation(d)), translation=draw(vec(d)))


_CUBE = np.array([[x, y, z] for x in (0.0, 1.0) for y in (0.0, 1.0) for z in (0.0, 1.0)])


@api("decompose_mesh", bounding.decompose_mesh, max_examples=3)
def _(draw):
    hull = engine.convex_hull(_CUBE)  # a closed, consistently oriented triangle mesh of the unit cube
    return dict(vertices=hull.points * draw(pos(0.5, 2.0)), faces=hull.faces)


# --- broad phase ------------------------------------------------------------------------------------------------
_METHOD = st.sampled_from(engine.BROAD_PHASES)


@api("find_pairs", engine.find_pairs)
def _(draw):
    lo, hi = draw(boxes(0, 12, d=draw(st.integers(1, 3))))
    return dict(lo=lo, hi=hi, method=draw(_METHOD))


for _name, _fn in [("brute_force_pairs", broadphase.brute_force_pairs), ("sap_pairs", broadphase.sap_pairs),
                   ("grid_pairs", broadphase.grid_pairs), ("octree_pairs", broadphase.octree_pairs),
                   ("tree_pairs", broadphase.tree_pairs), ("build_octree", broadphase.build_octree)]:
    api(_name, _fn)(lambda draw: dict(zip(("lo", "hi"), draw(boxes(0, 12)), strict=True)))


@api("sweep_intervals", engine.sweep_intervals)
def _(draw):
    lo, hi = draw(boxes(0, 10, d=1))
    return dict(begin=lo[:, 0], end=hi[:, 0])


@api("sap_example_trace", broadphase.sap_example_trace, optional=("begin", "end", "labels"))
def _(draw):
    lo, hi = draw(boxes(1, 6, d=1))
    return dict(begin=lo[:, 0], end=hi[:, 0])


@api("sphere_pairs", engine.sphere_pairs)
def _(draw):
    n = draw(st.integers(0, 12))
    return dict(centers=draw(hnp.arrays(np.float64, (n, 3), elements=_coord)),
                radii=draw(hnp.arrays(np.float64, (n,), elements=pos(0, 3))))


@api("spheres_overlap_pairs", broadphase.spheres_overlap_pairs)
def _(draw):
    n = draw(st.integers(2, 8))
    pairs = np.array([(i, j) for i in range(n) for j in range(i + 1, n)], dtype=np.int64)
    return dict(centers=draw(hnp.arrays(np.float64, (n, 3), elements=_coord)),
                radii=draw(hnp.arrays(np.float64, (n,), elements=pos(0, 3))), pairs=pairs)


@api("canonical_pairs", broadphase.canonical_pairs, optional=("n",))
def _(draw):
    n = draw(st.integers(1, 8))
    k = draw(st.integers(0, 10))
    return dict(pairs=draw(hnp.arrays(np.int64, (k, 2), elements=st.integers(0, n - 1))), n=n)


@api("cull_separating_sphere_pairs", broadphase.cull_separating_sphere_pairs)
def _(draw):
    n = draw(st.integers(2, 8))
    pairs = np.array([(i, j) for i in range(n) for j in range(i + 1, n)], dtype=np.int64)
    return dict(pairs=pairs, centers=draw(hnp.arrays(np.float64, (n, 3), elements=_coord)),
                radii=draw(hnp.arrays(np.float64, (n,), elements=pos(0, 3))),
                velocities=draw(hnp.arrays(np.float64, (n, 3), elements=_coord)))


@api("cull_separating_box_pairs", broadphase.cull_separating_box_pairs)
def _(draw):
    n = draw(st.integers(2, 8))
    lo, hi = draw(boxes(n, n))
    pairs = np.array([(i, j) for i in range(n) for j in range(i + 1, n)], dtype=np.int64)
    return dict(pairs=pairs, lo=lo, hi=hi, velocities=draw(hnp.arrays(np.float64, (n, 3), elements=_coord)))


@api("front_faces", broadphase.front_faces)
def _(draw):
    m = draw(st.integers(0, 8))
    nrm = np.random.default_rng(draw(st.integers(0, 99))).normal(size=(m, 3))
    nrm /= np.maximum(np.linalg.norm(nrm, axis=1, keepdims=True), 1e-9)
    return dict(normals=nrm, velocity=draw(vec()))


def _incremental_sap(lo, hi, lo_new, hi_new):
    sap = engine.IncrementalSAP(lo, hi)
    i = sap.add(lo_new, hi_new)
    sap.move(i, lo_new, hi_new)
    with_new = sap.pairs()
    sap.remove(i)
    return with_new, sap.update(lo, hi)


@api("IncrementalSAP", _incremental_sap, aliases=dict(lo_new="lo_i", hi_new="hi_i"))
def _(draw):
    lo, hi = draw(boxes(1, 8))
    a, b = draw(boxes(1, 1))
    return dict(lo=lo, hi=hi, lo_new=a[0], hi_new=b[0])


def _dynamic_tree(lo, hi, lo_q, hi_q, margin):
    tree = engine.DynamicAABBTree.from_boxes(lo, hi, margin=margin)
    found = tree.query(lo_q, hi_q)
    i = tree.insert(lo_q, hi_q)
    tree.move(i, lo_q, hi_q)
    with_new = tree.pairs()
    tree.remove(i)
    return found, with_new, tree.update(lo, hi)


@api("DynamicAABBTree", _dynamic_tree, optional=("margin",))
def _(draw):
    lo, hi = draw(boxes(1, 8))
    a, b = draw(boxes(1, 1))
    return dict(lo=lo, hi=hi, lo_q=a[0], hi_q=b[0], margin=draw(pos(0.0, 1.0)))


# --- narrow phase -----------------------------------------------------------------------------------------------
def _two_sets(draw):
    return dict(points_a=draw(points(1, 10)), points_b=draw(points(1, 10)))


api("gjk_distance", engine.gjk_distance)(_two_sets)
api("overlap_convex_sat", narrow.overlap_convex_sat)(lambda draw: dict(points_a=draw(general_points(4, 10)),
                                                                       points_b=draw(general_points(4, 10))))


@api("epa_penetration", engine.epa_penetration)
def _(draw):
    a = draw(general_points(4, 10))
    return dict(points_a=a, points_b=a * 0.5 + draw(vec(3, -0.5, 0.5)))


@api("contact_feature", engine.contact_feature)
def _(draw):
    return dict(points_a=draw(general_points(1, 8)), points_b=draw(general_points(1, 8)) + draw(vec()),
                radius_a=draw(pos(0, 1)), radius_b=draw(pos(0, 1)))


@api("time_of_impact", engine.time_of_impact, max_examples=60)
def _(draw):
    return dict(points_a=draw(general_points(1, 8)), velocity_a=draw(vec()),
                points_b=draw(general_points(1, 8)) + draw(vec()), velocity_b=draw(vec()), t_max=draw(pos(0.1, 2)))


@api("gjk_distance_batch", narrow.gjk_distance_batch)
def _(draw):
    k, n = draw(st.integers(0, 5)), draw(st.integers(1, 6))
    return dict(points_a=draw(hnp.arrays(np.float64, (k, n, 3), elements=_coord)),
                points_b=draw(hnp.arrays(np.float64, (k, n, 3), elements=_coord)))


def _packed(draw, s_min=2, s_max=5, general=False):
    sets = [draw(general_points(4, 8) if general else points(1, 6)) + 8.0 * i for i in range(draw(st.integers(s_min,
                                                                                                          s_max)))]
    pts, off = narrow.pack_point_sets(sets)
    s = len(sets)
    pairs = np.array([(i, j) for i in range(s) for j in range(i + 1, s)], dtype=np.int64)
    return pts, off, pairs


@api("gjk_distance_pairs", narrow.gjk_distance_pairs)
def _(draw):
    pts, off, pairs = _packed(draw)
    return dict(points=pts, offsets=off, pairs=pairs)


@api("epa_penetration_pairs", narrow.epa_penetration_pairs)
def _(draw):
    a = draw(general_points(4, 8))
    pts, off = narrow.pack_point_sets([a, a * 0.5 + 0.1])
    return dict(points=pts, offsets=off, pairs=np.array([[0, 1]]))


@api("time_of_impact_pairs", narrow.time_of_impact_pairs, max_examples=60)
def _(draw):
    pts, off, pairs = _packed(draw)
    s = off.shape[0] - 1
    return dict(points=pts, offsets=off, velocities=draw(hnp.arrays(np.float64, (s, 3), elements=_coord)),
                pairs=pairs, t_max=draw(pos(0.1, 2)))


@api("contact_feature_pairs", lambda points, offsets, pairs, radii: narrow.contact_feature_pairs(
    points, offsets, pairs, radii=radii), optional=("radii",))
def _(draw):
    pts, off, pairs = _packed(draw, general=True)
    s = off.shape[0] - 1
    return dict(points=pts, offsets=off, pairs=pairs,
                radii=draw(hnp.arrays(np.float64, (s,), elements=pos(0.0, 1.0))))


@api("overlap_convex_sat_pairs", narrow.overlap_convex_sat_pairs)
def _(draw):
    pts, off, pairs = _packed(draw, general=True)
    return dict(points=pts, offsets=off, pairs=pairs)


@api("pack_point_sets", lambda a, b: narrow.pack_point_sets([a, b]), indexed=False,
     aliases=dict(a="point_sets", b="point_sets"))
def _(draw):
    return dict(a=draw(points(1, 6)), b=draw(points(1, 6)))


@api("distance_point_segment", narrow.distance_point_segment)
def _(draw):
    n = draw(st.integers(0, 6))
    v = hnp.arrays(np.float64, (n, 3), elements=_coord)
    return dict(points=draw(v), p0=draw(v), p1=draw(v))


for _name, _fn in [("overlap_sphere_aabb", narrow.overlap_sphere_aabb)]:
    @api(_name, _fn)
    def _(draw):
        lo, hi = draw(boxes(1, 1))
        return dict(center=draw(vec()), radius=draw(pos(0, 3)), lo=lo[0], hi=hi[0])


@api("overlap_sphere_aabb_batch", narrow.overlap_sphere_aabb_batch)
def _(draw):
    n = draw(st.integers(0, 6))
    lo, hi = draw(boxes(n, n))
    return dict(centers=draw(hnp.arrays(np.float64, (n, 3), elements=_coord)),
                radii=draw(hnp.arrays(np.float64, (n,), elements=pos(0, 3))), lo=lo, hi=hi)


@api("overlap_sphere_sphere_batch", narrow.overlap_sphere_sphere_batch)
def _(draw):
    n = draw(st.integers(0, 6))
    c = hnp.arrays(np.float64, (n, 3), elements=_coord)
    r = hnp.arrays(np.float64, (n,), elements=pos(0, 3))
    return dict(centers_a=draw(c), radii_a=draw(r), centers_b=draw(c), radii_b=draw(r))


@api("overlap_aabb_aabb_batch", narrow.overlap_aabb_aabb_batch)
def _(draw):
    n = draw(st.integers(0, 6))
    (la, ha), (lb, hb) = draw(boxes(n, n)), draw(boxes(n, n))
    return dict(lo_a=la, hi_a=ha, lo_b=lb, hi_b=hb)


@api("overlap_sphere_obb", lambda center, radius, c, ax, e: narrow.overlap_sphere_obb(center, radius,
                                                                                     engine.OBB(c, ax, e)),
     aliases=dict(c="center", ax="axes", e="half_extents"))
def _(draw):
    return dict(center=draw(vec()), radius=draw(pos(0, 3)), c=draw(vec()), ax=draw(rotation()).T,
                e=draw(hnp.arrays(np.float64, (3,), elements=pos(0.1, 3))))


@api("overlap_sphere_obb_batch", narrow.overlap_sphere_obb_batch)
def _(draw):
    n = draw(st.integers(0, 5))
    return dict(centers=draw(hnp.arrays(np.float64, (n, 3), elements=_coord)),
                radii=draw(hnp.arrays(np.float64, (n,), elements=pos(0, 3))),
                box_centers=draw(hnp.arrays(np.float64, (n, 3), elements=_coord)),
                box_axes=_rotations(draw, n),
                box_half_extents=draw(hnp.arrays(np.float64, (n, 3), elements=pos(0.1, 3))))


@api("overlap_obb_obb_batch", narrow.overlap_obb_obb_batch)
def _(draw):
    n = draw(st.integers(0, 5))
    c = hnp.arrays(np.float64, (n, 3), elements=_coord)
    e = hnp.arrays(np.float64, (n, 3), elements=pos(0.1, 3))
    return dict(centers_a=draw(c), axes_a=_rotations(draw, n),
                half_extents_a=draw(e), centers_b=draw(c),
                axes_b=_rotations(draw, n), half_extents_b=draw(e))


@api("overlap_circle_segment", narrow.overlap_circle_segment)
def _(draw):
    return dict(center=draw(vec(2)), radius=draw(pos(0, 3)), p0=draw(vec(2)), p1=draw(vec(2)))


@api("overlap_circle_segment_batch", narrow.overlap_circle_segment_batch)
def _(draw):
    n = draw(st.integers(0, 6))
    v = hnp.arrays(np.float64, (n, 2), elements=_coord)
    return dict(centers=draw(v), radii=draw(hnp.arrays(np.float64, (n,), elements=pos(0, 3))), p0=draw(v),
                p1=draw(v))


@api("overlap_sphere_capsule", narrow.overlap_sphere_capsule)
def _(draw):
    return dict(center=draw(vec()), radius=draw(pos(0, 3)), p0=draw(vec()), p1=draw(vec()),
                capsule_radius=draw(pos(0, 3)))


@api("overlap_sphere_capsule_batch", narrow.overlap_sphere_capsule_batch)
def _(draw):
    n = draw(st.integers(0, 6))
    v = hnp.arrays(np.float64, (n, 3), elements=_coord)
    r = hnp.arrays(np.float64, (n,), elements=pos(0, 3))
    return dict(centers=draw(v), radii=draw(r), p0=draw(v), p1=draw(v), capsule_radii=draw(r))


@api("overlap_aabb_ground", narrow.overlap_aabb_ground)
def _(draw):
    lo, hi = draw(boxes(1, 1))
    return dict(lo=lo[0], hi=hi[0], altitude=draw(_coord))


@api("overlap_aabb_ground_batch", narrow.overlap_aabb_ground_batch)
def _(draw):
    lo, hi = draw(boxes(0, 6))
    return dict(lo=lo, hi=hi, altitude=draw(_coord))


@api("overlap_sphere_ground_batch", narrow.overlap_sphere_ground_batch)
def _(draw):
    n = draw(st.integers(0, 6))
    return dict(centers=draw(hnp.arrays(np.float64, (n, 3), elements=_coord)),
                radii=draw(hnp.arrays(np.float64, (n,), elements=pos(0, 3))), altitude=draw(_coord))


def _curve(x):
    return np.sin(x) - 1.0


@api("overlap_aabb_curve", lambda lo, hi, samples: narrow.overlap_aabb_curve(lo, hi, _curve, samples=samples))
def _(draw):
    lo, hi = draw(boxes(0, 5, d=2))
    return dict(lo=lo, hi=hi, samples=draw(st.integers(2, 64)))


@api("overlap_aabb_curve_bottom_middle", lambda lo, hi: narrow.overlap_aabb_curve_bottom_middle(lo, hi, _curve))
def _(draw):
    lo, hi = draw(boxes(0, 5, d=2))
    return dict(lo=lo, hi=hi)


@api("max_on_intervals", lambda lo_x, hi_x, samples: narrow.max_on_intervals(_curve, lo_x, hi_x, samples=samples))
def _(draw):
    lo, hi = draw(boxes(0, 5, d=1))
    return dict(lo_x=lo[:, 0], hi_x=hi[:, 0], samples=draw(st.integers(2, 64)))


@api("min_distance_to_curve", lambda points, half_width: narrow.min_distance_to_curve(points, _curve, half_width))
def _(draw):
    return dict(points=draw(points(0, 5, d=2)), half_width=draw(pos(0.5, 5)))


@api("overlap_circle_curve", lambda centers, radii: narrow.overlap_circle_curve(centers, radii, _curve))
def _(draw):
    n = draw(st.integers(0, 5))
    return dict(centers=draw(hnp.arrays(np.float64, (n, 2), elements=_coord)),
                radii=draw(hnp.arrays(np.float64, (n,), elements=pos(0, 3))))


# --- the confined gas -------------------------------------------------------------------------------------------
@api("simulate_gas", engine.simulate_gas, max_examples=15, nan_fields=("z_wall", "z_wall_err", "block_z_wall"))
def _(draw):
    return dict(n=draw(st.integers(2, 12)), radius=draw(pos(0.1, 0.6)), box=draw(pos(6.0, 12.0)),
                temperature=draw(pos(0.5, 2.0)), t_equilibrate=draw(pos(0.0, 0.2)), t_measure=draw(pos(0.2, 0.5)),
                dt=0.01, method=draw(st.sampled_from(gas.GAS_METHODS)),
                boundary=draw(st.sampled_from(gas.GAS_BOUNDARIES)), seed=draw(st.integers(0, 100)), blocks=2)


@api("collide_elastic", gas.collide_elastic)
def _(draw):
    return dict(v1=draw(vec()), v2=draw(vec()), m1=draw(pos(0.1, 10)), m2=draw(pos(0.1, 10)), p1=draw(vec()),
                p2=draw(vec()))


@api("reflect_off_wall", gas.reflect_off_wall)
def _(draw):
    return dict(velocity=draw(vec()), normal=np.eye(3)[draw(st.integers(0, 2))] * draw(st.sampled_from([-1.0, 1.0])))


def _gas_state(draw, n_max=6):
    n = draw(st.integers(2, n_max))
    g = np.arange(n, dtype=np.float64)
    positions = np.stack([g * 1.5 - 3.0, np.zeros(n), np.zeros(n)], axis=1)
    return dict(positions=positions, velocities=draw(hnp.arrays(np.float64, (n, 3), elements=_coord)),
                radii=np.full(n, 0.5), masses=draw(hnp.arrays(np.float64, (n,), elements=pos(0.1, 3))))


@api("EventDrivenGas", lambda positions, velocities, radii, masses, box, t:
     gas.EventDrivenGas(positions, velocities, radii, masses, box, False).run(t))
def _(draw):
    return dict(**_gas_state(draw), box=10.0, t=draw(pos(0.0, 0.5)))


@api("SteppedGas", lambda positions, velocities, radii, masses, box, dt:
     gas.SteppedGas(positions, velocities, radii, masses, box, False, dt).run(5))
def _(draw):
    return dict(**_gas_state(draw), box=10.0, dt=draw(pos(1e-3, 0.05)))


@api("packing_fraction", gas.packing_fraction)
def _(draw):
    n = draw(st.integers(1, 10))
    return dict(radii=draw(hnp.arrays(np.float64, (n,), elements=pos(0.01, 0.5))), box=draw(pos(3, 12)),
                boundary=draw(st.sampled_from(gas.GAS_BOUNDARIES)))


@api("radius_for_packing", gas.radius_for_packing)
def _(draw):
    return dict(n=draw(st.integers(1, 1000)), eta=draw(pos(0.01, 0.45)), box=draw(pos(3, 12)),
                boundary=draw(st.sampled_from(gas.GAS_BOUNDARIES)))


api("carnahan_starling", gas.carnahan_starling)(lambda draw: dict(eta=draw(pos(0.0, 0.5))))
api("collision_rate", gas.collision_rate)(
    lambda draw: dict(collisions=draw(st.integers(0, 10**6)), n=draw(st.integers(1, 1000)), t=draw(pos(0.1, 100))))
api("compressibility_from_collision_rate", gas.compressibility_from_collision_rate)(
    lambda draw: dict(rate=draw(pos(0, 100)), sigma=draw(pos(0.01, 1)), mass=draw(pos(0.1, 5)),
                      temperature=draw(pos(0.1, 5))))
api("compressibility_from_virial", gas.compressibility_from_virial)(
    lambda draw: dict(virial=draw(pos(0, 1e4)), n=draw(st.integers(1, 1000)), temperature=draw(pos(0.1, 5)),
                      t=draw(pos(0.1, 100))))
api("compressibility_from_walls", gas.compressibility_from_walls)(
    lambda draw: dict(wall_impulse=draw(pos(0, 1e4)), n=draw(st.integers(1, 1000)), temperature=draw(pos(0.1, 5)),
                      side=draw(pos(1, 10)), t=draw(pos(0.1, 100))))
api("kinetic_temperature", gas.kinetic_temperature)(
    lambda draw: dict(velocities=draw(points(1, 10)), masses=draw(pos(0.1, 5))))
api("scaled_speeds", gas.scaled_speeds)(
    lambda draw: dict(velocities=draw(points(1, 10)), masses=draw(pos(0.1, 5)), temperature=draw(pos(0.1, 5))))
api("maxwell_boltzmann_test", gas.maxwell_boltzmann_test)(
    lambda draw: dict(speeds=draw(hnp.arrays(np.float64, (draw(st.integers(2, 30)),), elements=pos(0.01, 5)))))
api("mean_and_standard_error", gas.mean_and_standard_error)(
    lambda draw: dict(values=draw(hnp.arrays(np.float64, (draw(st.integers(2, 30)),), elements=_coord))))
api("speed_moment_ratio", gas.speed_moment_ratio)(
    lambda draw: dict(speeds=draw(hnp.arrays(np.float64, (draw(st.integers(1, 30)),), elements=pos(0.01, 5)))))

def _load_box(center, half_extents, velocity, rotation):
    return contact_io.load_shape({"shape": "box", "center": center, "half_extents": half_extents, "velocity": velocity,
                                  "rotation": rotation})


@api("load_shape", _load_box, optional=("velocity", "rotation"))
def _(draw):
    return dict(center=draw(vec()), half_extents=draw(hnp.arrays(np.float64, (3,), elements=pos(0.0, 3))),
                velocity=draw(vec()), rotation=draw(rotation()))


@api("plot_speed_histogram", lambda speeds: _bar_heights(gas.plot_speed_histogram(speeds, _scratch_png())),
     max_examples=3)
def _(draw):
    return dict(speeds=draw(hnp.arrays(np.float64, (draw(st.integers(2, 30)),), elements=pos(0.01, 5))))


def _bar_heights(figure):
    """The histogram the returned Figure draws (its bar heights), the numbers the NaN check looks at."""
    return np.array([bar.get_height() for bar in figure.axes[0].patches])


def _scratch_png():
    import os  # noqa: PLC0415
    import tempfile  # noqa: PLC0415
    return os.path.join(tempfile.mkdtemp(prefix="engine-fuzz-"), "speeds.png")


# --- the pipeline: shapes and World -------------------------------------------------------------------------------
api("Sphere", engine.Sphere)(lambda draw: dict(center=draw(vec()), radius=draw(pos(0.01, 3))))
api("Box", engine.Box, optional=("rotation",))(
    lambda draw: dict(center=draw(vec()), half_extents=draw(hnp.arrays(np.float64, (3,), elements=pos(0.01, 3))),
                      rotation=draw(rotation())))
api("Capsule", engine.Capsule)(lambda draw: dict(p0=draw(vec()), p1=draw(vec()), radius=draw(pos(0.01, 3))))
api("ConvexPolyhedron", engine.ConvexPolyhedron)(lambda draw: dict(points=draw(general_points(4, 12))))
api("Compound", lambda shapes, positions, rotations: engine.Compound(shapes, positions, rotations),
    optional=("rotations",))(
    lambda draw: dict(shapes=[engine.Sphere([0, 0, 0], draw(pos(0.01, 3))),
                              engine.Box([0, 0, 0], draw(hnp.arrays(np.float64, (3,), elements=pos(0.01, 3))))],
                      positions=draw(points(2, 2)), rotations=np.stack([draw(rotation()), draw(rotation())])))
api("Plane", engine.Plane)(lambda draw: dict(altitude=draw(_coord)))
api("HeightCurve", lambda samples: engine.HeightCurve(_curve, samples=samples))(
    lambda draw: dict(samples=draw(st.integers(2, 128))))
_GRID_TRIANGLES = np.array([[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4], [3, 4, 7], [3, 7, 6], [4, 5, 8], [4, 8, 7]])
api("TriangleMesh", engine.TriangleMesh)(  # a 3 x 3 grid of random heights: no zero-area triangle
    lambda draw: dict(vertices=np.column_stack([np.repeat([0.0, 1.0, 2.0], 3), draw(
        hnp.arrays(np.float64, (9,), elements=_coord)), np.tile([0.0, 1.0, 2.0], 3)]), triangles=_GRID_TRIANGLES))
api("HeightField", engine.HeightField)(
    lambda draw: dict(heights=draw(hnp.arrays(np.float64, (3, 4), elements=_coord)),
                      spacing=draw(pos(0.01, 3)), origin=draw(hnp.arrays(np.float64, (2,), elements=_coord))))


def _per_body(value, n):
    """The rows of a per-body argument; a corrupted one that has no rows (None, a scalar, a string) is handed
    to every body's constructor as it is, so that the engine, not this adapter, must refuse it."""
    if isinstance(value, str | bytes) or not hasattr(value, "__len__"):
        return [value] * n
    return list(value)


def _world(broad_phase, centers, radii, velocities, moved, dt):
    world = engine.World(broad_phase=broad_phase)
    n = max([len(v) for v in (centers, radii, velocities) if hasattr(v, "__len__") and not isinstance(v, str)],
            default=1)
    ids = [world.add(engine.Sphere(c, r), velocity=v)
           for c, r, v in zip(_per_body(centers, n), _per_body(radii, n), _per_body(velocities, n))]
    world.add(engine.Plane(-5.0))
    world.update(ids, moved)
    return world.pairs(), world.contacts(), world.time_of_impact(dt)


@api("World", _world, max_examples=60, indexed=False, optional=("velocities",),
     aliases=dict(centers="center", radii="radius", velocities="velocity", moved="centers"))
def _(draw):
    n = draw(st.integers(1, 8))
    c = hnp.arrays(np.float64, (n, 3), elements=_coord)
    return dict(broad_phase=draw(st.sampled_from(engine.BROAD_PHASES)), centers=draw(c),
                radii=draw(hnp.arrays(np.float64, (n,), elements=pos(0.1, 3))), velocities=draw(c), moved=draw(c),
                dt=draw(pos(0.01, 1.0)))


def _rays(origins, directions):
    """max_distance is left out: +inf is one of its valid values (properties/test_world_rays.py checks its
    refusals: negative, NaN, the wrong length)."""
    max_distance = 30.0
    world = engine.World()
    world.add(engine.Plane(-5.0))
    world.add(engine.Sphere([0.0, 0.0, 0.0], 1.0))
    world.add(engine.Box([3.0, 0.0, 0.0], [1.0, 0.5, 0.5]), static=True)
    return world.cast_rays(origins, directions, max_distance), world.cast_rays(origins, directions, max_distance,
                                                                              all_hits=True)


@api("World.cast_rays", _rays, max_examples=60, nan_fields=("point", "normal"))
def _(draw):
    n = draw(st.integers(1, 8))
    return dict(origins=draw(hnp.arrays(np.float64, (n, 3), elements=_coord)),
                directions=draw(hnp.arrays(np.float64, (n, 3), elements=pos(0.1, 3))))


#: public names that are not called with arrays: result records, exceptions, constants, JSON/file front ends (their
#: parsers are fuzzed in properties/test_contact_io.py-style tests of their own), plotting to a file.
NOT_CALLABLE_API = {
    "BisectionResult": "result record (dataclass)", "FallResult": "result record", "CubeDrop": "result record",
    "Impact": "result record", "ConvexHull": "result record built by convex_hull", "Contact": "result record",
    "GasResult": "result record",
    "ShapeHit": "result record built by World.cast_shape",
    "RayHits": "result record built by World.cast_rays",
    "RayHit": "result record built by World.cast_ray",
    "ContactBatch": "result record built by contact_feature_pairs", "BROAD_PHASES": "constant",
    "KDOP_SIZES": "constant",
    "BOUNDING_KINDS": "constant", "GAS_METHODS": "constant", "GAS_BOUNDARIES": "constant",
    "MAX_STEPS": "constant", "GasEventCapReached": "exception",
    "TOINotConverged": "exception", "EPANotConverged": "exception", "GJKNotConverged": "exception",
    "ShapeSpec": "result record built by load_shape", "SHAPE_KINDS": "constant", "ALL": "constant",
    "describe_contact": "text front end over load_shape (fuzzed here) and time_of_impact/contact_feature (fuzzed)",
    **dict.fromkeys(("ray_sphere", "ray_box", "ray_capsule", "ray_halfspace", "ray_hull"),
                    "compiled ray kernel, called from compiled code: no validation by contract (the caller "
                    "validates); properties/test_ray_kernels.py checks it"),
}

PUBLIC_MODULES = (engine, bounding, broadphase, narrow, gas, contact_io)
