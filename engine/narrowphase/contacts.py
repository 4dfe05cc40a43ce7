"""The contact record: one type for every contact query of the engine (World frames and batched contact features).

``ContactSet`` holds the contacts of k pairs of shapes as arrays:

- ``pairs`` (k, 2) int64: the two shapes of each pair (for ``World``: canonical body ids, i < j);
- ``separation`` (k,) float64: signed distance (< 0 penetrating, 0 touching, > 0 apart); ``depth`` (k,) =
  max(−separation, 0) >= 0;
- ``normal`` (k, 3): unit vectors from the pair's first shape towards its second (translating the second shape
  by depth · normal separates the pair);
- ``feature_a``, ``feature_b`` (k,) int8: the feature of each side that touches, a code of ``FEATURE_NAMES``
  (1 vertex, 2 edge, 3 face; for a rounded shape, ``radius_a``/``radius_b`` > 0: sphere, cylinder, face);
  ``names_a``, ``names_b`` and ``kind`` ("vertex-face", ...) compute the names on demand;
- ``points`` (M, 3), ``point_offsets`` (k + 1,) int64: pair p's contact points are
  ``points[point_offsets[p]:point_offsets[p + 1]]`` (``points_of(p)``);
- ``point_ids`` (M,) int64 or None: per point, which feature of each shape made it (Box2D's ``b2ContactFeature``,
  Bullet's manifold point cache): the same id while the same two features touch, a different one when they
  change; ``describe_point_id`` spells one out; ``persists`` (M,) bool or None: whether that point (same pair,
  same id) was already in the previous frame's contacts (World only);
- ``closest_a``, ``closest_b`` (k, 3) or None: GJK's closest (or EPA's deepest) points, and ``exact_fallback``
  (k,) bool or None: pairs whose depth came from Qhull — given by ``contact_feature_pairs``.

A point id packs two *feature keys*, one per shape: key = type · 2^20 + index with type 1 vertex, 2 edge, 3 face
and index the vertex / edge / face number in the shape's own numbering (a box: vertex 4·[x>0] + 2·[y>0] + [z>0],
edge 4·axis + 2·[first other axis > 0] + [second > 0], face 2·axis + [side > 0]; a hull: its vertex numbers;
a sphere, a capsule's segment, a ground: index 0). id = key_a · 2^23 + key_b, plus a multiple of 2^46 when two
points of one pair would otherwise share an id.

The kernels here are shared by every contact kernel: ``feature_key``, ``point_id``, ``reduce_manifold`` (at most
``MAX_POINTS`` = 4 points per pair, as Bullet's and ODE's manifolds) and ``mark_persisting``.
"""
from __future__ import annotations

from collections import namedtuple
from dataclasses import dataclass

import numpy as np

from .._config import njit

__all__ = ["ContactSet", "PairFeatureNames", "feature_name", "FEATURE_NAMES", "ROUND_FEATURE_NAMES", "VERTEX", "EDGE",
           "FACE", "MAX_POINTS",
           "feature_key", "point_id", "describe_point_id", "reduce_manifold", "mark_persisting",
           "ContactRows", "contact_rows", "APART", "TOUCHING", "DEFERRED", "write_pair", "write_point",
           "key_kind", "contact_set_from_rows", "swap_point_id",
           "Scratch", "kernel_scratch", "contact_of_one_pair"]

VERTEX, EDGE, FACE = 1, 2, 3
#: feature codes (``feature_a``, ``feature_b``) -> names, for polytopes and for rounded shapes (radius > 0)
FEATURE_NAMES = {VERTEX: "vertex", EDGE: "edge", FACE: "face"}
ROUND_FEATURE_NAMES = {VERTEX: "sphere", EDGE: "cylinder", FACE: "face"}

#: the most contact points a pair keeps (a face on a face: the 4 that span the largest area, deepest first)
MAX_POINTS = 4

#: ``ContactRows.status`` of a pair: apart, touching or overlapping, or left to a later (batched) stage
APART, TOUCHING, DEFERRED = 0, 1, 2

