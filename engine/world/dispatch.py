"""The dispatch tables of the narrow phase — overlap, contact, time of impact — keyed by (shape kind, shape kind),
grounds included, in ONE place.

As in Box2D (``b2_registers`` in ``contact.c``), parry (``DefaultQueryDispatcher``) and Jolt
(``CollisionDispatch``): every candidate pair of the broad phase is answered by the kernel its two shapes' kinds
select. A table row maps (kind_a, kind_b), kind_a <= kind_b (codes of engine/world/shapes.py), to a kernel code;
``table_array`` turns a table into a (kinds × kinds) int8 array that the compiled frame indexes per pair.
Adding a shape kind means adding its rows (and, for a new closed form, its kernel code).

Kernels answered inside the compiled loop (``answer_pairs``, ``impact_pairs``), exact to round-off:
- ``ROUND_CORES``: sphere–sphere, sphere–capsule, capsule–capsule (closest points of segments, Ericson 5.1.9;
  engine.narrowphase.segment_segment);
- ``SPHERE_BOX``: the closest point of an OBB (Ericson 5.1.3; engine.narrowphase.sphere_box);
- ``BOX_BOX`` (contacts: SAT + the clipped manifold, engine.narrowphase.box_box) and ``BOX_BOX_SAT`` (overlap:
  its separating-axis test alone);
- ``BODY_PLANE``: every body against a ``Plane`` (its core points against the ground's half-space,
  engine.narrowphase.plane);
- ``SPHERE_SPHERE_TOI``, ``PLANE_TOI``: times of impact of two translating spheres (a quadratic) and of a
  translating body over a plane (its lowest point moves linearly).
Kernels answered after the loop, one batched call per kernel for all its pairs (``DEFERRED``):
- ``GJK_DISTANCE`` / ``GJK_EPA``: the pairs with no closed form (hulls, box–capsule): GJK distance, then EPA
  and the contact features (engine.narrowphase, ``engine/world/convex.py``);
- ``CURVE_OVERLAP``, ``SPHERE_CURVE_OVERLAP``, ``CURVE_CONTACT``, ``CURVE_TOI``: a body against a ``HeightCurve``
  (its function f is a Python callable, evaluated on numpy arrays: ``engine/world/curve.py``);
- ``ADVANCEMENT``: conservative advancement (engine.narrowphase.time_of_impact_pairs).
"""
from __future__ import annotations

import math

import numpy as np

from engine._config import njit
from engine.narrowphase.box_box import contact_box_box, overlap_box_box
from engine.narrowphase.contacts import APART, DEFERRED, TOUCHING
from engine.narrowphase.plane import contact_points_plane
from engine.narrowphase.segment_segment import contact_round_cores
from engine.narrowphase.sphere_box import contact_sphere_box

from .convex import gjk_contact_rows, gjk_overlap_rows
from .curve import curve_candidates, curve_rows
from .shapes import BOX, CAPSULE, CURVE, HULL, KIND_NAMES, PLANE, SPHERE

__all__ = ["OVERLAP_TABLE", "CONTACT_TABLE", "IMPACT_TABLE", "NARROW_TESTS", "KERNEL_NAMES", "table_array",
           "overlapping_boxes", "answer_pairs", "impact_pairs", "ROUND_CORES", "SPHERE_BOX", "BOX_BOX",
           "BOX_BOX_SAT", "BODY_PLANE",
           "GJK_DISTANCE", "GJK_EPA", "CURVE_OVERLAP", "SPHERE_CURVE_OVERLAP", "CURVE_CONTACT",
           "SPHERE_SPHERE_TOI", "PLANE_TOI", "ADVANCEMENT", "CURVE_TOI", "COMPILED_KERNELS",
           "GROUND_CANDIDATES", "DEFERRED_ROWS"]

