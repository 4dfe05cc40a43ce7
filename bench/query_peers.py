"""The scene queries of the query benchmarks (bench/test_bench_queries.py, bench/report_queries.py): workloads and
peers, each engine driven the way its users drive it.

The scene: ``query_scene(n)`` — the "mixed" frame scene of the World benchmark (``engine.workloads.frame_scene``:
half spheres r = 0.5, half boxes of half extents 0.4 with random rotations, uniform in a cube at solid fraction
0.06) with a ground ``Plane`` at y = 0, the bottom of the cube: body i is index i, the ground index n. The peers
are built by bench/world_peers.py's frames (the same models as the frame benchmark).

Workloads (seeded, fixed batches):
- ``random_rays(scene)`` — ``RAYS`` rays, origins uniform in the scene's box, directions uniform on the sphere,
  ``max_distance`` the scene's size (the cube's side);
- ``lidar_fan(scene)`` — 360 × 32 rays from one point near the centre of the scene (outside every body), azimuth
  every degree, elevation −15°..+15° (y up), the same ``max_distance``;
- ``shape_casts(scene, kind)`` — ``CASTS`` sweeps of a sphere (r = 0.3) or a box (half extents 0.3, 0.2, 0.1,
  randomly turned) from a point uniform in the scene's box by a random displacement of length up to the scene's
  size / 4.

Peers, each with ``cast(rays)`` (the timed call, the engine's own output) and ``answer(rays, raw)`` (that output
as ``(body, distance, normal)`` arrays: body −1 and distance inf for a miss):
- ``WorldRays`` — ``World.cast_rays(origins, directions, max_distance)`` (broad phase "tree", "sap" or "grid",
  one thread);
- ``BulletRays`` — pybullet ``rayTestBatch(from, to, numThreads=1)`` in DIRECT mode; a batch is cut into pieces
  of at most ``BULLET_BATCH`` = 16,383 rays (pybullet 3.2.7 answers a batch of 16,384 with 16,383 results,
  dropping the last ray without a word, and refuses a larger one); ``hitFraction`` is relative to the segment
  from → to: distance = fraction × max_distance. A ray that starts inside a box does not report that box (the
  ray goes on to the next body); inside a sphere it is reported at distance 0 or not, depending on the ray;
- ``MuJoCoRays`` — ``mj_multiRay`` for a fan (one origin ``pnt``, many unit ``vec``, ``cutoff`` =
  max_distance), an ``mj_ray`` loop for rays of many origins (``flg_static=1`` so the ground, a geom of the world
  body, is seen; ``geomgroup=None``, ``bodyexclude=-1``). Distances are along ``vec`` (unit here), −1 a miss; a
  ray that starts inside a geom reports where it leaves it. MuJoCo 3.3+ gives the normals.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from bench.world_peers import MUJOCO_MAX_BODIES, BulletFrame, EngineFrame, MuJoCoFrame
from engine.workloads import SEED, FrameScene, frame_scene, random_quaternions
from engine.world import Box, Sphere

#: rays of the random-ray batch, shape casts per batch
RAYS = 10_000
CASTS = 1_000
#: the lidar fan: azimuths × elevations, elevation range (degrees)
FAN_AZIMUTHS = 360
FAN_ELEVATIONS = 32
FAN_ELEVATION_RANGE = (-15.0, 15.0)
#: pybullet's largest whole batch: rayTestBatch answers 16,384 rays with 16,383 results (the last one dropped
#: without a word) and raises for more, so the batches are cut into pieces of at most this many rays
BULLET_BATCH = 16_383
#: sphere radius and box half extents of the shape casts
CAST_SPHERE_RADIUS = 0.3
CAST_BOX_HALF = (0.3, 0.2, 0.1)


class Rays(NamedTuple):
    """A batch of rays: origins (k, 3) (all equal for a fan), unit directions (k, 3), the segment length, and the
    fan's single origin (None for rays of many origins)."""

    origins: np.ndarray
    directions: np.ndarray
    max_distance: float
    origin: np.ndarray | None = None


def query_scene(n: int, seed: int = SEED) -> FrameScene:
    """The mixed frame scene of n bodies with the ground Plane(0) under it (this module's summary)."""
    return frame_scene("mixed", n, seed)._replace(ground=0.0)


def scene_box(scene: FrameScene) -> tuple[np.ndarray, np.ndarray]:
    """The box of the bodies' centres (lo, hi): the cube the scene was drawn in."""
    return scene.centers.min(axis=0), scene.centers.max(axis=0)


def scene_size(scene: FrameScene) -> float:
    """The scene's size: the side of its cube (the largest extent of its centres)."""
    lo, hi = scene_box(scene)
    return float((hi - lo).max())


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def random_rays(scene: FrameScene, count: int = RAYS, seed: int = 11) -> Rays:
    """``count`` rays, origins uniform in the scene's box, directions uniform, max_distance the scene's size."""
    rng = np.random.default_rng(seed)
    lo, hi = scene_box(scene)
    return Rays(rng.uniform(lo, hi, (count, 3)), _unit(rng.normal(size=(count, 3))), scene_size(scene))