#: the per-pair output of the contact kernels, one row per pair p (a bundle of arrays that numba passes as one
#: argument): ``status`` (k,) int8; ``separation`` (k,); ``normal`` (k, 3) from the pair's first shape to its
#: second; ``feature_a``, ``feature_b`` (k,) int8; ``count`` (k,) int64 points; ``points`` (k, MAX_POINTS, 3);
#: ``ids`` (k, MAX_POINTS) int64 point ids
ContactRows = namedtuple("ContactRows", "status separation normal feature_a feature_b count points ids")


def contact_rows(k: int) -> ContactRows:
    """Fresh ContactRows for k pairs (status APART, no point)."""
    return ContactRows(np.zeros(k, np.int8), np.zeros(k), np.zeros((k, 3)), np.zeros(k, np.int8),
                       np.zeros(k, np.int8), np.zeros(k, np.int64), np.zeros((k, MAX_POINTS, 3)),
                       np.zeros((k, MAX_POINTS), np.int64))


_KEY_BITS = 20
_ID_BITS = 23
_BUMP_BITS = 46


@njit(inline="always")
def feature_key(kind, index):
    """A feature of one shape as an int64: ``kind`` (1 vertex, 2 edge, 3 face) and its ``index`` (< 2^20)."""
    return (np.int64(kind) << _KEY_BITS) | np.int64(index)


@njit(inline="always")
def key_kind(key):
    """The kind (1 vertex, 2 edge, 3 face) of a feature key."""
    return np.int8(key >> _KEY_BITS)


@njit(inline="always")
def point_id(key_a, key_b):
    """The id of a contact point made by feature ``key_a`` of the first shape and ``key_b`` of the second."""
    return (np.int64(key_a) << _ID_BITS) | np.int64(key_b)


@njit(inline="always")
def swap_point_id(pid):
    """The id of the same point with the two shapes' roles exchanged."""
    low = (np.int64(1) << _ID_BITS) - 1
    return ((pid & low) << _ID_BITS) | ((pid >> _ID_BITS) & low) | ((pid >> _BUMP_BITS) << _BUMP_BITS)


def describe_point_id(pid: int) -> str:
    """Spell out the two features a contact point id names, the first shape's first.

    Parameters
    ----------
    pid : int
        A point id of ``ContactSet.point_ids``.

    Returns
    -------
    str
        E.g. ``"vertex 3 - face 1"``, with ``" (#2)"`` appended when two points of a pair shared the features.

    Examples
    --------
    >>> from engine.world import describe_point_id
    >>> describe_point_id(8796121333761)
    'vertex 3 - face 1'
    """
    pid = int(pid)
    bump = pid >> _BUMP_BITS
    pid &= (1 << _BUMP_BITS) - 1
    keys = (pid >> _ID_BITS, pid & ((1 << _ID_BITS) - 1))
    text = " - ".join(f"{FEATURE_NAMES.get(k >> _KEY_BITS, '?')} {k & ((1 << _KEY_BITS) - 1)}" for k in keys)
    return text + (f" (#{bump + 1})" if bump else "")


@njit(inline="always")
def write_pair(rows, p, separation, nx, ny, nz, fa, fb, count, flip):
    """Row p of ``rows``: touching (separation <= 0) or apart; the normal and features given for the kernel's own
    order (A, B) are stored for the pair's order: ``flip`` means the pair's first shape is the kernel's B."""
    rows.status[p] = TOUCHING if separation <= 0.0 else APART
    rows.separation[p] = separation
    sign = -1.0 if flip else 1.0
    rows.normal[p, 0] = sign * nx
    rows.normal[p, 1] = sign * ny
    rows.normal[p, 2] = sign * nz
    rows.feature_a[p] = fb if flip else fa
    rows.feature_b[p] = fa if flip else fb
    rows.count[p] = count


@njit(inline="always")
def write_point(rows, p, slot, x, y, z, key_a, key_b, flip):
    """Contact point ``slot`` of pair p, made by feature key_a of the kernel's A and key_b of its B."""
    rows.points[p, slot, 0] = x
    rows.points[p, slot, 1] = y
    rows.points[p, slot, 2] = z
    rows.ids[p, slot] = point_id(key_b, key_a) if flip else point_id(key_a, key_b)


