"""The rows of the dispatch table: for every (shape kind, shape kind) pair, the kernel that answers each question
("overlap", "contact", "impact", "distance"; engine/world/dispatch.py), and the batched loops that feed the
narrow-phase kernels (engine/narrowphase/) from the body store.

Closed forms, exact to round-off:
- sphere–sphere, sphere–capsule, capsule–capsule: the closest points of their segments (Ericson 5.1.9);
- sphere–box: the closest point of an OBB (Ericson 5.1.3); box–box: SAT, and the clipped manifold for contacts;
- every convex body against a ``Plane``: its core points against the half-space; its time of impact is linear;
- two spheres' time of impact: a quadratic (Ericson 5.5.5).
Every other pair of convex kinds falls back on GJK distance / GJK + EPA + contact features, and conservative
advancement for the time of impact (parry's explicit GJK fallback); their signed distance is GJK's distance apart
and EPA's depth overlapping (engine.narrowphase.signed_distance, which also turns the closed forms' contact rows
into witness points). A convex body against a ``HeightCurve``:
engine.narrowphase.curve_ground (f is a Python callable). A convex body against a ``TriangleMesh`` or a
``HeightField``: engine.narrowphase.mesh_contact (the candidate triangles under the body's box, one kernel per
triangle, the active-edge fix, the merge), one compiled call per surface. A ``Compound`` is answered part by
part. Two static-only shapes (grounds, surfaces) are never paired: their cells are explicitly unsupported.
"""
from __future__ import annotations

import numpy as np

from engine._config import njit
from engine.narrowphase import time_of_impact_pairs
from engine.narrowphase.box_box import contact_box_box, overlap_box_box
from engine.narrowphase.contacts import APART, TOUCHING, contact_rows
from engine.narrowphase.convex_cores import Cores, gjk_contact_rows, gjk_overlap_rows, pack_cores
from engine.narrowphase.curve_ground import curve_contact_rows, curve_impact_times, curve_overlap
from engine.narrowphase.mesh_contact import (
    BODY_BOX,
    BODY_HULL,
    BODY_ROUND,
    IMPACT_ITERATIONS,
    mesh_contact_rows,
    mesh_distance_rows,
    mesh_impact_times,
    mesh_overlap_rows,
    mesh_work,
)
from engine.narrowphase.plane import contact_points_plane, impact_time_plane
from engine.narrowphase.segment_segment import contact_round_cores
from engine.narrowphase.signed_distance import (
    convex_distance_rows,
    curve_distance_rows,
    distance_plane,
    sign_like_overlap,
    witnesses_from_contact,
)
from engine.narrowphase.sphere_box import contact_sphere_box
from engine.narrowphase.sphere_sweep import impact_time_spheres
from engine.narrowphase.status import raise_for_status

from .dispatch import PARTS, QUESTIONS, DispatchTable, Kernel, unsupported
from .kinds import KINDS
from .shapes import BOX, CAPSULE, CURVE, FIELD, HULL, MESH, PLANE, SPHERE

__all__ = ["ROUND_CORES", "SPHERE_BOX", "BOX_BOX", "BOX_BOX_SAT", "BODY_PLANE", "GJK_DISTANCE", "GJK_EPA",
           "CURVE_OVERLAP", "CURVE_CONTACT", "SPHERE_SWEEP", "PLANE_SWEEP", "ADVANCEMENT", "CURVE_SWEEP",
           "ROUND_CORES_DISTANCE", "SPHERE_BOX_DISTANCE", "BOX_BOX_DISTANCE", "PLANE_DISTANCE", "GJK_EPA_DISTANCE",
           "CURVE_DISTANCE", "MESH_OVERLAP", "MESH_CONTACT", "MESH_SWEEP", "MESH_DISTANCE", "ROWS", "TABLE"]


@njit(inline="always")
def _oriented(kind, pairs, p):
    """(a, b, flip): the kernel's A is the pair's shape of lower kind code (``kind``: the store's kind codes)."""
    i, j = pairs[p, 0], pairs[p, 1]
    if kind[i] > kind[j]:
        return j, i, True
    return i, j, False


