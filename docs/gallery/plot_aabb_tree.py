"""
The dynamic AABB tree: its boxes by depth, and what a query visits
==================================================================

The chapter's non-uniform subdivision as Box2D, Bullet and FCL build it: a binary tree whose leaves hold the
objects' boxes, *fattened* by a margin so that small moves leave the tree unchanged, and whose inner nodes hold
the box enclosing their two children. An object is inserted by walking down the cheapest branch (the one whose box
grows least) and pairing its leaf with the node where the walk stops; with no rebalancing, a tree grown one
insertion at a time can become deep, and ``rebuild()`` rebuilds it top-down (split at the middle of the widest
spread of the centres) over the same fat leaves.

A query descends from the root into every node whose box overlaps the query box and skips whole subtrees
otherwise; at a leaf it compares the object's exact box. Left and middle: every node's box, coloured by depth
(``DynamicAABBTree.node_boxes()``), as inserted and after ``rebuild()``. Right: one query on the rebuilt tree —
the nodes it tested, those it entered, and the objects it found.
"""
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.patches import Rectangle

from engine.broadphase import DynamicAABBTree

rng = np.random.default_rng(11)
n = 40
lo = np.concatenate([rng.normal(6.0, 1.5, (n // 2, 2)), rng.uniform(0.0, 20.0, (n - n // 2, 2))])
hi = lo + rng.uniform(0.3, 1.5, (n, 2))
tree = DynamicAABBTree(dim=2, margin=0.2)
ids = [tree.insert(lo[i], hi[i]) for i in range(n)]  # one by one, as objects appear in a game
q_lo, q_hi = np.array([0.5, 12.0]), np.array([6.0, 20.0])


def query_visits(tree, q_lo, q_hi):
    """The tree's nodes (node_boxes()) and, for a query box, which nodes it tests and which it enters."""
    node_lo, node_hi, depth, leaf = tree.node_boxes()  # the root first, depth first
    # in depth-first order a node's parent is the last node listed before it one level up
    parent = np.full(len(depth), -1)
    last_at = {}
    for k, d in enumerate(depth):
        parent[k] = last_at.get(d - 1, -1)
        last_at[d] = k
    # a node is tested when its parent was entered (the root always), entered when its box overlaps the query
    overlaps = np.all(node_lo <= q_hi, axis=1) & np.all(q_lo <= node_hi, axis=1)
    tested = np.zeros(len(depth), bool)
    entered = np.zeros(len(depth), bool)
    for k in range(len(depth)):  # parents come before their children
        tested[k] = parent[k] == -1 or entered[parent[k]]
        entered[k] = tested[k] and overlaps[k]
    return node_lo, node_hi, depth, leaf, tested, entered


def draw_by_depth(ax, tree, title):
    node_lo, node_hi, depth, leaf = tree.node_boxes()
    colours = plt.cm.viridis(np.linspace(0.0, 0.9, depth.max() + 1))
    for k in np.argsort(depth, kind="stable"):
        style = {"ls": "--", "lw": 0.8} if leaf[k] else {"lw": 2.2 - 1.6 * depth[k] / depth.max()}
        ax.add_patch(Rectangle(node_lo[k], *(node_hi[k] - node_lo[k]), fill=False, color=colours[depth[k]],
                               **style))
    for i in ids:
        ax.add_patch(Rectangle(lo[i], *(hi[i] - lo[i]), color="crimson", alpha=0.5))
    ax.set_title(f"{title}: {len(depth)} nodes, height {tree.height},\narea ratio {tree.area_ratio():.1f} "
                 "(colour = depth, dashed = a leaf's fat box)", fontsize=9)


fig, (grown, rebuilt, query) = plt.subplots(1, 3, figsize=(15, 5.8))
draw_by_depth(grown, tree, "inserted one by one")
tested_grown = query_visits(tree, q_lo, q_hi)[4].sum()
pairs_before = tree.pairs()
tree.rebuild()
assert np.array_equal(tree.pairs(), pairs_before)  # the same fat leaves, the same pairs: only inner nodes change
draw_by_depth(rebuilt, tree, "after rebuild()")

node_lo, node_hi, depth, leaf, tested, entered = query_visits(tree, q_lo, q_hi)
found = tree.query(q_lo, q_hi)
exact = np.flatnonzero(np.all(lo <= q_hi, axis=1) & np.all(q_lo <= hi, axis=1))
assert np.array_equal(found, exact)  # exactly the boxes that overlap the query, whatever the margins
assert len(found) <= np.count_nonzero(entered & leaf)  # fat leaves entered, then their exact boxes compared
for k in range(len(depth)):
    if not tested[k]:
        colour, width = "0.85", 0.6
    else:
        colour, width = ("C2", 1.6) if entered[k] else ("C1", 1.2)
    query.add_patch(Rectangle(node_lo[k], *(node_hi[k] - node_lo[k]), fill=False, color=colour, lw=width,
                              ls="--" if leaf[k] else "-"))
hit = np.zeros(n, bool)
hit[found] = True
for i in ids:
    query.add_patch(Rectangle(lo[i], *(hi[i] - lo[i]), color="crimson" if hit[i] else "0.6", alpha=0.6))
query.add_patch(Rectangle(q_lo, *(q_hi - q_lo), fill=False, color="k", lw=2.5))
query.set_title(f"a query (black) tests {tested.sum()} of {len(depth)} nodes (orange: missed, green: entered;\n"
                f"{tested_grown} before the rebuild) and finds {len(found)} objects (red)", fontsize=9)
for ax in (grown, rebuilt, query):
    ax.autoscale()
    ax.set_aspect("equal")
fig.tight_layout()
