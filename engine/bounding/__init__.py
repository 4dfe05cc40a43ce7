"""Bounding volumes (chapter: "Volumes englobants"): sphere, AABB, OBB, k-DOP, convex hull, decomposition.

Each volume has a fit from points, an overlap test, merge / contains, and an update under rotation and
translation; batched forms take stacked arrays and run in one compiled call. Volumes are closed: two volumes
that touch overlap, and a point on the boundary is contained.

How to pick (cheapest first):

- spheres: 4 numbers, an update under rotation that moves only the centre, loose on elongated objects;
- AABBs: 6 numbers, the broad phase's native volume, re-fitted (or conservatively grown) after a rotation;
- k-DOPs: k numbers, tighter than AABBs at a few more interval tests;
- OBBs: 15 numbers, tight on elongated objects, tested by the separating axis theorem;
- the convex hull: exact for convex objects, the narrow phase's input;
- a convex decomposition for concave objects.
"""
from __future__ import annotations

from collections.abc import Iterable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .._validate import as_float_array
from .aabb import (
    aabb_contains,
    fit_aabb,
    fit_aabbs,
    merge_aabb,
    overlap_aabb_aabb,
    overlap_aabbs,
    transform_aabb,
    transform_aabbs,
)
from .decompose import decompose_mesh, decompose_polygon, triangulate_polygon
from .hull import ConvexHull, convex_hull, is_convex
from .kdop import (
    KDOP_SIZES,
    fit_kdop,
    fit_kdops,
    kdop_contains,
    kdop_directions,
    merge_kdop,
    overlap_kdop_kdop,
    overlap_kdops,
    transform_kdop,
    update_kdop,
)
from .obb import OBB, fit_obb, merge_obb, transform_obb
from .sphere import (
    circumsphere,
    merge_spheres,
    min_bounding_sphere,
    overlap_sphere_sphere,
    overlap_spheres,
    ritter_sphere,
    ritter_spheres,
    sphere_contains,
    transform_sphere,
)

__all__ = [
    # sphere
    "ritter_sphere", "ritter_spheres", "min_bounding_sphere", "circumsphere", "overlap_sphere_sphere",
    "overlap_spheres", "merge_spheres", "sphere_contains", "transform_sphere",
    # AABB
    "fit_aabb", "fit_aabbs", "overlap_aabb_aabb", "overlap_aabbs", "merge_aabb", "aabb_contains",
    "transform_aabb", "transform_aabbs",
    # OBB
    "OBB", "fit_obb", "merge_obb", "transform_obb",
    # k-DOP
    "KDOP_SIZES", "kdop_directions", "fit_kdop", "fit_kdops", "overlap_kdop_kdop", "overlap_kdops",
    "merge_kdop", "kdop_contains", "update_kdop", "transform_kdop",
    # hull, convexity, decomposition
    "ConvexHull", "convex_hull", "is_convex", "triangulate_polygon", "decompose_polygon", "decompose_mesh",
    # summaries for the command line (JSON-ready dicts)
    "BOUNDING_KINDS", "describe_bounding_volumes", "describe_hull", "describe_decomposition",
]

#: the volumes ``describe_bounding_volumes`` can fit, by name: "welzl" and "ritter" (spheres), "aabb", "obb",
#: "kdop8" (2-D), "kdop14", "kdop18", "kdop26" (3-D)
BOUNDING_KINDS = ("welzl", "ritter", "aabb", "obb", "kdop8", "kdop14", "kdop18", "kdop26")