#: work space of the contact kernels, allocated once per batch (``kernel_scratch``): no kernel allocates per
#: pair. ``mat`` (3, 3), ``vec`` (8,), ``ivec`` (8,) int64; the clipping polygons ``poly``, ``work`` (9, 6) and
#: their tags ``tags``, ``work_tags`` (9, 4) int64; candidate points ``pts`` (m, 3), ``deep`` (m,), ``ids`` (m,)
#: int64; the 4 points kept by ``reduce_manifold``: ``red_p`` (4, 3), ``red_d`` (4,), ``red_i`` (4,) int64
Scratch = namedtuple("Scratch", "mat vec ivec poly work tags work_tags pts deep ids red_p red_d red_i")


def kernel_scratch(m: int = 9) -> Scratch:
    """Scratch for kernels over shapes of at most m core points."""
    n = max(int(m), 9)
    return Scratch(np.empty((3, 3)), np.empty(8), np.zeros(8, np.int64), np.empty((9, 6)), np.empty((9, 6)),
                   np.zeros((9, 4), np.int64), np.zeros((9, 4), np.int64), np.empty((n, 3)), np.empty(n),
                   np.empty(n, np.int64), np.empty((MAX_POINTS, 3)), np.empty(MAX_POINTS),
                   np.empty(MAX_POINTS, np.int64))


@njit(inline="always")
def _area(points, a, b, c, nx, ny, nz):
    """(p_b − p_a) × (p_c − p_a) · n: twice the signed area of the triangle of points a, b, c seen along n."""
    ux, uy, uz = points[b, 0] - points[a, 0], points[b, 1] - points[a, 1], points[b, 2] - points[a, 2]
    vx, vy, vz = points[c, 0] - points[a, 0], points[c, 1] - points[a, 1], points[c, 2] - points[a, 2]
    return (uy * vz - uz * vy) * nx + (uz * vx - ux * vz) * ny + (ux * vy - uy * vx) * nz


@njit
def reduce_manifold(points, depths, ids, count, nx, ny, nz, scratch):
    """Keep at most MAX_POINTS of the ``count`` candidate points (points (n, 3), depths (n,), ids (n,), rewritten
    in place in their first rows; returns the new count): the deepest point, the one farthest from it, then the
    two that add the largest triangle area on either side of that segment (the area-maximising choice of Bullet's
    ``sortCachedPoints``; ODE's ``cullPoints`` keeps 4 by angle). Ids equal within the pair are made distinct."""
    if count > MAX_POINTS:
        k0 = 0
        for i in range(1, count):
            if depths[i] > depths[k0]:
                k0 = i
        k1, best = -1, -1.0
        for i in range(count):  # the farthest from the deepest
            d = (points[i, 0] - points[k0, 0]) ** 2 + (points[i, 1] - points[k0, 1]) ** 2 \
                + (points[i, 2] - points[k0, 2]) ** 2
            if d > best:
                k1, best = i, d
        k2, k3, best2, best3 = -1, -1, 0.0, 0.0  # largest area on the positive, then on the negative side
        for i in range(count):
            area = _area(points, k0, k1, i, nx, ny, nz)
            if area > best2 and i != k0 and i != k1:
                k2, best2 = i, area
            if -area > best3 and i != k0 and i != k1:
                k3, best3 = i, -area
        kept = 0
        for k in (k0, k1, k2, k3):
            if k >= 0:
                for c in range(3):
                    scratch.red_p[kept, c] = points[k, c]
                scratch.red_d[kept] = depths[k]
                scratch.red_i[kept] = ids[k]
                kept += 1
        for s in range(kept):
            for c in range(3):
                points[s, c] = scratch.red_p[s, c]
            depths[s] = scratch.red_d[s]
            ids[s] = scratch.red_i[s]
        count = kept
    for i in range(1, count):  # two points of one pair never share an id
        for j in range(i):
            while ids[i] == ids[j]:
                ids[i] += np.int64(1) << _BUMP_BITS
    return count


