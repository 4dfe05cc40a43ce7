"""The collision pipeline over bodies of mixed shapes: shapes, the narrow-phase dispatch table, ``World``.

``engine.world.shapes`` (Sphere, Box, Capsule, ConvexPolyhedron, Plane, HeightCurve), ``engine.world.dispatch``
(shape kind × shape kind → batched exact test), ``engine.world.world`` (World: broad phase → narrow phase →
contacts / time of impact, with per-stage counters), ``engine.world.demo`` (``collide demo``).
"""
from __future__ import annotations

from .dispatch import NARROW_TESTS
from .shapes import Box, Capsule, ConvexPolyhedron, HeightCurve, Plane, Shape, Sphere
from .world import ContactSet, ImpactSet, World, WorldStats

__all__ = ["Sphere", "Box", "Capsule", "ConvexPolyhedron", "Plane", "HeightCurve", "Shape", "World",
           "ContactSet", "ImpactSet", "WorldStats", "NARROW_TESTS"]
