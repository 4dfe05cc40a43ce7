"""Static triangle surfaces — a triangle soup with its own BVH, or a heightfield's grid — as one bundle of arrays
that the compiled kernels read (``MeshArrays``), and the choice of the triangles a query box can reach.

- ``mesh_arrays(vertices, triangles)``: any soup, open or closed; its BVH is the engine's AABB tree built top-down
  over the triangles' boxes (engine.broadphase.aabb_tree, SAH split; Ericson 6.2), queried by descent (6.5).
- ``heightfield_arrays(heights, spacing, origin)``: y-up samples (nx, nz) at (x0 + i·dx, z0 + k·dz); cell (i, k)
  holds two triangles split along the (i, k)–(i+1, k+1) diagonal (triangles 2c and 2c + 1 of cell
  c = i·(nz − 1) + k), wound so that their normals point up. No tree: the cells under a box are its candidates.
  Its arrays are exactly those of the ``TriangleMesh`` of the same triangles, so every answer is the same.

Active edges (Jolt's ``ActiveEdges``, Bullet's internal-edge utility): an edge shared by two triangles is
*inactive* when the two faces are coplanar to within ``ACTIVE_EDGE_COS`` (Jolt's default: 5 degrees) or meet in a
concave fold; a contact whose feature on a triangle is an inactive edge (or a vertex whose two edges in that
triangle are both inactive) takes the triangle's face normal instead of the edge's: a body sliding over a flat
tessellated floor never meets the ghost normal of an internal edge. Boundary edges, edges of three or more
triangles and convex folds sharper than the threshold are active. The fold is judged with the winding of the
first triangle (consistently wound meshes: outward normals).

Triangles are two-sided surfaces: a body touches a triangle when their distance is 0, whatever the side.
"""
from __future__ import annotations

import math
from collections import namedtuple

import numpy as np

from engine._config import njit
from engine._validate import as_float_array
from engine.broadphase.aabb_tree import DynamicAABBTree

__all__ = ["MeshArrays", "mesh_arrays", "heightfield_arrays", "ACTIVE_EDGE_COS", "triangle_corners",
           "candidate_triangles", "mesh_box", "VERTEX_EDGES"]

#: the cosine of the largest dihedral fold of an inactive edge (Jolt's default threshold, 5 degrees)
ACTIVE_EDGE_COS = math.cos(math.radians(5.0))

#: a triangle's vertex v lies on its edges v and (v + 2) % 3 (edge e joins corners e and (e + 1) % 3)
VERTEX_EDGES = np.array([[0, 2], [1, 0], [2, 1]], np.int64)

#: what the kernels read of a static triangle surface:
#: ``vertices`` (nv, 3) float64, world coordinates; ``triangles`` (nt, 3) int64 corner indices; ``normals``
#: (nt, 3) unit face normals (right-hand rule on the corners' order); ``active`` (nt, 3) bool, edge e joining
#: corners e and (e + 1) % 3 (see the module docstring); the BVH ``root`` (−1 for a heightfield), ``node_lo``,
#: ``node_hi`` (nodes, 3), ``child1``, ``child2``, ``obj_of`` (nodes,) int64 (engine.broadphase.aabb_tree); the
#: grid ``grid_n`` (2,) int64 (nx, nz) samples, zeros for a soup, and ``grid_f`` (4,) float64 (x0, z0, dx, dz)
MeshArrays = namedtuple("MeshArrays", "vertices triangles normals active root node_lo node_hi child1 child2 obj_of "
                                      "grid_n grid_f")


def _face_normals(vertices, triangles, name):
    a, b, c = (vertices[triangles[:, k]] for k in range(3))
    cross = np.cross(b - a, c - a)
    norm = np.sqrt((cross * cross).sum(axis=1))
    bad = np.flatnonzero(~(norm > 0.0))
    if bad.size:
        t = int(bad[0])
        raise ValueError(f"{name}[{t}] = {triangles[t].tolist()} is degenerate (zero area: its corners are "
                         f"collinear or repeated)")
    return cross / norm[:, None]


