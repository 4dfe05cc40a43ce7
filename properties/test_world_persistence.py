"""Persistent contacts: a contact point's id (which feature of each shape made it) stays the same while the same
features touch, and changes when they change; ``persists`` says which points were already there the frame
before (Box2D's ``b2ContactFeature``, Bullet's manifold point cache — what a solver warm-starts from).

Each property drives one pair through two frames:
- a motion that keeps the same features in contact (a box sliding and turning a little on the ground or on a
  larger box, a sphere rolling within a face, a capsule sliding along the ground, a hull pressing a little
  more) gives the same ids, all persisting;
- a motion that changes them (the box tilted onto an edge, turned by a quarter turn so that other corners
  touch, slid until a corner leaves the face below; the sphere moved over the face's edge) gives new ids
  for the points whose features changed — those do not persist — while the points whose features did not
  change keep theirs.
"""
from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from engine import Box, Capsule, ConvexPolyhedron, Plane, Sphere, World
from engine.world import describe_point_id

small = st.floats(-0.05, 0.05, allow_nan=False)


def _frame(w):
    c = w.contacts()
    assert len(c) == 1, c.pairs
    return dict(zip(c.ids_of(0).tolist(), c.persists[c.point_offsets[0]:c.point_offsets[1]].tolist()))


def _yaw(angle):
    return Rotation.from_euler("y", angle).as_matrix()


@given(small, small, st.floats(-0.2, 0.2), st.floats(0.0, 0.05), st.sampled_from(["tree", "sap", "grid"]))
@settings(max_examples=60)
def test_box_on_the_ground_keeps_its_corners(dx, dz, yaw, press, broad_phase):
    w = World(broad_phase)
    box = w.add(Box([0.0, 0.49, 0.0], [0.5, 0.5, 0.5]))
    w.add(Plane(0.0))
    first = _frame(w)
    assert len(first) == 4 and not any(first.values())
    w.move(box, center=[dx, 0.5 - 0.01 - press, dz], rotation=_yaw(yaw))
    second = _frame(w)
    assert second.keys() == first.keys() and all(second.values())
    assert w.stats.persisting == 4
    # tilted onto one bottom edge: two of the corners lift off, the other two keep their ids
    w.move(box, rotation=Rotation.from_euler("x", 0.2).as_matrix())
    tilted = _frame(w)
    assert len(tilted) == 2 and set(tilted) < set(first) and all(tilted.values())
    # a quarter turn about x: another face (other vertex numbers) stands on the ground
    w.move(box, center=[0.0, 0.49, 0.0], rotation=Rotation.from_euler("x", np.pi / 2).as_matrix())
    turned = _frame(w)
    assert len(turned) == 4 and set(turned) != set(first)
    assert not any(turned[i] for i in set(turned) - set(tilted))


@given(small, small, st.floats(-0.1, 0.1), st.sampled_from(["tree", "sap"]))
@settings(max_examples=60)
def test_box_on_a_box_keeps_its_manifold_until_a_corner_leaves(dx, dz, yaw, broad_phase):
    w = World(broad_phase)
    w.add(Box([0.0, 0.0, 0.0], [2.0, 0.5, 2.0]))
    top = w.add(Box([0.0, 0.99, 0.0], [0.5, 0.5, 0.5]))
    first = _frame(w)
    assert len(first) == 4
    w.move(top, center=[dx, 0.99, dz], rotation=_yaw(yaw))
    second = _frame(w)
    assert second.keys() == first.keys() and all(second.values())
    # slid until it overhangs the edge of the lower box: its corners beyond the edge leave, clipped points on
    # the lower box's edge appear with new ids (edge of the lower box, edge of the upper one)
    w.move(top, center=[1.8, 0.99, dz], rotation=_yaw(yaw))
    over = _frame(w)
    new = set(over) - set(first)
    assert new and not any(over[i] for i in new)
    assert all(over[i] for i in set(over) & set(first))
    assert all(describe_point_id(i).startswith("edge") for i in new)


@given(small, small, st.floats(0.0, 0.05))
@settings(max_examples=60)
def test_sphere_rolling_on_a_face_keeps_its_id(dx, dz, press):
    w = World()
    w.add(Box([0.0, 0.0, 0.0], [1.0, 0.5, 1.0]))
    ball = w.add(Sphere([0.0, 0.99, 0.0], 0.5))
    (first,) = _frame(w)
    assert describe_point_id(first).startswith("face 3")  # the box (the pair's first) by its +y face
    w.move(ball, center=[dx, 0.99 - press, dz])
    assert _frame(w) == {first: True}
    w.move(ball, center=[1.2, 0.9, dz])  # over the box's +x edge: another feature
    ((moved, persists),) = _frame(w).items()
    assert moved != first and not persists and describe_point_id(moved).startswith("edge")


@given(small, st.floats(-0.3, 0.3), st.floats(0.0, 0.05))
@settings(max_examples=40)
def test_capsule_lying_on_the_ground(dx, yaw, press):
    w = World()
    rod = w.add(Capsule([-1.0, 0.29, 0.0], [1.0, 0.29, 0.0], 0.3))
    w.add(Plane(0.0))
    first = _frame(w)
    assert len(first) == 2
    w.move(rod, center=[dx, 0.29 - press, 0.0], rotation=_yaw(yaw))
    second = _frame(w)
    assert second.keys() == first.keys() and all(second.values())
    w.move(rod, rotation=Rotation.from_euler("z", 0.3).as_matrix())  # one end lifted
    lifted = _frame(w)
    assert len(lifted) == 1 and set(lifted) < set(first) and all(lifted.values())


@given(st.integers(0, 2**16), small, small, st.floats(0.0, 0.02))
@settings(max_examples=40)
def test_hull_pair_keeps_its_features(seed, dx, dz, press):
    """Two hulls (the GJK/EPA path): a small translation that keeps the same support features keeps the ids."""
    rng = np.random.default_rng(seed)
    pts = rng.normal(size=(12, 3))
    pts /= np.linalg.norm(pts, axis=1, keepdims=True)
    w = World()
    a = w.add(ConvexPolyhedron(np.concatenate([pts, [[0.0, 0.0, 0.0]]]) * 1.0))
    top = pts[np.argmax(pts[:, 1])]
    b = w.add(ConvexPolyhedron(-pts + 2.0 * 0.995 * top))  # A turned over, its tip pressed into A's top vertex
    c0, _, _ = w.pose(b)
    first = _frame(w)
    w.move(b, center=c0 - press * top)  # pressed towards A's centre: the tip 0.995 top goes deeper inside A
    second = _frame(w)
    assert all(second[i] for i in set(second) & set(first))  # the points whose features stayed persist ...
    assert not any(second[i] for i in set(second) - set(first))  # ... the others are new
    w.move(b, center=c0 - press * top + [1e-9 * dx, 0.0, 1e-9 * dz])  # a nudge far below every tolerance
    third = _frame(w)
    assert third.keys() == second.keys() and all(third.values())
    assert a in w.contacts().pairs[0]