@njit(inline="always")
def _ground_second(bounded, pairs, p):
    """(a, g, flip): the body first, the ground (the unbounded shape) second, whatever their kind codes."""
    i, j = pairs[p, 0], pairs[p, 1]
    if bounded[i]:
        return i, j, False
    return j, i, True


@njit(inline="always")
def _point(points, b, v):
    return points[b, v, 0], points[b, v, 1], points[b, v, 2]


@njit
def _round_cores_rows(bodies, pairs, sel, rows):
    for p in sel:
        a, b, flip = _oriented(bodies.kind, pairs, p)
        contact_round_cores(_point(bodies.points, a, 0), _point(bodies.points, a, bodies.count[a] - 1),
                            bodies.radius[a], _point(bodies.points, b, 0),
                            _point(bodies.points, b, bodies.count[b] - 1), bodies.radius[b], rows, p, flip)


@njit
def _sphere_box_rows(bodies, pairs, sel, rows, scratch):
    for p in sel:
        a, b, flip = _oriented(bodies.kind, pairs, p)
        contact_sphere_box(bodies.center, bodies.radius, bodies.rotation, bodies.half, a, b, rows, p, flip, scratch)


@njit
def _box_box_rows(bodies, pairs, sel, rows, scratch):
    for p in sel:
        a, b, flip = _oriented(bodies.kind, pairs, p)
        contact_box_box(bodies.center, bodies.rotation, bodies.half, a, b, rows, p, flip, scratch)


@njit
def _box_box_sat_rows(bodies, pairs, sel, rows, scratch):
    for p in sel:
        a, b, _ = _oriented(bodies.kind, pairs, p)
        touch = overlap_box_box(bodies.center, bodies.rotation, bodies.half, a, b, scratch)
        rows.status[p] = TOUCHING if touch else APART


@njit
def _plane_rows(bodies, pairs, sel, rows, scratch):
    for p in sel:
        a, g, flip = _ground_second(bodies.bounded, pairs, p)
        contact_points_plane(bodies.points, bodies.count, bodies.radius, a,
                             (bodies.center[g, 0], bodies.center[g, 1], bodies.center[g, 2]),
                             (bodies.rotation[g, 0, 1], bodies.rotation[g, 1, 1], bodies.rotation[g, 2, 1]),
                             rows, p, flip, scratch)


@njit
def _sphere_sweep_times(bodies, pairs, sel, dt, times):
    for p in sel:
        a, b, _ = _oriented(bodies.kind, pairs, p)
        times[p] = impact_time_spheres(bodies.center[a], bodies.center[b], bodies.velocity[a], bodies.velocity[b],
                                       bodies.radius[a] + bodies.radius[b], dt)


@njit
def _plane_sweep_times(bodies, pairs, sel, dt, times):
    for p in sel:
        a, g, _ = _ground_second(bodies.bounded, pairs, p)
        times[p] = impact_time_plane(bodies.points, bodies.count, bodies.radius, bodies.velocity[a], a,
                                     bodies.center[g], bodies.rotation[g, :, 1], dt)


@njit
def _plane_distances(bodies, pairs, sel, out):
    for p in sel:
        a, g, flip = _ground_second(bodies.bounded, pairs, p)
        distance_plane(bodies.points, bodies.count, bodies.radius, a,
                       (bodies.center[g, 0], bodies.center[g, 1], bodies.center[g, 2]),
                       (bodies.rotation[g, 0, 1], bodies.rotation[g, 1, 1], bodies.rotation[g, 2, 1]), out, p, flip)


@njit
def _box_box_touching(bodies, pairs, sel, scratch):
    touch = np.empty(sel.shape[0], np.bool_)
    for q in range(sel.shape[0]):
        a, b, _ = _oriented(bodies.kind, pairs, sel[q])
        touch[q] = overlap_box_box(bodies.center, bodies.rotation, bodies.half, a, b, scratch)
    return touch


