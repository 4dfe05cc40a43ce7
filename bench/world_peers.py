"""The frame peers of the World benchmark, each driven the way its users drive it, and the agreement checks.

A frame is: upload every body's pose, detect, read the contacts.
- ``EngineFrame`` — ``World.update(ids, centers, rotations=quaternions)`` + ``World.contacts()``;
- ``MuJoCoFrame`` — one free body per shape in an MJCF model (spheres, boxes, capsules, meshes whose convex hull
  MuJoCo computes; the ground a ``plane`` geom turned to face +y); write ``qpos`` (position, quaternion w x y z),
  ``mj_kinematics`` + ``mj_collision``, read ``d.contact`` (``geom``, ``dist``). Its broad phase reserves about
  4 n² bytes of the model's arena (``MUJOCO_MAX_BODIES`` bounds the scenes it is given);
- ``BulletFrame`` — pybullet in DIRECT mode, one multibody of mass 1 per shape (capsules along z, hulls as
  ``GEOM_MESH`` convex hulls; the ground a static ``GEOM_PLANE`` of normal +y), ``resetBasePositionAndOrientation``
  per body (quaternion x y z w), ``performCollisionDetection``, ``getContactPoints``.
Each frame has ``upload(centers, quaternions)``, ``detect()`` and ``read()``; ``frame.penetrating(threshold)``
returns the pairs (k, 2) of body indices (the ground is index n) whose deepest contact is deeper than
``threshold`` and that depth (k,): MuJoCo's and Bullet's depths are per contact point (the largest is taken), the
engine's the pair's minimum translation distance. ``agreement`` compares two such answers, ``disagreements``
lists the pairs one of them finds deeper than ``AGREEMENT_BAND`` and the other misses.

Each frame also takes a static level (``level``, an ``engine.workloads.StaticBoxes``; its boxes are indices
n + g, n + g + 1, ... after the moving bodies and the g grounds) and a collision filter (``filters``, the
``(category, mask)`` arrays of ``engine.workloads.category_masks``):
- World: the boxes ``add(..., static=True)``; ``set_filter(ids, category=, mask=)``;
- MuJoCo: the boxes as geoms of the world body (body 0: never tested against each other); ``contype`` =
  category, ``conaffinity`` = mask (MuJoCo's OR rule equals the AND rule of the others for symmetric masks);
- pybullet: the boxes as multibodies of mass 0 (static); ``setCollisionFilterGroupMask(body, -1, category,
  mask)`` (pybullet's rule: ``group_i & mask_j`` and ``group_j & mask_i``).

``exact_depth(shape_a, pose_a, shape_b, pose_b)``: the penetration depth as the distance from the origin to the
boundary of the Minkowski difference A − B (Qhull on the differences of the cores' points, plus the radii).
"""
from __future__ import annotations

import importlib
import time

import numpy as np

from engine.workloads import FrameScene, StaticBoxes, quaternion_matrices
from engine.world import Box, Capsule, Plane, Sphere, World


def _per_pair_max(pairs: np.ndarray, depth: np.ndarray, threshold: float):
    """Rows of (pairs, depth) grouped by pair (canonical i < j), the largest depth of each, kept above threshold."""
    if pairs.shape[0] == 0:
        return np.empty((0, 2), np.int64), np.empty(0)
    p = np.sort(pairs, axis=1).astype(np.int64)
    order = np.lexsort((-depth, p[:, 1], p[:, 0]))
    p, d = p[order], depth[order]
    first = np.ones(p.shape[0], bool)
    first[1:] = (p[1:] != p[:-1]).any(axis=1)
    p, d = p[first], d[first]
    keep = d > threshold
    return p[keep], d[keep]


class WorldFrame:
    """What every frame on the engine's World shares: the subclass sets ``self.world``, the moving bodies' ids
    ``self.ids`` and ``self.last = None``; ``upload`` is ``World.update`` of their poses, ``detect`` is
    ``World.contacts()`` (kept as ``self.last``), ``read`` returns it."""

    def upload(self, centers, quaternions):
        self.world.update(self.ids, centers, rotations=quaternions)

    def detect(self):
        self.last = self.world.contacts()
        return self.last

    def read(self):
        return self.last


