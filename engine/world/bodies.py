"""The body store of a ``World``: every body's state as structure-of-arrays, indexed by id, and the batch pose
upload (one compiled kernel: the whole batch checked, then written — ``upload_bodies``).

``BodyStore`` arrays (capacity ``cap`` rows; row ``id`` is body ``id``; rows of removed ids have kind −1):

- ``kind`` (cap,) int8 — the code of the shape's kind (engine/world/kinds.py);
- ``center`` (cap, 3), ``rotation`` (cap, 3, 3) (columns = the body's axes in the world), ``velocity`` (cap, 3);
- ``radius`` (cap,) — the ball sweeping the core (sphere and capsule radius, 0 for boxes and hulls);
- ``half`` (cap, 3) — a box's half extents (0 for the others);
- ``count`` (cap,) int64, ``local`` (cap, M, 3) — the core's points in the body frame, ``points`` (cap, M, 3) —
  the same in the world (center + rotation @ local); rows past ``count`` repeat the first point;
- ``lo``, ``hi`` (cap, 3) — the body's AABB (the points' min / max, grown by the radius; a compound's: the union
  of its parts'; an unbounded kind's: the whole space);
- ``fat_lo``, ``fat_hi`` (cap, 3) — the enlarged box the broad phase holds, ``escaped`` (cap,) bool — the body's
  AABB left it since the broad phase last looked;
- ``bounded``, ``static``, ``sensor`` (cap,) bool — the kind has a finite AABB; the body never moves (level
  geometry); it is a sensor (reported by ``pairs`` and ``events``, never by ``contacts``);
- ``category``, ``mask`` (cap,) uint64, ``group`` (cap,) int64 — the collision filter (engine/world/filters.py);
- ``owner`` (cap,) int64 — −1 for a body; for a part of a compound, the compound's id (the part's row is not a
  body of the world: it is moved with its compound and answers for it in the narrow phase); ``part`` (cap,)
  int64 — the part's number in its compound (0 for a body); ``first_part``, ``next_part`` (cap,) int64 — a
  compound's parts as a linked list (−1 ends it); ``part_center`` (cap, 3), ``part_rotation`` (cap, 3, 3) — a
  part's pose in its compound's frame;
- ``planes`` (cap, F, 4), ``n_planes`` (cap,) int64 — a hull's face planes (n, e) in the body frame, the solid
  being n·x <= e (the ray kernels clip by them); none for the other kinds.
A ground (``Plane``) stores a point of its surface in ``center``, its rotation's second column is its outward
normal (+y).

``view()`` returns the arrays as a ``BodyArrays`` bundle (no copy: the compiled kernels' argument);
``World.bodies()`` gives users read-only views of the live rows.

Scratch rows (``scratch(shape)``, the world's shape queries): a query shape (a compound with its parts) is
written into the rows just past ``n_ids``, placed at its pose, and wiped back to fresh rows on exit — the rows
past ``n_ids`` are never read by the world and never hold a body (``new_id`` hands out ``n_ids`` only after the
free heap is empty), so ids, ``free`` and ``n_ids`` are untouched. More rows are made for good when needed (as
an ``add`` would); a query shape with more core points than the rows hold runs on grown copies of the arrays,
and the original arrays are put back on exit.

Rotations of an update: ``(k, 3, 3)`` matrices (columns = the body axes, orthonormal with det +1, to
``ROTATION_TOL``), ``(k, 4)`` unit quaternions in (w, x, y, z) order (scalar first, as MuJoCo and scipy's
``as_quat(scalar_first=True)``; not normalised for you), or a ``scipy.spatial.transform.Rotation`` of length k
(engine.world.shapes.as_rotation_batch).
"""
from __future__ import annotations

import heapq
from collections import namedtuple
from collections.abc import Iterator
from contextlib import contextmanager

import numpy as np

from engine._config import njit

__all__ = ["BodyArrays", "BodyStore", "refresh_bodies", "place_bodies", "upload_bodies", "UPLOAD_OK", "BAD_IDS",
           "BAD_CENTERS", "BAD_ROTATIONS", "BAD_VELOCITIES"]

