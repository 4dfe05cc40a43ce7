"""Ghost normals (Jolt's active edges, engine.narrowphase.mesh_contact.fix_normal): bodies slid across tessellated
flat floors — a HeightField of zeros; a TriangleMesh of a flat grid with random diagonals and random extra vertices,
on a randomly tilted plane — and across gentle folds (faces under 5 degrees apart) always get one of the floor's
face normals (±), never an internal edge's; over a sharp convex ridge the edge's normal is kept.

Planted defect caught (reverted): fix_normal doing nothing (no active-edge fix) — the gentle-fold property fails
(a sphere over the fold's edge gets the edge's normal, between the two faces').
"""
from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from engine.world import World
from engine.world.shapes import Box, HeightField, Sphere, TriangleMesh

SCALES = (1e-3, 1.0, 1e3)


def _random_rotation(rng):
    q = rng.normal(size=4)
    w, x, y, z = q / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def _flat_grid_mesh(rng, n, spacing):
    """A flat n × n grid on y = 0, each cell split along a random diagonal, some triangles split again at a random
    inner point (an extra vertex on the plane)."""
    i, k = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    vertices = [np.stack([i.ravel() * spacing, np.zeros(n * n), k.ravel() * spacing], axis=1)]
    count = n * n
    triangles = []
    for a in range(n - 1):
        for b in range(n - 1):
            v00, v01, v10, v11 = a * n + b, a * n + b + 1, (a + 1) * n + b, (a + 1) * n + b + 1
            pair = ([v00, v01, v11], [v00, v11, v10]) if rng.random() < 0.5 else ([v00, v01, v10], [v01, v11, v10])
            for tri in pair:
                if rng.random() < 0.3:  # an extra vertex inside: three triangles
                    w = rng.dirichlet(np.ones(3)) * 0.8 + 0.2 / 3
                    corners = np.concatenate(vertices)[tri]
                    vertices.append((w @ corners)[None])
                    triangles += [[tri[0], tri[1], count], [tri[1], tri[2], count], [tri[2], tri[0], count]]
                    count += 1
                else:
                    triangles.append(tri)
    return np.concatenate(vertices), np.array(triangles)


def _bodies_over(rng, world, frame, origin, extent, scale, boxes=True):
    """Spheres and boxes at random places over the floor (``frame``: columns u, up, v, right-handed; the floor
    spans origin + [0, extent] u + [0, extent] v), sunk a little into it: their ids."""
    ids = []
    u, up, v = frame.T
    for _ in range(6):
        size = rng.uniform(0.05, 0.15) * scale  # its reach (at most √3 · size) stays off the floor's boundary
        at = origin + rng.uniform(0.3, 0.7) * extent * u + rng.uniform(0.3, 0.7) * extent * v
        sink = rng.uniform(0.01, 0.5) * size
        if boxes and rng.random() < 0.5:
            half = rng.uniform(0.5, 1.0, 3) * size
            rot = frame if rng.random() < 0.5 else _random_rotation(rng)
            lowest = np.abs(rot.T @ up) @ half  # the box's extent along up
            ids.append(world.add(Box(at + (lowest - sink) * up, half, rot)))
        else:
            ids.append(world.add(Sphere(at + (size - sink) * up, size)))
    return ids


def _assert_normals_among(world, surface, normals):
    contacts = world.contacts()
    assert len(contacts) > 0
    for k in range(len(contacts)):
        if surface not in contacts.pairs[k]:
            continue
        alignment = np.abs(normals @ contacts.normal[k]).max()
        assert alignment >= 1.0 - 1e-12, (contacts.normal[k], contacts.kind[k])


@settings(deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from(SCALES), st.booleans())
def test_flat_floors_give_the_face_normal(seed, scale, field):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(3, 9))
    spacing = scale / (n - 1)
    world = World()
    if field:
        floor = HeightField(np.zeros((n, n)), spacing)
        frame, origin = np.eye(3), np.zeros(3)
    else:
        vertices, triangles = _flat_grid_mesh(rng, n, spacing)
        rot = _random_rotation(rng)
        shift = rng.normal(size=3) * scale
        floor = TriangleMesh(vertices @ rot.T + shift, triangles)
        frame, origin = rot, shift
    g = world.add(floor)
    _bodies_over(rng, world, frame, origin, scale, scale)
    _assert_normals_among(world, g, frame[:, 1][None])


@settings(deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from(SCALES), st.floats(0.2, 2.4), st.booleans())
def test_gentle_folds_give_a_face_normal(seed, scale, tilt_degrees, ridge):
    """Two slopes of ± tilt (faces 2 tilt < 5 degrees apart) meeting along a grid line: a convex ridge or a concave
    valley; bodies anywhere over it (off the boundary edges, which are active) get one of the faces' normals."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(5, 10))
    spacing = scale / (n - 1)
    fold = int(rng.integers(2, n - 2))
    slope = np.tan(np.radians(tilt_degrees)) * np.abs(np.arange(n) - fold) * spacing
    heights = np.repeat((-slope if ridge else slope)[:, None], n, axis=1)
    world = World()
    field = HeightField(heights, spacing)
    g = world.add(field)
    for _ in range(6):
        size = rng.uniform(0.05, 0.4) * spacing  # its reach stays within two cells of the fold
        x = (fold + rng.uniform(-1.0, 1.0)) * spacing
        z = rng.uniform(0.3, 0.7) * scale
        y = np.interp(x, np.arange(n) * spacing, heights[:, 0])
        sink = rng.uniform(0.01, 0.5) * size
        if rng.random() < 0.5:
            world.add(Sphere([x, y + size - sink, z], size))
        else:
            half = rng.uniform(0.5, 1.0, 3) * size
            world.add(Box([x, y + half[1] - sink, z], half))
    _assert_normals_among(world, g, field.mesh.normals)


@settings(deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from(SCALES), st.floats(20.0, 60.0))
def test_a_sharp_convex_ridge_keeps_its_edge_normal(seed, scale, tilt_degrees):
    rng = np.random.default_rng(seed)
    n = 5
    spacing = scale / (n - 1)
    slope = np.tan(np.radians(tilt_degrees)) * np.abs(np.arange(n) - 2) * spacing
    field = HeightField(np.repeat(-slope[:, None], n, axis=1), spacing)
    world = World()
    g = world.add(field)
    radius = rng.uniform(0.05, 0.2) * scale
    sphere = world.add(Sphere([2 * spacing, radius * rng.uniform(0.5, 0.99), rng.uniform(0.3, 0.7) * scale], radius))
    contacts = world.contacts()
    assert contacts.pairs.tolist() == [[g, sphere]]
    normal = contacts.normal[0]
    np.testing.assert_allclose(normal, [0.0, 1.0, 0.0], atol=1e-12)  # the ridge's own normal, straight up
    assert np.abs(field.mesh.normals @ normal).max() < np.cos(np.radians(tilt_degrees / 2))