class EngineFrame(WorldFrame):
    """The engine's World on a scene; body i has id i, the ground (if any) id n."""

    name = "engine"

    def __init__(self, scene: FrameScene, broad_phase: str = "tree", level: StaticBoxes | None = None,
                 filters=None, threads: int | None = None):
        # threads: World's thread count (None: its default)
        self.world = World(broad_phase) if threads is None else World(broad_phase, threads=threads)
        self.ids = np.array([self.world.add(s) for s in scene.shapes], np.int64)
        if scene.ground is not None:
            self.world.add(Plane(scene.ground))
        for c, h, q in zip(*_level_arrays(level)):
            self.world.add(Box(c, h, q), static=True)
        if filters is not None:
            category, mask = filters
            for cat, msk in sorted(set(zip(category.tolist(), mask.tolist()))):
                self.world.set_filter(self.ids[(category == cat) & (mask == msk)], category=cat, mask=msk)
        self.upload(scene.centers, scene.quaternions)
        self.last = None

    def penetrating(self, threshold: float = 1e-6):
        c = self.last if self.last is not None else self.detect()
        keep = c.depth > threshold
        return c.pairs[keep], c.depth[keep]


def _level_arrays(level: StaticBoxes | None):
    """(centres, half extents, quaternions) of a level's boxes as lists, empty for no level."""
    if level is None:
        return [], [], []
    return level.centers.tolist(), level.half_extents.tolist(), level.quaternions.tolist()


def _mjcf_filter(filters, i: int) -> str:
    """contype = category and conaffinity = mask: MuJoCo's rule (an OR of the two directions) then gives the
    pairs of Box2D's (an AND) for the symmetric masks of ``engine.workloads.category_masks``."""
    if filters is None:
        return ""
    return f' contype="{int(filters[0][i])}" conaffinity="{int(filters[1][i])}"'


def _mjcf_level(level: StaticBoxes | None) -> str:
    """The level's boxes as geoms of the world body (MuJoCo never tests two geoms of one body)."""
    return "".join('<geom type="box" size="{!r} {!r} {!r}" pos="{!r} {!r} {!r}" quat="{!r} {!r} {!r} {!r}"/>'
                   .format(*h, *c, *q) for c, h, q in zip(*_level_arrays(level)))


def _mjcf(scene: FrameScene, level: StaticBoxes | None = None, filters=None) -> str:
    assets, bodies = [], []
    meshes: dict = {}
    for i, s in enumerate(scene.shapes):
        filt = _mjcf_filter(filters, i)
        if isinstance(s, Sphere):
            geom = f'<geom type="sphere" size="{float(s.radius)!r}"{filt}/>'
        elif isinstance(s, Box):
            geom = '<geom type="box" size="{!r} {!r} {!r}"{}/>'.format(*map(float, s.half_extents), filt)
        elif isinstance(s, Capsule):
            half = float(np.linalg.norm(s.local[1] - s.local[0]) / 2)
            geom = f'<geom type="capsule" size="{float(s.radius)!r} {half!r}"{filt}/>'
        else:
            key = id(s)
            if key not in meshes:
                meshes[key] = f"hull{len(meshes)}"
                verts = " ".join(repr(float(x)) for x in s.local.ravel())
                assets.append(f'<mesh name="{meshes[key]}" vertex="{verts}"/>')
            geom = f'<geom type="mesh" mesh="{meshes[key]}"{filt}/>'
        pos = " ".join(repr(float(x)) for x in scene.centers[i])
        bodies.append(f'<body pos="{pos}"><freejoint/>{geom}</body>')
    ground = ""
    if scene.ground is not None:  # MuJoCo's plane faces +z: turned by -90 degrees about x to face +y
        ground = (f'<geom name="ground" type="plane" size="0 0 1" pos="0 {float(scene.ground)!r} 0" '
                  f'quat="0.7071067811865476 -0.7071067811865476 0 0"/>')
    n = len(scene.shapes) + 1
    memory = 64 + (4 * n * n) // 2**20 + 1  # mj_broadphase takes ~2 n^2 bytes of the arena, twice
    return (f'<mujoco><size memory="{memory}M"/><asset>{"".join(assets)}</asset>'
            f'<worldbody>{ground}{_mjcf_level(level)}{"".join(bodies)}</worldbody></mujoco>')


#: the largest scene handed to MuJoCo here: its arena grows as 4 n² bytes (40 GB at n = 1e5)
MUJOCO_MAX_BODIES = 20_000