#: the compiled kernels' view of the store (one namedtuple of arrays)
BodyArrays = namedtuple("BodyArrays", "kind center rotation velocity radius half count local points lo hi "
                                      "fat_lo fat_hi escaped bounded static sensor category mask group owner part "
                                      "first_part next_part part_center part_rotation planes n_planes")

_ALL_BITS = np.iinfo(np.uint64).max
_FIELDS = {"kind": ((), np.int8, -1), "center": ((3,), np.float64, 0.0), "rotation": ((3, 3), np.float64, 0.0),
           "velocity": ((3,), np.float64, 0.0), "radius": ((), np.float64, 0.0), "half": ((3,), np.float64, 0.0),
           "count": ((), np.int64, 1), "lo": ((3,), np.float64, 0.0), "hi": ((3,), np.float64, 0.0),
           "fat_lo": ((3,), np.float64, 0.0), "fat_hi": ((3,), np.float64, 0.0), "escaped": ((), np.bool_, False),
           "bounded": ((), np.bool_, True), "static": ((), np.bool_, False), "sensor": ((), np.bool_, False),
           "category": ((), np.uint64, 1), "mask": ((), np.uint64, _ALL_BITS), "group": ((), np.int64, 0),
           "owner": ((), np.int64, -1), "part": ((), np.int64, 0), "first_part": ((), np.int64, -1),
           "next_part": ((), np.int64, -1), "part_center": ((3,), np.float64, 0.0),
           "part_rotation": ((3, 3), np.float64, 0.0), "n_planes": ((), np.int64, 0)}
_CORE = ("local", "points")
_PLANES = "planes"


