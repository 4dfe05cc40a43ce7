"""
A lidar scan and a shape cast: asking the World what a robot sees
=================================================================

``World.cast_rays`` answers a whole batch of rays in one compiled call: each ray walks the static bodies' tree and
the moving bodies' tree, clipped by its nearest hit so far (Box2D's ray cast), and meets each body it reaches by
its shape's exact kernel (a sphere's quadratic, a box's slabs, a hull's face planes, a compound part by part).

Left: a scene seen from above — static crates and pillars, moving balls and capsules on a ground — and a
360 × 24 lidar fan from a robot at its centre, each hit coloured by its distance (misses are not drawn). Right:
a box swept across the scene by ``World.cast_shape``: its start, the pose where it first touches a body
(``fraction``), the contact point and the hit surface's normal.
"""
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.patches import Circle, Polygon, Rectangle

from engine import Box, Capsule, Plane, Sphere, World

rng = np.random.default_rng(3)
world = World()
world.add(Plane(0.0))
shapes = []
for _ in range(40):  # static crates, turned about y
    c = rng.uniform(-12.0, 12.0, 2)
    if np.hypot(*c) < 2.5:
        continue
    angle = rng.uniform(0.0, np.pi)
    rot = np.array([[np.cos(angle), 0.0, np.sin(angle)], [0.0, 1.0, 0.0], [-np.sin(angle), 0.0, np.cos(angle)]])
    half = np.array([rng.uniform(0.3, 1.0), 1.0, rng.uniform(0.3, 1.0)])
    world.add(Box([c[0], 1.0, c[1]], half, rot), static=True)
    shapes.append(("box", c, half, angle))
for _ in range(25):  # moving balls and capsules
    c = rng.uniform(-12.0, 12.0, 2)
    if np.hypot(*c) < 2.5:
        continue
    if rng.random() < 0.5:
        world.add(Sphere([c[0], 0.6, c[1]], 0.6))
        shapes.append(("ball", c, 0.6, 0.0))
    else:
        world.add(Capsule([c[0] - 0.7, 0.4, c[1]], [c[0] + 0.7, 0.4, c[1]], 0.4))
        shapes.append(("capsule", c, 0.4, 0.7))

robot = np.array([0.0, 1.0, 0.0])
azimuth, elevation = np.meshgrid(np.radians(np.arange(0.0, 360.0, 1.0)), np.radians(np.linspace(-10, 10, 24)))
directions = np.stack([np.cos(elevation) * np.cos(azimuth), np.sin(elevation),
                       np.cos(elevation) * np.sin(azimuth)], axis=-1).reshape(-1, 3)
scan = world.cast_rays(np.tile(robot, (directions.shape[0], 1)), directions, max_distance=18.0)
seen = (scan.body >= 0) & (world.bodies().kind[np.maximum(scan.body, 0)] != world.bodies().kind[0])


def draw_scene(ax):
    for kind, c, size, extra in shapes:
        if kind == "box":
            corners = np.array([[sx * size[0], sz * size[2]] for sx, sz in ((-1, -1), (1, -1), (1, 1), (-1, 1))])
            turn = np.array([[np.cos(extra), np.sin(extra)], [-np.sin(extra), np.cos(extra)]])
            ax.add_patch(Polygon(c + corners @ turn.T, closed=True, color="0.55"))
        elif kind == "ball":
            ax.add_patch(Circle(c, size, color="tab:blue", alpha=0.6))
        else:  # a capsule from above: a rectangle between two discs
            ax.add_patch(Rectangle((c[0] - extra, c[1] - size), 2 * extra, 2 * size, color="tab:green", alpha=0.6))
            for end in (-extra, extra):
                ax.add_patch(Circle((c[0] + end, c[1]), size, color="tab:green", alpha=0.6))
    ax.set_xlim(-13, 13)
    ax.set_ylim(-13, 13)
    ax.set_aspect("equal")
    ax.set_xlabel("x")
    ax.set_ylabel("z")


fig, (left, right) = plt.subplots(1, 2, figsize=(12, 6))
draw_scene(left)
points = scan.point[seen]
dots = left.scatter(points[:, 0], points[:, 2], c=scan.distance[seen], s=2, cmap="viridis")
left.plot(*robot[[0, 2]], "r^", ms=10)
fig.colorbar(dots, ax=left, shrink=0.7, label="distance of the hit")
left.set_title(f"lidar: {directions.shape[0]} rays, {seen.sum()} hits on bodies (ground hits not drawn)")

draw_scene(right)
start, sweep = np.array([-11.0, 1.0, -11.0]), np.array([22.0, 0.0, 20.0])
probe = Box(start, [0.5, 0.5, 0.5])
hit = world.cast_shape(probe, sweep)
square = np.array([[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]])
right.add_patch(Polygon(start[[0, 2]] + square, closed=True, fill=False, ec="k", ls="--"))
right.annotate("", xy=(start + sweep)[[0, 2]], xytext=start[[0, 2]], arrowprops={"arrowstyle": "->", "color": "k"})
if hit is not None:
    at = start + hit.fraction * sweep
    right.add_patch(Polygon(at[[0, 2]] + square, closed=True, fill=False, ec="tab:red", lw=2))
    right.plot(*hit.point[[0, 2]], "o", color="tab:red")
    right.annotate("", xy=(hit.point + 2.0 * hit.normal)[[0, 2]], xytext=hit.point[[0, 2]],
                   arrowprops={"arrowstyle": "->", "color": "tab:red"})
    right.set_title(f"cast_shape: touches body {hit.body} at fraction {hit.fraction:.3f}")
fig.tight_layout()
plt.show()
