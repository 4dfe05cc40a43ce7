"""The JSON-ready summaries of the bounding volumes (``describe_bounding_volumes``, ``describe_hull``,
``describe_decomposition``: what ``colldet bounding`` / ``hull`` / ``decompose`` print) say exactly what the
fits say, under the documented keys, with the documented measures:

- a sphere's measure is its area pi r^2 in 2-D and its volume 4/3 pi r^3 in 3-D;
- an AABB's is the product of its sides, an OBB's 8 times the product of its half extents;
- a k-DOP lists its slab directions and bounds; the hull its vertices, faces, volume (area in 2-D) and area
  (Qhull's volume and area as the independent oracle); the decomposition its vertex count, convexity,
  triangles and pieces.
"""
from __future__ import annotations

import json
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.spatial import ConvexHull as QhullHull

from engine.bounding import (
    BOUNDING_KINDS,
    convex_hull,
    decompose_polygon,
    describe_bounding_volumes,
    describe_decomposition,
    describe_hull,
    fit_aabb,
    fit_kdop,
    fit_obb,
    is_convex,
    kdop_directions,
    min_bounding_sphere,
    ritter_sphere,
    triangulate_polygon,
)
from properties.strategies.geometry import convex_polygons, general_position_clouds, star_polygons

BALL = {2: math.pi, 3: 4.0 * math.pi / 3.0}


@given(st.sampled_from([2, 3]).flatmap(lambda d: general_position_clouds(d, max_size=30)))
def test_bounding_summary_is_every_fit_with_its_measure(pts):
    d = pts.shape[1]
    summary = json.loads(json.dumps(describe_bounding_volumes(pts)))
    assert summary["points"] == len(pts) and summary["dim"] == d
    kinds = {"welzl", "ritter", "aabb"} | ({"obb", "kdop14", "kdop18", "kdop26"} if d == 3 else {"kdop8"})
    assert set(summary) == kinds | {"points", "dim"}
    for kind, fit in (("welzl", min_bounding_sphere), ("ritter", ritter_sphere)):
        center, radius = fit(pts)
        assert summary[kind] == {"center": center.tolist(), "radius": radius,
                                 "measure": pytest.approx(BALL[d] * radius**d, rel=1e-14)}
    lo, hi = fit_aabb(pts)
    assert summary["aabb"] == {"lo": lo.tolist(), "hi": hi.tolist(),
                               "measure": pytest.approx(float(np.prod(hi - lo)), rel=1e-14)}
    if d == 3:
        box = fit_obb(pts)
        assert summary["obb"] == {"center": box.center.tolist(), "axes": box.axes.tolist(),
                                  "half_extents": box.half_extents.tolist(),
                                  "measure": pytest.approx(8.0 * float(np.prod(box.half_extents)), rel=1e-14)}
    for kind in kinds - {"welzl", "ritter", "aabb", "obb"}:
        k = int(kind[4:])
        lo, hi = fit_kdop(pts, k)
        assert summary[kind] == {"directions": kdop_directions(k).tolist(), "lo": lo.tolist(), "hi": hi.tolist()}


@given(st.sampled_from([2, 3]).flatmap(lambda d: general_position_clouds(d, max_size=20)), st.data())
def test_bounding_summary_of_chosen_kinds_has_those_kinds_only(pts, data):
    d = pts.shape[1]
    applicable = [k for k in BOUNDING_KINDS if (k in ("obb", "kdop14", "kdop18", "kdop26")) == (d == 3)
                  or k in ("welzl", "ritter", "aabb")]
    kinds = data.draw(st.lists(st.sampled_from(applicable), min_size=1, max_size=3, unique=True))
    summary = describe_bounding_volumes(pts, kinds=kinds)
    assert set(summary) == set(kinds) | {"points", "dim"}


@given(st.sampled_from([2, 3]).flatmap(lambda d: general_position_clouds(d, max_size=40)))
def test_hull_summary_is_the_hull(pts):
    hull = convex_hull(pts)
    summary = json.loads(json.dumps(describe_hull(pts)))
    assert summary == {"dim": pts.shape[1], "vertices": hull.vertices.tolist(), "faces": hull.faces.tolist(),
                       "volume": hull.volume, "area": hull.area}
    qhull = QhullHull(pts)
    assert sorted(summary["vertices"]) == sorted(qhull.vertices.tolist())
    assert summary["volume"] == pytest.approx(qhull.volume, rel=1e-9)
    assert summary["area"] == pytest.approx(qhull.area, rel=1e-9)


@given(st.one_of(star_polygons(), convex_polygons()))
def test_decomposition_summary_is_the_decomposition(poly):
    summary = json.loads(json.dumps(describe_decomposition(poly)))
    assert summary == {"vertices": len(poly), "convex": is_convex(poly),
                       "triangles": triangulate_polygon(poly).tolist(),
                       "pieces": [p.tolist() for p in decompose_polygon(poly)]}
    assert len(summary["triangles"]) == len(poly) - 2
    assert summary["convex"] == (len(summary["pieces"]) == 1)


def test_decomposition_summary_of_a_notched_square():
    notched = [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [1.0, 1.0], [0.0, 2.0]]
    summary = describe_decomposition(notched)
    assert summary["vertices"] == 5 and summary["convex"] is False
    assert len(summary["triangles"]) == 3 and len(summary["pieces"]) == 2
    assert describe_decomposition([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])["convex"] is True
