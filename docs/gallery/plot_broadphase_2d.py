"""
Broad phase in 2-D: brute force, sweep and prune, and a uniform grid
====================================================================

The broad phase proposes the pairs of objects whose bounding boxes overlap. Brute force tests every pair,
(n² − n)/2 of them. Sweep and prune sorts the boxes along one axis and only tests boxes whose intervals overlap
on it; the uniform grid only tests boxes that share a cell. All three return exactly the same pairs; what
differs is the number of box tests they make (``return_tests=True``).
"""
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.patches import Rectangle

import engine

rng = np.random.default_rng(3)
n = 60
lo = rng.uniform(0, 20, (n, 2))
hi = lo + rng.uniform(0.5, 2.5, (n, 2))

counts = {}
for method in ("brute", "sap", "grid"):
    pairs, tests = engine.find_pairs(lo, hi, method, return_tests=True)
    counts[method] = tests
assert all(np.array_equal(pairs, engine.find_pairs(lo, hi, m)) for m in ("brute", "sap", "grid", "tree"))

fig, (ax, bar) = plt.subplots(1, 2, figsize=(10, 4.6), gridspec_kw={"width_ratios": [3, 2]})
touching = np.zeros(n, bool)
touching[pairs.ravel()] = True
for i in range(n):
    ax.add_patch(Rectangle(lo[i], *(hi[i] - lo[i]), fill=False, lw=1.2, color="crimson" if touching[i] else "0.4"))
centre = 0.5 * (lo + hi)
for i, j in pairs:
    ax.plot(*zip(centre[i], centre[j]), color="crimson", lw=0.8)
for b, e in zip(lo[:, 0], hi[:, 0]):  # the intervals that sweep and prune sorts
    ax.plot([b, e], [-1.0, -1.0], color="C0", alpha=0.15, lw=6, solid_capstyle="butt")
ax.set_xlim(-0.5, 23)
ax.set_ylim(-1.8, 23)
ax.set_aspect("equal")
ax.set_title(f"{n} boxes, {len(pairs)} overlapping pairs (red); x-intervals below")
bar.bar(list(counts), list(counts.values()), color=["0.5", "C0", "C2"])
bar.set_ylabel("box tests made")
bar.set_title("same pairs, fewer tests")
fig.tight_layout()
