"""``World``: the chapter's collision pipeline over bodies of mixed shapes, one compiled frame.

Slide "Pipeline de détection de collisions": pose upload → broad phase (bounding boxes; one of
engine.BROAD_PHASES, by default the dynamic AABB tree of fat boxes, Box2D's ``b2DynamicTree``) → the exact test
of every candidate pair through the dispatch tables (engine/world/dispatch.py: shape kind × shape kind → kernel)
→ "l'instant et le lieu précis (vertex, côtés, faces)": ``contacts()`` (where) and ``time_of_impact(dt)``
(when: "Méthode cinématique" culling of separating pairs, then the impact kernels).

A frame::

    world.update(ids, centers, rotations=quaternions)   # one validation pass, one compiled kernel
    contacts = world.contacts()                         # broad phase (kept across frames), compiled narrow phase

``update`` validates the whole batch (ids live, movable and distinct; finite centres; unit quaternions
(w, x, y, z), proper rotation matrices or a scipy Rotation; finite velocities) before it writes anything, then
refreshes the world points and AABBs of the batch in one compiled kernel (engine/world/bodies.py). The body
store is readable without copies (``bodies()``). Each query refreshes ``stats`` (the work and the time of each
stage). Contacts carry per-point feature ids and whether each point persists from the previous ``contacts()``.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import cast

import numpy as np

from engine._validate import as_choice, as_float_array, as_nonnegative
from engine.broadphase import BROAD_PHASES, cull_separating_box_pairs, find_pairs
from engine.narrowphase import time_of_impact_pairs
from engine.narrowphase.contacts import (
    DEFERRED,
    FEATURE_NAMES,
    TOUCHING,
    ContactSet,
    contact_rows,
    contact_set_from_rows,
    kernel_scratch,
    mark_persisting,
)

from .bodies import BodyArrays, BodyStore, as_rotation_batch, refresh_bodies
from .broad import make_broad_phase
from .convex import pack_cores
from .curve import curve_impact_times
from .dispatch import (
    ADVANCEMENT,
    CONTACT_TABLE,
    CURVE_TOI,
    DEFERRED_ROWS,
    GROUND_CANDIDATES,
    IMPACT_TABLE,
    OVERLAP_TABLE,
    answer_pairs,
    impact_pairs,
    overlapping_boxes,
    table_array,
)
from .shapes import BOX, KIND_NAMES, PLANE, Box, Shape, as_rotation

__all__ = ["World", "ContactSet", "ImpactSet", "WorldStats", "FEATURE_NAMES"]

_TABLES = {"overlap": table_array(OVERLAP_TABLE), "contact": table_array(CONTACT_TABLE),
           "impact": table_array(IMPACT_TABLE)}
# empty stand-ins for the optional arrays of the upload kernel (one compiled signature for every call)
_NO_VECTORS = np.empty((0, 3))
_NO_MATRICES = np.empty((0, 3, 3))
_NO_QUATERNIONS = np.empty((0, 4))


def _touching_in_order(cand, rows) -> np.ndarray:
    """The rows of the touching candidates, in lexicographic order of their pairs (canonical output)."""
    sel = np.flatnonzero(rows.status == TOUCHING)
    return sel[np.lexsort((cand[sel, 1], cand[sel, 0]))]


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
    ``culled`` (kinematic culling, time_of_impact only), ``narrow_tests`` (candidates whose AABBs overlap),
    ``overlapping`` (pairs that touch), ``contacts`` (contact points), ``persisting`` (points that persist from
    the previous contacts()), ``impacts``; ``groups`` {"sphere-box": narrow tests, ...}; ``seconds`` {"upload",
    "broad", "narrow", "contacts"}: wall time of each stage (upload: the updates since the previous query)."""

    query: str = ""
    bodies: int = 0
    candidate_pairs: int = 0
    culled: int = 0
    narrow_tests: int = 0
    overlapping: int = 0
    contacts: int = 0
    persisting: int = 0
    impacts: int = 0
    groups: dict = field(default_factory=dict)
    seconds: dict = field(default_factory=dict)

    def as_dict(self) -> dict:
        return dict(self.__dict__)


