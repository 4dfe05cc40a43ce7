"""The contact manifold: the pipeline's last stage — "l'instant et le lieu précis (vertex, côtés, faces) de
contact" (the "where"; the "when" is engine.narrowphase.time_of_impact).

``contact_feature`` finds, for two convex shapes (convex hulls of point sets, optionally swept by a ball of radius
r: spheres, capsules, rounded boxes), the contact normal n (from A towards B; GJK's closest points when they are
apart, EPA's normal when they overlap: engine.narrowphase.penetration) and the supporting feature of each shape
along it (engine.narrowphase.features): the vertices of A within ``feature_tol`` of A's support plane max a·n,
and of B within it of min b·n. One vertex is a *vertex*, two (or collinear ones) an *edge*, three or more a
*face*; the pair names the contact (vertex–face, edge–edge, face–face, edge–face ...). The contact points are
the intersection of the two features projected on the plane orthogonal to n (engine.narrowphase.clipping:
Sutherland–Hodgman for face–face, Ericson 8.3.4 / Box2D's ``b2ClipPolygons``; segment clipping for edge–face;
closest points of two segments for edge–edge, Ericson 5.1.9), placed on the mid-plane between the two support
planes:

    n, signed distance, closest points <- the penetration chain (GJK → EPA → exact fallback)
    F_A <- feature of A's support set along n;  F_B <- feature of B's support set along −n
    points <- F_A ∩ F_B in the plane ⊥ n, repeated and flat points dropped, lifted to the mid-plane

Overlapping polyhedra (no radius) whose normal n lies within arccos(``box_box.FACE_KEEP_COS``) = 17.8° of a face
normal take their points from that face instead, by box–box's rule (``box_box.prefer_face``, ODE's
``fudge_factor``): between nearly flush hulls the penetration solver's n is often an edge–edge direction between
the two face normals and its support sets are a vertex or an edge, one point where the hulls touch over a
polygon. The face of either hull through its support vertex nearest to n (``features.adjacent_face``) is the
reference face; the other hull's most anti-parallel face, when within the angle too (the faces nearly flush), is
clipped by its side planes (as ``box_box``'s face manifold), and the clipped points below the reference face —
points of both hulls, so between the two support planes ⊥ n — are moved along n onto their mid-plane. The
separation and the normal stay the penetration chain's: translating B by depth · n separates the pair; only the
points and the feature names come from the face.

Kernels (public within the package): ``feature_scratch`` (``FeatureScratch``), ``contact_points`` (one pair) and
``contact_points_pairs`` (k pairs in one compiled loop).
"""
from __future__ import annotations

import math
from collections import namedtuple
from dataclasses import dataclass

import numpy as np

from .._config import njit
from .._validate import as_float_array, as_nonnegative, as_positive, as_radii, check_offsets, check_pairs
from .box_box import FACE_KEEP_COS, TIE, prefer_face
from .clipping import clip_polygon, clip_segment, closest_segments_2d, drop_flat_vertices
from .contacts import PairFeatureNames, feature_name
from .features import adjacent_face, feature_polygon, plane_basis, support_set
from .gjk import MAX_ITERATIONS
from .penetration import ONE_PAIR, penetration_pairs
from .rescale import largest_coordinate, rescale_unit
from .status import OVERLAP

__all__ = ["Contact", "ContactBatch", "contact_feature", "contact_feature_pairs", "FEATURE_TOL", "FeatureScratch",
           "feature_scratch", "contact_points", "contact_points_pairs"]

#: relative tolerance (× the size of the shapes) of the support-plane test that groups vertices into a feature
FEATURE_TOL = 1e-7