def _outside_every_body(scene: FrameScene, point: np.ndarray, clearance: float = 0.05) -> bool:
    """True when ``point`` is farther than ``clearance`` from every body's bounding sphere."""
    bound = np.array([s.radius if isinstance(s, Sphere) else float(np.linalg.norm(s.half_extents))
                      for s in scene.shapes])
    return bool((np.linalg.norm(scene.centers - point, axis=1) > bound + clearance).all())


def fan_origin(scene: FrameScene, seed: int = 12) -> np.ndarray:
    """A point near the centre of the scene, outside every body (the first of a seeded sequence of points ever
    farther from the centre)."""
    lo, hi = scene_box(scene)
    centre = 0.5 * (lo + hi)
    rng = np.random.default_rng(seed)
    for step in range(10_000):
        point = centre + 0.01 * step * rng.normal(size=3)
        if _outside_every_body(scene, point):
            return point
    raise ValueError("no free point found near the scene's centre")


def lidar_fan(scene: FrameScene, azimuths: int = FAN_AZIMUTHS, elevations: int = FAN_ELEVATIONS,
              elevation_range: tuple[float, float] = FAN_ELEVATION_RANGE) -> Rays:
    """A lidar's fan from ``fan_origin``: ``azimuths`` × ``elevations`` unit directions (y up), ordered by
    elevation then azimuth."""
    origin = fan_origin(scene)
    az = np.radians(np.arange(azimuths) * 360.0 / azimuths)
    el = np.radians(np.linspace(*elevation_range, elevations))
    e, a = np.meshgrid(el, az, indexing="ij")
    dirs = np.stack([np.cos(e) * np.cos(a), np.sin(e), np.cos(e) * np.sin(a)], axis=-1).reshape(-1, 3)
    return Rays(np.broadcast_to(origin, dirs.shape).copy(), dirs, scene_size(scene), origin)


class ShapeCasts(NamedTuple):
    """A batch of shape casts: the shapes (each at its start pose) and their displacements (k, 3)."""

    kind: str
    shapes: list
    displacements: np.ndarray


def shape_casts(scene: FrameScene, kind: str, count: int = CASTS, seed: int = 13) -> ShapeCasts:
    """``count`` casts of a sphere (r = 0.3) or a randomly turned box from points uniform in the scene's box, by
    displacements of random direction and length uniform in [0, size / 4]."""
    rng = np.random.default_rng(seed)
    lo, hi = scene_box(scene)
    starts = rng.uniform(lo, hi, (count, 3))
    disp = _unit(rng.normal(size=(count, 3))) * rng.uniform(0.0, scene_size(scene) / 4, (count, 1))
    if kind == "sphere":
        shapes = [Sphere(c, CAST_SPHERE_RADIUS) for c in starts]
    elif kind == "box":
        shapes = [Box(c, CAST_BOX_HALF, q) for c, q in zip(starts, random_quaternions(count, rng))]
    else:
        raise ValueError(f"kind must be 'sphere' or 'box', got {kind!r}")
    return ShapeCasts(kind, shapes, disp)


# ---------------------------------------------------------------------------------------------------------------
# the peers
# ---------------------------------------------------------------------------------------------------------------

class WorldRays:
    """The engine's World on a scene (bench/world_peers.EngineFrame: body i is id i, the ground id n)."""

    def __init__(self, scene: FrameScene, broad_phase: str = "tree"):
        self.name = f"World {broad_phase}"
        self.world = EngineFrame(scene, broad_phase, threads=1).world

    def cast(self, rays: Rays):
        return self.world.cast_rays(rays.origins, rays.directions, rays.max_distance)

    def answer(self, rays: Rays, raw):
        return np.asarray(raw.body), np.asarray(raw.distance), np.asarray(raw.normal)

    def cast_shapes(self, casts: ShapeCasts) -> list:
        """Each cast's ``ShapeHit`` or None; a cast that raises gives its exception instead (counted and shown
        by the report rather than stopping the batch)."""
        cast = self.world.cast_shape
        out = []
        for s, d in zip(casts.shapes, casts.displacements):
            try:
                out.append(cast(s, d))
            except RuntimeError as error:
                out.append(error)
        return out


