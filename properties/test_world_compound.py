"""Properties of ``Compound`` bodies in ``engine.World``: a compound is its parts, moved as one.

- the same scene built twice — once with compounds, once with each part as a body of its own at the same world
  pose (the parts of one compound excluded from each other) — gives the same ``pairs()`` (parts mapped to their
  compound), and per (body pair, part pair) the same contacts (depth, normal, points, features, point ids), against
  grounds and between compounds, after ``move`` and ``update`` with rotations; its ``time_of_impact`` is the
  earliest of its parts'. Both worlds run the same kernels on the same poses: the answers agree to round-off.
  The parts' world poses are checked apart, against the compound's pose composed with each part's (numpy).
- ``Compound.from_mesh`` on a concave (U-shaped) closed mesh: every vertex of the mesh lies in a part, and a
  sphere in the notch of the U touches it or not as its distance to the U says — where the convex hull of the
  mesh would touch it.
"""
from __future__ import annotations

import copy
import functools

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from engine import BROAD_PHASES, Box, Compound, ConvexPolyhedron, Plane, Sphere, World, gjk_distance
from properties.strategies.geometry import rotations
from properties.strategies.world import any_bodies_near, compounds_near, ground_kinds, registered_shapes

#: a scene of side ~3: the parts of compounds and the bodies about them touch often
CENTERS = st.tuples(*[st.floats(-1.5, 1.5, allow_nan=False)] * 3).map(np.array)
#: grounds of every static-only kind, near the scene (their level in [-1.5, 0])
NEAR_GROUNDS = registered_shapes(ground_kinds, st.tuples(st.just(0.0), st.floats(-1.5, 0.0),
                                                         st.just(0.0)).map(np.array))
VELOCITIES = st.tuples(*[st.floats(-2.0, 2.0, allow_nan=False)] * 3).map(np.array)
#: round-off allowed between the two worlds (the same kernels on the same poses: in practice none)
RTOL = 1e-12


def part_rows(world, body):
    """The store rows of a compound's parts, in part order."""
    b = world.bodies()
    rows = np.flatnonzero(b.owner == body)
    return rows[np.argsort(b.part[rows])]


