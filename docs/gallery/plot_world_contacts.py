"""
The pipeline: broad phase, narrow phase, contacts
=================================================

A ``World`` runs the chapter's pipeline on mixed shapes: the broad phase (an AABB tree kept across frames)
proposes candidate pairs from bounding boxes, the narrow phase tests each candidate exactly with the routine for
its two shape kinds, and ``contacts()`` says where: one normal and depth per touching pair and its contact points.
The picture is a side view (x–y): bounding boxes of the candidates in grey, contact points in red, normals as
arrows scaled by the depth.
"""
import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Circle, Polygon, Rectangle

import engine
from engine import Box, Capsule, Plane, Sphere, World

world = World(broad_phase="tree")
world.add(Plane(0.0))
world.add(Sphere([0.0, 0.45, 0.0], 0.5))
world.add(Box([1.05, 0.48, 0.0], [0.5, 0.5, 0.5], rotation=[np.cos(0.2), 0, 0, np.sin(0.2)]))
world.add(Capsule([-2.2, 0.25, 0.0], [-1.0, 0.55, 0.0], 0.3))
world.add(Sphere([1.1, 1.35, 0.0], 0.4))
contacts = world.contacts()

fig = Figure(figsize=(7, 3.6))
ax = fig.subplots()
ax.axhline(0.0, color="0.3", lw=2)
for body in world.ids():
    if world.kind(body) == "plane":
        continue
    lo, hi = world.aabb(body)
    ax.add_patch(Rectangle(lo[:2], *(hi - lo)[:2], fill=False, color="0.6", lw=0.8, ls="--"))
    core = world.world_points(body)[:, :2]  # the core points, swept by the body's radius
    radius = world.radius(body)
    if radius > 0.0:  # a sphere (one core point) or a capsule (its segment)
        for c in core:
            ax.add_patch(Circle(c, radius, alpha=0.5, lw=0))
        if len(core) == 2:  # the capsule's side: the segment pushed out by the radius both ways
            d = core[1] - core[0]
            side = radius * np.array([-d[1], d[0]]) / np.hypot(*d)
            ax.add_patch(Polygon([core[0] + side, core[1] + side, core[1] - side, core[0] - side], alpha=0.5, lw=0))
    else:  # a box: the outline of its corners, by the chapter's 2-D hull
        outline = engine.convex_hull(core)
        ax.add_patch(Polygon(outline.points[outline.vertices], alpha=0.5, lw=0))
for p in range(len(contacts)):
    points = contacts.points_of(p)
    normal = contacts.normal[p]
    ax.plot(points[:, 0], points[:, 1], "o", color="crimson", ms=4)
    ax.arrow(*points[0, :2], *(0.6 * normal[:2]), color="crimson", width=0.01, head_width=0.06)
ax.set_aspect("equal")
ax.set_xlim(-3, 2.5)
ax.set_ylim(-0.3, 2.0)
ax.set_title(f"{len(world.pairs())} touching pairs, {sum(len(contacts.points_of(p)) for p in range(len(contacts)))}"
             " contact points")
fig.tight_layout()
fig