class BulletRays:
    """pybullet (DIRECT) on a scene, as bench/world_peers.BulletFrame builds it."""

    name = "pybullet"

    def __init__(self, scene: FrameScene):
        self.frame = BulletFrame(scene)
        self.frame.detect()  # the broad phase's boxes at the scene's poses (rays traverse them)
        self.p = self.frame.p
        lookup = np.full(max(self.frame.index) + 2, -1, np.int64)
        for unique_id, index in self.frame.index.items():
            lookup[unique_id] = index
        self.lookup = lookup  # pybullet's body unique id -> scene index; lookup[-1] = -1 (a miss)
        self._segments: dict = {}

    def _segments_of(self, rays: Rays):
        """The from / to lists of each batch piece (prepared once per batch, outside the timing)."""
        key = id(rays)
        if key not in self._segments:
            to = rays.origins + rays.max_distance * rays.directions
            self._segments[key] = [(rays.origins[s:s + BULLET_BATCH].tolist(), to[s:s + BULLET_BATCH].tolist())
                                   for s in range(0, len(to), BULLET_BATCH)]
        return self._segments[key]

    def cast(self, rays: Rays):
        test, client = self.p.rayTestBatch, self.frame.client
        out = []
        for start, end in self._segments_of(rays):
            out.extend(test(start, end, numThreads=1, physicsClientId=client))
        return out

    def answer(self, rays: Rays, raw):
        uid = np.array([r[0] for r in raw], np.int64)
        fraction = np.array([r[2] for r in raw])
        body = self.lookup[uid]
        distance = np.where(body >= 0, fraction * rays.max_distance, np.inf)
        normal = np.where((body >= 0)[:, None], np.array([r[4] for r in raw], float).reshape(-1, 3), np.nan)
        return body, distance, normal

    def close(self):
        self.frame.close()


class MuJoCoRays:
    """MuJoCo on a scene, as bench/world_peers.MuJoCoFrame builds it (``mj_kinematics`` once: the geoms' poses)."""

    name = "MuJoCo"

    def __init__(self, scene: FrameScene):
        if len(scene.shapes) > MUJOCO_MAX_BODIES:
            raise ValueError(f"MuJoCo's model reserves 4 n^2 bytes: n <= {MUJOCO_MAX_BODIES}")
        self.frame = MuJoCoFrame(scene)
        self.mujoco, self.model, self.data = self.frame.mujoco, self.frame.model, self.frame.data
        self.mujoco.mj_kinematics(self.model, self.data)
        self.geom_body = np.append(self.frame.geom_body, -1)  # geom id -> scene index; [-1] = -1 (a miss)

    def cast(self, rays: Rays):
        """A fan: one ``mj_multiRay``; rays of many origins: an ``mj_ray`` loop."""
        if rays.origin is not None:
            return self.multi_ray(rays)
        return self.ray_loop(rays)

    def multi_ray(self, rays: Rays):
        k = len(rays.directions)
        geom, dist, normal = np.empty(k, np.int32), np.empty(k), np.empty((k, 3))
        self.mujoco.mj_multiRay(self.model, self.data, rays.origin, rays.directions.ravel(), None, 1, -1, geom,
                                dist, normal.ravel(), k, rays.max_distance)
        return geom, dist, normal

    def ray_loop(self, rays: Rays):
        k = len(rays.directions)
        geom, dist, normal = np.empty(k, np.int32), np.empty(k), np.empty((k, 3))
        ray, model, data = self.mujoco.mj_ray, self.model, self.data
        gid = np.empty(1, np.int32)
        for i, (pnt, vec) in enumerate(zip(rays.origins, rays.directions)):
            dist[i] = ray(model, data, pnt, vec, None, 1, -1, gid, normal[i])
            geom[i] = gid[0]
        return geom, dist, normal

    def answer(self, rays: Rays, raw):
        geom, dist, normal = raw
        # mj_ray has no cutoff: a hit beyond max_distance is a miss of the segment
        hit = (geom >= 0) & (dist >= 0.0) & (dist <= rays.max_distance)
        body = np.where(hit, self.geom_body[geom], -1)
        return body, np.where(hit, dist, np.inf), np.where(hit[:, None], normal, np.nan)


def ray_peer(name: str, scene: FrameScene):
    """The peer called ``name``: "World tree" / "World sap" / "World grid", "pybullet", "MuJoCo"."""
    if name.startswith("World"):
        return WorldRays(scene, name.split()[1])
    return BulletRays(scene) if name == "pybullet" else MuJoCoRays(scene)


#: each engine's answer for a ray that starts inside a body, in bench/ray_reference.py's terms
INSIDE_CONVENTION = {"World": "zero", "pybullet": "skip", "MuJoCo": "exit"}


def inside_convention(peer: str) -> str:
    return INSIDE_CONVENTION[peer.split()[0]]


def rays_per_second(count: int, seconds: float) -> float:
    return count / seconds if seconds > 0 else math.nan


__all__ = ["RAYS", "CASTS", "BULLET_BATCH", "Rays", "ShapeCasts", "query_scene", "scene_box", "scene_size",
           "random_rays", "lidar_fan", "fan_origin", "shape_casts", "WorldRays", "BulletRays", "MuJoCoRays",
           "ray_peer", "INSIDE_CONVENTION", "inside_convention", "rays_per_second"]