class Twins:
    """One scene as two worlds: ``whole`` with the compounds, ``split`` with each part as a body of its own at
    the same world pose. ``items[k]`` = (id in ``whole``, ids in ``split`` (one per part, or the body's own));
    ``origin[split id]`` = (id in ``whole``, part number)."""

    def __init__(self, broad_phase, ground, shapes, static):
        self.whole, self.split = World(broad_phase), World(broad_phase)
        self.items, self.origin, self.static = [], {}, []
        if ground is not None:  # added first: id 0 in both worlds
            g = self.whole.add(ground)
            assert self.split.add(ground) == g
            self.origin[g] = (g, 0)
        for shape, still in zip(shapes, static):
            w = self.whole.add(shape, static=still)
            if isinstance(shape, Compound):
                ids = []
                for row, (part, _, _) in zip(part_rows(self.whole, w), shape.parts):
                    placed = copy.copy(part)  # the part's geometry at its world pose, read off the store
                    placed.center = self.whole.bodies().center[row].copy()
                    placed.rotation = self.whole.bodies().rotation[row].copy()
                    ids.append(self.split.add(placed, static=still))
                for x, a in enumerate(ids):
                    for b in ids[x + 1:]:
                        self.split.exclude(a, b)
            else:
                ids = [self.split.add(shape, static=still)]
            self.items.append((w, ids))
            self.static.append(still)
            for k, s in enumerate(ids):
                self.origin[s] = (w, k if isinstance(shape, Compound) else 0)
        self.check_poses()

    def compound(self, k) -> bool:
        return isinstance(self.whole.shape(self.items[k][0]), Compound)

    def sync(self, k):
        """Move item k's parts in ``split`` to their poses in ``whole`` (after the compound moved)."""
        w, ids = self.items[k]
        rows = part_rows(self.whole, w)
        b = self.whole.bodies()
        self.split.update(ids, b.center[rows], rotations=b.rotation[rows], velocities=b.velocity[rows])

    def check_poses(self):
        """Each part's world pose is its compound's pose composed with its own (numpy, independently), and
        ``world_points(compound, part=k)`` are the points of its twin."""
        b = self.whole.bodies()
        for (w, ids) in self.items:
            shape = self.whole.shape(w)
            if not isinstance(shape, Compound):
                continue
            center, rotation, velocity = self.whole.pose(w)
            for k, (row, (part, position, turn)) in enumerate(zip(part_rows(self.whole, w), shape.parts)):
                scale = 1.0 + np.abs(center).max() + np.abs(position).max()
                np.testing.assert_allclose(b.center[row], center + rotation @ position, rtol=0, atol=1e-12 * scale)
                np.testing.assert_allclose(b.rotation[row], rotation @ turn, rtol=0, atol=1e-12)
                np.testing.assert_array_equal(b.velocity[row], velocity)
                np.testing.assert_array_equal(self.whole.world_points(w, part=k), self.split.world_points(ids[k]))
                assert self.whole.radius(w, part=k) == self.split.radius(ids[k]) == part.radius

    def split_contacts(self):
        """``split``'s contacts, rows mapped to (whole i, whole j, part_a, part_b) and sorted as ``whole``'s."""
        cs = self.split.contacts()
        keys = []
        for x, y in cs.pairs.tolist():
            (i, pa), (j, pb) = self.origin[x], self.origin[y]
            assert i < j  # the ids of both worlds are in the same order: the kernels see the same pair order
            keys.append((i, j, pa, pb))
        order = sorted(range(len(keys)), key=keys.__getitem__)
        return cs, [keys[r] for r in order], order

    def check(self):
        self.check_poses()
        got = self.whole.pairs()
        mapped = {(self.origin[x][0], self.origin[y][0]) for x, y in self.split.pairs().tolist()}
        assert [tuple(p) for p in got.tolist()] == sorted(mapped)
        whole = self.whole.contacts()
        split, keys, order = self.split_contacts()
        assert list(zip(whole.pairs[:, 0].tolist(), whole.pairs[:, 1].tolist(), whole.part_a.tolist(),
                        whole.part_b.tolist())) == keys
        for name in ("depth", "separation", "normal"):
            np.testing.assert_allclose(getattr(whole, name), getattr(split, name)[order], rtol=RTOL,
                                       atol=RTOL, err_msg=name)
        for name in ("feature_a", "feature_b", "radius_a", "radius_b"):
            np.testing.assert_array_equal(getattr(whole, name), getattr(split, name)[order], err_msg=name)
        counts = np.diff(split.point_offsets)[order]
        np.testing.assert_array_equal(np.diff(whole.point_offsets), counts)
        rows = np.concatenate([np.arange(split.point_offsets[r], split.point_offsets[r + 1]) for r in order] +
                              [np.zeros(0, np.int64)]).astype(np.int64)
        np.testing.assert_allclose(whole.points, split.points[rows], rtol=RTOL, atol=RTOL)
        np.testing.assert_array_equal(whole.point_ids, split.point_ids[rows])
        np.testing.assert_array_equal(whole.persists, split.persists[rows])

    def check_impacts(self, dt):
        whole = self.whole.time_of_impact(dt)
        earliest: dict = {}
        split = self.split.time_of_impact(dt)
        for (x, y), t in zip(split.pairs.tolist(), split.times.tolist()):
            key = (self.origin[x][0], self.origin[y][0])
            earliest[key] = min(t, earliest.get(key, np.inf))
        assert [tuple(p) for p in whole.pairs.tolist()] == sorted(earliest)
        np.testing.assert_allclose(whole.times, [earliest[k] for k in sorted(earliest)], rtol=RTOL, atol=RTOL)


@st.composite
def scenes(draw):
    """A ground or none, 1-3 compounds and 0-3 other bodies (every bounded kind) in a drawn order, some static."""
    shapes = draw(st.lists(compounds_near(CENTERS), min_size=1, max_size=3))
    shapes += draw(st.lists(any_bodies_near(CENTERS), max_size=3))
    shapes = draw(st.permutations(shapes))
    static = draw(st.lists(st.sampled_from([False, False, True]), min_size=len(shapes), max_size=len(shapes)))
    return draw(st.none() | NEAR_GROUNDS), shapes, static


