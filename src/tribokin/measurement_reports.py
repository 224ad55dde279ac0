"""A measurement file -> ISO 9283 report folder (``tribokin measure``), in the folder shape of ``run``.

Everything is read and checked first (the file, the noise-floor file, the pose names that become
file names); then the figures are computed and the folder is written all at once with
:func:`tribokin.output.folder.atomic_folder`: ``summary.json``, ``poses.csv`` (one row per pose and
direction, the column names of ``run``'s), ``field_<pose>.png``, ``drift.png`` (with ``t_s``) and,
unless ``report == "none"``, ``report.html``.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from pathlib import Path

from tribokin.checks import positive, seed_int
from tribokin.maps.budget import check_parts
from tribokin.measurement.contract import Measurements, file_size, read_measurements, read_stream
from tribokin.measurement.drift import pose_drift
from tribokin.measurement.figures import (
    BOOTSTRAP_RESAMPLES,
    BOOTSTRAP_SEED,
    PoseFigures,
    bootstrap_bytes,
    measurement_figures,
    pose_clouds,
)
from tribokin.measurement.noise import Flag, NoiseFloor, flag_figures, noise_floor
from tribokin.measurement.registration import UNAVAILABLE, Registration, register_measurements
from tribokin.measurement.segmentation import (
    DWELL_MIN_DURATION_S,
    DWELL_RADIUS_M,
    MATCH_RADIUS_M,
    Dwell,
    dwell_measurements,
    find_dwells,
    label_dwells,
)
from tribokin.output.folder import atomic_folder, check_output_folder
from tribokin.output.writers import write_rows
from tribokin.provenance import software_versions
from tribokin.study.names import check_measured_pose_names, pose_figure_file
from tribokin.units import UM_PER_M, um

DRIFT_FIGURE = "drift.png"
#: Bytes per row of a measurement file while its figures are drawn (the field's points, the drift plot's), measured
#: (``tracemalloc``) and rounded up about twofold.
DRAWN_BYTES_PER_ROW = 200
#: Report-row keys that belong to the pose (across its directions), not to one direction.
POSE_KEYS = ("vAP_p_um", "RP_l_all_directions_um", "commanded_spread_um", "commanded_corrected", "registered")


@dataclass(frozen=True)
class Segmenting:
    """How ``--segment`` finds dwells in a raw stream (:mod:`tribokin.measurement.segmentation`).

    Attributes:
        radius_m: a dwell holds still within this radius [m].
        min_duration_s: for at least this long [s].
        match_radius_m: dwells within this distance of a pose's first dwell are its cycles [m].
    """

    radius_m: float = DWELL_RADIUS_M
    min_duration_s: float = DWELL_MIN_DURATION_S
    match_radius_m: float = MATCH_RADIUS_M

    def checked(self) -> Segmenting:
        """The options, each checked positive (errors name the command-line option)."""
        return Segmenting(*(positive(value, "command line", key) for value, key in
                            ((self.radius_m, "--dwell-radius-m"), (self.min_duration_s, "--dwell-min-s"),
                             (self.match_radius_m, "--match-radius-m"))))


def _registration_summary(measurements: Measurements, registration: Registration | None) -> dict:
    if registration is not None:
        return {"made": True, "rms_residual_um": um(registration.rms_residual_m),
                "rotation": registration.rotation.tolist(), "translation_m": registration.translation_m.tolist(),
                "poses": list(registration.poses)}
    has_commanded = measurements.poses[0].pooled("commanded_m") is not None
    return {"made": False, "why": UNAVAILABLE if has_commanded else
            "the measuring frame is not registered: the file has no commanded positions (cx, cy, cz)"}


def _correction_summary(figures: tuple[PoseFigures, ...]) -> dict:
    spreads = [f.commanded_spread_m for f in figures if f.commanded_spread_m is not None]
    if not spreads:
        return {"made": False, "why": "no commanded positions", "largest_spread_um": None}
    made = any(f.commanded_corrected for f in figures)
    largest = um(max(spreads))
    if made:
        why = "each row referred to its own commanded position, turned into the measuring frame by the registration"
    elif largest == 0:
        why = "the commanded positions of each pose agree"
    else:
        why = "not made: the commanded positions within a pose differ, and without a registration they cannot be " \
              "turned into the measuring frame; rows are used as measured"
    return {"made": made, "why": why, "largest_spread_um": largest}


def _flag_names(flags: tuple[Flag, ...], pose: str, direction: str | None) -> list[str]:
    return [f.figure for f in flags if f.pose == pose and f.direction == direction]


def _direction_rows(figures: PoseFigures, flags: tuple[Flag, ...]) -> list[dict]:
    """The pose's report rows under ``run``'s ``poses.csv`` names: ``name``, ``direction``, its figures
    (with ``barycenter_m`` and the noise flags), then the pose's."""
    rows = []
    for row, direction in zip(figures.report_rows(), figures.directions, strict=True):
        rows.append({"name": row.pop("pose"), "direction": row.pop("direction"), "cycles": row.pop("cycles"),
                     "barycenter_m": direction.barycenter_m.tolist(), **row,
                     "noise_flags": " ".join(_flag_names(flags, figures.pose, direction.direction))})
    return rows


