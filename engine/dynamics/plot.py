"""Plots of the falling bodies: the trajectory y(t) and the impacts located by bisection.

The functions build a matplotlib ``Figure`` without touching pyplot's global state or the backend (they work in a
notebook, a GUI or a headless job alike), save it when a path is given, and return it.
"""
from __future__ import annotations

from pathlib import Path

__all__ = ["plot_fall"]


def plot_fall(t, y, t_impacts, y_impacts, label: str = "particle", path: str | Path | None = None):
    """The height y(t) of a falling body and its impacts.

    Parameters
    ----------
    t, y : array_like, shape (n,)
        Trajectory samples (``FallResult.t``, ``FallResult.y``).
    t_impacts, y_impacts : array_like, shape (k,)
        Impact times (located by bisection) and heights, marked on the curve in a colour distinct from the
        curve's (the marks lie on it).
    label : str
        Legend of the curve.
    path : str or Path, optional
        When given, the figure is also written there (the format follows the suffix).

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.figure import Figure

    # the figure's size and resolution are styling, promised nowhere (no property could tell 110 dpi from 111)
    fig = Figure(figsize=(8, 4), dpi=110)  # pragma: no mutate
    ax = fig.add_subplot()
    ax.plot(t, y, lw=1.2, label=f"{label}: y(t), RK4")
    ax.scatter(t_impacts, y_impacts, color="crimson", zorder=3, s=18, label="impacts (tc by bisection)")
    ax.axhline(0.0, color="k", lw=0.8)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("y (m)")
    ax.legend(loc="upper right")
    ax.set_title("Falling body on the ground y = 0")
    fig.tight_layout()
    if path is not None:
        fig.savefig(path)
    return fig
