"""Figures of a calibration (``tribokin calibrate``): measured clouds beside the model's predicted ellipses, and
a parity plot of measured against predicted ISO 9283 figures with their prediction intervals.

Clouds are drawn in µm about the pose's pooled measured barycentre, in three projections of the world
frame; an ellipse is the 95 % region of the projected 2-D Gaussian, at Mahalanobis radius
``sqrt(chi2.ppf(0.95, 2))`` (:data:`RADIUS_95_2D`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import matplotlib
import numpy as np
from matplotlib.lines import Line2D
from matplotlib.ticker import LogFormatter
from scipy.stats import chi2

from tribokin.calibration.cross_validation import PredictedFigure
from tribokin.iso9283.metrics import barycenter
from tribokin.units import UM_PER_M
from tribokin.viz.canvas import agg_figure
from tribokin.viz.figures import DIRECTION_COLOURS, frame_field

#: Mahalanobis radius of the 95 % region of a 2-D Gaussian (2.4477).
RADIUS_95_2D = float(np.sqrt(chi2.ppf(0.95, 2)))
#: The panels of the clouds figure: base-frame axes (i, j) drawn as (horizontal, vertical).
PROJECTIONS = ((0, 1), (0, 2), (1, 2))
#: Values spanning more than this factor are drawn on log-log axes in the parity plot.
LOG_SPAN = 20.0
#: The parity plot names its points when it has at most this many.
MOST_LABELLED = 15


class _PlainLogFormatter(LogFormatter):
    """The ticks :class:`LogFormatter` labels, written as plain numbers (0.2, 10): the default 10ⁿ labels are
    math text, which these figures turn off."""

    def __call__(self, x, pos=None):
        return f"{x:g}" if super().__call__(x, pos) else ""


@dataclass(frozen=True, eq=False)
class PredictedCloud:
    """One approach direction's measured cycles beside the model's prediction, in the world frame.

    Attributes:
        direction: approach label.
        points_m: (n, 3) measured positions [m], n ≥ 1.
        predicted_mean_m: (3,) predicted barycentre [m].
        predicted_covariance_m2: (3, 3) predicted covariance of one cycle's position [m²].
    """

    direction: str
    points_m: np.ndarray
    predicted_mean_m: np.ndarray
    predicted_covariance_m2: np.ndarray


@dataclass(frozen=True)
class ParityPoint:
    """One measured figure beside its prediction.

    Attributes:
        label: what it is, e.g. ``"P1 +x"``.
        kind: which figure, e.g. ``"RP_l"`` or ``"vAP_p"``; one marker and colour per kind.
        figure: measured, predicted and 95 % prediction interval [m].
    """

    label: str
    kind: str
    figure: PredictedFigure


def ellipse_outline(mean_2d: np.ndarray, covariance_2x2: np.ndarray, radius: float, points: int = 181
                    ) -> np.ndarray:
    """(points, 2) closed outline (last row = first) of ``{x : (x - m)ᵀ C⁻¹ (x - m) = radius²}`` about
    ``mean_2d`` (2,) for a symmetric positive semi-definite ``covariance_2x2`` (2, 2), in their units."""
    values, vectors = np.linalg.eigh(covariance_2x2)
    angles = np.append(np.linspace(0.0, 2 * np.pi, points - 1, endpoint=False), 0.0)
    circle = np.stack([np.cos(angles), np.sin(angles)])
    return np.asarray(mean_2d) + (radius * (vectors * np.sqrt(np.clip(values, 0.0, None))) @ circle).T


@matplotlib.rc_context({"text.parse_math": False})  # names as written: '$' is no math
def save_calibration_clouds(directions: list[PredictedCloud] | tuple[PredictedCloud, ...], path: Path,
                            title: str = "") -> None:
    """One pose's measured clouds (``directions``: at least one) and the model's predictions in the x-y, x-z and y-z
    projections, in µm about
    the pooled measured barycentre: per direction (one colour each) its cycles, measured barycentre (×) and 95 %
    ellipse (dashed, from three cycles on; sample covariance), predicted barycentre (◇) and 95 % ellipse (solid)."""
    centre = barycenter(np.concatenate([d.points_m for d in directions]))
    fig = agg_figure(figsize=(13, 5.2))
    panels = fig.subplots(1, len(PROJECTIONS))
    colours = DIRECTION_COLOURS * len(directions)
    reaches = np.ones(len(PROJECTIONS))  # half-width of each panel [µm]
    for d, colour in zip(directions, colours, strict=False):
        points = (d.points_m - centre) * UM_PER_M
        measured = points.mean(axis=0)
        predicted = (d.predicted_mean_m - centre) * UM_PER_M
        covariance = d.predicted_covariance_m2 * UM_PER_M ** 2
        spread = np.cov(points.T) if len(points) >= 3 else None
        for k, (panel, pair) in enumerate(zip(panels, map(list, PROJECTIONS), strict=True)):
            block = np.ix_(pair, pair)
            outline = ellipse_outline(predicted[pair], covariance[block], RADIUS_95_2D)
            panel.scatter(*points[:, pair].T, s=12, color=colour, alpha=0.65, lw=0, zorder=3)
            panel.plot(*outline.T, color=colour, lw=1.6, zorder=4)
            panel.plot(*measured[pair], "x", color=colour, ms=9, mew=2, zorder=5)
            panel.plot(*predicted[pair], "D", mfc="white", mec=colour, ms=7, mew=1.6, zorder=5)
            reaches[k] = max(reaches[k], np.abs(points[:, pair]).max(), np.abs(outline).max())
            if spread is not None:
                outline = ellipse_outline(measured[pair], spread[block], RADIUS_95_2D)
                panel.plot(*outline.T, "--", color=colour, lw=1.2, zorder=4)
                reaches[k] = max(reaches[k], np.abs(outline).max())
    for panel, (i, j), reach in zip(panels, PROJECTIONS, reaches * 1.08, strict=True):
        panel.plot(0, 0, "k+", ms=10, mew=1.5, zorder=6)
        frame_field(panel, i, j, reach)
        panel.set_title(f"{'xyz'[i]}-{'xyz'[j]}")
    grey = "#555555"
    fig.legend(handles=[Line2D([], [], color=colour, marker="o", ls="none", label=f"{d.direction}: {len(d.points_m)} "
                               f"cycle{'s' * (len(d.points_m) > 1)}")
                        for d, colour in zip(directions, colours, strict=False)],
               loc="lower center", bbox_to_anchor=(0.5, 0.05), ncol=len(directions), fontsize=8)
    fig.legend(handles=[Line2D([], [], color=grey, marker="x", ms=8, mew=2, ls="--", lw=1.2,
                               label="measured (barycentre, 95 % ellipse)"),
                        Line2D([], [], color=grey, marker="D", mfc="white", ms=7, mew=1.6, lw=1.6,
                               label="predicted (model, 95 %)"),
                        Line2D([], [], color="k", marker="+", ms=10, mew=1.5, ls="none",
                               label="pooled measured barycentre")],
               loc="lower center", bbox_to_anchor=(0.5, 0.0), ncol=3, fontsize=8)
    fig.suptitle(title)
    fig.tight_layout(rect=(0, 0.14, 1, 1))
    fig.savefig(path, dpi=110)


@matplotlib.rc_context({"text.parse_math": False})  # labels as written: '$' is no math
def save_parity(points: list[ParityPoint] | tuple[ParityPoint, ...], path: Path, title: str = "") -> None:
    """Predicted against measured figures [µm] of ``points`` (at least one) with their 95 % prediction intervals
    (bars) and the line y = x; one marker and colour per kind; log-log axes when the measured and predicted
    figures span more than a factor :data:`LOG_SPAN`, else linear from 0; each point named when there are at
    most :data:`MOST_LABELLED`."""
    measured = np.array([p.figure.measured_m for p in points]) * UM_PER_M
    predicted = np.array([p.figure.predicted_m for p in points]) * UM_PER_M
    low, high = (np.array([p.figure.interval_m for p in points]) * UM_PER_M).T
    figures = np.concatenate([measured, predicted])
    logarithmic = figures.min() > 0 and figures.max() > LOG_SPAN * figures.min()
    values = np.concatenate([figures, low, high])
    fig = agg_figure(figsize=(6.4, 6.4))
    axes = fig.subplots()
    kinds = list(dict.fromkeys(p.kind for p in points))
    for kind, colour, marker in zip(kinds, DIRECTION_COLOURS * len(kinds), "osD^v<>" * len(kinds), strict=False):
        mine = np.array([p.kind == kind for p in points])
        axes.errorbar(measured[mine], (low[mine] + high[mine]) / 2, yerr=(high[mine] - low[mine]) / 2, fmt="none",
                      ecolor=colour, elinewidth=1, capsize=3, alpha=0.7, zorder=2)
        axes.plot(measured[mine], predicted[mine], marker, color=colour, ms=6, ls="none", zorder=3,
                  label=f"{kind} (bar: 95 % prediction interval)")
    if len(points) <= MOST_LABELLED:
        for p, x, y in zip(points, measured, predicted, strict=True):
            axes.annotate(p.label, (x, y), xytext=(4, -9), textcoords="offset points", fontsize=6.5, color="#333333")
    limits = (values[values > 0].min() / 1.5, values.max() * 1.5) if logarithmic else (0.0, values.max() * 1.08)
    axes.plot(limits, limits, color="#888888", lw=1, zorder=1, label="y = x")
    if logarithmic:
        axes.set_xscale("log")
        axes.set_yscale("log")
        for axis in (axes.xaxis, axes.yaxis):
            axis.set_major_formatter(_PlainLogFormatter())
            axis.set_minor_formatter(_PlainLogFormatter(labelOnlyBase=False, minor_thresholds=(2, 0.5)))
    axes.set_xlim(limits)
    axes.set_ylim(limits)
    axes.set_aspect("equal")
    axes.set_xlabel("measured [µm]")
    axes.set_ylabel("predicted [µm]")
    axes.set_title(title or "measured and predicted figures")
    axes.grid(alpha=0.3, which="both" if logarithmic else "major")
    axes.legend(loc="upper left", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
