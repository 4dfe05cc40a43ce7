"""``colldet demo``, the simulation: boxes, spheres, capsules and a hull falling onto a curved ground.

The chapter's falling-body recipe ("La solution ?": stop the ODE at tc, apply the response, restart), for every
body of a ``World``: each frame, each body's state Y = (x, v) takes one RK4 step (engine.rk4_step) under
gravity and linear drag; if the body's gap to the ground (``HeightCurve``) is then <= 0, the impact time tc in
[t, t + Δt] is located by bisection (engine.bisect, Algorithme 3) on the body's gap to the curve — never by the
penetration — the body is put at Y(tc) and answered with restitution along the curve's normal
(V_après = V − (1 + e)(V·n) n), and the rest of the frame is integrated from tc. Bodies do not rotate (no
rigid-body rotation solver) and pass through each other (their contacts are drawn, not answered).

The drawing (``draw``, ``demo_figure``, ``run_demo``: matplotlib, the GIF and the PNG) is in
``engine.demo_plot``, which imports this module (never the reverse).
"""
from __future__ import annotations

import numpy as np

from engine.dynamics.bisection import bisect
from engine.dynamics.rk4 import rk4_step
from engine.narrowphase.curve_ground import ground_gap, lower_boundary
from engine.world import Box, Capsule, ConvexPolyhedron, HeightCurve, Sphere, World

__all__ = ["build_scene", "DemoScene", "ground_height", "GRAVITY"]

GRAVITY = np.array([0.0, -9.81, 0.0])


def ground_height(x):
    """The demo's curved ground y = f(x) = 0.04 x² + 0.5 sin(1.3 x) − 0.8: a valley with a bump."""
    x = np.asarray(x, dtype=float)
    return 0.04 * x ** 2 + 0.5 * np.sin(1.3 * x) - 0.8


def _rot_z(angle):
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