def describe_bounding_volumes(points: ArrayLike, kinds: Iterable[str] | None = None) -> dict[str, Any]:
    """Fit every requested volume to a point cloud and summarise each as plain lists (JSON-ready).

    What ``colldet bound`` prints.

    Parameters
    ----------
    points : array_like, shape (n, d)
        The point cloud, n >= 1, d = 2 or 3, finite.
    kinds : iterable of str, optional
        Names from ``BOUNDING_KINDS``. Default: all that apply to the dimension ("obb" and the 3-D k-DOPs need
        d = 3, "kdop8" needs d = 2).

    Returns
    -------
    dict
        ``"points"`` (n) and ``"dim"`` (d), then one entry per kind: a dict of the volume's parameters as
        lists ("center" and "radius" for spheres; "lo", "hi" for an AABB; "center", "axes", "half_extents" for
        an OBB; "directions", "lo", "hi" for a k-DOP) and, for spheres, AABBs and OBBs, its ``"measure"`` (area
        in 2-D, volume in 3-D), so that volumes can be compared for tightness.

    Raises
    ------
    ValueError
        For invalid points (NaN, ±inf, no row, d not 2 or 3), or a kind that does not apply to d.
    TypeError
        For non-numeric points.
    """
    from .aabb import as_points

    pts = as_points(points)
    d = pts.shape[1]
    applicable = [k for k in BOUNDING_KINDS
                  if not ((k == "obb" or k in ("kdop14", "kdop18", "kdop26")) and d != 3)
                  and not (k == "kdop8" and d != 2)]
    kinds = applicable if kinds is None else list(kinds)
    out: dict = {"points": int(pts.shape[0]), "dim": d}
    ball = np.pi if d == 2 else 4.0 * np.pi / 3.0
    for kind in kinds:
        if kind not in applicable:
            raise ValueError(f"kind {kind!r} does not apply to {d}-D points; expected one of {applicable}")
        if kind in ("welzl", "ritter"):
            c, r = (min_bounding_sphere if kind == "welzl" else ritter_sphere)(pts)
            out[kind] = {"center": c.tolist(), "radius": r, "measure": ball * r**d}
        elif kind == "aabb":
            lo, hi = fit_aabb(pts)
            out[kind] = {"lo": lo.tolist(), "hi": hi.tolist(), "measure": float(np.prod(hi - lo))}
        elif kind == "obb":
            box = fit_obb(pts)
            out[kind] = {"center": box.center.tolist(), "axes": box.axes.tolist(),
                         "half_extents": box.half_extents.tolist(), "measure": float(8 * np.prod(box.half_extents))}
        else:
            k = int(kind[4:])
            lo, hi = fit_kdop(pts, k)
            out[kind] = {"directions": kdop_directions(k).tolist(), "lo": lo.tolist(), "hi": hi.tolist()}
    return out


def describe_hull(points: ArrayLike) -> dict[str, Any]:
    """The convex hull of a point cloud as plain lists (JSON-ready): what ``colldet hull`` prints.

    Parameters
    ----------
    points : array_like, shape (n, d)
        The points, d = 2 or 3 (see :func:`convex_hull` for what is refused).

    Returns
    -------
    dict
        ``"dim"``, ``"vertices"`` (indices into ``points``), ``"faces"`` (index lists), ``"volume"`` (the
        area in 2-D) and ``"area"`` (the perimeter in 2-D), as given by :func:`convex_hull`.
    """
    hull = convex_hull(points)
    return {"dim": hull.dim, "vertices": hull.vertices.tolist(), "faces": hull.faces.tolist(),
            "volume": hull.volume, "area": hull.area}


def describe_decomposition(polygon: ArrayLike) -> dict[str, Any]:
    """A simple polygon split into convex pieces, as plain lists (JSON-ready): what ``colldet decompose`` prints.

    Parameters
    ----------
    polygon : array_like, shape (n, 2)
        A simple polygon in boundary order (either orientation), n >= 3.

    Returns
    -------
    dict
        ``"vertices"`` (n), ``"convex"`` (bool), ``"triangles"`` (the ear-clipping triangulation, index
        triples) and ``"pieces"`` (the convex pieces of :func:`decompose_polygon`, index lists).

    Raises
    ------
    ValueError
        When the polygon is invalid (fewer than 3 vertices, not finite, not simple, zero area).
    TypeError
        For a non-numeric polygon.
    """
    poly = as_float_array(polygon, "polygon", shape=(None, 2), min_rows=3)
    pieces = decompose_polygon(poly)
    triangles = triangulate_polygon(poly)
    return {"vertices": int(len(poly)), "convex": is_convex(poly), "triangles": triangles.tolist(),
            "pieces": [p.tolist() for p in pieces]}
