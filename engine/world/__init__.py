"""The collision pipeline over bodies of mixed shapes: shapes, the body store, the dispatch tables, ``World``.

``engine.world.shapes`` (Sphere, Box, Capsule, ConvexPolyhedron, Plane, HeightCurve), ``engine.world.bodies``
(the structure-of-arrays body store and the compiled pose upload), ``engine.world.broad`` (the broad phase kept
across frames), ``engine.world.dispatch`` (shape kind × shape kind → kernel, for overlap, contact and time of
impact; the compiled narrow phase), ``engine.world.convex`` (the GJK/EPA rows), ``engine.world.curve`` (the
curved-ground rows), ``engine.world.world`` (World: the frame, with per-stage counters and times),
``engine.world.demo`` (``colldet demo``'s simulation, ``DemoScene``) and ``engine.world.demo_plot`` (its
drawing: ``draw``, ``demo_figure``, ``run_demo``).
"""
from __future__ import annotations

from engine.narrowphase.contacts import ContactSet, describe_point_id

from .dispatch import CONTACT_TABLE, IMPACT_TABLE, NARROW_TESTS, OVERLAP_TABLE
from .shapes import Box, Capsule, ConvexPolyhedron, HeightCurve, Plane, Shape, Sphere
from .world import ImpactSet, World, WorldStats

__all__ = ["Sphere", "Box", "Capsule", "ConvexPolyhedron", "Plane", "HeightCurve", "Shape", "World",
           "ContactSet", "ImpactSet", "WorldStats", "NARROW_TESTS", "OVERLAP_TABLE", "CONTACT_TABLE",
           "IMPACT_TABLE", "describe_point_id"]
