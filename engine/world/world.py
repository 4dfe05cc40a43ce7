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
    """The answer of ``World.time_of_impact(dt)``: the pairs that touch within dt and when.

    ``len(impacts)`` is k.

    Attributes
    ----------
    pairs : numpy.ndarray, shape (k, 2), int64
        Canonical pairs of ids (i < j per row, rows in lexicographic order).
    times : numpy.ndarray, shape (k,), float64
        The first-contact time of each pair, in [0, dt] (0 for a pair already touching).
    """

    pairs: np.ndarray
    times: np.ndarray

    def __len__(self) -> int:
        return int(self.pairs.shape[0])


@dataclass
class WorldStats:
    """The work and the time of each stage in a ``World``'s last query (``world.stats``).

    Attributes
    ----------
    query : str
        "pairs", "contacts" or "time_of_impact".
    bodies : int
        Live bodies (grounds excluded).
    candidate_pairs : int
        Pairs the broad phase returned, bodies and grounds.
    culled : int
        Candidates dropped by the kinematic culling (pairs apart and moving apart; ``time_of_impact`` only).
    narrow_tests : int
        Candidates whose boxes overlap, tested exactly.
    overlapping : int
        Pairs that touch.
    contacts, persisting : int
        Contact points, and those that persist from the previous ``contacts()``.
    impacts : int
        Pairs that touch within dt (``time_of_impact``).
    groups : dict of str to int
        Narrow tests per shape-kind pair, e.g. ``{"sphere-box": 12}``.
    seconds : dict of str to float
        Wall time of the stages "upload" (the updates since the previous query), "broad", "narrow" and
        "contacts".
    """

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
        """The statistics as a plain dict (field name to value), e.g. for a table or JSON.

        Returns
        -------
        dict
            A shallow copy of the fields.
        """
        return dict(self.__dict__)


