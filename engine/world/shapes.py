"""The shapes a ``World`` holds: four convex bodies, compounds of them, and two grounds — each class with its
kind's registry entry (engine/world/kinds.py), declared once here.

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

A ``Compound`` is one rigid body made of convex parts (each a shape above at a pose in the compound's frame),
such as the pieces of a convex decomposition (``Compound.from_mesh``).

Grounds fill the half-space below a height, the chapter's "sol plat" (``Plane(altitude)``: y <= a) and "Sol
courbe" (``HeightCurve(f)``: y <= f(x), extruded along z). They are static (they never move) and unbounded: they
do not enter the broad phase, their own candidate test picks the bodies that may touch them.

Every class also gives ``example()``, a small instance (the warm-up compiles the dispatch rows with it), and
``random(rng, center, size)``, a random instance about ``center`` of about ``size`` (the tests' strategies).
"""
from __future__ import annotations

import numpy as np

from engine._validate import as_float, as_float_array, as_half_extents, as_positive, check_callable
from engine.bounding.aabb import ROTATION_TOL, as_rotation_matrix
from engine.bounding.decompose import decompose_mesh
from engine.bounding.hull import convex_hull
from engine.narrowphase.curve_ground import curve_candidates
from engine.narrowphase.ray_hull import hull_planes
from engine.narrowphase.triangle_mesh import MeshArrays, heightfield_arrays, mesh_arrays, mesh_box

from .kinds import ShapeKind, shape_kind

__all__ = ["Shape", "Sphere", "Box", "Capsule", "ConvexPolyhedron", "Compound", "Plane", "HeightCurve",
           "TriangleMesh", "HeightField", "as_rotation", "as_rotation_batch", "QUATERNION_ORDER", "SPHERE", "BOX",
           "CAPSULE", "HULL", "COMPOUND", "PLANE", "CURVE", "MESH", "FIELD"]

#: the quaternion convention of every rotation argument, as the error messages say it
QUATERNION_ORDER = "(w, x, y, z)"

_CORNER_SIGNS = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=float)


def _plane_candidates(plane, lo, hi) -> np.ndarray:
    # the contact kernel computes (altitude - centre) + radius, whose round-off can reach 0 where lo = centre -
    # radius is a few ulps above the plane: the candidates take that round-off in, the kernel decides
    slack = 4.0 * np.finfo(float).eps * (abs(plane.altitude) + np.abs(lo[:, 1]) + (hi[:, 1] - lo[:, 1]))
    return lo[:, 1] <= plane.altitude + slack



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
            raise ValueError(f"{name} must be a unit quaternion in {QUATERNION_ORDER} order, got |q| = {norm!r} "
                             f"(normalise it first)")
    return as_rotation_matrix(rotation, name)


def as_rotation_batch(rotations, k: int, name: str = "rotations"):
    """``(mode, array)``: mode 1 with (k, 3, 3) proper rotation matrices, or mode 2 with (k, 4) unit quaternions
    (w, x, y, z); from matrices, quaternions or a scipy Rotation of length k (see the module docstring).
    ValueError naming ``name`` and the first bad index."""
    if hasattr(rotations, "as_matrix") and not isinstance(rotations, np.ndarray):  # scipy Rotation
        mats = np.asarray(rotations.as_matrix(), dtype=float)
        rotations = mats.reshape(1, 3, 3) if mats.shape == (3, 3) else mats
    r = as_float_array(rotations, name, ndim=None)
    if r.shape == (k, 4):
        err = np.abs(np.sqrt((r * r).sum(axis=1)) - 1.0)
        bad = np.flatnonzero(~(err <= ROTATION_TOL))
        if bad.size:
            q = r[bad[0]]
            raise ValueError(f"{name}[{bad[0]}] must be a unit quaternion in {QUATERNION_ORDER} order, got |q| = "
                             f"{float(np.sqrt(q @ q))!r} (normalise it first)")
        return 2, r
    if r.shape == (k, 3, 3):
        gram = np.einsum("kji,kjl->kil", r, r) - np.eye(3)
        err = np.abs(gram).max(axis=(1, 2)) if k else np.zeros(0)
        bad = np.flatnonzero(~(err <= ROTATION_TOL))
        if bad.size:
            raise ValueError(f"{name}[{bad[0]}] must be an orthonormal matrix (columns = the body axes): max "
                             f"|R^T R - I| = {err[bad[0]]:.3g}")
        det = np.linalg.det(r) if k else np.zeros(0)
        bad = np.flatnonzero(det < 0)
        if bad.size:
            raise ValueError(f"{name}[{bad[0]}] must be a proper rotation (det = -1: a reflection)")
        return 1, r
    raise ValueError(f"{name} must have shape ({k}, 3, 3) (rotation matrices, columns = the body axes) or "
                     f"({k}, 4) (unit quaternions in {QUATERNION_ORDER} order), or be a scipy Rotation of length "
                     f"{k}; got shape {r.shape}")


