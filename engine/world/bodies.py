"""The body store of a ``World``: every body's state as structure-of-arrays, indexed by id, and the batch pose
upload (one validation pass over the whole batch, then one compiled kernel).

``BodyStore`` arrays (capacity ``cap`` rows; row ``id`` is body ``id``; rows of removed ids have kind −1):

- ``kind`` (cap,) int8 — a shape code of engine.world.shapes (SPHERE, BOX, CAPSULE, HULL, PLANE, CURVE);
- ``center`` (cap, 3), ``rotation`` (cap, 3, 3) (columns = the body's axes in the world), ``velocity`` (cap, 3);
- ``radius`` (cap,) — the ball sweeping the core (sphere and capsule radius, 0 for boxes and hulls);
- ``half`` (cap, 3) — a box's half extents (0 for the others);
- ``count`` (cap,) int64, ``local`` (cap, M, 3) — the core's points in the body frame, ``points`` (cap, M, 3) —
  the same in the world (center + rotation @ local); rows past ``count`` repeat the first point;
- ``lo``, ``hi`` (cap, 3) — the body's AABB (the points' min / max, grown by the radius);
- ``fat_lo``, ``fat_hi`` (cap, 3) — the enlarged box the tree broad phase holds, ``escaped`` (cap,) bool —
  the body's AABB left it since the broad phase last looked.
A ground (``Plane``) stores a point of its surface in ``center``, its rotation's second column is its outward
normal (+y), and its AABB is unbounded below the surface.

``view()`` returns the arrays as a ``BodyArrays`` bundle (no copy: the compiled kernels' argument);
``World.bodies()`` gives users read-only views of the live rows.

Rotations of an update: ``(k, 3, 3)`` matrices (columns = the body axes, orthonormal with det +1, to
``ROTATION_TOL``), ``(k, 4)`` unit quaternions in (w, x, y, z) order (scalar first, as MuJoCo and scipy's
``as_quat(scalar_first=True)``; not normalised for you), or a ``scipy.spatial.transform.Rotation`` of length k.
"""
from __future__ import annotations

from collections import namedtuple

import numpy as np

from engine._config import njit
from engine._validate import as_float_array
from engine.bounding.aabb import ROTATION_TOL

from .shapes import PLANE

__all__ = ["BodyArrays", "BodyStore", "as_rotation_batch", "refresh_bodies", "QUATERNION_ORDER"]

#: the quaternion convention of every rotation argument, as the error messages say it
QUATERNION_ORDER = "(w, x, y, z)"

#: the compiled kernels' view of the store (one namedtuple of arrays)
BodyArrays = namedtuple("BodyArrays", "kind center rotation velocity radius half count local points lo hi "
                                      "fat_lo fat_hi escaped")

_FIELDS = {"kind": ((), np.int8, -1), "center": ((3,), np.float64, 0.0), "rotation": ((3, 3), np.float64, 0.0),
           "velocity": ((3,), np.float64, 0.0), "radius": ((), np.float64, 0.0), "half": ((3,), np.float64, 0.0),
           "count": ((), np.int64, 1), "lo": ((3,), np.float64, 0.0), "hi": ((3,), np.float64, 0.0),
           "fat_lo": ((3,), np.float64, 0.0), "fat_hi": ((3,), np.float64, 0.0), "escaped": ((), np.bool_, False)}