class World:
    """A collision world: ``World(broad_phase="tree")`` (any of engine.BROAD_PHASES).

    - ``add(shape, velocity=None) -> id``; ``remove(id)``; ``move(id, center=None, rotation=None,
      velocity=None)``; ``update(ids, centers, rotations=None, velocities=None)`` moves a batch;
    - ``pairs()`` -> canonical (k, 2) int64 ids of overlapping shapes; ``contacts()`` -> ``ContactSet``;
      ``time_of_impact(dt)`` -> ``ImpactSet`` (bodies move with their constant velocities; grounds are fixed);
    - ``stats`` (``WorldStats``): the work of each stage in the last query; ``bodies()``: the body store.

    Ids are ints, reused after ``remove``. Grounds (``Plane``, ``HeightCurve``) take ids too but cannot move.
    """

    def __init__(self, broad_phase: str = "tree"):
        self.broad_phase = as_choice(broad_phase, "broad_phase", BROAD_PHASES)
        self._store = BodyStore()
        self._shapes: dict = {}
        self._grounds: dict = {}
        self._broad = make_broad_phase(self.broad_phase)
        self._previous = (np.empty((0, 2), np.int64), np.empty(0, np.int64))
        self._upload_seconds = 0.0
        self.stats = WorldStats()

    @property
    def rebuild_threshold(self) -> int:
        """Tree broad phase: more bodies than this leaving their fat boxes (or added) since the last query rebuild
        the tree; SAP: more bodies than this added since the last query rebuild the sweep over every body."""
        return getattr(self._broad, "rebuild_threshold", 0)

    @rebuild_threshold.setter
    def rebuild_threshold(self, value: int) -> None:
        if hasattr(self._broad, "rebuild_threshold"):
            self._broad.rebuild_threshold = int(value)

    # -- bodies --------------------------------------------------------------------------------------------
    def add(self, shape, velocity=None) -> int:
        """Add a shape (Sphere, Box, Capsule, ConvexPolyhedron, Plane, HeightCurve); returns its id."""
        if not isinstance(shape, Shape):
            raise TypeError(f"shape must be an engine shape (Sphere, Box, ...), got {type(shape).__name__}")
        vel = np.zeros(3) if velocity is None else as_float_array(velocity, "velocity", shape=(3,))
        ground = shape.kind >= PLANE
        st = self._store
        body = st.new_id(1 if ground else shape.local.shape[0])
        st.kind[body] = shape.kind
        self._shapes[body] = shape
        if ground:
            self._grounds[body] = shape
            st.center[body] = (0.0, getattr(shape, "altitude", 0.0), 0.0)
            st.rotation[body] = np.eye(3)
            st.velocity[body] = st.radius[body] = st.half[body] = 0.0
            st.count[body] = 1
            st.local[body] = st.points[body] = 0.0
            st.lo[body] = -np.inf
            st.hi[body] = (np.inf, st.center[body, 1] if shape.kind == PLANE else np.inf, np.inf)
            return body
        m = shape.local.shape[0]
        st.radius[body] = shape.radius
        st.half[body] = cast(Box, shape).half_extents if shape.kind == BOX else 0.0
        st.count[body] = m
        st.local[body, :m] = shape.local
        st.local[body, m:] = shape.local[0]
        self._broad.add(st, body)
        refresh_bodies(st.view(), np.array([body]), shape.center[None], 1,
                       np.ascontiguousarray(shape.rotation, dtype=np.float64)[None], _NO_QUATERNIONS, vel[None])
        return body

    def remove(self, body_id) -> None:
        """Delete a body (or a ground); its id may be reused by a later ``add``."""
        body = self._check_id(body_id, movable=False)
        if body in self._grounds:
            del self._grounds[body]
        else:
            self._broad.remove(self._store, body)
        del self._shapes[body]
        self._store.release(body)

    def move(self, body_id, center=None, rotation=None, velocity=None) -> None:
        """New pose of one body: ``center`` (3,), ``rotation`` (3x3, columns = axes; a unit quaternion (w, x,
        y, z); or a scipy Rotation), ``velocity`` (3,); the ones left None keep their value."""
        body = self._check_id(body_id)
        st = self._store
        c = st.center[body] if center is None else as_float_array(center, "center", shape=(3,))
        rot = None if rotation is None else as_rotation(rotation)
        v = _NO_VECTORS if velocity is None else as_float_array(velocity, "velocity", shape=(3,))[None]
        refresh_bodies(st.view(), np.array([body]), np.array(c)[None], 0 if rot is None else 1,
                       _NO_MATRICES if rot is None else np.ascontiguousarray(rot, dtype=np.float64)[None],
                       _NO_QUATERNIONS, v)

    def update(self, ids, centers, rotations=None, velocities=None) -> None:
        """Move many bodies at once: ``ids`` (k,) distinct, ``centers`` (k, 3), ``rotations`` (k, 3, 3) (columns
        = axes), (k, 4) unit quaternions (w, x, y, z) or a scipy Rotation of length k, ``velocities`` (k, 3).
        Everything is checked before anything is written (ValueError naming the argument and the index; the
        world is then unchanged); the caller's arrays are never modified."""
        t0 = time.perf_counter()
        st = self._store
        idx = st.check_ids(ids)
        k = idx.shape[0]
        c = as_float_array(centers, "centers", shape=(k, 3))
        mode, rot = (0, None) if rotations is None else as_rotation_batch(rotations, k)
        v = _NO_VECTORS if velocities is None else as_float_array(velocities, "velocities", shape=(k, 3))
        refresh_bodies(st.view(), idx, c, mode, rot if mode == 1 else _NO_MATRICES,
                       rot if mode == 2 else _NO_QUATERNIONS, v)
        self._upload_seconds += time.perf_counter() - t0

    def _check_id(self, body_id, name="id", *, movable=True) -> int:
        if isinstance(body_id, bool) or not isinstance(body_id, int | np.integer):
            raise TypeError(f"{name} must be an int, got {type(body_id).__name__}")
        body = int(body_id)
        if not (0 <= body < self._store.n_ids and self._store.kind[body] >= 0):
            raise ValueError(f"{name} {body} is not a body of this world")
        if movable and body in self._grounds:
            raise ValueError(f"{name} {body} is a ground, which cannot move")
        return body

    def ids(self) -> np.ndarray:
        """Live ids (bodies and grounds), ascending."""
        return self._store.live().astype(np.int64)

    def bodies(self) -> BodyArrays:
        """The body store (engine/world/bodies.py) as read-only views of rows 0..max id (no copy; rows of
        removed ids have kind −1)."""
        n = self._store.n_ids
        views = []
        for arr in self._store.view():
            v = arr[:n]
            v.flags.writeable = False
            views.append(v)
        return BodyArrays(*views)

    def shape(self, body_id) -> Shape:
        """The shape added under ``body_id`` (its pose as added; the current pose is ``pose(id)``)."""
        return self._shapes[self._check_id(body_id, movable=False)]

    def pose(self, body_id):
        """``(center (3,), rotation (3, 3), velocity (3,))`` of a body (copies)."""
        b = self._check_id(body_id)
        return self._store.center[b].copy(), self._store.rotation[b].copy(), self._store.velocity[b].copy()

    def kind(self, body_id) -> str:
        return KIND_NAMES[self._store.kind[self._check_id(body_id, movable=False)]]

    def world_points(self, body_id) -> np.ndarray:
        """The body's core points in world coordinates (m, 3) (swept by ``radius(id)``)."""
        b = self._check_id(body_id)
        return self._store.points[b, : self._store.count[b]].copy()

    def radius(self, body_id) -> float:
        return float(self._store.radius[self._check_id(body_id)])

    def aabb(self, body_id):
        b = self._check_id(body_id)
        return self._store.lo[b].copy(), self._store.hi[b].copy()

    # -- the frame -----------------------------------------------------------------------------------------
    def _live_bodies(self) -> np.ndarray:
        live = self._store.live()
        return live[self._store.kind[live] < PLANE]

    def _ground_candidates(self, bodies, lo, hi) -> list:
        out = []
        for g in sorted(self._grounds):
            hit = bodies[GROUND_CANDIDATES[self._store.kind[g]](self._grounds[g], lo, hi)]
            out.append(np.stack([np.minimum(hit, g), np.maximum(hit, g)], axis=1).astype(np.int64))
        return out

    def _candidates(self):
        """Broad phase: candidate pairs of ids, i < j per row, no repeat, in no particular order (bodies among
        themselves, then against the grounds)."""
        bodies = self._live_bodies()
        cand = self._broad.candidates(self._store, bodies)
        if self._grounds:
            st = self._store
            cand = np.concatenate([cand, *self._ground_candidates(bodies, st.lo[bodies], st.hi[bodies])])
        return np.ascontiguousarray(cand), bodies

    def _answer(self, table: str):
        """Broad phase, then the narrow phase of every candidate through ``table``: (pairs, rows, stats)."""
        t0 = time.perf_counter()
        cand, bodies = self._candidates()
        view = self._store.view()
        counts = np.zeros((len(KIND_NAMES), len(KIND_NAMES)), np.int64)
        tested = cand.shape[0]
        cand = overlapping_boxes(view, cand, counts)
        t1 = time.perf_counter()
        rows = contact_rows(cand.shape[0])
        answer_pairs(view, cand, _TABLES[table], rows, kernel_scratch(view.points.shape[1]))
        deferred = np.flatnonzero(rows.status == DEFERRED)
        if deferred.size:
            kinds = self._store.kind[cand[deferred]]
            codes = _TABLES[table][kinds[:, 0], kinds[:, 1]]
            for code in np.unique(codes).tolist():
                DEFERRED_ROWS[code](view, cand, deferred[codes == code], rows, self._grounds)
        t2 = time.perf_counter()
        groups = {f"{KIND_NAMES[a]}-{KIND_NAMES[b]}": int(counts[a, b]) for a, b in zip(*counts.nonzero())}
        stats = WorldStats(bodies=int(bodies.shape[0]), candidate_pairs=int(tested), narrow_tests=int(cand.shape[0]),
                           groups=groups,
                           seconds={"upload": self._upload_seconds, "broad": t1 - t0, "narrow": t2 - t1})
        self._upload_seconds = 0.0
        return cand, rows, stats

    def pairs(self) -> np.ndarray:
        """Canonical pairs (k, 2) int64 of ids whose shapes overlap (touching counts): broad phase, then the
        exact test of each candidate through the overlap table."""
        cand, rows, stats = self._answer("overlap")
        out = np.ascontiguousarray(cand[_touching_in_order(cand, rows)])
        stats.query, stats.overlapping = "pairs", int(out.shape[0])
        self.stats = stats
        return out

    def contacts(self) -> ContactSet:
        """Contacts of the overlapping pairs (``ContactSet``: pairs, depth, normal from the first id to the
        second, features, points, point ids and whether each point persists from the previous call), through
        the contact table: closed forms for sphere–sphere, sphere–box, sphere–capsule, capsule–capsule, box–box
        and every body on a Plane; GJK/EPA with the contact features for the others; the curve rows."""
        cand, rows, stats = self._answer("contact")
        t0 = time.perf_counter()
        radius = self._store.radius[cand]
        out = contact_set_from_rows(rows, cand, radius[:, 0], radius[:, 1], keep=_touching_in_order(cand, rows))
        prev_pairs, prev_ids = self._previous
        point_ids, persists = out.point_ids, out.persists
        assert point_ids is not None and persists is not None  # contact_set_from_rows always sets both
        mark_persisting(prev_pairs, prev_ids, out.pairs, out.point_offsets, point_ids, persists)
        owner = np.repeat(out.pairs, np.diff(out.point_offsets), axis=0)
        order = np.lexsort((point_ids, owner[:, 1], owner[:, 0]))
        self._previous = (np.ascontiguousarray(owner[order]), point_ids[order])
        stats.seconds["contacts"] = time.perf_counter() - t0
        stats.query, stats.overlapping = "contacts", len(out)
        stats.contacts, stats.persisting = int(out.points.shape[0]), int(persists.sum())
        self.stats = stats
        return out

    def time_of_impact(self, dt) -> ImpactSet:
        """Pairs that touch within ``dt`` (>= 0) while the bodies move with their velocities, with their first
        contact times (0 for pairs already touching). Broad phase on the swept AABBs, kinematic culling of the
        pairs apart and moving apart (engine.broadphase.cull_separating_box_pairs), then the impact table:
        closed forms for two spheres and a body over a Plane, conservative advancement for the other bodies
        (engine.narrowphase.time_of_impact_pairs, distance within 1e-9 at the returned time), bisection on the
        sampled gap for a HeightCurve."""
        dt = as_nonnegative(dt, "dt")
        st = self._store
        bodies = self._live_bodies()
        v = st.velocity[bodies]
        lo, hi = st.lo[bodies], st.hi[bodies]
        sw_lo, sw_hi = np.minimum(lo, lo + v * dt), np.maximum(hi, hi + v * dt)
        rows = find_pairs(sw_lo, sw_hi, self.broad_phase) if bodies.shape[0] > 1 else np.empty((0, 2), np.int64)
        kept = cull_separating_box_pairs(rows, lo, hi, v) if rows.shape[0] else rows
        ground = self._ground_candidates(bodies, sw_lo, sw_hi)
        cand = np.ascontiguousarray(np.concatenate([bodies[kept], *ground]) if ground else bodies[kept])
        times = np.full(cand.shape[0], np.inf)
        deferred = np.zeros(cand.shape[0], np.bool_)
        view = st.view()
        impact_pairs(view, cand, _TABLES["impact"], dt, times, deferred)
        self._deferred_impacts(view, cand, np.flatnonzero(deferred), dt, times)
        hit = np.isfinite(times)
        pairs, times = cand[hit], times[hit]
        order = np.lexsort((pairs[:, 1], pairs[:, 0]))
        self.stats = WorldStats(query="time_of_impact", bodies=int(bodies.shape[0]),
                                candidate_pairs=int(rows.shape[0] + sum(g.shape[0] for g in ground)),
                                culled=int(rows.shape[0] - kept.shape[0]), narrow_tests=int(cand.shape[0]),
                                impacts=int(pairs.shape[0]))
        return ImpactSet(pairs=np.ascontiguousarray(pairs[order]), times=times[order])

    def _deferred_impacts(self, view, cand, sel, dt, times) -> None:
        """The impact rows answered by batched calls: conservative advancement, and the curve grounds."""
        if sel.size == 0:
            return
        kinds = self._store.kind[cand[sel]]
        codes = _TABLES["impact"][kinds[:, 0], kinds[:, 1]]
        adv = sel[codes == ADVANCEMENT]
        if adv.size:
            points, offsets, local, radii = pack_cores(view, cand[adv])
            ids = np.unique(cand[adv])
            times[adv] = time_of_impact_pairs(points, offsets, self._store.velocity[ids], local, t_max=dt,
                                              radii=radii)
        curve = sel[codes == CURVE_TOI]
        for g in np.unique(cand[curve][np.isin(cand[curve], list(self._grounds))]).tolist():
            rows = curve[(cand[curve] == g).any(axis=1)]
            body = np.where(cand[rows, 0] == g, cand[rows, 1], cand[rows, 0])
            times[rows] = curve_impact_times(view, self._grounds[g], body, dt)