@dataclass(frozen=True)
class Contact:
    """The contact of one pair of convex shapes: whether they touch, and where (``contact_feature``'s answer).

    Attributes
    ----------
    separation : float
        Signed distance between the shapes: > 0 apart, 0 touching, < 0 minus the penetration depth.
    normal : numpy.ndarray, shape (3,), float64
        Unit vector from A towards B.
    feature_a, feature_b : str
        The feature of each side: "vertex", "edge" or "face" ("sphere" or "cylinder" on a rounded shape).
    kind : str
        Both names, A's first, e.g. "vertex-face".
    points : numpy.ndarray, shape (q, 3), float64
        The contact point(s) on the mid-plane between the two support planes: q = 1 for a vertex or crossing
        edges, 2 for an edge on a face or parallel edges, up to the clipped polygon's size for face–face.
        Nearly flush overlapping polyhedra (faces within arccos(``FACE_KEEP_COS``) of the normal): the points of
        the face manifold, on the same mid-plane (module docstring).
    closest_a, closest_b : numpy.ndarray, shape (3,), float64
        GJK's closest (or EPA's deepest) points of A and of B.
    """

    separation: float
    normal: np.ndarray
    feature_a: str
    feature_b: str
    kind: str
    points: np.ndarray
    closest_a: np.ndarray
    closest_b: np.ndarray

    @property
    def touching(self) -> bool:
        """Whether the shapes touch or overlap: ``separation <= 0``."""
        return self.separation <= 0.0


# ---------------------------------------------------------------------------------------------------------------
# kernels
# ---------------------------------------------------------------------------------------------------------------

#: the scratch of ``contact_points`` (see ``feature_scratch``)
FeatureScratch = namedtuple("FeatureScratch", ["S", "FA", "FB", "buf", "basis", "verts"])


@njit
def feature_scratch(n_max):
    """``contact_points``' scratch for shapes of up to ``n_max`` points, allocated here only: ``S`` (2 n_max + 2, 2)
    (support sets, then the clipped points), ``FA``, ``FB`` (n_max + 1, 2) (the two features), ``buf``
    (2, 2 n_max + 2, 2) (Sutherland–Hodgman's two halves), ``basis`` (2, 3) (the contact plane's frame) and
    ``verts`` (2, n_max) int64 (the vertices of a reference and an incident face)."""
    return FeatureScratch(np.empty((2 * n_max + 2, 2)), np.empty((n_max + 1, 2)), np.empty((n_max + 1, 2)),
                          np.empty((2, 2 * n_max + 2, 2)), np.empty((2, 3)), np.empty((2, n_max), np.int64))


@njit
def _pair_size(pa, pb, ra, rb):
    """The largest extent over the three axes of the two point sets together (at least ra + rb, and 1e-300)."""
    size = 0.0
    for c in range(3):
        lo = np.inf
        hi = -np.inf
        for i in range(pa.shape[0]):
            lo = min(lo, pa[i, c])
            hi = max(hi, pa[i, c])
        for i in range(pb.shape[0]):
            lo = min(lo, pb[i, c])
            hi = max(hi, pb[i, c])
        size = max(size, hi - lo)
    return max(size, ra + rb, 1e-300)


@njit
def _intersect_features(FA, na, FB, nb, tol, S, buf):
    """The intersection of the two features in the plane, into S; returns its number of points (0 when round-off
    left no overlap)."""
    if na == 1:
        S[0, 0], S[0, 1] = FA[0, 0], FA[0, 1]
        return 1
    if nb == 1:
        S[0, 0], S[0, 1] = FB[0, 0], FB[0, 1]
        return 1
    if na == 2 and nb == 2:
        return closest_segments_2d(FA, FB, tol, S)
    if na == 2:
        return clip_segment(FA[0, 0], FA[0, 1], FA[1, 0], FA[1, 1], FB, nb, S)
    if nb == 2:
        return clip_segment(FB[0, 0], FB[0, 1], FB[1, 0], FB[1, 1], FA, na, S)
    half, count = clip_polygon(FA, na, FB, nb, buf)
    for i in range(count):
        S[i, 0] = buf[half, i, 0]
        S[i, 1] = buf[half, i, 1]
    return count


@njit
def _drop_repeats(S, count, tol):
    """Drop the points of S[:count] within tol of an earlier one (greedy, first kept); returns the new count."""
    kept = 0
    for i in range(count):
        fresh = True
        for j in range(kept):
            dx = S[i, 0] - S[j, 0]
            dy = S[i, 1] - S[j, 1]
            if not math.sqrt(dx * dx + dy * dy) > tol:
                fresh = False
                break
        if fresh:
            S[kept, 0] = S[i, 0]
            S[kept, 1] = S[i, 1]
            kept += 1
    return kept


