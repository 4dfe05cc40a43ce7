"""The collision pipeline over bodies of mixed shapes, as a game declares them.

``engine.world.kinds`` (the registry of shape kinds), ``engine.world.shapes`` (Sphere, Box, Capsule, ConvexPolyhedron,
Compound, Plane, HeightCurve, TriangleMesh, HeightField, each with its kind's entry), ``engine.world.bodies`` (the
structure-of-arrays body store and the compiled pose upload), ``engine.world.broad`` (the broad phases kept across
frames: the moving bodies', the static bodies'), ``engine.world.filters`` (categories, masks, groups, exclusions,
sensors), ``engine.world.dispatch`` (the dispatch machinery: shape kind × shape kind × question → kernel) and
``engine.world.rows`` (its rows), ``engine.world.world`` (World: the frame, with per-stage counters and times, and its
events), ``engine.world.shape_queries`` (a box or a shape against the world: ``query_aabb``, ``overlap``,
``cast_shape`` and its ``ShapeHit``), ``engine.world.ray_rows`` (the ray table: one row per kind) and
``engine.world.ray_cast`` (a batch of rays through the world's trees and grid: ``RayHits``, ``RayHit``).
"""
from __future__ import annotations

from engine.narrowphase.contacts import ContactSet, describe_point_id

from . import shapes
from .dispatch import QUESTIONS, UnsupportedQuery
from .filters import ALL
from .kinds import KINDS
from .ray_cast import RayHit, RayHits
from .rows import TABLE
from .shape_queries import ShapeHit
from .shapes import *  # noqa: F403 (the shape classes: shapes.__all__)
from .world import ImpactSet, World, WorldStats

__all__ = [*shapes.__all__, "World", "ContactSet", "ImpactSet", "RayHits", "RayHit", "ShapeHit", "WorldStats", "ALL",
           "KINDS", "TABLE",
           "QUESTIONS", "UnsupportedQuery", "describe_point_id"]
