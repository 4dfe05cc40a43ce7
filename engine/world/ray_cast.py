"""Ray casts against a ``World``: a whole batch of rays through the broad phase's structures in one compiled call.

Each ray o + t·d (d unit, t in [0, t_max]) is answered by every structure that holds bodies, each walked with the
ray clipped by the nearest hit found so far (Box2D's ``b2DynamicTree_RayCast``; Ericson, *Real-Time Collision
Detection* 6.5 and 7.4.2):

- the grounds a compiled row answers (``Plane``), one test each;
- the static bodies' tree (engine/world/broad.py, ``StaticPairs``), depth first, nearer child first;
- the moving bodies, by the world's broad phase: the dynamic tree of fat boxes ("tree"), a uniform grid walked by
  the 3-D DDA of Amanatides and Woo ("grid", engine/broadphase/ray_grid.py), every body's box ("brute"), and for
  the methods that keep no hierarchy ("sap", "octree") a tree built over the AABBs, kept until a body changes;
- at a body: its AABB's slab test, the filter (its category against the query's mask; sensors are never hit: they
  are trigger volumes, not surfaces), then the ray table's row for its kind (engine/world/ray_rows.py) — for a
  static triangle surface (``TriangleMesh``, ``HeightField``, in the static tree) the nearest of its triangles,
  by its own BVH or its heightfield's cells (engine/narrowphase/ray_mesh.py).
A nearest-hit query keeps the smallest t (ties: the lowest id, so every structure gives the same answer);
``every=True`` collects every hit in [0, t_max] instead. Grounds whose shape lives in Python (``HeightCurve``) are
answered after the compiled pass by their row's batch function. ``threads`` split the rays into contiguous
chunks run by the same compiled (GIL-free) kernel: each ray's answer is the same bit for bit.
"""
from __future__ import annotations

from collections import namedtuple
from dataclasses import dataclass

import numpy as np

from engine._config import MAX_THREADS, njit
from engine.broadphase.pairs import split_even
from engine.broadphase.ray_aabb import inverse_direction, ray_aabb_interval, ray_row_interval
from engine.broadphase.ray_grid import dda_start, dda_step
from engine.broadphase.thread_pool import run_parts
from engine.narrowphase.ray_mesh import as_rays

from .ray_rows import RAY_ROWS, ray_hit

__all__ = ["RayHits", "RayHit", "RayScene", "Forest", "TREE", "GRID", "LIST", "forest_of", "as_rays",
           "cast_ray_batch", "check_threads"]

#: how the scene holds its moving bodies: a tree, a grid, a plain list
TREE, GRID, LIST = 0, 1, 2

#: what a batch walks (built by the World, engine/world/world.py): ``rb`` the rows' arrays (``ray_bodies``),
#: ``lo``, ``hi``, ``category``, ``sensor`` the store's; ``listed`` (k,) ids tested one by one (the grounds a
#: compiled row answers, and every moving body for "brute"); ``forest`` the trees (``forest_of``: the static
#: bodies' and, for TREE, the moving bodies'); ``method`` (TREE, GRID or LIST) with ``grid``
#: (engine.broadphase.ray_grid.RayGrid) and ``grid_body`` for GRID; ``host`` [(id, shape)] the grounds answered
#: in Python; ``reach`` the length a host ground is searched along a ray of unbounded length
RayScene = namedtuple("RayScene", "rb lo hi category sensor listed forest method grid grid_body host reach")

#: trees side by side in one set of arrays: ``roots`` (k,), ``node_lo``, ``node_hi`` (nodes, 3), ``child1``,
#: ``child2`` (nodes,) (−1 at a leaf), ``body_at`` (nodes,) the body id of a leaf (−1 for an inner node)
Forest = namedtuple("Forest", "roots node_lo node_hi child1 child2 body_at")