def _vec3(value, name):
    return as_float_array(value, name, shape=(3,))


def _random_rotation(rng) -> np.ndarray:
    q = rng.normal(size=4)
    w, x, y, z = q / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


class Shape:
    """Base class of the shapes a ``World`` holds: a pose and a convex core swept by a ball.

    Every body is stored alike — world points = ``center + rotation @ local`` — so the narrow phase treats every
    pair the same way (GJK on the world points plus the radii), and the closed-form tests read the same data.

    Attributes
    ----------
    kind : engine.world.kinds.ShapeKind
        The shape's registry entry: ``kind.name`` ("sphere", ...) and ``kind.code``, its row and column in the
        dispatch tables.
    center : numpy.ndarray, shape (3,), float64
        The pose's position.
    rotation : numpy.ndarray, shape (3, 3), float64
        The pose's rotation; its columns are the body's axes in the world.
    local : numpy.ndarray, shape (m, 3), float64
        The core's points in the body frame.
    radius : float
        The radius of the ball that sweeps the core, >= 0 (0 for a polyhedron).
    half : numpy.ndarray, shape (3,), float64
        A box's half extents (zeros for the other kinds).
    planes : numpy.ndarray, shape (F, 4), float64
        A polyhedron's face planes (n, e) in the body frame, the solid being n·x <= e, n unit (none for the other
        kinds).
    """

    kind: ShapeKind  # each class sets its own entry
    radius: float = 0.0
    half: np.ndarray = np.zeros(3)
    planes: np.ndarray = np.zeros((0, 4))
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

    @classmethod
    def example(cls) -> Shape:
        """A small instance near the origin (what the warm-up compiles each dispatch row with)."""
        return cls.random(np.random.default_rng(0), np.zeros(3), 1.0)

    @classmethod
    def random(cls, rng, center, size) -> Shape:
        """A random instance about ``center`` (3,) of about ``size`` (> 0), drawn from ``rng`` (a numpy
        Generator): the tests' strategies build every kind through this."""
        raise NotImplementedError(f"{cls.__name__} has no random instances")

    def __repr__(self) -> str:
        return f"{type(self).__name__}(center={self.center.tolist()}, radius={self.radius})"


@shape_kind("sphere")
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

    def __init__(self, center, radius):
        self.center = _vec3(center, "center")
        self.radius = as_positive(radius, "radius")
        self.rotation = np.eye(3)
        self.local = np.zeros((1, 3))

    @classmethod
    def random(cls, rng, center, size) -> Sphere:
        return cls(center, size * rng.uniform(0.3, 1.0))


@shape_kind("box")
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

    def __init__(self, center, half_extents, rotation=None):
        self.center = _vec3(center, "center")
        half = as_half_extents(half_extents, "half_extents")
        self.half_extents = self.half = half
        self.rotation = as_rotation(rotation)
        self.local = _CORNER_SIGNS * half

    @classmethod
    def random(cls, rng, center, size) -> Box:
        return cls(center, size * rng.uniform(0.3, 1.0, 3), _random_rotation(rng))


@shape_kind("capsule")
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

    def __init__(self, p0, p1, radius):
        a = _vec3(p0, "p0")
        b = _vec3(p1, "p1")
        self.radius = as_positive(radius, "radius")
        self.center = 0.5 * (a + b)
        self.rotation = np.eye(3)
        self.local = np.stack([a - self.center, b - self.center])

    @classmethod
    def random(cls, rng, center, size) -> Capsule:
        half = rng.uniform(-1.0, 1.0, 3) * size
        return cls(center - half, center + half, size * rng.uniform(0.2, 0.5))


