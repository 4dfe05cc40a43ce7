"""Narrow phase (chapter: "Pipeline de détection de collisions" — the precise test, then the instant and place of
contact): separating axes, GJK distance, EPA penetration, primitive tests, contact features and time of impact.

Every test has a single-pair form and a batched form over arrays of pairs in one compiled call.

.. _batched-pairs:

Batched pairs
-------------
A ``*_batch`` function (``overlap_sphere_sphere_batch``, ``overlap_sphere_obb_batch``, ...) takes per-shape arrays
of the A shapes (n rows) and of the B shapes (m rows), and answers k pairs in one compiled call:

- without index arrays (``index_a = index_b = None``), pair p is row p of A against row p of B: n == m == k;
- with ``index_a``, ``index_b`` (k,) integer array_like (given together), pair p is row ``index_a[p]`` of A
  against row ``index_b[p]`` of B — the form a dispatch table (shape kind × shape kind → batched test) calls.

Radii are (n,) or a scalar standing for n equal radii, >= 0. The answer is a fresh (k,) bool ndarray, True where
the closed shapes meet (touching counts). Errors are raised before any kernel runs: ``ValueError`` naming the
argument (and the first bad index) for NaN or ±inf, a negative radius, ``lo > hi``, a wrong shape, A and B of
different lengths without index arrays, only one index array, or an index out of range; ``TypeError`` for
non-numeric arrays or non-integer indices.

.. _packed-point-sets:

Packed point sets
-----------------
The ``*_pairs`` functions (``gjk_distance_pairs``, ``epa_penetration_pairs``, ``contact_feature_pairs``,
``time_of_impact_pairs``, ``overlap_convex_sat_pairs``) take S convex shapes at once, each the convex hull of its
vertices:

- ``points`` : (N, 3) float64 array_like, every shape's vertices one after the other, finite;
- ``offsets`` : (S + 1,) integer array_like, strictly increasing from 0 to N: shape s owns
  ``points[offsets[s]:offsets[s + 1]]`` (at least one point); ``pack_point_sets`` builds both from a list;
- ``pairs`` : (k, 2) integer array_like, rows (shape_a, shape_b) of shape indices in [0, S).

The answers are arrays of k rows, row p for ``pairs[p]``. ``ValueError`` names the argument and the first bad
row (NaN or ±inf in ``points``, offsets not increasing or not ending at N, a shape index out of range);
``TypeError`` is raised for non-integer ``offsets`` or ``pairs``.

The kernel layer
----------------
The public functions above validate their arguments (engine._validate) and call compiled kernels, which other
modules (engine.world's compiled frame, for one) may call directly, without going through ``_`` names. Arrays are
float64 C-contiguous unless said otherwise, index arrays int64; a kernel never allocates in its per-pair loop (the
scratch bundles are allocated once per call, each by one function).

================================  ================================================================================
module: kernels                   what they compute (shapes)
================================  ================================================================================
``status``                        the one numbering of kernel outcomes — SEPARATED, OVERLAP, GJK_NOT_CONVERGED,
                                  INVALID_INPUT, EPA_NOT_CONVERGED, TOI_NOT_CONVERGED — and ``raise_for_status``
                                  (GJKNotConverged, EPANotConverged, TOINotConverged derive from NotConverged)
``support``: ``support_index``,   the support mapping s(d) of points (n, 3); of coordinate rows S[row:row + 3]
``support_index_rows``,           (x, y, z rows of n points); of M = A − B: (ia, ib, w)
``support_minkowski``
``rescale``: ``rescale_unit``,    the power of two that brings a tiny or huge pair into [2^-160, 2^160]
``largest_coordinate``
``simplex``: ``closest_on_*``     GJK's sub-algorithm: closest point of a segment / triangle / tetrahedron to the
                                  origin (scalars in: the vertices; out: supporting vertices and weights)
``gjk``: ``gjk_scratch``,         ``GJKScratch`` (W (4, 3), IA, IB (4,), lam (4,), S (8, n), status (1,), the
``gjk_pairs_kernel``,             empty pair list no_pairs (0, 2), no_offsets (1,)); GJK on k pairs, shapes
``gjk_kernel``                    addressed by row ranges of (S, N, 3) arrays (packed with a pair list, or
                                  aligned), or on one pair pa (n, 3), pb (m, 3) (out (7,): closest points,
                                  distance)
``epa``: ``epa_polytope``,        ``Polytope`` (EPA's mesh and flood-fill scratch, the layout of
``epa_kernel``,                   engine.bounding.horizon); EPA from GJK's simplex: out (10,) depth, normal,
``trace_epa``                     witness points; the polytope of every iteration (``EPAStep``), for pictures
``touching_normal``:              the normal of hulls touching at a point p: a direction of M's normal cone
``touching_normal_at_vertex``
``penetration``:                  the chain GJK → EPA → rescale for one pair (out (10,): signed distance, normal,
``penetration_kernel``,           points on A and B) and k packed pairs; ``penetration_pairs`` adds the exact
``penetration_pairs_kernel``,     Qhull fallback (``minkowski_fallback``) and raises for unsolved pairs
``penetration_pairs``
``features``: ``plane_basis``,    the contact plane's frame (2, 3); a shape's support set projected on it (m, 2);
``support_set``,                  its reduction to a vertex, an edge or a counter-clockwise polygon
``feature_polygon``
``clipping``: ``clip_polygon``,   Sutherland–Hodgman, Cyrus–Beck, crossing / overlap of two edges, flat-vertex
``clip_segment``,                 removal, on (n, 2) polygons
``closest_segments_2d``,
``drop_flat_vertices``
``contact_manifold``:             ``FeatureScratch``; the contact features and points of one pair given its normal
``feature_scratch``,              and closest points, and of k packed pairs
``contact_points``,
``contact_points_pairs``
``motion``: ``pose_at``           the vertices (n, 3) of a body moving with constant v, ω at time t
``time_of_impact``:               conservative advancement on one pair / k packed pairs (times (k,), status (k,))
``toi_kernel``,
``toi_pairs_kernel``
``ray_sphere``, ``ray_box``,      the first hit (t, nx, ny, nz) of a ray o + t d (3-tuples, d unit, t in
``ray_capsule``,                  [0, tmax]) with a closed solid sphere, oriented box, capsule, half-space, convex
``ray_halfspace``, ``ray_hull``   polyhedron given by planes (F, 4) (``hull_planes`` of a point set); (0, −d) from
                                  inside, (inf, nan, nan, nan) for a miss
``triangle_mesh``:                a static triangle surface as arrays (world vertices (nv, 3), triangles (nt, 3),
``MeshArrays``,                   face normals, active edges (nt, 3), a BVH or a heightfield's grid); the triangles
``candidate_triangles``           whose boxes meet a box, ascending
``triangle_contact``:             one round core (a sphere's point, a capsule's segment) against one triangle:
``round_core_answer``,            closest points, the triangle's feature, a ``TriangleContact`` (Ericson 5.1.5,
``round_core_triangle``           5.1.10)
``box_triangle``                  the 13-axis SAT of a box and a triangle, exact depth, clipped manifold (5.2.9)
``mesh_contact``:                 convex bodies against one surface, batched: overlap, contact (the active-edge
``mesh_contact_rows``, ...        fix, one merged manifold per body), distance, time of impact
``ray_triangle``, ``ray_mesh``    the watertight ray–triangle test (Woop, Benthin, Wald 2013); the nearest
                                  triangle of a surface along a ray (BVH, heightfield cells)
================================  ================================================================================
"""
from __future__ import annotations

