"""The ray table: for every shape kind, how a ray meets one body of that kind — the rows the ray traversals of
engine/world/ray_cast.py call at each body they reach.

A row is a ``RayRow``: ``hit(rb, b, o, d, t_max) -> (t, nx, ny, nz, part)``, compiled, for the body in store row
b (``rb``: the ``ray_bodies`` tuple of the store's arrays), the ray o + t·d (3-tuples, d unit) and t in
[0, t_max]: t = inf for a miss, else the distance to the first point of the closed solid and the outward unit
normal there (a ray starting inside: t = 0, normal −d), ``part`` the compound's part hit or the surface's triangle
hit (0 otherwise). A kind whose
shape lives in Python (a ``HeightCurve``'s f) has ``hit = None`` and a ``host(shape, origins, directions, t_max)
-> (t (k,), normals (k, 3))`` answering a batch, run after the compiled pass.

The exact kernels are in engine/narrowphase/ (ray_sphere, ray_box, ray_capsule, ray_halfspace, ray_hull); a
``Compound`` asks its parts' rows and keeps the nearest.

The static triangle surfaces (``TriangleMesh``, ``HeightField``) are bounded static bodies, reached by the walks of
the static tree like any other; their triangles are not in the store (it keeps only the 8 corners of their AABB),
so ``rb`` carries them too: ``rb[11]`` ``surface_of`` (cap,) int64, a surface body's index in ``rb[12]`` (−1 for
the other rows), and ``rb[12]`` the world's surfaces side by side (engine.narrowphase.ray_mesh.SurfaceSet). Their
row is compiled like the others: the nearest triangle by the surface's BVH or its heightfield's cells, each by the
watertight ray–triangle test (engine/narrowphase/ray_triangle.py), ``part`` the triangle hit (its index in the
surface's ``triangles``). A surface is a two-sided shell, not a solid: a ray meets it only where it crosses a
triangle (t = 0 for an origin on one), with the triangle's normal turned against the ray.

``ray_hit`` is the table compiled into one function: a chain of ``if kind == code`` links built from the rows, one
per kind — a new kind adds a row, not a branch.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from engine._config import njit
from engine.narrowphase.ray_box import ray_box
from engine.narrowphase.ray_capsule import ray_capsule
from engine.narrowphase.ray_curve import ray_curve_batch
from engine.narrowphase.ray_halfspace import ray_halfspace
from engine.narrowphase.ray_hull import ray_hull
from engine.narrowphase.ray_mesh import SurfaceSet, ray_surface, surface_set
from engine.narrowphase.ray_sphere import ray_sphere

from .kinds import KINDS, ShapeKind
from .shapes import BOX, CAPSULE, COMPOUND, CURVE, FIELD, HULL, MESH, PLANE, SPHERE

__all__ = ["RayRow", "RAY_ROWS", "SURFACE_KINDS", "ray_bodies", "ray_surfaces", "ray_hit"]


@dataclass(frozen=True, eq=False)
class RayRow:
    """How a ray meets a body of one kind (see the module docstring): ``hit`` compiled, or ``host`` for a batch."""

    name: str
    hit: Callable | None = None
    host: Callable | None = None


#: the kinds whose rows read a surface of ``rb[12]`` (their shapes carry ``mesh``, a MeshArrays)
SURFACE_KINDS = (MESH, FIELD)


def ray_surfaces(ids, meshes, capacity: int, kept: SurfaceSet | None = None) -> tuple:
    """(surface_of (capacity,) int64, SurfaceSet) of the surface bodies ``ids`` (k,) with their ``meshes`` (k
    MeshArrays, in the order of ``ids``): row ids[s] → s, −1 elsewhere; ``kept``, when given, is the SurfaceSet of
    these same meshes built before (it is reused, not built again)."""
    surface_of = np.full(capacity, -1, np.int64)
    surface_of[np.asarray(ids, np.int64)] = np.arange(len(meshes), dtype=np.int64)
    return surface_of, surface_set(meshes) if kept is None else kept


def ray_bodies(bodies, surfaces: tuple | None = None) -> tuple:
    """The store's arrays the rows read (engine.world.bodies.BodyArrays → a plain tuple, for the compiled code):
    (kind, center, rotation, radius, half, points, planes, n_planes, first_part, next_part, part, surface_of,
    surfaces) — the last two from ``ray_surfaces`` (none when ``surfaces`` is None; the module docstring)."""
    if surfaces is None:
        surfaces = ray_surfaces(np.empty(0, np.int64), [], bodies.kind.shape[0])
    return (bodies.kind, bodies.center, bodies.rotation, bodies.radius, bodies.half, bodies.points, bodies.planes,
            bodies.n_planes, bodies.first_part, bodies.next_part, bodies.part, surfaces[0], surfaces[1])


@njit(inline="always")
def _p3(a, b, v):
    return a[b, v, 0], a[b, v, 1], a[b, v, 2]


@njit(inline="always")
def _v3(a, b):
    return a[b, 0], a[b, 1], a[b, 2]


@njit(inline="always")
def _with_part(hit, part):
    return hit[0], hit[1], hit[2], hit[3], part


@njit(inline="always")
def _sphere(rb, b, o, d, t_max):
    return _with_part(ray_sphere(o, d, t_max, _p3(rb[5], b, 0), rb[3][b]), 0)


@njit(inline="always")
def _box(rb, b, o, d, t_max):
    return _with_part(ray_box(o, d, t_max, _v3(rb[1], b), rb[2][b], _v3(rb[4], b)), 0)


@njit(inline="always")
def _capsule(rb, b, o, d, t_max):
    return _with_part(ray_capsule(o, d, t_max, _p3(rb[5], b, 0), _p3(rb[5], b, 1), rb[3][b]), 0)


@njit(inline="always")
def _hull(rb, b, o, d, t_max):
    return _with_part(ray_hull(o, d, t_max, _v3(rb[1], b), rb[2][b], rb[6][b], rb[7][b]), 0)


@njit(inline="always")
def _plane(rb, b, o, d, t_max):
    R = rb[2][b]
    return _with_part(ray_halfspace(o, d, t_max, _v3(rb[1], b), (R[0, 1], R[1, 1], R[2, 1])), 0)


@njit(inline="always")
def _surface(rb, b, o, d, t_max):
    """A triangle surface: its nearest triangle (``ray_surface`` is one compiled call, shared by every walk)."""
    return ray_surface(rb[12], rb[11][b], o, d, t_max)


@njit(inline="always")
def _miss(kind, rb, b, o, d, t_max):
    return np.inf, np.nan, np.nan, np.nan, 0


def _link(code: int, hit, rest):
    """``if kind == code: hit(...) else rest(...)``: one link of the compiled table."""
    @njit(inline="always")
    def link(kind, rb, b, o, d, t_max):
        if kind == code:
            return hit(rb, b, o, d, t_max)
        return rest(kind, rb, b, o, d, t_max)
    return link


def _chain(rows: dict) -> Callable:
    """The rows with a compiled ``hit`` as one function ``(kind, rb, b, o, d, t_max)``; other kinds miss."""
    chain = _miss
    for kind, row in rows.items():
        if row.hit is not None:
            chain = _link(kind.code, row.hit, chain)
    return chain


#: the convex kinds' rows: what a compound's parts are
_PART_ROWS: dict[ShapeKind, RayRow] = {
    SPHERE: RayRow("sphere: the stable quadratic", _sphere),
    BOX: RayRow("box: slabs in the box frame", _box),
    CAPSULE: RayRow("capsule: cylinder and end spheres", _capsule),
    HULL: RayRow("hull: clipping by the face planes", _hull),
}
_part_chain = _chain(_PART_ROWS)


@njit
def _part_hit(kind, rb, b, o, d, t_max):
    """A compound's part: one compiled call (not inlined: the walks inline the table at each of their visits, and
    the parts' rows inlined inside it again would double what each walk compiles)."""
    return _part_chain(kind, rb, b, o, d, t_max)


