"""No geometrically impossible answer (issue 18): every function returning points or normals, on degenerate pairs.

The pairs (properties.strategies.degenerate.placed_pairs) are a box and a box or a convex cloud put face on
face, edge on face or vertex on face, touching, a little apart or overlapping, with axes parallel or turned by
quarter turns ± 1e-9, at sizes 1e-6 to 1e6. The checks (properties.geometry_checks, each tolerance derived
there) are the same for every function:

- ``gjk_distance`` (and ``gjk_distance_pairs``, ``gjk_distance_batch``): closest points on their shapes,
  |p_a − p_b| = distance, and apart, the shapes' projections on (p_b − p_a)/d leave exactly that gap;
- ``epa_penetration(..., witnesses=True)`` and ``epa_penetration_pairs``: a unit normal, witnesses on their
  shapes with p_a − p_b = depth · n, and B moved by the depth along n touches A without overlapping it;
- ``contact_feature`` and ``contact_feature_pairs``: unit normals, closest points on their shapes, contact points
  in the depth band of both shapes, the separation consistent with the normal;
- ``World.contacts()``: the same on the ContactSet (points, normals, depths) of boxes and hulls;
- ``time_of_impact``: at t_hit the shapes touch (GJK distance within the TOI tolerance) and are apart before it.
"""
from __future__ import annotations

import numpy as np
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st

from engine import Box, ConvexPolyhedron, World
from engine.narrowphase import (
    contact_feature,
    contact_feature_pairs,
    epa_penetration,
    epa_penetration_pairs,
    gjk_distance,
    gjk_distance_batch,
    gjk_distance_pairs,
    pack_point_sets,
    time_of_impact,
)
from engine.narrowphase.epa import EPA_TOL
from engine.narrowphase.gjk import OVERLAP_TOL
from properties.geometry_checks import (
    assert_closest_gap,
    assert_in_depth_band,
    assert_on_hull,
    assert_separated_after,
    assert_unit,
    assert_witness_gap,
    minkowski_size,
    pair_scale,
    projection_overlap,
)
from properties.strategies.degenerate import SIGNS, PlacedPair, placed_pairs

#: GJK stops when |v|² − v·w <= REL_TOL |v|² + 1e-15 size(M)²; its direction (p_b − p_a)/d then errs by about
#: 1e-15 size(M)² / d² radians... measured by the projections, the gap along it is off by at most that stop
#: term over d: 1e-15 size(M)² / d (the slack of assert_separated_after for closest points)
GJK_STOP = 1e-15

apart = st.sampled_from([1e-6, 1e-3, 0.1])
overlapping = st.sampled_from([-1e-6, -1e-3, -0.3])

#: near-touching pairs (found under the ci profile) where GJK's closest points left their projections overlapping
#: by 4 to 5 times the allowance along (p_b − p_a)/d: the barycentric weights of the final face, from ratios of
#: products of dot products, were 25–250 u off, which tilted v by that times size(M)/|v|
NEAR_TOUCHING_FACE = PlacedPair(
    a=np.array([[-2e-08, -1.745e-06, -1.655655774549036e-06],
                [-2e-08, -1.745e-06, -1.344344225450964e-06],
                [-2e-08, -1.2549999999999998e-06, -1.655655774549036e-06],
                [-2e-08, -1.2549999999999998e-06, -1.344344225450964e-06],
                [2e-08, -1.745e-06, -1.655655774549036e-06],
                [2e-08, -1.745e-06, -1.344344225450964e-06],
                [2e-08, -1.2549999999999998e-06, -1.655655774549036e-06],
                [2e-08, -1.2549999999999998e-06, -1.344344225450964e-06]]),
    b=np.array([[-8.216231930924244e-16, -1.955000245440746e-06, -7.246931242054976e-07],
                [3.9999999178376805e-08, -1.955000245441057e-06, -7.246931241702657e-07],
                [-8.19989107864183e-16, -1.745000245440746e-06, -7.246931241060772e-07],
                [3.999999918001089e-08, -1.7450002454410572e-06, -7.246931240708453e-07],
                [-1.6340852282414886e-18, -1.955000245e-06, -1.6556557746484562e-06],
                [3.999999999836591e-08, -1.955000245000311e-06, -1.6556557746132245e-06],
                [0.0, -1.745000245e-06, -1.655655774549036e-06],
                [4e-08, -1.7450002450003112e-06, -1.655655774513804e-06]]),
    gap=2.4499999999999997e-13, normal=np.array([0.0, -1.0, 0.0]),
    scale=1e-06, box_a=None, box_b=None)
