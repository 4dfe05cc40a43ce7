"""``World.update`` refuses an id given several times by naming its first two places:
``ids[second] = v repeats ids[first]`` (engine.world.bodies.BodyStore.check_ids), however many times it repeats
and wherever the other ids are. The ids are sorted to find the repeat; only a stable sort keeps the places of
equal ids in order (numpy's default sort does not, for arrays of a few tens of entries already).
"""
from __future__ import annotations

import re

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from engine import Sphere, World


@given(data=st.data(), n=st.integers(8, 48), times=st.integers(3, 6))
def test_a_repeated_id_is_named_at_its_first_two_places(data, n, times):
    w = World()
    bodies = [w.add(Sphere([3.0 * k, 0.0, 0.0], 1.0)) for k in range(n)]
    order = data.draw(st.permutations(bodies))
    places = sorted(data.draw(st.sets(st.integers(0, n - 1), min_size=times, max_size=times)))
    ids = np.array(order, dtype=np.int64)
    v = int(ids[places[0]])
    ids[places] = v  # v at `times` places, every other id once
    with pytest.raises(ValueError, match=re.escape(f"ids[{places[1]}] = {v} repeats ids[{places[0]}]")):
        w.update(ids, np.zeros((n, 3)))
