"""Pairs of convex cores swept by balls, with no closed form (a hull against any body, a box against a capsule):
GJK distance (Ericson 9.5) for "do they overlap?", GJK/EPA and the contact features (``contact_feature_pairs``)
for "where?" — one batched call for all such pairs — and the point ids of those contacts.

The shapes come as ``Cores``: per shape s, its world core points ``points[s, :count[s]]`` (points (n, M, 3);
rows past the count repeat the first point), the radius sweeping them and its AABB. The cores of the pairs'
shapes are packed (``points`` (N, 3) + ``offsets``); a pair overlaps when the GJK distance of its cores is at
most the sum of the radii. A contact point's id names,
for each shape, the kind of its supporting feature along the normal (its vertices within
``engine.narrowphase.contact_manifold.FEATURE_TOL`` × the pair's size of the support plane: vertex, edge, face) and the
support vertex nearest to the point in the contact plane — the same while the same features touch.
"""
from __future__ import annotations

from collections import namedtuple

import numpy as np

from .._config import njit
from .contact_manifold import FEATURE_TOL, contact_feature_pairs
from .contacts import APART, TOUCHING, feature_key, kernel_scratch, point_id, reduce_manifold
from .gjk import gjk_distance_pairs

__all__ = ["Cores", "pack_cores", "gjk_overlap_rows", "gjk_contact_rows", "feature_point_ids",
           "nearest_support_vertex"]

#: n convex shapes as swept cores: ``points`` (n, M, 3) world core points (rows past ``count[s]`` repeat the
#: first), ``count`` (n,) int64, ``radius`` (n,), ``lo``, ``hi`` (n, 3) their AABBs
Cores = namedtuple("Cores", "points count radius lo hi")


def pack_cores(cores, pairs):
    """``(points (N, 3), offsets (S + 1,), local_pairs (k, 2), radii (S,))``: the cores (``Cores``) of the
    shapes of ``pairs`` (k, 2) packed for the ``*_pairs`` kernels, and the pairs renumbered into them."""
    ids = np.unique(pairs)
    count = cores.count[ids]
    keep = np.arange(cores.points.shape[1])[None, :] < count[:, None]
    offsets = np.zeros(ids.shape[0] + 1, np.int64)
    np.cumsum(count, out=offsets[1:])
    points = np.ascontiguousarray(cores.points[ids][keep])
    return points, offsets, np.searchsorted(ids, pairs).astype(np.int64), cores.radius[ids]


def _overlap(cores, pairs):
    points, offsets, local, radii = pack_cores(cores, pairs)
    dist = gjk_distance_pairs(points, offsets, local)[0]
    separation = dist - cores.radius[pairs[:, 0]] - cores.radius[pairs[:, 1]]
    return separation, (points, offsets, local, radii)


def gjk_overlap_rows(cores, pairs, sel, rows) -> None:
    """Rows ``sel`` of ``rows`` for the candidate pairs ``pairs[sel]``: touching when the GJK distance of the
    cores is at most the sum of the radii."""
    separation, _ = _overlap(cores, pairs[sel])
    rows.status[sel] = np.where(separation <= 0.0, TOUCHING, APART)
    rows.separation[sel] = separation


def gjk_contact_rows(cores, pairs, sel, rows) -> None:
    """Rows ``sel``: the overlap of ``gjk_overlap_rows``, then for the touching pairs the normal (from the
    pair's first body to its second), depth, features and points of contact_feature_pairs, with their ids."""
    separation, (points, offsets, local, radii) = _overlap(cores, pairs[sel])
    touch = separation <= 0.0
    rows.status[sel] = np.where(touch, TOUCHING, APART)
    rows.separation[sel] = separation
    if not touch.any():
        return
    batch = contact_feature_pairs(points, offsets, local[touch], radii=radii)
    feature_point_ids(cores, pairs[sel[touch]], sel[touch], np.minimum(batch.separation, 0.0), batch.normal,
                      batch.feature_a, batch.feature_b, batch.points, batch.point_offsets, FEATURE_TOL, rows,
                      kernel_scratch(int(np.diff(batch.point_offsets).max())))


@njit
def nearest_support_vertex(points, count, nx, ny, nz, sign, tol, x):
    """The row of points[:count] ((m, 3)) in the support set along sign·n (within tol of the support plane) nearest
    to x (3,) in the plane ⊥ n: the vertex that names a contact point's feature."""
    top = -np.inf
    for v in range(count):
        top = max(top, sign * (points[v, 0] * nx + points[v, 1] * ny + points[v, 2] * nz))
    best = np.inf
    pick = 0
    for v in range(count):
        if sign * (points[v, 0] * nx + points[v, 1] * ny + points[v, 2] * nz) >= top - tol:
            dx, dy, dz = x[0] - points[v, 0], x[1] - points[v, 1], x[2] - points[v, 2]
            along = dx * nx + dy * ny + dz * nz
            off = (dx - along * nx) ** 2 + (dy - along * ny) ** 2 + (dz - along * nz) ** 2
            if off < best:
                best, pick = off, v
    return pick


@njit
def feature_point_ids(cores, pairs, rows_of, separation, normal, feature_a, feature_b, points, offsets, ftol,
                      rows, scratch):
    """Write contact q (pair pairs[q] = (i, j), normal from i to j, its points points[offsets[q]:offsets[q + 1]])
    into row rows_of[q]: at most MAX_POINTS points, each with the id (feature of i at its nearest support vertex,
    feature of j at its nearest support vertex). ``scratch``: contacts.kernel_scratch(most points of a pair)."""
    scratch_p, scratch_d, scratch_i = scratch.pts, scratch.deep, scratch.ids
    for q in range(pairs.shape[0]):
        i, j, p = pairs[q, 0], pairs[q, 1], rows_of[q]
        nx, ny, nz = normal[q, 0], normal[q, 1], normal[q, 2]
        size = 0.0
        for b in (i, j):
            for c in range(3):
                size = max(size, cores.hi[b, c] - cores.lo[b, c])
        tol = ftol * max(size, 1e-300)
        n = np.int64(0)  # typed int64 from the start: reduce_manifold is compiled for one count type
        scratch_d[:] = 0.0  # the points lie on one plane: the reduction keeps the first as the deepest
        for x in range(offsets[q], offsets[q + 1]):
            va = nearest_support_vertex(cores.points[i], cores.count[i], nx, ny, nz, 1.0, tol, points[x])
            vb = nearest_support_vertex(cores.points[j], cores.count[j], nx, ny, nz, -1.0, tol, points[x])
            for c in range(3):  # coordinate by coordinate: no shape check to compile
                scratch_p[n, c] = points[x, c]
            scratch_i[n] = point_id(feature_key(feature_a[q], va), feature_key(feature_b[q], vb))
            n += 1
        n = reduce_manifold(scratch_p, scratch_d, scratch_i, n, nx, ny, nz, scratch)
        rows.status[p] = TOUCHING
        rows.separation[p] = separation[q]
        for c in range(3):
            rows.normal[p, c] = normal[q, c]
        rows.feature_a[p] = feature_a[q]
        rows.feature_b[p] = feature_b[q]
        rows.count[p] = n
        for v in range(n):
            for c in range(3):
                rows.points[p, v, c] = scratch_p[v, c]
            rows.ids[p, v] = scratch_i[v]