class BodyStore:
    """Structure-of-arrays state of the bodies (see the module docstring); ids are reused after ``release``, the
    smallest first (``free`` is a heap)."""

    # the state arrays, set by _alloc from _FIELDS (+ local, points); shapes and dtypes in the module docstring
    kind: np.ndarray
    center: np.ndarray
    rotation: np.ndarray
    velocity: np.ndarray
    radius: np.ndarray
    half: np.ndarray
    count: np.ndarray
    local: np.ndarray
    points: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    fat_lo: np.ndarray
    fat_hi: np.ndarray
    escaped: np.ndarray
    bounded: np.ndarray
    static: np.ndarray
    sensor: np.ndarray
    category: np.ndarray
    mask: np.ndarray
    group: np.ndarray
    owner: np.ndarray
    part: np.ndarray
    first_part: np.ndarray
    next_part: np.ndarray
    part_center: np.ndarray
    part_rotation: np.ndarray
    planes: np.ndarray
    n_planes: np.ndarray

    def __init__(self, capacity: int = 16, max_points: int = 1):
        self.n_ids = 0
        self.free: list[int] = []
        self._alloc(capacity, max_points, 1)

    def _alloc(self, cap, m, f, old=None):
        self._view: BodyArrays | None = None
        for name, (shape, dtype, fill) in _FIELDS.items():
            arr = np.full((cap, *shape), fill, dtype)
            if old is not None:
                arr[: old[name].shape[0]] = old[name]
            setattr(self, name, arr)
        for name in _CORE:
            arr = np.zeros((cap, m, 3))
            if old is not None:
                n_old, m_old = old[name].shape[:2]
                arr[:n_old, :m_old] = old[name]
                arr[:n_old, m_old:] = old[name][:, :1]  # padding repeats the first point
            setattr(self, name, arr)
        planes = np.zeros((cap, f, 4))
        if old is not None:
            planes[: old[_PLANES].shape[0], : old[_PLANES].shape[1]] = old[_PLANES]
        self.planes = planes
        fresh = slice(0 if old is None else old["kind"].shape[0], cap)
        self.rotation[fresh] = self.part_rotation[fresh] = np.eye(3)

    @property
    def capacity(self) -> int:
        return int(self.kind.shape[0])

    def view(self) -> BodyArrays:
        """The arrays as one ``BodyArrays`` (no copy), kept until the arrays are replaced (``_alloc``, the end of
        ``scratch``)."""
        if self._view is None:
            self._view = BodyArrays(*(getattr(self, name) for name in BodyArrays._fields))
        return self._view

    def new_id(self, m: int, f: int = 0) -> int:
        """The smallest free id, for a body of m core points and f face planes (growing the arrays when
        needed)."""
        body = heapq.heappop(self.free) if self.free else self.n_ids
        if body == self.n_ids:
            self.n_ids += 1
        self._reserve(body + 1, m, f)
        return body

    def _reserve(self, rows: int, m: int, f: int = 0) -> None:
        """Room for rows 0 to rows - 1, m core points and f face planes per row (the arrays grow, their content
        kept)."""
        if rows > self.capacity or m > self.local.shape[1] or f > self.planes.shape[1]:
            old = {name: getattr(self, name) for name in (*_FIELDS, *_CORE, _PLANES)}
            self._alloc(max(self.capacity, 2 * rows), max(m, self.local.shape[1]), max(f, self.planes.shape[1]),
                        old)

    @contextmanager
    def scratch(self, shape) -> Iterator[list[int]]:
        """Hold ``shape`` in scratch rows past the live ones while the block runs (see the module docstring).

        Yields the rows: ``[row, *parts]`` — the shape's row (``n_ids``), then a compound's parts (owner = row,
        linked as ``World.add`` links them); every row placed at the shape's pose (``center``, ``rotation``), with
        zero velocity and the default filter. On exit, normal or not, the rows are fresh again (the ``_FIELDS``
        fills, identity rotations, zero points). Room for more rows is made for good (the capacity is not part of
        what ``World.bodies()`` shows); when the shape has more core points than the store's rows hold, the block
        runs on grown copies and the old arrays are put back on exit (a copy of the store per such query). A
        ground (unbounded shape) is refused: ValueError.
        """
        if not shape.kind.bounded:
            raise ValueError(f"shape must be a bounded body shape, got a {shape.kind.name} (a ground)")
        parts = getattr(shape, "parts", ())
        first = self.n_ids
        rows = list(range(first, first + 1 + len(parts)))
        self._reserve(rows[-1] + 1, self.local.shape[1])  # more rows, kept: rows past n_ids are never shown
        arrays = {name: getattr(self, name) for name in (*_FIELDS, *_CORE, _PLANES)}
        try:
            shapes = (shape, *(p[0] for p in parts))
            self._reserve(rows[-1] + 1, max(s.local.shape[0] for s in shapes), max(s.planes.shape[0] for s in shapes))
            self.write_shape(first, shape)
            for k, ((part, position, rotation), row) in enumerate(zip(parts, rows[1:])):
                self.write_shape(row, part)
                self.owner[row], self.part[row] = first, k
                self.part_center[row], self.part_rotation[row] = position, rotation
                if k == 0:
                    self.first_part[first] = row
                else:
                    self.next_part[row - 1] = row
            self.fat_lo[first], self.fat_hi[first] = np.inf, -np.inf
            refresh_bodies(self.view(), np.array([first]), np.asarray(shape.center, np.float64)[None], 1,
                           np.ascontiguousarray(shape.rotation, dtype=np.float64)[None], np.empty((0, 4)),
                           np.zeros((1, 3)))
            yield rows
        finally:
            if self.kind is arrays["kind"]:
                self._wipe(first, len(rows))
            else:  # the arrays grew for the query: the old ones, untouched, come back (views of them stay live)
                for name, arr in arrays.items():
                    setattr(self, name, arr)
                self._view = None

    def _wipe(self, first: int, k: int) -> None:
        """Rows first to first + k - 1 back to fresh rows (as ``_alloc`` makes them)."""
        rows = slice(first, min(first + k, self.capacity))
        for name, (_, _, fill) in _FIELDS.items():
            getattr(self, name)[rows] = fill
        for name in (*_CORE, _PLANES):
            getattr(self, name)[rows] = 0.0
        self.rotation[rows] = self.part_rotation[rows] = np.eye(3)

    def write_shape(self, body: int, shape) -> None:
        """Row ``body`` from a shape's core (``local``, ``radius``, ``half``) and its kind's flags; the pose is
        set by the upload (``refresh_bodies``), the filter and the parts by the world."""
        m = shape.local.shape[0]
        self.kind[body] = shape.kind.code
        self.bounded[body] = shape.kind.bounded
        self.radius[body] = shape.radius
        self.half[body] = shape.half
        self.count[body] = m
        self.local[body, :m] = shape.local
        self.local[body, m:] = shape.local[0]
        f = shape.planes.shape[0]
        self.planes[body, :f] = shape.planes
        self.n_planes[body] = f
        self.velocity[body] = 0.0
        self.owner[body] = -1
        self.part[body] = 0
        self.first_part[body] = self.next_part[body] = -1
        self.escaped[body] = False
        if not shape.kind.bounded:
            self.lo[body], self.hi[body] = -np.inf, np.inf

    def release(self, body: int) -> None:
        self.kind[body] = -1
        self.escaped[body] = False
        self.first_part[body] = self.owner[body] = -1
        heapq.heappush(self.free, body)

    def live(self) -> np.ndarray:
        """Ids of the live bodies (grounds included, parts of compounds excluded), ascending."""
        n = self.n_ids
        return np.flatnonzero((self.kind[:n] >= 0) & (self.owner[:n] < 0))

    def parts_of(self, body: int) -> list[int]:
        """The rows of a compound's parts, in part order (empty for any other body)."""
        rows = []
        s = int(self.first_part[body])
        while s >= 0:
            rows.append(s)
            s = int(self.next_part[s])
        return rows

    def check_ids(self, ids, name: str = "ids", *, moving: bool = True) -> np.ndarray:
        """ids (k,) as int64, each a live body (``moving``: one that may move — not static, not a ground), all
        distinct — else TypeError / ValueError naming ``name`` and the index."""
        idx = np.asarray(ids)
        if idx.dtype.kind not in "iu" or idx.ndim != 1:
            raise TypeError(f"{name} must be a 1-D integer array, got dtype {idx.dtype} and shape {idx.shape}")
        idx = idx.astype(np.int64)
        outside = (idx < 0) | (idx >= self.n_ids)
        at = np.where(outside, 0, idx)
        bad = np.flatnonzero(outside | (self.kind[at] < 0) | (self.owner[at] >= 0))
        if bad.size:
            raise ValueError(f"{name}[{bad[0]}] = {idx[bad[0]]} is not a body of this world (never added, or "
                             f"removed)")
        bad = np.flatnonzero(self.static[idx]) if moving else np.empty(0, np.int64)
        if bad.size:
            what = "a ground" if not self.bounded[idx[bad[0]]] else "static (level geometry)"
            raise ValueError(f"{name}[{bad[0]}] = {idx[bad[0]]} is {what}, which cannot move")
        order = np.argsort(idx, kind="stable")
        same = np.flatnonzero(idx[order][1:] == idx[order][:-1])
        if same.size:
            first, again = sorted((int(order[same[0]]), int(order[same[0] + 1])))
            raise ValueError(f"{name}[{again}] = {idx[again]} repeats {name}[{first}]: ids must be distinct")
        return idx