NEAR_TOUCHING_TILTED = PlacedPair(
    a=np.array([[-1.8021441261664023e-08, 5.68917348483311e-07, 1.642014481882923e-07],
                [8.083519890070166e-08, 6.305514414391926e-07, 1.9298691815691148e-07],
                [-5.260788624065697e-08, 3.303661633096207e-07, 7.937546806792187e-07],
                [4.624875392170871e-08, 3.9200025626550236e-07, 8.225401506478379e-07],
                [-4.624875392170871e-08, 6.079997437344976e-07, 1.7745984935216208e-07],
                [5.260788624065697e-08, 6.696338366903793e-07, 2.0624531932078127e-07],
                [-8.083519890070166e-08, 3.6944855856080736e-07, 8.070130818430885e-07],
                [1.8021441261664023e-08, 4.31082651516689e-07, 8.357985518117077e-07]]),
    b=np.array([[7.372022560044752e-08, 5.814341759387347e-07, 3.2262425427222293e-07],
                [4.1185437717976397e-07, 7.922504822158693e-07, 4.210835024285892e-07],
                [4.0029764291790124e-08, 3.490628096676416e-07, 9.358685132256425e-07],
                [3.781639158711066e-07, 5.598791159447762e-07, 1.0343277613820087e-06],
                [5.678383800442071e-08, 6.048836130894466e-07, 3.305792949705449e-07],
                [3.9491798958373715e-07, 8.156999193665813e-07, 4.2903854312691104e-07],
                [2.3093376695763316e-08, 3.7251224681835356e-07, 9.438235539239643e-07],
                [3.612275282750798e-07, 5.833285530954883e-07, 1.0422828020803307e-06]]),
    gap=8.426522142392062e-12, normal=np.array([0.8238053346863807, 0.513617441299014, 0.23987891640516038]),
    scale=1e-06, box_a=None, box_b=None)


def _check_closest(a, b, d, ca, cb) -> None:
    """At distance 0 GJK returns one common point, the mean of its points on A and on B, which may be apart by
    up to OVERLAP_TOL × size(M) (its touching tolerance): half of that is allowed off each hull."""
    scale = pair_scale(a, b)
    allowed = 0.5 * OVERLAP_TOL * minkowski_size(a, b) if d == 0.0 else 0.0
    assert_on_hull(ca, a, scale, radius=allowed, what="closest_a")
    assert_on_hull(cb, b, scale, radius=allowed, what="closest_b")
    assert_closest_gap(ca, cb, d, scale)
    if d > 0.0:
        size = minkowski_size(a, b)
        assert_separated_after(a, b, (cb - ca) / d, -d, scale, slack=GJK_STOP * size * size / d)


@settings(max_examples=60)
@given(placed_pairs())
@example(NEAR_TOUCHING_FACE)
@example(NEAR_TOUCHING_TILTED)
def test_gjk_closest_points_single_pairs_and_batch(pair):
    a, b = pair.a, pair.b
    d, ca, cb = gjk_distance(a, b)
    _check_closest(a, b, d, ca, cb)
    points, offsets = pack_point_sets([a, b])
    dp, cap, cbp = gjk_distance_pairs(points, offsets, [[0, 1], [1, 0]])
    _check_closest(a, b, dp[0], cap[0], cbp[0])
    _check_closest(b, a, dp[1], cap[1], cbp[1])
    if a.shape == b.shape:
        db, cab, cbb = gjk_distance_batch(a[None], b[None])
        _check_closest(a, b, db[0], cab[0], cbb[0])