@given(scenes(), st.sampled_from(BROAD_PHASES), st.data())
def test_a_compound_is_its_parts(scene, broad_phase, data):
    ground, shapes, static = scene
    twins = Twins(broad_phase, ground, shapes, static)
    twins.check()
    moving = [k for k, still in enumerate(static) if not still]
    if not moving:
        return
    # move: one body at a time, a new centre and rotation
    for k in data.draw(st.lists(st.sampled_from(moving), unique=True, min_size=1), label="moved"):
        center, rotation = data.draw(CENTERS, label="center"), data.draw(st.none() | rotations(), label="rotation")
        w, ids = twins.items[k]
        twins.whole.move(w, center=center, rotation=rotation)
        if twins.compound(k):
            twins.sync(k)
        else:
            twins.split.move(ids[0], center=center, rotation=rotation)
    twins.check()
    # update: a batch, quaternions, and velocities for the time of impact
    chosen = data.draw(st.lists(st.sampled_from(moving), unique=True, min_size=1), label="updated")
    rng = np.random.default_rng(data.draw(st.integers(0, 2**16), label="seed"))
    centers = rng.uniform(-1.5, 1.5, (len(chosen), 3))
    q = rng.normal(size=(len(chosen), 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    v = np.array([data.draw(VELOCITIES, label="velocity") for _ in chosen])
    twins.whole.update([twins.items[k][0] for k in chosen], centers, rotations=q, velocities=v)
    for row, k in enumerate(chosen):
        if twins.compound(k):
            twins.sync(k)
        else:
            twins.split.update(twins.items[k][1], centers[row:row + 1], rotations=q[row:row + 1],
                               velocities=v[row:row + 1])
    twins.check()
    twins.check_impacts(1.0)


def test_compounds_against_each_other_and_the_ground_after_turns():
    """Two compounds interlocked above a plane, turned step by step: compound–compound and compound–plane rows."""
    rng = np.random.default_rng(7)
    parts = [Box(np.zeros(3), [0.8, 0.2, 0.2]), Sphere(np.zeros(3), 0.35), ConvexPolyhedron(rng.normal(size=(9, 3)))]
    a = Compound(parts, [[0.0, 0.0, 0.0], [0.9, 0.0, 0.0], [-0.9, 0.3, 0.0]], center=[0.0, 0.3, 0.0])
    b = Compound(parts[:2], [[0.0, 0.0, 0.0], [0.0, 0.6, 0.0]], center=[0.5, 0.5, 0.1])
    twins = Twins("tree", Plane(0.0), [a, b], [False, False])
    (ia, _), (ib, _) = twins.items
    seen = set()
    for step in range(12):
        angle = 0.3 * step
        turn = np.array([[np.cos(angle), 0.0, np.sin(angle)], [0.0, 1.0, 0.0], [-np.sin(angle), 0.0, np.cos(angle)]])
        w, _ = twins.items[1]
        twins.whole.move(w, center=[0.5, 0.15 + 0.05 * step, 0.1], rotation=turn)
        twins.sync(1)
        twins.check()
        rows = twins.whole.contacts()
        seen |= {(i, j, pa, pb) for (i, j), pa, pb in zip(rows.pairs.tolist(), rows.part_a.tolist(),
                                                          rows.part_b.tolist())}
    # the compounds touched each other by several pairs of parts, and the plane by several parts of each
    assert len({(pa, pb) for i, j, pa, pb in seen if (i, j) == (ia, ib)}) >= 2
    assert len({pb for i, j, pa, pb in seen if (i, j) == (0, ia)}) >= 2
    assert len({pb for i, j, pa, pb in seen if (i, j) == (0, ib)}) >= 1


# ---------------------------------------------------------------------------------------------------------------
# Compound.from_mesh on a concave mesh
# ---------------------------------------------------------------------------------------------------------------

#: a U in the xy-plane (outline counter-clockwise), extruded over z in [-0.5, 0.5]: the notch is x in [1, 2],
#: y in [1, 3]
U_OUTLINE = np.array([(0, 0), (3, 0), (3, 3), (2, 3), (2, 1), (1, 1), (1, 3), (0, 3)], float)
U_DEPTH = 0.5
#: the outline's triangles (convex quads of the U, split): every one counter-clockwise seen from +z
U_CAP = [(0, 1, 4), (0, 4, 5), (1, 2, 3), (1, 3, 4), (0, 5, 6), (0, 6, 7)]


def u_mesh():
    """The U's closed triangle mesh: (16, 3) vertices, (28, 3) outward triangles."""
    n = len(U_OUTLINE)
    verts = np.concatenate([np.c_[U_OUTLINE, np.full(n, -U_DEPTH)], np.c_[U_OUTLINE, np.full(n, U_DEPTH)]])
    tris = [t for a, b, c in U_CAP for t in ((a + n, b + n, c + n), (a, c, b))]
    tris += [t for k in range(n) for t in ((k, (k + 1) % n, (k + 1) % n + n), (k, (k + 1) % n + n, k + n))]
    return verts, np.array(tris, np.int64)


def u_distance(p):
    """Distance from p to the solid U (the union of its three boxes)."""
    boxes = [((0, 0), (3, 1)), ((0, 1), (1, 3)), ((2, 1), (3, 3))]
    best = np.inf
    for (x0, y0), (x1, y1) in boxes:
        lo, hi = np.array([x0, y0, -U_DEPTH]), np.array([x1, y1, U_DEPTH])
        best = min(best, float(np.linalg.norm(np.maximum(0.0, np.maximum(lo - p, p - hi)))))
    return best


@functools.cache
def u_compound():
    pytest.importorskip("coacd")
    return Compound.from_mesh(*u_mesh())


def test_u_mesh_is_closed_and_outward():
    verts, tris = u_mesh()
    edges = {}
    for t in tris.tolist():
        for a, b in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0])):
            edges[(a, b)] = edges.get((a, b), 0) + 1
    assert all(n == 1 and edges.get((b, a)) == 1 for (a, b), n in edges.items())  # closed, consistently wound
    v = verts[tris]
    volume = np.einsum("ij,ij->i", v[:, 0], np.cross(v[:, 1], v[:, 2])).sum() / 6.0
    assert volume == pytest.approx(3.0 + 2.0 + 2.0)


