"""
Sweep and prune in 1-D: the slide's example, step by step
=========================================================

The chapter's sweep sorts the 2n end points of the intervals [b_i, e_i] and walks them once, keeping a list of
the *active* intervals (begun, not yet ended). When an interval begins, it overlaps every active one; when it
ends, it leaves the list. On the slide's six intervals the sweep reports 8 pairs — exactly the overlapping ones,
with 12 events instead of the 15 tests of brute force.
"""
import matplotlib.pyplot as plt
import numpy as np

import engine
from engine.broadphase.sweep_and_prune import SLIDE_EXAMPLE

labels = sorted(SLIDE_EXAMPLE)
begin = np.array([SLIDE_EXAMPLE[k][0] for k in labels])
end = np.array([SLIDE_EXAMPLE[k][1] for k in labels])
pairs = engine.sweep_intervals(begin, end)  # indices into the arrays, canonical (i < j)
print(engine.broadphase.sap_example_trace())

fig, ax = plt.subplots(figsize=(8, 3.6))
for row, (b, e, k) in enumerate(zip(begin, end, labels)):
    ax.plot([b, e], [row, row], lw=6, solid_capstyle="butt", color=f"C{row}")
    ax.text(b - 0.3, row, f"{k}", ha="right", va="center")
events = sorted([(b, 0, k) for b, k in zip(begin, labels)] + [(e, 1, k) for e, k in zip(end, labels)])
for x, kind, _ in events:  # the sorted list of end points that the sweep walks
    ax.axvline(x, color="0.85", lw=0.8, zorder=0)
ax.set_yticks([])
ax.set_xlabel("x")
ax.set_title(f"{len(events)} events swept, {len(pairs)} pairs reported: "
             + ", ".join(f"({labels[i]}, {labels[j]})" for i, j in pairs))
fig.tight_layout()