# kernel codes (0: no kernel — ground against ground, never asked)
ROUND_CORES, SPHERE_BOX, BOX_BOX, BOX_BOX_SAT, BODY_PLANE = 1, 2, 3, 4, 5
GJK_DISTANCE, GJK_EPA, CURVE_OVERLAP, SPHERE_CURVE_OVERLAP, CURVE_CONTACT = 6, 7, 8, 9, 10
SPHERE_SPHERE_TOI, PLANE_TOI, ADVANCEMENT, CURVE_TOI = 11, 12, 13, 14
KERNEL_NAMES = {ROUND_CORES: "closest points of segments", SPHERE_BOX: "closest point of an OBB",
                BOX_BOX: "box SAT + clipping", BOX_BOX_SAT: "box SAT", BODY_PLANE: "core points against a plane",
                GJK_DISTANCE: "GJK distance", GJK_EPA: "GJK/EPA + contact features",
                CURVE_OVERLAP: "lower boundary against the curve", SPHERE_CURVE_OVERLAP: "circle against the curve",
                CURVE_CONTACT: "deepest point under the curve", SPHERE_SPHERE_TOI: "sphere sweep (quadratic)",
                PLANE_TOI: "lowest point sweep (linear)", ADVANCEMENT: "conservative advancement",
                CURVE_TOI: "bisection on the curve gap"}
#: the codes answered inside the compiled loop; every other code is DEFERRED to its batched row
COMPILED_KERNELS = frozenset({ROUND_CORES, SPHERE_BOX, BOX_BOX, BOX_BOX_SAT, BODY_PLANE, SPHERE_SPHERE_TOI,
                              PLANE_TOI})

_BODIES = (SPHERE, BOX, CAPSULE, HULL)


def _rows(closed_forms: dict, otherwise: int, plane: int, curve: int, sphere_curve: int) -> dict:
    table = {}
    for x, a in enumerate(_BODIES):
        for b in _BODIES[x:]:
            table[(a, b)] = closed_forms.get((a, b), otherwise)
        table[(a, PLANE)] = plane
        table[(a, CURVE)] = sphere_curve if a == SPHERE else curve
    return table


_ROUND = {(SPHERE, SPHERE): ROUND_CORES, (SPHERE, CAPSULE): ROUND_CORES, (CAPSULE, CAPSULE): ROUND_CORES,
          (SPHERE, BOX): SPHERE_BOX}

#: "do they overlap?" (touching counts): (kind_a, kind_b) -> kernel code
OVERLAP_TABLE = _rows({**_ROUND, (BOX, BOX): BOX_BOX_SAT}, GJK_DISTANCE, BODY_PLANE, CURVE_OVERLAP,
                      SPHERE_CURVE_OVERLAP)
#: "where do they touch?" (depth, normal, features, points)
CONTACT_TABLE = _rows({**_ROUND, (BOX, BOX): BOX_BOX}, GJK_EPA, BODY_PLANE, CURVE_CONTACT, CURVE_CONTACT)
#: "when do they touch?" (bodies translating with their velocities)
IMPACT_TABLE = _rows({(SPHERE, SPHERE): SPHERE_SPHERE_TOI}, ADVANCEMENT, PLANE_TOI, CURVE_TOI, CURVE_TOI)
#: the overlap table, under its former name
NARROW_TESTS = OVERLAP_TABLE


def _plane_candidates(plane, lo, hi) -> np.ndarray:
    # the contact kernel computes (altitude - centre) + radius, whose round-off can reach 0 where lo = centre -
    # radius is a few ulps above the plane: the candidates take that round-off in, the kernel decides
    slack = 4.0 * np.finfo(float).eps * (abs(plane.altitude) + np.abs(lo[:, 1]) + (hi[:, 1] - lo[:, 1]))
    return lo[:, 1] <= plane.altitude + slack


#: ground kind -> which bodies' AABBs (lo, hi (n, 3)) may touch that ground: bool (n,)
GROUND_CANDIDATES = {PLANE: _plane_candidates, CURVE: curve_candidates}

