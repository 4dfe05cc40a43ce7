"""``World``: the chapter's collision pipeline over bodies of mixed shapes, as a game declares them.

Slide "Pipeline de détection de collisions": pose upload → broad phase (bounding boxes; one of
engine.BROAD_PHASES for the moving bodies, by default the dynamic AABB tree of fat boxes, Box2D's
``b2DynamicTree``; a tree of its own for the static level geometry, engine/world/broad.py) → the collision
filter (engine/world/filters.py) → the exact test of every remaining pair through the dispatch table
(engine/world/dispatch.py, rows in engine/world/rows.py: shape kind × shape kind → kernel) → "l'instant et le lieu
précis (vertex, côtés, faces)": ``contacts()`` (where) and ``time_of_impact(dt)`` (when: "Méthode cinématique"
culling of separating pairs, then the impact kernels). ``events()`` reports the pairs that began and ended
touching. The questions a game asks of the world between frames: rays (``cast_rays``, ``cast_ray``:
engine/world/ray_cast.py), a shape swept or placed (``cast_shape``, ``overlap``) and a box (``query_aabb``:
engine/world/shape_queries.py), distances (``closest_points``, ``pairs_within``: the table's "distance" rows).

A frame::

    world.update(ids, centers, rotations=quaternions)   # one compiled kernel: checks, then writes
    contacts = world.contacts()                         # broad phase (kept across frames), compiled narrow phase

``update`` checks the whole batch (ids live, movable and distinct; finite centres; unit quaternions
(w, x, y, z), proper rotation matrices or a scipy Rotation; finite velocities) inside its compiled kernel before it
writes anything — a refused batch raises from Python, naming the argument and its first bad index —, then
refreshes the world points and AABBs of the batch in the same kernel (engine/world/bodies.py). The body
store is readable without copies (``bodies()``). Each query refreshes ``stats`` (the work and the time of each
stage). Contacts carry per-point feature ids and whether each point persists from the previous ``contacts()``.
"""
from __future__ import annotations

import itertools
import time
from dataclasses import dataclass, field

import numpy as np

from engine._validate import MAX_MAGNITUDE, as_choice, as_float_array, as_nonnegative
from engine.bounding.aabb import ROTATION_TOL
from engine.broadphase import BROAD_PHASES, DynamicAABBTree, cull_separating_box_pairs, find_pairs
from engine.broadphase.ray_grid import build_ray_grid
from engine.narrowphase.contacts import (
    FEATURE_NAMES,
    TOUCHING,
    ContactSet,
    kernel_scratch,
)

from .bodies import BAD_CENTERS, BAD_IDS, BAD_ROTATIONS, UPLOAD_OK, BodyArrays, BodyStore, refresh_bodies, upload_bodies
from .broad import StaticPairs, fatten, fatten_around, make_broad_phase
from .dispatch import NarrowContext, answer
from .filters import ALL, Exclusions, as_bits, as_group
from .kinds import KINDS
from .ray_cast import (
    GRID,
    LIST,
    TREE,
    RayHit,
    RayHits,
    RayScene,
    as_rays,
    cast_ray_batch,
    check_threads,
    forest_of,
)
from .ray_rows import RAY_ROWS, SURFACE_KINDS, ray_bodies, ray_surfaces
from .record import contact_record
from .rows import TABLE
from .shape_queries import ShapeHit, as_box, as_query_shape, bodies_in_box, cast, overlapping_bodies
from .shapes import Shape, as_rotation, as_rotation_batch

__all__ = ["World", "ContactSet", "ImpactSet", "WorldStats", "RayHits", "RayHit", "FEATURE_NAMES"]

# empty stand-ins for the optional arrays of the upload kernel (one compiled signature for every call)
_NO_VECTORS = np.empty((0, 3))
_NO_MATRICES = np.empty((0, 3, 3))
_NO_QUATERNIONS = np.empty((0, 4))
_NO_PAIRS = np.empty((0, 2), np.int64)
#: the rays' tree is built again when its summed node sides, over the root's, grow past this factor of the value
#: it had when built (the bodies moved far from where it was built)
RAY_TREE_DECAY = 1.5


