"""Figures and report page of measured data (``tribokin measure``): repeatability field, drift, report.html.

The field is that of :func:`tribokin.viz.figures.save_repeatability_field` without what only a
simulation knows (the commanded position's reference circle and the friction band): the measured
cycles about the pose's pooled barycentre, each direction's barycentre and RP_l circle. The page is
``run``'s report without the 3-D scene: the settings, the ISO table and the PNGs.
"""

from __future__ import annotations

import html
import json
from pathlib import Path

import matplotlib
import numpy as np
from matplotlib.patches import Circle

from tribokin.iso9283.metrics import barycenter
from tribokin.measurement.contract import Measurements
from tribokin.measurement.figures import PoseFigures, pose_clouds
from tribokin.measurement.registration import Registration
from tribokin.units import UM_PER_M
from tribokin.viz.canvas import agg_figure
from tribokin.viz.figures import DIRECTION_COLOURS, field_axes, frame_field
from tribokin.viz.report import STYLE, embedded_figures, html_table, key_value_table, write_page

#: Columns of the measured ISO table: (``poses.csv`` row key, header with unit).
MEASURED_COLUMNS = (("name", "pose"), ("direction", "direction"), ("cycles", "cycles"), ("RP_l_um", "RP_l [µm]"),
                    ("RP_l_95_um", "RP_l 95 % interval [µm]"), ("AP_p_um", "AP_p [µm]"), ("vAP_p_um", "vAP_p [µm]"),
                    ("RP_l_all_directions_um", "RP_l all directions [µm]"), ("RP_a_mdeg", "RP_a [mdeg]"),
                    ("RP_b_mdeg", "RP_b [mdeg]"), ("RP_c_mdeg", "RP_c [mdeg]"), ("noise_flags", "within 2× noise"))


@matplotlib.rc_context({"text.parse_math": False})  # names as written: '$' is no math
def save_measured_field(figures: PoseFigures, clouds_m: list[np.ndarray], path: Path, title: str = "") -> None:
    """Repeatability field of one measured pose, in µm about its pooled barycentre: left the cycles of each
    direction (``clouds_m``, (n, 3) [m] per direction, as the figures used them) with its barycentre and RP_l
    circle; right each cycle's distance from the pooled barycentre, in file order per direction."""
    centre = barycenter(np.concatenate(clouds_m))
    deviations = [(points - centre) * UM_PER_M for points in clouds_m]
    i, j = field_axes(np.concatenate(deviations))
    fig = agg_figure(figsize=(11, 5.4))
    field, series = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1.1, 1]})
    reach, start = 1.0, 1
    for d, points, colour in zip(figures.directions, deviations, DIRECTION_COLOURS * len(deviations), strict=False):
        middle = (d.barycenter_m - centre) * UM_PER_M
        rp_l = 0.0 if d.RP_l_m is None else d.RP_l_m * UM_PER_M
        text = f"{d.direction}: {d.cycles} cycles, " + ("too short for RP" if d.RP_l_m is None
                                                         else f"RP_l = {rp_l:.2f} µm")
        field.scatter(points[:, i], points[:, j], s=16, color=colour, alpha=0.8, zorder=3, label=text)
        field.plot(middle[i], middle[j], "x", color=colour, ms=9, mew=2, zorder=4)
        if d.RP_l_m is not None:
            field.add_patch(Circle((middle[i], middle[j]), rp_l, fill=False, color=colour, lw=1.2))
        distances = np.linalg.norm(points, axis=1)
        series.plot(np.arange(start, start + len(points)), distances, "o-", ms=3, lw=0.6, color=colour)
        start += len(points)
        reach = max(reach, np.linalg.norm(middle) + rp_l, distances.max())
    reach *= 1.15
    field.plot(0, 0, "k+", ms=12, mew=2, zorder=4, label="pooled barycentre")
    frame_field(field, i, j, reach)
    field.set_title(f"repeatability field (RP_l all directions = {figures.RP_l_all_directions_m * UM_PER_M:.2f} µm)")
    fig.legend(*field.get_legend_handles_labels(), loc="lower center", ncol=3, fontsize=7)
    series.set_xlabel("cycle (per direction, in order)")
    series.set_ylabel("distance from pooled barycentre [µm]")
    series.set_ylim(0, reach)
    series.set_title("each cycle")
    series.grid(alpha=0.3)
    fig.suptitle(title)
    fig.tight_layout(rect=(0, 0.12, 1, 1))
    fig.savefig(path, dpi=110)


