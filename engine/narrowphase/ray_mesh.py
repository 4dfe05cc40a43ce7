"""A ray through a static triangle surface (engine.narrowphase.triangle_mesh): the nearest triangle it meets, each
triangle by the watertight test of engine/narrowphase/ray_triangle.py (two-sided).

- A soup: its BVH walked depth first, the nearer child first, a node skipped once its entry lies beyond the
  nearest hit found so far (Ericson, *Real-Time Collision Detection* 6.5; Box2D's ``b2DynamicTree_RayCast``).
- A heightfield: its cells in the order the ray crosses them on the x–z plane, the 2-D form of the grid walk of
  Amanatides and Woo, "A Fast Voxel Traversal Algorithm for Ray Tracing" (Eurographics 1987), taken one *slab* at a
  time along the axis of the larger horizontal component u: the ray's span over slab j covers a few cells of the
  other axis w, and a cell whose height range the ray's heights over the slab miss is skipped. The walk stops at
  the first slab that begins beyond the nearest hit. A purely vertical ray is one slab of one or more cells.

The answer is the smallest t over all the triangles, ties to the lowest triangle id, whatever the walk: every
pruning is conservative by a slack (1e-9 of the surface's diagonal plus of the distance) far above the round-off
of the computed box and cell boundaries, so a triangle whose computed t could beat the best is always tested.
Hence a ``HeightField`` answers bit for bit as the ``TriangleMesh`` of its triangles (same t, same normal, same
triangle). The normal is the triangle's stored unit face normal turned against the ray.

Surfaces side by side (``SurfaceSet``, built by ``surface_set``) let one compiled function answer any of them:
``ray_surface(surfaces, s, o, d, t_max)``; ``ray_mesh`` answers a batch of rays against one ``MeshArrays``.
"""
from __future__ import annotations

import math
from collections import namedtuple

import numpy as np

from .._config import njit
from .._validate import as_float_array
from ..broadphase.ray_aabb import inverse_direction, ray_row_interval
from .ray_triangle import ray_triangle_side

__all__ = ["SurfaceSet", "surface_set", "ray_surface", "ray_mesh", "as_rays", "RAY_SLACK"]

#: the relative slack of every pruning test (of the surface's diagonal and of the distance)
RAY_SLACK = 1e-9

#: surfaces side by side, indices shifted so that every array is one: ``vertices`` (V, 3), ``triangles`` (T, 3)
#: int64 rows of ``vertices``, ``normals`` (T, 3); the BVH nodes ``node_lo``, ``node_hi`` (N, 3), ``child1``,
#: ``child2`` (N,) (−1 at a leaf), ``obj_of`` (N,) the triangle of a leaf; per surface (S,): ``root`` (−1 for a
#: heightfield), ``first_tri`` (its triangle 0's row), ``grid_n`` (S, 2) int64 (nx, nz; zeros for a soup),
#: ``grid_f`` (S, 4) (x0, z0, dx, dz), ``box_lo``, ``box_hi`` (S, 3) its AABB, ``diagonal`` (S,) the AABB's
SurfaceSet = namedtuple("SurfaceSet", "vertices triangles normals node_lo node_hi child1 child2 obj_of root first_tri "
                                      "grid_n grid_f box_lo box_hi diagonal")


def _shifted(a, offset):
    return np.where(a >= 0, a + offset, -1)


def surface_set(meshes) -> SurfaceSet:
    """The ``SurfaceSet`` of a sequence of ``MeshArrays`` (surface s is ``meshes[s]``; an empty sequence gives one
    with no surface)."""
    v, t, n, lo, hi, c1, c2, obj = [np.zeros((0, 3))], [np.zeros((0, 3), np.int64)], [np.zeros((0, 3))], \
        [np.zeros((0, 3))], [np.zeros((0, 3))], [np.zeros(0, np.int64)], [np.zeros(0, np.int64)], \
        [np.zeros(0, np.int64)]
    root, first_tri, grid_n, grid_f, box_lo, box_hi = [], [], [], [], [], []
    nv = nt = nn = 0
    for m in meshes:
        v.append(m.vertices)
        t.append(m.triangles + nv)
        n.append(m.normals)
        lo.append(m.node_lo)
        hi.append(m.node_hi)
        c1.append(_shifted(m.child1, nn))
        c2.append(_shifted(m.child2, nn))
        obj.append(_shifted(m.obj_of, nt))
        root.append(m.root + nn if m.root >= 0 else -1)
        first_tri.append(nt)
        grid_n.append(m.grid_n)
        grid_f.append(m.grid_f)
        box_lo.append(m.vertices.min(axis=0))
        box_hi.append(m.vertices.max(axis=0))
        nv, nt, nn = nv + m.vertices.shape[0], nt + m.triangles.shape[0], nn + m.node_lo.shape[0]
    box_lo_a = np.array(box_lo).reshape(-1, 3)
    box_hi_a = np.array(box_hi).reshape(-1, 3)
    return SurfaceSet(np.concatenate(v), np.concatenate(t).astype(np.int64), np.concatenate(n), np.concatenate(lo),
                      np.concatenate(hi), np.concatenate(c1).astype(np.int64), np.concatenate(c2).astype(np.int64),
                      np.concatenate(obj).astype(np.int64), np.array(root, np.int64), np.array(first_tri, np.int64),
                      np.array(grid_n, np.int64).reshape(-1, 2), np.array(grid_f, np.float64).reshape(-1, 4),
                      box_lo_a, box_hi_a, np.sqrt(((box_hi_a - box_lo_a) ** 2).sum(axis=1)))