@njit
def mark_persisting(prev_pairs, prev_ids, pairs, offsets, ids, persists):
    """persists[q] = whether point q (pair p's points are ids[offsets[p]:offsets[p + 1]], pairs (k, 2)) has the
    same pair and id in the previous frame (prev_pairs (k', 2), prev_ids (M',), one row per point, sorted by
    (pair, id)): a binary search per point."""
    n_prev = prev_ids.shape[0]
    for p in range(pairs.shape[0]):
        a = pairs[p, 0]
        b = pairs[p, 1]
        for q in range(offsets[p], offsets[p + 1]):
            lo = 0
            hi = n_prev
            while lo < hi:  # first row >= (a, b, id)
                mid = (lo + hi) // 2
                ma = prev_pairs[mid, 0]
                mb = prev_pairs[mid, 1]
                if ma < a or (ma == a and (mb < b or (mb == b and prev_ids[mid] < ids[q]))):
                    lo = mid + 1
                else:
                    hi = mid
            persists[q] = (lo < n_prev and prev_pairs[lo, 0] == a and prev_pairs[lo, 1] == b
                           and prev_ids[lo] == ids[q])


def feature_name(code, radius) -> str:
    """The name of feature ``code`` (VERTEX, EDGE, FACE) of a shape swept by ``radius``: "vertex", "edge",
    "face", or on a rounded shape (radius > 0) "sphere", "cylinder", "face"."""
    return (ROUND_FEATURE_NAMES if radius > 0 else FEATURE_NAMES)[int(code)]


class PairFeatureNames:
    """Feature names, computed on demand, of a record of k pairs with feature codes ``feature_a``, ``feature_b``
    (k,) and radii ``radius_a``, ``radius_b`` (k,)."""

    feature_a: np.ndarray
    feature_b: np.ndarray
    radius_a: np.ndarray
    radius_b: np.ndarray

    @property
    def names_a(self) -> list:
        """The first shape's feature of every pair: "vertex", "edge", "face" (rounded: "sphere", "cylinder")."""
        return [feature_name(c, r) for c, r in zip(self.feature_a, self.radius_a)]

    @property
    def names_b(self) -> list:
        """The second shape's feature of every pair, as ``names_a``."""
        return [feature_name(c, r) for c, r in zip(self.feature_b, self.radius_b)]

    @property
    def kind(self) -> list:
        """"vertex-face", "edge-edge" ... for every pair (the first shape's feature first)."""
        return [f"{a}-{b}" for a, b in zip(self.names_a, self.names_b)]


@dataclass(frozen=True)
class ContactSet(PairFeatureNames):
    """The contacts of k pairs of shapes, as arrays: the one contact record of ``World.contacts()``.

    Point ids and feature keys are described in ``engine.narrowphase.contacts``; ``len(contacts)`` is k and
    ``names_a``, ``names_b``, ``kind`` give the feature names as lists of k strings.

    Attributes
    ----------
    pairs : numpy.ndarray, shape (k, 2), int64
        The two shapes of each pair (for ``World``: body ids, i < j, rows in lexicographic order of (i, j,
        part_a, part_b): a pair of bodies has one row, a compound one row per touching pair of parts).
    separation, depth : numpy.ndarray, shape (k,), float64
        Signed distance (< 0 penetrating, 0 touching, > 0 apart), and depth = max(−separation, 0).
    normal : numpy.ndarray, shape (k, 3), float64
        Unit vectors from the pair's first shape to its second: translating the second by depth · normal
        separates the pair.
    feature_a, feature_b : numpy.ndarray, shape (k,), int8
        The touching feature of each side, a code of ``FEATURE_NAMES`` (1 vertex, 2 edge, 3 face).
    points : numpy.ndarray, shape (M, 3), float64
        Every pair's contact points, packed.
    point_offsets : numpy.ndarray, shape (k + 1,), int64
        Pair p owns rows ``point_offsets[p]:point_offsets[p + 1]`` of ``points`` (``points_of(p)``).
    radius_a, radius_b : numpy.ndarray, shape (k,), float64
        Sweeping radii of the two sides (> 0: a rounded shape, whose features are named sphere, cylinder, face).
    point_ids : numpy.ndarray, shape (M,), int64, or None
        Per point, which feature of each shape made it: the same id while the same two features touch
        (``describe_point_id``).
    persists : numpy.ndarray, shape (M,), bool, or None
        Whether that point (same pair, same id) was in the previous frame's contacts (World only).
    closest_a, closest_b : numpy.ndarray, shape (k, 3), float64, or None
        GJK's closest (or EPA's deepest) points, when given.
    exact_fallback : numpy.ndarray, shape (k,), bool, or None
        Pairs whose depth came from Qhull, when given.
    part_a, part_b : numpy.ndarray, shape (k,), int64, or None
        For ``World``: the part of each side that touches (a ``Compound``'s part number; 0 for any other body).
    """

    pairs: np.ndarray
    separation: np.ndarray
    depth: np.ndarray
    normal: np.ndarray
    feature_a: np.ndarray
    feature_b: np.ndarray
    points: np.ndarray
    point_offsets: np.ndarray
    radius_a: np.ndarray
    radius_b: np.ndarray
    point_ids: np.ndarray | None = None
    persists: np.ndarray | None = None
    closest_a: np.ndarray | None = None
    closest_b: np.ndarray | None = None
    exact_fallback: np.ndarray | None = None
    part_a: np.ndarray | None = None
    part_b: np.ndarray | None = None

    def __len__(self) -> int:
        return int(self.pairs.shape[0])

    def points_of(self, p: int) -> np.ndarray:
        """The contact points of pair p.

        Parameters
        ----------
        p : int
            A row, 0 <= p < k.

        Returns
        -------
        numpy.ndarray, shape (m, 3), float64
            A view of ``points`` (1 <= m <= 4 for a World contact).
        """
        return self.points[self.point_offsets[p]:self.point_offsets[p + 1]]

    def ids_of(self, p: int) -> np.ndarray:
        """The point ids of pair p.

        Parameters
        ----------
        p : int
            Which pair (a row).

        Returns
        -------
        numpy.ndarray, shape (m,), int64
            A view of ``point_ids``, aligned with ``points_of(p)``.
        """
        assert self.point_ids is not None, "this ContactSet carries no point ids"
        return self.point_ids[self.point_offsets[p]:self.point_offsets[p + 1]]



