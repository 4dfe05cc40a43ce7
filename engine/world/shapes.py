"""The shapes a ``World`` holds: four convex bodies and two grounds (DESIGN.md section 3).

Every body is stored the same way: a pose (``center`` (3,), ``rotation`` (3, 3)) and a convex *core* given by
local points (m, 3) — world = center + rotation @ local — swept by a ball of ``radius`` (Ericson 4.5, "sphere
swept volumes"): a sphere is one point swept by r, a capsule a segment swept by r, a box its 8 corners (r = 0),
a convex polyhedron the vertices of its hull (r = 0). The narrow phase (GJK on the world points + radii) then
treats every pair alike; the cheaper exact tests (sphere–sphere, sphere–box, box–box SAT, sphere–capsule) use
the same data.

Rotation (``Box``, ``move``): a 3x3 matrix whose COLUMNS are the body's axes in the world (orthonormal with
determinant +1, to 1e-9), a unit quaternion in (w, x, y, z) order (scalar first, as MuJoCo; scipy's
``Rotation.as_quat()`` is (x, y, z, w) unless ``scalar_first=True``), or a ``scipy.spatial.transform.Rotation``.
An unnormalised quaternion is rejected (ValueError naming ``rotation`` and the expected order), not silently
normalised: a quaternion of norm 2 is almost always a bug in the caller's integrator. Note that ``engine.OBB``
stores the axes as ROWS: ``OBB(c, rotation.T, half)``.

Grounds fill the half-space below a height, the chapter's "sol plat" (``Plane(altitude)``: y <= a) and "Sol
courbe" (``HeightCurve(f)``: y <= f(x), extruded along z). They never move and do not enter the broad phase.
"""
from __future__ import annotations

import numpy as np

from engine._validate import as_float, as_float_array, as_half_extents, as_positive
from engine.bounding.aabb import ROTATION_TOL, as_rotation_matrix
from engine.bounding.hull import convex_hull

__all__ = ["Shape", "Sphere", "Box", "Capsule", "ConvexPolyhedron", "Plane", "HeightCurve",
           "as_rotation_matrix", "as_rotation", "SPHERE", "BOX", "CAPSULE", "HULL", "PLANE", "CURVE", "KIND_NAMES"]

# shape kinds: the row and column labels of the dispatch table (engine/world/dispatch.py)
SPHERE, BOX, CAPSULE, HULL, PLANE, CURVE = range(6)
KIND_NAMES = ("sphere", "box", "capsule", "hull", "plane", "curve")

def as_rotation(rotation, name: str = "rotation") -> np.ndarray:
    """A proper rotation matrix (3, 3) (columns = the body's axes) from None (identity), a 3x3 matrix, a unit
    quaternion (w, x, y, z) or a scipy Rotation; ValueError naming ``name`` (and, for a quaternion, its order)."""
    if hasattr(rotation, "as_matrix") and not isinstance(rotation, np.ndarray):  # scipy Rotation
        rotation = np.asarray(rotation.as_matrix(), dtype=float)
        if rotation.shape != (3, 3):
            raise ValueError(f"{name} must be a single rotation, got a Rotation of {rotation.shape[0]}")
    if rotation is not None and np.shape(rotation) == (4,):
        q = as_float_array(rotation, name, shape=(4,))
        norm = float(np.sqrt(q @ q))
        if abs(norm - 1.0) > ROTATION_TOL:
            raise ValueError(f"{name} must be a unit quaternion in (w, x, y, z) order, got |q| = {norm!r} "
                             f"(normalise it first)")
    return as_rotation_matrix(rotation, name)


def _vec3(value, name):
    return as_float_array(value, name, shape=(3,))


class Shape:
    """Base class: ``kind`` (a code of the dispatch table), pose ``center``/``rotation``, core ``local`` points
    (m, 3) and sweep ``radius``."""

    kind: int = -1
    radius: float = 0.0
    center: np.ndarray
    rotation: np.ndarray
    local: np.ndarray

    def world_points(self) -> np.ndarray:
        """The core's points in world coordinates, (m, 3)."""
        return self.center + self.local @ self.rotation.T

    def __repr__(self) -> str:
        return f"{type(self).__name__}(center={self.center.tolist()}, radius={self.radius})"


