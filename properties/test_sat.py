"""SAT: ``obb_overlap`` and ``overlap_convex_sat`` agree with GJK (overlap iff distance 0) and with coal's collide."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from engine.bounding.obb import OBB
from engine.narrowphase.gjk import gjk_distance
from engine.narrowphase.sat import obb_overlap, overlap_convex_sat, overlap_obb_obb_batch
from properties.strategies.degenerate import PlacedPair
from properties.strategies.narrow import edge_edge_obb_pairs, obb_pairs, obbs, point_clouds

GAP = 1e-7  # pairs closer than this (relative to their size) are left out: SAT's epsilon may call them touching
COAL_BAND = 1e-5  # against coal: gaps and depths below this (relative) are left to coal's gjk_tolerance

#: a box put 2.5e-5 below another, on its edge, turned by 1e-9 (found under the ci profile): GJK stopped 2.36e-12
#: above the gap (the bound below allows 1.0e-12) when a step did not decrease |v| — round-off hid the progress of
#: a step that still turned v towards the vertex the next support point would have found
NEAR_TOUCHING_EDGE = PlacedPair(
    a=np.array([[-0.025, -0.025, -0.025],
                [-0.025, -0.025, 0.025],
                [-0.025, 0.025, -0.025],
                [-0.025, 0.025, 0.025],
                [0.025, -0.025, -0.025],
                [0.025, -0.025, 0.025],
                [0.025, 0.025, -0.025],
                [0.025, 0.025, 0.025]]),
    b=np.array([[-0.0749999999419923, -0.05000000003864733, -0.07502500001936038],
                [-0.07499999995191181, -0.05000000004808819, -0.025025000019360373],
                [-0.07499999999008049, -3.864732839309326e-11, -0.07502500000991952],
                [-0.075, -4.808818621082622e-11, -0.025025000009919515],
                [-0.024999999941992295, -0.049999999990559145, -0.07502500000944086],
                [-0.02499999995191181, -0.05, -0.025025000009440856],
                [-0.02499999999008048, 9.440857817732962e-12, -0.07502500000000001],
                [-0.024999999999999998, 0.0, -0.025025]]),
    gap=2.5e-05, normal=np.array([0.0, 0.0, -1.0]),
    scale=1.0, box_a=None, box_b=None)


def _scale(a: OBB, b: OBB) -> float:
    return max(np.abs(np.concatenate([a.corners(), b.corners()])).max(), 1.0)


def _coal_collide(a: OBB, b: OBB) -> bool:
    import coal

    def placed(box):
        # coal's Box takes full side lengths; its rotation's columns are the box axes
        return coal.Box(*(2.0 * box.half_extents)), coal.Transform3s(box.axes.T.copy(), box.center.copy())

    ga, ta = placed(a)
    gb, tb = placed(b)
    res = coal.CollisionResult()
    coal.collide(ga, ta, gb, tb, coal.CollisionRequest(), res)
    return res.isCollision()


@given(obb_pairs())
def test_obb_overlap_iff_gjk_distance_zero(pair):
    a, b = pair
    d, _, _ = gjk_distance(a.corners(), b.corners())
    assume(d == 0.0 or d > GAP * _scale(a, b))
    assert obb_overlap(a, b) == (d == 0.0)
    assert obb_overlap(b, a) == (d == 0.0)


@settings(max_examples=100)
@given(obb_pairs())
def test_obb_overlap_agrees_with_coal(pair):
    a, b = pair
    d, _, _ = gjk_distance(a.corners(), b.corners())
    # coal decides grazing pairs with its own GJK tolerance (CollisionRequest().gjk_tolerance = 1e-6): it calls a
    # 6.25e-7 gap a collision (test below), so only gaps and depths clearly above it are compared with coal
    band = COAL_BAND * _scale(a, b)
    assume(d > band or d == 0.0)
    if d == 0.0:
        from engine.narrowphase.penetration import epa_penetration

        assume(epa_penetration(a.corners(), b.corners())[0] > band)
    assert obb_overlap(a, b) == _coal_collide(a, b)


def test_a_gap_below_coals_tolerance_is_a_gap():
    """Boxes 6.25e-7 apart (GJK; python-fcl's collide agrees): coal's collide says they touch (its gjk_tolerance is
    1e-6), obb_overlap says they do not, as the exact distance does."""
    s, c = 0.8414709848078965, 0.5403023058681398
    a = OBB([0.0, 0.0, 0.0], [[1.0, 0.0, 0.0], [0.0, c, s], [0.0, -s, c]], [1.0, 1.0, 1.0])
    b = OBB([0.4877103693176462, -0.30116867893975674, 2.2570137946006916], [[0.0, 1.0, 0.0], [c, 0.0, s],
                                                                          [-s, 0.0, c]], [1.0, 1.0, 0.0625])
    d, ca, cb = gjk_distance(a.corners(), b.corners())
    assert 5e-7 < d < 7e-7
    assert not obb_overlap(a, b) and not obb_overlap(b, a)
    # moved across the gap (and 3e-7 further): the boxes overlap
    assert obb_overlap(a, OBB(b.center + 1.5 * (ca - cb), b.axes, b.half_extents))


@given(edge_edge_obb_pairs())
def test_obb_overlap_on_crossing_edges(pair):
    """Boxes separated (or not) across crossing edges: only the edge-edge axis decides, one of the 9 each time."""
    a, b = pair
    d, _, _ = gjk_distance(a.corners(), b.corners())
    assume(d == 0.0 or d > GAP * _scale(a, b))
    assert obb_overlap(a, b) == (d == 0.0)


def test_parallel_edges_and_face_separation_examples():
    axes = np.eye(3)
    a = OBB([0, 0, 0], axes, [1, 1, 1])
    # identical orientation: every cross-product axis is null; separation only along x
    assert not obb_overlap(a, OBB([2.0 + 1e-6, 0.3, -0.2], axes, [1, 1, 1]))
    assert obb_overlap(a, OBB([2.0, 0.3, -0.2], axes, [1, 1, 1]))  # touching counts
    # edges parallel to z, boxes rotated 45 degrees about it: separated only along an edge-edge axis? no,
    # along B's face normal; check against the exact answer
    c, s = np.cos(np.pi / 4), np.sin(np.pi / 4)
    rot = np.array([[c, s, 0], [-s, c, 0], [0, 0, 1]])
    gap = 1 + np.sqrt(2)
    assert obb_overlap(a, OBB([gap - 1e-9, 0, 0], rot, [1, 1, 1]))
    assert not obb_overlap(a, OBB([gap + 1e-6, 0, 0], rot, [1, 1, 1]))


@given(obb_pairs(), st.data())
def test_batch_equals_single(pair, data):
    boxes = [pair[0], pair[1]] + [data.draw(obbs()) for _ in range(3)]
    centers = np.array([b.center for b in boxes])
    axes = np.array([b.axes for b in boxes])
    half = np.array([b.half_extents for b in boxes])
    aligned = overlap_obb_obb_batch(centers, axes, half, centers[::-1], axes[::-1], half[::-1])
    for p in range(5):
        assert aligned[p] == obb_overlap(boxes[p], boxes[4 - p])
    ia = np.array(data.draw(st.lists(st.integers(0, 4), min_size=1, max_size=8)))
    ib = np.array(data.draw(st.lists(st.integers(0, 4), min_size=len(ia), max_size=len(ia))))
    indexed = overlap_obb_obb_batch(centers, axes, half, centers, axes, half, ia, ib)
    for p in range(len(ia)):
        assert indexed[p] == obb_overlap(boxes[ia[p]], boxes[ib[p]])


@settings(max_examples=100)
@given(point_clouds(), point_clouds(spread=4.0))
def test_convex_sat_iff_gjk_distance_zero(a, b):
    d, _, _ = gjk_distance(a, b)
    scale = max(np.abs(np.concatenate([a, b])).max(), 1.0)
    assume(d == 0.0 or d > GAP * scale)
    if d == 0.0:
        from engine.narrowphase.penetration import epa_penetration

        assume(epa_penetration(a, b)[0] > GAP * scale)
    assert overlap_convex_sat(a, b) == (d == 0.0)


def test_convex_sat_flat_shapes():
    seg_a = np.array([[-1.0, 0, 0], [1.0, 0, 0]])
    seg_b = np.array([[0.0, -1, 0.1], [0.0, 1, 0.1]])
    assert not overlap_convex_sat(seg_a, seg_b)
    assert overlap_convex_sat(seg_a, seg_b - [0, 0, 0.1])
    square = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]])
    assert overlap_convex_sat(square, square + [0.5, 0.5, 0])
    assert not overlap_convex_sat(square, square + [0.5, 0.5, 1e-3])


def test_bad_input_raises():
    good_c = np.zeros((1, 3))
    good_a = np.eye(3)[None]
    good_h = np.ones((1, 3))
    with pytest.raises(ValueError, match="orthonormal"):
        overlap_obb_obb_batch(good_c, 2 * good_a, good_h, good_c, good_a, good_h)
    with pytest.raises(ValueError, match=r"half_extents_b\[0, 1\]"):
        overlap_obb_obb_batch(good_c, good_a, good_h, good_c, good_a, np.array([[1.0, -1.0, 1.0]]))
    with pytest.raises(ValueError, match="finite"):
        overlap_obb_obb_batch(np.full((1, 3), np.nan), good_a, good_h, good_c, good_a, good_h)
    with pytest.raises(ValueError, match=r"index_b\[0\]"):
        overlap_obb_obb_batch(good_c, good_a, good_h, good_c, good_a, good_h, [0], [3])
    with pytest.raises(ValueError):
        OBB([0, 0, 0], [[1, 0, 0], [0, 1, 0], [0, 0, 2]], [1, 1, 1])
    with pytest.raises(ValueError):
        OBB([0, 0, 0], np.eye(3), [1, -1, 1])
    with pytest.raises(TypeError):
        obb_overlap(OBB([0, 0, 0], np.eye(3), [1, 1, 1]), "box")
    with pytest.raises(ValueError):
        overlap_convex_sat(np.zeros((0, 3)), np.zeros((3, 3)))


# --- touching hulls (issue 18): closed sets, touching counts as overlapping, as GJK's distance 0 -----------------

def test_convex_sat_touching_boxes_at_a_non_binary_coordinate():
    """B's face put on A's face x = -0.025 by a translation rounded in binary: B's face lands at
    -0.02500000000000001, 1.7e-17 (of boxes of size 0.6) from A's. GJK's distance is 0 (below its OVERLAP_TOL of
    the pair's size): SAT compared the projections exactly and called the pair separated."""
    from properties.strategies.degenerate import SIGNS

    a = SIGNS * [0.025, 0.01973981683858466, 0.22160007946468377]
    b = np.array([[-0.14688025994948423, -0.20481289242630615, 0.22583840883939155],
                  [-0.14688025994948423, 0.113071510929034, 0.32848948547141354],
                  [-0.14688025994948423, -0.044821745051581874, -0.26961368084171344],
                  [-0.14688025994948423, 0.2730626583037583, -0.1669626042096915],
                  [-0.02500000000000001, -0.20481289242630615, 0.22583840883939155],
                  [-0.02500000000000001, 0.113071510929034, 0.32848948547141354],
                  [-0.02500000000000001, -0.044821745051581874, -0.26961368084171344],
                  [-0.02500000000000001, 0.2730626583037583, -0.1669626042096915]])
    assert gjk_distance(a, b)[0] == 0.0
    assert overlap_convex_sat(a, b) and overlap_convex_sat(b, a)
    # 1e-9 apart (well above the tolerance, 1e-10 of the pair's size): separated
    assert not overlap_convex_sat(a, b - [1e-9, 0.0, 0.0])


@settings(max_examples=100)
@given(st.data())
def test_convex_sat_on_placed_pairs_agrees_with_the_construction(data):
    """A hull put on a face of a box (face, edge or vertex on the face, axes parallel or turned by quarter turns
    ± 1e-9, sizes 1e-6..1e6): touching or overlapping pairs overlap, a gap of 1e-6 of the box's size separates;
    GJK agrees: the gap, or (nearly) 0. GJK stops when |v|² − v·w <= REL_TOL |v|² + 1e-15 size(M)², and for hulls
    that touch v·w <= 0: its distance there is at most sqrt(1e-15) size(M) = 3.2e-8 size(M), not always 0."""
    from properties.strategies.degenerate import placed_pairs

    _check_placed_pair(data.draw(placed_pairs(gaps=st.sampled_from([0.0, -1e-6, -0.3, 1e-6, 1e-3]))))


def test_convex_sat_and_gjk_on_the_near_touching_edge_pair():
    """The pinned pair GJK once answered 2.36e-12 above its gap (the bound allows 1.0e-12)."""
    _check_placed_pair(NEAR_TOUCHING_EDGE)


def _check_placed_pair(pair) -> None:
    from properties.geometry_checks import minkowski_size

    d, _, _ = gjk_distance(pair.a, pair.b)
    overlapping = pair.gap <= 0.0
    assert overlap_convex_sat(pair.a, pair.b) == overlapping, (pair.gap, d)
    assert overlap_convex_sat(pair.b, pair.a) == overlapping
    if overlapping:
        assert d <= 3.2e-8 * minkowski_size(pair.a, pair.b)
    else:
        # the construction's own round-off: B's coordinates rounded once after the move (a few u of them)
        # and GJK's stop test |v|² − v·w <= ... + 1e-15 size(M)²: its distance is within 1e-15 size(M)² / d
        size = minkowski_size(pair.a, pair.b)
        assert abs(d - pair.gap) <= 1e-9 * pair.gap + 1e-12 * np.abs(pair.b).max() + 1e-15 * size * size / d
