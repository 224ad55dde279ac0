"""Matplotlib figures of results (PNG), in micrometres: a pose's repeatability field and its drift test."""

from __future__ import annotations

from pathlib import Path

import matplotlib
import numpy as np
from matplotlib import colormaps
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.patches import Circle

from tribokin.simulation.drift import PoseDrift
from tribokin.simulation.pose_result import PoseResult
from tribokin.units import UM_PER_M
from tribokin.viz.canvas import NO_MATH, agg_figure, save_png

#: Colours of the approach directions' barycenters and RP_l circles, in the order of the directions.
DIRECTION_COLOURS = ("#e63946", "#457b9d", "#8338ec", "#fb8500", "#6a994e", "#b5179e")
#: A drift figure's bands: this many Monte Carlo standard errors either side of a mean (about 95 %).
BAND_ERRORS = 2
#: A drift test this long [s] or longer is drawn against minutes, a shorter one against seconds.
MINUTES_FROM_S = 120.0


def field_axes(deviations_um: np.ndarray) -> tuple[int, int]:
    """The two world axes along which the cloud spreads most (ties keep x, y, z order)."""
    spread = np.ptp(deviations_um, axis=0) if len(deviations_um) else np.zeros(3)
    order = np.argsort(-spread, kind="stable")
    return tuple(sorted(order[:2]))


def frame_field(axes: Axes, i: int, j: int, reach_um: float) -> None:
    """Square ``axes`` of world axes ``i`` (horizontal) and ``j`` (vertical), ±``reach_um`` [µm] about 0 at equal
    scale, labelled as deviations in µm, with a light grid."""
    axes.set_xlim(-reach_um, reach_um)
    axes.set_ylim(-reach_um, reach_um)
    axes.set_aspect("equal")
    axes.set_xlabel(f"{'xyz'[i]} deviation [µm]")
    axes.set_ylabel(f"{'xyz'[j]} deviation [µm]")
    axes.grid(alpha=0.3)


@matplotlib.rc_context(NO_MATH)
def save_repeatability_field(pose: PoseResult, path: Path, title: str = "") -> None:
    """:func:`repeatability_field` written to ``path`` (PNG)."""
    save_png(repeatability_field(pose, title), path)


@matplotlib.rc_context(NO_MATH)
def repeatability_field(pose: PoseResult, title: str = "") -> Figure:
    """The paper's "repeatability field" (Fig. 10-13) of one pose, in µm.

    Left: the cycle cloud around the commanded position, the reference circle
    of the transmission offset epsilon_t, the dispersion band between the
    smallest and largest friction effect (epsilon_D1, epsilon_D2), the
    barycenter and the RP_l circle around it, per approach direction. Right: the
    distance of each cycle from the commanded position, with the same band.
    """
    deviations = (pose.positions_m - pose.commanded_position_m) * UM_PER_M
    distances = np.linalg.norm(deviations, axis=1)
    eps_t = np.linalg.norm(pose.reference_position_m - pose.commanded_position_m) * UM_PER_M
    eps_d1, eps_d2 = distances.min(), distances.max()
    i, j = field_axes(deviations)

    directions = pose.metrics.directions
    one = len(directions) == 1
    # several directions: the legend goes below both panels, on a taller figure
    fig = agg_figure(figsize=(11, 4.8 if one else 6.2))
    field, series = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1.1, 1]})
    band_colour, ref_colour = "#f4a261", "#264653"
    field.add_patch(Circle((0, 0), eps_d2, color=band_colour, alpha=0.35, lw=0,
                           label=f"dispersion band ε_D1–ε_D2 = {eps_d1:.2f}–{eps_d2:.2f} µm"))
    field.add_patch(Circle((0, 0), eps_d1, color="white", lw=0))
    field.add_patch(Circle((0, 0), eps_t, fill=False, ls="--", color=ref_colour, lw=1.2,
                           label=f"ε_t reference circle = {eps_t:.2f} µm"))
    centres = [(m.barycenter_m - pose.commanded_position_m) * UM_PER_M for m in directions.values()]
    radii = [m.RP_l_m * UM_PER_M for m in directions.values()]
    for (label, m), centre, rp_l, colour in zip(directions.items(), centres, radii, DIRECTION_COLOURS, strict=False):
        text = (f"RP_l = {rp_l:.2f} µm around the barycenter" if one else
                f"{label}: RP_l = {rp_l:.2f} µm, AP_p = {m.AP_p_m * UM_PER_M:.2f} µm (barycenter ×)")
        field.add_patch(Circle((centre[i], centre[j]), rp_l, fill=False, color=colour, lw=1.2, label=text))
    field.scatter(deviations[:, i], deviations[:, j], s=14, color="#2a9d8f", alpha=0.8, zorder=3,
                  label=f"{pose.cycles} cycles")
    field.plot(0, 0, "k+", ms=12, mew=2, zorder=4, label="commanded position")
    for m, centre, colour in zip(directions.values(), centres, DIRECTION_COLOURS, strict=False):
        field.plot(centre[i], centre[j], "x", color=colour, ms=9, mew=2, zorder=4,
                   label=f"barycenter, AP_p = {m.AP_p_m * UM_PER_M:.2f} µm" if one else None)
    reach = max(eps_d2, eps_t, *(np.linalg.norm(c) + r for c, r in zip(centres, radii, strict=True)), 1.0) * 1.15
    frame_field(field, i, j, reach)
    field.set_title("repeatability field")
    if one:
        field.legend(loc="upper left", fontsize=7, framealpha=0.9)
    else:
        fig.legend(*field.get_legend_handles_labels(), loc="lower center", ncol=3, fontsize=7)

    cycles = np.arange(1, pose.cycles + 1)
    series.axhspan(eps_d1, eps_d2, color=band_colour, alpha=0.35)
    series.axhline(eps_t, ls="--", color=ref_colour, lw=1.2)
    series.plot(cycles, distances, "o-", ms=3, lw=0.6, color="#2a9d8f")
    series.set_xlabel("cycle")
    series.set_ylabel("distance from commanded position [µm]")
    series.set_ylim(0, reach)
    series.set_title("each cycle")
    series.grid(alpha=0.3)
    fig.suptitle(title)
    fig.tight_layout(rect=(0, 0 if one else 0.15, 1, 1))
    return fig