@njit
def _project(points, verts, count, basis, S):
    """The rows ``verts[:count]`` of ``points`` projected on ``basis`` (2, 3) into S[:count]."""
    for k in range(count):
        v = verts[k]
        for r in range(2):
            S[k, r] = points[v, 0] * basis[r, 0] + points[v, 1] * basis[r, 1] + points[v, 2] * basis[r, 2]


@njit
def _clipped_face(px, py, pz, level_i, level, m, n, mid, tol, scratch, out_points, start, count):
    """Lift the clipped polygon S[:count] (coordinates (s, t) on ``scratch.basis`` = (u, v), the plane ⊥ the
    reference normal m) onto the incident face's plane p·x = ``level_i`` (p = (px, py, pz) unit, p·m < 0): the
    point y = s u + t v + z m of that plane has z = (level_i − s p·u − t p·v) / p·m. Each y at most ``tol``
    above the reference face (z <= ``level`` + tol) lies in both hulls, so between the two support planes ⊥ n;
    it goes into out_points[start:] moved along n onto their mid-plane x·n = ``mid`` (at most half the depth
    away). Returns the number written."""
    S, basis = scratch.S, scratch.basis
    mu = px * basis[0, 0] + py * basis[0, 1] + pz * basis[0, 2]
    mv = px * basis[1, 0] + py * basis[1, 1] + pz * basis[1, 2]
    mm = px * m[0] + py * m[1] + pz * m[2]
    kept = 0
    for i in range(count):
        z = (level_i - S[i, 0] * mu - S[i, 1] * mv) / mm
        if level - z >= -tol:
            y0 = S[i, 0] * basis[0, 0] + S[i, 1] * basis[1, 0] + z * m[0]
            y1 = S[i, 0] * basis[0, 1] + S[i, 1] * basis[1, 1] + z * m[1]
            y2 = S[i, 0] * basis[0, 2] + S[i, 1] * basis[1, 2] + z * m[2]
            lift = mid - (y0 * n[0] + y1 * n[1] + y2 * n[2])
            out_points[start + kept, 0] = y0 + lift * n[0]
            out_points[start + kept, 1] = y1 + lift * n[1]
            out_points[start + kept, 2] = y2 + lift * n[2]
            kept += 1
    return kept


@njit
def _face_manifold(pa, pb, nx, ny, nz, top_a, bot_b, size, tol, scratch, out_points, start):
    """The face manifold of two overlapping polyhedra along the penetration normal n (box–box's ``prefer_face``
    on hulls): the face of either hull through its support vertex nearest to n (A's along n, B's along −n; A's
    on a tie) is the *reference* face when ``prefer_face`` keeps it (within arccos(``FACE_KEEP_COS``) of n);
    the other hull's face through its support vertex most anti-parallel to it, if within that angle too (the
    faces nearly flush), is the *incident* face, clipped by the reference face's side planes (Sutherland–Hodgman
    in the plane ⊥ its normal, Ericson 8.3.4; ODE's ``dBoxBox``, Box2D's ``b2ClipPolygons``), its points below
    the reference face kept and moved along n onto the mid-plane of the two support planes. Returns
    (kind_a, kind_b, count): the reference FACE and the incident feature its count spans; count 0 when no face
    is kept (the support features answer)."""
    verts = scratch.verts
    count_a, cos_a, ax, ay, az, level_a = adjacent_face(pa, nx, ny, nz, FACE_KEEP_COS, tol, verts[0])
    count_b, cos_b, bx, by, bz, level_b = adjacent_face(pb, -nx, -ny, -nz, FACE_KEEP_COS, tol, verts[1])
    if count_a < 3 and count_b < 3:
        return 0, 0, 0
    ref_is_a = count_a >= 3 and (count_b < 3 or cos_a >= cos_b)
    ref, inc = (pa, pb) if ref_is_a else (pb, pa)
    m = (ax, ay, az) if ref_is_a else (bx, by, bz)
    level, count, cos = (level_a, count_a, cos_a) if ref_is_a else (level_b, count_b, cos_b)
    ref_verts = verts[0] if ref_is_a else verts[1]
    bottom = np.inf  # the incident hull's lowest level along m: the face's overlap is level − bottom
    for i in range(inc.shape[0]):
        bottom = min(bottom, inc[i, 0] * m[0] + inc[i, 1] * m[1] + inc[i, 2] * m[2])
    if not prefer_face(level - bottom, top_a - bot_b, cos, TIE * size):
        return 0, 0, 0
    inc_verts = verts[1] if ref_is_a else verts[0]
    # the two faces nearly flush: the incident face within the angle too (a steeper one touches by the edge or
    # the vertex that the support sets give)
    count_i, _, px, py, pz, level_i = adjacent_face(inc, -m[0], -m[1], -m[2], FACE_KEEP_COS, tol, inc_verts)
    if count_i < 3:
        return 0, 0, 0
    S, basis = scratch.S, scratch.basis
    plane_basis(m[0], m[1], m[2], basis)
    _project(ref, ref_verts, count, basis, S)
    nr = feature_polygon(S, count, tol, scratch.FA)
    _project(inc, inc_verts, count_i, basis, S)
    ni = feature_polygon(S, count_i, tol, scratch.FB)
    if nr < 3 or ni < 3:
        return 0, 0, 0
    half, clipped = clip_polygon(scratch.FB, ni, scratch.FA, nr, scratch.buf)
    for i in range(clipped):
        S[i, 0], S[i, 1] = scratch.buf[half, i, 0], scratch.buf[half, i, 1]
    clipped = drop_flat_vertices(S, _drop_repeats(S, clipped, tol), tol)
    mid = 0.5 * (top_a + bot_b)
    kept = _clipped_face(px, py, pz, level_i, level, m, (nx, ny, nz), mid, tol, scratch, out_points, start,
                         clipped)
    kind = min(kept, 3)
    return (3, kind, kept) if ref_is_a else (kind, 3, kept)


