"""``colldet demo``, the drawing: the x–y side view of a ``DemoScene`` (engine.demo) with matplotlib.

Bodies, contact points and normals, the per-stage pair counts in a corner; an animated GIF (matplotlib +
Pillow) of the frames, or one still frame (``--png``). Plotting only: the physics is ``DemoScene.step``.
"""
from __future__ import annotations

import numpy as np

from .demo import DemoScene, ground_height

__all__ = ["draw", "demo_figure", "run_demo"]


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
