"""Shape queries of a ``World``: which bodies a box or a shape overlaps, and what a shape swept along a
translation hits first (the query layer of Box2D's ``b2World_OverlapAABB`` / ``b2World_OverlapShape`` /
``b2World_CastShape``, Jolt's ``CollideShape`` / ``CastShape``).

The query shape answers through the world's own dispatch table (engine/world/rows.py), as a body would: it is
written into scratch rows of the body store past the live ones (``BodyStore.scratch``: no id taken, the free ids,
``n_ids``, the broad phases, the filters, events, contact persistence and ``World.stats`` untouched; the rows are
wiped on exit, also after an error), then its candidate pairs (body, query) go through
``engine.world.dispatch.answer`` with the filter off (the query's ``mask`` selected the bodies beforehand).

- Candidates: one vectorised pass over the store's live bodies (moving and static) with the closed box test
  ``lo_b <= hi and lo <= hi_b``; a ground (unbounded kind) is a candidate when its kind's ``candidates(shape, lo,
  hi)`` test accepts the box (a box wholly above a ``Plane`` does not report it). Compound parts are never
  reported: the compound is, by its id. The pass costs O(bodies) numpy work per query (about a millisecond for
  1e5 bodies) and reads no broad-phase structure, so every ``broad_phase`` answers alike.
- Mask: a body is reported iff ``category_body & mask != 0``. The query has no category of its own, so the
  bodies' masks, groups and exclusions play no part.
- Sensors: ``query_aabb`` and ``overlap`` report them (they are bodies; a mask leaves them out);
  ``cast_shape`` never hits them (as ``time_of_impact`` and ``contacts``: a sensor is no obstacle).
- ``cast_shape``: the impact question of the table with the query's rows moving by the displacement over
  dt = 1 and every body held still (a velocity array of zeros but for the query rows replaces the store's in the
  kernels' view: the bodies' own velocities are not read) — closed forms for two spheres and for a Plane,
  conservative advancement (distance <= 1e-9 at the returned fraction) for the other convex pairs, bisection for
  a HeightCurve; the earliest fraction wins, ties to the lowest id. Point and normal: the contact question at the
  pose moved to that fraction; when the pair is still apart there by the advancement's tolerance, a bounded body
  gives GJK's closest points instead (normal along them, point halfway between the two surfaces: exact to
  round-off at that pose); a ground, or cores that meet to round-off with no contact row yet, give the contact of
  the pose pushed on along the cast (towards the body's centre for no displacement, down into a ground) by the
  smallest of 1e-12, 2e-12, 4e-12, ... times the scene's scale that touches (the point is then off the pose at
  the fraction by that push, ~1e-9 at most in practice).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from engine._validate import as_float_array
from engine.bounding.aabb import check_ordered
from engine.narrowphase import gjk_distance
from engine.narrowphase.contacts import TOUCHING, kernel_scratch

from .bodies import BodyStore, refresh_bodies
from .dispatch import NarrowContext, answer
from .rows import TABLE
from .shapes import Shape

__all__ = ["ShapeHit", "as_box", "as_query_shape", "bodies_in_box", "overlapping_bodies", "cast"]

_NO_QUATERNIONS = np.empty((0, 4))
_NO_VECTORS = np.empty((0, 3))


@dataclass(frozen=True)
class ShapeHit:
    """The answer of ``World.cast_shape``: the first body the swept shape touches, when and where.

    Attributes
    ----------
    fraction : float
        In [0, 1]: the shape touches the body first when translated by ``fraction * displacement`` (0 when it
        already touches at its start).
    body : int
        The id of the body hit (a compound's id, never a part; grounds included).
    point : numpy.ndarray, shape (3,), float64
        A contact point at that moment (the mean of the contact's points: on both surfaces, to ~1e-9).
    normal : numpy.ndarray, shape (3,), float64
        Unit; the hit surface's normal, pointing from the body hit towards the cast shape (against the motion).
    """

    fraction: float
    body: int
    point: np.ndarray
    normal: np.ndarray


def as_box(lo, hi) -> tuple[np.ndarray, np.ndarray]:
    """A closed box from corners ``lo``, ``hi`` ((3,), finite, lo <= hi): ValueError / TypeError naming them."""
    lo_, hi_ = as_float_array(lo, "lo", shape=(3,)), as_float_array(hi, "hi", shape=(3,))
    check_ordered(lo_, hi_)
    return lo_, hi_


def as_query_shape(shape) -> Shape:
    """A body shape for a query: TypeError for a non-shape, ValueError for a ground or a triangle surface (a
    static-only kind: never paired with another static shape)."""
    if not isinstance(shape, Shape):
        raise TypeError(f"shape must be an engine shape (Sphere, Box, Capsule, ConvexPolyhedron, Compound), got "
                        f"{type(shape).__name__}")
    if not shape.kind.bounded or shape.kind.static_only:
        raise ValueError(f"shape must be a body shape (sphere, box, capsule, hull or compound), got a "
                         f"{shape.kind.name}: a ground cannot be a query shape")
    return shape


def bodies_in_box(store: BodyStore, grounds: dict, lo, hi, mask: int, *, sensors: bool = True) -> np.ndarray:
    """Ids (sorted int64) of the live bodies whose AABB overlaps the closed box [lo, hi] ((3,) each) — grounds by
    their kind's candidates test — with ``category & mask != 0`` (and not sensors unless ``sensors``)."""
    n = store.n_ids
    keep = (store.kind[:n] >= 0) & (store.owner[:n] < 0) & store.bounded[:n]
    keep &= (store.lo[:n] <= hi).all(axis=1) & (lo <= store.hi[:n]).all(axis=1)
    keep &= (store.category[:n] & np.uint64(mask)) != 0
    if not sensors:
        keep &= ~store.sensor[:n]
    for g, ground in grounds.items():
        passes = (int(store.category[g]) & mask) != 0 and (sensors or not store.sensor[g])
        keep[g] = passes and bool(ground.kind.candidates(ground, lo[None], hi[None])[0])
    return np.flatnonzero(keep).astype(np.int64)


def _context(store: BodyStore, grounds: dict, has_parts: bool, dt: float = 0.0, velocity=None) -> NarrowContext:
    view = store.view()
    if velocity is not None:
        view = view._replace(velocity=velocity)
    return NarrowContext(view, grounds, kernel_scratch(view.points.shape[1]), dt, has_parts)


def _pairs_with(bodies: np.ndarray, row: int) -> np.ndarray:
    return np.ascontiguousarray(np.stack([bodies, np.full(bodies.shape[0], row, np.int64)], axis=1))


def overlapping_bodies(store: BodyStore, grounds: dict, has_compounds: bool, shape: Shape, mask: int, *,
                       shapes: dict | None = None) -> np.ndarray:
    """Ids (sorted int64) of the bodies (sensors included) with ``category & mask != 0`` whose shapes overlap
    ``shape`` (closed), through the overlap rows of the dispatch table. ``shapes``: {id: Shape} of every body whose
    kernels read the shape object (the grounds, the triangle surfaces; default ``grounds``)."""
    shapes = grounds if shapes is None else shapes
    with store.scratch(shape) as rows:
        q = rows[0]
        cand = bodies_in_box(store, grounds, store.lo[q].copy(), store.hi[q].copy(), mask)
        if cand.shape[0] == 0:
            return cand
        ctx = _context(store, shapes, has_compounds or len(rows) > 1)
        result = answer(TABLE, "overlap", ctx, _pairs_with(cand, q))
        return cand[np.unique(result.origin[result.out.status == TOUCHING])]


def cast(store: BodyStore, grounds: dict, has_compounds: bool, shape: Shape, displacement, mask: int, *,
         shapes: dict | None = None):
    """The first body (not a sensor, ``category & mask != 0``) that ``shape`` touches while translated by
    ``fraction * displacement``, fraction in [0, 1]: a ``ShapeHit``, or None (see the module docstring);
    ``shapes`` as ``overlapping_bodies``'."""
    shapes = grounds if shapes is None else shapes
    with store.scratch(shape) as rows:
        q = rows[0]
        lo, hi = store.lo[q].copy(), store.hi[q].copy()
        cand = bodies_in_box(store, grounds, np.minimum(lo, lo + displacement), np.maximum(hi, hi + displacement),
                             mask, sensors=False)
        if cand.shape[0] == 0:
            return None
        has_parts = has_compounds or len(rows) > 1
        velocity = np.zeros_like(store.velocity)
        velocity[rows] = displacement
        result = answer(TABLE, "impact", _context(store, shapes, has_parts, 1.0, velocity), _pairs_with(cand, q))
        times = np.full(cand.shape[0], np.inf)
        np.minimum.at(times, result.origin, result.out)
        first = int(np.argmin(times))  # the first of the minima: cand is sorted, so the lowest id wins ties
        if not np.isfinite(times[first]):
            return None
        fraction = float(min(max(times[first], 0.0), 1.0))
        body = int(cand[first])
        center = shape.center + fraction * displacement
        point, normal = _touch(store, shapes, has_parts, shape, rows, body, center,
                               _push_direction(store, body, center, displacement))
        return ShapeHit(fraction=fraction, body=body, point=point, normal=normal)


def _place(store: BodyStore, row: int, shape: Shape, center) -> None:
    refresh_bodies(store.view(), np.array([row]), np.asarray(center, np.float64)[None], 1,
                   np.ascontiguousarray(shape.rotation, dtype=np.float64)[None], _NO_QUATERNIONS, _NO_VECTORS)


def _contact(store, grounds, has_parts, body, q):
    """(point, normal) of the deepest touching row of the contact (body, query) at the query's current pose, or
    None when no row touches."""
    result = answer(TABLE, "contact", _context(store, grounds, has_parts), _pairs_with(np.array([body]), q))
    rows = result.out
    touching = np.flatnonzero(rows.status == TOUCHING)
    if touching.size == 0:
        return None
    best = touching[np.argmin(rows.separation[touching])]
    n = rows.normal[best]
    points = rows.points[best, : max(int(rows.count[best]), 1)]
    return points.mean(axis=0), n / np.linalg.norm(n)


def _closest(store: BodyStore, body: int, rows: list) -> tuple[np.ndarray, np.ndarray] | None:
    """(point, normal) from GJK's closest points of the body's cores and the query's (the nearest pair of parts):
    the normal from the body to the query, the point halfway between the two surfaces; None when the cores meet
    (no direction)."""
    best = None
    for b in store.parts_of(body) or [body]:
        for s in rows[1:] or rows:
            d, ca, cb = gjk_distance(store.points[b, : store.count[b]], store.points[s, : store.count[s]])
            gap = d - store.radius[b] - store.radius[s]
            if d > 0.0 and (best is None or gap < best[0]):
                n = (cb - ca) / d
                best = (gap, 0.5 * ((ca + store.radius[b] * n) + (cb - store.radius[s] * n)), n)
    return None if best is None else (best[1], best[2])


def _push_direction(store, body, center, displacement) -> np.ndarray:
    """Where to push the query into the body it hit when its kernels see no contact yet: along the cast, or
    (no displacement) towards the body's centre, or down into a ground."""
    length = float(np.linalg.norm(displacement))
    if length > 0.0:
        return displacement / length
    towards = store.center[body] - center
    if store.bounded[body] and np.linalg.norm(towards) > 0.0:
        return towards / np.linalg.norm(towards)
    return np.array([0.0, -1.0, 0.0])


def _surface_closest(store, grounds, has_parts, body, q):
    """(point, normal) of a triangle surface and the query from the distance question: its witnesses (the normal
    from the surface to the query, the point halfway between them); None when they meet."""
    result = answer(TABLE, "distance", _context(store, grounds, has_parts), _pairs_with(np.array([body]), q),
                    margin=np.inf)
    out = result.out
    if out.distance.shape[0] == 0 or not out.distance.min() > 0.0:
        return None
    best = int(np.argmin(out.distance))
    return 0.5 * (out.point_a[best] + out.point_b[best]), out.normal[best]


def _touch(store, grounds, has_parts, shape, rows, body, center, push_direction):
    """Point and normal of the contact of the query (scratch rows ``rows``) at ``center`` with ``body``
    (``grounds``: the shapes the kernels read)."""
    q = rows[0]
    _place(store, q, shape, center)
    found = _contact(store, grounds, has_parts, body, q)
    kind = grounds[body].kind if body in grounds else None
    surface = kind is not None and kind.bounded and kind.static_only  # a triangle surface: its core is its box
    if found is None and surface:
        found = _surface_closest(store, grounds, has_parts, body, q)
    elif found is None and store.bounded[body]:
        found = _closest(store, body, rows)
    if found is None:  # cores that meet to round-off yet no contact row (or a ground): push the query in
        scale = max(1.0, float(np.abs(store.lo[q]).max()), float(np.abs(store.hi[q]).max()))
        push = 1e-12 * scale
        while found is None and push < 1e-3 * scale:
            _place(store, q, shape, center + push * push_direction)
            found = _contact(store, grounds, has_parts, body, q)
            push *= 2.0
        _place(store, q, shape, center)
    if found is None:
        raise RuntimeError(f"cast_shape: no contact with body {body} at the fraction of its impact")
    point, normal = found
    return np.array(point, np.float64), np.array(normal, np.float64)