# -- one triangle, the nearest so far ---------------------------------------------------------------------------
@njit(inline="always")
def _corner(sf, tri, k):
    v = sf.vertices
    i = sf.triangles[tri, k]
    return v[i, 0], v[i, 1], v[i, 2]


@njit(inline="always")
def _try(sf, tri, o, d, t_max, best):
    """``best`` = (t, side, triangle) or triangle ``tri``'s hit when nearer (ties: the lower id)."""
    t, side = ray_triangle_side(o, d, t_max, _corner(sf, tri, 0), _corner(sf, tri, 1), _corner(sf, tri, 2))
    if t < math.inf and (t < best[0] or (t == best[0] and (best[2] < 0 or tri < best[2]))):
        return t, side, tri
    return best


@njit(inline="always")
def _slack(sf, s, t):
    """How far beyond ``t`` a node or a cell is still looked at (the module docstring)."""
    if t == math.inf:
        return math.inf
    return RAY_SLACK * (sf.diagonal[s] + t)


# -- a soup: the BVH ----------------------------------------------------------------------------------------------
@njit(inline="always")
def _push(stack, stack_t, top, node, t):
    if top == stack.shape[0]:
        stack = np.concatenate((stack, np.empty_like(stack)))
        stack_t = np.concatenate((stack_t, np.empty_like(stack_t)))
    stack[top], stack_t[top] = node, t
    return stack, stack_t, top + 1


@njit(inline="always")
def _node_entry(sf, s, o, d, inv, node, best_t):
    """The entry t of the ray into the node's box, or inf when it misses it before ``best_t`` (with the slack)."""
    slack = _slack(sf, s, best_t)
    t0, t1 = ray_row_interval(o, d, inv, sf.node_lo, sf.node_hi, node, best_t + slack)
    if t0 > t1 + RAY_SLACK * (sf.diagonal[s] + t1):
        return math.inf
    return t0


@njit(inline="always")
def _ray_soup(sf, s, o, d, t_max):
    """The nearest (t, side, triangle) of the soup s: depth first, the nearer child first, pruned by the best t."""
    inv = inverse_direction(d)
    best = (t_max, 0.0, np.int64(-1))
    stack, stack_t = np.empty(64, np.int64), np.empty(64)
    top = 0
    t_root = _node_entry(sf, s, o, d, inv, sf.root[s], t_max)
    if t_root < math.inf:
        stack, stack_t, top = _push(stack, stack_t, top, sf.root[s], t_root)
    while top > 0:
        top -= 1
        node = stack[top]
        if stack_t[top] > best[0] + _slack(sf, s, best[0]):
            continue
        if sf.child1[node] < 0:
            best = _try(sf, sf.obj_of[node], o, d, best[0], best)
            continue
        a, b = sf.child1[node], sf.child2[node]
        ta = _node_entry(sf, s, o, d, inv, a, best[0])
        tb = _node_entry(sf, s, o, d, inv, b, best[0])
        if ta > tb:  # push the farther first: the nearer is popped first
            a, b, ta, tb = b, a, tb, ta
        if tb < math.inf:
            stack, stack_t, top = _push(stack, stack_t, top, b, tb)
        if ta < math.inf:
            stack, stack_t, top = _push(stack, stack_t, top, a, ta)
    return best


# -- a heightfield: the cells on the ray's path ----------------------------------------------------------------
@njit(inline="always")
def _cell_span(lo_c, hi_c, start, step, cells):
    """The cells [first, last] along one axis that [lo_c, hi_c] meets, clipped to [0, cells − 1]."""
    first = max(int(math.floor((lo_c - start) / step)), 0)
    last = min(int(math.floor((hi_c - start) / step)), cells - 1)
    return first, last