class MuJoCoFreeBodyFrame:
    """What the MuJoCo frames share: one free body per moving body, the subclass sets ``self.mujoco``,
    ``self.model``, ``self.data`` and ``self.qpos`` (the free bodies' ``qpos`` as (n, 7)); ``upload`` writes
    position and quaternion (w x y z), ``detect`` is ``mj_kinematics`` + ``mj_collision``."""

    def upload(self, centers, quaternions):
        self.qpos[:, :3] = centers
        self.qpos[:, 3:] = quaternions

    def detect(self):
        self.mujoco.mj_kinematics(self.model, self.data)
        self.mujoco.mj_collision(self.model, self.data)


class BulletMultiBodyFrame:
    """What the pybullet frames share: one multibody per moving body (``self.bodies``) in the DIRECT client
    ``self.client`` of ``self.p`` (the subclass sets them); ``upload`` is ``resetBasePositionAndOrientation`` per
    body (quaternion x y z w), ``detect`` ``performCollisionDetection``, ``read`` ``getContactPoints``."""

    def upload(self, centers, quaternions):
        xyzw = np.roll(quaternions, -1, axis=1).tolist()
        reset = self.p.resetBasePositionAndOrientation
        for b, c, q in zip(self.bodies, centers.tolist(), xyzw):
            reset(b, c, q, physicsClientId=self.client)

    def detect(self):
        self.p.performCollisionDetection(physicsClientId=self.client)

    def read(self):
        return self.p.getContactPoints(physicsClientId=self.client)

    def close(self):
        self.p.disconnect(physicsClientId=self.client)


class MuJoCoFrame(MuJoCoFreeBodyFrame):
    """MuJoCo on a scene: free bodies, ``mj_kinematics`` + ``mj_collision`` per frame."""

    name = "MuJoCo"

    def __init__(self, scene: FrameScene, level: StaticBoxes | None = None, filters=None):
        import mujoco

        self.mujoco = mujoco
        self.model = mujoco.MjModel.from_xml_string(_mjcf(scene, level, filters))
        self.data = mujoco.MjData(self.model)
        n = len(scene.shapes)
        # geom id -> body index: free body b + 1 is index b; the world body's geoms, the ground first then the
        # level's boxes in order, are n, n + 1, ...
        on_world = self.model.geom_bodyid == 0
        self.geom_body = np.where(on_world, n + np.cumsum(on_world) - 1, self.model.geom_bodyid - 1).astype(np.int64)
        self.qpos = self.data.qpos.reshape(n, 7)
        self.upload(scene.centers, scene.quaternions)

    def read(self):
        con = self.data.contact
        return self.geom_body[con.geom], -np.asarray(con.dist)

    def penetrating(self, threshold: float = 1e-6):
        pairs, depth = self.read()
        return _per_pair_max(pairs, depth, threshold)


class BulletFrame(BulletMultiBodyFrame):
    """pybullet (DIRECT) on a scene: one multibody per shape, ``performCollisionDetection`` per frame."""

    name = "pybullet"

    def __init__(self, scene: FrameScene, level: StaticBoxes | None = None, filters=None):
        import pybullet

        self.p = pybullet
        self.client = pybullet.connect(pybullet.DIRECT)
        cache: dict = {}
        self.bodies = []
        xyzw = np.roll(scene.quaternions, -1, axis=1).tolist()
        for s, c, q in zip(scene.shapes, scene.centers.tolist(), xyzw):  # created at their poses (not all at 0)
            key = ("sphere", s.radius) if isinstance(s, Sphere) else id(s)
            if key not in cache:
                cache[key] = self._collision_shape(s)
            self.bodies.append(pybullet.createMultiBody(1.0, cache[key], basePosition=c, baseOrientation=q,
                                                        physicsClientId=self.client))
        n = len(self.bodies)
        self.index = {b: i for i, b in enumerate(self.bodies)}
        if scene.ground is not None:
            plane = pybullet.createCollisionShape(pybullet.GEOM_PLANE, planeNormal=[0, 1, 0],
                                                  physicsClientId=self.client)
            ground = pybullet.createMultiBody(0.0, plane, basePosition=[0, scene.ground, 0],
                                              physicsClientId=self.client)
            self.index[ground] = n
        self._add_level(level, len(self.index))
        if filters is not None:
            for b, cat, msk in zip(self.bodies, filters[0].tolist(), filters[1].tolist()):
                pybullet.setCollisionFilterGroupMask(b, -1, cat, msk, physicsClientId=self.client)
        self.upload(scene.centers, scene.quaternions)

    def _add_level(self, level: StaticBoxes | None, first: int) -> None:
        """The level's boxes as multibodies of mass 0 (static: never moved, never tested against each other),
        indices first, first + 1, ..."""
        p = self.p
        for k, (c, h, q) in enumerate(zip(*_level_arrays(level))):
            shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=h, physicsClientId=self.client)
            body = p.createMultiBody(0.0, shape, basePosition=c, baseOrientation=[*q[1:], q[0]],
                                     physicsClientId=self.client)
            self.index[body] = first + k

    def _collision_shape(self, s):
        p = self.p
        if isinstance(s, Sphere):
            return p.createCollisionShape(p.GEOM_SPHERE, radius=s.radius, physicsClientId=self.client)
        if isinstance(s, Box):
            return p.createCollisionShape(p.GEOM_BOX, halfExtents=s.half_extents.tolist(),
                                          physicsClientId=self.client)
        if isinstance(s, Capsule):
            length = float(np.linalg.norm(s.local[1] - s.local[0]))
            return p.createCollisionShape(p.GEOM_CAPSULE, radius=s.radius, height=length,
                                          physicsClientId=self.client)
        return p.createCollisionShape(p.GEOM_MESH, vertices=s.local.tolist(), physicsClientId=self.client)

    def penetrating(self, threshold: float = 1e-6):
        points = self.read()
        if not points:
            return np.empty((0, 2), np.int64), np.empty(0)
        pairs = np.array([(self.index[c[1]], self.index[c[2]]) for c in points], np.int64)
        depth = -np.array([c[8] for c in points])
        return _per_pair_max(pairs, depth, threshold)