def contact_set_from_rows(rows: ContactRows, pairs, radius_a, radius_b, *, keep=None,
                          keep_apart: bool = False) -> ContactSet:
    """The ContactSet of the rows whose status is TOUCHING (every row with ``keep_apart``; or the rows ``keep``,
    an index array, in its order), their points packed in row order. ``pairs`` (k, 2), ``radius_a``,
    ``radius_b`` (k,)."""
    if keep is None:
        keep = np.flatnonzero(np.ones(rows.status.shape[0], np.bool_) if keep_apart else rows.status == TOUCHING)
    sel = keep
    count = rows.count[sel]
    offsets = np.zeros(sel.shape[0] + 1, np.int64)
    np.cumsum(count, out=offsets[1:])
    slot = np.arange(rows.points.shape[1])[None, :] < count[:, None]
    separation = rows.separation[sel]
    return ContactSet(pairs=np.ascontiguousarray(pairs[sel]), separation=separation,
                      depth=np.maximum(-separation, 0.0), normal=rows.normal[sel], feature_a=rows.feature_a[sel],
                      feature_b=rows.feature_b[sel], points=rows.points[sel][slot], point_offsets=offsets,
                      radius_a=np.asarray(radius_a)[sel], radius_b=np.asarray(radius_b)[sel],
                      point_ids=rows.ids[sel][slot], persists=np.zeros(int(offsets[-1]), np.bool_))


def contact_of_one_pair(kernel, args, radius_a: float = 0.0, radius_b: float = 0.0,
                        scratch_points: int | None = 9) -> ContactSet:
    """The ContactSet of one pair (``pairs`` [[0, 1]], kept when apart too) from a contact kernel called as
    ``kernel(*args, rows, 0, False, scratch)``: row 0 of fresh ContactRows, no flip, and a ``kernel_scratch``
    for shapes of at most ``scratch_points`` core points (``None``: the kernel takes no scratch argument).
    ``radius_a``, ``radius_b``: the rounding radii of the pair's first and second shape."""
    rows = contact_rows(1)
    if scratch_points is None:
        kernel(*args, rows, 0, False)
    else:
        kernel(*args, rows, 0, False, kernel_scratch(scratch_points))
    return contact_set_from_rows(rows, np.array([[0, 1]], np.int64), np.array([float(radius_a)]),
                                 np.array([float(radius_b)]), keep_apart=True)