@njit
def contact_points(pa, pb, ra, rb, n, ca, cb, ftol, scratch, out_points, start):
    """The "where" of one pair: hull(pa) swept by radius ``ra`` against hull(pb) swept by ``rb`` ((n, 3), (m, 3)
    float64), given the contact normal ``n`` (3,) (A towards B) and the closest (or deepest) points ``ca``, ``cb``
    (3,) of the cores. The support sets of A (within tol of max a·n) and of B (within tol of min b·n), projected on
    the plane ⊥ n, reduced to features, intersected, cleaned (repeated points, and polygon vertices flat between
    their neighbours, dropped) and lifted to the mid-plane between the two support planes. Writes the points into
    ``out_points[start:]`` (room for n + m + 1 rows); returns (kind_a, kind_b, count), kind 1 vertex, 2 edge, 3
    face. ``scratch`` from ``feature_scratch`` (max(n, m) points)."""
    S, basis = scratch.S, scratch.basis
    size = _pair_size(pa, pb, ra, rb)
    tol = ftol * size
    nx, ny, nz = n[0], n[1], n[2]
    top_a = -np.inf
    for i in range(pa.shape[0]):
        top_a = max(top_a, pa[i, 0] * nx + pa[i, 1] * ny + pa[i, 2] * nz)
    bot_b = np.inf
    for i in range(pb.shape[0]):
        bot_b = min(bot_b, pb[i, 0] * nx + pb[i, 1] * ny + pb[i, 2] * nz)
    if ra == 0.0 and rb == 0.0 and top_a >= bot_b:  # overlapping polyhedra: a face within the angle keeps them
        kind_a, kind_b, kept = _face_manifold(pa, pb, nx, ny, nz, top_a, bot_b, size, tol, scratch, out_points, start)
        if kept > 0:
            return kind_a, kind_b, kept
    plane_basis(nx, ny, nz, basis)
    na = feature_polygon(S, support_set(pa, nx, ny, nz, top_a, tol, 1, basis, S), tol, scratch.FA)
    nb = feature_polygon(S, support_set(pb, nx, ny, nz, bot_b, tol, -1, basis, S), tol, scratch.FB)
    count = _intersect_features(scratch.FA, na, scratch.FB, nb, tol, S, scratch.buf)
    if count == 0:  # round-off left no overlap: fall back on the closest points
        for r in range(2):
            S[0, r] = 0.5 * ((ca[0] + cb[0]) * basis[r, 0] + (ca[1] + cb[1]) * basis[r, 1]
                             + (ca[2] + cb[2]) * basis[r, 2])
        count = 1
    kept = drop_flat_vertices(S, _drop_repeats(S, count, tol), tol)
    mid = 0.5 * ((top_a + ra) + (bot_b - rb))
    for i in range(kept):
        for c in range(3):
            out_points[start + i, c] = S[i, 0] * basis[0, c] + S[i, 1] * basis[1, c] + mid * n[c]
    return min(na, 3), min(nb, 3), kept