class BodyStore:
    """Structure-of-arrays state of the bodies (see the module docstring); ids are reused after ``remove``."""

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

    def __init__(self, capacity: int = 16, max_points: int = 1):
        self.n_ids = 0
        self.free: list[int] = []
        self._alloc(capacity, max_points)

    def _alloc(self, cap, m, old=None):
        for name, (shape, dtype, fill) in _FIELDS.items():
            arr = np.full((cap, *shape), fill, dtype)
            if old is not None:
                arr[: old[name].shape[0]] = old[name]
            setattr(self, name, arr)
        self.rotation[self.kind < 0] = np.eye(3)
        for name in ("local", "points"):
            arr = np.zeros((cap, m, 3))
            if old is not None:
                n_old, m_old = old[name].shape[:2]
                arr[:n_old, :m_old] = old[name]
                arr[:n_old, m_old:] = old[name][:, :1]  # padding repeats the first point
            setattr(self, name, arr)

    @property
    def capacity(self) -> int:
        return int(self.kind.shape[0])

    def view(self) -> BodyArrays:
        return BodyArrays(*(getattr(self, name) for name in BodyArrays._fields))

    def new_id(self, m: int) -> int:
        """A free id for a body of m core points (growing the arrays when needed)."""
        body = self.free.pop() if self.free else self.n_ids
        if body == self.n_ids:
            self.n_ids += 1
        if body >= self.capacity or m > self.local.shape[1]:
            old = {name: getattr(self, name) for name in (*_FIELDS, "local", "points")}
            self._alloc(max(self.capacity, 2 * body + 2), max(m, self.local.shape[1]), old)
        return body

    def release(self, body: int) -> None:
        self.kind[body] = -1
        self.escaped[body] = False
        self.free.append(body)

    def live(self) -> np.ndarray:
        """Ids of the live rows (bodies and grounds), ascending."""
        return np.flatnonzero(self.kind[: self.n_ids] >= 0)

    def check_ids(self, ids, name: str = "ids") -> np.ndarray:
        """ids (k,) as int64, each a live movable body, all distinct — else TypeError / ValueError naming
        ``name`` and the index."""
        idx = np.asarray(ids)
        if idx.dtype.kind not in "iu" or idx.ndim != 1:
            raise TypeError(f"{name} must be a 1-D integer array, got dtype {idx.dtype} and shape {idx.shape}")
        idx = idx.astype(np.int64)
        outside = (idx < 0) | (idx >= self.n_ids)
        kind = np.where(outside, -1, self.kind[np.where(outside, 0, idx)])
        bad = np.flatnonzero(kind < 0)
        if bad.size:
            raise ValueError(f"{name}[{bad[0]}] = {idx[bad[0]]} is not a body of this world (never added, or "
                             f"removed)")
        bad = np.flatnonzero(kind >= PLANE)
        if bad.size:
            raise ValueError(f"{name}[{bad[0]}] = {idx[bad[0]]} is a ground, which cannot move")
        order = np.argsort(idx, kind="stable")
        same = np.flatnonzero(idx[order][1:] == idx[order][:-1])
        if same.size:
            first, again = sorted((int(order[same[0]]), int(order[same[0] + 1])))
            raise ValueError(f"{name}[{again}] = {idx[again]} repeats {name}[{first}]: ids must be distinct")
        return idx


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


@njit
def refresh_bodies(bodies, ids, centers, mode, rotations, quaternions, velocities):
    """The pose upload: for each body ids[r], centre centers[r]; rotation rotations[r] (mode 1), from the unit
    quaternion quaternions[r] = (w, x, y, z) (mode 2) or unchanged (mode 0); velocity velocities[r] when
    velocities has k rows; then its world points (center + R @ local, the padding rows repeating the first)
    and AABB (min / max of the points ∓ the radius), and whether the AABB left its fat box."""
    has_velocity = velocities.shape[0] == ids.shape[0]
    for r in range(ids.shape[0]):
        b = ids[r]
        for c in range(3):
            bodies.center[b, c] = centers[r, c]
        R = bodies.rotation[b]
        if mode == 1:
            R[:, :] = rotations[r]
        elif mode == 2:
            w, x, y, z = quaternions[r, 0], quaternions[r, 1], quaternions[r, 2], quaternions[r, 3]
            R[0, 0], R[0, 1], R[0, 2] = 1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)
            R[1, 0], R[1, 1], R[1, 2] = 2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)
            R[2, 0], R[2, 1], R[2, 2] = 2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)
        if has_velocity:
            for c in range(3):
                bodies.velocity[b, c] = velocities[r, c]
        world_points(bodies, b)


@njit
def world_points(bodies, b):
    """Body b's world points and AABB from its pose (Ericson 4.2.6: the AABB of the rotated core), and its
    ``escaped`` flag."""
    m = bodies.count[b]
    R = bodies.rotation[b]
    rad = bodies.radius[b]
    lo0 = lo1 = lo2 = np.inf
    hi0 = hi1 = hi2 = -np.inf
    for v in range(m):
        lx, ly, lz = bodies.local[b, v, 0], bodies.local[b, v, 1], bodies.local[b, v, 2]
        x = bodies.center[b, 0] + R[0, 0] * lx + R[0, 1] * ly + R[0, 2] * lz
        y = bodies.center[b, 1] + R[1, 0] * lx + R[1, 1] * ly + R[1, 2] * lz
        z = bodies.center[b, 2] + R[2, 0] * lx + R[2, 1] * ly + R[2, 2] * lz
        bodies.points[b, v, 0], bodies.points[b, v, 1], bodies.points[b, v, 2] = x, y, z
        lo0, lo1, lo2 = min(lo0, x), min(lo1, y), min(lo2, z)
        hi0, hi1, hi2 = max(hi0, x), max(hi1, y), max(hi2, z)
    for v in range(m, bodies.points.shape[1]):  # the padding repeats the first point
        for c in range(3):
            bodies.points[b, v, c] = bodies.points[b, 0, c]
    bodies.lo[b, 0], bodies.lo[b, 1], bodies.lo[b, 2] = lo0 - rad, lo1 - rad, lo2 - rad
    bodies.hi[b, 0], bodies.hi[b, 1], bodies.hi[b, 2] = hi0 + rad, hi1 + rad, hi2 + rad
    for c in range(3):
        if bodies.lo[b, c] < bodies.fat_lo[b, c] or bodies.hi[b, c] > bodies.fat_hi[b, c]:
            bodies.escaped[b] = True