def _pose_summary(figures: PoseFigures, rows: list[dict], drift: list[dict], flags: tuple[Flag, ...]) -> dict:
    """A pose in ``summary.json``: its figures across directions, ``directions`` (label -> figures), the drift
    of its series with times, and the noise flags of its figures across directions."""
    pose = {"name": figures.pose, "cycles": sum(d.cycles for d in figures.directions),
            **{key: rows[0][key] for key in POSE_KEYS}, "directions": {}}
    for row in rows:
        pose["directions"][row["direction"]] = {key: value for key, value in row.items()
                                                if key not in (*POSE_KEYS, "name", "direction")}
        pose["directions"][row["direction"]]["noise_flags"] = _flag_names(flags, figures.pose, row["direction"])
    pose["drift"] = drift
    pose["noise_flags"] = _flag_names(flags, figures.pose, None)
    return pose


def _floor_summary(path, floor: NoiseFloor | None) -> dict | None:
    if floor is None:
        return None
    return {"file": str(path), "readings": floor.readings, "RP_l_um": um(floor.RP_l_m),
            "std_um": (floor.std_m * UM_PER_M).tolist(), "flag_factor": 2.0,
            "rule": "a figure at or below 2x the floor is flagged: RP_l and vAP_p against the floor's RP_l, "
                    "ellipsoid semi-axes against its largest per-axis standard deviation"}


def _dwell_summary(dwell: Dwell) -> dict:
    return {"start_s": dwell.start_s, "end_s": dwell.end_s, "position_m": dwell.position_m.tolist()}


def read_input(path, segmenting: Segmenting | None) -> tuple[Measurements, dict | None]:
    """The measurements of ``path``: a measurement file, or with ``segmenting`` a raw stream cut into dwells;
    and the segmentation's summary (its options, dwells found, the unmatched ones), or None."""
    if segmenting is None:
        return read_measurements(path), None
    stream = read_stream(path)
    dwells = label_dwells(find_dwells(stream.times_s, stream.positions_m, segmenting.radius_m,
                                      segmenting.min_duration_s), segmenting.match_radius_m)
    measurements = dwell_measurements(stream, dwells)
    return measurements, {"dwell_radius_m": segmenting.radius_m, "dwell_min_duration_s": segmenting.min_duration_s,
                          "match_radius_m": segmenting.match_radius_m, "dwells": len(dwells),
                          "unmatched": [_dwell_summary(d) for d in dwells if d.pose is None]}