#: the kernels answered after the compiled loop, by one batched call each: code -> rows(bodies, pairs, sel,
#: rows, grounds) filling rows ``sel`` of ``rows`` (grounds: {id: shape})
DEFERRED_ROWS = {
    GJK_DISTANCE: lambda bodies, pairs, sel, rows, grounds: gjk_overlap_rows(bodies, pairs, sel, rows),
    GJK_EPA: lambda bodies, pairs, sel, rows, grounds: gjk_contact_rows(bodies, pairs, sel, rows),
    CURVE_OVERLAP: lambda bodies, pairs, sel, rows, grounds: curve_rows(bodies, pairs, sel, rows, grounds, False),
    SPHERE_CURVE_OVERLAP: lambda bodies, pairs, sel, rows, grounds: curve_rows(bodies, pairs, sel, rows, grounds,
                                                                               False),
    CURVE_CONTACT: lambda bodies, pairs, sel, rows, grounds: curve_rows(bodies, pairs, sel, rows, grounds, True),
}


def table_array(table: dict) -> np.ndarray:
    """A table as a symmetric (kinds × kinds) int8 array (0 where no row: ground–ground)."""
    out = np.zeros((len(KIND_NAMES), len(KIND_NAMES)), np.int8)
    for (a, b), code in table.items():
        out[a, b] = out[b, a] = code
    return out


@njit(inline="always")
def _boxes_overlap(bodies, i, j):
    for c in range(3):
        if bodies.lo[i, c] > bodies.hi[j, c] or bodies.lo[j, c] > bodies.hi[i, c]:
            return False
    return True


@njit(inline="always")
def _point(points, b, v):
    return points[b, v, 0], points[b, v, 1], points[b, v, 2]


@njit
def overlapping_boxes(bodies, pairs, counts):
    """The candidate pairs (k, 2) whose AABBs overlap (closed), in order, as a new (k', 2) array; ``counts``
    ((kinds, kinds) int64) += the number of them per (kind, kind), lower kind first. A pair with a ground is
    kept as it is: the ground's own candidate test (``GROUND_CANDIDATES``) has already allowed for round-off."""
    out = np.empty_like(pairs)
    m = 0
    for p in range(pairs.shape[0]):
        i, j = pairs[p, 0], pairs[p, 1]
        if bodies.kind[i] >= PLANE or bodies.kind[j] >= PLANE or _boxes_overlap(bodies, i, j):
            out[m, 0], out[m, 1] = i, j
            m += 1
            ki, kj = bodies.kind[i], bodies.kind[j]
            counts[min(ki, kj), max(ki, kj)] += 1
    return out[:m]


@njit
def answer_pairs(bodies, pairs, table, rows, scratch):
    """The compiled narrow phase: for every pair (pairs (k, 2), ids, AABBs overlapping), the kernel
    ``table[kind_i, kind_j]`` (an overlap or a contact table) into row p of ``rows``
    (engine.narrowphase.contacts.ContactRows); the kernel's A is the shape of lower kind, ``flip`` when that is
    the pair's second; ``scratch``: engine.narrowphase.contacts.kernel_scratch(points per body). Codes outside
    COMPILED_KERNELS get status DEFERRED."""
    for p in range(pairs.shape[0]):
        i, j = pairs[p, 0], pairs[p, 1]
        flip = bodies.kind[i] > bodies.kind[j]
        a, b = (j, i) if flip else (i, j)
        code = table[bodies.kind[a], bodies.kind[b]]
        if code == ROUND_CORES:
            contact_round_cores(_point(bodies.points, a, 0), _point(bodies.points, a, bodies.count[a] - 1),
                                bodies.radius[a], _point(bodies.points, b, 0),
                                _point(bodies.points, b, bodies.count[b] - 1), bodies.radius[b], rows, p, flip)
        elif code == SPHERE_BOX:
            contact_sphere_box(bodies.center, bodies.radius, bodies.rotation, bodies.half, a, b, rows, p, flip,
                               scratch)
        elif code == BOX_BOX:
            contact_box_box(bodies.center, bodies.rotation, bodies.half, a, b, rows, p, flip, scratch)
        elif code == BOX_BOX_SAT:
            touch = overlap_box_box(bodies.center, bodies.rotation, bodies.half, a, b, scratch)
            rows.status[p] = TOUCHING if touch else APART
        elif code == BODY_PLANE:
            contact_points_plane(bodies.points, bodies.count, bodies.radius, a,
                                 (bodies.center[b, 0], bodies.center[b, 1], bodies.center[b, 2]),
                                 (bodies.rotation[b, 0, 1], bodies.rotation[b, 1, 1], bodies.rotation[b, 2, 1]),
                                 rows, p, flip, scratch)
        else:
            rows.status[p] = DEFERRED