#: what ``upload_bodies`` says of a batch: accepted, or the argument that failed (the index comes with it)
UPLOAD_OK, BAD_IDS, BAD_CENTERS, BAD_ROTATIONS, BAD_VELOCITIES = 0, 1, 2, 3, 4


@njit(inline="always")
def _bad_ids(bodies, n_ids, ids):
    """The first index r whose id is not a live moving body (a part, static, a ground, out of range) or repeats
    an earlier one; -1 when every id passes."""
    seen = np.zeros(n_ids, np.bool_)
    for r in range(ids.shape[0]):
        b = ids[r]
        if b < 0 or b >= n_ids or bodies.kind[b] < 0 or bodies.owner[b] >= 0 or bodies.static[b] or seen[b]:
            return r
        seen[b] = True
    return -1


@njit(inline="always")
def _bad_row(values, limit):
    """The first row of values (k, m) holding a NaN, an infinity or a magnitude above ``limit``; -1 if none."""
    for r in range(values.shape[0]):
        for c in range(values.shape[1]):
            if not abs(values[r, c]) <= limit:  # a NaN fails every comparison
                return r
    return -1


@njit(inline="always")
def _bad_quaternion(quaternions, tol):
    """The first quaternion whose norm is not within ``tol`` of 1 (NaN included); -1 if none."""
    for r in range(quaternions.shape[0]):
        w, x, y, z = quaternions[r, 0], quaternions[r, 1], quaternions[r, 2], quaternions[r, 3]
        if not abs(np.sqrt(w * w + x * x + y * y + z * z) - 1.0) <= tol:
            return r
    return -1