def check_memory(path, noise_path=None, available: int | None = None) -> None:
    """An :class:`InputError` naming the file if measuring it needs more memory than is ``available`` [bytes]
    (default: what the machine has), estimated from its size before it is read: its reading, the bootstrap of a
    series as long as the file (a block of resamples, :func:`~tribokin.measurement.figures.bootstrap_bytes`) and
    the figures drawn."""
    size = file_size(path)
    floor = 0 if noise_path is None else file_size(noise_path).reading_bytes
    check_parts([(size.reading_bytes + floor, f"reading its {size.lines:,} lines"),
                 (bootstrap_bytes(size.lines), "the bootstrap intervals of RP_l"),
                 (DRAWN_BYTES_PER_ROW * size.lines, "its figures")],
                "measuring this file", "split it into several files", path, "rows", available)


def measure(path, out, force: bool = False, seed: int = BOOTSTRAP_SEED, segmenting: Segmenting | None = None,
            noise_path=None, report: str = "full") -> dict:
    """ISO 9283 figures of a measurement file written to the folder ``out`` (module docstring).

    Args:
        path: the measurement file (or, with ``segmenting``, a raw stream).
        out: output folder (must not exist, unless ``force``).
        seed: seed of the bootstrap intervals of RP_l.
        segmenting: find the dwells of a raw stream with these options.
        noise_path: readings of the robot standing still: figures within 2x of that spread are flagged.
        report: ``"full"`` writes ``report.html``, ``"none"`` does not.

    Returns:
        the content of ``summary.json``.
    """
    from tribokin.viz.measured import save_drift, save_measured_field, write_measurement_report

    check_output_folder(out, force)
    seed = seed_int(seed, "command line", "--seed")
    segmenting = None if segmenting is None else segmenting.checked()
    check_memory(path, noise_path)
    measurements, segmentation = read_input(path, segmenting)
    floor = None if noise_path is None else noise_floor(read_stream(noise_path, require_time=False))
    check_measured_pose_names([pose.name for pose in measurements.poses], path, pose_figure_file)

    registration = register_measurements(measurements)
    figures = measurement_figures(measurements, registration, seed=seed)
    flags = () if floor is None else flag_figures(figures, floor)
    drifts = [[d.report_row() for d in pose_drift(pose, registration)] for pose in measurements.poses]
    rows = [_direction_rows(f, flags) for f in figures]
    summary = {
        "settings": {
            "file": str(path), "sha256": hashlib.sha256(Path(path).read_bytes()).hexdigest(),
            "columns": list(measurements.columns) if segmentation is None else ["t_s", "x, y, z"],
            "segmentation": segmentation,
            "registration": _registration_summary(measurements, registration),
            "commanded_correction": _correction_summary(figures),
            "bootstrap": {"resamples": BOOTSTRAP_RESAMPLES, "seed": seed, "interval": "percentile, 95 %"},
            "noise_floor": _floor_summary(noise_path, floor),
        },
        "reproduce": {"versions": software_versions()},
        "poses": [_pose_summary(f, r, d, flags) for f, r, d in zip(figures, rows, drifts, strict=True)],
    }
    timed = measurements.poses[0].series[0].times_s is not None
    with atomic_folder(out, force) as folder:
        (folder / "summary.json").write_text(json.dumps(summary, indent=2) + "\n", encoding="utf-8")
        write_rows([row for pose_rows in rows for row in pose_rows], [], folder / "poses.csv")
        for pose, pose_figures in zip(measurements.poses, figures, strict=True):
            save_measured_field(pose_figures, pose_clouds(pose, registration).positions_m,
                                folder / pose_figure_file(pose.name), title=f"{Path(path).name} — {pose.name}")
        if timed:
            save_drift(measurements, registration, folder / DRIFT_FIGURE, title=Path(path).name)
        if report != "none":
            names = [pose_figure_file(p.name) for p in measurements.poses] + ([DRIFT_FIGURE] if timed else [])
            write_measurement_report(summary, [row for pose_rows in rows for row in pose_rows], folder, names)
    return summary
