"""Bounding volumes (chapter: "Volumes englobants"): sphere, AABB, OBB, k-DOP, convex hull, decomposition.

Each volume has a fit from points, an overlap test, merge / contains, and an update under rotation and
translation; batched forms take stacked arrays and run in one compiled call.

How to pick (cheapest first): spheres (4 numbers, rotation-free update, loose on elongated objects) — AABBs
(6 numbers, the broad phase's native volume, must be re-fitted after a rotation) — k-DOPs (k numbers, tighter
than AABBs at a few more interval tests) — OBBs (15 numbers, tight on elongated objects, SAT test) — the convex
hull (exact for convex objects, the narrow phase's input) — a convex decomposition for concave objects.
"""
import numpy as np

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
    "ritter_sphere", "ritter_spheres", "min_bounding_sphere", "overlap_sphere_sphere", "overlap_spheres",
    "merge_spheres", "sphere_contains", "transform_sphere",
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

#: the volumes ``describe_bounding_volumes`` can fit, by name
BOUNDING_KINDS = ("welzl", "ritter", "aabb", "obb", "kdop8", "kdop14", "kdop18", "kdop26")


def describe_bounding_volumes(points, kinds=None) -> dict:
    """Fit every requested volume to ``points`` (n, d), d = 2 or 3, and summarise each as plain lists.

    ``kinds``: names from ``BOUNDING_KINDS`` (default: all that apply to the dimension: "obb" and the 3-D
    k-DOPs need d = 3, "kdop8" needs d = 2). Each entry has the volume's parameters and its ``measure`` (area
    in 2-D, volume in 3-D), so volumes can be compared for tightness.
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


def describe_hull(points) -> dict:
    """The convex hull of ``points`` (n, d) as plain lists: vertices, faces, volume (area in 2-D), area."""
    hull = convex_hull(points)
    return {"dim": hull.dim, "vertices": hull.vertices.tolist(), "faces": hull.faces.tolist(),
            "volume": hull.volume, "area": hull.area}


def describe_decomposition(polygon) -> dict:
    """A simple polygon (n, 2) split into convex pieces (index lists), with its triangulation and counts."""
    poly = as_float_array(polygon, "polygon", shape=(None, 2), min_rows=3)
    pieces = decompose_polygon(poly)
    triangles = triangulate_polygon(poly)
    return {"vertices": int(len(poly)), "convex": is_convex(poly), "triangles": triangles.tolist(),
            "pieces": [p.tolist() for p in pieces]}
