"""The level benchmark's scene, its peers and its exact answer: bodies resting on a terrain of smooth hills.

The scene (``level_scene(n)``)
- the terrain: ``terrain_heights()``, 128 × 128 samples at spacing 0.5 (y-up, sample (i, k) at
  (x0 + 0.5 i, z0 + 0.5 k), centred on the origin), a deterministic sum of Gaussian hills and sines; the
  engine's ``HeightField`` of it and the ``TriangleMesh`` of the same triangles (``field.mesh``);
- n bodies, even indices spheres (r = 0.3), odd indices boxes (half extent 0.25) turned at random, over uniform
  (x, z) at a random height above the surface at (x, z): about half of them touch it;
- ``NEAR_TOUCHING`` (200) of them, half spheres half boxes, put at their exact touching height (the bisection of
  ``touching_heights`` on the exact answer) then moved up (just out) or down (just in) by ``NEAR_OFFSET`` · s,
  s the body's size (the sphere's radius, the box's half extent): within 1e-7 of touching.
The bodies are in one collision category and the terrain in another, masked so that bodies never pair with each
other (they overlap freely): every peer answers the body–terrain pairs only.

The exact answer (``exact_answer``), independent of the engine: the triangles whose AABBs meet a body's AABB
(an xz grid of buckets over the triangles' boxes, ``TriangleBuckets``); a sphere touches the surface when the
distance from its centre to the nearest of them (``point_triangle_distance``: the projection on the plane when it
falls inside the triangle, else the nearest edge; Ericson 5.1.5) is at most r, its depth r − that distance; a
box touches when some triangle has no separating axis among the 13 of the SAT (triangle normal, 3 box faces, 9
edge × edge; Ericson 5.2.9, Akenine-Möller), closed (intervals that meet touch).

The peers, each driven the way its users drive it (``upload(centers, quaternions)``, ``detect()``, ``read()``,
then ``touching()`` -> (bodies (k,) ascending, deepest depth (k,))):
- ``LevelWorldFrame`` — ``World`` with ``HeightField`` (surface "field") or ``TriangleMesh`` ("mesh") added,
  ``update(ids, centers, rotations=quaternions)`` + ``contacts()``; also ``distances()`` (``closest_points``);
- ``LevelMuJoCoFrame`` — an ``hfield`` geom in the world body. MuJoCo's hfield is z-up: sample (r, c) of its
  ``nrow × ncol`` data lies at local (X, Y) = (c·2 rx/(ncol − 1) − rx, r·2 ry/(nrow − 1) − ry), height
  data · top, base down to −bottom (``size = rx ry top bottom``), each cell split along (r, c)–(r+1, c+1). The
  map: row r = our i (local Y = our x), column c = our k (local X = our z), local Z = our y — the geom turned by
  the rotation taking X → z, Y → x, Z → y (quaternion (0.5, −0.5, −0.5, −0.5), a proper rotation, which keeps the
  split diagonal on ours), placed at (x centre, min height, z centre). Heights are stored normalised to [0, 1] in
  float32: MuJoCo's surface is ours to (max − min) · 2⁻²⁴ (about 2e-7 here);
- ``LevelBulletFrame`` — pybullet ``GEOM_HEIGHTFIELD`` (surface "field") or a concave ``GEOM_MESH``
  (``GEOM_FORCE_CONCAVE_TRIMESH``, "mesh") in a static multibody. Bullet's heightfield is z-up here (pybullet's
  up axis), vertex (x, y) = data[y·rows + x] at ((x − (rows − 1)/2)·sx, (y − (cols − 1)/2)·sy, h − (min + max)/2),
  each cell split along (x+1, y)–(x, y+1). The map: Bullet x = our i, Bullet y = nz − 1 − our k, Bullet z = our
  y — the body turned by −90° about x (quaternion xyzw (−√½, 0, 0, √½)), which puts the split on ours. pybullet
  computes in float32 (positions of ~30 units carry ~2e-6 of round-off).
The bodies' categories: World ``set_filter`` (Box2D's rule), MuJoCo ``contype`` / ``conaffinity``, pybullet
``setCollisionFilterGroupMask``. ``CoalDistance``: coal's ``BVHModelOBBRSS`` of the triangles, ``coal.distance``
per body (the signed distance queries against ``World.closest_points``).
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from bench.world_peers import BulletMultiBodyFrame, MuJoCoFreeBodyFrame, WorldFrame
from engine.world import Box, HeightField, Sphere, TriangleMesh, World

TERRAIN_SAMPLES = 128
TERRAIN_SPACING = 0.5
SPHERE_RADIUS = 0.3
BOX_HALF = 0.25
NEAR_TOUCHING = 200
NEAR_OFFSET = 1e-7
#: the collision categories: bodies pair with the terrain, never with each other
BODY_CATEGORY, TERRAIN_CATEGORY = 1, 2
#: a frame's jitter about the scene's poses (a length, and an angle in radians)
FRAME_STEP, FRAME_TURN = 0.002, 0.01


# ---------------------------------------------------------------------------------------------------------------
# the scene
# ---------------------------------------------------------------------------------------------------------------

def terrain_heights(samples: int = TERRAIN_SAMPLES, spacing: float = TERRAIN_SPACING):
    """The terrain: heights (samples, samples) float64 and the origin (x0, z0) of sample (0, 0), centred on 0.

    Three Gaussian hills (one a hollow) and two sine swells, slopes below 1: h(x, z) at x = x0 + i·spacing,
    z = z0 + k·spacing."""
    half = (samples - 1) * spacing / 2
    x = np.arange(samples) * spacing - half
    x, z = np.meshgrid(x, x, indexing="ij")
    h = np.zeros_like(x)
    for amp, cx, cz, width in ((1.5, -14.0, -10.0, 6.0), (2.0, 12.0, 9.0, 8.0), (-1.2, -2.0, 18.0, 5.0)):
        h += amp * np.exp(-((x - cx) ** 2 + (z - cz) ** 2) / (2 * width * width))
    h += 0.5 * np.sin(2 * np.pi * x / 13.0) * np.cos(2 * np.pi * z / 19.0)
    h += 0.3 * np.sin(2 * np.pi * (x + 2 * z) / 29.0 + 0.4)
    return h, (-half, -half)


class LevelScene(NamedTuple):
    """A scene of the level benchmark.

    Attributes
    ----------
    heights : numpy.ndarray, shape (nx, nz), float64
        The terrain's samples (y-up), at (origin[0] + i·spacing, origin[1] + k·spacing).
    spacing : float
    origin : tuple of float
    vertices, triangles : numpy.ndarray, shapes (nx·nz, 3) float64 and (2 (nx − 1)(nz − 1), 3) int64
        The same surface as triangles (the engine's ``HeightField`` order: vertex (i, k) = i·nz + k).
    shapes : list of Shape, length n
        Engine shapes in their body frame (Sphere at the origin, Box unturned).
    is_sphere : numpy.ndarray, shape (n,), bool
    size : numpy.ndarray, shape (n,), float64
        The sphere's radius or the box's half extent.
    centers, quaternions : numpy.ndarray, shapes (n, 3) and (n, 4) float64
        The poses (unit quaternions, w x y z).
    near : numpy.ndarray, shape (NEAR_TOUCHING,), int64
        The bodies placed within NEAR_OFFSET · size of touching, ascending.
    near_in : numpy.ndarray, shape (NEAR_TOUCHING,), bool
        Whether each of them was moved in (touching) rather than out.
    """

    heights: np.ndarray
    spacing: float
    origin: tuple
    vertices: np.ndarray
    triangles: np.ndarray
    shapes: list
    is_sphere: np.ndarray
    size: np.ndarray
    centers: np.ndarray
    quaternions: np.ndarray
    near: np.ndarray
    near_in: np.ndarray


def unit_quaternions(n: int, rng) -> np.ndarray:
    """n uniform random unit quaternions (n, 4), w x y z (normalised Gaussians)."""
    q = rng.normal(size=(n, 4))
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def rotation_matrices(q) -> np.ndarray:
    """(n, 3, 3) rotation matrices of unit quaternions (n, 4), w x y z."""
    w, x, y, z = np.asarray(q, float).T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], axis=-1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], axis=-1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=-1)], axis=1)


def level_scene(n: int, seed: int = 31, samples: int = TERRAIN_SAMPLES, near: int = NEAR_TOUCHING) -> LevelScene:
    """The scene of the module docstring with n bodies (n >= near) on a terrain of samples × samples."""
    rng = np.random.default_rng(seed)
    heights, origin = terrain_heights(samples)
    field = HeightField(heights, TERRAIN_SPACING, origin)
    vertices, triangles = np.array(field.mesh.vertices), np.array(field.mesh.triangles)
    is_sphere = np.arange(n) % 2 == 0
    size = np.where(is_sphere, SPHERE_RADIUS, BOX_HALF)
    span = (samples - 1) * TERRAIN_SPACING
    xz = origin + rng.uniform(1.0, span - 1.0, size=(n, 2))
    buckets = TriangleBuckets(vertices, triangles)
    ground = surface_heights(buckets, xz)
    lift = rng.uniform(0.0, 1.0, n) * np.where(is_sphere, 0.6, 0.75)
    centers = np.column_stack([xz[:, 0], ground + lift, xz[:, 1]])
    quaternions = unit_quaternions(n, rng)
    # the near bodies: half spheres, half boxes; half of each moved in, half out
    picks = [rng.choice(np.flatnonzero(is_sphere == s), near // 2, replace=False) for s in (True, False)]
    near_ids = np.sort(np.concatenate(picks))
    near_in = rng.permutation(np.arange(near_ids.shape[0]) % 2 == 0)
    probe = LevelScene(heights, TERRAIN_SPACING, origin, vertices, triangles, [], is_sphere, size, centers,
                       quaternions, near_ids, near_in)
    top = touching_heights(probe, near_ids, buckets)
    centers[near_ids, 1] = top + np.where(near_in, -1.0, 1.0) * NEAR_OFFSET * size[near_ids]
    shapes = [Sphere((0.0, 0.0, 0.0), SPHERE_RADIUS) if s else Box((0.0, 0.0, 0.0), (BOX_HALF,) * 3)
              for s in is_sphere]
    return probe._replace(shapes=shapes, centers=centers)


def level_motion(scene: LevelScene, rounds: int, seed: int = 9) -> list:
    """``rounds`` poses (centers (n, 3), quaternions (n, 4)), each the scene's poses moved by a random step of
    scale ``FRAME_STEP`` and turned by ~``FRAME_TURN``: frames of bodies jostling on the terrain."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(rounds):
        half = 0.5 * rng.normal(0.0, FRAME_TURN, (scene.centers.shape[0], 3))
        dq = np.concatenate([np.cos(np.linalg.norm(half, axis=1, keepdims=True)), half], axis=1)
        dq /= np.linalg.norm(dq, axis=1, keepdims=True)
        q = quaternion_product(dq, scene.quaternions)
        out.append((scene.centers + rng.normal(0.0, FRAME_STEP, scene.centers.shape),
                    q / np.linalg.norm(q, axis=1, keepdims=True)))
    return out


def quaternion_product(a, b) -> np.ndarray:
    """Row-wise Hamilton products a ⊗ b of quaternions (n, 4), w x y z."""
    aw, ax, ay, az = a.T
    bw, bx, by, bz = b.T
    return np.stack([aw * bw - ax * bx - ay * by - az * bz, aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx, aw * bz + ax * by - ay * bx + az * bw], axis=1)


def field_of(scene: LevelScene) -> HeightField:
    return HeightField(scene.heights, scene.spacing, scene.origin)


def mesh_of(scene: LevelScene) -> TriangleMesh:
    return TriangleMesh(scene.vertices, scene.triangles)


# ---------------------------------------------------------------------------------------------------------------
# the exact answer
# ---------------------------------------------------------------------------------------------------------------

class TriangleBuckets:
    """The triangles of a soup bucketed on an xz grid of their AABBs (cell: the mean xz extent of a triangle),
    for the candidates under a box: ``pairs(lo, hi)``."""

    def __init__(self, vertices, triangles):
        self.corners = np.asarray(vertices, float)[np.asarray(triangles)]  # (nt, 3, 3)
        self.lo, self.hi = self.corners.min(axis=1), self.corners.max(axis=1)
        self.base = self.lo[:, [0, 2]].min(axis=0)
        self.cell = float(np.mean(self.hi[:, [0, 2]] - self.lo[:, [0, 2]]))
        self.shape = (self._cell(self.hi[:, [0, 2]]).max(axis=0) + 1).astype(np.int64)
        owner, cells = _covered_cells(self._cell(self.lo[:, [0, 2]]), self._cell(self.hi[:, [0, 2]]), self.shape)
        order = np.argsort(cells, kind="stable")
        self.triangle_of = owner[order]
        self.start = np.searchsorted(cells[order], np.arange(self.shape[0] * self.shape[1] + 1))

    def _cell(self, xz):
        return np.floor((xz - self.base) / self.cell).astype(np.int64)

    def pairs(self, lo, hi):
        """(body (m,), triangle (m,)): every triangle whose AABB meets box b [lo[b], hi[b]] ((n, 3) each), each
        pair once, sorted by body then triangle."""
        c0 = np.clip(self._cell(lo[:, [0, 2]]), 0, self.shape - 1)
        c1 = np.clip(self._cell(hi[:, [0, 2]]), 0, self.shape - 1)
        body, cells = _covered_cells(c0, c1, self.shape)
        count = self.start[cells + 1] - self.start[cells]
        body = np.repeat(body, count)
        first = np.repeat(self.start[cells] - np.cumsum(count) + count, count)
        tri = self.triangle_of[np.arange(body.shape[0]) + first]
        meets = np.all((self.lo[tri] <= hi[body]) & (lo[body] <= self.hi[tri]), axis=1)
        key = np.unique(body[meets] * self.corners.shape[0] + tri[meets])
        return key // self.corners.shape[0], key % self.corners.shape[0]


def _covered_cells(c0, c1, shape):
    """(owner (m,), cell (m,)): every cell of each range [c0[j], c1[j]] (inclusive, (n, 2) cell coordinates) as
    flat indices i·shape[1] + k."""
    owners, cells = [], []
    span = c1 - c0
    for di in range(int(span[:, 0].max(initial=0)) + 1):
        for dk in range(int(span[:, 1].max(initial=0)) + 1):
            j = np.flatnonzero((span[:, 0] >= di) & (span[:, 1] >= dk))
            owners.append(j)
            cells.append((c0[j, 0] + di) * shape[1] + c0[j, 1] + dk)
    return np.concatenate(owners), np.concatenate(cells)


def _dot(u, v):
    return np.einsum("ij,ij->i", u, v)


def _segment_distance2(p, a, b):
    """Squared distances (m,) from points p to segments [a, b] (rows)."""
    ab = b - a
    t = np.clip(_dot(p - a, ab) / _dot(ab, ab), 0.0, 1.0)
    d = p - (a + t[:, None] * ab)
    return _dot(d, d)


def point_triangle_distance(p, a, b, c) -> np.ndarray:
    """Distances (m,) from points p to triangles (a, b, c) (rows (m, 3) each): the distance to the plane when the
    point's projection falls inside the triangle (all three edge tests non-negative), else to the nearest edge
    (Ericson 5.1.5's regions; the edge distance is the minimum over the three edges, which the plane distance
    never exceeds)."""
    n = np.cross(b - a, c - a)
    inside = ((_dot(np.cross(b - a, p - a), n) >= 0) & (_dot(np.cross(c - b, p - b), n) >= 0)
              & (_dot(np.cross(a - c, p - c), n) >= 0))
    edge = np.minimum(np.minimum(_segment_distance2(p, a, b), _segment_distance2(p, b, c)),
                      _segment_distance2(p, c, a))
    plane = _dot(p - a, n) ** 2 / _dot(n, n)
    return np.sqrt(np.where(inside, np.minimum(plane, edge), edge))


def box_triangle_overlap(center, axes, half, a, b, c) -> np.ndarray:
    """Whether boxes (center (m, 3), unit axes as the columns of axes (m, 3, 3), half extents (m, 3)) meet
    triangles (a, b, c) (rows (m, 3) each), closed: no separating axis among the 13 of the SAT (the triangle's
    normal, the box's 3 face normals, the 9 cross products of a box edge with a triangle edge). A zero cross
    product (parallel edges) projects both shapes to 0 and separates nothing."""
    v = [a - center, b - center, c - center]
    edges = [b - a, c - b, a - c]
    candidates = [np.cross(edges[0], edges[1])] + [axes[:, :, i] for i in range(3)]
    candidates += [np.cross(axes[:, :, i], e) for i in range(3) for e in edges]
    apart = np.zeros(center.shape[0], bool)
    for axis in candidates:
        radius = sum(half[:, i] * np.abs(_dot(axes[:, :, i], axis)) for i in range(3))
        p = np.stack([_dot(x, axis) for x in v])
        apart |= (p.min(axis=0) > radius) | (p.max(axis=0) < -radius)
    return ~apart


def _body_boxes(centers, rotations, size, is_sphere):
    """The bodies' AABBs (lo, hi) (n, 3): a sphere's centre ± r, a box's centre ± |R| h."""
    extent = np.where(is_sphere[:, None], size[:, None], np.abs(rotations).sum(axis=2) * size[:, None])
    return centers - extent, centers + extent


def _per_body_min(values, body, n):
    out = np.full(n, np.inf)
    np.minimum.at(out, body, values)
    return out


def sphere_distances(buckets: TriangleBuckets, centers, radius) -> np.ndarray:
    """Distances (n,) from the centres (n, 3) to the nearest triangle under each AABB centre ± radius (inf for
    none): the distance to the surface wherever it is at most radius (a larger radius reaches farther)."""
    r = np.broadcast_to(np.asarray(radius, float), centers.shape[:1])[:, None]
    body, tri = buckets.pairs(centers - r, centers + r)
    t = buckets.corners[tri]
    return _per_body_min(point_triangle_distance(centers[body], t[:, 0], t[:, 1], t[:, 2]), body, len(centers))


def boxes_touch(buckets: TriangleBuckets, centers, rotations, half) -> np.ndarray:
    """Whether each box (centres (n, 3), rotations (n, 3, 3), half extents (n,)) meets a triangle (n,) bool."""
    lo, hi = _body_boxes(centers, rotations, np.asarray(half, float), np.zeros(len(centers), bool))
    body, tri = buckets.pairs(lo, hi)
    t = buckets.corners[tri]
    h = np.repeat(np.asarray(half, float)[body][:, None], 3, axis=1)
    hit = box_triangle_overlap(centers[body], rotations[body], h, t[:, 0], t[:, 1], t[:, 2])
    return np.bincount(body[hit], minlength=len(centers)) > 0


def exact_answer(scene: LevelScene, centers=None, quaternions=None, buckets=None):
    """(touching (n,) bool, sphere depth (n,) float64: r − distance for spheres, NaN for boxes) at the scene's
    poses (or those given)."""
    centers = scene.centers if centers is None else centers
    rot = rotation_matrices(scene.quaternions if quaternions is None else quaternions)
    buckets = buckets or TriangleBuckets(scene.vertices, scene.triangles)
    s, b = np.flatnonzero(scene.is_sphere), np.flatnonzero(~scene.is_sphere)
    touching = np.zeros(len(centers), bool)
    depth = np.full(len(centers), np.nan)
    depth[s] = scene.size[s] - sphere_distances(buckets, centers[s], scene.size[s])
    touching[s] = depth[s] >= 0.0
    touching[b] = boxes_touch(buckets, centers[b], rot[b], scene.size[b])
    return touching, depth


def surface_heights(buckets: TriangleBuckets, xz) -> np.ndarray:
    """The surface's height (m,) straight above or below the points xz (m, 2): the triangle whose xz projection
    holds the point (barycentric coordinates, the largest when two share an edge), its plane there; NaN off it."""
    p = np.column_stack([xz[:, 0], np.zeros(len(xz)), xz[:, 1]])
    lo, hi = p.copy(), p.copy()
    lo[:, 1], hi[:, 1] = -np.inf, np.inf
    body, tri = buckets.pairs(lo, hi)
    a, b, c = (buckets.corners[tri, k] for k in range(3))
    ab, ac, ap = b - a, c - a, p[body] - a
    det = ab[:, 0] * ac[:, 2] - ab[:, 2] * ac[:, 0]
    u = (ap[:, 0] * ac[:, 2] - ap[:, 2] * ac[:, 0]) / det
    v = (ab[:, 0] * ap[:, 2] - ab[:, 2] * ap[:, 0]) / det
    inside = np.minimum(np.minimum(u, v), 1 - u - v)
    y = a[:, 1] + u * ab[:, 1] + v * ac[:, 1]
    order = np.lexsort((-inside, body))  # per point, the most inside triangle first
    first = order[np.r_[True, body[order][1:] != body[order][:-1]]] if order.size else order
    first = first[inside[first] >= -1e-12]
    out = np.full(len(xz), np.nan)
    out[body[first]] = y[first]
    return out


def touching_heights(scene: LevelScene, ids, buckets: TriangleBuckets, iterations: int = 80) -> np.ndarray:
    """The highest centre altitude (k,) at which each body ``ids`` (its x, z and rotation kept) still touches the
    surface, by bisection on the exact answer: from the surface's height at (x, z) (the centre on the surface:
    touching) to 1 + 2·size above it (apart; for a graph surface the touching altitudes form one interval). Returns
    the touching end of the final bracket."""
    ids = np.asarray(ids)
    c = scene.centers[ids].copy()
    q = scene.quaternions[ids]
    sub = scene._replace(is_sphere=scene.is_sphere[ids], size=scene.size[ids])
    lo = surface_heights(buckets, c[:, [0, 2]])
    hi = lo + 1.0 + 2.0 * sub.size

    def touches(y):
        c[:, 1] = y
        return exact_answer(sub, c, q, buckets)[0]

    if not (touches(lo).all() and not touches(hi).any()):
        raise RuntimeError("touching_heights: the bracket does not hold the touching altitude")
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        t = touches(mid)
        lo, hi = np.where(t, mid, lo), np.where(t, hi, mid)
    return lo


def wrong_against_exact(scene: LevelScene, exact_touching, bodies, depth=None, exact_depth=None) -> dict:
    """A peer's touching bodies (ascending ids (k,), deepest depth (k,)) against the exact answer: bodies missed
    and extra, how many of them are near-touching bodies, and for spheres the largest |depth − exact depth| over
    the spheres both find touching (NaN when none or no depths)."""
    found = np.zeros(len(exact_touching), bool)
    found[np.asarray(bodies, np.int64)] = True
    near = np.zeros(len(exact_touching), bool)
    near[scene.near] = True
    missed, extra = exact_touching & ~found, found & ~exact_touching
    out = {"exact_touching": int(exact_touching.sum()), "touching": int(found.sum()), "missed": int(missed.sum()),
           "extra": int(extra.sum()), "missed_near": int((missed & near).sum()),
           "extra_near": int((extra & near).sum()), "wrong": int((missed | extra).sum()),
           "sphere_depth_error_max": math.nan}
    if depth is not None and exact_depth is not None:
        d = np.full(len(exact_touching), np.nan)
        d[np.asarray(bodies, np.int64)] = depth
        both = found & exact_touching & scene.is_sphere
        if both.any():
            out["sphere_depth_error_max"] = float(np.max(np.abs(d[both] - exact_depth[both])))
    return out


def deepest_per_body(bodies, depth):
    """(ascending bodies (k,), the largest depth of each (k,)) of per-contact rows (bodies (m,), depth (m,))."""
    bodies = np.asarray(bodies, np.int64)
    depth = np.asarray(depth, float)
    if bodies.shape[0] == 0:
        return np.empty(0, np.int64), np.empty(0)
    order = np.lexsort((-depth, bodies))
    b, d = bodies[order], depth[order]
    first = np.r_[True, b[1:] != b[:-1]]
    return b[first], d[first]


# ---------------------------------------------------------------------------------------------------------------
# the peers
# ---------------------------------------------------------------------------------------------------------------

class LevelWorldFrame(WorldFrame):
    """The engine's World: the bodies (ids 0 .. n − 1), then the surface (a HeightField or its TriangleMesh)."""

    def __init__(self, scene: LevelScene, surface: str = "field", broad_phase: str = "tree"):
        self.name = f"World {surface}"
        self.world = World(broad_phase)
        self.ids = np.array([self.world.add(s) for s in scene.shapes], np.int64)
        self.surface = self.world.add(field_of(scene) if surface == "field" else mesh_of(scene))
        self.world.set_filter(self.ids, category=BODY_CATEGORY, mask=TERRAIN_CATEGORY)
        self.world.set_filter([self.surface], category=TERRAIN_CATEGORY, mask=BODY_CATEGORY)
        self.upload(scene.centers, scene.quaternions)
        self.last = None

    def touching(self):
        c = self.last if self.last is not None else self.detect()
        on = (c.pairs == self.surface).any(axis=1)
        return deepest_per_body(c.pairs[on].min(axis=1), c.depth[on])

    def contact_points(self):
        """(points (M, 3), body of each point (M,)) of the last ``contacts()``."""
        c = self.last if self.last is not None else self.detect()
        counts = np.diff(c.point_offsets)
        return c.points, np.repeat(c.pairs.min(axis=1), counts)

    def distances(self):
        """``closest_points`` of every body against the surface: signed distances (n,)."""
        return self.world.closest_points(self.ids, np.full(self.ids.shape, self.surface))[0]


def _mjcf_level(scene: LevelScene) -> str:
    """The MJCF of the module docstring: the hfield geom (its data set after compiling), one free body per body."""
    nx, nz = scene.heights.shape
    rx, ry = (nz - 1) * scene.spacing / 2, (nx - 1) * scene.spacing / 2
    low, top = float(scene.heights.min()), float(np.ptp(scene.heights))
    pos = (scene.origin[0] + ry, low, scene.origin[1] + rx)
    body = f' contype="{BODY_CATEGORY}" conaffinity="{TERRAIN_CATEGORY}"'
    bodies = []
    for s, size, c in zip(scene.is_sphere.tolist(), scene.size.tolist(), scene.centers.tolist()):
        geom = (f'<geom type="sphere" size="{size!r}"{body}/>' if s else
                f'<geom type="box" size="{size!r} {size!r} {size!r}"{body}/>')
        bodies.append(f'<body pos="{c[0]!r} {c[1]!r} {c[2]!r}"><freejoint/>{geom}</body>')
    n = len(bodies) + 1
    memory = 64 + (4 * n * n) // 2**20 + 1  # mj_broadphase takes ~2 n^2 bytes of the arena, twice
    return (f'<mujoco><size memory="{memory}M"/><asset><hfield name="terrain" nrow="{nx}" ncol="{nz}" '
            f'size="{rx!r} {ry!r} {top!r} 1.0"/></asset><worldbody>'
            f'<geom name="terrain" type="hfield" hfield="terrain" pos="{pos[0]!r} {pos[1]!r} {pos[2]!r}" '
            f'quat="0.5 -0.5 -0.5 -0.5" contype="{TERRAIN_CATEGORY}" conaffinity="{BODY_CATEGORY}"/>'
            f'{"".join(bodies)}</worldbody></mujoco>')


class LevelMuJoCoFrame(MuJoCoFreeBodyFrame):
    """MuJoCo: the terrain as an hfield geom, free bodies; ``mj_kinematics`` + ``mj_collision`` per frame."""

    name = "MuJoCo hfield"

    def __init__(self, scene: LevelScene):
        import mujoco

        self.mujoco = mujoco
        self.model = mujoco.MjModel.from_xml_string(_mjcf_level(scene))
        h = scene.heights
        self.model.hfield_data[:] = ((h - h.min()) / np.ptp(h)).astype(np.float32).ravel()
        self.data = mujoco.MjData(self.model)
        self.qpos = self.data.qpos.reshape(len(scene.shapes), 7)
        self.upload(scene.centers, scene.quaternions)

    def read(self):
        con = self.data.contact
        return np.asarray(con.geom), -np.asarray(con.dist), np.asarray(con.pos)

    def touching(self):
        geom, depth, _ = self.read()
        body = self.model.geom_bodyid[geom.max(axis=1)] - 1  # the terrain is geom 0 (world body)
        keep = depth >= 0.0
        return deepest_per_body(body[keep], depth[keep])

    def contact_points(self):
        geom, _, pos = self.read()
        return pos, self.model.geom_bodyid[geom.max(axis=1)] - 1


class LevelBulletFrame(BulletMultiBodyFrame):
    """pybullet (DIRECT): the terrain as a static heightfield or concave mesh, one multibody per body;
    ``performCollisionDetection`` per frame."""

    def __init__(self, scene: LevelScene, surface: str = "field"):
        import pybullet

        self.name = f"pybullet {'heightfield' if surface == 'field' else 'mesh'}"
        self.p = p = pybullet
        self.client = p.connect(p.DIRECT)
        terrain = self._terrain(scene, surface)
        p.setCollisionFilterGroupMask(terrain, -1, TERRAIN_CATEGORY, BODY_CATEGORY, physicsClientId=self.client)
        shapes = {True: p.createCollisionShape(p.GEOM_SPHERE, radius=SPHERE_RADIUS, physicsClientId=self.client),
                  False: p.createCollisionShape(p.GEOM_BOX, halfExtents=[BOX_HALF] * 3, physicsClientId=self.client)}
        xyzw = np.roll(scene.quaternions, -1, axis=1).tolist()
        self.bodies = []
        for s, c, q in zip(scene.is_sphere.tolist(), scene.centers.tolist(), xyzw):
            b = p.createMultiBody(1.0, shapes[s], basePosition=c, baseOrientation=q, physicsClientId=self.client)
            p.setCollisionFilterGroupMask(b, -1, BODY_CATEGORY, TERRAIN_CATEGORY, physicsClientId=self.client)
            self.bodies.append(b)
        self.index = np.full(max(self.bodies) + 1, -1, np.int64)
        self.index[self.bodies] = np.arange(len(self.bodies))
        self.terrain = terrain

    def _terrain(self, scene: LevelScene, surface: str) -> int:
        """The static terrain multibody (module docstring: Bullet's heightfield conventions and the map)."""
        p, c = self.p, self.client
        if surface != "field":
            shape = p.createCollisionShape(p.GEOM_MESH, vertices=scene.vertices.tolist(),
                                           indices=scene.triangles.ravel().tolist(),
                                           flags=p.GEOM_FORCE_CONCAVE_TRIMESH, physicsClientId=c)
            return p.createMultiBody(0.0, shape, physicsClientId=c)
        h = scene.heights
        nx, nz = h.shape
        mid = 0.5 * (h.min() + h.max())
        data = (h[:, ::-1] - mid).T.ravel()  # Bullet (x, y) = our (i, nz - 1 - k), stored at y * rows + x
        shape = p.createCollisionShape(p.GEOM_HEIGHTFIELD, meshScale=[scene.spacing, scene.spacing, 1.0],
                                       heightfieldData=data.tolist(), numHeightfieldRows=nx,
                                       numHeightfieldColumns=nz, physicsClientId=c)
        centre = [scene.origin[0] + (nx - 1) * scene.spacing / 2, mid, scene.origin[1] + (nz - 1) * scene.spacing / 2]
        return p.createMultiBody(0.0, shape, basePosition=centre, baseOrientation=[-math.sqrt(0.5), 0, 0,
                                                                                   math.sqrt(0.5)],
                                 physicsClientId=c)

    def _rows(self):
        """(body (m,), depth (m,), point on the terrain (m, 3)) of the contact points with the terrain."""
        points = [c for c in self.read() if self.terrain in (c[1], c[2])]
        if not points:
            return np.empty(0, np.int64), np.empty(0), np.empty((0, 3))
        other = np.array([c[2] if c[1] == self.terrain else c[1] for c in points])
        on_terrain = np.array([c[6] if c[1] == self.terrain else c[5] for c in points])
        return self.index[other], -np.array([c[8] for c in points]), on_terrain

    def touching(self):
        body, depth, _ = self._rows()
        keep = depth >= 0.0  # Bullet reports points up to its contact breaking threshold apart
        return deepest_per_body(body[keep], depth[keep])

    def contact_points(self):
        body, depth, point = self._rows()
        return point[depth >= 0.0], body[depth >= 0.0]


class CoalDistance:
    """coal: the surface as a ``BVHModelOBBRSS``, ``coal.distance`` per body (signed: negative when penetrating,
    as coal's shape–triangle distance reports it)."""

    name = "coal BVH"

    def __init__(self, scene: LevelScene):
        import coal

        self.coal = coal
        model = coal.BVHModelOBBRSS()
        model.beginModel(scene.triangles.shape[0], scene.vertices.shape[0])
        model.addVertices(np.ascontiguousarray(scene.vertices))
        model.addTriangles(np.ascontiguousarray(scene.triangles, dtype=np.int64))
        model.endModel()
        self.surface = coal.CollisionObject(model, coal.Transform3s())
        self.shapes = [coal.Sphere(SPHERE_RADIUS) if s else coal.Box(*(2 * BOX_HALF,) * 3)
                       for s in scene.is_sphere]
        self.request = coal.DistanceRequest()
        self.centers, self.rotations = scene.centers, rotation_matrices(scene.quaternions)

    def upload(self, centers, quaternions):
        self.centers, self.rotations = centers, rotation_matrices(quaternions)

    def distances(self):
        coal = self.coal
        out = np.empty(len(self.shapes))
        for k, (shape, c, r) in enumerate(zip(self.shapes, self.centers, self.rotations)):
            result = coal.DistanceResult()
            coal.distance(coal.CollisionObject(shape, coal.Transform3s(r, c)), self.surface, self.request, result)
            out[k] = result.min_distance
        return out
