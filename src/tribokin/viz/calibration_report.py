"""The report page of a calibration (``tribokin calibrate``): inputs, fitted parameters (and, with ``--fit-ar1``, the
friction groups' ar1), measured against predicted per pose, figures (parity plot, clouds, the calibrated study's
map). No 3-D scene."""

from __future__ import annotations

import html
from pathlib import Path

from tribokin.measured.calibrated import INTERVALS
from tribokin.viz.report import STYLE, embedded_figures, html_table, key_value_table, write_page

#: Columns of the comparison table: (``comparison.csv`` key, header with unit).
COMPARISON_COLUMNS = (("pose", "pose"), ("direction", "direction"), ("figure", "figure"), ("cycles", "cycles"),
                      ("measured_um", "measured [µm]"), ("predicted_um", "predicted, all poses [µm]"),
                      ("predicted_low_um", "95 % low [µm]"), ("predicted_high_um", "95 % high [µm]"),
                      ("held_out_predicted_um", "predicted, pose held out [µm]"),
                      ("held_out_low_um", "95 % low [µm]"), ("held_out_high_um", "95 % high [µm]"))


def _shown(value: float | None, unit: str) -> str:
    if value is None:
        return "–"
    return f"{value * 1e6:.4g} µm" if unit == "m" else f"{value:.4g} {unit}"


def _parameter_rows(parameters: list[dict]) -> list[list]:
    rows = []
    for p in parameters:
        if not p["identifiable"]:
            rows.append([p["name"], "not identifiable", "–", "–",
                         f"kept at the fit's {_shown(p['kept_value'], p['unit'])}, not determined"
                         f": {p['hint']}"])
            continue
        interval = ", ".join("unbounded" if v is None else _shown(v, p["unit"]) for v in p["ci95"])
        wald = ", ".join(_shown(v, p["unit"]) for v in p["ci95_wald"])
        rows.append([p["name"], _shown(p["value"], p["unit"]), _shown(p["std_error"], p["unit"]), f"[{interval}]",
                     f"Wald (log scale) [{wald}]"])
    return rows


def _frame_text(registration: dict) -> str:
    """The measuring frame's line: registered (by a best fit, or a transform given) and its residual, or why not;
    its warning after it."""
    if not registration["made"]:
        return registration["why"]
    rms = registration["rms_residual_um"]
    head = "registered to the world" if registration["method"] == "best-fit" else registration["why"]
    text = head + ("" if rms is None else f", rms residual {rms:.1f} µm ({registration['note']})")
    return text if registration["warning"] is None else f"{text} (warning: {registration['warning']})"


def _ar1_text(entry: dict) -> str:
    """``calibration.json``'s ``ar1`` in a line: each group's estimate and interval or why it has none, or why the
    measurements allow none, and the fit's limitation."""
    if entry["reason"] is not None:
        return f"not fitted: {entry['reason']}"
    groups = [f"{g['key']}: {g['value']:.3f} [{g['ci95'][0]:.3f}, {g['ci95'][1]:.3f}] ({g['series']} series)"
              if g["value"] is not None else f"{g['key']}: not fitted ({g['reason']})" for g in entry["groups"]]
    return "; ".join(groups) + f". Note: {entry['limitation']}"


def calibration_report_html(summary: dict, rows: list[dict], folder: Path, figure_names: list[str]) -> str:
    """The page: inputs, parameters, fit, the comparison table of ``rows`` (``comparison.csv``), figures."""
    settings, registration, information = summary["settings"], summary["registration"], summary["information"]
    inputs = {
        "study": f"{settings['study']} (sha256 {settings['study_sha256']})",
        "measurements": f"{settings['measurements']} (sha256 {settings['measurements_sha256']})",
        "robot": f"{settings['robot']}, tool frame {settings['tool_frame']}",
        "fitted": f"{', '.join(settings['fit'])} of joints {settings['fitted_joints']}, tie = {settings['tie']}",
        "configurations": settings["configurations"]["source"],
        "measuring frame": _frame_text(registration),
        "series left out": "; ".join(f"{s['pose']} '{s['direction']}' ({s['cycles']} cycles): {s['why']}"
                                     for s in settings["left_out"]) or "none",
        "intervals": settings["intervals"],
        "predictions": settings["predictions"],
        "fit": (f"log L = {summary['log_likelihood']:.6g}, AIC = {summary['aic']:.6g}, information rank "
                f"{information['rank']} of {information['free_parameters']}, condition number "
                f"{information['condition_number']:.3g}, optimiser converged: {information['converged']}"),
    }
    if "ar1" in summary:
        inputs["ar1 (calibrate --fit-ar1)"] = _ar1_text(summary["ar1"])
    table = [[row[key] for key, _ in COMPARISON_COLUMNS] for row in rows]
    label = next(label for method, label in INTERVALS.values() if method == settings["intervals"])
    title = html.escape(f"tribokin calibrate — {Path(settings['study']).name} on {Path(settings['measurements']).name}")
    return f"""<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>{title}</title><style>{STYLE}</style></head>
<body><h1>{title}</h1>
<h2>Inputs</h2>{key_value_table(inputs)}
<h2>Fitted parameters</h2>{html_table(["parameter", "value", "standard error", f"95 % interval ({label})", "note"],
                                     _parameter_rows(summary["parameters"]), text_columns=(0, 4))}
<h2>Measured against predicted</h2>
<p>RP_l per approach direction and vAP_p per pose; predicted by the fit to every pose, and by the fit without the
pose (what the model predicts where it was not measured).</p>
{html_table([header for _, header in COMPARISON_COLUMNS], table)}
<h2>Figures</h2>{embedded_figures(folder, figure_names)}
</body></html>
"""


def write_calibration_report(summary: dict, rows: list[dict], folder, figure_names: list[str]) -> Path:
    """Write ``folder/report.html``; returns its path."""
    return write_page(folder, calibration_report_html(summary, rows, Path(folder), figure_names))
