"""``World``: the chapter's collision pipeline over bodies of mixed shapes.

Slide "Pipeline de détection de collisions": a broad phase (bounding boxes, one of engine.BROAD_PHASES — by
default the incremental dynamic AABB tree, Box2D's ``b2DynamicTree``), then the exact narrow test of each
candidate pair through the dispatch table (engine/world/dispatch.py, one batched call per pair of shape kinds),
then "l'instant et le lieu précis (vertex, côtés, faces)": ``contacts()`` (where) and ``time_of_impact(dt)``
(when: "Méthode cinématique" culling of separating pairs, then conservative advancement).

Bodies are stored as structure-of-arrays indexed by id (pose, velocity, sweep radius, box half extents, padded
local core points); grounds (``Plane``, ``HeightCurve``) are kept apart: they are tested against the bodies'
AABBs (``overlap_aabb_curve``) instead of entering the broad phase. Every query refreshes ``world.stats``, the
work done by each stage.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from engine._validate import as_choice, as_float_array, as_nonnegative
from engine.broadphase import BROAD_PHASES, DynamicAABBTree, cull_separating_box_pairs, find_pairs
from engine.narrowphase import contact_feature_pairs, overlap_aabb_curve, time_of_impact_pairs

from .dispatch import ground_gap, lower_boundary, overlap_groups
from .shapes import BOX, KIND_NAMES, PLANE, Shape, as_rotation_matrix

__all__ = ["World", "ContactSet", "ImpactSet", "FEATURE_NAMES"]

#: feature codes of ContactSet.feature_a / feature_b (as engine.narrowphase.contact_feature_pairs)
FEATURE_NAMES = {1: "vertex", 2: "edge", 3: "face"}
_ROUND_NAMES = {1: "sphere", 2: "cylinder", 3: "face"}

#: a batch update moving more bodies than this rebuilds the tree in one top-down pass instead of moving leaves
REBUILD_THRESHOLD = 64


@dataclass(frozen=True)
class ContactSet:
    """Contacts of k overlapping pairs. ``pairs`` (k, 2) canonical; ``separation`` (k,) (<= 0: −depth);
    ``depth`` (k,) >= 0; ``normal`` (k, 3) unit, from the pair's first body to its second; ``feature_a``,
    ``feature_b`` (k,) int8 (1 vertex, 2 edge, 3 face); ``kind`` list of k strings ("vertex-face", ...);
    ``points`` (M, 3) with pair p's contact points at ``points[point_offsets[p]:point_offsets[p + 1]]``."""

    pairs: np.ndarray
    separation: np.ndarray
    depth: np.ndarray
    normal: np.ndarray
    feature_a: np.ndarray
    feature_b: np.ndarray
    kind: list
    points: np.ndarray
    point_offsets: np.ndarray

    def __len__(self) -> int:
        return int(self.pairs.shape[0])

    def points_of(self, p: int) -> np.ndarray:
        return self.points[self.point_offsets[p]:self.point_offsets[p + 1]]


@dataclass(frozen=True)
class ImpactSet:
    """Pairs (k, 2) canonical that touch within dt, with their first-contact ``times`` (k,) in [0, dt]."""

    pairs: np.ndarray
    times: np.ndarray

    def __len__(self) -> int:
        return int(self.pairs.shape[0])


@dataclass
class WorldStats:
    """Work of each stage in the last query: ``bodies``, ``candidate_pairs`` (broad phase, bodies and grounds),
    ``culled`` (kinematic culling, time_of_impact only), ``narrow_tests``, ``overlapping`` (pairs that touch),
    ``contacts`` (contact points), ``impacts``; ``groups`` {"sphere-box": tests, ...}."""

    query: str = ""
    bodies: int = 0
    candidate_pairs: int = 0
    culled: int = 0
    narrow_tests: int = 0
    overlapping: int = 0
    contacts: int = 0
    impacts: int = 0
    groups: dict = field(default_factory=dict)

    def as_dict(self) -> dict:
        return dict(self.__dict__)