def _canonical_order(pairs: np.ndarray) -> np.ndarray:
    return np.lexsort((pairs[:, 1], pairs[:, 0]))


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
        "pairs", "contacts", "time_of_impact" or "events".
    bodies : int
        Live moving bodies (static bodies and grounds excluded).
    candidate_pairs : int
        Pairs the broad phase returned: moving bodies among themselves, against the static bodies and against
        the grounds.
    static_pairs : int
        Those of them with a static body or a ground.
    filtered : int
        Candidates whose boxes overlap (any candidate for ``time_of_impact``) that the filter dropped before the
        narrow phase (category / mask / group, excluded pairs, two sensors; for ``contacts`` and
        ``time_of_impact`` every pair with a sensor).
    culled : int
        Candidates dropped by the kinematic culling (pairs apart and moving apart; ``time_of_impact`` only).
    narrow_tests : int
        Pairs tested exactly (a compound's: pairs of its parts whose boxes overlap); for ``time_of_impact`` the
        overlap tests of the pairs whose boxes overlap at the start plus the impact tests of those not touching.
    overlapping : int
        Pairs that touch (``contacts``: pairs of parts).
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
    static_pairs: int = 0
    filtered: int = 0
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


def _as_ids(ids) -> np.ndarray:
    """ids as a 1-D int64 array (TypeError naming ``ids`` otherwise); the upload kernel checks the values."""
    idx = np.asarray(ids)
    if idx.dtype.kind not in "iu" or idx.ndim != 1:
        raise TypeError(f"ids must be a 1-D integer array, got dtype {idx.dtype} and shape {idx.shape}")
    return idx if idx.dtype == np.int64 else idx.astype(np.int64)


def _as_rows(value, name: str, shape: tuple) -> np.ndarray:
    """A float64 array of the given shape for the upload kernel, which checks its values: a float64 array of that
    shape is read as it is (no copy when contiguous); anything else goes through ``as_float_array`` (a checked
    copy)."""
    if isinstance(value, np.ndarray) and value.dtype == np.float64 and value.shape == shape:
        return np.ascontiguousarray(value)
    return as_float_array(value, name, shape=shape)


def _as_rotations(rotations, k: int):
    """(mode, array) for the upload kernel: float64 (k, 4) quaternions (mode 2) or (k, 3, 3) matrices (mode 1)
    as they are (the kernel checks them); anything else through ``as_rotation_batch``."""
    if isinstance(rotations, np.ndarray) and rotations.dtype == np.float64:
        if rotations.shape == (k, 4):
            return 2, np.ascontiguousarray(rotations)
        if rotations.shape == (k, 3, 3):
            return 1, np.ascontiguousarray(rotations)
    return as_rotation_batch(rotations, k)


def _upload_error(store, verdict: int, at: int, ids, centers, rotations, velocities):
    """Raise the error of a batch the upload kernel refused: the argument's own check gives the message (the
    argument and its first bad index); a value the kernel refused that the check would pass still raises."""
    k = int(np.asarray(ids).shape[0])
    if verdict == BAD_IDS:
        store.check_ids(ids)
        raise ValueError(f"ids[{at}] is not a distinct live moving body of this world")
    if verdict == BAD_ROTATIONS:
        as_rotation_batch(rotations, k)
        raise ValueError(f"rotations[{at}] must be a proper rotation (a unit quaternion or an orthonormal matrix "
                         f"of determinant +1)")
    name, value = ("centers", centers) if verdict == BAD_CENTERS else ("velocities", velocities)
    as_float_array(value, name, shape=(k, 3))
    raise ValueError(f"{name}[{at}] must be finite, of magnitude <= {MAX_MAGNITUDE:g}")


def _flag(value, name: str) -> bool:
    if not isinstance(value, bool | np.bool_):
        raise TypeError(f"{name} must be a bool, got {type(value).__name__}")
    return bool(value)


#: "sphere-box", ... for each cell of the (kind, kind) counts, made again when a kind is registered
_GROUP_NAMES: list = []


def _groups(counts) -> dict:
    global _GROUP_NAMES
    if len(_GROUP_NAMES) != len(KINDS):
        _GROUP_NAMES = [[f"{a.name}-{b.name}" for b in KINDS] for a in KINDS]
    a, b = counts.nonzero()
    return {_GROUP_NAMES[i][j]: int(counts[i, j]) for i, j in zip(a.tolist(), b.tolist())}


class World:
    """A collision world: bodies of mixed shapes, as a game declares them, and the chapter's pipeline over them.

    Each query runs broad phase (bounding boxes kept across frames; by default the dynamic AABB tree of fat boxes,
    and a tree of its own for the static bodies) → the collision filter → the exact test of every remaining pair
    through the dispatch table (shape kind × shape kind → kernel) → ``pairs()`` (whether), ``contacts()`` (where)
    or ``time_of_impact(dt)`` (when); ``events()`` says which pairs began and ended touching. Bodies are added
    once (``add``: moving or static, with a collision filter, as sensors), then moved a batch at a time
    (``update``) or one by one (``move``). Ids are ints, reused after ``remove``; grounds (``Plane``,
    ``HeightCurve``) take ids too, are static and cannot move. World is y-up.

    Filtering (Box2D's ``b2Filter``): a pair is tested iff ``category_i & mask_j`` and ``category_j & mask_i`` are
    both non-zero, except that ``group_i == group_j != 0`` decides alone (> 0 always, < 0 never); a pair excluded
    by ``exclude(i, j)`` is never tested, whatever the groups; two static bodies are never paired. A sensor is
    reported by ``pairs()`` and ``events()``, never by ``contacts()`` or ``time_of_impact``, and two sensors never
    report each other. A filtered pair never reaches the narrow phase (``stats.filtered`` counts them).

    Parameters
    ----------
    broad_phase : str, default "tree"
        A name of ``engine.BROAD_PHASES``: the broad phase of the moving bodies.
    threads : int, default 1
        Threads of the batched work (engine/world/split.py): the narrow phase of every query (each kernel's pairs
        in contiguous ranges), the AABB test and filter of the candidates, the contact record's rows, the broad
        phases that keep no state ("grid", "octree", "brute") and ``pairs_within``'s, ``cast_rays``' rays; a
        batch too small to repay the hand-over stays on the calling thread. Every answer is the same bit for
        bit whatever the count.

    Attributes
    ----------
    broad_phase : str
        As given.
    threads : int
        As given.
    stats : WorldStats
        The work of each stage in the last query.

    Raises
    ------
    ValueError, TypeError
        For an unknown ``broad_phase``, or one that is not a string; ``threads`` not an int in [1, 256].

    Examples
    --------
    A ball of radius 0.5 resting 0.1 deep on a box, then thrown at it from above:

    >>> from engine import Box, Sphere, World
    >>> world = World()
    >>> ball = world.add(Sphere([0.0, 1.0, 0.0], 0.5))
    >>> table = world.add(Box([0.0, 0.0, 0.0], [1.0, 0.6, 1.0]), static=True)
    >>> world.pairs()
    array([[0, 1]])
    >>> contacts = world.contacts()
    >>> contacts.kind, contacts.depth.round(12), contacts.points_of(0)
    (['sphere-face'], array([0.1]), array([[0.  , 0.55, 0.  ]]))
    >>> world.update([ball], [[0.0, 3.0, 0.0]], velocities=[[0.0, -2.0, 0.0]])
    >>> world.time_of_impact(1.0).times
    array([0.95])
    """

    def __init__(self, broad_phase: str = "tree", *, threads: int = 1):
        self.broad_phase = as_choice(broad_phase, "broad_phase", BROAD_PHASES)
        self.threads = check_threads(threads)
        self._version = 0  # bumped by every change of a body: what the ray scene was built for
        self._moving_ids: np.ndarray | None = None  # the moving bodies, until the next add or remove
        self._scratch: tuple | None = None  # (points per body, the kernels' scratch for that many)
        self._ray_scene: tuple[int, RayScene] | None = None
        self._ray_tree_state: tuple | None = None  # (bodies, tree, quality when built) of the rays' tree
        self._ray_surface_state: tuple | None = None  # (meshes, SurfaceSet) of the surfaces the rays last saw
        self._store = BodyStore()
        self._shapes: dict[int, Shape] = {}
        self._grounds: dict[int, Shape] = {}  # the unbounded static shapes, found by their own candidate test
        self._broad = make_broad_phase(self.broad_phase, self.threads)
        self._static = StaticPairs()
        self._exclusions = Exclusions()
        self._filtering = False  # a body was given a filter, a group or the sensor flag (never reset)
        self._compounds = 0  # live compounds: only then are pairs split into parts
        self._stamps = itertools.count(1)
        self._stamp = np.zeros(16, np.int64)  # per id: which add() it came from (events tell bodies apart)
        self._previous = (_NO_PAIRS, np.empty(0, np.int64))
        self._touching = (_NO_PAIRS, np.empty(0, np.int64))
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
    def add(self, shape, velocity=None, *, static=False, category=1, mask=ALL, group=0, sensor=False) -> int:
        """Add a shape as a body; returns its id.

        Parameters
        ----------
        shape : Shape
            A ``Sphere``, ``Box``, ``Capsule``, ``ConvexPolyhedron``, ``Compound``, ``Plane``, ``HeightCurve``,
            ``TriangleMesh`` or ``HeightField``; its pose as built.
        velocity : array_like, shape (3,), optional
            Its constant velocity for ``time_of_impact``; default zero (a static body's must be zero).
        static : bool, default False
            Level geometry: it never moves (``move`` / ``update`` refuse it), is kept in a broad-phase tree of its
            own, and is never paired with another static body. Grounds and triangle surfaces are always static.
        category, mask : int, default 1 and ``engine.ALL``
            Its collision categories and the categories it collides with: 64-bit sets (ints in [0, 2^64)).
        group : int, default 0
            Its collision group (a signed 64-bit int): two bodies of one non-zero group always collide (> 0) or
            never (< 0), whatever their categories and masks.
        sensor : bool, default False
            A trigger: reported by ``pairs()`` and ``events()``, never by ``contacts()`` or ``time_of_impact``.

        Returns
        -------
        int
            The new id (the smallest free one; a compound's parts take the next free rows of the store).

        Raises
        ------
        TypeError
            When ``shape`` is not an engine shape; a ``static`` or ``sensor`` that is not a bool; a float or
            non-integer ``category``, ``mask`` or ``group``.
        ValueError
            For a velocity not of shape (3,) or not finite, a non-zero velocity of a static body, a negative
            ``category`` or ``mask`` or one beyond 64 bits; the world is then unchanged.
        """
        if not isinstance(shape, Shape):
            raise TypeError(f"shape must be an engine shape (Sphere, Box, ...), got {type(shape).__name__}")
        vel = np.zeros(3) if velocity is None else as_float_array(velocity, "velocity", shape=(3,))
        static = _flag(static, "static") or shape.kind.static_only
        sensor = _flag(sensor, "sensor")
        bits = (as_bits(category, "category"), as_bits(mask, "mask"), as_group(group))
        if static and vel.any():
            raise ValueError(f"velocity must be zero for a static body, got {vel.tolist()}")
        body = self._new_body(shape)
        self._version += 1
        self._moving_ids = None
        st = self._store
        st.static[body], st.sensor[body] = static, sensor
        st.category[body], st.mask[body], st.group[body] = bits
        self._filtering |= sensor or bits != (1, ALL, 0)
        st.fat_lo[body], st.fat_hi[body] = np.inf, -np.inf  # no fat box yet: the upload flags it escaped
        refresh_bodies(st.view(), np.array([body]), shape.center[None], 1,
                       np.ascontiguousarray(shape.rotation, dtype=np.float64)[None], _NO_QUATERNIONS, vel[None])
        if not shape.kind.bounded:
            self._grounds[body] = shape
        elif static:
            self._static.add(body)
        else:
            self._broad.add(st, body)
        return body

    def _new_body(self, shape) -> int:
        """A store row for the shape (and rows for a compound's parts, linked to it), with a new stamp."""
        st = self._store
        body = st.new_id(shape.local.shape[0], shape.planes.shape[0])
        st.write_shape(body, shape)
        last = -1
        for k, (part, position, rotation) in enumerate(getattr(shape, "parts", ())):
            row = st.new_id(part.local.shape[0], part.planes.shape[0])
            st.write_shape(row, part)
            st.owner[row], st.part[row] = body, k
            st.part_center[row], st.part_rotation[row] = position, rotation
            if last < 0:
                st.first_part[body] = row
            else:
                st.next_part[last] = row
            last = row
        self._shapes[body] = shape
        self._compounds += int(shape.kind.composite)
        if body >= self._stamp.shape[0]:
            self._stamp = np.concatenate([self._stamp, np.zeros(body + 1, np.int64)])
        self._stamp[body] = next(self._stamps)
        return body

    def remove(self, body_id) -> None:
        """Delete a body (a compound with its parts) or a ground; its id may be reused by a later ``add``.

        Parameters
        ----------
        body_id : int
            A live id.

        Raises
        ------
        ValueError
            For an id that is not in this world; ``TypeError`` for a non-integer id.
        """
        body = self._check_id(body_id)
        self._version += 1
        self._moving_ids = None
        st = self._store
        if body in self._grounds:
            del self._grounds[body]
        elif st.static[body]:
            self._static.remove(st, body)
        else:
            self._broad.remove(st, body)
            self._static.remove(st, body)
        self._exclusions.forget(body)
        self._compounds -= int(self._shapes[body].kind.composite)
        for row in st.parts_of(body):
            st.release(row)
        del self._shapes[body]
        st.release(body)

    def move(self, body_id, center=None, rotation=None, velocity=None) -> None:
        """Set the pose of one body; the arguments left None keep their value.

        Parameters
        ----------
        body_id : int
            A live moving body (not static, not a ground).
        center : array_like, shape (3,), optional
            The new position.
        rotation : array_like or scipy.spatial.transform.Rotation, optional
            A (3, 3) rotation matrix (columns = the body's axes), a unit quaternion (w, x, y, z) or a scipy Rotation.
        velocity : array_like, shape (3,), optional
            The new constant velocity.

        Raises
        ------
        ValueError
            For a static body, a ground or an unknown id, or a bad vector or rotation (named); the body is then
            unchanged.
        """
        body = self._check_id(body_id, moving=True)
        st = self._store
        c = st.center[body] if center is None else as_float_array(center, "center", shape=(3,))
        rot = None if rotation is None else as_rotation(rotation)
        v = _NO_VECTORS if velocity is None else as_float_array(velocity, "velocity", shape=(3,))[None]
        self._version += 1
        refresh_bodies(st.view(), np.array([body]), np.array(c)[None], 0 if rot is None else 1,
                       _NO_MATRICES if rot is None else np.ascontiguousarray(rot, dtype=np.float64)[None],
                       _NO_QUATERNIONS, v)

    def update(self, ids, centers, rotations=None, velocities=None) -> None:
        """Move many bodies at once, in one compiled kernel that checks the batch, then writes it.

        Everything is checked before anything is written: on an error the world is unchanged. The caller's arrays
        are never modified.

        Parameters
        ----------
        ids : array_like, shape (k,), int
            Distinct live moving bodies (not static, not grounds).
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
            Naming the argument and the first bad index: an unknown, static, ground or repeated id, a non-finite
            value, a wrong shape, a non-unit quaternion or an improper matrix.
        TypeError
            For ids that are not a 1-D integer array.
        """
        t0 = time.perf_counter()
        st = self._store
        idx = _as_ids(ids)
        k = idx.shape[0]
        c = _as_rows(centers, "centers", (k, 3))
        mode, rot = (0, None) if rotations is None else _as_rotations(rotations, k)
        v = _NO_VECTORS if velocities is None else _as_rows(velocities, "velocities", (k, 3))
        verdict, at = upload_bodies(st.view(), st.n_ids, idx, c, mode, rot if mode == 1 else _NO_MATRICES,
                                    rot if mode == 2 else _NO_QUATERNIONS, v, MAX_MAGNITUDE, ROTATION_TOL)
        if verdict != UPLOAD_OK:  # nothing was written: say why, naming the argument and the first bad index
            _upload_error(st, verdict, at, ids, centers, rotations, velocities)
        self._version += 1
        self._upload_seconds += time.perf_counter() - t0

    # -- filters -------------------------------------------------------------------------------------------
    def set_filter(self, ids, category=None, mask=None, group=None) -> None:
        """Change the collision filter of bodies; the arguments left None keep their value.

        Parameters
        ----------
        ids : int or array_like of int, shape (k,)
            Live bodies (static ones and grounds included), distinct.
        category, mask : int, optional
            New 64-bit sets, ints in [0, 2^64), for every body of ``ids``.
        group : int, optional
            A new group (signed 64-bit) for every body of ``ids``.

        Raises
        ------
        TypeError
            For ids that are not integers, or a float / non-integer category, mask or group.
        ValueError
            For an unknown or repeated id, a negative or over-64-bit category or mask; the world is then unchanged.
        """
        idx = self._store.check_ids(np.atleast_1d(np.asarray(ids)), moving=False)
        values = {"category": None if category is None else as_bits(category, "category"),
                  "mask": None if mask is None else as_bits(mask, "mask"),
                  "group": None if group is None else as_group(group)}
        for name, value in values.items():
            if value is not None:
                getattr(self._store, name)[idx] = value
                self._filtering = True

    def exclude(self, i, j) -> None:
        """Never test the pair (i, j), whatever the filters and groups (MuJoCo's ``<exclude>``, pybullet's
        ``setCollisionFilterPair(..., enable=0)``); it lasts until ``include(i, j)`` or until either is removed.

        Parameters
        ----------
        i, j : int
            Two distinct live ids.

        Raises
        ------
        ValueError
            For an unknown id, or i == j; ``TypeError`` for a non-integer id.
        """
        a, b = self._check_pair(i, j)
        self._exclusions.exclude(a, b)

    def include(self, i, j) -> None:
        """Undo ``exclude(i, j)`` (same arguments and errors): the pair is filtered by the categories, masks and
        groups again; nothing happens when it was not excluded."""
        a, b = self._check_pair(i, j)
        self._exclusions.include(a, b)

    def excluded(self) -> np.ndarray:
        """The excluded pairs.

        Returns
        -------
        numpy.ndarray, shape (k, 2), int64
            Canonical pairs (i < j, rows sorted).
        """
        return np.array(sorted(self._exclusions.pairs), np.int64).reshape(-1, 2)

    def _check_pair(self, i, j) -> tuple[int, int]:
        a, b = self._check_id(i, "i"), self._check_id(j, "j")
        if a == b:
            raise ValueError(f"i and j must be two different bodies, got {a} twice")
        return a, b

    def _check_id(self, body_id, name="id", *, moving=False, bounded=False) -> int:
        """A live id as an int; ``moving``: refuse static bodies and grounds; ``bounded``: refuse grounds."""
        if isinstance(body_id, bool) or not isinstance(body_id, int | np.integer):
            raise TypeError(f"{name} must be an int, got {type(body_id).__name__}")
        body = int(body_id)
        if body not in self._shapes:
            raise ValueError(f"{name} {body} is not a body of this world")
        if (moving or bounded) and body in self._grounds:
            raise ValueError(f"{name} {body} is a ground, which cannot move")
        if moving and self._store.static[body]:
            raise ValueError(f"{name} {body} is static (level geometry), which cannot move")
        return body

    # -- rays ----------------------------------------------------------------------------------------------
    def _ray_tree(self, bodies):
        """A tree over the moving bodies' exact AABBs for the rays: built for a set of bodies, refitted when only
        their poses changed, built again when they left it much looser than built (``RAY_TREE_DECAY``)."""
        st = self._store
        kept = self._ray_tree_state
        if kept is not None and np.array_equal(kept[0], bodies):
            if kept[1].refit(st.lo[bodies], st.hi[bodies]) <= RAY_TREE_DECAY * kept[2]:
                return kept[1]
        tree = DynamicAABBTree.from_boxes(st.lo[bodies], st.hi[bodies], margin=0.0, split="sah")
        self._ray_tree_state = (bodies, tree, tree.refit(st.lo[bodies], st.hi[bodies]))
        return tree

    def _moving_structure(self, bodies):
        """(method, trees, listed ids, grid, grid body ids) of the moving bodies, for the rays."""
        st = self._store
        empty = np.empty(0, np.int64)
        if self.broad_phase == "brute" or bodies.shape[0] == 0:
            return LIST, [], bodies, None, empty
        if self.broad_phase == "grid":
            return GRID, [], empty, build_ray_grid(st.lo[bodies], st.hi[bodies]), bodies
        return TREE, [(self._ray_tree(bodies).arrays(), bodies)], empty, None, empty

    def _surfaces(self) -> tuple:
        """(surface_of, SurfaceSet) of the triangle surfaces (engine/world/ray_rows.py), the set built again only
        when the surfaces changed."""
        st = self._store
        codes = [kind.code for kind in SURFACE_KINDS]
        ids = np.flatnonzero(np.isin(st.kind, codes) & (st.owner < 0))
        meshes = [self._shapes[int(b)].mesh for b in ids]  # type: ignore[attr-defined]  # surfaces only
        kept = self._ray_surface_state
        same = kept is not None and len(kept[0]) == len(meshes) and all(a is b for a, b in zip(kept[0], meshes))
        surfaces = ray_surfaces(ids, meshes, st.kind.shape[0], kept[1] if same and kept is not None else None)
        self._ray_surface_state = (meshes, surfaces[1])
        return surfaces

    def _rays(self) -> RayScene:
        """The structures the rays walk, built again only when a body changed since (``_version``)."""
        if self._ray_scene is not None and self._ray_scene[0] == self._version:
            return self._ray_scene[1]
        st = self._store
        bodies = self._moving()
        method, trees, listed, grid, grid_body = self._moving_structure(bodies)
        rows = {g: RAY_ROWS[shape.kind] for g, shape in sorted(self._grounds.items())}
        compiled = np.array([g for g, row in rows.items() if row.hit is not None], np.int64)
        host = [(g, self._grounds[g]) for g, row in rows.items() if row.hit is None]
        live = st.live()
        bounded = live[st.bounded[live]]
        span = st.hi[bounded].max(axis=0) - st.lo[bounded].min(axis=0) if bounded.size else np.ones(3)
        scene = RayScene(ray_bodies(st.view(), self._surfaces()), st.lo, st.hi, st.category, st.sensor,
                         np.concatenate([compiled, listed]), forest_of([self._static.tree_arrays(st), *trees]),
                         method, build_ray_grid(np.zeros((1, 3)), np.zeros((1, 3))) if grid is None else grid,
                         grid_body, host, max(1.0, 4.0 * float(np.sqrt((span * span).sum()))))
        self._ray_scene = (self._version, scene)
        return scene

    def cast_rays(self, origins, directions, max_distance=np.inf, *, mask=ALL, all_hits=False) -> RayHits:
        """Cast a batch of rays: the nearest body each one hits, or every hit.

        One compiled call for the whole batch (split into ``threads`` chunks): each ray walks the static bodies'
        tree, the moving bodies' broad-phase structure (the tree of fat boxes, the grid by 3-D DDA, ...) clipped by
        its nearest hit so far, and tests the bodies it reaches exactly (engine/world/ray_rows.py: spheres, boxes,
        capsules, hulls, compounds part by part, the Plane, the nearest triangle of a TriangleMesh or HeightField
        (two-sided and watertight: a ray through a shared edge or vertex never slips between its triangles); a
        HeightCurve by sampling and bisection of the height gap, within ``max_distance``, or 4 × the bodies'
        extent when that is infinite). Sensors are never hit.

        Parameters
        ----------
        origins : array_like, shape (k, 3), float64
            Where the rays start.
        directions : array_like, shape (k, 3), float64
            Their directions, of any non-zero length (distances are along the unit direction).
        max_distance : float or array_like of shape (k,), default inf
            How far each ray goes, >= 0 (0: only a body containing the origin is hit).
        mask : int, default ``engine.ALL``
            A 64-bit set of categories: a body is hit only if ``category & mask`` is non-zero.
        all_hits : bool, default False
            Every hit of every ray instead of the nearest.

        Returns
        -------
        RayHits
            Nearest: one row per ray (``body`` −1, ``distance`` inf and NaN point and normal for a miss). A ray
            that starts inside a body (or on its surface) hits it at distance 0, with normal −direction; a triangle
            surface is a shell, not a solid: it is hit where the ray crosses it (at 0 from an origin on it), with the
            triangle's normal turned against the ray, and ``part`` is that triangle. Ties in distance go to the
            lowest id. ``all_hits``: one row per hit, sorted by (ray, distance, body).

        Raises
        ------
        ValueError
            For origins or directions not of shape (k, 3) or not finite, a zero direction, a negative or NaN
            ``max_distance`` or one of the wrong length (named, with the first bad index); the world is unchanged.
        TypeError
            For a non-numeric array, a float ``mask``, or an ``all_hits`` that is not a bool.

        Examples
        --------
        >>> from engine import Box, Plane, Sphere, World
        >>> world = World()
        >>> ground = world.add(Plane(0.0))
        >>> ball = world.add(Sphere([0.0, 1.0, 5.0], 0.5))
        >>> hits = world.cast_rays([[0.0, 1.0, 0.0], [0.0, 3.0, 0.0]], [[0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])
        >>> hits.body, hits.distance
        (array([1, 0]), array([4.5, 3. ]))
        >>> hits.normal[0]
        array([ 0.,  0., -1.])
        """
        o, d, t_max = as_rays(origins, directions, max_distance)
        bits = as_bits(mask, "mask")
        every = _flag(all_hits, "all_hits")
        return cast_ray_batch(self._rays(), o, d, t_max, bits, every, self.threads)

    def cast_ray(self, origin, direction, max_distance=np.inf, *, mask=ALL) -> RayHit | None:
        """Cast one ray: the nearest body it hits (as ``cast_rays`` for a batch of one).

        Parameters
        ----------
        origin, direction : array_like, shape (3,), float64
            The ray; the direction of any non-zero length.
        max_distance : float, default inf
            How far it goes, >= 0.
        mask : int, default ``engine.ALL``
            The categories it may hit.

        Returns
        -------
        RayHit or None
            ``body``, ``distance`` (along the unit direction), ``point``, ``normal`` and ``part``; None for a miss.

        Raises
        ------
        ValueError, TypeError
            As ``cast_rays``, naming ``origin``, ``direction`` or ``max_distance``.
        """
        o = as_float_array(origin, "origin", shape=(3,))
        d = as_float_array(direction, "direction", shape=(3,))
        if not np.sqrt((d * d).sum()) > 0.0:
            raise ValueError(f"direction must have a non-zero length, got {d.tolist()}")
        if np.ndim(max_distance) != 0:
            raise ValueError(f"max_distance must be a scalar, got shape {np.shape(max_distance)}")
        hits = self.cast_rays(o[None], d[None], max_distance, mask=mask)
        if hits.body[0] < 0:
            return None
        return RayHit(body=int(hits.body[0]), distance=float(hits.distance[0]), point=hits.point[0],
                      normal=hits.normal[0], part=int(hits.part[0]))

    # -- what is in the world ------------------------------------------------------------------------------
    def ids(self) -> np.ndarray:
        """The live ids: bodies (moving and static) and grounds.

        Returns
        -------
        numpy.ndarray, shape (n,), int64
            Ascending.
        """
        return self._store.live().astype(np.int64)

    def bodies(self) -> BodyArrays:
        """The body store as read-only views of rows 0 to the largest row in use (no copy).

        Returns
        -------
        BodyArrays
            The structure-of-arrays store of ``engine.world.bodies`` (kind, centre, rotation, velocity, radius,
            points, AABBs, the static and sensor flags, the filters, the parts of compounds ...); rows of removed
            ids have kind −1, and the rows of a compound's parts have ``owner`` = the compound's id.
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
        return self._shapes[self._check_id(body_id)]

    def is_static(self, body_id) -> bool:
        """Whether a body is static (level geometry, grounds included).

        Parameters
        ----------
        body_id : int
            A live id.

        Returns
        -------
        bool
        """
        return bool(self._store.static[self._check_id(body_id)])

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
        b = self._check_id(body_id, bounded=True)
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
            "sphere", "box", "capsule", "hull", "compound", "plane" or "curve" (engine.world.kinds.KINDS).
        """
        return KINDS[self._store.kind[self._check_id(body_id)]].name

    def _core_row(self, body_id, part) -> int:
        """The store row of a body's core: the body itself, or part ``part`` of a compound."""
        b = self._check_id(body_id, bounded=True)
        parts = self._store.parts_of(b)
        if part is None and not parts:
            return b
        if isinstance(part, bool) or not isinstance(part, int | np.integer):
            raise TypeError(f"part must be an int (body {b} is a compound of {len(parts)} parts), got "
                            f"{type(part).__name__}")
        if not 0 <= int(part) < max(len(parts), 1):
            raise ValueError(f"part must be in [0, {max(len(parts), 1)}) for body {b}, got {part}")
        return parts[int(part)] if parts else b

    def world_points(self, body_id, part=None) -> np.ndarray:
        """A body's core points in world coordinates, swept by ``radius(body_id)``.

        Parameters
        ----------
        body_id : int
            The body whose points to return (not a ground).
        part : int, optional
            For a compound: which part (required); for another body: None or 0 (its one part, as contacts name it).

        Returns
        -------
        numpy.ndarray, shape (m, 3), float64
            A copy; m = 1 for a sphere, 2 for a capsule, 8 for a box, the hull's vertex count for a polyhedron.
        """
        row = self._core_row(body_id, part)
        return self._store.points[row, : self._store.count[row]].copy()

    def radius(self, body_id, part=None) -> float:
        """The radius that sweeps a body's core (0 for boxes and polyhedra).

        Parameters
        ----------
        body_id : int
            Which body.
        part : int, optional
            For a compound: which part (required); for another body: None or 0.

        Returns
        -------
        float
        """
        return float(self._store.radius[self._core_row(body_id, part)])

    def aabb(self, body_id):
        """A body's current axis-aligned bounding box (the exact box of its swept core; a compound's: of all its
        parts).

        Parameters
        ----------
        body_id : int
            A body's id; a ground is refused (ValueError), as in ``pose``.

        Returns
        -------
        lo, hi : numpy.ndarray, shape (3,), float64
            Its corners (copies).
        """
        b = self._check_id(body_id, bounded=True)
        return self._store.lo[b].copy(), self._store.hi[b].copy()

    # -- shape queries -------------------------------------------------------------------------------------
    def query_aabb(self, lo, hi, *, mask=ALL) -> np.ndarray:
        """The bodies whose AABBs overlap the closed box [lo, hi] (touching counts).

        Moving and static bodies by their current AABB (``aabb(i)``); a ground (``Plane``, ``HeightCurve``: its
        AABB is the whole space) when its kind's candidate test accepts the box (a box wholly above a Plane does
        not report it); a compound by its id (never its parts); sensors included. The query has no category of
        its own: a body is reported iff ``category_body & mask != 0``, whatever the body's mask, group and
        exclusions. Reads no broad-phase structure (one vectorised pass over the store); changes nothing in the
        world (``stats`` included).

        Parameters
        ----------
        lo, hi : array_like, shape (3,)
            The box's corners, finite, ``lo <= hi`` on every axis.
        mask : int, default ``engine.ALL``
            The categories to report: a 64-bit set (an int in [0, 2^64)).

        Returns
        -------
        numpy.ndarray, shape (k,), int64
            The ids, ascending.

        Raises
        ------
        ValueError
            For ``lo`` or ``hi`` not of shape (3,) or not finite, ``lo > hi`` on an axis, a negative or over-64-bit
            ``mask``.
        TypeError
            For non-numeric corners, or a ``mask`` that is not an int.
        """
        box_lo, box_hi = as_box(lo, hi)
        return bodies_in_box(self._store, self._grounds, box_lo, box_hi, as_bits(mask, "mask"))

    def overlap(self, shape, *, mask=ALL) -> np.ndarray:
        """The bodies whose shapes overlap ``shape`` at its pose (closed: touching counts), exactly.

        The candidates are the bodies whose AABBs overlap the shape's (grounds: their kind's candidate test, as
        ``query_aabb``); each is tested through the overlap table, as ``pairs()`` tests a pair (a compound, query
        or body, part by part). Sensors are reported (they are bodies; leave them out with ``mask``). A body is
        reported iff ``category_body & mask != 0``. The shape is not added: ids, filters, events, contacts and
        ``stats`` are unchanged.

        Parameters
        ----------
        shape : Shape
            A ``Sphere``, ``Box``, ``Capsule``, ``ConvexPolyhedron`` or ``Compound``, at its pose as built.
        mask : int, default ``engine.ALL``
            The categories to report: a 64-bit set.

        Returns
        -------
        numpy.ndarray, shape (k,), int64
            The ids, ascending.

        Raises
        ------
        TypeError
            For a ``shape`` that is not an engine shape, a ``mask`` that is not an int.
        ValueError
            For a ground (``Plane``, ``HeightCurve``) as ``shape``, a negative or over-64-bit ``mask``.
        """
        shape = as_query_shape(shape)
        return overlapping_bodies(self._store, self._grounds, self._compounds > 0, shape, as_bits(mask, "mask"),
                                  shapes=self._shapes)

    def cast_shape(self, shape, displacement, *, mask=ALL) -> ShapeHit | None:
        """The first body that ``shape`` touches when translated from its pose by ``fraction * displacement``,
        fraction in [0, 1] (a shape cast: the rotation stays; every body holds still, its velocity unused).

        Candidates: the bodies whose AABBs overlap the swept AABB of the shape (grounds by their candidate test on
        that box), with ``category_body & mask != 0``; sensors are never hit (as in ``time_of_impact``). Each
        candidate's fraction comes from the impact table with the shape's velocity = ``displacement`` over
        dt = 1: closed forms for two spheres and for a Plane, conservative advancement otherwise (the distance at
        the returned fraction is <= 1e-9, so a shape that far from a body counts as touching it), bisection for a
        HeightCurve; the earliest wins, ties to the lowest id. The point and normal are the contact's at the pose
        moved to that fraction (a pair still apart there by the tolerance: GJK's closest points; see
        engine/world/shape_queries.py). The world is unchanged.

        Parameters
        ----------
        shape : Shape
            A ``Sphere``, ``Box``, ``Capsule``, ``ConvexPolyhedron`` or ``Compound``, at its start pose.
        displacement : array_like, shape (3,)
            The translation of the whole sweep, finite (zero: whether the shape touches a body where it is).
        mask : int, default ``engine.ALL``
            The categories that can be hit: a 64-bit set.

        Returns
        -------
        ShapeHit or None
            ``fraction`` (0 when the shape touches a body at its start), ``body`` (the id), ``point`` (3,) and
            ``normal`` (3,) (unit, from the body hit towards the cast shape); None when nothing is hit.

        Raises
        ------
        TypeError
            For a ``shape`` that is not an engine shape, a non-numeric ``displacement``, a ``mask`` that is not an
            int.
        ValueError
            For a ground as ``shape``, a ``displacement`` not of shape (3,) or not finite, a bad ``mask``.
        engine.narrowphase.TOINotConverged
            When conservative advancement reaches its iteration cap.

        Examples
        --------
        A ball of radius 0.5 dropped 3 down onto a static box whose top is at y = 0.5:

        >>> from engine import Box, Sphere, World
        >>> world = World()
        >>> floor = world.add(Box([0.0, 0.0, 0.0], [2.0, 0.5, 2.0]), static=True)
        >>> hit = world.cast_shape(Sphere([0.0, 2.0, 0.0], 0.5), [0.0, -3.0, 0.0])
        >>> hit.body == floor, round(hit.fraction, 12), hit.normal.round(12) + 0.0, hit.point.round(12) + 0.0
        (True, 0.333333333333, array([0., 1., 0.]), array([0. , 0.5, 0. ]))
        >>> world.cast_shape(Sphere([0.0, 2.0, 0.0], 0.5), [3.0, 0.0, 0.0]) is None
        True
        >>> world.overlap(Sphere([0.0, 1.0, 0.0], 0.5)), world.query_aabb([-1, 3, -1], [1, 4, 1])
        (array([0]), array([], dtype=int64))
        """
        shape = as_query_shape(shape)
        move = as_float_array(displacement, "displacement", shape=(3,))
        return cast(self._store, self._grounds, self._compounds > 0, shape, move, as_bits(mask, "mask"),
                    shapes=self._shapes)

    # -- the frame -----------------------------------------------------------------------------------------
    def _moving(self) -> np.ndarray:
        """The live moving bodies (not static, not grounds, not parts), ascending; read-only, found again only
        after an ``add`` or a ``remove``."""
        if self._moving_ids is None:
            st = self._store
            n = st.n_ids
            ids = np.flatnonzero((st.kind[:n] >= 0) & (st.owner[:n] < 0) & ~st.static[:n])
            ids.flags.writeable = False
            self._moving_ids = ids
        return self._moving_ids

    def _ground_candidates(self, bodies, lo, hi) -> list:
        out = []
        for g in sorted(self._grounds):
            ground = self._grounds[g]
            test = ground.kind.candidates
            assert test is not None  # an unbounded kind has one (engine/world/kinds.py)
            hit = bodies[test(ground, lo, hi)]
            out.append(np.stack([np.minimum(hit, g), np.maximum(hit, g)], axis=1).astype(np.int64))
        return out

    def _candidates(self):
        """Broad phase: candidate pairs of ids, i < j per row, no repeat, in no particular order — the moving
        bodies among themselves, against the static bodies, against the grounds — and how many involve a static
        body or a ground."""
        st = self._store
        bodies = self._moving()
        escaped = bodies[st.escaped[bodies]]
        if escaped.shape[0]:
            fatten(st, escaped)
        static = [self._static.candidates(st, bodies, escaped),
                  *self._ground_candidates(bodies, st.lo[bodies], st.hi[bodies])]
        cand = np.concatenate([self._broad.candidates(st, bodies, escaped), *static])
        return np.ascontiguousarray(cand), bodies, sum(s.shape[0] for s in static)

    def _filter_keys(self):
        """The excluded keys for the filter, or None while no body has had a filter, a group or the sensor flag
        and no pair is excluded (every pair passes: the classification skips the filter)."""
        return self._exclusions.keys() if self._filtering or self._exclusions.pairs else None

    def _context(self, dt: float = 0.0) -> NarrowContext:
        """What the kernels read: the store, the shapes by id (the grounds' and the triangle surfaces' kernels read
        their shape objects), scratch for the store's points per body (kept while that count holds), ``dt``,
        whether a compound is present, and this world's threads."""
        view = self._store.view()
        m = view.points.shape[1]
        if self._scratch is None or self._scratch[0] != m:
            self._scratch = (m, kernel_scratch(m))
        return NarrowContext(view, self._shapes, self._scratch[1], dt, self._compounds > 0, self.threads)

    def _answer(self, question: str, query: str):
        """Broad phase, then ``question`` for every candidate the AABB test and the filter keep: (candidate pairs of
        bodies (k, 2), Answer, stats)."""
        t0 = time.perf_counter()
        cand, bodies, static = self._candidates()
        stats = WorldStats(query=query, bodies=int(bodies.shape[0]), candidate_pairs=int(cand.shape[0]),
                           static_pairs=int(static))
        t1 = time.perf_counter()
        result = answer(TABLE, question, self._context(), cand, self._filter_keys(), question != "overlap")
        stats.narrow_tests, stats.groups = int(result.pairs.shape[0]), _groups(result.counts)
        stats.filtered = int(result.filtered)
        stats.seconds = {"upload": self._upload_seconds, "broad": t1 - t0, "narrow": time.perf_counter() - t1}
        self._upload_seconds = 0.0
        return cand, result, stats

    def _touching_pairs(self, query: str) -> np.ndarray:
        cand, result, stats = self._answer("overlap", query)
        origin = np.unique(result.origin[result.out.status == TOUCHING])
        out = cand[origin]
        out = np.ascontiguousarray(out[_canonical_order(out)])
        stats.overlapping = int(out.shape[0])
        self.stats = stats
        return out

    def pairs(self) -> np.ndarray:
        """Canonical pairs of ids whose shapes overlap (touching counts), sensors included.

        The broad phase, the filter, then the exact test of each remaining pair through the overlap table (a
        compound overlaps when one of its parts does). Refreshes ``stats``.

        Returns
        -------
        numpy.ndarray, shape (k, 2), int64
            i < j in every row, rows in lexicographic order, no repeat.
        """
        return self._touching_pairs("pairs")

    def events(self):
        """The pairs that began and ended touching since the last call (as ``pairs()``: sensors included).

        The first call reports every touching pair as begun. A pair ends when its bodies part, when one of them is
        removed (even if a new body takes its id and touches the other: that is a new pair, which begins), or
        when a filter change or an exclusion stops it from being tested. Independent of the other queries made in
        between. Refreshes ``stats``.

        Returns
        -------
        begin, end : numpy.ndarray, shape (k, 2), int64
            Canonical pairs (i < j, rows sorted).
        """
        now = self._touching_pairs("events")
        keys = self._stamp[now[:, 0]] << 32 | self._stamp[now[:, 1]]
        before, before_keys = self._touching
        self._touching = (now, keys)
        return now[~np.isin(keys, before_keys)], before[~np.isin(before_keys, keys)]

    def contacts(self) -> ContactSet:
        """The contacts of the touching pairs (sensors never), with per-point feature ids that persist across
        frames.

        Through the contact table: closed forms for sphere–sphere, sphere–box, sphere–capsule, capsule–capsule,
        box–box and every body on a Plane; GJK/EPA with the contact features for the others; the curve rows for a
        HeightCurve; a compound part by part. Each point's id names the two features that made it (Box2D's
        ``b2ContactFeature``) and ``persists`` says whether the same pair (same parts) had the same id in the
        previous call. Refreshes ``stats``.

        Returns
        -------
        ContactSet
            One row per touching pair of parts — one per pair of bodies, several for a compound —, rows in
            lexicographic order of (i, j, part_a, part_b), normals from the first id to the second, at most 4
            points per row, with ``point_ids``, ``persists``, ``part_a`` and ``part_b`` (0 for a body that is not
            a compound).
        """
        cand, result, stats = self._answer("contact", "contacts")
        t0 = time.perf_counter()
        st = self._store
        (pairs, separation, depth, normal, feature_a, feature_b, points, offsets, radius_a, radius_b, point_ids,
         persists, part_a, part_b, *previous) = contact_record(result.out, cand, result.origin, result.pairs,
                                                               st.part, st.radius, *self._previous, self.threads)
        self._previous = tuple(previous)
        out = ContactSet(pairs=pairs, separation=separation, depth=depth, normal=normal, feature_a=feature_a,
                         feature_b=feature_b, points=points, point_offsets=offsets, radius_a=radius_a,
                         radius_b=radius_b, point_ids=point_ids, persists=persists, part_a=part_a, part_b=part_b)
        stats.seconds["contacts"] = time.perf_counter() - t0
        stats.overlapping = int(pairs.shape[0])
        stats.contacts, stats.persisting = int(points.shape[0]), int(np.count_nonzero(persists))
        self.stats = stats
        return out

    def _swept_candidates(self, dt: float):
        """The kept broad phase asked for the pairs whose swept boxes (each body's AABB swept over ``dt`` with its
        velocity) overlap: the bodies whose swept box leaves their fat box are given fat boxes around it first
        (Box2D's ``b2MoveProxy`` with a displacement). Returns (pairs (k, 2) of ids — moving pairs the kinematic
        method keeps, then the static and ground pairs —, how many are static or ground pairs, how many moving
        pairs were culled)."""
        st = self._store
        bodies = self._moving()
        v, lo, hi = st.velocity[bodies], st.lo[bodies], st.hi[bodies]
        sw_lo, sw_hi = np.minimum(lo, lo + v * dt), np.maximum(hi, hi + v * dt)
        out = st.escaped[bodies] | ((sw_lo < st.fat_lo[bodies]) | (sw_hi > st.fat_hi[bodies])).any(axis=1)
        moved = bodies[out]
        fatten_around(st, moved, sw_lo[out], sw_hi[out])
        rows = self._broad.swept(st, bodies, moved, sw_lo, sw_hi)
        kept = cull_separating_box_pairs(rows, lo, hi, v) if rows.shape[0] else _NO_PAIRS
        static = [self._static.swept(st, bodies, moved, sw_lo, sw_hi), *self._ground_candidates(bodies, sw_lo, sw_hi)]
        n_static = sum(s.shape[0] for s in static)
        cand = np.ascontiguousarray(np.concatenate([bodies[kept], *static]))
        return cand, n_static, int(rows.shape[0] - kept.shape[0])

    def time_of_impact(self, dt) -> ImpactSet:
        """The pairs that touch within ``dt`` while the bodies move with their velocities, and when (sensors
        never).

        The world's kept broad phase asked for the pairs whose swept boxes overlap (a body whose swept box leaves
        its fat box is given a fat box around it, as Box2D moves a proxy by its displacement), kinematic culling of
        the moving pairs apart and moving apart (``engine.broadphase.cull_separating_box_pairs``), the filter, the
        overlap table for the pairs touching at the start (time 0), then the impact table for the others: closed
        forms for two spheres and a body over a Plane, conservative advancement for the other bodies
        (``engine.narrowphase.time_of_impact_pairs``, distance within 1e-9 at the returned time), bisection on the
        sampled gap for a HeightCurve; a compound's time is the earliest of its parts'. Static bodies and grounds
        are fixed; the poses are not changed (the fat boxes may grow). Refreshes ``stats``.

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
        cand, static, culled = self._swept_candidates(dt)
        stats = WorldStats(query="time_of_impact", bodies=int(self._moving().shape[0]),
                           candidate_pairs=int(cand.shape[0] + culled), static_pairs=int(static), culled=culled)
        keys = self._filter_keys()
        touching = answer(TABLE, "overlap", self._context(), cand, keys, True)
        now = np.zeros(cand.shape[0], np.bool_)
        now[touching.origin[touching.out.status == TOUCHING]] = True
        later = np.flatnonzero(~now)
        result = answer(TABLE, "impact", self._context(dt), np.ascontiguousarray(cand[later]), keys, True)
        stats.filtered = int(result.filtered)
        times = np.full(cand.shape[0], np.inf)
        times[now] = 0.0
        np.minimum.at(times, later[result.origin], result.out)
        hit = np.isfinite(times)
        pairs, times = cand[hit], times[hit]
        order = _canonical_order(pairs)
        stats.narrow_tests = int(touching.pairs.shape[0] + result.pairs.shape[0])
        stats.groups = _groups(touching.counts + result.counts)
        stats.impacts = int(pairs.shape[0])
        self.stats = stats
        return ImpactSet(pairs=np.ascontiguousarray(pairs[order]), times=times[order])

    # -- distances -----------------------------------------------------------------------------------------
    def _pair_ids(self, ids_a, ids_b) -> np.ndarray:
        """ids_a, ids_b as the rows (k, 2) int64 of a pair list: 1-D integer arrays of one length, live ids, no
        body paired with itself, not two grounds — else TypeError / ValueError naming the argument and the first
        bad index."""
        st = self._store
        cols = []
        for value, name in ((ids_a, "ids_a"), (ids_b, "ids_b")):
            idx = np.asarray(value)
            if idx.dtype.kind not in "iu" or idx.ndim != 1:
                raise TypeError(f"{name} must be a 1-D integer array, got dtype {idx.dtype} and shape {idx.shape}")
            cols.append(idx)
        if cols[0].shape != cols[1].shape:
            raise ValueError(f"ids_a and ids_b must have the same length, got {cols[0].shape[0]} and "
                             f"{cols[1].shape[0]}")
        for idx, name in zip(cols, ("ids_a", "ids_b")):
            outside = (idx < 0) | (idx >= st.n_ids)
            at = np.where(outside, 0, idx).astype(np.int64)
            bad = np.flatnonzero(outside | (st.kind[at] < 0) | (st.owner[at] >= 0))
            if bad.size:
                raise ValueError(f"{name}[{bad[0]}] = {idx[bad[0]]} is not a body of this world (never added, or "
                                 f"removed)")
        pairs = np.stack([c.astype(np.int64) for c in cols], axis=1).reshape(-1, 2)
        bad = np.flatnonzero(pairs[:, 0] == pairs[:, 1])
        if bad.size:
            raise ValueError(f"ids_b[{bad[0]}] = {pairs[bad[0], 1]} is ids_a[{bad[0]}]: a body has no distance to "
                             f"itself")
        # level geometry (grounds, triangle surfaces) is neither convex nor made of convex parts
        level = np.array([not (k.convex or k.composite) for k in KINDS])[st.kind[pairs]]
        bad = np.flatnonzero(level[:, 0] & level[:, 1])
        if bad.size:
            raise ValueError(f"ids_a[{bad[0]}] = {pairs[bad[0], 0]} and ids_b[{bad[0]}] = {pairs[bad[0], 1]} are "
                             f"both level geometry (grounds or triangle surfaces): they have no distance")
        return pairs

    def _distances(self, pairs: np.ndarray, margin: float, keys):
        """The distance question over pairs of bodies (k, 2): the signed distance (k,) — the least over a
        compound's parts; inf for a pair none of whose rows passed the box test and the filter — and the two
        witness points (k, 3) of the row that gave it, with the Answer."""
        result = answer(TABLE, "distance", self._context(), np.ascontiguousarray(pairs), keys, False, margin)
        out = result.out
        k = pairs.shape[0]
        distance, point_a, point_b = np.full(k, np.inf), np.full((k, 3), np.nan), np.full((k, 3), np.nan)
        if result.origin.shape[0]:
            order = np.lexsort((out.distance, result.origin))  # by pair, nearest row first
            first = order[np.r_[True, result.origin[order][1:] != result.origin[order][:-1]]]
            at = result.origin[first]
            distance[at], point_a[at], point_b[at] = out.distance[first], out.point_a[first], out.point_b[first]
        return distance, point_a, point_b, result

    def closest_points(self, ids_a, ids_b):
        """The signed distance of each pair of bodies (ids_a[k], ids_b[k]) and its witness points.

        The distance table (engine/world/rows.py): closed forms for sphere–sphere, sphere–capsule,
        capsule–capsule and sphere–box (the contact kernels' closest points), a body against a Plane (its lowest
        core point), GJK distance / EPA depth for every other convex pair (box–box with the SAT's verdict on
        contact), the sampled curve for a HeightCurve; a compound: its nearest part. No broad phase and no filter:
        the pairs are asked for. The sign follows the overlap test of ``pairs()``: distance <= 0 exactly when the
        two bodies overlap by that test. Static bodies, and a body against a ground, are allowed.

        Parameters
        ----------
        ids_a, ids_b : array_like, shape (k,), int
            Live ids; ids_a[k] != ids_b[k], not two grounds.

        Returns
        -------
        distance : numpy.ndarray, shape (k,), float64
            The gap when apart (> 0), 0 touching, minus the penetration depth when overlapping (the depth of
            ``contacts()`` for that pair).
        point_a, point_b : numpy.ndarray, shape (k, 3), float64
            On the surface of ids_a[k] and of ids_b[k]: the closest points when apart, the deepest points when
            overlapping; point_b − point_a is distance times the unit normal from the first body to the second.

        Raises
        ------
        TypeError
            For ids that are not 1-D integer arrays.
        ValueError
            For arrays of different lengths, an id that is not live, a body paired with itself or two grounds
            (naming the argument and the first bad index); the world is unchanged.
        """
        pairs = self._pair_ids(ids_a, ids_b)
        distance, point_a, point_b, result = self._distances(pairs, np.inf, None)
        stats = WorldStats(query="closest_points", bodies=int(self._moving().shape[0]),
                           candidate_pairs=int(pairs.shape[0]), narrow_tests=int(result.pairs.shape[0]),
                           groups=_groups(result.counts))
        self.stats = stats
        return distance, point_a, point_b

    def pairs_within(self, margin):
        """Every canonical pair of bodies whose signed distance is at most ``margin`` (closed), and the distances.

        Broad phase on the AABBs grown by the margin (the moving bodies among themselves with this world's broad
        phase, against the static tree, the grounds' own candidate tests), the filter of ``pairs()`` (categories,
        masks, groups, exclusions; sensors are reported, two sensors never report each other; two static bodies
        are never paired), the boxes at most ``margin`` apart, then the distance table (``closest_points``).
        ``pairs_within(0.0)`` gives exactly ``pairs()``. Refreshes ``stats``.

        Parameters
        ----------
        margin : float
            >= 0, finite.

        Returns
        -------
        pairs : numpy.ndarray, shape (k, 2), int64
            i < j in every row, rows in lexicographic order.
        distance : numpy.ndarray, shape (k,), float64
            Their signed distances (<= margin; negative: penetrating).

        Raises
        ------
        ValueError
            For a negative or non-finite ``margin``; ``TypeError`` for one that is not a real number.
        """
        margin = as_nonnegative(margin, "margin")
        t0 = time.perf_counter()
        st = self._store
        bodies = self._moving()
        grow = 2.0 * margin  # a superset of the boxes at most margin apart, whatever the round-off
        lo, hi = st.lo[bodies] - grow, st.hi[bodies] + grow
        rows = find_pairs(lo, hi, self.broad_phase, threads=self.threads) if bodies.shape[0] > 1 else _NO_PAIRS
        static = [self._static.query(st, bodies, lo, hi), *self._ground_candidates(bodies, lo, hi)]
        cand = np.ascontiguousarray(np.concatenate([bodies[rows], *static]))
        stats = WorldStats(query="pairs_within", bodies=int(bodies.shape[0]), candidate_pairs=int(cand.shape[0]),
                           static_pairs=int(sum(s.shape[0] for s in static)))
        t1 = time.perf_counter()
        distance, _, _, result = self._distances(cand, margin, self._filter_keys())
        near = distance <= margin
        pairs, distance = cand[near], distance[near]
        order = _canonical_order(pairs)
        stats.narrow_tests, stats.groups = int(result.pairs.shape[0]), _groups(result.counts)
        stats.filtered, stats.overlapping = int(result.filtered), int(pairs.shape[0])
        stats.seconds = {"upload": self._upload_seconds, "broad": t1 - t0, "narrow": time.perf_counter() - t1}
        self._upload_seconds = 0.0
        self.stats = stats
        return np.ascontiguousarray(pairs[order]), distance[order]
