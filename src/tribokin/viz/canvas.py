"""Matplotlib figures drawn off screen: a ``Figure`` on its own Agg canvas, no pyplot state, no backend switch."""

from __future__ import annotations

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

#: Resolution of the PNG figures of an output folder [dots per inch].
PNG_DPI = 110
#: rcParams of figures showing names as written (study, pose, joints, scenarios: '$' is no math), in effect where a
#: figure is drawn and where it is saved.
NO_MATH = {"text.parse_math": False}


def agg_figure(**options) -> Figure:
    """A new ``Figure(**options)`` (``figsize`` [in], ``layout``, ...) drawn by Agg; nothing keeps it alive but
    its caller, so it needs no closing."""
    figure = Figure(**options)
    FigureCanvasAgg(figure)
    return figure


def save_png(figure: Figure, path) -> None:
    """``figure`` written to ``path`` as a PNG at ``PNG_DPI``."""
    figure.savefig(path, dpi=PNG_DPI)