@njit(inline="always")
def _compound(rb, b, o, d, t_max):
    """The nearest part hit (ties: the first part)."""
    best_t, nx, ny, nz, best_part = np.inf, np.nan, np.nan, np.nan, 0
    s = rb[8][b]
    while s >= 0:
        t, mx, my, mz, _ = _part_hit(rb[0][s], rb, s, o, d, min(t_max, best_t))
        if t < best_t:
            best_t, nx, ny, nz, best_part = t, mx, my, mz, rb[10][s]
        s = rb[9][s]
    return best_t, nx, ny, nz, best_part


def _curve_batch(shape, origins, directions, t_max):
    """A HeightCurve's rays: four gap samples per sample of its narrow test along each ray."""
    return ray_curve_batch(shape.height, shape.slope, 4 * shape.samples, origins, directions, t_max)


#: kind → its row (every registered kind has one: properties/test_world_rays.py checks it)
RAY_ROWS: dict[ShapeKind, RayRow] = {
    **_PART_ROWS,
    COMPOUND: RayRow("compound: the nearest of its parts", _compound),
    PLANE: RayRow("plane: the half-space below it", _plane),
    CURVE: RayRow("curve: sampling and bisection of the height gap", host=_curve_batch),
    MESH: RayRow("mesh: its BVH, each triangle by the watertight test", _surface),
    FIELD: RayRow("field: its cells on the ray's path, each triangle by the watertight test", _surface),
}
assert all(kind in RAY_ROWS for kind in KINDS), "every shape kind needs its row in the ray table"

#: the table compiled: ``ray_hit(kind, rb, b, o, d, t_max) -> (t, nx, ny, nz, part)``, inlined into the walks
ray_hit = _chain(RAY_ROWS)
