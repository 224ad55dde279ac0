"""The folders of ``tribokin measure`` and ``tribokin calibrate``, each written all at once."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from tribokin.calibration.cross_validation import predicted_clouds
from tribokin.measured.calibrated import PARITY_FIGURE, CalibrationResult
from tribokin.measured.iso_figures import MeasurementResult
from tribokin.measurement.figures import pose_clouds
from tribokin.output.dispatch import folder_writer
from tribokin.output.folder import atomic_folder
from tribokin.output.json_files import write_json
from tribokin.output.writers import write_rows
from tribokin.study.names import cloud_figure_file, pose_figure_file

DRIFT_FIGURE = "drift.png"


@folder_writer.register(MeasurementResult)
def write_measurement(result: MeasurementResult, out, force: bool = False, report: str = "full") -> Path:
    """``summary.json``, ``poses.csv``, ``field_<pose>.png``, ``drift.png`` (rows with times) and, unless ``report``
    is ``"none"``, ``report.html``, written to ``out`` all at once."""
    from tribokin.viz.measured import save_drift, save_measured_field, write_measurement_report

    summary, rows, name = result.summary(), result.rows(), Path(result.file).name
    measurements, registration = result.measurements, result.registration
    with atomic_folder(out, force) as folder:
        write_json(summary, folder / "summary.json")
        write_rows(rows, [], folder / "poses.csv")
        for pose, pose_figures in zip(measurements.poses, result.figures, strict=True):
            save_measured_field(pose_figures, pose_clouds(pose, registration).positions_m,
                                folder / pose_figure_file(pose.name), title=f"{name} — {pose.name}")
        if result.timed:
            save_drift(measurements, registration, folder / DRIFT_FIGURE, title=name)
        if report != "none":
            names = [pose_figure_file(p.name) for p in measurements.poses] + ([DRIFT_FIGURE] if result.timed else [])
            write_measurement_report(summary, rows, folder, names)
    return Path(out)


@folder_writer.register(CalibrationResult)
def write_calibration(result: CalibrationResult, out, force: bool = False, report: str = "full") -> Path:
    """``calibration.json``, ``comparison.csv``, ``calibrated.toml``, ``clouds_<pose>.png``, ``parity.png``, the
    calibrated map's figures and, unless ``report`` is ``"none"``, ``report.html``, written to ``out`` all at once."""
    from tribokin.viz.calibration import ParityPoint, PredictedCloud, save_calibration_clouds, save_parity
    from tribokin.viz.calibration_report import write_calibration_report
    from tribokin.viz.maps import save_map_figures

    summary, rows, calibration = result.summary(), result.rows(), result.calibration
    with atomic_folder(out, force) as folder:
        write_json(summary, folder / "calibration.json")
        write_rows(rows, [], folder / "comparison.csv")
        (folder / "calibrated.toml").write_text(result.calibrated_text(Path(out)), encoding="utf-8")
        figures = []
        for pose in result.poses_in_base_frame():
            clouds = [PredictedCloud(s.direction, np.asarray(s.points_m), centre, covariance)
                      for s, (covariance, centre) in zip(pose.series, predicted_clouds(calibration, pose), strict=True)]
            save_calibration_clouds(clouds, folder / cloud_figure_file(pose.label), title=f"{pose.label}")
            figures.append(cloud_figure_file(pose.label))
        parity = [ParityPoint(f"{c.pose} {c.direction}", c.figure, c.held_out) for c in result.compared]
        save_parity(parity, folder / PARITY_FIGURE, title="held-out poses: measured against predicted")
        figures.insert(0, PARITY_FIGURE)
        if result.map is not None:
            figures += [p.name for p in save_map_figures(result.map, folder, f"{result.calibrated.name} (calibrated)")]
        if report != "none":
            write_calibration_report(summary, rows, folder, figures)
    return Path(out)