@njit(inline="always")
def _cell_heights(sf, tri):
    """The lowest and highest corner of a cell (its two triangles share its four corners; ``tri`` the first)."""
    y0, y1 = math.inf, -math.inf
    for k in range(3):
        y0, y1 = min(y0, _corner(sf, tri, k)[1]), max(y1, _corner(sf, tri, k)[1])
    y0, y1 = min(y0, _corner(sf, tri + 1, 2)[1]), max(y1, _corner(sf, tri + 1, 2)[1])
    return y0, y1


@njit(inline="always")
def _slab_times(o_u, d_u, u_lo, u_hi, t0, t1):
    """The part of [t0, t1] where the ray's u coordinate lies in [u_lo, u_hi] (all of it when d_u == 0)."""
    if d_u == 0.0:
        return t0, t1
    ta, tb = (u_lo - o_u) / d_u, (u_hi - o_u) / d_u
    if ta > tb:
        ta, tb = tb, ta
    return max(t0, ta), min(t1, tb)


@njit(inline="always")
def _grid_frame(sf, s, d):
    """(u, w, u0, w0, du, dw, cells_u, cells_w): u the horizontal axis (0: x, 2: z) of the larger |d|."""
    x0, z0, dx, dz = sf.grid_f[s, 0], sf.grid_f[s, 1], sf.grid_f[s, 2], sf.grid_f[s, 3]
    cx, cz = sf.grid_n[s, 0] - 1, sf.grid_n[s, 1] - 1
    if abs(d[0]) >= abs(d[2]):
        return 0, 2, x0, z0, dx, dz, cx, cz
    return 2, 0, z0, x0, dz, dx, cz, cx


@njit(inline="always")
def _slab(sf, s, o, d, j, frame, ta, tb, pad, best):
    """Slab j (cells of index j along u), the ray's span [ta, tb] over it: its cells the ray's w and y spans
    meet (± pad), each cell's two triangles."""
    u, w, u0, w0, du, dw, cells_u, cells_w = frame
    wa, wb = o[w] + ta * d[w], o[w] + tb * d[w]
    ya, yb = o[1] + ta * d[1], o[1] + tb * d[1]
    y_lo, y_hi = min(ya, yb) - pad, max(ya, yb) + pad
    k0, k1 = _cell_span(min(wa, wb) - pad, max(wa, wb) + pad, w0, dw, cells_w)
    nz1 = sf.grid_n[s, 1] - 1
    for k in range(k0, k1 + 1):
        i, kk = (j, k) if u == 0 else (k, j)
        tri = sf.first_tri[s] + 2 * (i * nz1 + kk)
        c_lo, c_hi = _cell_heights(sf, tri)
        if c_hi < y_lo or c_lo > y_hi:
            continue
        best = _try(sf, tri, o, d, best[0], best)
        best = _try(sf, tri + 1, o, d, best[0], best)
    return best


@njit(inline="always")
def _ray_field(sf, s, o, d, t_max):
    """The nearest (t, side, triangle) of the heightfield s: slab by slab along u, until a slab begins beyond
    the best hit."""
    best = (t_max, 0.0, np.int64(-1))
    inv = inverse_direction(d)
    t0, t1 = ray_row_interval(o, d, inv, sf.box_lo, sf.box_hi, s, t_max + _slack(sf, s, t_max))
    slack0 = _slack(sf, s, 0.0)
    if t0 > t1 + _slack(sf, s, t1):
        return best
    t0, t1 = max(0.0, t0 - slack0 - RAY_SLACK * t0), t1 + _slack(sf, s, t1)
    frame = _grid_frame(sf, s, d)
    u, _, u0, _, du, _, cells_u, _ = frame
    pad = slack0
    ua, ub = o[u] + t0 * d[u], o[u] + t1 * d[u]
    j0, j1 = _cell_span(min(ua, ub) - pad, max(ua, ub) + pad, u0, du, cells_u)
    step = -1 if d[u] < 0.0 else 1
    j = j1 if step < 0 else j0
    for _ in range(j1 - j0 + 1):
        ta, tb = _slab_times(o[u], d[u], u0 + j * du - pad, u0 + (j + 1) * du + pad, t0, t1)
        if ta > best[0] + _slack(sf, s, best[0]):
            break
        if ta <= tb:
            best = _slab(sf, s, o, d, j, frame, ta, tb, pad, best)
        j += step
    return best