def forest_of(trees) -> Forest:
    """One ``Forest`` of trees given as (engine.broadphase.TreeArrays, body ids by tree object) pairs: one compiled
    copy of the walk goes through every root."""
    roots, lo, hi, c1, c2, body_at, offset = [], [np.zeros((1, 3))], [np.zeros((1, 3))], [], [], [], 0
    for tree, body_of in trees:
        if tree.root < 0:
            continue
        roots.append(tree.root + offset)
        lo.append(tree.node_lo)
        hi.append(tree.node_hi)
        c1.append(np.where(tree.child1 >= 0, tree.child1 + offset, -1))
        c2.append(np.where(tree.child2 >= 0, tree.child2 + offset, -1))
        leaf = (tree.child1 < 0) & (tree.obj_of >= 0)
        body_at.append(np.where(leaf, body_of[np.where(leaf, tree.obj_of, 0)] if body_of.size else -1, -1))
        offset += tree.node_lo.shape[0]
    if not roots:  # one unused node keeps the arrays' shapes
        return Forest(np.empty(0, np.int64), lo[0], hi[0], np.full(1, -1, np.int64), np.full(1, -1, np.int64),
                      np.full(1, -1, np.int64))
    return Forest(np.array(roots, np.int64), np.concatenate(lo[1:]), np.concatenate(hi[1:]), np.concatenate(c1),
                  np.concatenate(c2), np.concatenate(body_at).astype(np.int64))


@dataclass(frozen=True)
class RayHits:
    """The answer of ``World.cast_rays``: one row per ray (nearest hit), or one per hit (``all_hits=True``).

    ``len(hits)`` is the number of rows.

    Attributes
    ----------
    ray : numpy.ndarray, shape (k,), int64
        The ray of each row (0 .. rays − 1 in order for the nearest hits; for every hit, rows sorted by (ray,
        distance, body)).
    body : numpy.ndarray, shape (k,), int64
        The id hit, −1 for a miss.
    distance : numpy.ndarray, shape (k,), float64
        Along the unit direction, from the origin (0 for a ray starting inside); inf for a miss.
    point : numpy.ndarray, shape (k, 3), float64
        origin + distance × unit direction; NaN for a miss.
    normal : numpy.ndarray, shape (k, 3), float64
        The outward unit normal of the surface hit (−direction for a ray starting inside); NaN for a miss.
    part : numpy.ndarray, shape (k,), int64
        The part hit of a ``Compound``, the triangle hit of a ``TriangleMesh`` or ``HeightField`` (its row in the
        shape's ``triangles``; ties in distance: the lowest); 0 for other bodies and misses.
    """

    ray: np.ndarray
    body: np.ndarray
    distance: np.ndarray
    point: np.ndarray
    normal: np.ndarray
    part: np.ndarray

    def __len__(self) -> int:
        return int(self.body.shape[0])


@dataclass(frozen=True)
class RayHit:
    """The answer of ``World.cast_ray``: ``body`` (int), ``distance`` (float), ``point`` (3,), ``normal`` (3,)
    and ``part`` (int), as one row of ``RayHits``."""

    body: int
    distance: float
    point: np.ndarray
    normal: np.ndarray
    part: int


def check_threads(threads) -> int:
    """``threads`` as an int in [1, MAX_THREADS] (TypeError / ValueError naming it)."""
    if isinstance(threads, bool) or not isinstance(threads, int | np.integer):
        raise TypeError(f"threads must be an int, got {type(threads).__name__}")
    if not 1 <= int(threads) <= MAX_THREADS:
        raise ValueError(f"threads must be in [1, {MAX_THREADS}], got {threads}")
    return int(threads)


# -- the compiled walk ------------------------------------------------------------------------------------------
#: a walk's state: (t, body, nx, ny, nz, part) of the nearest hit so far
@njit(inline="always")
def _visit(sc, b, o, d, inv, every, state, hits, r, box_test):
    """Body b met by ray r: the filter, its AABB (``box_test``: a tree's leaf box is the AABB already), the row;
    keeps the nearer hit (``every``: appends each one to ``hits``)."""
    rb, lo, hi, category, sensor, mask = sc
    if rb[0][b] < 0 or sensor[b] or (category[b] & mask) == 0:
        return state
    if box_test:
        t0, t1 = ray_row_interval(o, d, inv, lo, hi, b, state[0])
        if t0 > t1:
            return state
    t, nx, ny, nz, part = ray_hit(rb[0][b], rb, b, o, d, state[0])
    if t == np.inf:
        return state
    if every:
        hits.append((r, b, t, nx, ny, nz, part))
        return state
    if t < state[0] or state[1] < 0 or b < state[1]:
        return (t, b, nx, ny, nz, part)
    return state


