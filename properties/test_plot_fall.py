"""The falling-body plot (engine.dynamics.plot.plot_fall) draws what it is given and writes only where it is told.

Oracle: the figure's own artists read back — the curve's data are the trajectory samples, the marked points are
the impacts, the ground line is y = 0, the legend names the curve with the caller's label; with ``path`` the file
exists and is an image of the figure; without it nothing is written; pyplot's global state is untouched.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from engine.dynamics.plot import plot_fall
from engine.dynamics.scenes import drop_particle

labels = st.text("abcdefghijklmnopqrstuvwxyz ", min_size=1, max_size=12).filter(str.strip)


@settings(max_examples=10)
@given(st.floats(0.5, 5.0), st.floats(0.3, 0.9), labels)
def test_the_figure_shows_the_trajectory_the_impacts_and_the_ground(height, e, label):
    res = drop_particle(height, restitution=e, dt=0.01, t_end=2.0)
    t_hits = np.array([i.t for i in res.impacts])
    y_hits = np.interp(t_hits, res.t, res.y)
    fig = plot_fall(res.t, res.y, t_hits, y_hits, label=label)
    (ax,) = fig.axes
    curves = [line for line in ax.get_lines() if len(line.get_xdata()) == len(res.t)]
    assert len(curves) == 1
    np.testing.assert_array_equal(curves[0].get_xdata(), res.t)
    np.testing.assert_array_equal(curves[0].get_ydata(), res.y)
    (marks,) = ax.collections
    np.testing.assert_array_equal(marks.get_offsets(), np.column_stack([t_hits, y_hits]).reshape(-1, 2))
    ground = [line for line in ax.get_lines() if line is not curves[0]]
    assert len(ground) == 1 and set(np.asarray(ground[0].get_ydata(), dtype=float)) == {0.0}
    legend = ax.get_legend()
    assert legend is not None
    texts = [text.get_text() for text in legend.get_texts()]
    assert len(texts) == 2 and texts[0].startswith(label + ":")
    assert ax.get_xlabel().startswith("t") and ax.get_ylabel().startswith("y")


def test_the_figure_is_written_only_when_a_path_is_given(tmp_path, monkeypatch):
    pytest.importorskip("matplotlib")
    import matplotlib.pyplot as plt

    before = plt.get_fignums()
    monkeypatch.chdir(tmp_path)
    t = np.linspace(0.0, 1.0, 11)
    y = 1.0 - t**2
    fig = plot_fall(t, y, [1.0], [0.0])
    assert list(tmp_path.iterdir()) == []  # no path: nothing written, not even in the working directory
    out = tmp_path / "fall.png"
    again = plot_fall(t, y, [1.0], [0.0], label="ball", path=out)
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert again is not fig
    assert plt.get_fignums() == before  # pyplot's figure manager never saw them


def test_the_impacts_are_marked_in_a_colour_distinct_from_the_curve():
    """The impact marks lie on the curve: drawn in the curve's own colour they would be hard to see (matplotlib's
    default for a scatter after one line is that line's colour, C0)."""
    from matplotlib.colors import to_rgba

    t = np.linspace(0.0, 1.0, 11)
    y = 1.0 - t**2
    fig = plot_fall(t, y, [0.5, 1.0], [0.75, 0.0])
    (ax,) = fig.axes
    curve = next(line for line in ax.get_lines() if len(line.get_xdata()) == len(t))
    (marks,) = ax.collections
    curve_colour = np.array(to_rgba(curve.get_color()))
    for colour in (*marks.get_facecolors(), *marks.get_edgecolors()):
        assert not np.allclose(colour, curve_colour), (colour, curve_colour)