def _witness_rows(rows_kernel):
    """A distance kernel from a contact kernel whose point 0 lies halfway between the surfaces (the closed forms):
    the contact rows, then their witnesses."""
    def run(ctx, pairs, sel, out):
        rows = contact_rows(pairs.shape[0])
        rows_kernel(ctx, pairs, sel, rows)
        witnesses_from_contact(rows, sel, out)
    return run


def _box_box_distances(ctx, pairs, sel, out) -> None:
    """GJK/EPA on the corners, the sign of the SAT (the overlap question's test: pairs() and the distance agree)."""
    convex_distance_rows(_cores(ctx.bodies), pairs, sel, out)
    sign_like_overlap(out, sel, _box_box_touching(ctx.bodies, pairs, sel, ctx.scratch))


def _gjk_distances(ctx, pairs, sel, out) -> None:
    """GJK/EPA on the cores, the sign of the overlap test (core distance − radii <= 0)."""
    cores = _cores(ctx.bodies)
    core_distance = convex_distance_rows(cores, pairs, sel, out)
    pr = pairs[sel]
    sign_like_overlap(out, sel, core_distance - cores.radius[pr[:, 0]] - cores.radius[pr[:, 1]] <= 0.0)


def _cores(bodies) -> Cores:
    return Cores(bodies.points, bodies.count, bodies.radius, bodies.lo, bodies.hi)


def _advancement_times(ctx, pairs, sel, times) -> None:
    points, offsets, local, radii = pack_cores(_cores(ctx.bodies), pairs[sel])
    ids = np.unique(pairs[sel])
    times[sel] = time_of_impact_pairs(points, offsets, ctx.bodies.velocity[ids], local, t_max=ctx.dt, radii=radii)


def _by_curve(ctx, pairs, sel):
    """Per curve ground g among the pairs ``pairs[sel]``: (g's shape, the rows of its pairs, their bodies, whether
    the curve is the pair's first shape)."""
    bodies = ctx.bodies
    pr = pairs[sel]
    is_curve = bodies.kind[pr] == CURVE.code
    for g in np.unique(pr[is_curve]).tolist():
        mine = (pr == g).any(axis=1)
        rows, sub = sel[mine], pr[mine]
        first = sub[:, 0] == g
        yield ctx.shapes[g], rows, np.where(first, sub[:, 1], sub[:, 0]), first


def _curve_rows(ctx, pairs, sel, rows, contacts: bool) -> None:
    bodies = ctx.bodies
    for curve, at, body, first in _by_curve(ctx, pairs, sel):
        hit = curve_overlap(curve, bodies.points[body], bodies.radius[body], bodies.center[body],
                            bodies.kind[body] == SPHERE.code)
        rows.status[at] = np.where(hit, TOUCHING, APART)
        if contacts:
            curve_contact_rows(curve, bodies.points[body[hit]], bodies.radius[body[hit]], bodies.center[body[hit]],
                               first[hit], rows, at[hit])


def _curve_distances(ctx, pairs, sel, out) -> None:
    bodies = ctx.bodies
    for curve, at, body, first in _by_curve(ctx, pairs, sel):
        curve_distance_rows(curve, bodies.points[body], bodies.radius[body], bodies.center[body],
                            bodies.kind[body] == SPHERE.code, first, out, at)


def _curve_times(ctx, pairs, sel, times) -> None:
    bodies = ctx.bodies
    for curve, at, body, _ in _by_curve(ctx, pairs, sel):
        times[at] = curve_impact_times(curve, bodies.points[body], bodies.radius[body], bodies.velocity[body],
                                       ctx.dt)