class DemoScene:
    """A World of falling bodies over a HeightCurve, stepped by RK4 with impacts located by bisection.

    The ground is ``HeightCurve(ground_height, samples=96)``; the bodies (every centre at z = 0), in order:

    - a box at (−5, 5), half extents (0.6, 0.4, 0.5), turned 0.4 rad about z;
    - a sphere at (−3.2, 7), radius 0.5;
    - a capsule from (−1.9, 6) to (−0.7, 6.4), radius 0.3;
    - a box at (0.8, 8), half extents (0.5, 0.5, 0.5), turned −0.3 rad about z;
    - a sphere at (2.6, 5.5), radius 0.7;
    - a capsule from (3.8, 7.5) to (4.8, 6.9), radius 0.35;
    - the hull of 14 points drawn from N((5.6, 9, 0), 0.45²) per coordinate (``numpy.random.default_rng(seed)``).

    Each starts with velocity (u, 0, 0), u uniform in [−0.8, 0.8] m/s, drawn from the same generator after the
    hull's points. Per unit mass, a free body's state Y = (x, v) obeys dY/dt = (v, GRAVITY − drag · v).

    Parameters
    ----------
    restitution : float, default 0.6
        e of the response along the ground's normal n: v' = v − (1 + e)(v · n) n. A body whose speed along n
        after it, e · |v · n|, is below 0.3 m/s comes to rest there (velocity 0, and it moves no more), as does
        a body touching the ground at the start of a frame whose RK4 step ends below it.
    drag : float, default 0.05
        The linear drag coefficient (1/s).
    dt : float, default 0.02
        The frame (s); up to 4 impacts per body and frame are located and answered.
    seed : int, default 0
        Seeds the hull's points and the initial velocities.

    Attributes
    ----------
    world : World
        The bodies and the ground; ``ground`` is the ground's id, ``ids`` the bodies' ids (int array).
    t : float
        The time reached (``dt`` per ``step``).
    impacts : list of (float, int, float)
        Every impact answered so far: (time, body id, speed along the normal before it).
    resting : numpy.ndarray of bool
        Per body (in the order of ``ids``): whether it came to rest.
    """

    def __init__(self, *, restitution: float = 0.6, drag: float = 0.05, dt: float = 0.02, seed: int = 0):
        self.world = World("tree")
        self.ground = self.world.add(HeightCurve(ground_height, samples=96))
        rng = np.random.default_rng(seed)
        shapes = [
            Box([-5.0, 5.0, 0.0], [0.6, 0.4, 0.5], _rot_z(0.4)),
            Sphere([-3.2, 7.0, 0.0], 0.5),
            Capsule([-1.9, 6.0, 0.0], [-0.7, 6.4, 0.0], 0.3),
            Box([0.8, 8.0, 0.0], [0.5, 0.5, 0.5], _rot_z(-0.3)),
            Sphere([2.6, 5.5, 0.0], 0.7),
            Capsule([3.8, 7.5, 0.0], [4.8, 6.9, 0.0], 0.35),
            ConvexPolyhedron(rng.normal(size=(14, 3)) * 0.45 + [5.6, 9.0, 0.0]),
        ]
        self.ids = np.array([self.world.add(s, velocity=[rng.uniform(-0.8, 0.8), 0.0, 0.0]) for s in shapes])
        self.restitution = restitution
        self.drag = drag
        self.dt = dt
        self.t = 0.0
        self.impacts: list = []  # (time, body id, speed along the normal before)
        self.resting = np.zeros(len(self.ids), bool)

    def _derivative(self, t, y):
        return np.concatenate([y[3:], GRAVITY - self.drag * y[3:]])

    def _gap(self, body, center):
        """Gap (min of y − f(x) over the body's lower boundary) and the normal at that point."""
        local = self.world.world_points(body) - self.world.pose(body)[0]
        curve = self.world.shape(self.ground)
        bnd = lower_boundary((center + local)[None], np.array([self.world.radius(body)]), curve.samples)
        gap, xs, _ = ground_gap(curve, bnd)
        x = float(xs[0])
        slope = float(curve.slope(np.array([x]))[0])
        n = np.array([-slope, 1.0, 0.0]) / np.hypot(slope, 1.0)
        return float(gap[0]), n

    def step(self):
        """One frame: RK4 for each body; an impact inside the frame is located by bisection and answered."""
        centers, velocities = [], []
        for row, body in enumerate(self.ids.tolist()):
            c, _, v = self.world.pose(body)
            if self.resting[row]:
                centers.append(c)
                velocities.append(np.zeros(3))
                continue
            y = np.concatenate([c, v])
            remaining = self.dt
            for _ in range(4):  # at most a few impacts per frame
                y_next = rk4_step(self._derivative, self.t, y, remaining)
                gap_end, _ = self._gap(body, y_next[:3])
                if gap_end > 0.0:
                    y = y_next
                    break
                gap_start, _ = self._gap(body, y[:3])
                if gap_start <= 0.0:  # already touching at the start: resting on the ground
                    y = np.concatenate([y[:3], np.zeros(3)])
                    self.resting[row] = True
                    break
                # Algorithme 3: tc in [0, remaining] with gap(Y(tc)) = 0, taking the root's outer (apart) side
                y_start = y

                def gap_at(tau, y_start=y_start, body=body):
                    return self._gap(body, rk4_step(self._derivative, self.t, y_start, tau)[:3])[0]

                # the final bracket's apart end: gap(Y(tc)) >= 0 (Algorithme 3 keeps f(a) of f(0)'s sign), so a body
                # that bounced is apart at the start of the rest of the frame, not taken for one at rest
                _, found = bisect(gap_at, 0.0, remaining, 1e-9, full_output=True)
                tc = found.a
                y = rk4_step(self._derivative, self.t, y_start, tc)
                _, n = self._gap(body, y[:3])
                vn = float(y[3:] @ n)
                if vn < 0.0:
                    self.impacts.append((self.t + self.dt - remaining + tc, body, -vn))
                    y[3:] = y[3:] - (1.0 + self.restitution) * vn * n
                    if -vn * self.restitution < 0.3:  # too slow to bounce visibly: comes to rest
                        y[3:] = 0.0
                        self.resting[row] = True
                        break
                remaining -= tc
                if remaining <= 1e-12:
                    break
            centers.append(y[:3])
            velocities.append(y[3:])
        self.world.update(self.ids, np.array(centers), velocities=np.array(velocities))
        self.t += self.dt


def build_scene(**kwargs) -> DemoScene:
    """``DemoScene(**kwargs)``."""
    return DemoScene(**kwargs)