class Geometry:
    """World arrays for the narrow phase, with lazily derived ones (world points, OBB axes, capsule ends)."""

    def __init__(self, world):
        self.world = world
        self.kind = world._kind
        self.center = world._center
        self.rotation = world._rot
        self.radius = world._radius
        self.half = world._half
        self.count = world._count
        self.local = world._local
        self.grounds = world._grounds

    @cached_property
    def padded_points(self) -> np.ndarray:
        """(cap, M, 3) world points of every core (rows past ``count`` repeat the first point)."""
        return self.world._world_points

    @cached_property
    def _packed(self):
        mask = np.arange(self.local.shape[1])[None, :] < self.count[:, None]
        offsets = np.zeros(self.count.shape[0] + 1, np.int64)
        np.cumsum(self.count, out=offsets[1:])
        return np.ascontiguousarray(self.padded_points[mask]), offsets

    @property
    def points(self):
        return self._packed[0]

    @property
    def offsets(self):
        return self._packed[1]

    @cached_property
    def axes_rows(self) -> np.ndarray:
        return np.ascontiguousarray(self.rotation.transpose(0, 2, 1))

    @cached_property
    def segment_ends(self):
        pts = self.padded_points
        return np.ascontiguousarray(pts[:, 0]), np.ascontiguousarray(pts[:, 1])

    def lowest_y(self, bodies) -> np.ndarray:
        return self.padded_points[bodies, :, 1].min(axis=1) - self.radius[bodies]


def _canonical(pairs: np.ndarray) -> np.ndarray:
    if pairs.shape[0] == 0:
        return np.empty((0, 2), np.int64)
    p = np.sort(pairs, axis=1).astype(np.int64)
    p = p[np.lexsort((p[:, 1], p[:, 0]))]
    return np.ascontiguousarray(p)


def _contacts_of_pairs(points, offsets, pairs, radii):
    """Contacts of body pairs (k, 2) of packed shapes (points (N, 3), offsets (S + 1,), radii (S,)), in one compiled
    call (engine.narrowphase.contact_feature_pairs). Returns (separation (k,), normal (k, 3), feature_a (k,) int8,
    feature_b (k,) int8, kinds, points (M, 3), point_offsets (k + 1,)).
    """
    batch = contact_feature_pairs(points, offsets, pairs, radii=radii)
    return (batch.separation, batch.normal, batch.feature_a, batch.feature_b, list(batch.kind), batch.points,
            batch.point_offsets)


