"""
GJK: the simplex walks towards the origin
=========================================

Two convex sets are apart exactly when their Minkowski difference M = A − B does not contain the origin, and
their distance is the distance from the origin to M. GJK (Ericson 9.5) never builds M: it keeps a simplex of at
most four support points of M, finds the simplex's closest point v to the origin, and asks for the support point
w of M in the direction −v. It stops when w brings no progress (v·v − v·w ≤ ε v·v).

This example runs those steps one by one with the engine's own kernels (``support_minkowski``, the support
mapping, and ``closest_on_simplex``, the sub-algorithm of Ericson 5.1) on two flat polygons in the plane z = 0,
and draws each iteration's simplex and closest point on top of M (drawn here only for the picture). The last v
is the distance ``gjk_distance`` returns.
"""
import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Polygon

import engine
from engine.narrowphase.simplex import closest_on_simplex
from engine.narrowphase.support import support_minkowski

angles = np.linspace(0.0, 2.0 * np.pi, 7)[:-1]
a = np.column_stack([1.2 * np.cos(angles) + 3.0, 0.8 * np.sin(angles) + 1.4, np.zeros(6)])
b = np.array([[-1.0, -0.6, 0.0], [0.9, -0.3, 0.0], [0.2, 1.1, 0.0], [-0.8, 0.7, 0.0]])

simplex = [a[0] - b[0]]  # any point of M starts the walk
steps = []
for _ in range(16):
    w_prev = np.array(simplex)
    padded = np.vstack([w_prev, np.zeros((4 - len(w_prev), 3))])
    if len(w_prev) == 1:
        v = w_prev[0]
    else:
        m, s0, s1, s2, l0, l1, l2, l3 = closest_on_simplex(len(w_prev), *padded.ravel())
        keep = [s0, s1, s2][:m]
        weights = np.array([l0, l1, l2][:m])
        simplex = [w_prev[k] for k in keep]
        v = weights @ np.array(simplex)
    steps.append((np.array(simplex), v.copy()))
    _, _, wx, wy, wz = support_minkowski(a, b, -v[0], -v[1], -v[2])
    w = np.array([wx, wy, wz])
    if v @ v - v @ w <= 1e-12 * (v @ v):
        break
    simplex = simplex + [w]

distance, closest_a, closest_b = engine.gjk_distance(a, b)
assert np.isclose(np.linalg.norm(steps[-1][1]), distance, rtol=1e-12)

differences = (a[:, None, :2] - b[None, :, :2]).reshape(-1, 2)
outline = engine.convex_hull(differences)
fig = Figure(figsize=(6.4, 5))
ax = fig.subplots()
ax.add_patch(Polygon(outline.points[outline.vertices], color="0.85", label="M = A − B"))
colours = [f"C{k % 10}" for k in range(len(steps))]
for k, (simplex_k, v) in enumerate(steps):
    closed = np.vstack([simplex_k[:, :2], simplex_k[:1, :2]])
    ax.plot(closed[:, 0], closed[:, 1], "-o", color=colours[k], ms=4, lw=1.2, label=f"iteration {k}: |v| = "
            f"{np.linalg.norm(v):.4f}")
    ax.plot([0.0, v[0]], [0.0, v[1]], ":", color=colours[k], lw=1)
ax.plot(0.0, 0.0, "k+", ms=12, mew=2)
ax.set_aspect("equal")
ax.legend(fontsize=8, loc="upper left")
ax.set_title(f"GJK: distance {distance:.6f} after {len(steps)} simplices")
fig.tight_layout()
fig
