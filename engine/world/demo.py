"""``collide demo``: boxes, spheres and capsules falling onto a curved ground, drawn with the pipeline's output.

The chapter's falling-body recipe ("La solution ?": stop the ODE at tc, apply the response, restart), for every
body of a ``World``: each frame, each body's state Y = (x, v) takes one RK4 step (engine.rk4_step) under
gravity and linear drag; if the World then reports the body overlapping the ground (``HeightCurve``), the impact
time tc in [t, t + Δt] is located by bisection (engine.bisect, Algorithme 3) on the body's gap to the curve —
never by the penetration — the body is put at Y(tc) and answered with restitution along the curve's normal
(V_après = V − (1 + e)(V·n) n), and the rest of the frame is integrated from tc. Bodies do not rotate (no
rigid-body rotation solver) and pass through each other (their contacts are drawn, not answered).

Writes an animated GIF (matplotlib + Pillow) of the x–y side view — bodies, contact points and normals, the
per-stage pair counts in a corner — or one still frame (``--png``).
"""
from __future__ import annotations

import numpy as np

from engine.dynamics.bisection import bisect
from engine.dynamics.rk4 import rk4_step

from .curve import ground_gap, lower_boundary
from .shapes import Box, Capsule, ConvexPolyhedron, HeightCurve, Sphere
from .world import World

__all__ = ["build_scene", "DemoScene", "run_demo", "demo_figure"]

GRAVITY = np.array([0.0, -9.81, 0.0])


def ground_height(x):
    """The demo's curved ground y = f(x): a valley with a bump."""
    x = np.asarray(x, dtype=float)
    return 0.04 * x ** 2 + 0.5 * np.sin(1.3 * x) - 0.8


def _rot_z(angle):
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


class DemoScene:
    """A World of falling bodies over a HeightCurve, stepped by RK4 with impacts located by bisection."""

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

                tc = bisect(gap_at, 0.0, remaining, 1e-9)
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
    return DemoScene(**kwargs)


def _outline(world, body):
    """A closed 2-D outline (x, y) of a body's side view."""
    pts = world.world_points(body)[:, :2]
    r = world.radius(body)
    if r > 0:  # rounded: sample the disc around every core point
        a = np.linspace(0, 2 * np.pi, 48, endpoint=False)
        pts = (pts[:, None, :] + r * np.stack([np.cos(a), np.sin(a)], axis=1)[None]).reshape(-1, 2)
    from scipy.spatial import ConvexHull

    return pts[ConvexHull(pts).vertices]


def draw(scene: DemoScene, ax):
    """Draw the scene's current state on a matplotlib axis: ground, bodies, contacts, stage counts."""
    from matplotlib.patches import Polygon

    w = scene.world
    ax.clear()
    x = np.linspace(-8, 8, 400)
    y = ground_height(x)
    ax.fill_between(x, y, -3, color="#c8b898")
    ax.plot(x, y, color="#6b5b3e", lw=1.5)
    colors = {"sphere": "#4c72b0", "box": "#dd8452", "capsule": "#55a868", "hull": "#8172b3"}
    for body in scene.ids.tolist():
        ax.add_patch(Polygon(_outline(w, body), closed=True, fc=colors[w.kind(body)], ec="k", lw=0.8, alpha=0.9))
    contacts = w.contacts()
    stats = w.stats
    if len(contacts):
        pts = contacts.points
        owner = np.repeat(np.arange(len(contacts)), np.diff(contacts.point_offsets))
        n = contacts.normal[owner]
        ax.quiver(pts[:, 0], pts[:, 1], n[:, 0], n[:, 1], color="crimson", scale=12, width=0.005)
        ax.plot(pts[:, 0], pts[:, 1], "o", color="crimson", ms=4)
    ax.text(0.02, 0.97, f"t = {scene.t:5.2f} s\nbodies: {stats.bodies}\ncandidate pairs: {stats.candidate_pairs}\n"
            f"narrow tests: {stats.narrow_tests}\noverlapping pairs: {stats.overlapping}\n"
            f"contact points: {stats.contacts}\nimpacts so far: {len(scene.impacts)}",
            transform=ax.transAxes, va="top", ha="left", fontsize=8, family="monospace",
            bbox=dict(fc="white", ec="0.6", alpha=0.85))
    ax.set_xlim(-8, 8)
    ax.set_ylim(-3, 10)
    ax.set_aspect("equal")
    ax.set_title("collide demo — World pipeline (x–y side view)", fontsize=10)
    ax.set_xticks([])
    ax.set_yticks([])


def _figure():
    """A Figure with its own Agg canvas: no pyplot, the process's backend is never switched."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6.4, 5.2), dpi=80)
    FigureCanvasAgg(fig)
    return fig, fig.add_subplot()


def demo_figure(path: str | None = None, *, frame: int = 70, restitution: float = 0.6, seed: int = 0):
    """The demo scene after ``frame`` frames, drawn; saved to ``path`` (a PNG) only when a path is given.
    Returns ``(figure, scene)``."""
    if isinstance(frame, bool) or not isinstance(frame, int) or frame < 0:
        raise ValueError(f"frame must be an int >= 0, got {frame!r}")
    scene = DemoScene(restitution=restitution, seed=seed)
    for _ in range(frame):
        scene.step()
    fig, ax = _figure()
    draw(scene, ax)
    if path is not None:
        fig.savefig(path, dpi=80)
    return fig, scene


def run_demo(*, out: str | None = "demo.gif", png: str | None = None, frames: int = 150, png_frame: int = 70,
             fps: int = 25, restitution: float = 0.6, seed: int = 0) -> int:
    """Simulate ``frames`` frames; write the GIF to ``out`` (None: no GIF) and/or frame ``png_frame`` to ``png``."""
    from matplotlib.animation import FuncAnimation, PillowWriter

    if out is None and png is None:
        raise ValueError("out and png are both None: nothing to write (give --png with --no-gif)")
    if frames < 1 or not 0 <= png_frame < frames:
        raise ValueError(f"frames must be >= 1 and png_frame in [0, frames), got {frames} and {png_frame}")
    if out is None:
        _, scene = demo_figure(png, frame=png_frame, restitution=restitution, seed=seed)
    else:
        scene = DemoScene(restitution=restitution, seed=seed)
        fig, ax = _figure()

        def update(k):
            if k:
                scene.step()
            draw(scene, ax)
            if png is not None and k == png_frame:
                fig.savefig(png, dpi=80)
            return []

        FuncAnimation(fig, update, frames=frames, blit=False).save(out, writer=PillowWriter(fps=fps))
    for t, body, speed in scene.impacts:
        print(f"impact t = {t:.6f} s  body {body} ({scene.world.kind(body)})  normal speed {speed:.3f} m/s")
    if out is not None:
        print(f"wrote {out}")
    if png is not None:
        print(f"wrote {png}")
    return 0