def _by_surface(ctx, pairs, sel):
    """Per triangle surface g (a TriangleMesh or HeightField) among the pairs ``pairs[sel]``: (g's MeshArrays, the
    rows of its pairs, their bodies, each body's shape code of engine.narrowphase.mesh_contact, whether the
    surface is the pair's first shape)."""
    bodies = ctx.bodies
    pr = pairs[sel]
    kinds = bodies.kind[pr]
    for g in np.unique(pr[(kinds == MESH.code) | (kinds == FIELD.code)]).tolist():
        mine = (pr == g).any(axis=1)
        rows, sub = sel[mine], pr[mine]
        first = sub[:, 0] == g
        body = np.ascontiguousarray(np.where(first, sub[:, 1], sub[:, 0]))
        kind = bodies.kind[body]
        shape = np.where(kind == BOX.code, BODY_BOX, np.where(kind == HULL.code, BODY_HULL, BODY_ROUND))
        yield ctx.shapes[g].mesh, np.ascontiguousarray(rows), body, shape.astype(np.int64), first


def _mesh_answers(kernel):
    """A Kernel.run over the surfaces' pairs: ``kernel(mesh, bodies, shape, body, at, flip, out, work)`` per
    surface, with scratch of its own (mesh_work: any thread may run it)."""
    def run(ctx, pairs, sel, out):
        for mesh, at, body, shape, first in _by_surface(ctx, pairs, sel):
            kernel(mesh, ctx.bodies, shape, body, at, first, out, mesh_work(mesh, ctx.bodies.points.shape[1]))
    return run


def _mesh_times(ctx, pairs, sel, times) -> None:
    for mesh, at, body, _, _ in _by_surface(ctx, pairs, sel):
        status = np.zeros(at.shape[0], np.int64)
        mesh_impact_times(mesh, ctx.bodies, body, float(ctx.dt), times, at, status)
        raise_for_status(status, IMPACT_ITERATIONS, "pairs")


# -- the kernels ------------------------------------------------------------------------------------------
ROUND_CORES = Kernel("closest points of segments", lambda ctx, pairs, sel, out:
                     _round_cores_rows(ctx.bodies, pairs, sel, out))
SPHERE_BOX = Kernel("closest point of an OBB", lambda ctx, pairs, sel, out:
                    _sphere_box_rows(ctx.bodies, pairs, sel, out, ctx.scratch))
BOX_BOX = Kernel("box SAT + clipping", lambda ctx, pairs, sel, out:
                 _box_box_rows(ctx.bodies, pairs, sel, out, ctx.scratch))
BOX_BOX_SAT = Kernel("box SAT", lambda ctx, pairs, sel, out: _box_box_sat_rows(ctx.bodies, pairs, sel, out,
                                                                                ctx.scratch))
BODY_PLANE = Kernel("core points against a plane", lambda ctx, pairs, sel, out:
                    _plane_rows(ctx.bodies, pairs, sel, out, ctx.scratch))
GJK_DISTANCE = Kernel("GJK distance", lambda ctx, pairs, sel, out:
                      gjk_overlap_rows(_cores(ctx.bodies), pairs, sel, out))
GJK_EPA = Kernel("GJK/EPA + contact features", lambda ctx, pairs, sel, out:
                 gjk_contact_rows(_cores(ctx.bodies), pairs, sel, out))
# the curve's rows call its Python function f: one thread (f need not be thread-safe)
CURVE_OVERLAP = Kernel("lower boundary (a sphere: its disc) against the curve", lambda ctx, pairs, sel, out:
                       _curve_rows(ctx, pairs, sel, out, False), threaded=False)
CURVE_CONTACT = Kernel("deepest point under the curve", lambda ctx, pairs, sel, out:
                       _curve_rows(ctx, pairs, sel, out, True), threaded=False)
SPHERE_SWEEP = Kernel("sphere sweep (quadratic)", lambda ctx, pairs, sel, out:
                      _sphere_sweep_times(ctx.bodies, pairs, sel, ctx.dt, out))
PLANE_SWEEP = Kernel("lowest point sweep (linear)", lambda ctx, pairs, sel, out:
                     _plane_sweep_times(ctx.bodies, pairs, sel, ctx.dt, out))
ADVANCEMENT = Kernel("conservative advancement", _advancement_times)
CURVE_SWEEP = Kernel("bisection on the curve gap", _curve_times, threaded=False)

