"""One convex body against one triangle of a static surface (engine.narrowphase.triangle_mesh): what every
per-triangle kernel writes (``TriangleContact``), the bundle the mesh's pair kernels read back and merge.
"""
from __future__ import annotations

from collections import namedtuple

import numpy as np

__all__ = ["TriangleContact", "triangle_contact", "MAX_TRIANGLE_POINTS"]

#: the most candidate points one body–triangle contact writes (a box face clipped by a triangle: up to 7)
MAX_TRIANGLE_POINTS = 8

#: one body against one triangle, reused from triangle to triangle (no allocation per triangle):
#: ``separation`` (1,) the signed distance (< 0: penetration depth; > 0 apart: the distance, or a lower bound of it
#: for the SAT kernels); ``normal`` (3,) unit, from the body towards the triangle (translating the triangle by
#: depth · normal separates them), before the active-edge fix; ``tri_feature`` (2,) int64: the triangle's feature
#: that touches, (type, local index) — type contacts.VERTEX (corner v), EDGE (edge e joins corners e and
#: (e + 1) % 3) or FACE (index 0); ``body_feature`` (1,) int64: the body's feature code (contacts.VERTEX, EDGE,
#: FACE); ``count`` (1,) int64 points; ``points`` (MAX_TRIANGLE_POINTS, 3) contact points, ``depths`` (…,) their
#: penetration along the normal (>= 0), ``body_keys`` (…,) int64 the body's feature key of each point
#: (contacts.feature_key), ``tri_keys`` (…,) int64 the triangle's, with the local index (the pair kernel turns it
#: into the surface's numbering)
TriangleContact = namedtuple("TriangleContact", "separation normal tri_feature body_feature count points depths "
                                                "body_keys tri_keys")


def triangle_contact() -> TriangleContact:
    """A fresh, empty ``TriangleContact``."""
    m = MAX_TRIANGLE_POINTS
    return TriangleContact(np.full(1, np.inf), np.zeros(3), np.zeros(2, np.int64), np.zeros(1, np.int64),
                           np.zeros(1, np.int64), np.zeros((m, 3)), np.zeros(m), np.zeros(m, np.int64),
                           np.zeros(m, np.int64))