def _active_edges(vertices, triangles, normals):
    """(nt, 3) bool: the active edges of the module docstring."""
    nt = triangles.shape[0]
    ends = np.stack([triangles, np.roll(triangles, -1, axis=1)], axis=2).reshape(-1, 2)  # edge 3t + e
    key = np.sort(ends, axis=1)
    order = np.lexsort((key[:, 1], key[:, 0]))
    sk = key[order]
    same_next = np.r_[(sk[1:] == sk[:-1]).all(axis=1), False]
    same_prev = np.r_[False, same_next[:-1]]
    starts = np.flatnonzero(~same_prev)
    sizes = np.diff(np.r_[starts, key.shape[0]])
    active = np.ones(3 * nt, bool)
    two = starts[sizes == 2]
    e1, e2 = order[two], order[two + 1]
    t1, t2 = e1 // 3, e2 // 3
    n1, n2 = normals[t1], normals[t2]
    # the corner of t2 off the shared edge: the one that is neither end
    other = triangles[t2]
    off = np.where((other != key[e1][:, :1]) & (other != key[e1][:, 1:]), other, -1).max(axis=1)
    fold = ((vertices[off] - vertices[key[e1][:, 0]]) * n1).sum(axis=1)
    coplanar = np.abs((n1 * n2).sum(axis=1)) >= ACTIVE_EDGE_COS
    concave = fold > 0.0
    inactive = coplanar | concave
    active[e1[inactive]] = False
    active[e2[inactive]] = False
    return active.reshape(nt, 3)


def _as_triangles(triangles, nv, name):
    arr = np.asarray(triangles)
    if arr.dtype == object or arr.dtype.kind not in "iu":
        if arr.dtype.kind == "f" and arr.size and np.isfinite(arr).all() and np.array_equal(arr, np.round(arr)):
            arr = arr.astype(np.int64)
        else:
            raise TypeError(f"{name} must be an integer array of vertex indices, got dtype {arr.dtype}")
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise ValueError(f"{name} must have shape (nt, 3), got {arr.shape}")
    if arr.shape[0] == 0:
        raise ValueError(f"{name} must hold at least one triangle")
    out = np.ascontiguousarray(arr, dtype=np.int64)
    bad = np.flatnonzero(((out < 0) | (out >= nv)).any(axis=1))
    if bad.size:
        t = int(bad[0])
        raise ValueError(f"{name}[{t}] = {out[t].tolist()} has an index out of range [0, {nv})")
    return out


def _with_tree(vertices, triangles, normals, active, grid_n, grid_f, tree: bool) -> MeshArrays:
    if tree:
        corners = vertices[triangles]
        built = DynamicAABBTree.from_boxes(corners.min(axis=1), corners.max(axis=1), margin=0.0, split="sah")
        root, node_lo, node_hi, child1, child2, obj_of = built.arrays()
    else:
        root, node_lo, node_hi = -1, np.zeros((0, 3)), np.zeros((0, 3))
        child1 = child2 = obj_of = np.zeros(0, np.int64)
    return MeshArrays(vertices, triangles, normals, active, np.int64(root), node_lo, node_hi, child1, child2,
                      obj_of, grid_n, grid_f)


def mesh_arrays(vertices, triangles, *, names=("vertices", "triangles")) -> MeshArrays:
    """The ``MeshArrays`` of a triangle soup.

    Parameters
    ----------
    vertices : array_like, shape (nv, 3)
        Finite coordinates (world frame).
    triangles : array_like, shape (nt, 3), integers
        Corner indices into ``vertices``, nt >= 1.
    names : (str, str)
        The argument names the errors use.

    Raises
    ------
    ValueError
        For non-finite vertices, indices out of range, or a zero-area triangle — naming the first bad index.
    TypeError
        For non-numeric vertices or non-integer triangles.
    """
    v = as_float_array(vertices, names[0], shape=(None, 3), min_rows=3)
    t = _as_triangles(triangles, v.shape[0], names[1])
    normals = _face_normals(v, t, names[1])
    return _with_tree(v, t, normals, _active_edges(v, t, normals), np.zeros(2, np.int64), np.zeros(4), True)


def heightfield_triangles(nx: int, nz: int) -> np.ndarray:
    """The corner indices (2 (nx − 1)(nz − 1), 3) of a heightfield's triangles, vertex (i, k) = i·nz + k (see the
    module docstring)."""
    i, k = np.meshgrid(np.arange(nx - 1), np.arange(nz - 1), indexing="ij")
    v00 = (i * nz + k).ravel()
    v01, v11, v10 = v00 + 1, v00 + nz + 1, v00 + nz
    tri = np.empty((v00.shape[0], 2, 3), np.int64)
    tri[:, 0] = np.stack([v00, v01, v11], axis=1)
    tri[:, 1] = np.stack([v00, v11, v10], axis=1)
    return tri.reshape(-1, 3)