@shape_kind("hull")
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
        self.planes = hull_planes(self.local)

    @classmethod
    def random(cls, rng, center, size) -> ConvexPolyhedron:
        return cls(center + rng.normal(size=(int(rng.integers(4, 21)), 3)) * size * 0.7)


@shape_kind("compound", convex=False, composite=True)
class Compound(Shape):
    """One rigid body made of convex parts: each part a ``Sphere``, ``Box``, ``Capsule`` or ``ConvexPolyhedron``
    placed at ``positions[k]`` with ``rotations[k]`` in the compound's frame (Box2D's shapes of one body, Bullet's
    ``btCompoundShape``, MuJoCo's geoms of one body).

    Only each part's geometry is used (its core, radius and half extents); the pose it was built with is replaced
    by its place in the compound. The compound's own pose starts at ``center`` with ``rotation``; ``World.move``
    and ``World.update`` move it as one body, every part with it. Its contacts name the part that touches
    (``ContactSet.part_a``, ``part_b``); a concave object is the union of the convex pieces of its decomposition
    (``Compound.from_mesh``).

    Parameters
    ----------
    shapes : sequence of Shape
        The parts, at least one, each of a convex kind (not a compound, not a ground).
    positions : array_like, shape (n, 3)
        Each part's centre in the compound's frame, finite.
    rotations : array_like or scipy.spatial.transform.Rotation, optional
        Each part's rotation in the compound's frame: (n, 3, 3) matrices (columns = the part's axes), (n, 4) unit
        quaternions (w, x, y, z) or a scipy Rotation of length n; default: the rotation each part was built with.
    center : array_like, shape (3,), optional
        The compound's position (default the origin).
    rotation : array_like or scipy.spatial.transform.Rotation, optional
        The compound's rotation (default the identity).

    Attributes
    ----------
    parts : tuple of (Shape, numpy.ndarray (3,), numpy.ndarray (3, 3))
        Each part with its centre and rotation in the compound's frame.

    Raises
    ------
    TypeError
        For ``shapes`` that is not a sequence of engine shapes, or a part of a kind that cannot be one (named
        ``shapes[k]``).
    ValueError
        For no part, positions or rotations of the wrong shape or not finite, a non-unit quaternion or an improper
        matrix (named ``positions`` / ``rotations`` with the index).
    """

    def __init__(self, shapes, positions, rotations=None, *, center=None, rotation=None):
        if isinstance(shapes, Shape) or not isinstance(shapes, list | tuple):
            raise TypeError(f"shapes must be a list or tuple of shapes, got {type(shapes).__name__}")
        if not shapes:
            raise ValueError("shapes must hold at least one part")
        for k, part in enumerate(shapes):
            if not isinstance(part, Shape):
                raise TypeError(f"shapes[{k}] must be an engine shape, got {type(part).__name__}")
            if not part.kind.convex:
                raise TypeError(f"shapes[{k}] is a {part.kind.name}: the parts of a compound are convex shapes "
                                f"(sphere, box, capsule, hull)")
        n = len(shapes)
        pos = as_float_array(positions, "positions", shape=(n, 3))
        if rotations is None:
            rot = np.stack([part.rotation for part in shapes])
        else:
            mode, given = as_rotation_batch(rotations, n)
            rot = given if mode == 1 else np.stack([as_rotation(q, f"rotations[{k}]") for k, q in enumerate(given)])
        self.center = np.zeros(3) if center is None else _vec3(center, "center")
        self.rotation = as_rotation(rotation)
        self.local = np.zeros((1, 3))
        self.parts = tuple((part, pos[k].copy(), np.array(rot[k], dtype=float)) for k, part in enumerate(shapes))

    @classmethod
    def from_mesh(cls, vertices, triangles, *, threshold: float = 0.05, seed: int = 0, **options) -> Compound:
        """The compound of the convex pieces of a (concave) triangle mesh, by the engine's convex decomposition
        (``engine.bounding.decompose_mesh``, through the optional ``coacd`` package).

        Parameters
        ----------
        vertices : array_like, shape (n, 3)
            The mesh's vertices, in the compound's frame.
        triangles : array_like of int, shape (m, 3)
            Its triangles (vertex indices).
        threshold, seed, **options
            Passed on to ``decompose_mesh`` (lower ``threshold``: more, finer pieces).

        Returns
        -------
        Compound
            One ``ConvexPolyhedron`` part per piece, at the origin with the identity rotation.

        Raises
        ------
        ImportError
            When coacd is not installed (``pip install "colldet[decompose]"``).
        ValueError
            For a bad mesh (see ``decompose_mesh``), or a piece that spans no volume (named with its index).
        """
        pieces = decompose_mesh(vertices, triangles, threshold=threshold, seed=seed, **options)
        parts = []
        for k, (points, _) in enumerate(pieces):
            try:
                parts.append(ConvexPolyhedron(points))
            except ValueError as exc:
                raise ValueError(f"piece {k} of the decomposition is not a solid: {exc}") from None
        return cls(parts, np.array([part.center for part in parts]))

    @classmethod
    def random(cls, rng, center, size) -> Compound:
        kinds = (Sphere, Box, Capsule, ConvexPolyhedron)
        n = int(rng.integers(1, 4))
        parts = [kinds[int(rng.integers(len(kinds)))].random(rng, np.zeros(3), 0.6 * size) for _ in range(n)]
        return cls(parts, rng.uniform(-size, size, (n, 3)), center=center, rotation=_random_rotation(rng))

    def __repr__(self) -> str:
        return f"Compound({len(self.parts)} parts, center={self.center.tolist()})"


