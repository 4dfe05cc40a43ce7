"""
A filtered scene: static level, collision layers, a trigger
===========================================================

A level of static crates (grey) on a ground, a player (blue) and enemies (red) in their own categories, and a
door that is a sensor (dashed): it reports the player entering it, never a contact. Enemies do not collide with
each other (their mask leaves out their own category) and one enemy is in a negative group with the player
(never tested). Every overlapping pair of boxes is drawn: solid red where the World reports a contact, dotted
grey where the filter dropped the pair before the narrow phase, dashed blue for the trigger's report.
"""
import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Circle, Rectangle

import engine
from engine import Box, Plane, Sphere, World

PLAYER, ENEMY, LEVEL = 1, 2, 4
world = World()
world.add(Plane(0.0), category=LEVEL)
crates = [world.add(Box([1.6 * x, 0.5, 0.0], [0.5, 0.5, 0.5]), static=True, category=LEVEL) for x in range(-3, 4)]
player = world.add(Sphere([0.1, 1.4, 0.0], 0.5), category=PLAYER)
enemies = [world.add(Sphere([x, y, 0.0], 0.45), category=ENEMY, mask=engine.ALL & ~ENEMY)
           for x, y in ((0.9, 1.5), (1.6, 1.3), (-0.75, 1.55))]
world.set_filter(enemies[2], group=-1)
world.set_filter(player, group=-1)  # the player and the third enemy: one negative group, never tested
door = world.add(Box([-0.4, 1.9, 0.0], [0.6, 0.9, 0.8]), static=True, sensor=True, category=LEVEL, mask=PLAYER)

touching = {tuple(p) for p in world.pairs().tolist()}
contacts = world.contacts()
with_contact = {tuple(p) for p in contacts.pairs.tolist()}
ids = world.ids()
boxes = {int(b): world.aabb(b) for b in ids if world.kind(b) != "plane"}
overlapping = [(i, j) for i in boxes for j in boxes if i < j and not (world.is_static(i) and world.is_static(j))
               and np.all(boxes[i][0] <= boxes[j][1]) and np.all(boxes[j][0] <= boxes[i][1])]

fig = Figure(figsize=(7.5, 3.4))
ax = fig.subplots()
ax.axhline(0.0, color="0.3", lw=2)
for b, (lo, hi) in boxes.items():
    center = world.pose(b)[0]
    if b == door:
        ax.add_patch(Rectangle(lo[:2], *(hi - lo)[:2], fill=False, ls="--", color="tab:blue", lw=1.2))
    elif world.kind(b) == "box":
        ax.add_patch(Rectangle(lo[:2], *(hi - lo)[:2], color="0.75"))
    else:
        ax.add_patch(Circle(center[:2], world.radius(b), color="tab:blue" if b == player else "tab:red", alpha=0.6))
for i, j in overlapping:
    a, b = world.pose(i)[0][:2], world.pose(j)[0][:2]
    if (i, j) in with_contact:
        style = dict(color="crimson", lw=1.6)
    elif (i, j) in touching:
        style = dict(color="tab:blue", ls="--", lw=1.2)
    else:
        style = dict(color="0.5", ls=":", lw=1.2)
    ax.plot([a[0], b[0]], [a[1], b[1]], **style)
for p in range(len(contacts)):
    points = contacts.points_of(p)
    ax.plot(points[:, 0], points[:, 1], "o", color="crimson", ms=3)
for label, style in (("contact", dict(color="crimson", lw=1.6)), ("trigger report", dict(color="tab:blue", ls="--")),
                     ("filtered", dict(color="0.5", ls=":"))):
    ax.plot([], [], label=label, **style)
ax.legend(loc="upper right", fontsize=8)
ax.set_aspect("equal")
ax.set_xlim(-5.3, 5.3)
ax.set_ylim(-0.2, 3.0)
ax.set_title(f"{len(with_contact)} contacts, {len(touching - with_contact)} trigger report, "
             f"{world.stats.filtered} pairs filtered before the narrow phase")
fig.tight_layout()
fig