@njit
def contact_points_pairs(points, offsets, pairs, radii, ftol, normal, closest_a, closest_b, kind_a, kind_b,
                         out_points, point_start, point_count):
    """``contact_points`` over k pairs of packed shapes (``points`` (N, 3), ``offsets`` (S + 1,), ``pairs`` (k, 2),
    ``radii`` (S,)) in one compiled loop, given each pair's ``normal`` and the closest points of the cores
    (``closest_a``, ``closest_b`` (k, 3), moved out to the swept surfaces here: + r_A n, − r_B n). Pair p writes
    kind_a[p], kind_b[p] (int8), point_count[p] points at ``out_points[point_start[p]:]``. Tiny or huge pairs are
    solved on copies scaled by a power of two (``rescale_unit``)."""
    n_max = np.int64(1)  # typed int64 from the start: feature_scratch is compiled for one size type
    for s in range(offsets.shape[0] - 1):
        n_max = max(n_max, offsets[s + 1] - offsets[s])
    scratch = feature_scratch(n_max)
    for p in range(pairs.shape[0]):
        i = pairs[p, 0]
        j = pairs[p, 1]
        pa = points[offsets[i]:offsets[i + 1]]
        pb = points[offsets[j]:offsets[j + 1]]
        ra = radii[i]
        rb = radii[j]
        unit = rescale_unit(max(largest_coordinate(pa, pb), ra, rb))
        if unit != 1.0:
            pa = pa * unit
            pb = pb * unit
            ra *= unit
            rb *= unit
            for c in range(3):
                closest_a[p, c] *= unit
                closest_b[p, c] *= unit
        ka, kb, cnt = contact_points(pa, pb, ra, rb, normal[p], closest_a[p], closest_b[p], ftol, scratch,
                                     out_points, point_start[p])
        kind_a[p] = ka
        kind_b[p] = kb
        point_count[p] = cnt
        for c in range(3):
            closest_a[p, c] = (closest_a[p, c] + ra * normal[p, c]) / unit
            closest_b[p, c] = (closest_b[p, c] - rb * normal[p, c]) / unit
            for q in range(point_start[p], point_start[p] + cnt):
                out_points[q, c] /= unit


# ---------------------------------------------------------------------------------------------------------------
# public functions
# ---------------------------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class ContactBatch(PairFeatureNames):
    """``contact_feature`` of k pairs, as arrays (``contact_feature_pairs``' answer).

    ``len(batch)`` is k and ``batch[p]`` the ``Contact`` of pair p (an int, negative counts from the end);
    ``names_a``, ``names_b`` and ``kind`` give the feature names as lists of k strings.

    Attributes
    ----------
    separation : numpy.ndarray, shape (k,), float64
        Signed distances (> 0 apart, 0 touching, < 0 penetrating).
    normal : numpy.ndarray, shape (k, 3), float64
        Unit vectors, from each pair's first shape towards its second.
    feature_a, feature_b : numpy.ndarray, shape (k,), int8
        Feature codes: 1 vertex, 2 edge, 3 face (on a rounded shape, radius > 0: sphere, cylinder, face).
    points, point_offsets : numpy.ndarray, shapes (M, 3) float64 and (k + 1,) int64
        Pair p's contact points are ``points[point_offsets[p]:point_offsets[p + 1]]``, at least one per pair.
    closest_a, closest_b : numpy.ndarray, shape (k, 3), float64
        The closest (or, overlapping, deepest) point of each side.
    radius_a, radius_b : numpy.ndarray, shape (k,), float64
        The sweeping radii of the two shapes of every pair.
    exact_fallback : numpy.ndarray, shape (k,), bool
        Pairs whose depth came from Qhull on the Minkowski difference (EPA broke down on round-off; see
        ``engine.narrowphase.epa``).
    """

    separation: np.ndarray
    normal: np.ndarray
    feature_a: np.ndarray
    feature_b: np.ndarray
    points: np.ndarray
    point_offsets: np.ndarray
    closest_a: np.ndarray
    closest_b: np.ndarray
    radius_a: np.ndarray
    radius_b: np.ndarray
    exact_fallback: np.ndarray

    def __len__(self) -> int:
        return int(self.separation.shape[0])

    def __getitem__(self, p) -> Contact:
        if isinstance(p, bool) or not isinstance(p, int | np.integer):
            raise TypeError(f"p must be an int, got {type(p).__name__}")
        k = len(self)
        if not -k <= p < k:
            raise IndexError(f"pair {p} outside a batch of {k}")
        p = int(p) % k
        fa = feature_name(self.feature_a[p], self.radius_a[p])
        fb = feature_name(self.feature_b[p], self.radius_b[p])
        return Contact(separation=float(self.separation[p]), normal=self.normal[p].copy(), feature_a=fa,
                       feature_b=fb, kind=f"{fa}-{fb}",
                       points=self.points[self.point_offsets[p]:self.point_offsets[p + 1]].copy(),
                       closest_a=self.closest_a[p].copy(), closest_b=self.closest_b[p].copy())