def frame_peers(scene: FrameScene, broad_phase: str = "tree"):
    """The three frames on one scene: ``[EngineFrame, MuJoCoFrame, BulletFrame]``."""
    return [EngineFrame(scene, broad_phase), MuJoCoFrame(scene), BulletFrame(scene)]


def frame_stages(frame, centers, quaternions, clock=time.perf_counter) -> dict:
    """One frame at the given poses, timed stage by stage in ``clock``'s seconds: ``{"upload": s, "detect": s,
    "read": s, "frame": s}`` (MuJoCo's and Bullet's "detect" is their broad and narrow phase, "read" the reading
    of their contacts; the engine's "detect" is ``contacts()``, which returns them)."""
    t0 = clock()
    frame.upload(centers, quaternions)
    t1 = clock()
    frame.detect()
    t2 = clock()
    frame.read()
    t3 = clock()
    return {"upload": t1 - t0, "detect": t2 - t1, "read": t3 - t2, "frame": t3 - t0}


def time_stages(frame, poses, clock=time.perf_counter) -> dict:
    """Minimum over the poses of each stage of one frame (``frame_stages``): ``{"upload": s, "detect": s,
    "read": s, "frame": s}``."""
    best = {"upload": np.inf, "detect": np.inf, "read": np.inf, "frame": np.inf}
    for centers, quats in poses:
        for key, value in frame_stages(frame, centers, quats, clock).items():
            best[key] = min(best[key], value)
    return best


def benchmark_clock(request):
    """The clock pytest-benchmark times with (``--benchmark-timer``; ``time.perf_counter`` by default), so that a
    benchmark's stages are in the clock of its statistics."""
    name = request.config.getoption("benchmark_timer", None)
    if not name:
        return time.perf_counter
    module, _, attr = str(name).rpartition(".")
    return getattr(importlib.import_module(module or "time"), attr)


def benchmark_frames(benchmark, frame, poses, warmup: int, rounds: int, clock=time.perf_counter,
                     more_stages=None) -> dict:
    """``warmup`` untimed frames (upload + detect) at the first poses, then ``rounds`` frames at the next ones,
    each timed by pytest-benchmark (``benchmark.pedantic``). Returns the stages of the fastest frame
    (``frame_stages``, plus what ``more_stages(frame, detect seconds)`` adds, e.g. a split of detect) as
    ``stage_<name>``, and ``detection_min``: the fastest detect + read on its own (a peer whose upload dominates
    its frame, pybullet's loop of resets, has its fastest frame chosen by the upload's noise)."""
    for centers, quats in poses[:warmup]:
        frame.upload(centers, quats)
        frame.detect()
    todo = iter(poses[warmup:])
    fastest: dict = {}
    detection = []

    def one_frame():
        times = frame_stages(frame, *next(todo), clock)
        detection.append(times["detect"] + times["read"])
        if more_stages is not None:
            times.update(more_stages(frame, times["detect"]))
        if times["frame"] < fastest.get("frame", np.inf):  # the stages of the fastest frame, which add up to it
            fastest.clear()
            fastest.update(times)

    benchmark.pedantic(one_frame, rounds=rounds, iterations=1, warmup_rounds=0)
    return {**{f"stage_{k}": v for k, v in fastest.items()}, "detection_min": min(detection)}


