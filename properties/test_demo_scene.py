"""``DemoScene.step`` (engine/demo.py), the physics of ``colldet demo``, against independent computations.

- No body ends a frame below the ground: the gap y − f(x) over each body's documented lower boundary (the
  polygon of its supports in the ground's ``samples`` downward directions), its chords sampled densely, against
  the documented formula of the ground (not the engine's ``lower_boundary`` / ``ground_gap``).
- A bounce on a straight ground y = s x (flat for s = 0) matches the closed form of a body under gravity and
  linear drag, v(t) = v e^(−kt) + g φ1(t), x(t) = x + v φ1(t) + g φ2(t) with φ1 = (1 − e^(−kt)) / k and
  φ2 = (t − φ1) / k (series in kt), the impact time a root of the box's gap (its lowest corner against the
  line) found by ``brentq``, then v_n' = −e v_n with the tangential velocity unchanged, and the rest of the
  frame in closed form again; each frame is compared from the scene's own state at its start.
- The same seed gives the same frames, bit for bit; the documented scene and defaults.
- For e <= 1 and drag >= 0, no body's mechanical energy ½|v|² − g·x grows across a frame (bounces included).
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq

from engine import Box, HeightCurve, World
from engine.demo import GRAVITY, DemoScene, build_scene

G = np.array([0.0, -9.81, 0.0])  # the documented gravity (m/s²), written here independently of GRAVITY
REST_SPEED = 0.3  # documented: below e·|v·n| = 0.3 m/s a bounce comes to rest


def documented_ground(x):
    return 0.04 * x ** 2 + 0.5 * np.sin(1.3 * x) - 0.8


def rot_z(angle):
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


# ------------------------------------------------------------------------------------------------ the gap
def outline_gap(world, body, samples=96, f=documented_ground) -> float:
    """min of y − f(x) over the body's lower boundary as the curved ground documents it
    (engine/narrowphase/curve_ground.py):
    the polygon through the supports of its core points swept by its radius in ``samples`` directions spread
    evenly over the lower half-turn [π, 2π] (a vertex of a polytope with a narrower normal cone than π/samples
    lies above that polygon: the ground's narrow test does not see it, by design); each chord sampled every 2e-3,
    where the chord error of f is below h²/8 · max|f''| < 1e-6; f is the documented ground, not the scene's."""
    pts = world.world_points(body)[:, :2]
    theta = np.linspace(np.pi, 2.0 * np.pi, samples)
    d = np.stack([np.cos(theta), np.sin(theta)], axis=1)
    sup = pts[np.argmax(pts @ d.T, axis=0)] + world.radius(body) * d
    edge = sup[1:] - sup[:-1]
    n = np.maximum(1, np.ceil(np.linalg.norm(edge, axis=1) / 2e-3)).astype(np.int64)  # samples per chord
    which = np.repeat(np.arange(edge.shape[0]), n)
    u = (np.arange(which.size) - np.repeat(np.cumsum(n) - n, n)) / n[which]  # 0, 1/n, ..., (n − 1)/n per chord
    xy = np.concatenate([sup[which] + u[:, None] * edge[which], sup[-1:]])
    return float(np.min(xy[:, 1] - f(xy[:, 0])))


def lower_bodies(scene, heights):
    """Move each body straight down (or up) so that its outline's gap to the ground is the given height."""
    centers = np.array([scene.world.pose(b)[0] for b in scene.ids.tolist()])
    for row, body in enumerate(scene.ids.tolist()):
        centers[row, 1] += heights[row] - outline_gap(scene.world, body)
    velocities = np.array([scene.world.pose(b)[2] for b in scene.ids.tolist()])
    scene.world.update(scene.ids, centers, velocities=velocities)


def gap_tolerance(scene) -> float:
    """How far below the ground a body may end a frame: the bisection's final bracket (1e-9 s) times the speed
    (< 20 m/s), this file's chord sampling (1e-6), and the engine's golden-section search (0.618^40 of two
    sample intervals)."""
    return 1e-6 + 2e-8 + 1e-7


scene_settings = settings(max_examples=8)


def lowered_scene(seed, restitution, drag, dt, heights):
    """A demo scene with its bodies lowered to ``heights`` above the ground."""
    scene = DemoScene(restitution=restitution, drag=drag, dt=dt, seed=seed)
    lower_bodies(scene, heights)
    return scene


def frames(scene, duration=0.4):
    """Step the scene frame by frame over ``duration`` (and one frame more), yielding after each step."""
    for _ in range(int(duration / scene.dt) + 1):
        scene.step()
        yield scene
#: a demo scene: its seed, restitution, drag, frame step and the heights its seven bodies are lowered to
scene_cases = given(seed=st.integers(0, 2 ** 16), restitution=st.floats(0.0, 1.0), drag=st.floats(0.0, 0.5),
                    dt=st.floats(0.01, 0.05), heights=st.lists(st.floats(0.01, 0.6), min_size=7, max_size=7))


@scene_settings
@scene_cases
@example(seed=0, restitution=0.6, drag=0.05, dt=0.02, heights=[0.05, 0.3, 0.02, 0.6, 0.1, 0.25, 0.4])
def test_no_body_ends_a_frame_below_the_ground(seed, restitution, drag, dt, heights):
    scene = lowered_scene(seed, restitution, drag, dt, heights)
    tol = gap_tolerance(scene)
    for _ in frames(scene):
        for body in scene.ids.tolist():
            gap = outline_gap(scene.world, body)
            assert gap >= -tol, (body, scene.world.kind(body), gap, tol, scene.t)
    assert scene.impacts, "no impact happened: the property did not exercise a bounce"


def test_the_default_scene_stays_above_the_ground_for_its_150_frames():
    scene = DemoScene()
    tol = gap_tolerance(scene)
    for _ in range(150):
        scene.step()
        assert min(outline_gap(scene.world, b) for b in scene.ids.tolist()) >= -tol
    assert len(scene.impacts) >= 7


# ------------------------------------------------------------------------------------------------ closed form
def phi(k, t):
    """φ1 = (1 − e^(−kt)) / k and φ2 = (t − φ1) / k, by their series (k t <= 0.05 here: 14 terms are exact to
    rounding); at k = 0 they are t and t² / 2."""
    phi1 = phi2 = 0.0
    term = t  # t^n / n! · (−k)^(n−1), n = 1
    for n in range(1, 15):
        phi1 += term
        term2 = term * t / (n + 1)  # t^(n+1) / (n+1)! · (−k)^(n−1): the n+1-th term of φ2
        phi2 += term2
        term = -k * term2
    return phi1, phi2


def flight(p, v, k, t):
    """Position and velocity after t under dv/dt = G − k v (closed form)."""
    phi1, phi2 = phi(k, t)
    return p + v * phi1 + G * phi2, v * math.exp(-k * t) + G * phi1


def closed_form_frame(p, v, resting, *, slope, lowest, k, e, dt, t0):
    """One frame of a box over y = slope · x, from (p, v): ((p, v) at its end, resting, impacts in it)."""
    if resting:
        return p, np.zeros(3), True, []
    m = np.array([-slope, 1.0, 0.0])
    n = m / math.hypot(slope, 1.0)

    def gap(q):
        return float(q @ m) + lowest

    impacts, remaining = [], dt
    for _ in range(4):
        p1, v1 = flight(p, v, k, remaining)
        if gap(p1) > 0.0:  # the gap is concave in t (gravity pulls towards the line): positive all the way
            return p1, v1, False, impacts
        if gap(p) <= 0.0:  # touching at the start and below at the end: at rest where it is
            return p, np.zeros(3), True, impacts
        tc = brentq(lambda t, p=p, v=v: gap(flight(p, v, k, t)[0]), 0.0, remaining, xtol=1e-15, rtol=1e-15)
        p, v = flight(p, v, k, tc)
        vn = float(v @ n)
        if vn < 0.0:
            impacts.append((t0 + dt - remaining + tc, -vn))
            v = v - (1.0 + e) * vn * n
            if -vn * e < REST_SPEED:
                return p, np.zeros(3), True, impacts
        remaining -= tc
    return p, v, False, impacts


def straight_ground_scene(slope, restitution, drag, dt, center, half, angle, velocity):
    """A DemoScene whose world is one box over the straight ground y = slope · x."""
    scene = DemoScene(restitution=restitution, drag=drag, dt=dt)
    scene.world = World("tree")
    scene.ground = scene.world.add(HeightCurve(lambda x: slope * np.asarray(x, dtype=float), samples=96))
    scene.ids = np.array([scene.world.add(Box(center, half, rot_z(angle)), velocity=velocity)])
    scene.resting = np.zeros(1, bool)
    return scene


@settings(max_examples=25)
@given(slope=st.one_of(st.just(0.0), st.floats(-0.6, 0.6)), restitution=st.floats(0.0, 1.0),
       drag=st.one_of(st.just(0.0), st.floats(0.0, 0.5)), dt=st.floats(0.005, 0.05),
       half=st.tuples(*[st.floats(0.1, 1.0)] * 3), angle=st.floats(-math.pi, math.pi),
       x0=st.floats(-3.0, 3.0), height=st.one_of(st.just(-1e-3), st.floats(0.01, 1.2)), vx=st.floats(-3.0, 3.0),
       vy=st.floats(-4.0, 1.0))
@example(slope=0.0, restitution=0.8, drag=0.0, dt=0.02, half=(0.5, 0.5, 0.5), angle=0.0, x0=0.0, height=1.0,
         vx=0.0, vy=0.0)  # flat ground, no drag: the textbook drop
@example(slope=0.3, restitution=0.05, drag=0.1, dt=0.02, half=(0.4, 0.2, 0.3), angle=0.5, x0=1.0, height=0.5,
         vx=1.0, vy=-1.0)  # a slow bounce (e·|v_n| < 0.3 m/s): comes to rest on the slope
@example(slope=-0.2, restitution=0.6, drag=0.05, dt=0.02, half=(0.3, 0.3, 0.3), angle=0.2, x0=0.0, height=-1e-3,
         vx=0.5, vy=-0.5)  # touching at the start, below after the step: at rest at once
def test_a_bounce_on_straight_ground_matches_the_closed_form(slope, restitution, drag, dt, half, angle, x0,
                                                              height, vx, vy):
    m = np.array([-slope, 1.0, 0.0])
    corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * half
    lowest = float(np.min((corners @ rot_z(angle).T) @ m))  # the box's lowest corner's offset along m
    center = np.array([x0, slope * x0 - lowest + height, 0.0])  # gap y − s x + lowest = height
    velocity = np.array([vx, vy, 0.0])
    scene = straight_ground_scene(slope, restitution, drag, dt, center, half, angle, velocity)
    body = int(scene.ids[0])
    bounced_frames = 0
    for _ in range(int(3.0 / dt)):
        p, _, v = scene.world.pose(body)
        t0, before = scene.t, len(scene.impacts)
        want_p, want_v, want_rest, want_impacts = closed_form_frame(
            p, v, bool(scene.resting[0]), slope=slope, lowest=lowest, k=drag, e=restitution, dt=dt, t0=t0)
        scene.step()
        got_p, _, got_v = scene.world.pose(body)
        got_impacts = scene.impacts[before:]
        assert scene.t == pytest.approx(t0 + dt, abs=1e-15)
        assert [b for _, b, _ in got_impacts] == [body] * len(want_impacts)
        np.testing.assert_allclose([t for t, _, _ in got_impacts], [t for t, _ in want_impacts], atol=1e-8)
        np.testing.assert_allclose([s for _, _, s in got_impacts], [s for _, s in want_impacts], atol=1e-6)
        np.testing.assert_allclose(got_p, want_p, atol=1e-7, rtol=0)
        np.testing.assert_allclose(got_v, want_v, atol=1e-6, rtol=0)
        assert bool(scene.resting[0]) == want_rest
        bounced_frames += bool(want_impacts) or want_rest
        if bounced_frames >= 2 or want_rest:
            break
    assert bounced_frames, "no bounce within 3 s"


# ------------------------------------------------------------------------------------------------ energy
def energies(scene):
    """½|v|² − g·x of each body (per unit mass)."""
    out = []
    for body in scene.ids.tolist():
        c, _, v = scene.world.pose(body)
        out.append(0.5 * float(v @ v) - float(G @ c))
    return np.array(out)


@scene_settings
@scene_cases
@example(seed=0, restitution=1.0, drag=0.0, dt=0.02, heights=[0.05, 0.3, 0.02, 0.6, 0.1, 0.25, 0.4])
def test_mechanical_energy_never_grows_with_e_at_most_one(seed, restitution, drag, dt, heights):
    scene = lowered_scene(seed, restitution, drag, dt, heights)
    before = energies(scene)
    for _ in frames(scene):
        after = energies(scene)
        # RK4 on this linear ODE: a relative error below 1e-10 per frame; the bisection's 1e-9 s adds nothing
        # (the state at tc is the RK4 state there)
        assert np.all(after <= before + 1e-9 * (1.0 + np.abs(before))), (after - before, scene.t)
        before = after
    assert scene.impacts


# ------------------------------------------------------------------------------------------------ seeds, scene
def run_frames(scene, frames):
    for _ in range(frames):
        scene.step()
    return [scene.world.pose(b) for b in scene.ids.tolist()]


@settings(max_examples=4)
@given(seed=st.integers(0, 2 ** 32 - 1), restitution=st.floats(0.0, 1.0), dt=st.floats(0.01, 0.05))
def test_the_same_seed_gives_the_same_frames(seed, restitution, dt):
    heights = [0.05, 0.3, 0.02, 0.6, 0.1, 0.25, 0.4]
    scenes = [DemoScene(restitution=restitution, dt=dt, seed=seed), build_scene(restitution=restitution, dt=dt,
                                                                                  seed=seed)]
    for scene in scenes:
        lower_bodies(scene, heights)
    frames = int(0.3 / dt) + 1
    a, b = (run_frames(s, frames) for s in scenes)
    for pa, pb in zip(a, b):
        for xa, xb in zip(pa, pb):
            assert np.array_equal(xa, xb)
    assert scenes[0].impacts == scenes[1].impacts and scenes[0].impacts
    assert np.array_equal(scenes[0].resting, scenes[1].resting)
    assert scenes[0].t == scenes[1].t


def test_the_defaults_are_the_documented_ones():
    scene = DemoScene()
    assert (scene.restitution, scene.drag, scene.dt, scene.t, scene.impacts) == (0.6, 0.05, 0.02, 0.0, [])
    assert np.array_equal(GRAVITY, G)
    twin = DemoScene(restitution=0.6, drag=0.05, dt=0.02, seed=0)
    for pa, pb in zip(run_frames(scene, 60), run_frames(twin, 60)):
        assert all(np.array_equal(x, y) for x, y in zip(pa, pb))
    assert scene.impacts == twin.impacts


def test_the_scene_holds_the_documented_bodies():
    scene = DemoScene(seed=7)
    w = scene.world
    ground = w.shape(scene.ground)
    assert w.kind(scene.ground) == "curve" and ground.samples == 96
    x = np.linspace(-8.0, 8.0, 33)
    np.testing.assert_allclose(ground.height(x), documented_ground(x), rtol=0, atol=1e-15)
    boxes = {0: ((-5.0, 5.0), (0.6, 0.4, 0.5), 0.4), 3: ((0.8, 8.0), (0.5, 0.5, 0.5), -0.3)}
    rounded = {1: ([(-3.2, 7.0)], 0.5), 2: ([(-1.9, 6.0), (-0.7, 6.4)], 0.3), 4: ([(2.6, 5.5)], 0.7),
               5: ([(3.8, 7.5), (4.8, 6.9)], 0.35)}
    ids = scene.ids.tolist()
    assert len(ids) == 7 and [w.kind(b) for b in ids] == ["box", "sphere", "capsule", "box", "sphere", "capsule",
                                                          "hull"]
    for row, (c, half, angle) in boxes.items():
        corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * half
        want = corners @ rot_z(angle).T + [*c, 0.0]
        got = w.world_points(ids[row])
        assert w.radius(ids[row]) == 0.0
        np.testing.assert_allclose(np.sort(got, axis=0), np.sort(want, axis=0), atol=1e-12)
    for row, (core, r) in rounded.items():
        got = w.world_points(ids[row])
        want = np.array([[*p, 0.0] for p in core])
        np.testing.assert_allclose(got[np.lexsort(got.T[::-1])], want[np.lexsort(want.T[::-1])], atol=1e-12)
        assert w.radius(ids[row]) == pytest.approx(r, abs=1e-15)
    rng = np.random.default_rng(7)
    cloud = rng.normal(size=(14, 3)) * 0.45 + [5.6, 9.0, 0.0]
    hull_points = w.world_points(ids[6])
    assert {tuple(p) for p in np.round(hull_points, 12)} <= {tuple(p) for p in np.round(cloud, 12)}
    for body in ids:
        assert w.pose(body)[0][2] == pytest.approx(0.0, abs=1e-12) or body == ids[6]
        v = w.pose(body)[2]
        assert v[1] == 0.0 and v[2] == 0.0 and -0.8 <= v[0] <= 0.8
    assert not scene.resting.any() and scene.resting.shape == (7,)


def test_initial_velocities_are_the_documented_draws():
    for seed in (0, 1, 2, 3):
        scene = DemoScene(seed=seed)
        rng = np.random.default_rng(seed)
        rng.normal(size=(14, 3))  # the hull's points come first
        want = [rng.uniform(-0.8, 0.8) for _ in range(7)]
        got = [scene.world.pose(b)[2][0] for b in scene.ids.tolist()]
        assert got == want


def test_at_most_four_impacts_per_body_and_frame():
    """The documented cap: a box bouncing elastically on flat ground with a period of 0.2 s meets it 5 times in a
    frame of 1 s (at 0.101, 0.303, ... s); 4 are answered, the body ends the frame above the ground."""
    h = 0.05
    scene = straight_ground_scene(0.0, 1.0, 0.0, 1.0, [0.0, 0.5 + h, 0.0], [0.5, 0.5, 0.5], 0.0, [0.0, 0.0, 0.0])
    scene.step()
    period = 2.0 * math.sqrt(2.0 * h / 9.81)
    np.testing.assert_allclose([t for t, _, _ in scene.impacts], period * (np.arange(4) + 0.5), atol=1e-8)
    np.testing.assert_allclose([s for _, _, s in scene.impacts], math.sqrt(2.0 * 9.81 * h), rtol=1e-8)
    c, _, v = scene.world.pose(int(scene.ids[0]))
    assert c[1] - 0.5 >= -1e-8 and v[1] > 0.0
