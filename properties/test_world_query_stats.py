"""``World.stats`` after ``pairs()`` and ``contacts()`` (engine.world.world.WorldStats): the query's name, the live
bodies (grounds excluded, removed bodies not counted), candidates >= narrow tests >= overlapping pairs, the
overlapping pairs and contact points of the answer, and narrow tests per kind pair summing to the narrow tests.

Scenes: spheres on a line (each overlapping the next when their spacing is small), some removed, optionally a
Plane ground under them.
"""
from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from engine import Plane, Sphere, World


@given(n=st.integers(1, 8), spacing=st.floats(0.5, 3.0), removed=st.sets(st.integers(0, 7), max_size=3),
       ground=st.booleans())
def test_stats_of_pairs_and_contacts_count_the_live_bodies_and_the_answer(n, spacing, removed, ground):
    w = World()
    ids = [w.add(Sphere([spacing * k, 0.0, 0.4], 0.5)) for k in range(n)]
    if ground:
        w.add(Plane(0.0))
    for k in sorted(removed):
        if k < n:
            w.remove(ids[k])
    live = n - len([k for k in removed if k < n])
    pairs = w.pairs()
    s = w.stats
    assert (s.query, s.bodies, s.overlapping) == ("pairs", live, pairs.shape[0])
    assert s.candidate_pairs >= s.narrow_tests >= s.overlapping
    assert sum(s.groups.values()) == s.narrow_tests
    cs = w.contacts()
    s = w.stats
    assert (s.query, s.bodies, s.overlapping, s.contacts) == ("contacts", live, len(cs), cs.points.shape[0])
    assert s.candidate_pairs >= s.narrow_tests >= s.overlapping
    assert np.array_equal(cs.pairs, pairs)