@njit
def _sphere_sweep(bodies, a, b, dt):
    """First t in [0, dt] at which spheres a, b (translating) touch, inf if none: |d0 + w t| = r_a + r_b."""
    dx, dy, dz = (bodies.center[b, 0] - bodies.center[a, 0], bodies.center[b, 1] - bodies.center[a, 1],
                  bodies.center[b, 2] - bodies.center[a, 2])
    wx, wy, wz = (bodies.velocity[b, 0] - bodies.velocity[a, 0], bodies.velocity[b, 1] - bodies.velocity[a, 1],
                  bodies.velocity[b, 2] - bodies.velocity[a, 2])
    reach = bodies.radius[a] + bodies.radius[b]
    c0 = dx * dx + dy * dy + dz * dz - reach * reach
    if c0 <= 0.0:
        return 0.0
    half_b = dx * wx + dy * wy + dz * wz
    aa = wx * wx + wy * wy + wz * wz
    disc = half_b * half_b - aa * c0
    if half_b >= 0.0 or disc < 0.0:
        return np.inf  # moving apart, or passing by
    t = c0 / (-half_b + math.sqrt(disc))  # the smaller root, without cancellation
    return t if t <= dt else np.inf


@njit
def _plane_sweep(bodies, a, g, dt):
    """First t in [0, dt] at which body a (translating) touches plane g: its lowest point moves linearly."""
    up = bodies.rotation[g, :, 1]
    low = np.inf
    for v in range(bodies.count[a]):
        low = min(low, (bodies.points[a, v, 0] - bodies.center[g, 0]) * up[0]
                  + (bodies.points[a, v, 1] - bodies.center[g, 1]) * up[1]
                  + (bodies.points[a, v, 2] - bodies.center[g, 2]) * up[2])
    gap = low - bodies.radius[a]
    if gap <= 0.0:
        return 0.0
    rate = bodies.velocity[a, 0] * up[0] + bodies.velocity[a, 1] * up[1] + bodies.velocity[a, 2] * up[2]
    if rate >= 0.0:
        return np.inf
    t = gap / -rate
    return t if t <= dt else np.inf


@njit
def impact_pairs(bodies, pairs, table, dt, times, deferred):
    """Times of impact within [0, dt] (inf: none) of the pairs whose ``table`` kernel is a closed form;
    ``deferred[p]`` is set for the others."""
    for p in range(pairs.shape[0]):
        i, j = pairs[p, 0], pairs[p, 1]
        a, b = (j, i) if bodies.kind[i] > bodies.kind[j] else (i, j)
        code = table[bodies.kind[a], bodies.kind[b]]
        deferred[p] = False
        if code == SPHERE_SPHERE_TOI:
            times[p] = _sphere_sweep(bodies, a, b, dt)
        elif code == PLANE_TOI:
            times[p] = _plane_sweep(bodies, a, b, dt)
        else:
            deferred[p] = True
            times[p] = np.inf