class Sphere(Shape):
    """``Sphere(center (3,), radius > 0)``."""

    kind = SPHERE

    def __init__(self, center, radius):
        self.center = _vec3(center, "center")
        self.radius = as_positive(radius, "radius")
        self.rotation = np.eye(3)
        self.local = np.zeros((1, 3))


class Box(Shape):
    """``Box(center (3,), half_extents (3,) > 0, rotation=None)``: an oriented box (OBB); rotation a 3x3 matrix
    whose columns are the box axes, a unit quaternion (w, x, y, z) or a scipy Rotation."""

    kind = BOX

    def __init__(self, center, half_extents, rotation=None):
        self.center = _vec3(center, "center")
        half = as_half_extents(half_extents, "half_extents")
        self.half_extents = half
        self.rotation = as_rotation(rotation)
        signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=float)
        self.local = signs * half


class Capsule(Shape):
    """``Capsule(p0 (3,), p1 (3,), radius > 0)``: the segment p0–p1 swept by a ball; its center is the midpoint
    and its rotation starts as the identity (``move`` turns the segment about the center)."""

    kind = CAPSULE

    def __init__(self, p0, p1, radius):
        a = _vec3(p0, "p0")
        b = _vec3(p1, "p1")
        self.radius = as_positive(radius, "radius")
        self.center = 0.5 * (a + b)
        self.rotation = np.eye(3)
        self.local = np.stack([a - self.center, b - self.center])


class ConvexPolyhedron(Shape):
    """``ConvexPolyhedron(points (n, 3))``: the convex hull of the points (engine.convex_hull, quickhull), which
    must have a volume (>= 4 points, not coplanar). Its center is the mean of the hull vertices."""

    kind = HULL

    def __init__(self, points):
        pts = as_float_array(points, "points", shape=(None, 3), min_rows=4)
        try:
            hull = convex_hull(pts)
        except ValueError as exc:
            raise ValueError(f"points must span a volume: {exc}") from None
        if not hull.volume > 0.0:
            raise ValueError("points must span a volume (they are coplanar)")
        verts = pts[np.sort(hull.vertices)]
        self.center = verts.mean(axis=0)
        self.rotation = np.eye(3)
        self.local = verts - self.center


class Plane(Shape):
    """``Plane(altitude=0.0)``: the flat ground, solid below y = altitude (slide "sol plat")."""

    kind = PLANE

    def __init__(self, altitude=0.0):
        self.altitude = as_float(altitude, "altitude")

    def height(self, x) -> np.ndarray:
        return np.full(np.shape(x), self.altitude)

    def __repr__(self) -> str:
        return f"Plane(altitude={self.altitude})"


class HeightCurve(Shape):
    """``HeightCurve(f, *, samples=64)``: the curved ground, solid below y = f(x) (slide "Sol courbe"), extruded
    along z. ``f`` is a vectorised callable (numpy array -> array of the same shape), continuous; ``samples``
    is the number of points per body on which the narrow test samples the body's lower boundary (then refined
    around the lowest one by golden-section search: ``dispatch.ground_gap``)."""

    kind = CURVE

    def __init__(self, f, *, samples: int = 64):
        if not callable(f):
            raise TypeError(f"f must be a callable y = f(x), got {type(f).__name__}")
        if isinstance(samples, bool) or not isinstance(samples, int | np.integer) or samples < 8:
            raise ValueError(f"samples must be an int >= 8, got {samples!r}")
        probe = np.asarray(f(np.linspace(-1.0, 1.0, 3)), dtype=float)
        if probe.shape != (3,):
            raise ValueError(f"f must be vectorised (array in, same-shape array out), got shape {probe.shape}")
        self.f = f
        self.samples = int(samples)

    def height(self, x) -> np.ndarray:
        y = np.asarray(self.f(np.asarray(x, dtype=float)), dtype=float)
        if not np.isfinite(y).all():
            raise ValueError("f returned a non-finite height")
        return y

    def slope(self, x) -> np.ndarray:
        """f'(x) by a central difference."""
        x = np.asarray(x, dtype=float)
        h = 1e-6 * np.maximum(1.0, np.abs(x))
        return (self.height(x + h) - self.height(x - h)) / (2 * h)

    def __repr__(self) -> str:
        return f"HeightCurve({getattr(self.f, '__name__', 'f')})"
