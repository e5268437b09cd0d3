"""The gallery's image scraper: every matplotlib figure a code block made.

flexsat's plot functions build :class:`matplotlib.figure.Figure` objects without
pyplot (no display, no global state), so sphinx-gallery's own scraper, which asks
pyplot for its figures, sees none. This one records every figure as it is created
(pyplot's too) and, after each code block, saves those of the block for the page.
"""

from __future__ import annotations

from matplotlib.figure import Figure

_created: list[Figure] = []
_init = Figure.__init__


def _recording_init(self, *args, **kwargs):
    _init(self, *args, **kwargs)
    _created.append(self)


Figure.__init__ = _recording_init


def scrape(block, block_vars, gallery_conf):
    """Save the figures the block made; return the reST that shows them."""
    import matplotlib.pyplot as plt
    from sphinx_gallery.scrapers import figure_rst

    paths = []
    for figure, path in zip(list(_created), block_vars["image_path_iterator"], strict=False):
        figure.savefig(path)
        paths.append(path)
    _created.clear()
    plt.close("all")
    return figure_rst(paths, gallery_conf["src_dir"])