@matplotlib.rc_context({"text.parse_math": False})
def save_drift(measurements: Measurements, registration: Registration | None, path: Path, title: str = "") -> None:
    """The barycentre's path over time: per pose and direction of two or more cycles, the distance [µm] of the
    running barycentre (mean of the cycles so far, in time order) from the series' final barycentre."""
    fig = agg_figure(figsize=(9, 4.8))
    axes = fig.subplots()
    for pose in measurements.poses:
        for series, points in zip(pose.series, pose_clouds(pose, registration).positions_m, strict=True):
            if series.too_short:
                continue
            order = np.argsort(series.times_s, kind="stable")
            running = np.cumsum(points[order], axis=0) / np.arange(1, len(order) + 1)[:, None]
            axes.plot(series.times_s[order], np.linalg.norm(running - running[-1], axis=1) * UM_PER_M, "o-",
                      ms=3, lw=0.8, label=f"{pose.name} {series.direction}")
    axes.set_xlabel("t [s]")
    axes.set_ylabel("running barycentre from final [µm]")
    axes.set_title("drift of the barycentre")
    axes.grid(alpha=0.3)
    axes.legend(fontsize=7, ncol=2)
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def _interval(value) -> str | None:
    return None if value is None else f"{value[0]:.3f}–{value[1]:.3f}"


def registration_text(registration: dict) -> str:
    """The report's line of ``summary.json``'s registration entry: the best fit's poses and residual, the transform
    given, or why the frame was kept; its warning after it."""
    if not registration["made"]:
        text = registration["why"]
    elif registration["method"] == "best-fit":
        text = f"made on {len(registration['poses'])} poses, rms residual {registration['rms_residual_um']:.3f} µm"
    else:
        rms = registration["rms_residual_um"]
        text = registration["why"] + ("" if rms is None else f", rms residual {rms:.3f} µm")
    warning = registration.get("warning")
    return text if warning is None else f"{text} (warning: {warning})"


def measurement_report_html(summary: dict, rows: list[dict], folder: Path, figure_names: list[str]) -> str:
    """The report page: settings, the ISO table of ``rows`` (``poses.csv`` rows before flattening), figures."""
    settings = summary["settings"]
    registration = settings["registration"]
    correction = settings["commanded_correction"]
    floor = settings["noise_floor"]
    inputs = {
        "file": settings["file"], "sha256": settings["sha256"], "columns": ", ".join(settings["columns"]),
        "registration": registration_text(registration),
        "re-taught points": correction["why"] + ("" if correction["largest_spread_um"] is None else
                                                 f" (largest spread {correction['largest_spread_um']:.3f} µm)"),
        "bootstrap": json.dumps(settings["bootstrap"], ensure_ascii=False),
        "noise floor": "none given" if floor is None else (f"{floor['file']}: {floor['readings']} readings, RP_l "
                                                            f"{floor['RP_l_um']:.3f} µm"),
    }
    if settings["segmentation"] is not None:
        segmentation = settings["segmentation"]
        inputs["segmentation"] = (f"{segmentation['dwells']} dwells, {len(segmentation['unmatched'])} unmatched")
    table = [[_interval(row[key]) if key == "RP_l_95_um" else row[key] for key, _ in MEASURED_COLUMNS]
             for row in rows]
    title = html.escape(f"tribokin measure — {Path(settings['file']).name}")
    return f"""<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>{title}</title><style>{STYLE}</style></head>
<body><h1>{title}</h1>
<h2>Inputs</h2>{key_value_table(inputs)}
<h2>ISO 9283 figures per pose</h2>{html_table([header for _, header in MEASURED_COLUMNS], table)}
<h2>Figures</h2>{embedded_figures(folder, figure_names)}
</body></html>
"""


def write_measurement_report(summary: dict, rows: list[dict], folder, figure_names: list[str]) -> Path:
    """Write ``folder/report.html`` (a temporary name, then renamed); returns its path."""
    return write_page(folder, measurement_report_html(summary, rows, Path(folder), figure_names))
