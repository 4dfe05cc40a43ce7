"""Stateful properties: random insert / remove / move sequences on the dynamic AABB tree and on incremental
sweep-and-prune; after every step the pairs equal brute force on the live boxes."""
from __future__ import annotations

import numpy as np
from hypothesis import settings
from hypothesis import strategies as st
from hypothesis.stateful import Bundle, RuleBasedStateMachine, consumes, invariant, precondition, rule

from engine.broadphase import DynamicAABBTree, IncrementalSAP, find_pairs

DIM = 3
coordinate = st.integers(-12, 12).map(float) | st.floats(-12, 12, allow_nan=False)
extent = st.sampled_from([0.0, 0.5, 1.0, 2.0, 3.0]) | st.floats(0, 4, allow_nan=False)


@st.composite
def boxes(draw, d=DIM):
    lo = np.array([draw(coordinate) for _ in range(d)])
    hi = lo + np.array([draw(extent) for _ in range(d)])
    return lo, hi


def brute_pairs_of_ids(boxes_by_id):
    """Brute force on the live boxes, reported as canonical pairs of ids."""
    ids = sorted(boxes_by_id)
    if len(ids) < 2:
        return []
    lo = np.array([boxes_by_id[i][0] for i in ids])
    hi = np.array([boxes_by_id[i][1] for i in ids])
    ids = np.array(ids)
    return sorted((int(ids[a]), int(ids[b])) for a, b in find_pairs(lo, hi, "brute").tolist())


class _Machine(RuleBasedStateMachine):
    objects = Bundle("objects")

    def __init__(self):
        super().__init__()
        self.model: dict[int, tuple[np.ndarray, np.ndarray]] = {}

    def check_pairs(self, got):
        got = got.tolist()
        assert got == sorted(got)
        assert [tuple(p) for p in got] == brute_pairs_of_ids(self.model)


class DynamicTreeMachine(_Machine):
    def __init__(self):
        super().__init__()
        self.tree = DynamicAABBTree(dim=DIM, margin=None)

    @rule(target=_Machine.objects, box=boxes())
    def insert(self, box):
        obj = self.tree.insert(*box)
        assert obj not in self.model
        self.model[obj] = box
        return obj

    @rule(obj=consumes(_Machine.objects))
    def remove(self, obj):
        self.tree.remove(obj)
        del self.model[obj]

    @rule(obj=_Machine.objects, box=boxes())
    def move(self, obj, box):
        self.tree.move(obj, *box)
        self.model[obj] = box

    @rule(obj=_Machine.objects, step=st.floats(-0.3, 0.3, allow_nan=False))
    def nudge(self, obj, step):  # small moves stay inside the fat box
        lo, hi = self.model[obj]
        box = (lo + step, hi + step)
        self.tree.move(obj, *box)
        self.model[obj] = box

    @precondition(lambda self: len(self.model) > 0)
    @rule()
    def rebuild(self):
        self.tree.rebuild()

    @rule(q=boxes())
    def query(self, q):
        expected = sorted(i for i, (lo, hi) in self.model.items() if np.all(lo <= q[1]) and np.all(q[0] <= hi))
        assert self.tree.query(*q).tolist() == expected

    @invariant()
    def pairs_equal_brute_force(self):
        self.tree.check_structure()
        assert len(self.tree) == len(self.model)
        self.check_pairs(self.tree.pairs())


class IncrementalSAPMachine(_Machine):
    def __init__(self):
        super().__init__()
        self.sap = IncrementalSAP(dim=DIM)

    @rule(target=_Machine.objects, box=boxes())
    def add(self, box):
        obj = self.sap.add(*box)
        assert obj not in self.model
        self.model[obj] = box
        return obj

    @rule(obj=consumes(_Machine.objects))
    def remove(self, obj):
        self.sap.remove(obj)
        del self.model[obj]

    @rule(obj=_Machine.objects, box=boxes())
    def move(self, obj, box):
        self.sap.move(obj, *box)
        self.model[obj] = box

    @precondition(lambda self: len(self.model) > 0)
    @rule(shift=st.lists(st.floats(-2, 2, allow_nan=False), min_size=1, max_size=40))
    def update_all(self, shift):
        ids = sorted(self.model)
        lo = np.array([self.model[i][0] for i in ids])
        hi = np.array([self.model[i][1] for i in ids])
        delta = np.resize(np.array(shift), len(ids))[:, None]
        lo, hi = lo + delta, hi + delta
        for row, i in enumerate(ids):
            self.model[i] = (lo[row], hi[row])
        self.check_pairs(self.sap.update(lo, hi))

    @invariant()
    def pairs_equal_brute_force(self):
        assert len(self.sap) == len(self.model)
        assert self.sap.ids().tolist() == sorted(self.model)
        self.check_pairs(self.sap.pairs())


TestDynamicTree = DynamicTreeMachine.TestCase
TestDynamicTree.settings = settings(max_examples=60, stateful_step_count=40, deadline=None)
TestIncrementalSAP = IncrementalSAPMachine.TestCase
TestIncrementalSAP.settings = settings(max_examples=60, stateful_step_count=40, deadline=None)


def test_tree_from_boxes_and_update():
    rng = np.random.default_rng(0)
    lo = rng.uniform(-10, 10, (50, 2))
    hi = lo + rng.uniform(0, 3, (50, 2))
    tree = DynamicAABBTree.from_boxes(lo, hi)
    tree.check_structure()
    np.testing.assert_array_equal(tree.pairs(), find_pairs(lo, hi, "brute"))
    lo2, hi2 = lo + 0.7, hi + 0.9
    np.testing.assert_array_equal(tree.update(lo2, hi2), find_pairs(lo2, hi2, "brute"))
    tree.check_structure()


def test_incremental_sap_repairs_by_insertion_sort():
    rng = np.random.default_rng(1)
    lo = rng.uniform(-10, 10, (200, 3))
    hi = lo + 1.0
    sap = IncrementalSAP(lo, hi)
    sap.pairs()
    assert sap.last_swaps == 0
    step = rng.normal(0, 0.05, lo.shape)
    np.testing.assert_array_equal(sap.update(lo + step, hi + step), find_pairs(lo + step, hi + step, "brute"))
    assert 0 < sap.last_swaps < 200  # nearly sorted: few swaps


def test_tree_query_skips_free_slots():
    # regression: a node slot that is not a live leaf (free, or never built) must be ignored, whatever it holds
    from engine.broadphase.aabb_tree import tree_leaf_pairs

    rng = np.random.default_rng(3)
    lo = rng.uniform(-5, 5, (30, 3))
    hi = lo + 1.5
    tree = DynamicAABBTree.from_boxes(lo, hi, margin=0.0)
    extra = tree._node_lo.shape[0]
    node_lo = np.vstack([tree._node_lo, np.full((2, 3), -1e9)])
    node_hi = np.vstack([tree._node_hi, np.full((2, 3), 1e9)])
    child1 = np.concatenate([tree._child1, [-1, -1]])
    child2 = np.concatenate([tree._child2, [-1, -1]])
    obj_of = np.concatenate([tree._obj_of, [10**9, -5]])  # garbage in the extra slots
    got = tree_leaf_pairs(tree._root, node_lo, node_hi, child1, child2, obj_of, tree._obj_lo, tree._obj_hi,
                             tree._obj_node, 30)[0]
    assert extra > 0
    np.testing.assert_array_equal(got, find_pairs(lo, hi, "brute"))
