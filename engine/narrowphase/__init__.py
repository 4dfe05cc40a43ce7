"""Narrow phase (chapter: "Pipeline de détection de collisions" — the precise test, then the instant and place of
contact): separating axes, GJK distance, EPA penetration, primitive tests, contact features and time of impact.

Every test has a single-pair form and a batched form over arrays of pairs in one compiled call. Batched forms
take either aligned arrays (pair p = row p of A against row p of B) or index arrays ``index_a``, ``index_b`` (k,)
into per-shape arrays — the form a dispatch table (shape kind × shape kind → batched test) calls. Convex point
sets are packed as ``points`` (N, 3) + ``offsets`` (S + 1,) and paired by a (k, 2) ``pairs`` array.
"""
from __future__ import annotations

from .contact import (
    Contact,
    ContactBatch,
    TOINotConverged,
    contact_feature,
    contact_feature_pairs,
    time_of_impact,
    time_of_impact_pairs,
)
from .contact_io import describe_contact, load_shape
from .epa import EPANotConverged, epa_penetration, epa_penetration_pairs
from .gjk import GJKNotConverged, gjk_distance, gjk_distance_batch, gjk_distance_pairs, pack_point_sets
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
from .sat import obb_overlap, overlap_convex_sat, overlap_convex_sat_pairs, overlap_obb_obb_batch

__all__ = [
    "Contact", "ContactBatch", "TOINotConverged", "contact_feature", "contact_feature_pairs", "time_of_impact",
    "time_of_impact_pairs",
    "describe_contact", "load_shape",
    "EPANotConverged", "epa_penetration", "epa_penetration_pairs",
    "GJKNotConverged", "gjk_distance", "gjk_distance_batch", "gjk_distance_pairs", "pack_point_sets",
    "distance_point_segment", "max_on_intervals", "min_distance_to_curve",
    "overlap_aabb_aabb", "overlap_aabb_aabb_batch", "overlap_aabb_curve", "overlap_aabb_curve_bottom_middle",
    "overlap_aabb_ground", "overlap_aabb_ground_batch", "overlap_circle_curve", "overlap_circle_segment",
    "overlap_circle_segment_batch", "overlap_sphere_aabb", "overlap_sphere_aabb_batch", "overlap_sphere_capsule",
    "overlap_sphere_capsule_batch", "overlap_sphere_ground_batch", "overlap_sphere_obb", "overlap_sphere_obb_batch",
    "overlap_sphere_sphere", "overlap_sphere_sphere_batch",
    "obb_overlap", "overlap_convex_sat", "overlap_convex_sat_pairs", "overlap_obb_obb_batch",
]
