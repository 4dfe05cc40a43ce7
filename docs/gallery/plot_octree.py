"""
Hierarchical subdivision: the loose octree
==========================================

The chapter's non-uniform subdivision stores objects in a tree of cells: a cell holding too many objects is
split in eight (four in 2-D), and an object goes in the smallest cell that contains it. The *loose* octree
(Ericson 7.3.6) enlarges every cell so that objects straddling a boundary still go down the tree. Pairs are
then only tested between objects of a cell and its ancestors' objects.
"""
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.patches import Rectangle

from engine.broadphase import build_octree, find_pairs

rng = np.random.default_rng(5)
centres = np.concatenate([rng.normal(5, 1.2, (60, 2)), rng.uniform(0, 20, (40, 2))])
lo = centres - 0.3
hi = centres + 0.3
perm, node_lo, node_hi, first, last, child0, n_children = build_octree(lo, hi, leaf_size=4)
pairs, tests = find_pairs(lo, hi, "octree", return_tests=True)

fig, ax = plt.subplots(figsize=(6, 6))
for k in range(node_lo.shape[0]):
    depth_colour = "0.75" if n_children[k] else "C0"
    ax.add_patch(Rectangle(node_lo[k, :2], *(node_hi[k, :2] - node_lo[k, :2]), fill=False, lw=0.7,
                           color=depth_colour))
for i in range(lo.shape[0]):
    ax.add_patch(Rectangle(lo[i], *(hi[i] - lo[i]), color="crimson", alpha=0.6))
ax.autoscale()
ax.set_aspect("equal")
ax.set_title(f"{node_lo.shape[0]} loose cells (leaves blue), {len(pairs)} pairs, {tests} box tests "
             f"(brute force: {len(lo) * (len(lo) - 1) // 2})")
fig.tight_layout()