# ---------------------------------------------------------------------------------------------------------------
# the exact depth: distance from the origin to the boundary of the Minkowski difference
# ---------------------------------------------------------------------------------------------------------------

def core_points(shape, center, rotation) -> np.ndarray:
    """World points (m, 3) of a shape's core at a pose (its radius sweeps them)."""
    return center + shape.local @ rotation.T


def exact_depth(shape_a, pose_a, shape_b, pose_b) -> float:
    """Penetration depth (> 0 overlapping, <= 0 apart: minus the distance) of two bodies at their poses
    ``(center (3,), quaternion (4,) wxyz)``; a ``Plane`` as ``shape_b`` with ``pose_b`` None.

    Cores whose Minkowski difference has a volume: Qhull's facets of {a − b}; the depth is the smallest facet
    offset (the origin's distance to the boundary) plus the radii. Flat differences (point or segment cores):
    the distance of the cores by GJK, subtracted from the radii."""
    from scipy.spatial import ConvexHull

    from engine import gjk_distance

    pa = core_points(shape_a, pose_a[0], quaternion_matrices(pose_a[1][None])[0])
    radius = shape_a.radius
    if isinstance(shape_b, Plane):
        return float(shape_b.altitude - (pa[:, 1].min() - radius))
    pb = core_points(shape_b, pose_b[0], quaternion_matrices(pose_b[1][None])[0])
    radius += shape_b.radius
    dist, _, _ = gjk_distance(pa, pb)
    if dist > 0.0 or isinstance(shape_a, Sphere | Capsule) and isinstance(shape_b, Sphere | Capsule):
        return float(radius - dist)
    diff = (pa[:, None, :] - pb[None, :, :]).reshape(-1, 3)
    hull = ConvexHull(diff)
    # facet planes n·x + c <= 0 inside; the origin is inside, at distance -c from each facet
    return float(np.min(-hull.equations[:, 3]) + radius)


__all__ = ["WorldFrame", "MuJoCoFreeBodyFrame", "BulletMultiBodyFrame", "EngineFrame", "MuJoCoFrame", "BulletFrame",
           "frame_peers", "frame_stages", "time_stages", "benchmark_clock", "benchmark_frames", "exact_depth",
           "core_points", "MUJOCO_MAX_BODIES", "agreement", "disagreements", "AGREEMENT_BAND"]


#: pairs penetrating by less than this (bodies of size ~1) may be found by one engine only: round-off and the
#: peers' collision margins (Bullet's box margin puts its depths up to ~1e-3 off), as in
#: properties/test_world_peers.py
AGREEMENT_BAND = 5e-3


def disagreements(reference, peer, band: float = AGREEMENT_BAND) -> list:
    """The pairs of two ``penetrating()`` answers that one finds deeper than ``band`` and the other misses:
    ``[(i, j, depth, "reference" or "peer"), ...]`` (empty when the pair sets agree outside the band)."""
    ref = dict(zip(map(tuple, reference[0].tolist()), reference[1].tolist()))
    other = dict(zip(map(tuple, peer[0].tolist()), peer[1].tolist()))
    return ([(*p, d, "reference") for p, d in ref.items() if d > band and p not in other]
            + [(*p, d, "peer") for p, d in other.items() if d > band and p not in ref])


def agreement(reference, peer) -> dict:
    """Pair sets and depths of two ``penetrating()`` answers ``(pairs, depth)``: counts of the pairs both find,
    only the reference finds, only the peer finds, and the median / max |depth difference| on the common pairs."""
    ref = {tuple(p): d for p, d in zip(reference[0].tolist(), reference[1].tolist())}
    other = {tuple(p): d for p, d in zip(peer[0].tolist(), peer[1].tolist())}
    common = sorted(set(ref) & set(other))
    diff = np.array([abs(ref[p] - other[p]) for p in common]) if common else np.zeros(1)
    return {"common": len(common), "reference_only": len(set(ref) - set(other)),
            "peer_only": len(set(other) - set(ref)), "depth_diff_median": float(np.median(diff)),
            "depth_diff_max": float(diff.max())}
