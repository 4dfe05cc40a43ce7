"""engine — collision detection for game physics: whether, where and when two objects collide.

The main public names are importable from here; the subpackages hold the rest:
``engine.dynamics`` (falling bodies), ``engine.bounding`` (bounding volumes, hull, decomposition),
``engine.broadphase``, ``engine.narrowphase``, ``engine.gas``, ``engine.world`` (shapes and the pipeline).
engine/ARCHITECTURE.md maps each module to the chapter's slides, its oracle and its property file.
"""
from __future__ import annotations

from .bounding import OBB, ConvexHull, convex_hull, fit_obb, is_convex, min_bounding_sphere
from .broadphase import BROAD_PHASES, DynamicAABBTree, IncrementalSAP, find_pairs, sphere_pairs, sweep_intervals
from .dynamics.bisection import BisectionResult, bisect
from .dynamics.rk4 import rk4_step, split_state, state_vector
from .dynamics.scenes import CubeDrop, FallResult, Impact, drop_cube, drop_particle
from .gas import GasResult, simulate_gas
from .narrowphase import (
    Contact,
    ContactBatch,
    contact_feature,
    contact_feature_pairs,
    epa_penetration,
    gjk_distance,
    obb_overlap,
    overlap_convex_sat_pairs,
    time_of_impact,
)
from .world import (
    ALL,
    Box,
    Capsule,
    Compound,
    ConvexPolyhedron,
    HeightCurve,
    HeightField,
    Plane,
    RayHit,
    RayHits,
    ShapeHit,
    Sphere,
    TriangleMesh,
    World,
)


def _installed_version() -> str:
    """The version of the installed distribution ("colldet"), from its metadata; pyproject.toml sets it."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("colldet")
    except PackageNotFoundError:  # run from a source tree that was never installed
        return "0+unknown"


__version__ = _installed_version()

__all__ = [
    # dynamics: falling bodies, RK4, Algorithme 3
    "rk4_step", "state_vector", "split_state", "bisect", "BisectionResult",
    "drop_particle", "drop_cube", "FallResult", "CubeDrop", "Impact",
    # bounding volumes
    "OBB", "fit_obb", "min_bounding_sphere", "convex_hull", "ConvexHull", "is_convex",
    # broad phase
    "BROAD_PHASES", "find_pairs", "sweep_intervals", "sphere_pairs", "IncrementalSAP", "DynamicAABBTree",
    # narrow phase
    "obb_overlap", "gjk_distance", "epa_penetration", "contact_feature", "Contact", "time_of_impact",
    "contact_feature_pairs", "ContactBatch", "overlap_convex_sat_pairs",
    # the confined gas
    "simulate_gas", "GasResult",
    # the collision pipeline: shapes and World
    "Sphere", "Box", "Capsule", "ConvexPolyhedron", "Compound", "Plane", "HeightCurve", "TriangleMesh",
    "HeightField", "World", "ALL",
    "ShapeHit",
    "RayHits",
    "RayHit",
]
