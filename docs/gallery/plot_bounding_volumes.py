"""
Bounding volumes of one point cloud: how to pick
================================================

The chapter's "volumes englobants", each fitted to the same elongated, tilted cloud of 2-D points: the bounding
sphere (a circle here) by Ritter's fast method and by Welzl's exact one, the axis-aligned box (AABB), the
oriented box (OBB, by principal component analysis), the 8-DOP (four fixed slab directions: the axes and the
diagonals) and the convex hull. The tighter a volume, the fewer false alarms it passes on to the narrow phase;
the cheaper, the faster its overlap test and its update when the object moves:

- a sphere stores 3 numbers in 2-D (4 in 3-D), is tested with one distance, and a rotation only moves its
  centre, but it is loose on elongated objects;
- an AABB stores 4 (6), is tested interval by interval, and must be re-fitted (or conservatively grown) after a
  rotation;
- an 8-DOP stores 8 numbers (a 26-DOP 26), a few more interval tests for a tighter fit;
- an OBB stores 8 (15), follows the object's rotation exactly, and is tested by the separating axis theorem;
- the convex hull is exact for convex objects: it is what the narrow phase works on.

The engine's OBB is 3-D: the cloud is fitted at z = 0, where the box's first two axes lie in the plane.
"""
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.patches import Circle, Polygon, Rectangle

from engine.bounding import (
    aabb_contains,
    convex_hull,
    fit_aabb,
    fit_kdop,
    fit_obb,
    kdop_contains,
    kdop_directions,
    min_bounding_sphere,
    ritter_sphere,
    sphere_contains,
)

rng = np.random.default_rng(4)
angle = 0.5
turn = np.array([[np.cos(angle), np.sin(angle)], [-np.sin(angle), np.cos(angle)]])
points = (rng.normal(size=(200, 2)) * [3.0, 0.8]) @ turn + [10.0, 5.0]


def shoelace(polygon):
    """The area of a polygon (k, 2) given in boundary order."""
    x, y = polygon[:, 0], polygon[:, 1]
    return 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def clip(polygon, normal, offset):
    """The part of a convex polygon (k, 2) where normal · x <= offset (one Sutherland–Hodgman step)."""
    out = []
    for p, q in zip(polygon, np.roll(polygon, -1, axis=0)):
        dp, dq = normal @ p - offset, normal @ q - offset
        if dp <= 0.0:
            out.append(p)
        if dp * dq < 0.0:
            out.append(p + dp / (dp - dq) * (q - p))
    return np.array(out)


welzl_c, welzl_r = min_bounding_sphere(points)
ritter_c, ritter_r = ritter_sphere(points)
lo, hi = fit_aabb(points)
box = fit_obb(np.column_stack([points, np.zeros(len(points))]))
assert np.abs(box.axes[:2, 2]).max() == 0.0 and box.half_extents[2] == 0.0  # a flat box in the plane z = 0
obb_corners = box.center[:2] + np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * box.half_extents[:2] @ box.axes[:2, :2]
dop_lo, dop_hi = fit_kdop(points, 8)
dop = np.array([[lo[0], lo[1]], [hi[0], lo[1]], [hi[0], hi[1]], [lo[0], hi[1]]])  # the first two slabs: the AABB
for normal, low, high in zip(kdop_directions(8)[2:], dop_lo[2:], dop_hi[2:]):
    dop = clip(clip(dop, normal, high), -normal, -low)
hull = convex_hull(points)

# every volume holds every point (the boundary counts)
assert sphere_contains(welzl_c, welzl_r, points).all() and sphere_contains(ritter_c, ritter_r, points).all()
assert aabb_contains(lo, hi, points).all() and kdop_contains(dop_lo, dop_hi, points, 8).all()
assert box.contains(np.column_stack([points, np.zeros(len(points))])).all()

volumes = [  # name, numbers stored (2-D), area, the patch that draws it
    ("Welzl sphere (exact)", 3, np.pi * welzl_r**2, Circle(welzl_c, welzl_r)),
    ("Ritter sphere (fast)", 3, np.pi * ritter_r**2, Circle(ritter_c, ritter_r)),
    ("AABB", 4, float(np.prod(hi - lo)), Rectangle(lo, *(hi - lo))),
    ("8-DOP", 8, shoelace(dop), Polygon(dop)),
    ("OBB (PCA)", 8, 4.0 * box.half_extents[0] * box.half_extents[1], Polygon(obb_corners)),
    ("convex hull", 2 * len(hull.vertices), hull.volume, Polygon(points[hull.vertices])),
]
assert volumes[0][2] <= volumes[1][2]  # Welzl's circle is the smallest circle
assert all(area >= hull.volume * (1 - 1e-12) for _, _, area, _ in volumes)  # the hull is the tightest

print(f"{'volume':<22}{'numbers':>8}{'area':>9}{'× hull':>8}")
for name, numbers, area, _ in volumes:
    print(f"{name:<22}{numbers:>8}{area:>9.2f}{area / hull.volume:>8.2f}")

fig, axes = plt.subplots(2, 3, figsize=(12, 7), sharex=True, sharey=True)
for ax, (name, numbers, area, patch) in zip(axes.ravel(), volumes):
    patch.set(facecolor="C0", alpha=0.25, edgecolor="C0", lw=1.5)
    ax.add_patch(patch)
    ax.plot(points[:, 0], points[:, 1], ".", ms=3, color="0.2")
    ax.set_title(f"{name}\narea {area:.1f} = {area / hull.volume:.2f} × the hull's, {numbers} numbers", fontsize=9)
    ax.set_aspect("equal")
axes[0, 0].autoscale()
fig.tight_layout()