ROUND_CORES_DISTANCE = Kernel("closest points of segments, witnesses", _witness_rows(ROUND_CORES.run))
SPHERE_BOX_DISTANCE = Kernel("closest point of an OBB, witnesses", _witness_rows(SPHERE_BOX.run))
BOX_BOX_DISTANCE = Kernel("GJK/EPA on the corners, sign of the SAT", _box_box_distances)
PLANE_DISTANCE = Kernel("lowest core point against a plane", lambda ctx, pairs, sel, out:
                        _plane_distances(ctx.bodies, pairs, sel, out))
GJK_EPA_DISTANCE = Kernel("GJK distance / EPA depth", _gjk_distances)
CURVE_DISTANCE = Kernel("distance to the sampled curve / depth under it", _curve_distances, threaded=False)
MESH_OVERLAP = Kernel("candidate triangles: the first touching one", _mesh_answers(mesh_overlap_rows))
MESH_CONTACT = Kernel("candidate triangles, active edges, the deepest triangle's normal",
                      _mesh_answers(mesh_contact_rows))
MESH_SWEEP = Kernel("conservative advancement against the triangles under the swept box", _mesh_times)
MESH_DISTANCE = Kernel("the nearest triangle (boxes grown until no farther one can be nearer)",
                       _mesh_answers(mesh_distance_rows))
_MESH = {"overlap": MESH_OVERLAP, "contact": MESH_CONTACT, "impact": MESH_SWEEP, "distance": MESH_DISTANCE}

_GJK = {"overlap": GJK_DISTANCE, "contact": GJK_EPA, "impact": ADVANCEMENT, "distance": GJK_EPA_DISTANCE}
_ROUND = {"overlap": ROUND_CORES, "contact": ROUND_CORES, "impact": ADVANCEMENT, "distance": ROUND_CORES_DISTANCE}

#: (kind_a, kind_b), lower code first -> {question: Kernel}
ROWS: dict = {
    (SPHERE, SPHERE): {**_ROUND, "impact": SPHERE_SWEEP},
    (SPHERE, CAPSULE): _ROUND,
    (CAPSULE, CAPSULE): _ROUND,
    (SPHERE, BOX): {"overlap": SPHERE_BOX, "contact": SPHERE_BOX, "impact": ADVANCEMENT,
                    "distance": SPHERE_BOX_DISTANCE},
    (BOX, BOX): {"overlap": BOX_BOX_SAT, "contact": BOX_BOX, "impact": ADVANCEMENT, "distance": BOX_BOX_DISTANCE},
}
for _x, _a in enumerate(KINDS):
    for _b in KINDS[_x:]:
        if (_a, _b) in ROWS:
            continue
        if _a.composite or _b.composite:
            ROWS[_a, _b] = dict.fromkeys(QUESTIONS, PARTS)
        elif _a.convex and _b.convex:
            ROWS[_a, _b] = _GJK
        elif PLANE in (_a, _b) and (_a.convex or _b.convex):  # the kernels find the ground by its unboundedness
            ROWS[_a, _b] = {"overlap": BODY_PLANE, "contact": BODY_PLANE, "impact": PLANE_SWEEP,
                            "distance": PLANE_DISTANCE}
        elif CURVE in (_a, _b) and (_a.convex or _b.convex):  # ... and by its kind
            ROWS[_a, _b] = {"overlap": CURVE_OVERLAP, "contact": CURVE_CONTACT, "impact": CURVE_SWEEP,
                            "distance": CURVE_DISTANCE}
        elif (MESH in (_a, _b) or FIELD in (_a, _b)) and (_a.convex or _b.convex):  # ... by its kind
            ROWS[_a, _b] = _MESH
        else:
            ROWS[_a, _b] = dict.fromkeys(QUESTIONS, unsupported(
                f"a {_a.name} against a {_b.name}: two static shapes are never paired"))

#: the table every World reads
TABLE = DispatchTable(ROWS)
