"""
EPA: the polytope grows until its closest face is a face of M
=============================================================

When GJK finds the origin inside the Minkowski difference M = A − B, the hulls overlap, and the penetration depth
is the distance from the origin to the boundary of M: the length of the shortest translation that separates them.
The Expanding Polytope Algorithm (van den Bergen 4.3.3; Ericson 9.5) starts from GJK's last simplex, a
tetrahedron of points of M around the origin, and repeats: take the polytope's face closest to the origin, at
distance d along its outward normal n; ask for the support point w of M along n; if n·w − d is within round-off,
that face lies on M's boundary and (d, n) is the answer; otherwise cut away the faces that see w and join w to
the horizon edges.

This example records the engine's own EPA iteration by iteration (``trace_epa``, which caps the kernel at 0, 1,
2, … expansions) on a rotated box and an octahedron, draws the polytope at several iterations — its closest face
in red, the normal from the origin to that face, the support point w beyond it — and checks that the last face is
the depth and normal ``epa_penetration`` returns.
"""
import matplotlib.pyplot as plt
import numpy as np
from mpl_toolkits.mplot3d.art3d import Poly3DCollection

import engine
from engine.narrowphase.epa import trace_epa

corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float) * [0.9, 0.6, 0.5]
c, s = np.cos(0.5), np.sin(0.5)
turn = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]) @ np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
a = corners @ turn.T
b = np.vstack([np.eye(3), -np.eye(3)]) * [0.8, 0.7, 0.9] + [0.9, 0.5, 0.3]

steps, depth, normal = trace_epa(a, b)
expected_depth, expected_normal = engine.epa_penetration(a, b)
assert depth == expected_depth and np.array_equal(normal, expected_normal)
assert steps[-1].distance == depth and np.array_equal(steps[-1].normal, normal)
# the distance of the closest face never decreases: each expansion cuts away a part of the polytope that lies
# closer to the origin than M's boundary does
assert all(later.distance >= earlier.distance - 1e-12 for earlier, later in zip(steps, steps[1:]))
# and the support of M along any unit direction bounds the depth from above
assert all(step.support @ step.normal >= depth - 1e-12 for step in steps)

shown = sorted({0, 1, len(steps) // 3, 2 * len(steps) // 3, len(steps) - 1})[:5]
fig = plt.figure(figsize=(10, 6.4))  # a pyplot figure: the gallery's scraper collects only those
reach = np.abs(np.vstack([step.vertices for step in steps])).max()
for panel, k in enumerate(shown):
    ax = fig.add_subplot(2, 3, panel + 1, projection="3d")
    step = steps[k]
    triangles = step.vertices[step.faces]
    colours = ["tab:red" if f == step.closest_face else "0.8" for f in range(len(triangles))]
    ax.add_collection3d(Poly3DCollection(triangles, facecolors=colours, edgecolors="0.3", linewidths=0.4,
                                         alpha=0.45))
    foot = step.distance * step.normal
    ax.plot([0.0, foot[0]], [0.0, foot[1]], [0.0, foot[2]], "k-", lw=1.5)
    ax.scatter(*step.support, color="tab:blue", s=18)
    ax.scatter(0.0, 0.0, 0.0, color="k", marker="+", s=40)
    ax.set_xlim(-reach, reach)
    ax.set_ylim(-reach, reach)
    ax.set_zlim(-reach, reach)
    ax.set_box_aspect((1, 1, 1))
    ax.set_title(f"iteration {k}: {len(step.faces)} faces, d = {step.distance:.4f}", fontsize=9)
    ax.tick_params(labelsize=6)
ax = fig.add_subplot(2, 3, 6)
ax.plot(range(len(steps)), [step.distance for step in steps], "o-", ms=4, label="closest face d (lower bound)")
ax.plot(range(len(steps)), [step.support @ step.normal for step in steps], "s--", ms=3,
        label="support n·w (upper bound)")
ax.axhline(depth, color="tab:red", lw=0.8, label=f"depth {depth:.6f}")
ax.set_xlabel("iteration")
ax.legend(fontsize=8)
ax.set_title("the two bounds meet at the depth", fontsize=9)
fig.suptitle(f"EPA: depth {depth:.6f}, normal ({normal[0]:.3f}, {normal[1]:.3f}, {normal[2]:.3f}) "
             f"after {len(steps)} polytopes")
fig.tight_layout()