# -- the answer ---------------------------------------------------------------------------------------------------
@njit
def ray_surface(sf, s, o, d, t_max):
    """The nearest hit of the ray o + t·d (3-tuples, d unit, t in [0, t_max]) with surface s of the
    ``SurfaceSet`` sf: (t, nx, ny, nz, triangle) — the unit face normal against the ray and the triangle's id in
    its surface; (inf, nan, nan, nan, 0) for a miss."""
    if sf.root[s] >= 0:
        t, side, tri = _ray_soup(sf, s, o, d, t_max)
    elif sf.grid_n[s, 0] > 0:
        t, side, tri = _ray_field(sf, s, o, d, t_max)
    else:
        t, side, tri = math.inf, 0.0, np.int64(-1)
    if tri < 0:
        return math.inf, math.nan, math.nan, math.nan, 0
    n = sf.normals
    return t, side * n[tri, 0], side * n[tri, 1], side * n[tri, 2], tri - sf.first_tri[s]


@njit
def _ray_mesh_batch(sf, origins, directions, t_max, out_t, out_n, out_tri):
    for r in range(origins.shape[0]):
        o = (origins[r, 0], origins[r, 1], origins[r, 2])
        d = (directions[r, 0], directions[r, 1], directions[r, 2])
        t, nx, ny, nz, tri = ray_surface(sf, 0, o, d, t_max[r])
        out_t[r], out_n[r, 0], out_n[r, 1], out_n[r, 2] = t, nx, ny, nz
        out_tri[r] = tri if t < math.inf else -1


def as_rays(origins, directions, max_distance):
    """(origins (k, 3), unit directions (k, 3), t_max (k,)) checked: finite origins and directions, no zero
    direction, max_distance >= 0 (inf allowed) as a scalar or (k,) — else ValueError / TypeError naming the
    argument and the first bad index."""
    o = as_float_array(origins, "origins", shape=(None, 3))
    d = as_float_array(directions, "directions", shape=(None, 3))
    if d.shape[0] != o.shape[0]:
        raise ValueError(f"directions must have as many rows as origins ({o.shape[0]}), got {d.shape[0]}")
    length = np.sqrt((d * d).sum(axis=1))
    bad = np.flatnonzero(~(length > 0.0) | ~np.isfinite(length))
    if bad.size:
        raise ValueError(f"directions[{bad[0]}] = {d[bad[0]].tolist()} has no usable length (zero or overflowing)")
    t_max = np.asarray(max_distance)
    if t_max.dtype.kind not in "iuf":
        raise TypeError(f"max_distance must be a real number or array, got dtype {t_max.dtype}")
    if t_max.ndim > 1 or (t_max.ndim == 1 and t_max.shape[0] != o.shape[0]):
        raise ValueError(f"max_distance must be a scalar or have shape ({o.shape[0]},), got {t_max.shape}")
    t_max = np.broadcast_to(t_max.astype(np.float64), (o.shape[0],)).copy()
    bad = np.flatnonzero(~(t_max >= 0.0))
    if bad.size:
        where = f"max_distance[{bad[0]}]" if np.ndim(max_distance) else "max_distance"
        raise ValueError(f"{where} must be >= 0 (inf allowed), got {t_max[bad[0]]}")
    return o, d / length[:, None], t_max


def ray_mesh(mesh, origins, directions, max_distance=np.inf):
    """The nearest triangle of one surface each ray meets.

    Parameters
    ----------
    mesh : engine.narrowphase.triangle_mesh.MeshArrays
        A soup or a heightfield (``TriangleMesh(...).mesh``, ``HeightField(...).mesh``).
    origins, directions : array_like, shape (k, 3)
        The rays, finite; directions of any non-zero length (distances are along the unit direction).
    max_distance : float or array_like of shape (k,), default inf
        How far each ray goes, >= 0.

    Returns
    -------
    t : numpy.ndarray, shape (k,)
        The distance to the hit, inf for a miss.
    normals : numpy.ndarray, shape (k, 3)
        The unit face normal turned against the ray, NaN for a miss.
    triangles : numpy.ndarray, shape (k,), int64
        The triangle hit (ties in t: the lowest id), −1 for a miss.

    Raises
    ------
    ValueError, TypeError
        As ``as_rays`` (the rules of ``World.cast_rays``), naming the argument.
    """
    o, d, t_max = as_rays(origins, directions, max_distance)
    k = o.shape[0]
    out_t, out_n, out_tri = np.empty(k), np.empty((k, 3)), np.empty(k, np.int64)
    _ray_mesh_batch(surface_set([mesh]), o, d, t_max, out_t, out_n, out_tri)
    return out_t, out_n, out_tri