@njit(inline="always")
def _bad_matrix(rotations, tol):
    """The first matrix that is not a proper rotation: some entry of RᵀR − I beyond ``tol`` (NaN included), or a
    negative determinant (a reflection); -1 if none."""
    for r in range(rotations.shape[0]):
        R = rotations[r]
        for i in range(3):
            for j in range(3):
                dot = R[0, i] * R[0, j] + R[1, i] * R[1, j] + R[2, i] * R[2, j]
                if not abs(dot - (1.0 if i == j else 0.0)) <= tol:
                    return r
        det = (R[0, 0] * (R[1, 1] * R[2, 2] - R[1, 2] * R[2, 1]) - R[0, 1] * (R[1, 0] * R[2, 2] - R[1, 2] * R[2, 0])
               + R[0, 2] * (R[1, 0] * R[2, 1] - R[1, 1] * R[2, 0]))
        if det < 0.0:
            return r
    return -1


@njit
def upload_bodies(bodies, n_ids, ids, centers, mode, rotations, quaternions, velocities, limit, tol):
    """The checked pose upload: (verdict, index). Every argument is checked first, in order — ids (live moving
    bodies among the first ``n_ids`` rows, distinct), centres and velocities (finite, magnitude <= ``limit``),
    rotations (mode 1: proper rotation matrices to ``tol``; mode 2: quaternions of norm 1 to ``tol``) —; the
    first failure is returned as (BAD_..., its row) and nothing is written. Else ``refresh_bodies`` runs and
    (UPLOAD_OK, -1) is returned."""
    at = _bad_ids(bodies, n_ids, ids)
    if at >= 0:
        return BAD_IDS, at
    at = _bad_row(centers, limit)
    if at >= 0:
        return BAD_CENTERS, at
    if mode == 1:
        at = _bad_matrix(rotations, tol)
    elif mode == 2:
        at = _bad_quaternion(quaternions, tol)
    if at >= 0:
        return BAD_ROTATIONS, at
    at = _bad_row(velocities, limit)
    if at >= 0:
        return BAD_VELOCITIES, at
    refresh_bodies(bodies, ids, centers, mode, rotations, quaternions, velocities)
    return UPLOAD_OK, -1


@njit
def refresh_bodies(bodies, ids, centers, mode, rotations, quaternions, velocities):
    """The pose upload: for each body ids[r], centre centers[r]; rotation rotations[r] (mode 1), from the unit
    quaternion quaternions[r] = (w, x, y, z) (mode 2) or unchanged (mode 0); velocity velocities[r] when
    velocities has k rows; then its world points and AABB (``place_bodies``)."""
    has_velocity = velocities.shape[0] == ids.shape[0]
    for r in range(ids.shape[0]):
        b = ids[r]
        for c in range(3):
            bodies.center[b, c] = centers[r, c]
        R = bodies.rotation[b]
        if mode == 1:
            for i in range(3):  # element by element: a slice assignment would compile numba's shape-error path
                for j in range(3):
                    R[i, j] = rotations[r, i, j]
        elif mode == 2:
            w, x, y, z = quaternions[r, 0], quaternions[r, 1], quaternions[r, 2], quaternions[r, 3]
            R[0, 0], R[0, 1], R[0, 2] = 1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)
            R[1, 0], R[1, 1], R[1, 2] = 2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)
            R[2, 0], R[2, 1], R[2, 2] = 2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)
        if has_velocity:
            for c in range(3):
                bodies.velocity[b, c] = velocities[r, c]
    place_bodies(bodies.center, bodies.rotation, bodies.velocity, bodies.radius, bodies.count, bodies.local,
                 bodies.points, bodies.lo, bodies.hi, bodies.bounded, bodies.first_part, bodies.next_part,
                 bodies.part_center, bodies.part_rotation, bodies.fat_lo, bodies.fat_hi, bodies.escaped, ids)


