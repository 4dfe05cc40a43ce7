"""Bad input to ``World.update``: a ValueError naming the argument and the index, the world unchanged, the
caller's arrays never modified.

One batch of a random world is corrupted in one place — a NaN or an infinity in ``centers`` or ``velocities``,
a non-unit quaternion or a non-orthonormal / reflecting matrix in ``rotations``, an id never added, removed,
of a ground, or repeated — and the update must raise ValueError whose message names the argument and the index
(``centers[3, 1]``, ``rotations[2] must be a unit quaternion in (w, x, y, z) order``, ``ids[4] = 7 repeats
ids[1]``), leave every array of the body store, the pairs and the contacts as they were, and leave the caller's
arrays untouched. A valid batch after the failure then gives the same world as if the bad one never happened.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from engine import BROAD_PHASES, Box, Plane, Sphere, World
from engine.workloads import random_quaternions

CORRUPTIONS = ("center nan", "center inf", "velocity nan", "quaternion norm", "matrix skew", "matrix reflection",
               "unknown id", "removed id", "ground id", "duplicate id", "scipy length")


def _world(n, seed, broad_phase):
    rng = np.random.default_rng(seed)
    w = World(broad_phase)
    for i in range(n):
        w.add(Sphere(rng.uniform(-2, 2, 3), 0.5) if i % 2 else Box(rng.uniform(-2, 2, 3), [0.4, 0.3, 0.5]))
    w.add(Plane(-1.0))
    gone = w.add(Sphere([9.0, 9.0, 9.0], 0.1))
    w.remove(gone)
    w.contacts()
    return w, gone, rng


def _snapshot(w):
    return [a.copy() for a in w.bodies()], w.pairs(), w.contacts()


def _same(w, snap):
    arrays, pairs, contacts = snap
    for before, now in zip(arrays, w.bodies()):
        np.testing.assert_array_equal(before, now)
    np.testing.assert_array_equal(pairs, w.pairs())
    now = w.contacts()
    for name in ("pairs", "depth", "normal", "points", "point_ids"):
        np.testing.assert_array_equal(getattr(contacts, name), getattr(now, name))


@given(st.integers(2, 8), st.integers(0, 2**16), st.sampled_from(CORRUPTIONS), st.data(),
       st.sampled_from(BROAD_PHASES), st.sampled_from(["quaternions", "matrices"]))
@settings(max_examples=80)
def test_bad_batches_name_the_index_and_change_nothing(n, seed, corruption, data, broad_phase, form):
    w, gone, rng = _world(n, seed, broad_phase)
    k = data.draw(st.integers(2, n))
    ids = np.array(sorted(rng.choice(n, size=k, replace=False)), dtype=np.int64)
    centers = rng.uniform(-2, 2, (k, 3))
    velocities = rng.normal(size=(k, 3))
    q = random_quaternions(k, rng)
    rotations = q if form == "quaternions" else Rotation.from_quat(q, scalar_first=True).as_matrix()
    at = data.draw(st.integers(0, k - 1))
    col = data.draw(st.integers(0, 2))
    if corruption == "center nan":
        centers[at, col] = np.nan
        expected = rf"centers\[{at}, {col}\]"
    elif corruption == "center inf":
        centers[at, col] = -np.inf
        expected = rf"centers\[{at}, {col}\]"
    elif corruption == "velocity nan":
        velocities[at, col] = np.nan
        expected = rf"velocities\[{at}, {col}\]"
    elif corruption == "quaternion norm":
        rotations = q * 1.0
        rotations[at] *= data.draw(st.sampled_from([0.5, 1.0 + 1e-6, 2.0]))
        expected = rf"rotations\[{at}\] must be a unit quaternion in \(w, x, y, z\) order"
    elif corruption == "matrix skew":
        rotations = Rotation.from_quat(q, scalar_first=True).as_matrix()
        rotations[at, col, (col + 1) % 3] += 1e-6
        expected = rf"rotations\[{at}\] must be an orthonormal matrix"
    elif corruption == "matrix reflection":
        rotations = Rotation.from_quat(q, scalar_first=True).as_matrix()
        rotations[at, :, col] *= -1.0
        expected = rf"rotations\[{at}\] must be a proper rotation"
    elif corruption == "unknown id":
        ids[at] = 1000 + at
        expected = rf"ids\[{at}\] = {1000 + at} is not a body of this world"
    elif corruption == "removed id":
        ids[at] = gone
        expected = rf"ids\[{at}\] = {gone} is not a body of this world"
    elif corruption == "ground id":
        ids[at] = n  # the Plane
        expected = rf"ids\[{at}\] = {n} is a ground"
    elif corruption == "duplicate id":
        first = data.draw(st.integers(0, k - 1).filter(lambda i: i != at))
        ids[at] = ids[first]
        lo, hi = sorted((at, first))
        expected = rf"ids\[{hi}\] = {ids[at]} repeats ids\[{lo}\]"
    else:
        rotations = Rotation.from_quat(np.concatenate([q, q[:1]]), scalar_first=True)
        expected = rf"rotations must have shape \({k}, 3, 3\)"
    given_arrays = [np.array(a, copy=True) for a in (ids, centers, velocities)]
    if isinstance(rotations, np.ndarray):
        given_arrays.append(rotations.copy())
    snap = _snapshot(w)
    with pytest.raises(ValueError, match=expected):
        w.update(ids, centers, rotations=rotations, velocities=velocities)
    _same(w, snap)
    for before, now in zip(given_arrays, (ids, centers, velocities, rotations)):
        np.testing.assert_array_equal(before, now)  # the caller's arrays are never modified
    # a valid batch afterwards: the same world as one that never saw the bad batch
    twin, _, _ = _world(n, seed, broad_phase)
    good = np.arange(k, dtype=np.int64)
    for world in (w, twin):
        world.update(good, np.zeros((k, 3)) + np.arange(k)[:, None], rotations=q)
    np.testing.assert_array_equal(w.pairs(), twin.pairs())


def test_move_validation_names_the_argument_and_changes_nothing():
    w, gone, _ = _world(3, 1, "tree")
    snap = _snapshot(w)
    for kwargs, expected in (({"center": [0.0, np.nan, 0.0]}, r"center\[1\]"),
                             ({"rotation": [0.9, 0.0, 0.0, 0.0]}, r"\(w, x, y, z\)"),
                             ({"rotation": np.diag([1.0, 1.0, -1.0])}, "rotation"),
                             ({"velocity": [np.inf, 0.0, 0.0]}, r"velocity\[0\]")):
        with pytest.raises(ValueError, match=expected):
            w.move(0, **kwargs)
        _same(w, snap)
    with pytest.raises(ValueError, match=f"id {gone} is not a body"):
        w.move(gone, center=[0.0, 0.0, 0.0])
    _same(w, snap)


@pytest.mark.parametrize("bad", [1, 7, -1, -2])
def test_ids_never_added_are_refused_by_name_and_index(bad):
    """An id outside [0, number of ids ever given) is "not a body of this world", whichever body holds id 0."""
    world = World()
    body = world.add(Sphere([0.0, 0.0, 0.0], 0.5))
    before = world.pose(body)
    with pytest.raises(ValueError, match=rf"^ids\[1\] = {bad} is not a body of this world"):
        world.update([body, bad], [[1.0, 0.0, 0.0], [2.0, 0.0, 0.0]])
    assert all(np.array_equal(x, y) for x, y in zip(world.pose(body), before))


def test_one_scipy_rotation_turns_the_one_body_updated():
    world = World()
    body = world.add(Box([0.0, 0.0, 0.0], [1.0, 0.5, 0.25]))
    turn = Rotation.from_euler("z", 0.3)
    world.update([body], [[1.0, 2.0, 3.0]], rotations=turn)
    center, rotation, _ = world.pose(body)
    np.testing.assert_array_equal(center, [1.0, 2.0, 3.0])
    np.testing.assert_allclose(rotation, turn.as_matrix(), atol=1e-15)