@njit(inline="always")
def _walk_tree(sc, forest, root, o, d, inv, every, state, hits, r, stack, stack_t):
    """Depth first through the nodes of one tree that the clipped ray meets, the nearer child first (Box2D's ray
    cast)."""
    _, node_lo, node_hi, child1, child2, body_at = forest
    t0, t1 = ray_row_interval(o, d, inv, node_lo, node_hi, root, state[0])
    if t0 > t1:
        return state
    stack[0], stack_t[0], top = root, t0, 1
    while top > 0:
        top -= 1
        node = stack[top]
        if stack_t[top] > state[0]:
            continue
        if child1[node] < 0:
            state = _visit(sc, body_at[node], o, d, inv, every, state, hits, r, False)
            continue
        a, b = child1[node], child2[node]
        ta, ea = ray_row_interval(o, d, inv, node_lo, node_hi, a, state[0])
        tb, eb = ray_row_interval(o, d, inv, node_lo, node_hi, b, state[0])
        if ta > tb:  # push the farther first: the nearer is popped first
            a, b, ta, ea, tb, eb = b, a, tb, eb, ta, ea
        if tb <= eb:
            stack[top], stack_t[top] = b, tb
            top += 1
        if ta <= ea:
            stack[top], stack_t[top] = a, ta
            top += 1
    return state


@njit(inline="always")
def _walk_grid(sc, grid, grid_body, o, d, inv, every, state, hits, r, seen):
    """The cells the ray crosses, in order, until the nearest hit lies before the current cell's exit; ``seen``
    (per grid box: the last ray that tested it) keeps a box in several cells from being tested twice."""
    origin, top, side, dims, start, items, large = grid
    for q in range(large.shape[0]):
        state = _visit(sc, grid_body[large[q]], o, d, inv, every, state, hits, r, True)
    t_enter, t_exit = ray_aabb_interval(o, d, inv, origin, top, state[0])
    if t_enter > t_exit:
        return state
    cells, steps, t_next, t_delta = dda_start(o, d, t_enter, origin, side, dims)
    slack = 1e-9 * side  # the cell exits are computed: stop only past them by more than their round-off
    inside = True
    while inside:
        c = (cells[0] * dims[1] + cells[1]) * dims[2] + cells[2]
        for q in range(start[c], start[c + 1]):
            box = items[q]
            if seen[box] != r:
                seen[box] = r
                state = _visit(sc, grid_body[box], o, d, inv, every, state, hits, r, True)
        t_cell = min(t_next[0], t_next[1], t_next[2])
        if t_cell > t_exit or (not every and state[0] + slack < t_cell):
            break
        cells, t_next, inside = dda_step(cells, steps, t_next, t_delta, dims)
    return state


@njit(inline="always")
def _cast_one(sc, scene, o, d, t_max, every, grid_walk, hits, r, stack, stack_t, seen):
    """One ray through the scene: the listed bodies, the trees, and (``grid_walk``) the grid."""
    listed, forest, grid, grid_body = scene
    inv = inverse_direction(d)
    state = (t_max, -1, np.nan, np.nan, np.nan, 0)
    for q in range(listed.shape[0]):
        state = _visit(sc, listed[q], o, d, inv, every, state, hits, r, True)
    for k in range(forest[0].shape[0]):
        state = _walk_tree(sc, forest, forest[0][k], o, d, inv, every, state, hits, r, stack, stack_t)
    if grid_walk:
        state = _walk_grid(sc, grid, grid_body, o, d, inv, every, state, hits, r, seen)
    return state


@njit(inline="always")
def _cast_rays(r0, r1, every, grid_walk, origins, directions, t_max, sc, scene, out):
    """Rays r0 .. r1 − 1: the nearest hit of each into ``out`` (t, body, normal, part), or (``every``) every
    hit, returned as arrays (ray, body, t, normal, part)."""
    out_t, out_body, out_normal, out_part = out
    stack = np.empty(scene[1][1].shape[0] + 2, np.int64)
    stack_t = np.empty(stack.shape[0])
    seen = np.full(scene[3].shape[0], -1, np.int64)
    hits = [(np.int64(0), np.int64(0), 0.0, 0.0, 0.0, 0.0, np.int64(0))]  # (ray, body, t, normal, part)
    hits.pop()
    for r in range(r0, r1):
        o = (origins[r, 0], origins[r, 1], origins[r, 2])
        d = (directions[r, 0], directions[r, 1], directions[r, 2])
        state = _cast_one(sc, scene, o, d, t_max[r], every, grid_walk, hits, r, stack, stack_t, seen)
        if not every:
            out_body[r] = state[1]
            out_t[r] = state[0] if state[1] >= 0 else np.inf
            out_normal[r, 0], out_normal[r, 1], out_normal[r, 2] = state[2], state[3], state[4]
            out_part[r] = state[5]
    return _hit_arrays(hits)