def _check_penetration(a, b, depth, normal, point_a=None, point_b=None) -> None:
    scale = pair_scale(a, b)
    assert_unit(normal)
    assert depth >= 0.0
    assert_separated_after(a, b, normal, depth, scale)
    if point_a is not None:
        assert_on_hull(point_a, a, scale, what="point_a")
        assert_on_hull(point_b, b, scale, what="point_b")
        if depth == 0.0:  # touching: the witnesses differ by the origin's distance to GJK's simplex, <= EPA_TOL size(M)
            assert np.abs(point_a - point_b).max() <= EPA_TOL * minkowski_size(a, b) + 1e-12 * scale
        else:
            assert_witness_gap(point_a, point_b, depth, normal, scale)


@settings(max_examples=80)
@given(placed_pairs(gaps=overlapping))
def test_epa_witnesses_and_normals_single_and_pairs(pair):
    a, b = pair.a, pair.b
    depth, normal, point_a, point_b = epa_penetration(a, b, witnesses=True)
    _check_penetration(a, b, depth, normal, point_a, point_b)
    points, offsets = pack_point_sets([a, b])
    depths, normals = epa_penetration_pairs(points, offsets, [[0, 1], [1, 0]])
    _check_penetration(a, b, depths[0], normals[0])
    _check_penetration(b, a, depths[1], normals[1])


def _check_contact(a, b, separation, normal, points, closest_a, closest_b) -> None:
    scale = pair_scale(a, b)
    assert_unit(normal)
    assert points.shape[0] >= 1
    # touching (separation 0, no EPA depth): GJK's common point, as in _check_closest
    allowed = 0.5 * OVERLAP_TOL * minkowski_size(a, b) if separation == 0.0 else 0.0
    assert_on_hull(closest_a, a, scale, radius=allowed, what="closest_a")
    assert_on_hull(closest_b, b, scale, radius=allowed, what="closest_b")
    assert_in_depth_band(points, a, b, normal, scale)
    if separation <= 0.0:  # EPA's normal (or touching): the depth is the projections' overlap along it
        assert_separated_after(a, b, normal, -separation, scale)
    else:
        size = minkowski_size(a, b)
        assert_separated_after(a, b, normal, -separation, scale, slack=GJK_STOP * size * size / separation)


@settings(max_examples=80)
@given(placed_pairs())
def test_contact_feature_points_and_normals_single_and_pairs(pair):
    a, b = pair.a, pair.b
    c = contact_feature(a, b)
    _check_contact(a, b, c.separation, c.normal, c.points, c.closest_a, c.closest_b)
    points, offsets = pack_point_sets([a, b])
    batch = contact_feature_pairs(points, offsets, [[0, 1], [1, 0]])
    for p, (x, y) in enumerate(((a, b), (b, a))):
        got = batch[p]
        _check_contact(x, y, got.separation, got.normal, got.points, got.closest_a, got.closest_b)


@settings(max_examples=60)
@given(placed_pairs(gaps=st.sampled_from([0.0, -1e-6, -1e-3, -0.3])), st.booleans())
def test_world_contacts_points_normals_depths(pair, as_boxes):
    # as_boxes: the pair as World Boxes (the box-box closed form) when B is a box, else as hulls (GJK/EPA)
    world = World("brute")
    if as_boxes and pair.box_b is not None:
        ids = [world.add(Box(*pair.box_a)), world.add(Box(*pair.box_b))]
    else:
        ids = [world.add(ConvexPolyhedron(pair.a)), world.add(ConvexPolyhedron(pair.b))]
    cs = world.contacts()
    # touching pairs (and pairs pushed into A across one of its edges, which may only touch) can be called apart
    assume(len(cs) == 1)
    assert cs.pairs.tolist() == [sorted(ids)]
    a, b = (world.world_points(i) for i in cs.pairs[0])
    scale = pair_scale(a, b)
    assert_unit(cs.normal)
    assert cs.depth[0] >= 0.0
    assert_in_depth_band(cs.points_of(0), a, b, cs.normal[0], scale)
    assert_separated_after(a, b, cs.normal[0], cs.depth[0], scale)


