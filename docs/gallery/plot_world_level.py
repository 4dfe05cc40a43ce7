"""
A level: bodies resting on a heightfield
========================================

Level geometry is static: a ``HeightField`` (a grid of heights, two triangles per cell) or a ``TriangleMesh``
(any triangle soup, with its own tree over the triangles). A body against it is answered triangle by triangle —
the closest point of a triangle for spheres and capsules, the 13-axis separating-axis test for boxes — and the
contacts of one body are merged into one manifold of at most four points. Each ball and box below was lowered
onto the terrain until it touched (``cast_shape``), then pushed in by a hair; the contact points are drawn in red
with their normals, and every normal is the terrain's own (no ghost normal of an internal edge).
"""
import numpy as np
from matplotlib.figure import Figure

from engine import Box, HeightField, Sphere, World

n, spacing = 24, 0.5
x = np.arange(n) * spacing
heights = 0.6 * np.sin(0.5 * x)[:, None] * np.cos(0.4 * x)[None, :] + 0.2 * np.cos(0.9 * x)[None, :]
world = World()
terrain = world.add(HeightField(heights, spacing))
rng = np.random.default_rng(3)
for k in range(14):
    cx, cz = rng.uniform(1.0, x[-1] - 1.0, 2)
    probe = (Sphere([cx, 4.0, cz], 0.35) if k % 2 else
             Box([cx, 4.0, cz], [0.3, 0.2, 0.3], rotation=[np.cos(0.3 * k), 0.0, np.sin(0.3 * k), 0.0]))
    hit = world.cast_shape(probe, [0.0, -8.0, 0.0])  # where it first touches the terrain
    drop = np.array([0.0, -8.0 * hit.fraction - 1e-3, 0.0])
    rotation = None if k % 2 else probe.rotation
    world.add(Sphere(probe.center + drop, 0.35) if k % 2 else Box(probe.center + drop, [0.3, 0.2, 0.3],
                                                                  rotation=rotation))
contacts = world.contacts()

fig = Figure(figsize=(7.5, 5.5))
ax = fig.add_subplot(projection="3d")
gx, gz = np.meshgrid(x, x, indexing="ij")
ax.plot_surface(gx, gz, heights, cmap="terrain", alpha=0.55, linewidth=0.2, edgecolor="0.4")
for body in world.ids():
    if body == terrain:
        continue
    c = world.pose(body)[0]
    ax.scatter([c[0]], [c[2]], [c[1]], color="steelblue" if world.kind(body) == "sphere" else "darkorange", s=40)
for p in range(len(contacts)):
    pts = contacts.points_of(p)
    ax.scatter(pts[:, 0], pts[:, 2], pts[:, 1], color="crimson", s=8)
    # the normal points from the pair's first body to its second: from the terrain up to the body
    up = contacts.normal[p] if contacts.pairs[p, 0] == terrain else -contacts.normal[p]
    ax.quiver(pts[0, 0], pts[0, 2], pts[0, 1], up[0], up[2], up[1], length=0.8, color="crimson")
ax.set_xlabel("x")
ax.set_ylabel("z")
ax.set_zlabel("y (up)")
ax.set_title(f"{len(contacts)} bodies touching the terrain, "
             f"{sum(len(contacts.points_of(p)) for p in range(len(contacts)))} contact points")
fig.tight_layout()
fig