def _contact_batch(pts, off, pr, rad, ftol, max_iter) -> ContactBatch:
    """contact_feature_pairs on validated arrays: the penetration chain (with its exact fallback), then the
    features and contact points of every pair."""
    k = pr.shape[0]
    sizes = np.diff(off)
    room = sizes[pr[:, 0]] + sizes[pr[:, 1]] + 1 if k else np.zeros(0, np.int64)
    start = np.zeros(k + 1, np.int64)
    np.cumsum(room, out=start[1:])
    signed, normal, ca, cb, status, fallback = penetration_pairs(pts, off, pr, max_iter)
    # two coincident points: EPA's normal cone is every direction; any one will do, the same one every time
    if sizes.size and sizes.min() == 1:
        coincident = (status == OVERLAP) & (signed == 0.0) & (sizes[pr[:, 0]] == 1) & (sizes[pr[:, 1]] == 1)
        normal[coincident] = (1.0, 0.0, 0.0)
    separation = signed - rad[pr[:, 0]] - rad[pr[:, 1]]
    kind_a = np.zeros(k, np.int8)
    kind_b = np.zeros(k, np.int8)
    raw = np.empty((int(start[-1]), 3))
    count = np.zeros(k, np.int64)
    if k:
        contact_points_pairs(pts, off, pr, rad, ftol, normal, ca, cb, kind_a, kind_b, raw, start, count)
    point_offsets = np.zeros(k + 1, np.int64)
    np.cumsum(count, out=point_offsets[1:])
    # the rows of the points actually written: pair p's count rows from start[p]
    take = np.arange(point_offsets[-1]) + np.repeat(start[:-1] - point_offsets[:-1], count)
    return ContactBatch(separation=separation, normal=normal, feature_a=kind_a, feature_b=kind_b,
                        points=raw[take], point_offsets=point_offsets, closest_a=ca, closest_b=cb,
                        radius_a=rad[pr[:, 0]], radius_b=rad[pr[:, 1]], exact_fallback=fallback)