def heightfield_arrays(heights, spacing, origin=(0.0, 0.0)) -> MeshArrays:
    """The ``MeshArrays`` of a heightfield (see the module docstring).

    Parameters
    ----------
    heights : array_like, shape (nx, nz)
        Finite heights (y), nx, nz >= 2.
    spacing : float or (dx, dz)
        Positive sample spacings along x and z.
    origin : (x0, z0)
        Where sample (0, 0) lies.

    Raises
    ------
    ValueError
        For fewer than 2 × 2 samples, a non-finite height (naming its index), a non-positive or non-finite
        spacing, a non-finite origin. TypeError for non-numeric input.
    """
    h = as_float_array(heights, "heights", ndim=2)
    if h.shape[0] < 2 or h.shape[1] < 2:
        raise ValueError(f"heights must have at least 2 x 2 samples, got shape {h.shape}")
    sp = as_float_array(spacing, "spacing", ndim=None)
    if sp.shape not in ((), (2,)):
        raise ValueError(f"spacing must be a scalar or (dx, dz), got shape {sp.shape}")
    dx, dz = (float(sp), float(sp)) if sp.shape == () else (float(sp[0]), float(sp[1]))
    if not (dx > 0.0 and dz > 0.0):
        raise ValueError(f"spacing must be positive, got {(dx, dz)}")
    x0, z0 = as_float_array(origin, "origin", shape=(2,))
    nx, nz = h.shape
    i, k = np.meshgrid(np.arange(nx), np.arange(nz), indexing="ij")
    v = np.stack([x0 + i.ravel() * dx, h.ravel(), z0 + k.ravel() * dz], axis=1)
    t = heightfield_triangles(nx, nz)
    normals = _face_normals(v, t, "heights")
    return _with_tree(v, t, normals, _active_edges(v, t, normals), np.array([nx, nz], np.int64),
                      np.array([x0, z0, dx, dz]), False)


def mesh_box(mesh: MeshArrays):
    """The surface's AABB: (lo (3,), hi (3,))."""
    return mesh.vertices.min(axis=0), mesh.vertices.max(axis=0)


@njit(inline="always")
def triangle_corners(mesh, t):
    """Triangle t's corners as three 3-tuples."""
    v = mesh.vertices
    a, b, c = mesh.triangles[t, 0], mesh.triangles[t, 1], mesh.triangles[t, 2]
    return (v[a, 0], v[a, 1], v[a, 2]), (v[b, 0], v[b, 1], v[b, 2]), (v[c, 0], v[c, 1], v[c, 2])


@njit(inline="always")
def _triangle_meets_box(mesh, t, lo, hi):
    """Whether triangle t's AABB meets [lo, hi] (closed)."""
    for c in range(3):
        x0 = mesh.vertices[mesh.triangles[t, 0], c]
        x1 = mesh.vertices[mesh.triangles[t, 1], c]
        x2 = mesh.vertices[mesh.triangles[t, 2], c]
        if min(x0, min(x1, x2)) > hi[c] or max(x0, max(x1, x2)) < lo[c]:
            return False
    return True


@njit(inline="always")
def _cell_range(lo_c, hi_c, start, step, cells):
    """The cells [first, last] along one axis whose span can meet [lo_c, hi_c] (one cell of slack each side
    for the round-off of start + i·step; the exact triangle-box test decides)."""
    first = max(int(math.floor((lo_c - start) / step)) - 1, 0)
    last = min(int(math.floor((hi_c - start) / step)) + 1, cells - 1)
    return first, last


@njit
def candidate_triangles(mesh, lo, hi, stack, out):
    """The triangles whose AABBs meet the box [lo, hi] ((3,) each), ascending, in ``out``; returns (out, count)
    (``out`` grown when full). A soup descends its BVH (``stack``: at least nodes + 1 int64); a heightfield
    takes the cells under the box (module docstring)."""
    count = 0
    if mesh.grid_n[0] > 0:
        nz = mesh.grid_n[1]
        i0, i1 = _cell_range(lo[0], hi[0], mesh.grid_f[0], mesh.grid_f[2], mesh.grid_n[0] - 1)
        k0, k1 = _cell_range(lo[2], hi[2], mesh.grid_f[1], mesh.grid_f[3], nz - 1)
        for i in range(i0, i1 + 1):
            for k in range(k0, k1 + 1):
                for s in range(2):
                    t = 2 * (i * (nz - 1) + k) + s
                    if _triangle_meets_box(mesh, t, lo, hi):
                        if count == out.shape[0]:
                            out = np.concatenate((out, np.empty_like(out)))
                        out[count] = t
                        count += 1
        return out, count
    if mesh.root < 0:
        return out, count
    top = 1
    stack[0] = mesh.root
    while top > 0:
        top -= 1
        node = stack[top]
        hit = True
        for c in range(3):
            if lo[c] > mesh.node_hi[node, c] or mesh.node_lo[node, c] > hi[c]:
                hit = False
        if not hit:
            continue
        if mesh.child1[node] == -1:
            t = mesh.obj_of[node]
            if _triangle_meets_box(mesh, t, lo, hi):
                if count == out.shape[0]:
                    out = np.concatenate((out, np.empty_like(out)))
                out[count] = t
                count += 1
        else:
            stack[top] = mesh.child1[node]
            stack[top + 1] = mesh.child2[node]
            top += 2
    out[:count].sort()
    return out, count