@settings(max_examples=60)
@given(placed_pairs(gaps=st.sampled_from([1e-3, 0.1, 0.3])), st.floats(0.2, 0.9))
def test_time_of_impact_positions_touch_and_do_not_overlap_before(pair, when):
    """B moves straight towards A's face along −n, to arrive at t = ``when``: the exact time is gap / speed (the
    distance along the way is gap − speed t, B's lowest vertex above a point of A's face)."""
    a, b = pair.a, pair.b
    speed = pair.gap / when
    velocity = -speed * pair.normal
    t = time_of_impact(a, np.zeros(3), b, velocity)
    size = max(np.ptp(a, axis=0).max(), np.ptp(b, axis=0).max())
    tol = 1e-9 * size  # time_of_impact's default tolerance
    assert t is not None
    d_hit, ca, cb = gjk_distance(a, b + t * velocity)
    assert d_hit <= tol + 3.2e-8 * minkowski_size(a, b + t * velocity)
    _check_closest(a, b + t * velocity, d_hit, ca, cb)
    assert abs(t - when) * speed <= tol + 1e-12 * pair_scale(a, b)
    for frac in (0.0, 0.5, 0.99):
        d_before, _, _ = gjk_distance(a, b + frac * t * velocity)
        assert d_before > 0.0


# --- the defects the family found, pinned -------------------------------------------------------------------

CUBE = SIGNS * 0.025


def test_touching_witnesses_lie_on_both_shapes():
    """B's vertex (−0.024999975, −0.025, −0.025) lies on A's edge, B below A's face y = −0.025: the hulls touch
    (depth 0, normal −y). GJK ends on a segment of M through the origin; EPA's touching answer gave A's vertex of
    the segment's first point, A's corner (−0.025, −0.025, −0.025), as both witnesses: 1.1e-8 outside B. The
    witnesses are now the origin's barycentric weights on the segment applied to A's and to B's vertices."""
    b = np.array([[-0.0544567206009186, -0.05197964566051361, 0.008603947156256866],
                  [-0.05497747319942744, -0.06206875840725883, 0.001633257267911933],
                  [-0.024999975, -0.025000000000000005, -0.025],
                  [-0.08923551290440475, -0.06425888564166486, -0.006373469621144096]])
    depth, normal, point_a, point_b = epa_penetration(CUBE, b, witnesses=True)
    assert depth == 0.0
    _check_penetration(CUBE, b, depth, normal, point_a, point_b)


def test_normal_of_a_pair_apart_by_round_off_separates_them():
    """B's vertex put on A's corner: GJK's distance is 7.8e-18 (round-off of the translation), its closest points'
    difference a direction of pure round-off, along which the shapes overlap by 0.147 (of a 0.2 pair). The
    separated pair's normal is now checked against M below 1e-5 of the size and replaced by a direction of M's
    normal cone at the contact when that separates better (touching_normal.separated_normal_at_contact)."""
    a = SIGNS * [0.06, 0.025, 0.025]
    b = np.array([[-0.0894567456009186, -0.05197964566051361, 0.008603947156256866],
                  [-0.08997749819942744, -0.06206875840725883, 0.001633257267911933],
                  [-0.05999999999999999, -0.025000000000000005, -0.025],
                  [-0.12423553790440474, -0.06425888564166486, -0.006373469621144096]])
    d, ca, cb = gjk_distance(a, b)
    assert 0.0 < d < 1e-16
    assert projection_overlap(a, b, (cb - ca) / np.linalg.norm(cb - ca)) > 0.1  # the closest points' direction
    c = contact_feature(a, b)
    _check_contact(a, b, c.separation, c.normal, c.points, c.closest_a, c.closest_b)
    depth, normal = epa_penetration(a, b)
    _check_penetration(a, b, depth, normal)