def contact_feature_pairs(points, offsets, pairs, *, radii=None, feature_tol: float = FEATURE_TOL) -> ContactBatch:
    """``contact_feature`` for k pairs of packed convex shapes, in one compiled call.

    GJK, EPA for overlapping pairs, the support sets, the features and their clipping all run in one compiled
    loop (chapter: "l'instant et le lieu précis (vertex, côtés, faces) de contact"; Ericson 9.5, 8.3.4, 5.1.9).
    Where EPA folds on round-off (rare, see ``engine.narrowphase.epa``) the depth and normal of that pair come
    from Qhull (Python), flagged in ``exact_fallback``.

    Parameters
    ----------
    points, offsets, pairs
        The shapes (shape s the hull of its points) and the pairs, repeats allowed: :ref:`packed-point-sets`.
    radii : array_like, shape (S,), optional
        Shape s is swept by a ball of radius ``radii[s]`` >= 0; default all 0 (polyhedra).
    feature_tol : float, default 1e-7
        Relative tolerance (times the pair's size) within which support points count as one feature, > 0.

    Returns
    -------
    ContactBatch
        One row per pair; ``batch[p]`` equals ``contact_feature`` on ``pairs[p]``.

    Raises
    ------
    ValueError
        For a negative radius or ``radii`` not of shape (S,), or ``feature_tol <= 0``, besides the checks of
        :ref:`packed-point-sets`.
    GJKNotConverged, EPANotConverged
        For the first pair (``pairs[p]``) that neither the iterations nor the exact fallback solve.
    """
    pts = as_float_array(points, "points", shape=(None, 3))
    off = check_offsets(offsets, pts.shape[0])
    s = off.shape[0] - 1
    rad = np.zeros(s) if radii is None else as_radii(radii, "radii", s, scalar=False)
    pr = check_pairs(pairs, s)
    ftol = as_positive(feature_tol, "feature_tol")
    return _contact_batch(pts, off, pr, rad, ftol, MAX_ITERATIONS)


def contact_feature(points_a, points_b, *, radius_a: float = 0.0, radius_b: float = 0.0,
                    feature_tol: float = FEATURE_TOL) -> Contact:
    """Contact normal, features and contact point(s) of two convex shapes.

    Shape A is the convex hull of ``points_a`` swept by a ball of ``radius_a`` (0: a polyhedron; a single point
    with radius r: a sphere; two points: a capsule); likewise B. Works whether the shapes are apart (the features
    that face each other across the gap), touching, or overlapping (the features along EPA's normal): the support
    sets of both shapes along the normal, projected on the contact plane, reduced to a vertex, an edge or a polygon
    and clipped against each other (Sutherland–Hodgman, Ericson 8.3.4).

    Parameters
    ----------
    points_a : array_like, shape (n, 3), float64
        The core of A, n >= 1, finite.
    points_b : array_like, shape (m, 3), float64
        The core of B, m >= 1.
    radius_a, radius_b : float, default 0.0
        The sweeping radii, >= 0.
    feature_tol : float, default 1e-7
        Relative tolerance for grouping support points into a feature, > 0.

    Returns
    -------
    Contact
        ``contact_feature_pairs`` on this one pair.

    Raises
    ------
    ValueError
        For an empty set, a wrong shape, NaN or ±inf (named ``points_a`` / ``points_b``), a negative radius or
        ``feature_tol <= 0``.
    GJKNotConverged, EPANotConverged
        When the pair is left unsolved (see ``epa_penetration``).

    Examples
    --------
    A ball of radius 0.25 centred 0.5 above a unit cube, and a cube sinking 0.1 into it:

    >>> import numpy as np
    >>> import engine
    >>> cube = np.array([[x, y, z] for x in (0.0, 1.0) for y in (0.0, 1.0) for z in (0.0, 1.0)])
    >>> c = engine.contact_feature(cube, [[0.5, 1.5, 0.5]], radius_b=0.25)
    >>> c.separation, c.kind, c.touching
    (0.25, 'face-sphere', False)
    >>> c.normal, c.points
    (array([0., 1., 0.]), array([[0.5  , 1.125, 0.5  ]]))
    >>> c = engine.contact_feature(cube, cube + [0.0, 0.9, 0.0])
    >>> round(c.separation, 12), c.kind, len(c.points)
    (-0.1, 'face-face', 4)
    """
    pa = as_float_array(points_a, "points_a", shape=(None, 3), min_rows=1)
    pb = as_float_array(points_b, "points_b", shape=(None, 3), min_rows=1)
    ra = as_nonnegative(radius_a, "radius_a")
    rb = as_nonnegative(radius_b, "radius_b")
    ftol = as_positive(feature_tol, "feature_tol")
    off = np.array([0, pa.shape[0], pa.shape[0] + pb.shape[0]], np.int64)
    batch = _contact_batch(np.concatenate([pa, pb]), off, ONE_PAIR, np.array([ra, rb]), ftol, MAX_ITERATIONS)
    return batch[0]