@shape_kind("plane", bounded=False, static_only=True, convex=False, candidates=_plane_candidates)
class Plane(Shape):
    """The flat ground, solid below y = altitude (slide "sol plat"); static, and found by its own candidate test
    instead of the broad phase. Its pose is the point (0, altitude, 0) of its surface, its outward normal the
    rotation's second column (+y).

    Parameters
    ----------
    altitude : float, default 0.0
        The ground's height.

    Attributes
    ----------
    altitude : float
        As given.
    """

    def __init__(self, altitude=0.0):
        self.altitude = as_float(altitude, "altitude")
        self.center = np.array([0.0, self.altitude, 0.0])
        self.rotation = np.eye(3)
        self.local = np.zeros((1, 3))

    @classmethod
    def random(cls, rng, center, size) -> Plane:
        return cls(float(center[1]))

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


@shape_kind("curve", bounded=False, static_only=True, convex=False, candidates=curve_candidates)
class HeightCurve(Shape):
    """The curved ground, solid below y = f(x) (slide "Sol courbe"), extruded along z; static.

    The narrow test samples each body's lower boundary at ``samples`` abscissae and refines the lowest gap by
    golden-section search (``engine.narrowphase.curve_ground.ground_gap``).

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

    def __init__(self, f, *, samples: int = 64):
        check_callable(f, "f", "a callable y = f(x)")
        if isinstance(samples, bool) or not isinstance(samples, int | np.integer) or samples < 8:
            raise ValueError(f"samples must be an int >= 8, got {samples!r}")
        probe = np.asarray(f(np.linspace(-1.0, 1.0, 3)), dtype=float)
        if probe.shape != (3,):
            raise ValueError(f"f must be vectorised (array in, same-shape array out), got shape {probe.shape}")
        self.f = f
        self.samples = int(samples)
        self.center = np.zeros(3)
        self.rotation = np.eye(3)
        self.local = np.zeros((1, 3))

    @classmethod
    def random(cls, rng, center, size) -> HeightCurve:
        level, amplitude, wavenumber = float(center[1]), size * rng.uniform(0.1, 1.0), rng.uniform(0.3, 2.0)

        def wave(x):
            return level + amplitude * np.sin(wavenumber * x)
        return cls(wave)

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


class _Surface(Shape):
    """A static triangle surface (level geometry): its triangles in ``mesh`` (engine.narrowphase.triangle_mesh:
    world coordinates, face normals, active edges, the BVH or the grid); the store holds the 8 corners of its AABB
    as the core (the broad phase's box), the kernels read ``mesh``."""

    mesh: MeshArrays

    def _set_mesh(self, mesh: MeshArrays) -> None:
        self.mesh = mesh
        lo, hi = mesh_box(mesh)
        self.center = np.zeros(3)
        self.rotation = np.eye(3)
        self.local = lo + (hi - lo) * (_CORNER_SIGNS + 1.0) / 2.0

    @property
    def vertices(self) -> np.ndarray:
        """(nv, 3) float64: the corners, world coordinates (read-only view)."""
        v = self.mesh.vertices.view()
        v.flags.writeable = False
        return v

    @property
    def triangles(self) -> np.ndarray:
        """(nt, 3) int64: the corner indices of each triangle (read-only view)."""
        t = self.mesh.triangles.view()
        t.flags.writeable = False
        return t


@shape_kind("mesh", static_only=True, convex=False)
class TriangleMesh(_Surface):
    """A static triangle soup, open or closed (level geometry), with its own BVH over the triangles.

    Bodies touch its triangles (two-sided surfaces; a closed mesh is a shell, not a solid); contacts, distances,
    times of impact and rays are exact against the triangles, and internal edges give no ghost normals (see
    engine.narrowphase.triangle_mesh). Static: ``World.add`` makes it so.

    Parameters
    ----------
    vertices : array_like, shape (nv, 3)
        The corners, world coordinates, finite.
    triangles : array_like, shape (nt, 3), integers
        Indices into ``vertices``; nt >= 1; no zero-area triangle (thin ones are kept and answered exactly).

    Raises
    ------
    ValueError
        For NaN or infinite vertices, indices out of range, a zero-area triangle (naming the first bad index).
    TypeError
        For non-numeric vertices or non-integer triangles.
    """

    def __init__(self, vertices, triangles):
        self._set_mesh(mesh_arrays(vertices, triangles))

    @classmethod
    def random(cls, rng, center, size) -> TriangleMesh:
        """A bumpy open sheet of 2–6 × 2–6 cells about ``center`` with its corners jittered, shuffled triangles."""
        nx, nz = (int(x) for x in rng.integers(3, 8, size=2))
        field = HeightField.random(rng, center, size, shape=(nx, nz))
        v = field.mesh.vertices + rng.uniform(-0.2, 0.2, size=field.mesh.vertices.shape) * size / nx
        return cls(v, field.mesh.triangles[rng.permutation(field.mesh.triangles.shape[0])])

    def __repr__(self) -> str:
        return f"TriangleMesh({self.mesh.vertices.shape[0]} vertices, {self.mesh.triangles.shape[0]} triangles)"


@shape_kind("field", static_only=True, convex=False)
class HeightField(_Surface):
    """A static heightfield, y-up: heights (nx, nz) sampled at (x0 + i·dx, z0 + k·dz), two triangles per cell
    split along the (i, k)–(i+1, k+1) diagonal; answered exactly as the ``TriangleMesh`` of those triangles (the
    cells under a body are its candidates: no tree).

    Parameters
    ----------
    heights : array_like, shape (nx, nz)
        Finite heights, nx, nz >= 2.
    spacing : float or (dx, dz)
        Positive sample spacings.
    origin : (x0, z0), default (0, 0)
        Where sample (0, 0) lies.

    Raises
    ------
    ValueError
        For fewer than 2 × 2 samples, a non-finite height (naming its index), a non-positive spacing.
    """

    def __init__(self, heights, spacing, origin=(0.0, 0.0)):
        self._set_mesh(heightfield_arrays(heights, spacing, origin))
        self.heights = self.mesh.vertices[:, 1].reshape(tuple(self.mesh.grid_n))
        self.heights.flags.writeable = False
        self.spacing = (float(self.mesh.grid_f[2]), float(self.mesh.grid_f[3]))
        self.origin = (float(self.mesh.grid_f[0]), float(self.mesh.grid_f[1]))

    @classmethod
    def random(cls, rng, center, size, shape=None) -> HeightField:
        """Random hills of 2–6 × 2–6 cells spanning about ``size`` about ``center``."""
        nx, nz = shape if shape is not None else (int(x) for x in rng.integers(3, 8, size=2))
        h = center[1] + rng.uniform(-0.3, 0.3, size=(nx, nz)) * size
        spacing = (size / (nx - 1), size / (nz - 1))
        return cls(h, spacing, (center[0] - size / 2, center[2] - size / 2))

    def __repr__(self) -> str:
        return f"HeightField({self.heights.shape[0]} x {self.heights.shape[1]}, spacing={self.spacing})"


# the registry entries, in code order (the dispatch tables' rows and columns)
SPHERE, BOX, CAPSULE, HULL = Sphere.kind, Box.kind, Capsule.kind, ConvexPolyhedron.kind
COMPOUND, PLANE, CURVE = Compound.kind, Plane.kind, HeightCurve.kind
MESH, FIELD = TriangleMesh.kind, HeightField.kind