@matplotlib.rc_context(NO_MATH)
def save_drift_figure(drift: PoseDrift, path: Path, title: str = "") -> None:
    """:func:`drift_figure` written to ``path`` (PNG)."""
    save_png(drift_figure(drift, title), path)


@matplotlib.rc_context(NO_MATH)
def drift_figure(drift: PoseDrift, title: str = "") -> Figure:
    """A pose's ISO 9283 drift test against time, in µm and °C: the change of AP_p and RP_l from the start set to
    each set along the span (the end set's among them, and sets between; each a marker at its middle, a bar over its
    cycles), one line per approach direction, means over the simulated tests with a band of ``BAND_ERRORS`` Monte
    Carlo standard errors (of the tests' own changes); below, each warming joint's temperature at every cycle's start
    (its mean over the tests, with its band)."""
    test = drift.test
    minutes = test.span_cycles * drift.cycle_time_s >= MINUTES_FROM_S
    unit, scale = ("min", 1 / 60) if minutes else ("s", 1.0)
    fig = agg_figure(figsize=(9, 8.5))
    ap_axes, rp_axes, heat = fig.subplots(3, 1, sharex=True)
    times, half = drift.set_times_s * scale, test.set_cycles * drift.cycle_time_s / 2 * scale
    band = f"band: ±{BAND_ERRORS} Monte Carlo standard errors"
    for (label, series), colour in zip(drift.directions.items(), DIRECTION_COLOURS * len(drift.directions),
                                       strict=False):
        for axes, figure, mean_m, error_m in ((ap_axes, "AP_p", series.AP_p_m, series.AP_p_change_error_m),
                                              (rp_axes, "RP_l", series.RP_l_m, series.RP_l_change_error_m)):
            change, error = (mean_m - mean_m[0]) * UM_PER_M, BAND_ERRORS * error_m * UM_PER_M
            axes.fill_between(times, change - error, change + error, color=colour, alpha=0.25, lw=0)
            axes.errorbar(times, change, xerr=half, fmt="o-", ms=4, lw=1.2, capsize=0, color=colour,
                          label=f"approach {label} (start set: {figure} = {mean_m[0] * UM_PER_M:.2f} µm)")
    for axes, figure in ((ap_axes, "AP_p"), (rp_axes, "RP_l")):
        axes.axhline(0.0, color="#264653", lw=0.8, ls="--")
        axes.set_ylabel(f"{figure} − start set's [µm]")
        axes.set_title(f"{figure} of sets of {test.set_cycles} cycles from the start set's, means over {test.tests} "
                       f"simulated tests ({band})", fontsize=9)
        axes.grid(alpha=0.3)
        axes.legend(fontsize=7, ncol=2)
    cycle_times = drift.cycle_times_s * scale
    colours = colormaps["viridis"](np.linspace(0, 0.9, max(len(drift.joints), 1)))
    for j, (joint, colour) in enumerate(zip(drift.joints, colours, strict=False)):
        mean, error = drift.temperature_C[:, j], BAND_ERRORS * drift.temperature_error_C[:, j]
        heat.fill_between(cycle_times, mean - error, mean + error, color=colour, alpha=0.25, lw=0)
        heat.plot(cycle_times, mean, lw=1.2, color=colour, label=joint)
    if drift.joints:
        heat.set_title(f"joint temperatures at each cycle's start ({test.start} start; {band})", fontsize=9)
        heat.legend(fontsize=7, ncol=3)
    else:
        heat.text(0.5, 0.5, "no joint's friction has a thermal model: temperatures not modelled",
                  transform=heat.transAxes, ha="center", va="center", fontsize=9)
        heat.set_title("joint temperatures", fontsize=9)
    heat.set_ylabel("temperature [°C]")
    heat.set_xlabel(f"time from the drift test's start [{unit}]")
    heat.set_xlim(0, test.span_cycles * drift.cycle_time_s * scale)
    heat.grid(alpha=0.3)
    fig.suptitle(title)
    fig.tight_layout()
    return fig
