"""Bounding volumes (chapter: "Volumes englobants"): sphere, AABB, OBB, k-DOP, convex hull, decomposition.

Each volume has a fit from points, an overlap test, merge / contains, and an update under rotation and
translation; batched forms take stacked arrays and run in one compiled call.

How to pick (cheapest first): spheres (4 numbers, rotation-free update, loose on elongated objects) — AABBs
(6 numbers, the broad phase's native volume, must be re-fitted after a rotation) — k-DOPs (k numbers, tighter
than AABBs at a few more interval tests) — OBBs (15 numbers, tight on elongated objects, SAT test) — the convex
hull (exact for convex objects, the narrow phase's input) — a convex decomposition for concave objects.
"""
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
]