@njit
def place_bodies(center, rotation, velocity, radius, count, local, points, lo, hi, bounded, first_part, next_part,
                 part_center, part_rotation, fat_lo, fat_hi, escaped, ids):
    """The world points and AABB of each body ``ids[r]`` from its pose (the body store's arrays) — a compound's
    parts placed by its pose, its AABB the union of theirs — and its ``escaped`` flag (the AABB left its fat
    box)."""
    for r in range(ids.shape[0]):
        b = ids[r]
        if first_part[b] < 0:
            _core_points(center, rotation, radius, count, local, points, lo, hi, bounded, b)
        else:
            for c in range(3):
                lo[b, c], hi[b, c] = np.inf, -np.inf
            s = first_part[b]
            while s >= 0:
                _place_part(center, rotation, velocity, part_center, part_rotation, b, s)
                _core_points(center, rotation, radius, count, local, points, lo, hi, bounded, s)
                for c in range(3):
                    lo[b, c] = min(lo[b, c], lo[s, c])
                    hi[b, c] = max(hi[b, c], hi[s, c])
                s = next_part[s]
        for c in range(3):
            if lo[b, c] < fat_lo[b, c] or hi[b, c] > fat_hi[b, c]:
                escaped[b] = True


@njit(inline="always")
def _place_part(center, rotation, velocity, part_center, part_rotation, b, s):
    """Part s of compound b: centre c_b + R_b p_s, rotation R_b R_s, the compound's velocity."""
    R, p, P = rotation[b], part_center[s], part_rotation[s]
    for i in range(3):
        center[s, i] = center[b, i] + R[i, 0] * p[0] + R[i, 1] * p[1] + R[i, 2] * p[2]
        velocity[s, i] = velocity[b, i]
        for j in range(3):
            rotation[s, i, j] = R[i, 0] * P[0, j] + R[i, 1] * P[1, j] + R[i, 2] * P[2, j]


@njit(inline="always")
def _core_points(center, rotation, radius, count, local, points, lo, hi, bounded, b):
    """Body b's world points and AABB from its pose (Ericson 4.2.6: the AABB of the rotated core)."""
    m = count[b]
    R = rotation[b]
    rad = radius[b]
    lo0 = lo1 = lo2 = np.inf
    hi0 = hi1 = hi2 = -np.inf
    for v in range(m):
        lx, ly, lz = local[b, v, 0], local[b, v, 1], local[b, v, 2]
        x = center[b, 0] + R[0, 0] * lx + R[0, 1] * ly + R[0, 2] * lz
        y = center[b, 1] + R[1, 0] * lx + R[1, 1] * ly + R[1, 2] * lz
        z = center[b, 2] + R[2, 0] * lx + R[2, 1] * ly + R[2, 2] * lz
        points[b, v, 0], points[b, v, 1], points[b, v, 2] = x, y, z
        lo0, lo1, lo2 = min(lo0, x), min(lo1, y), min(lo2, z)
        hi0, hi1, hi2 = max(hi0, x), max(hi1, y), max(hi2, z)
    for v in range(m, points.shape[1]):  # the padding repeats the first point
        for c in range(3):
            points[b, v, c] = points[b, 0, c]
    if bounded[b]:
        lo[b, 0], lo[b, 1], lo[b, 2] = lo0 - rad, lo1 - rad, lo2 - rad
        hi[b, 0], hi[b, 1], hi[b, 2] = hi0 + rad, hi1 + rad, hi2 + rad
