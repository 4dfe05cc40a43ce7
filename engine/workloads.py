"""The standard workloads of the benchmarks and of the properties that check the benchmarks' claims.

Every generator is deterministic (a seed in, the same arrays out), so a figure in ``reports/`` can be reproduced
with the same call:

- ``w1_boxes(n)`` — Terdiman's box-pruning benchmark: n AABBs, centres integers uniform in [−2048, 2048)³,
  half extents integers uniform in [0, 127] (about 11.8k overlapping pairs at n = 10,000);
- ``w2_spheres(n, eta)`` — n equal spheres uniform in a cube at packing fraction ``eta`` (sphere volume over the
  cube's volume);
- ``mixed_world_scene(n)`` — n bodies for ``World``: spheres, rotated boxes and convex hulls uniform in a cube;
- ``random_steps(centers, rounds)`` — the per-frame motion: each body moves by a small random step every frame;
- the frame scenes of the World benchmark (``frame_scene(name, n)``, one ``FrameScene`` each): ``"mixed"`` — half
  spheres (r = 0.5), half boxes (half extents 0.4) with random rotations, uniform in a cube at solid fraction
  0.06; ``"pile"`` — boxes and spheres resting on the ground ``Plane(0)`` in a loose lattice of columns, every
  body pressing 0.002 into the one below; ``"hulls"`` — half capsules (r = 0.25, segment 0.6), half convex hulls of
  12 vertices (radius ~0.5), uniform at solid fraction 0.06. ``frame_motion(scene, rounds)`` gives each frame's
  poses;
- ``static_level(n_static, n_moving)`` — a game level of ``n_static`` static boxes (floor slabs, walls, pillars,
  crates on a grid of cells) and the "mixed" scene's bodies moving in it, most touching it: a ``FrameScene`` and
  a ``StaticBoxes``;
- ``category_masks(n)`` — the collision filter of the masked benchmark: four categories round-robin, masks that
  let 5 of the 10 unordered category pairs collide (``COLLIDING_CATEGORY_PAIRS``).

The big-level scenes, where a grid whose cell count is capped would coarsen until one cell holds a whole cluster
(the quadratic cliff the broad-phase benchmarks watch for):

- ``clustered_spheres(n, eta, clusters, separation)`` — ``clusters`` dense W2 clusters ``separation`` apart;
- ``huge_among_small_boxes(n, huge)`` — the boxes of W2 spheres plus ``huge`` boxes each as large as half the
  scene;
- ``planar_spheres(n, area_fraction)`` — equal spheres whose centres all lie on one plane (z = 0).

Shared arguments: ``seed`` (an int) seeds numpy's ``default_rng`` (``SEED`` by default for the W1/W2 family);
the sphere generators take ``radius`` (0.5 by default) and return ``(centres, radius)`` — centres (n, 3)
float64 and the ``radius`` given.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["SEED", "w1_boxes", "w2_spheres", "mixed_world_scene", "random_steps", "clustered_spheres",
           "huge_among_small_boxes", "planar_spheres", "BIG_LEVEL_SCENES", "big_level_boxes", "FrameScene",
           "FRAME_SCENES", "frame_scene", "frame_motion", "random_quaternions", "quaternion_matrices",
           "StaticBoxes", "LEVEL_CELL", "LEVEL_SLAB", "LEVEL_ROLES", "LEVEL_ITEM_CHANCES", "static_level",
           "CATEGORY_MASKS", "COLLIDING_CATEGORY_PAIRS", "MASKED_CATEGORY_PAIRS", "category_masks"]

#: the seed of every benchmark workload
SEED = 4


def w1_boxes(n: int, seed: int = SEED) -> tuple[np.ndarray, np.ndarray]:
    """Terdiman's box-pruning workload: n boxes with integer centres and half extents.

    Parameters
    ----------
    n : int
        The number of boxes.

    Returns
    -------
    lo, hi : numpy.ndarray, shape (n, 3), float64
        The boxes' corners, integer-valued: centres uniform in [-2048, 2048)³, half extents uniform in [0, 127].
    """
    rng = np.random.default_rng(seed)
    centre = rng.integers(-2048, 2048, size=(n, 3)).astype(float)
    half = rng.integers(0, 128, size=(n, 3)).astype(float)
    return centre - half, centre + half


def w2_spheres(n: int, eta: float, seed: int = SEED, radius: float = 0.5) -> tuple[np.ndarray, float]:
    """n equal spheres uniform in a cube at packing fraction ``eta``.

    Parameters
    ----------
    n : int
        The number of spheres.
    eta : float
        The packing fraction, > 0: the spheres' volume over the cube's.

    Returns
    -------
    centres : numpy.ndarray, shape (n, 3), float64
        Uniform in the cube [0, side)³.
    """
    side = (n * math.pi * (2 * radius) ** 3 / (6 * eta)) ** (1 / 3)
    return np.random.default_rng(seed).uniform(0.0, side, size=(n, 3)), radius


def mixed_world_scene(n: int, seed: int = 8) -> tuple[list, np.ndarray, np.ndarray]:
    """n bodies for ``World``: spheres, rotated boxes and convex hulls uniform in a cube.

    40 % spheres (r in [0.3, 0.7]), 30 % rotated boxes (half extents in [0.2, 0.6]), 30 % convex hulls of 12–20
    random points (radius ~0.5), at a bounding-sphere packing fraction of about 0.1.

    Parameters
    ----------
    n : int
        The number of bodies.
    seed : int, optional
        The seed of the random generator (and of the rotations).

    Returns
    -------
    shapes : list of Shape, length n
        ``Sphere``, ``Box`` and ``ConvexPolyhedron`` objects placed in the world.
    centers : numpy.ndarray, shape (n, 3), float64
        The bodies' centres.
    rotations : numpy.ndarray, shape (n, 3, 3), float64
        Uniformly random rotation matrices (used by the boxes).
    """
    from scipy.spatial.transform import Rotation

    from engine.world import Box, ConvexPolyhedron, Sphere
    from engine.world.shapes import Shape

    rng = np.random.default_rng(seed)
    kinds = rng.choice(3, size=n, p=[0.4, 0.3, 0.3])
    mean_volume = 4 / 3 * np.pi * 0.6 ** 3
    side = (n * mean_volume / 0.1) ** (1 / 3)
    centers = rng.uniform(0.0, side, size=(n, 3))
    rotations = Rotation.random(n, random_state=seed).as_matrix()
    shapes: list[Shape] = []
    for i in range(n):
        if kinds[i] == 0:
            shapes.append(Sphere(centers[i], rng.uniform(0.3, 0.7)))
        elif kinds[i] == 1:
            shapes.append(Box(centers[i], rng.uniform(0.2, 0.6, 3), rotations[i]))
        else:
            pts = rng.normal(size=(int(rng.integers(12, 21)), 3))
            pts *= 0.5 / np.linalg.norm(pts, axis=1, keepdims=True).max()
            shapes.append(ConvexPolyhedron(centers[i] + pts))
    return shapes, centers, rotations


def random_steps(centers: ArrayLike, rounds: int, step: float = 0.02, seed: int = 9) -> list[np.ndarray]:
    """The per-frame motion: each frame every centre moves by a normal step of scale ``step``.

    Parameters
    ----------
    centers : array_like, shape (n, 3)
        The starting centres; never modified.
    rounds : int
        The number of frames.
    step : float, optional
        The standard deviation of each coordinate's step.

    Returns
    -------
    list of numpy.ndarray, each shape (n, 3), float64
        ``rounds`` successive centre arrays, each the previous one moved.
    """
    rng = np.random.default_rng(seed)
    out, c = [], np.asarray(centers, dtype=float)
    for _ in range(rounds):
        c = c + rng.normal(0.0, step, c.shape)
        out.append(c)
    return out


def clustered_spheres(n: int, eta: float = 0.2, clusters: int = 2, separation: float = 1e6, seed: int = SEED,
                      radius: float = 0.5) -> tuple[np.ndarray, float]:
    """n equal spheres in ``clusters`` dense clusters far apart.

    Cluster k is a W2 cube of about n / clusters spheres at packing fraction ``eta``, shifted by k·separation
    along every axis.

    Parameters
    ----------
    n : int
        The number of spheres.
    eta : float, optional
        The packing fraction of each cluster, > 0.
    clusters : int, optional
        The number of clusters, >= 1.
    separation : float, optional
        The shift between consecutive clusters along every axis.

    Returns
    -------
    centres : numpy.ndarray, shape (n, 3), float64
        Cluster by cluster.
    """
    rng = np.random.default_rng(seed)
    sizes = [n // clusters + (1 if k < n % clusters else 0) for k in range(clusters)]
    parts = []
    for k, m in enumerate(sizes):
        side = (max(m, 1) * math.pi * (2 * radius) ** 3 / (6 * eta)) ** (1 / 3)
        parts.append(rng.uniform(0.0, side, size=(m, 3)) + k * separation)
    return np.concatenate(parts), radius


def huge_among_small_boxes(n: int, huge: int = 8, eta: float = 0.05, seed: int = SEED) -> tuple[np.ndarray, np.ndarray]:
    """The boxes of n − huge W2 spheres and ``huge`` boxes each spanning half the scene.

    Parameters
    ----------
    n : int
        The number of boxes in all.
    huge : int, optional
        How many of them are huge (at most n are made): each spans half the scene along every axis, at a random
        place in it.
    eta : float, optional
        The packing fraction of the small spheres (radius 0.5), > 0.

    Returns
    -------
    lo, hi : numpy.ndarray, shape (n, 3), float64
        The boxes' corners, the small ones first.
    """
    small = max(n - huge, 0)
    centres, radius = w2_spheres(small, eta, seed)
    side = (max(small, 1) * math.pi / (6 * eta)) ** (1 / 3)
    rng = np.random.default_rng(seed + 1)
    corner = rng.uniform(0.0, side / 2, size=(n - small, 3))
    lo = np.concatenate([centres - radius, corner])
    hi = np.concatenate([centres + radius, corner + side / 2])
    return lo, hi


def planar_spheres(n: int, area_fraction: float = 0.3, seed: int = SEED,
                   radius: float = 0.5) -> tuple[np.ndarray, float]:
    """n equal spheres whose centres all lie in one square of the plane z = 0.

    Parameters
    ----------
    n : int
        The number of spheres.
    area_fraction : float, optional
        The fraction of the square the spheres' discs cover, > 0.

    Returns
    -------
    centres : numpy.ndarray, shape (n, 3), float64
        Uniform in the square, z = 0.
    """
    side = math.sqrt(n * math.pi * radius ** 2 / area_fraction)
    centres = np.zeros((n, 3))
    centres[:, :2] = np.random.default_rng(seed).uniform(0.0, side, size=(n, 2))
    return centres, radius


#: the scenes of ``big_level_boxes``: the uniform W2 cube and the three big-level scenes
BIG_LEVEL_SCENES = ("uniform", "clusters", "huge", "plane")


def big_level_boxes(scene: str, n: int, seed: int = SEED) -> tuple[np.ndarray, np.ndarray]:
    """The boxes of one scene of ``BIG_LEVEL_SCENES``.

    Parameters
    ----------
    scene : str
        "uniform": the boxes of W2 spheres at η = 0.05; "clusters": those of ``clustered_spheres`` (two
        clusters at η = 0.2, 1e6 apart); "huge": ``huge_among_small_boxes`` (8 huge boxes); "plane": those of
        ``planar_spheres`` (area fraction 0.3).
    n : int
        The number of boxes.

    Returns
    -------
    lo, hi : numpy.ndarray, shape (n, 3), float64
        The boxes' corners.

    Raises
    ------
    ValueError
        If ``scene`` is not one of ``BIG_LEVEL_SCENES``.
    """
    if scene == "huge":
        return huge_among_small_boxes(n, seed=seed)
    if scene == "uniform":
        centres, radius = w2_spheres(n, 0.05, seed)
    elif scene == "clusters":
        centres, radius = clustered_spheres(n, seed=seed)
    elif scene == "plane":
        centres, radius = planar_spheres(n, seed=seed)
    else:
        raise ValueError(f"scene must be one of {BIG_LEVEL_SCENES}, got {scene!r}")
    return centres - radius, centres + radius


# ---------------------------------------------------------------------------------------------------------------
# the frame scenes of the World benchmark
# ---------------------------------------------------------------------------------------------------------------

class FrameScene(NamedTuple):
    """A scene of the frame benchmark.

    Attributes
    ----------
    name : str
        One of ``FRAME_SCENES``.
    shapes : list of Shape, length n
        The engine shapes, each built in its body frame at the origin (Sphere, Box with no rotation, Capsule
        along the body's z axis, ConvexPolyhedron centred on the mean of its vertices).
    centers : numpy.ndarray, shape (n, 3), float64
        The bodies' centres: body i sits at ``centers[i]``, turned by ``quaternions[i]``.
    quaternions : numpy.ndarray, shape (n, 4), float64
        The bodies' orientations, unit quaternions in (w, x, y, z) order.
    ground : float or None
        The altitude of a ``Plane`` (y <= ground is solid), or None for no ground.
    step, turn : float
        The scale of each frame's random translation (a length) and rotation (radians).
    """

    name: str
    shapes: list
    centers: np.ndarray
    quaternions: np.ndarray
    ground: float | None
    step: float
    turn: float


def random_quaternions(n: int, rng: np.random.Generator) -> np.ndarray:
    """n uniformly random unit quaternions (Shoemake: normalised 4-D normal samples).

    Parameters
    ----------
    n : int
        The number of quaternions.
    rng : numpy.random.Generator
        The random generator (advanced by the call).

    Returns
    -------
    numpy.ndarray, shape (n, 4), float64
        Unit quaternions in (w, x, y, z) order, w >= 0.
    """
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    return q * np.where(q[:, :1] < 0, -1.0, 1.0)


def quaternion_matrices(q: ArrayLike) -> np.ndarray:
    """The rotation matrices of unit quaternions.

    Parameters
    ----------
    q : array_like, shape (n, 4)
        Unit quaternions in (w, x, y, z) order.

    Returns
    -------
    numpy.ndarray, shape (n, 3, 3), float64
        The rotation matrices; their columns are the body axes.
    """
    w, x, y, z = np.asarray(q, dtype=float).T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], axis=-1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], axis=-1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=-1),
    ], axis=1)


def _cube_side(n: int, mean_volume: float, fraction: float) -> float:
    return (n * mean_volume / fraction) ** (1 / 3)


def _mixed_scene(n, rng):
    from engine.world import Box, Sphere

    is_box = np.arange(n) % 2 == 1
    side = _cube_side(n, 0.5 * (4 / 3 * math.pi * 0.5 ** 3 + 0.8 ** 3), 0.06)
    shapes = [Box(np.zeros(3), [0.4, 0.4, 0.4]) if b else Sphere(np.zeros(3), 0.5) for b in is_box]
    return shapes, rng.uniform(0.0, side, (n, 3)), random_quaternions(n, rng), None, 0.02, 0.02


#: lattice spacing of the pile (bodies of size 0.8 a little apart sideways) and the press of each body into
#: the one below it (and of the lowest layer into the ground)
PILE_SPACING = 0.84
PILE_PRESS = 0.002


def _pile_scene(n, rng):
    from engine.world import Box, Sphere

    layers = 5
    cols = math.ceil(math.sqrt(n / layers))
    site = np.arange(n)
    col, layer = site % (cols * cols), site // (cols * cols)
    is_box = rng.random(n) < 0.5
    shapes = [Box(np.zeros(3), [0.4, 0.4, 0.4]) if b else Sphere(np.zeros(3), 0.4) for b in is_box]
    jitter = rng.uniform(-0.015, 0.015, (n, 2))
    centers = np.empty((n, 3))
    centers[:, 0] = PILE_SPACING * (col % cols) + jitter[:, 0]
    centers[:, 2] = PILE_SPACING * (col // cols) + jitter[:, 1]
    centers[:, 1] = 0.4 - PILE_PRESS + layer * (0.8 - PILE_PRESS)
    yaw = rng.uniform(-0.01, 0.01, n)  # boxes turned a little about the vertical
    quats = np.stack([np.cos(yaw / 2), np.zeros(n), np.sin(yaw / 2), np.zeros(n)], axis=1)
    return shapes, centers, quats, 0.0, 1e-5, 1e-5


def _hull_scene(n, rng):
    from engine.world import Capsule, ConvexPolyhedron

    is_hull = np.arange(n) % 2 == 1
    variants = []
    for _ in range(16):  # 16 hull shapes, shared by the bodies: 12 points on a sphere of radius 0.5
        pts = rng.normal(size=(12, 3))
        variants.append(ConvexPolyhedron(0.5 * pts / np.linalg.norm(pts, axis=1, keepdims=True)))
    hull_volume = float(np.mean([_hull_volume(v.local) for v in variants]))
    capsule_volume = math.pi * 0.25 ** 2 * 0.6 + 4 / 3 * math.pi * 0.25 ** 3
    side = _cube_side(n, 0.5 * (hull_volume + capsule_volume), 0.06)
    pick = rng.integers(0, 16, n)
    shapes = [variants[pick[i]] if is_hull[i] else Capsule([0.0, 0.0, -0.3], [0.0, 0.0, 0.3], 0.25)
              for i in range(n)]
    return shapes, rng.uniform(0.0, side, (n, 3)), random_quaternions(n, rng), None, 0.02, 0.02


def _hull_volume(points) -> float:
    from engine.bounding.hull import convex_hull

    return float(convex_hull(points).volume)


FRAME_SCENES = {"mixed": _mixed_scene, "pile": _pile_scene, "hulls": _hull_scene}


def frame_scene(name: str, n: int, seed: int = SEED) -> FrameScene:
    """A frame scene of the World benchmark.

    Parameters
    ----------
    name : str
        One of ``FRAME_SCENES``: "mixed", "pile", "hulls" (described in this module's summary).
    n : int
        The number of bodies.

    Returns
    -------
    FrameScene
        The scene with n bodies.

    Raises
    ------
    ValueError
        If ``name`` is not one of ``FRAME_SCENES``.
    """
    if name not in FRAME_SCENES:
        raise ValueError(f"name must be one of {sorted(FRAME_SCENES)}, got {name!r}")
    shapes, centers, quats, ground, step, turn = FRAME_SCENES[name](int(n), np.random.default_rng(seed))
    return FrameScene(name, shapes, centers, quats, ground, step, turn)


def frame_motion(scene: FrameScene, rounds: int, seed: int = 9) -> list[tuple[np.ndarray, np.ndarray]]:
    """The per-frame motion of a frame scene.

    Each frame every body moves by a normal step of scale ``scene.step`` and turns by a random rotation of angle
    ~``scene.turn``.

    Parameters
    ----------
    scene : FrameScene
        The scene; its arrays are never modified.
    rounds : int
        The number of frames.

    Returns
    -------
    list of tuple (numpy.ndarray, numpy.ndarray)
        ``rounds`` successive poses ``(centers, quaternions)``: centres (n, 3) float64 and unit quaternions
        (n, 4) float64 in (w, x, y, z) order.
    """
    rng = np.random.default_rng(seed)
    c = scene.centers.copy()
    q = scene.quaternions.copy()
    out = []
    for _ in range(rounds):
        c = c + rng.normal(0.0, scene.step, c.shape)
        half = 0.5 * rng.normal(0.0, scene.turn, (c.shape[0], 3))
        dq = np.concatenate([np.cos(np.linalg.norm(half, axis=1, keepdims=True)), half], axis=1)
        dq /= np.linalg.norm(dq, axis=1, keepdims=True)
        q = _quaternion_product(dq, q)
        q /= np.linalg.norm(q, axis=1, keepdims=True)
        out.append((c, q))
    return out


def _quaternion_product(a, b):
    aw, ax, ay, az = a.T
    bw, bx, by, bz = b.T
    return np.stack([aw * bw - ax * bx - ay * by - az * bz, aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx, aw * bz + ax * by - ay * bx + az * bw], axis=1)


# ---------------------------------------------------------------------------------------------------------------
# the static level of the World benchmark, and the masked mixed scene
# ---------------------------------------------------------------------------------------------------------------

#: the side of a level cell (a floor tile) in the x–z plane, and the half thickness of the floor slabs
LEVEL_CELL = 4.0
LEVEL_SLAB = 0.25
#: what each static box of a level is, by its ``role`` code
LEVEL_ROLES = ("floor", "wall", "pillar", "crate")
#: the chance that a cell holds a wall, a pillar, a crate (each drawn independently; every cell has a floor)
LEVEL_ITEM_CHANCES = (0.3, 0.3, 0.4)


class StaticBoxes(NamedTuple):
    """The level geometry of a static-level scene: m boxes that never move.

    Attributes
    ----------
    centers : numpy.ndarray, shape (m, 3), float64
        The boxes' centres.
    half_extents : numpy.ndarray, shape (m, 3), float64
        Their half sizes along their own axes.
    quaternions : numpy.ndarray, shape (m, 4), float64
        Their orientations, unit quaternions (w, x, y, z) (turns about the vertical y axis).
    role : numpy.ndarray, shape (m,), int64
        Index into ``LEVEL_ROLES``: floor slab, wall, pillar or crate.
    """

    centers: np.ndarray
    half_extents: np.ndarray
    quaternions: np.ndarray
    role: np.ndarray


def _yaw_quaternion(angle: float) -> list[float]:
    return [math.cos(angle / 2), 0.0, math.sin(angle / 2), 0.0]


def _cell_items(rng, x0: float, z0: float) -> tuple[float, list]:
    """The boxes of the cell whose centre is (x0, z0): (floor top, [(role, centre, half extents, yaw), ...]).
    Every random number of a cell is drawn whatever the items kept, so a cell's layout depends on its rank only."""
    half = LEVEL_CELL / 2
    top = rng.uniform(-0.03, 0.03)  # tiles a little uneven
    u = rng.random(14)
    floor = (0, [x0 + 0.1 * (u[0] - 0.5), top - LEVEL_SLAB, z0 + 0.1 * (u[1] - 0.5)],
             [half - 0.02 - 0.08 * u[2], LEVEL_SLAB, half - 0.02 - 0.08 * u[3]], 0.0)
    items = [floor]
    along_x = u[4] < 0.5  # a wall on the cell's low-z edge (along x) or on its low-x edge (along z)
    length, height = half * (0.5 + 0.5 * u[5]), 0.75 + 0.75 * u[6]
    wall_half = [length, height, 0.15] if along_x else [0.15, height, length]
    wall_at = [x0, top + height, z0 - half + 0.15] if along_x else [x0 - half + 0.15, top + height, z0]
    pillar_half = [0.2 + 0.25 * u[7], 1.0 + u[8], 0.2 + 0.25 * u[7]]
    pillar_at = [x0 + (half - 0.6) * (2 * u[9] - 1), top + pillar_half[1], z0 + (half - 0.6) * (2 * u[10] - 1)]
    crate_half = rng.uniform(0.3, 0.7, 3)
    crate_at = [x0 + (half - 1.0) * (2 * u[11] - 1), top + crate_half[1], z0 + (half - 1.0) * (2 * u[12] - 1)]
    drawn = rng.random(3) < LEVEL_ITEM_CHANCES
    for role, keep, at, size, yaw in ((1, drawn[0], wall_at, wall_half, 0.0),
                                      (2, drawn[1], pillar_at, pillar_half, 0.0),
                                      (3, drawn[2], crate_at, crate_half, math.pi * u[13])):
        if keep:
            items.append((role, at, size, yaw))
    return top, items


def _level_boxes(n_static: int, rng) -> tuple[StaticBoxes, np.ndarray]:
    """n_static boxes, cell after cell in rows of ``cols`` cells, and the (x, z, floor top) of each cell used."""
    cols = max(1, math.ceil(math.sqrt(n_static / (1 + sum(LEVEL_ITEM_CHANCES)))))
    rows: list[tuple] = []
    cells: list[tuple] = []
    while len(rows) < n_static:
        k = len(cells)
        x0, z0 = LEVEL_CELL * (k % cols), LEVEL_CELL * (k // cols)
        top, items = _cell_items(rng, x0, z0)
        cells.append((x0, z0, top))
        rows.extend(items[: n_static - len(rows)])
    role = np.array([r[0] for r in rows], np.int64)
    centers = np.array([r[1] for r in rows], float)
    half = np.array([r[2] for r in rows], float)
    quats = np.array([_yaw_quaternion(r[3]) for r in rows], float)
    return StaticBoxes(centers, half, quats, role), np.array(cells)


def static_level(n_static: int = 5_000, n_moving: int = 500, seed: int = SEED,
                 resting: float = 0.6) -> tuple[FrameScene, StaticBoxes]:
    """A game level of static boxes and the bodies moving in it (the World benchmark's "static level").

    The level is a square grid of cells of side ``LEVEL_CELL`` in the x–z plane (y up), filled cell by cell
    (rows of ``ceil(sqrt(n_static / 2))`` cells) until it holds ``n_static`` boxes: every cell has a floor slab
    (half thickness ``LEVEL_SLAB``, a few cm smaller than the cell, its top at a random height in ±0.03) and,
    each drawn independently (``LEVEL_ITEM_CHANCES``), a wall along one of its edges (0.3 thick, 1.5–3 high),
    a pillar (square, 0.4–0.9 wide, 2–4 high) and a crate (sides 0.6–1.4, turned by a random yaw), all standing
    on the floor: two boxes per cell on average, of sizes from 0.3 to 4.

    The moving bodies are those of the "mixed" frame scene — alternately spheres (r = 0.5) and boxes (half
    extents 0.4), random rotations, each frame a random step of 0.02 and turn of 0.02 (``frame_motion``) — each
    over a random cell's floor: a share ``resting`` of them pressing into the floor by 0–0.1 (they touch it),
    the others 0.2–2.5 above it, among the walls, pillars and crates (they touch those they overlap).

    Parameters
    ----------
    n_static : int, optional
        The number of static boxes.
    n_moving : int, optional
        The number of moving bodies.
    seed : int, optional
        The seed of the layout, the placements and the rotations.
    resting : float, optional
        The share of the moving bodies placed pressing into the floor, in [0, 1].

    Returns
    -------
    scene : FrameScene
        The moving bodies, named "level", without a ground Plane (the floors are boxes).
    level : StaticBoxes
        The static boxes.
    """
    from engine.world import Box, Sphere

    rng = np.random.default_rng(seed)
    level, cells = _level_boxes(int(n_static), rng)
    n = int(n_moving)
    is_box = np.arange(n) % 2 == 1
    shapes = [Box(np.zeros(3), [0.4, 0.4, 0.4]) if b else Sphere(np.zeros(3), 0.5) for b in is_box]
    quats = random_quaternions(n, rng)
    # the half height of each body: its support along y (a box's: Σ_k |R[1, k]| h_k)
    reach = np.where(is_box, 0.4 * np.abs(quaternion_matrices(quats)[:, 1, :]).sum(axis=1), 0.5)
    cell = cells[rng.integers(0, cells.shape[0], n)]
    spread = LEVEL_CELL / 2 - 0.3
    lift = np.where(rng.random(n) < resting, -rng.uniform(0.0, 0.1, n), rng.uniform(0.2, 2.5, n))
    centers = np.stack([cell[:, 0] + rng.uniform(-spread, spread, n), cell[:, 2] + reach + lift,
                        cell[:, 1] + rng.uniform(-spread, spread, n)], axis=1)
    return FrameScene("level", shapes, centers, quats, None, 0.02, 0.02), level


#: the masked mixed scene: categories 0–3 (bits 1, 2, 4, 8) are assigned to the bodies round-robin; the mask of
#: category c is ``CATEGORY_MASKS[c]``: 0 collides with every category, 1 with 0 and 1, 2 and 3 with 0 only
CATEGORY_MASKS = (0b1111, 0b0011, 0b0001, 0b0001)
#: the 5 unordered category pairs CATEGORY_MASKS lets collide, and the 5 it masks off (of the 10)
COLLIDING_CATEGORY_PAIRS = ((0, 0), (0, 1), (0, 2), (0, 3), (1, 1))
MASKED_CATEGORY_PAIRS = ((1, 2), (1, 3), (2, 2), (2, 3), (3, 3))


def category_masks(n: int) -> tuple[np.ndarray, np.ndarray]:
    """The collision filter of the masked benchmark: body i in category ``i % 4``, with that category's mask.

    ``CATEGORY_MASKS`` is symmetric (category a's mask holds b iff b's mask holds a), so that
    ``category_i & mask_j`` and ``category_j & mask_i`` are both non-zero or both zero: Box2D's and pybullet's
    rule (both non-zero) and MuJoCo's (``contype_i & conaffinity_j`` or ``contype_j & conaffinity_i``, with
    contype = category and conaffinity = mask) give the same pair sets. Of the 10 unordered category pairs, the
    5 of ``COLLIDING_CATEGORY_PAIRS`` collide; with the categories equally frequent, 8 of the 16 ordered
    category pairs collide, so half of the body pairs are masked off.

    Parameters
    ----------
    n : int
        The number of bodies.

    Returns
    -------
    category, mask : numpy.ndarray, shape (n,), int64
        Each body's category bit (1, 2, 4 or 8) and mask.
    """
    c = np.arange(int(n)) % len(CATEGORY_MASKS)
    return (np.int64(1) << c).astype(np.int64), np.array(CATEGORY_MASKS, np.int64)[c]