class World:
    """A collision world: ``World(broad_phase="tree")`` (any of engine.BROAD_PHASES).

    - ``add(shape, velocity=None) -> id``; ``remove(id)``; ``move(id, center=None, rotation=None,
      velocity=None)``; ``update(ids, centers, rotations=None, velocities=None)`` moves many bodies with one
      broad-phase refit;
    - ``pairs()`` -> canonical (k, 2) int64 ids of overlapping shapes; ``contacts()`` -> ``ContactSet``;
      ``time_of_impact(dt)`` -> ``ImpactSet`` (bodies move with their constant velocities; grounds are fixed);
    - ``stats`` (``WorldStats``): the work of each stage in the last query.
    Ids are ints, reused after ``remove``. Grounds (``Plane``, ``HeightCurve``) take ids too but cannot move.
    """

    def __init__(self, broad_phase: str = "tree"):
        self.broad_phase = as_choice(broad_phase, "broad_phase", BROAD_PHASES)
        self._alloc(16, 1)
        self._n_ids = 0
        self._free: list[int] = []
        self._grounds: dict = {}
        self._shapes: dict = {}
        self._tree = DynamicAABBTree(dim=3) if self.broad_phase == "tree" else None
        self._body_leaf = np.full(16, -1, np.int64)
        self._leaf_body = np.full(16, -1, np.int64)
        self.stats = WorldStats()
        self.rebuild_threshold = REBUILD_THRESHOLD

    # -- storage ------------------------------------------------------------------------------------------
    def _alloc(self, cap, m):
        self._kind = np.full(cap, -1, np.int8)
        self._center = np.zeros((cap, 3))
        self._rot = np.tile(np.eye(3), (cap, 1, 1))
        self._vel = np.zeros((cap, 3))
        self._radius = np.zeros(cap)
        self._half = np.zeros((cap, 3))
        self._count = np.ones(cap, np.int64)
        self._local = np.zeros((cap, m, 3))
        self._lo = np.zeros((cap, 3))
        self._hi = np.zeros((cap, 3))
        self._world_points = np.zeros((cap, m, 3))

    def _grow(self, cap, m):
        old = {name: getattr(self, name) for name in ("_kind", "_center", "_rot", "_vel", "_radius", "_half",
                                                      "_count", "_local", "_lo", "_hi", "_world_points")}
        n_old, m_old = old["_kind"].shape[0], old["_local"].shape[1]
        self._alloc(cap, m)
        for name, arr in old.items():
            if name in ("_local", "_world_points"):
                getattr(self, name)[:n_old, :m_old] = arr
                getattr(self, name)[:n_old, m_old:] = arr[:, :1]  # padding repeats the first point
            else:
                getattr(self, name)[:n_old] = arr
        grown = np.full(cap, -1, np.int64)
        grown[:n_old] = self._body_leaf
        self._body_leaf = grown

    def _check_id(self, body_id, name="id", *, movable=True) -> int:
        if isinstance(body_id, bool) or not isinstance(body_id, int | np.integer):
            raise TypeError(f"{name} must be an int, got {type(body_id).__name__}")
        body_id = int(body_id)
        if not (0 <= body_id < self._n_ids and self._kind[body_id] >= 0):
            raise ValueError(f"{name} {body_id} is not a body of this world")
        if movable and body_id in self._grounds:
            raise ValueError(f"{name} {body_id} is a ground, which cannot move")
        return body_id

    def _refresh_aabbs(self, ids):
        """World points (center + R @ local) and AABBs (the points' min / max, grown by the radius) of ``ids``."""
        rot = self._rot[ids][:, None, :, :]
        local = self._local[ids]
        pts = (self._center[ids][:, None, :] + local[:, :, 0:1] * rot[..., 0] + local[:, :, 1:2] * rot[..., 1]
               + local[:, :, 2:3] * rot[..., 2])
        self._world_points[ids] = pts
        r = self._radius[ids][:, None]
        self._lo[ids] = pts.min(axis=1) - r
        self._hi[ids] = pts.max(axis=1) + r

    def _live_bodies(self) -> np.ndarray:
        live = np.flatnonzero(self._kind[: self._n_ids] >= 0)
        return live[self._kind[live] < PLANE]

    # -- tree bookkeeping ---------------------------------------------------------------------------------
    def _leaf_map(self, leaf, body):
        if leaf >= self._leaf_body.shape[0]:
            grown = np.full(2 * leaf + 2, -1, np.int64)
            grown[: self._leaf_body.shape[0]] = self._leaf_body
            self._leaf_body = grown
        self._leaf_body[leaf] = body
        self._body_leaf[body] = leaf

    def _rebuild_tree(self):
        bodies = self._live_bodies()
        self._tree = DynamicAABBTree.from_boxes(self._lo[bodies], self._hi[bodies])
        self._leaf_body = np.full(max(16, bodies.shape[0]), -1, np.int64)
        self._leaf_body[: bodies.shape[0]] = bodies
        self._body_leaf[:] = -1
        self._body_leaf[bodies] = np.arange(bodies.shape[0])

    # -- public: bodies -----------------------------------------------------------------------------------
    def add(self, shape, velocity=None) -> int:
        """Add a shape (Sphere, Box, Capsule, ConvexPolyhedron, Plane, HeightCurve); returns its id."""
        if not isinstance(shape, Shape):
            raise TypeError(f"shape must be an engine shape (Sphere, Box, ...), got {type(shape).__name__}")
        vel = np.zeros(3) if velocity is None else as_float_array(velocity, "velocity", shape=(3,))
        if self._free:
            body = self._free.pop()
        else:
            body = self._n_ids
            self._n_ids += 1
        m = 1 if shape.kind >= PLANE else shape.local.shape[0]
        cap = self._kind.shape[0]
        if body >= cap or m > self._local.shape[1]:
            self._grow(max(cap, 2 * body + 2), max(m, self._local.shape[1]))
        self._kind[body] = shape.kind
        self._shapes[body] = shape
        if shape.kind >= PLANE:
            self._grounds[body] = shape
            self._count[body] = 1
            self._local[body] = 0.0
            self._radius[body] = 0.0
            self._vel[body] = 0.0
            return body
        self._center[body] = shape.center
        self._rot[body] = shape.rotation
        self._vel[body] = vel
        self._radius[body] = shape.radius
        self._half[body] = shape.half_extents if shape.kind == BOX else 0.0
        self._count[body] = m
        self._local[body, :m] = shape.local
        self._local[body, m:] = shape.local[0]
        self._refresh_aabbs(np.array([body]))
        if self._tree is not None:
            self._leaf_map(self._tree.insert(self._lo[body], self._hi[body]), body)
        return body

    def remove(self, body_id) -> None:
        """Delete a body (or a ground); its id may be reused by a later ``add``."""
        body = self._check_id(body_id, movable=False)
        if body in self._grounds:
            del self._grounds[body]
        elif self._tree is not None:
            self._tree.remove(int(self._body_leaf[body]))
            self._leaf_body[self._body_leaf[body]] = -1
            self._body_leaf[body] = -1
        del self._shapes[body]
        self._kind[body] = -1
        self._free.append(body)

    def move(self, body_id, center=None, rotation=None, velocity=None) -> None:
        """New pose of one body: ``center`` (3,), ``rotation`` (3x3, columns = axes, or a unit quaternion),
        ``velocity`` (3,); the ones left None keep their value."""
        body = self._check_id(body_id)
        c = None if center is None else as_float_array(center, "center", shape=(3,))
        rot = None if rotation is None else as_rotation_matrix(rotation)
        v = None if velocity is None else as_float_array(velocity, "velocity", shape=(3,))
        if c is not None:
            self._center[body] = c
        if rot is not None:
            self._rot[body] = rot
        if v is not None:
            self._vel[body] = v
        self._refresh_aabbs(np.array([body]))
        if self._tree is not None:
            self._tree.move(int(self._body_leaf[body]), self._lo[body], self._hi[body])

    def update(self, ids, centers, rotations=None, velocities=None) -> None:
        """Move many bodies at once: ``ids`` (k,) distinct, ``centers`` (k, 3), ``rotations`` (k, 3, 3) (columns
        = axes) or (k, 4) unit quaternions, ``velocities`` (k, 3). One broad-phase refit: the tree is rebuilt
        top-down when more than REBUILD_THRESHOLD bodies move, else their leaves are moved."""
        idx = np.asarray(ids)
        if idx.dtype.kind not in "iu" or idx.ndim != 1:
            raise TypeError(f"ids must be a 1-D integer array, got dtype {idx.dtype} and shape {idx.shape}")
        idx = idx.astype(np.int64)
        k = idx.shape[0]
        bad = (idx < 0) | (idx >= self._n_ids)
        if not bad.any():
            bad = self._kind[idx] < 0
            bad |= self._kind[idx] >= PLANE
        if bad.any():
            raise ValueError(f"ids[{int(np.argmax(bad))}] = {int(idx[np.argmax(bad)])} is not a movable body")
        if np.unique(idx).shape[0] != k:
            raise ValueError("ids must be distinct")
        c = as_float_array(centers, "centers", shape=(k, 3))
        rot = None
        if rotations is not None:
            r = as_float_array(rotations, "rotations", ndim=None)
            if r.shape == (k, 4):
                norm = np.sqrt((r * r).sum(axis=1))
                if (np.abs(norm - 1.0) > 1e-9).any():
                    raise ValueError(f"rotations[{int(np.argmax(np.abs(norm - 1.0) > 1e-9))}] must be a unit "
                                     f"quaternion")
                rot = np.stack([as_rotation_matrix(q, "rotations") for q in r]) if k else np.empty((0, 3, 3))
            elif r.shape == (k, 3, 3):
                err = np.abs(np.matmul(r.transpose(0, 2, 1), r) - np.eye(3)).max(axis=(1, 2)) if k else np.zeros(0)
                det = np.linalg.det(r) if k else np.zeros(0)
                wrong = (err > 1e-9) | (det < 0)
                if wrong.any():
                    raise ValueError(f"rotations[{int(np.argmax(wrong))}] must be a proper orthonormal rotation")
                rot = r
            else:
                raise ValueError(f"rotations must have shape ({k}, 3, 3) or ({k}, 4), got {r.shape}")
        v = None if velocities is None else as_float_array(velocities, "velocities", shape=(k, 3))
        self._center[idx] = c
        if rot is not None:
            self._rot[idx] = rot
        if v is not None:
            self._vel[idx] = v
        self._refresh_aabbs(idx)
        if self._tree is None or k == 0:
            return
        if k > self.rebuild_threshold:
            self._rebuild_tree()
        else:
            for body in idx.tolist():
                self._tree.move(int(self._body_leaf[body]), self._lo[body], self._hi[body])

    def ids(self) -> np.ndarray:
        """Live ids (bodies and grounds), ascending."""
        return np.flatnonzero(self._kind[: self._n_ids] >= 0).astype(np.int64)

    def shape(self, body_id) -> Shape:
        """The shape added under ``body_id`` (its pose as added; the current pose is ``pose(id)``)."""
        return self._shapes[self._check_id(body_id, movable=False)]

    def pose(self, body_id):
        """``(center (3,), rotation (3, 3), velocity (3,))`` of a body (copies)."""
        body = self._check_id(body_id)
        return self._center[body].copy(), self._rot[body].copy(), self._vel[body].copy()

    def kind(self, body_id) -> str:
        return KIND_NAMES[self._kind[self._check_id(body_id, movable=False)]]

    def world_points(self, body_id) -> np.ndarray:
        """The body's core points in world coordinates (m, 3) (swept by ``radius(id)``)."""
        body = self._check_id(body_id)
        m = self._count[body]
        return self._center[body] + self._local[body, :m] @ self._rot[body].T

    def radius(self, body_id) -> float:
        return float(self._radius[self._check_id(body_id)])

    def aabb(self, body_id):
        body = self._check_id(body_id)
        return self._lo[body].copy(), self._hi[body].copy()

    # -- public: queries ----------------------------------------------------------------------------------
    def _candidates(self, lo=None, hi=None):
        """Broad phase: candidate pairs of ids (bodies among themselves, then bodies against grounds)."""
        bodies = self._live_bodies()
        if lo is None and self._tree is not None:
            leaf_pairs = self._tree.pairs()
            body_pairs = _canonical(self._leaf_body[leaf_pairs])
        else:
            lo = self._lo[bodies] if lo is None else lo
            hi = self._hi[bodies] if hi is None else hi
            rows = find_pairs(lo, hi, self.broad_phase) if bodies.shape[0] > 1 else np.empty((0, 2), np.int64)
            body_pairs = bodies[rows]
        ground_pairs = [self._ground_candidates(g, bodies, lo, hi) for g in sorted(self._grounds)]
        return body_pairs, ground_pairs, bodies

    def _ground_candidates(self, g, bodies, lo=None, hi=None):
        lo = self._lo[bodies] if lo is None else lo
        hi = self._hi[bodies] if hi is None else hi
        ground = self._grounds[g]
        if bodies.shape[0] == 0:
            return np.empty((0, 2), np.int64)
        if ground.kind == PLANE:
            hit = lo[:, 1] <= ground.altitude
        else:
            hit = overlap_aabb_curve(lo, hi, ground.f, samples=ground.samples)
        b = bodies[hit]
        return np.stack([np.minimum(b, g), np.maximum(b, g)], axis=1).astype(np.int64)

    def pairs(self) -> np.ndarray:
        """Canonical pairs (k, 2) int64 of ids whose shapes overlap (touching counts): broad phase, then the
        exact test of each candidate through the dispatch table."""
        body_pairs, ground_pairs, bodies = self._candidates()
        cand = np.concatenate([body_pairs] + ground_pairs) if ground_pairs else body_pairs
        mask, groups = overlap_groups(Geometry(self), cand)
        out = _canonical(cand[mask])
        self.stats = WorldStats(query="pairs", bodies=int(bodies.shape[0]), candidate_pairs=int(cand.shape[0]),
                                narrow_tests=int(cand.shape[0]), overlapping=int(out.shape[0]),
                                groups={f"{KIND_NAMES[a]}-{KIND_NAMES[b]}": n for (a, b), n in groups.items()})
        return out

    def contacts(self) -> ContactSet:
        """Contacts of the overlapping pairs (``ContactSet``). Body pairs: engine.narrowphase.contact_feature_pairs
        (GJK/EPA normal, supporting features, clipped contact points on the mid-plane). Body–ground pairs:
        closed form — normal ±y (Plane) or the curve's normal (−f'(x), 1) at the deepest sample (HeightCurve),
        points on the mid-plane between the body's lowest feature and the ground."""
        pairs = self.pairs()
        stats = self.stats
        k = pairs.shape[0]
        is_ground = np.isin(pairs, np.array(sorted(self._grounds), np.int64)).any(axis=1) if self._grounds \
            else np.zeros(k, np.bool_)
        sep = np.zeros(k)
        normal = np.zeros((k, 3))
        fa = np.zeros(k, np.int8)
        fb = np.zeros(k, np.int8)
        kinds = [""] * k
        point_lists: list = [None] * k
        geo = Geometry(self)
        body_rows = np.flatnonzero(~is_ground)
        if body_rows.size:
            s, n, a, b, kk, pts, offs = _contacts_of_pairs(geo.points, geo.offsets, pairs[body_rows], self._radius)
            sep[body_rows], normal[body_rows], fa[body_rows], fb[body_rows] = s, n, a, b
            for r, row in enumerate(body_rows.tolist()):
                kinds[row] = kk[r]
                point_lists[row] = pts[offs[r]:offs[r + 1]]
        ground_rows = np.flatnonzero(is_ground)
        for g in sorted(self._grounds):
            rows = ground_rows[(pairs[ground_rows] == g).any(axis=1)]
            if rows.size:
                self._ground_contacts(geo, g, pairs, rows, sep, normal, fa, fb, kinds, point_lists)
        counts = np.array([len(p) for p in point_lists], np.int64)
        offsets = np.zeros(k + 1, np.int64)
        np.cumsum(counts, out=offsets[1:])
        points = np.concatenate(point_lists) if k else np.empty((0, 3))
        stats.query = "contacts"
        stats.contacts = int(points.shape[0])
        self.stats = stats
        return ContactSet(pairs=pairs, separation=np.minimum(sep, 0.0), depth=np.maximum(-sep, 0.0), normal=normal,
                          feature_a=fa, feature_b=fb, kind=kinds, points=points, point_offsets=offsets)

    def _ground_contacts(self, geo, g, pairs, rows, sep, normal, fa, fb, kinds, point_lists):
        ground = self._grounds[g]
        bodies = np.where(pairs[rows, 0] == g, pairs[rows, 1], pairs[rows, 0])
        ground_first = pairs[rows, 0] == g
        sign = np.where(ground_first, 1.0, -1.0)[:, None]  # normal from the pair's first id to its second
        rounded = self._radius[bodies] > 0
        if ground.kind == PLANE:
            wp = geo.padded_points[bodies]
            valid = np.arange(wp.shape[1])[None, :] < self._count[bodies][:, None]
            y = np.where(valid, wp[:, :, 1], np.inf)
            low = y.min(axis=1)
            size = np.maximum(np.ptp(np.where(valid[:, :, None], wp, wp[:, :1]), axis=1).max(axis=1), 1.0)
            support = valid & (y <= (low + 1e-9 * size)[:, None])
            bottom = low - self._radius[bodies]
            mid = 0.5 * (bottom + ground.altitude)
            depth = ground.altitude - bottom
            up = np.array([0.0, 1.0, 0.0])
            feature = np.minimum(support.sum(axis=1), 3)
            for r, row in enumerate(rows.tolist()):
                p = wp[r][support[r]].copy()
                p[:, 1] = mid[r]
                point_lists[row] = p
            n_rows = up[None, :] * sign
        else:
            bnd = lower_boundary(geo, bodies, ground.samples)
            gap, x, y = ground_gap(ground, bnd)
            slope = ground.slope(x)
            n2 = np.stack([-slope, np.ones_like(slope)], axis=1) / np.sqrt(1 + slope ** 2)[:, None]
            depth = -gap * n2[:, 1]
            z = geo.center[bodies, 2]
            feature = np.ones(bodies.shape[0], np.int64)
            for r, row in enumerate(rows.tolist()):
                point_lists[row] = np.array([[x[r] + 0.5 * depth[r] * n2[r, 0], y[r] + 0.5 * depth[r] * n2[r, 1],
                                              z[r]]])
            n_rows = np.concatenate([n2, np.zeros((bodies.shape[0], 1))], axis=1) * sign
        sep[rows] = -depth
        normal[rows] = n_rows
        body_feature = feature.astype(np.int8)
        fa[rows] = np.where(ground_first, 3, body_feature)
        fb[rows] = np.where(ground_first, body_feature, 3)
        for r, row in enumerate(rows.tolist()):
            names = _ROUND_NAMES if rounded[r] else FEATURE_NAMES
            body_name = names[int(feature[r])]
            kinds[row] = f"face-{body_name}" if ground_first[r] else f"{body_name}-face"

    def time_of_impact(self, dt) -> ImpactSet:
        """Pairs that touch within ``dt`` (>= 0) while the bodies move with their velocities, with their first
        contact times (0 for pairs already touching). Broad phase on the swept AABBs, kinematic culling of the
        pairs apart and moving apart (engine.broadphase.cull_separating_box_pairs), then conservative
        advancement (engine.narrowphase.time_of_impact_pairs, distance within 1e-9 at the returned time);
        grounds: exact for Plane, bisection on the sampled gap for HeightCurve."""
        dt = as_nonnegative(dt, "dt")
        bodies = self._live_bodies()
        v = self._vel[bodies]
        lo, hi = self._lo[bodies], self._hi[bodies]
        sw_lo = np.minimum(lo, lo + v * dt)
        sw_hi = np.maximum(hi, hi + v * dt)
        rows = find_pairs(sw_lo, sw_hi, self.broad_phase) if bodies.shape[0] > 1 else np.empty((0, 2), np.int64)
        kept = cull_separating_box_pairs(rows, lo, hi, v) if rows.shape[0] else rows
        geo = Geometry(self)
        pts, offs = geo.points, geo.offsets
        # shape s of the packed arrays is body id s; velocities/radii by id
        vel_all = self._vel.copy()
        times = time_of_impact_pairs(pts, offs, vel_all, bodies[kept], t_max=dt, radii=self._radius) \
            if kept.shape[0] else np.empty(0)
        hit = np.isfinite(times)
        out_pairs = [bodies[kept][hit]]
        out_times = [times[hit]]
        n_ground_cand = 0
        for g in sorted(self._grounds):
            cand = self._ground_candidates(g, bodies, sw_lo, sw_hi)
            n_ground_cand += cand.shape[0]
            if cand.shape[0] == 0:
                continue
            gb = np.where(cand[:, 0] == g, cand[:, 1], cand[:, 0])
            t = self._ground_times(geo, self._grounds[g], gb, dt)
            ok = np.isfinite(t)
            out_pairs.append(cand[ok])
            out_times.append(t[ok])
        pairs = np.concatenate(out_pairs).astype(np.int64)
        times = np.concatenate(out_times)
        order = np.lexsort((pairs[:, 1], pairs[:, 0])) if pairs.shape[0] else np.empty(0, np.int64)
        self.stats = WorldStats(query="time_of_impact", bodies=int(bodies.shape[0]),
                                candidate_pairs=int(rows.shape[0] + n_ground_cand),
                                culled=int(rows.shape[0] - kept.shape[0]),
                                narrow_tests=int(kept.shape[0] + n_ground_cand), impacts=int(pairs.shape[0]))
        return ImpactSet(pairs=np.ascontiguousarray(pairs[order]), times=times[order])

    def _ground_times(self, geo, ground, bodies, dt, steps: int = 32, iterations: int = 60):
        """First t in [0, dt] at which each body (translating with its velocity) touches the ground; inf if none.
        Plane: exact (the lowest point moves linearly). Curve: the sampled gap at ``steps`` times brackets the
        first sign change, then Algorithme 3 (bisection), vectorised over the bodies."""
        v = self._vel[bodies]
        if ground.kind == PLANE:
            gap0 = geo.lowest_y(bodies) - ground.altitude
            with np.errstate(divide="ignore", invalid="ignore"):
                t = np.where(gap0 <= 0, 0.0, np.where(v[:, 1] < 0, gap0 / -v[:, 1], np.inf))
            return np.where(t <= dt, t, np.inf)
        bnd = lower_boundary(geo, bodies, ground.samples)  # (k, S, 2)

        def gap(t):
            moved = bnd + (t[:, None, None] * v[:, None, :2])
            return ground_gap(ground, moved)[0]

        k = bodies.shape[0]
        t_hit = np.full(k, np.inf)
        prev_t = np.zeros(k)
        g0 = gap(prev_t)
        t_hit[g0 <= 0] = 0.0
        lo_t = np.zeros(k)
        hi_t = np.full(k, np.nan)
        for s in range(1, steps + 1):
            t = np.full(k, dt * s / steps)
            pending = np.isinf(t_hit) & np.isnan(hi_t)
            if not pending.any():
                break
            crossed = pending & (gap(t) <= 0)
            hi_t[crossed] = t[crossed]
            lo_t[crossed] = dt * (s - 1) / steps
        todo = np.flatnonzero(~np.isnan(hi_t))
        a, b = lo_t[todo], hi_t[todo]
        sub = bnd[todo]
        vs = v[todo]
        for _ in range(iterations):  # Algorithme 3: keep the half whose ends have opposite signs
            m = 0.5 * (a + b)
            gm = ground_gap(ground, sub + m[:, None, None] * vs[:, None, :2])[0]
            inside = gm <= 0
            b = np.where(inside, m, b)
            a = np.where(inside, a, m)
        t_hit[todo] = b
        return t_hit
