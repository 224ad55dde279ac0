"""Matplotlib figures drawn off screen: a ``Figure`` on its own Agg canvas, no pyplot state, no backend switch."""

from __future__ import annotations

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure


def agg_figure(**options) -> Figure:
    """A new ``Figure(**options)`` (``figsize`` [in], ``layout``, ...) drawn by Agg; nothing keeps it alive but
    its caller, so it needs no closing."""
    figure = Figure(**options)
    FigureCanvasAgg(figure)
    return figure
