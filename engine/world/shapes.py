"""The shapes a ``World`` holds: four convex bodies and two grounds.

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

from engine._validate import as_float, as_float_array, as_half_extents, as_positive, check_callable
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
    """Base class of the shapes a ``World`` holds: a pose and a convex core swept by a ball.

    Every body is stored alike — world points = ``center + rotation @ local`` — so the narrow phase treats every
    pair the same way (GJK on the world points plus the radii), and the closed-form tests read the same data.

    Attributes
    ----------
    kind : int
        The shape's row and column in the dispatch tables (``KIND_NAMES[kind]`` is its name).
    center : numpy.ndarray, shape (3,), float64
        The pose's position.
    rotation : numpy.ndarray, shape (3, 3), float64
        The pose's rotation; its columns are the body's axes in the world.
    local : numpy.ndarray, shape (m, 3), float64
        The core's points in the body frame.
    radius : float
        The radius of the ball that sweeps the core, >= 0 (0 for a polyhedron).
    """

    kind: int = -1
    radius: float = 0.0
    center: np.ndarray
    rotation: np.ndarray
    local: np.ndarray

    def world_points(self) -> np.ndarray:
        """The core's points in world coordinates.

        Returns
        -------
        numpy.ndarray, shape (m, 3), float64
            ``center + local @ rotation.T``, a new array.
        """
        return self.center + self.local @ self.rotation.T

    def __repr__(self) -> str:
        return f"{type(self).__name__}(center={self.center.tolist()}, radius={self.radius})"


class Sphere(Shape):
    """A sphere: one point swept by a ball (the attributes of ``Shape``).

    Parameters
    ----------
    center : array_like, shape (3,)
        Its centre, finite.
    radius : float
        Its radius, > 0.

    Raises
    ------
    ValueError
        For a centre not of shape (3,), NaN or ±inf, or a radius <= 0.
    """

    kind = SPHERE

    def __init__(self, center, radius):
        self.center = _vec3(center, "center")
        self.radius = as_positive(radius, "radius")
        self.rotation = np.eye(3)
        self.local = np.zeros((1, 3))


class Box(Shape):
    """An oriented box (OBB): its 8 corners, unswept (``radius`` 0).

    Parameters
    ----------
    center : array_like, shape (3,)
        Its centre.
    half_extents : array_like, shape (3,)
        Half its size along each of its axes, > 0.
    rotation : array_like or scipy.spatial.transform.Rotation, optional
        A (3, 3) proper rotation matrix whose columns are the box axes in the world, a unit quaternion (4,) in
        (w, x, y, z) order, or a scipy Rotation; default the identity.

    Attributes
    ----------
    half_extents : numpy.ndarray, shape (3,), float64
        As given; the other attributes are those of ``Shape``.

    Raises
    ------
    ValueError
        For a half extent <= 0 (named with its index), an improper or non-orthonormal matrix, or a quaternion that
        is not of unit norm (it is refused, not normalised).
    """

    kind = BOX

    def __init__(self, center, half_extents, rotation=None):
        self.center = _vec3(center, "center")
        half = as_half_extents(half_extents, "half_extents")
        self.half_extents = half
        self.rotation = as_rotation(rotation)
        signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=float)
        self.local = signs * half


class Capsule(Shape):
    """A capsule: the segment p0–p1 swept by a ball of ``radius``.

    Its ``center`` is the segment's midpoint and its rotation starts as the identity (``World.move`` turns the
    segment about the centre).

    Parameters
    ----------
    p0, p1 : array_like, shape (3,)
        The ends of the axis segment.
    radius : float
        > 0.

    Raises
    ------
    ValueError
        For a non-finite end, or ``radius <= 0``.
    """

    kind = CAPSULE

    def __init__(self, p0, p1, radius):
        a = _vec3(p0, "p0")
        b = _vec3(p1, "p1")
        self.radius = as_positive(radius, "radius")
        self.center = 0.5 * (a + b)
        self.rotation = np.eye(3)
        self.local = np.stack([a - self.center, b - self.center])


class ConvexPolyhedron(Shape):
    """The convex hull of a point set (the engine's quickhull, ``engine.convex_hull``).

    The core keeps the hull's vertices only, centred on their mean (``center``); the rotation starts as the
    identity.

    Parameters
    ----------
    points : array_like, shape (n, 3), float64
        n >= 4 points spanning a volume (not coplanar); interior points are dropped.

    Raises
    ------
    ValueError
        For fewer than 4 points, NaN or ±inf, or points that span no volume.
    """

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
    """The flat ground, solid below y = altitude (slide "sol plat"); it never moves and takes no part in the broad
    phase.

    Parameters
    ----------
    altitude : float, default 0.0
        The ground's height.

    Attributes
    ----------
    altitude : float
        As given.
    """

    kind = PLANE

    def __init__(self, altitude=0.0):
        self.altitude = as_float(altitude, "altitude")

    def height(self, x) -> np.ndarray:
        """The ground's height at x: the altitude everywhere.

        Parameters
        ----------
        x : float or array_like
            Where to evaluate.

        Returns
        -------
        numpy.ndarray, float64
            ``altitude`` in an array of the shape of x.
        """
        return np.full(np.shape(x), self.altitude)

    def __repr__(self) -> str:
        return f"Plane(altitude={self.altitude})"


class HeightCurve(Shape):
    """The curved ground, solid below y = f(x) (slide "Sol courbe"), extruded along z; it never moves.

    The narrow test samples each body's lower boundary at ``samples`` abscissae and refines the lowest gap by
    golden-section search (``engine.world.dispatch.ground_gap``).

    Parameters
    ----------
    f : callable
        Vectorised and continuous: ``f(x)`` for a float64 array returns finite heights of x's shape.
    samples : int, default 64
        Samples per body, >= 8.

    Attributes
    ----------
    f : callable
        The height function.
    samples : int
        As given.

    Raises
    ------
    TypeError
        When ``f`` is not callable.
    ValueError
        For ``samples`` below 8, or an ``f`` that is not vectorised (probed on three points).
    """

    kind = CURVE

    def __init__(self, f, *, samples: int = 64):
        check_callable(f, "f", "a callable y = f(x)")
        if isinstance(samples, bool) or not isinstance(samples, int | np.integer) or samples < 8:
            raise ValueError(f"samples must be an int >= 8, got {samples!r}")
        probe = np.asarray(f(np.linspace(-1.0, 1.0, 3)), dtype=float)
        if probe.shape != (3,):
            raise ValueError(f"f must be vectorised (array in, same-shape array out), got shape {probe.shape}")
        self.f = f
        self.samples = int(samples)

    def height(self, x) -> np.ndarray:
        """The ground's height f(x), checked.

        Parameters
        ----------
        x : array_like
            Abscissae, any shape.

        Returns
        -------
        numpy.ndarray, the shape of x, float64

        Raises
        ------
        ValueError
            When f returns a non-finite height.
        """
        y = np.asarray(self.f(np.asarray(x, dtype=float)), dtype=float)
        if not np.isfinite(y).all():
            raise ValueError("f returned a non-finite height")
        return y

    def slope(self, x) -> np.ndarray:
        """The slope f'(x), by a central difference of step ``h = 1e-6·max(1, |x|)``.

        Parameters
        ----------
        x : float or array_like
            The abscissae, of any shape.

        Returns
        -------
        numpy.ndarray, float64
            ``(f(x + h) − f(x − h)) / 2h``, of the shape of x.
        """
        x = np.asarray(x, dtype=float)
        h = 1e-6 * np.maximum(1.0, np.abs(x))
        return (self.height(x + h) - self.height(x - h)) / (2 * h)

    def __repr__(self) -> str:
        return f"HeightCurve({getattr(self.f, '__name__', 'f')})"