def test_from_mesh_parts_cover_the_mesh_vertices():
    """Each vertex of the U is in (or on) a part: GJK distance ~0 to one part's hull at least; each part lies in
    the U (no part bridges the notch)."""
    compound = u_compound()
    world = World()
    c = world.add(compound)
    n = len(compound.parts)
    assert n >= 2  # concave: one convex piece cannot be it
    verts, _ = u_mesh()
    hulls = [world.world_points(c, part=k) for k in range(n)]
    for v in verts:
        gap = min(gjk_distance(v[None], h)[0] for h in hulls)
        assert gap <= 1e-6, (v, gap)
    for h in hulls:
        assert max(u_distance(p) for p in h) <= 1e-6


@given(rotations(), st.tuples(*[st.floats(-5.0, 5.0)] * 3).map(np.array), st.floats(1.2, 2.8),
       st.floats(-0.3, 0.3), st.floats(0.1, 0.45), st.sampled_from(BROAD_PHASES))
def test_a_sphere_in_the_notch_of_a_decomposed_u(turn, shift, height, offset, radius, broad_phase):
    """A sphere in the U's notch (its centre at height ``height``, ``offset`` from the notch's middle plane)
    touches the U exactly when its distance to the U is below its radius (a margin of 2e-3 either way, coacd's
    pieces being float32); the convex hull of the mesh, which fills the notch, touches it always. The whole scene
    is moved by a rigid motion."""
    compound = u_compound()
    center = np.array([1.5 + offset, height, 0.0])
    gap = u_distance(center) - radius
    if abs(gap) < 2e-3:
        return
    world, hull_world = World(broad_phase), World(broad_phase)
    c = world.add(compound)
    world.move(c, center=shift, rotation=turn)
    ball = world.add(Sphere(shift + turn @ center, radius))
    verts, _ = u_mesh()
    hull = hull_world.add(ConvexPolyhedron(verts @ turn.T + shift))
    hull_ball = hull_world.add(Sphere(shift + turn @ center, radius))
    touching = (min(c, ball), max(c, ball)) in {tuple(p) for p in world.pairs().tolist()}
    assert touching == (gap < 0), (gap, touching)
    assert {tuple(p) for p in hull_world.pairs().tolist()} == {(min(hull, hull_ball), max(hull, hull_ball))}
    contacts = world.contacts()
    if gap >= 0:
        assert len(contacts) == 0
    else:  # the centre is outside every part: the deepest part is the nearest, depth = radius - distance
        assert {tuple(p) for p in contacts.pairs.tolist()} == {(min(c, ball), max(c, ball))}
        np.testing.assert_allclose(contacts.depth.max(), -gap, atol=2e-3)