from .contact_manifold import Contact, ContactBatch, contact_feature, contact_feature_pairs
from .gjk import gjk_distance, gjk_distance_batch, gjk_distance_pairs, pack_point_sets
from .penetration import epa_penetration, epa_penetration_pairs
from .primitives import (
    distance_point_segment,
    max_on_intervals,
    min_distance_to_curve,
    overlap_aabb_aabb,
    overlap_aabb_aabb_batch,
    overlap_aabb_curve,
    overlap_aabb_curve_bottom_middle,
    overlap_aabb_ground,
    overlap_aabb_ground_batch,
    overlap_circle_curve,
    overlap_circle_segment,
    overlap_circle_segment_batch,
    overlap_sphere_aabb,
    overlap_sphere_aabb_batch,
    overlap_sphere_capsule,
    overlap_sphere_capsule_batch,
    overlap_sphere_ground_batch,
    overlap_sphere_obb,
    overlap_sphere_obb_batch,
    overlap_sphere_sphere,
    overlap_sphere_sphere_batch,
)
from .ray_box import ray_box
from .ray_capsule import ray_capsule
from .ray_halfspace import ray_halfspace
from .ray_hull import hull_planes, ray_hull
from .ray_sphere import ray_sphere
from .sat import obb_overlap, overlap_convex_sat, overlap_convex_sat_pairs, overlap_obb_obb_batch
from .status import EPANotConverged, GJKNotConverged, TOINotConverged
from .time_of_impact import time_of_impact, time_of_impact_pairs

__all__ = [
    "Contact", "ContactBatch", "TOINotConverged", "contact_feature", "contact_feature_pairs", "time_of_impact",
    "time_of_impact_pairs",
    "EPANotConverged", "epa_penetration", "epa_penetration_pairs",
    "GJKNotConverged", "gjk_distance", "gjk_distance_batch", "gjk_distance_pairs", "pack_point_sets",
    "distance_point_segment", "max_on_intervals", "min_distance_to_curve",
    "overlap_aabb_aabb", "overlap_aabb_aabb_batch", "overlap_aabb_curve", "overlap_aabb_curve_bottom_middle",
    "overlap_aabb_ground", "overlap_aabb_ground_batch", "overlap_circle_curve", "overlap_circle_segment",
    "overlap_circle_segment_batch", "overlap_sphere_aabb", "overlap_sphere_aabb_batch", "overlap_sphere_capsule",
    "overlap_sphere_capsule_batch", "overlap_sphere_ground_batch", "overlap_sphere_obb", "overlap_sphere_obb_batch",
    "overlap_sphere_sphere", "overlap_sphere_sphere_batch",
    "obb_overlap", "overlap_convex_sat", "overlap_convex_sat_pairs", "overlap_obb_obb_batch",
    "hull_planes", "ray_box", "ray_capsule", "ray_halfspace", "ray_hull", "ray_sphere",
]