class World:
    """A collision world: bodies of mixed shapes, and the chapter's pipeline over them.

    Each query runs broad phase (bounding boxes kept across frames; by default the dynamic AABB tree of fat boxes)
    → the exact test of every candidate pair through the dispatch tables (shape kind × shape kind → kernel) →
    ``contacts()`` (where) or ``time_of_impact(dt)`` (when). Bodies are added once (``add``), then moved a batch at a
    time (``update``) or one by one (``move``). Ids are ints, reused after ``remove``; grounds (``Plane``,
    ``HeightCurve``) take ids too but cannot move. World is y-up.

    Parameters
    ----------
    broad_phase : str, default "tree"
        A name of ``engine.BROAD_PHASES``.

    Attributes
    ----------
    broad_phase : str
        As given.
    stats : WorldStats
        The work of each stage in the last query.

    Raises
    ------
    ValueError, TypeError
        For an unknown ``broad_phase``, or one that is not a string.

    Examples
    --------
    A ball of radius 0.5 resting 0.1 deep on a box, then thrown at it from above:

    >>> from engine import Box, Sphere, World
    >>> world = World()
    >>> ball = world.add(Sphere([0.0, 1.0, 0.0], 0.5))
    >>> table = world.add(Box([0.0, 0.0, 0.0], [1.0, 0.6, 1.0]))
    >>> world.pairs()
    array([[0, 1]])
    >>> contacts = world.contacts()
    >>> contacts.kind, contacts.depth.round(12), contacts.points_of(0)
    (['sphere-face'], array([0.1]), array([[0.  , 0.55, 0.  ]]))
    >>> world.update([ball], [[0.0, 3.0, 0.0]], velocities=[[0.0, -2.0, 0.0]])
    >>> world.time_of_impact(1.0).times
    array([0.95])
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
        """Add a shape; returns its id.

        Parameters
        ----------
        shape : Shape
            A ``Sphere``, ``Box``, ``Capsule``, ``ConvexPolyhedron``, ``Plane`` or ``HeightCurve``; its pose as built.
        velocity : array_like, shape (3,), optional
            Its constant velocity for ``time_of_impact``; default zero (ignored for grounds).

        Returns
        -------
        int
            The new id (the smallest free one).

        Raises
        ------
        TypeError
            When ``shape`` is not an engine shape.
        ValueError
            For a velocity not of shape (3,) or not finite.
        """
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
        """Delete a body or a ground; its id may be reused by a later ``add``.

        Parameters
        ----------
        body_id : int
            A live id.

        Raises
        ------
        ValueError
            For an id that is not in this world; ``TypeError`` for a non-integer id.
        """
        body = self._check_id(body_id, movable=False)
        if body in self._grounds:
            del self._grounds[body]
        else:
            self._broad.remove(self._store, body)
        del self._shapes[body]
        self._store.release(body)

    def move(self, body_id, center=None, rotation=None, velocity=None) -> None:
        """Set the pose of one body; the arguments left None keep their value.

        Parameters
        ----------
        body_id : int
            A live body (not a ground).
        center : array_like, shape (3,), optional
            The new position.
        rotation : array_like or scipy.spatial.transform.Rotation, optional
            A (3, 3) rotation matrix (columns = the body's axes), a unit quaternion (w, x, y, z) or a scipy Rotation.
        velocity : array_like, shape (3,), optional
            The new constant velocity.

        Raises
        ------
        ValueError
            For a ground or an unknown id, or a bad vector or rotation (named); the body is then unchanged.
        """
        body = self._check_id(body_id)
        st = self._store
        c = st.center[body] if center is None else as_float_array(center, "center", shape=(3,))
        rot = None if rotation is None else as_rotation(rotation)
        v = _NO_VECTORS if velocity is None else as_float_array(velocity, "velocity", shape=(3,))[None]
        refresh_bodies(st.view(), np.array([body]), np.array(c)[None], 0 if rot is None else 1,
                       _NO_MATRICES if rot is None else np.ascontiguousarray(rot, dtype=np.float64)[None],
                       _NO_QUATERNIONS, v)

    def update(self, ids, centers, rotations=None, velocities=None) -> None:
        """Move many bodies at once, in one validation pass and one compiled kernel.

        Everything is checked before anything is written: on an error the world is unchanged. The caller's arrays
        are never modified.

        Parameters
        ----------
        ids : array_like, shape (k,), int
            Distinct live bodies (not grounds).
        centers : array_like, shape (k, 3), float64
            Their new positions.
        rotations : array_like or scipy.spatial.transform.Rotation, optional
            (k, 3, 3) rotation matrices (columns = axes), (k, 4) unit quaternions (w, x, y, z), or a scipy Rotation of
            length k; default: rotations unchanged.
        velocities : array_like, shape (k, 3), optional
            New constant velocities; default unchanged.

        Raises
        ------
        ValueError
            Naming the argument and the first bad index: an unknown, ground or repeated id, a non-finite value, a
            wrong shape, a non-unit quaternion or an improper matrix.
        TypeError
            For ids that are not a 1-D integer array.
        """
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
        """The live ids, bodies and grounds.

        Returns
        -------
        numpy.ndarray, shape (n,), int64
            Ascending.
        """
        return self._store.live().astype(np.int64)

    def bodies(self) -> BodyArrays:
        """The body store as read-only views of rows 0 to the largest id (no copy).

        Returns
        -------
        BodyArrays
            The structure-of-arrays store of ``engine.world.bodies`` (kind, centre, rotation, velocity, radius,
            points, AABBs ...); rows of removed ids have kind −1.
        """
        n = self._store.n_ids
        views = []
        for arr in self._store.view():
            v = arr[:n]
            v.flags.writeable = False
            views.append(v)
        return BodyArrays(*views)

    def shape(self, body_id) -> Shape:
        """The shape added under ``body_id``, with its pose as added (the current pose is ``pose(body_id)``).

        Parameters
        ----------
        body_id : int
            A live id (bodies and grounds).

        Returns
        -------
        Shape
        """
        return self._shapes[self._check_id(body_id, movable=False)]

    def pose(self, body_id):
        """The current pose and velocity of a body.

        Parameters
        ----------
        body_id : int
            A live body (grounds have no pose).

        Returns
        -------
        center : numpy.ndarray, shape (3,), float64
            Its position (a copy).
        rotation : numpy.ndarray, shape (3, 3), float64
            Columns = its axes in the world.
        velocity : numpy.ndarray, shape (3,), float64
            Its constant velocity.
        """
        b = self._check_id(body_id)
        return self._store.center[b].copy(), self._store.rotation[b].copy(), self._store.velocity[b].copy()

    def kind(self, body_id) -> str:
        """The kind of a body or ground, by name.

        Parameters
        ----------
        body_id : int
            Any live id, grounds included.

        Returns
        -------
        str
            "sphere", "box", "capsule", "hull", "plane" or "curve".
        """
        return KIND_NAMES[self._store.kind[self._check_id(body_id, movable=False)]]

    def world_points(self, body_id) -> np.ndarray:
        """The body's core points in world coordinates, swept by ``radius(body_id)``.

        Parameters
        ----------
        body_id : int
            The body whose points to return.

        Returns
        -------
        numpy.ndarray, shape (m, 3), float64
            A copy; m = 1 for a sphere, 2 for a capsule, 8 for a box, the hull's vertex count for a polyhedron.
        """
        b = self._check_id(body_id)
        return self._store.points[b, : self._store.count[b]].copy()

    def radius(self, body_id) -> float:
        """The radius that sweeps a body's core (0 for boxes and polyhedra).

        Parameters
        ----------
        body_id : int
            Which body.

        Returns
        -------
        float
        """
        return float(self._store.radius[self._check_id(body_id)])

    def aabb(self, body_id):
        """A body's current axis-aligned bounding box (the exact box of its swept core).

        Parameters
        ----------
        body_id : int
            A body's id; a ground is refused (ValueError), as in ``pose``.

        Returns
        -------
        lo, hi : numpy.ndarray, shape (3,), float64
            Its corners (copies).
        """
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
        """Canonical pairs of ids whose shapes overlap (touching counts).

        The broad phase, then the exact test of each candidate through the overlap table. Refreshes ``stats``.

        Returns
        -------
        numpy.ndarray, shape (k, 2), int64
            i < j in every row, rows in lexicographic order, no repeat.
        """
        cand, rows, stats = self._answer("overlap")
        out = np.ascontiguousarray(cand[_touching_in_order(cand, rows)])
        stats.query, stats.overlapping = "pairs", int(out.shape[0])
        self.stats = stats
        return out

    def contacts(self) -> ContactSet:
        """The contacts of the overlapping pairs, with per-point feature ids that persist across frames.

        Through the contact table: closed forms for sphere–sphere, sphere–box, sphere–capsule, capsule–capsule,
        box–box and every body on a Plane; GJK/EPA with the contact features for the others; the curve rows for a
        HeightCurve. Each point's id names the two features that made it (Box2D's ``b2ContactFeature``) and
        ``persists`` says whether the same pair had the same id in the previous call. Refreshes ``stats``.

        Returns
        -------
        ContactSet
            One row per touching pair (the canonical order of ``pairs()``), normals from the first id to the second,
            at most 4 points per pair, with ``point_ids`` and ``persists``.
        """
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
        """The pairs that touch within ``dt`` while the bodies move with their velocities, and when.

        Broad phase on the swept boxes, kinematic culling of the pairs apart and moving apart
        (``engine.broadphase.cull_separating_box_pairs``), then the impact table: closed forms for two spheres and a
        body over a Plane, conservative advancement for the other bodies (``engine.narrowphase.time_of_impact_pairs``,
        distance within 1e-9 at the returned time), bisection on the sampled gap for a HeightCurve. Grounds are fixed;
        the poses are not changed. Refreshes ``stats``.

        Parameters
        ----------
        dt : float
            The time window, >= 0.

        Returns
        -------
        ImpactSet
            The pairs (canonical) and their first-contact times in [0, dt] (0 for pairs already touching).

        Raises
        ------
        ValueError
            For a negative or non-finite ``dt``.
        engine.narrowphase.TOINotConverged
            When conservative advancement reaches its iteration cap on a pair.
        """
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
