"""An image scraper for the gallery: the figures an example builds without pyplot."""
from __future__ import annotations

_BARE_FIGURES: list = []  # kept alive, so that a figure is never drawn twice


def bare_figure_scraper(block, block_vars, gallery_conf, **kwargs):
    """The figures an example builds without pyplot: the engine's plot functions return a
    ``matplotlib.figure.Figure`` that pyplot does not know (they never switch the user's backend), so the
    matplotlib scraper, which asks pyplot, would miss them. Saves each new one found in the example's globals."""
    from matplotlib.figure import Figure
    from sphinx_gallery.scrapers import figure_rst

    paths = []
    for value in list(block_vars["example_globals"].values()):
        if isinstance(value, Figure) and value.canvas.manager is None and all(value is not f for f in _BARE_FIGURES):
            _BARE_FIGURES.append(value)
            path = next(block_vars["image_path_iterator"])
            value.savefig(path, dpi=100)
            paths.append(path)
    return figure_rst(paths, gallery_conf["src_dir"])