# one kernel per (every, grid): the flags are constants in each, so the compiler drops the code they rule out
@njit
def _nearest_kernel(r0, r1, origins, directions, t_max, sc, scene, out):
    return _cast_rays(r0, r1, False, False, origins, directions, t_max, sc, scene, out)


@njit
def _every_kernel(r0, r1, origins, directions, t_max, sc, scene, out):
    return _cast_rays(r0, r1, True, False, origins, directions, t_max, sc, scene, out)


@njit
def _nearest_grid_kernel(r0, r1, origins, directions, t_max, sc, scene, out):
    return _cast_rays(r0, r1, False, True, origins, directions, t_max, sc, scene, out)


@njit
def _every_grid_kernel(r0, r1, origins, directions, t_max, sc, scene, out):
    return _cast_rays(r0, r1, True, True, origins, directions, t_max, sc, scene, out)


_KERNELS = {(False, False): _nearest_kernel, (True, False): _every_kernel, (False, True): _nearest_grid_kernel,
            (True, True): _every_grid_kernel}


@njit
def _hit_arrays(hits):
    k = len(hits)
    ray, body, dist = np.empty(k, np.int64), np.empty(k, np.int64), np.empty(k)
    normal, part = np.empty((k, 3)), np.empty(k, np.int64)
    for q in range(k):
        ray[q], body[q], dist[q], normal[q, 0], normal[q, 1], normal[q, 2], part[q] = hits[q]
    return ray, body, dist, normal, part


# -- the batch --------------------------------------------------------------------------------------------------
def _compiled_args(scene: RayScene, mask: int):
    sc = (scene.rb, scene.lo, scene.hi, scene.category, scene.sensor, np.uint64(mask))
    walk = (scene.listed, scene.forest, scene.grid, scene.grid_body)
    return sc, walk


def _host_grounds(scene: RayScene, origins, directions, t_max, mask, every, out):
    """The grounds answered in Python, merged into ``out`` (nearest: (t, body, normal, part) per ray; every: the
    hit buffers)."""
    for g, shape in scene.host:
        if (int(scene.category[g]) & mask) == 0 or scene.sensor[g]:
            continue
        reach = np.where(np.isfinite(t_max), t_max, scene.reach)
        host = RAY_ROWS[shape.kind].host
        assert host is not None  # the World lists here only the grounds whose row answers in Python
        t, normal = host(shape, origins, directions, reach)
        hit = np.isfinite(t)
        if every:
            rows = np.flatnonzero(hit)
            out = [np.concatenate([a, b]) for a, b in zip(out, (rows, np.full(rows.size, g), t[rows], normal[rows],
                                                                   np.zeros(rows.size, np.int64)))]
        else:
            out_t, out_body, out_normal, _ = out
            better = hit & ((t < out_t) | ((t == out_t) & ((out_body < 0) | (g < out_body))))
            out_t[better], out_body[better], out_normal[better] = t[better], g, normal[better]
            out[3][better] = 0
    return out


def cast_ray_batch(scene: RayScene, origins, directions, t_max, mask: int, every: bool, threads: int) -> RayHits:
    """Every ray of a checked batch (``as_rays``) through ``scene``: the nearest hits, or every hit (``every``),
    as ``RayHits``; the rays split into ``threads`` contiguous chunks."""
    k = origins.shape[0]
    out = (np.full(k, np.inf), np.full(k, -1, np.int64), np.full((k, 3), np.nan), np.zeros(k, np.int64))
    sc, walk = _compiled_args(scene, mask)
    kernel = _KERNELS[every, scene.method == GRID]

    def run(span):
        return kernel(span[0], span[1], origins, directions, t_max, sc, walk, out)
    chunks = run_parts(run, split_even(k, threads, 1))
    if every:
        found = [np.concatenate([c[f] for c in chunks]) for f in range(5)]
        ray, body, t, normal, part = _host_grounds(scene, origins, directions, t_max, mask, True, found)
        order = np.lexsort((body, t, ray))
        ray, body, t, normal, part = ray[order], body[order], t[order], normal[order], part[order]
    else:
        t, body, normal, part = _host_grounds(scene, origins, directions, t_max, mask, False, list(out))
        ray = np.arange(k, dtype=np.int64)
    point = np.full((t.shape[0], 3), np.nan)
    hit = body >= 0
    point[hit] = origins[ray[hit]] + t[hit, None] * directions[ray[hit]]
    return RayHits(ray=ray, body=body, distance=t, point=point, normal=normal, part=part)
