"""A measurement file's ISO 9283 figures (``tribokin measure``), in the folder shape of ``run``.

Everything is read and checked first (the memory, the file, the noise-floor file, the pose names that become
file names); then the figures are computed into a :class:`MeasurementResult`, which writes ``summary.json``,
``poses.csv`` (one row per pose and direction, the column names of ``run``'s), ``field_<pose>.png``,
``drift.png`` (with ``t_s``) and, unless ``report == "none"``, ``report.html``.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field
from pathlib import Path

from tribokin.checks import argument, positive, seed_int
from tribokin.maps.budget import check_parts
from tribokin.measured.written import Written
from tribokin.measurement.contract import Measurements, file_size, read_measurements, read_stream
from tribokin.measurement.drift import pose_drift
from tribokin.measurement.figures import (
    BOOTSTRAP_RESAMPLES,
    BOOTSTRAP_SEED,
    PoseFigures,
    bootstrap_bytes,
    measurement_figures,
)
from tribokin.measurement.independence import Independence, independence_settings, pose_independence
from tribokin.measurement.noise import Flag, NoiseFloor, flag_figures, noise_floor
from tribokin.measurement.registration import Choice, Frame, Registration, Transform, checked_choice, choose_frame
from tribokin.measurement.segmentation import (
    DWELL_MIN_DURATION_S,
    DWELL_RADIUS_M,
    MATCH_RADIUS_M,
    Dwell,
    dwell_measurements,
    find_dwells,
    label_dwells,
)
from tribokin.output.provenance import software_versions
from tribokin.study.names import check_measured_pose_names, pose_figure_file
from tribokin.units import UM_PER_M, um

#: Bytes per row of a measurement file while its figures are drawn (the field's points, the drift plot's), measured
#: (``tracemalloc``) and rounded up about twofold.
DRAWN_BYTES_PER_ROW = 200
#: Report-row keys that belong to the pose (across its directions), not to one direction.
POSE_KEYS = ("vAP_p_um", "RP_l_all_directions_um", "commanded_spread_um", "commanded_corrected", "registered")
#: What a figure is flagged against (``summary.json``'s ``noise_floor.rule``).
FLAG_RULE = ("a figure at or below 2x the floor is flagged: RP_l and vAP_p against the floor's RP_l, ellipsoid "
             "semi-axes against its largest per-axis standard deviation")


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
        """The options, each checked positive (a :class:`~tribokin.errors.SettingsError` names the field)."""
        return Segmenting(*(argument(positive, getattr(self, name), name)
                            for name in ("radius_m", "min_duration_s", "match_radius_m")))


@dataclass(frozen=True)
class Segmentation:
    """A raw stream cut into dwells: the options and every dwell found (an unmatched one has no pose)."""

    options: Segmenting
    dwells: tuple[Dwell, ...]

    @property
    def unmatched(self) -> tuple[Dwell, ...]:
        """The dwells at a position visited once, which no pose takes."""
        return tuple(d for d in self.dwells if d.pose is None)

    def summary(self) -> dict:
        """``summary.json``'s ``settings.segmentation``."""
        return {"dwell_radius_m": self.options.radius_m, "dwell_min_duration_s": self.options.min_duration_s,
                "match_radius_m": self.options.match_radius_m, "dwells": len(self.dwells),
                "unmatched": [{"start_s": d.start_s, "end_s": d.end_s, "position_m": d.position_m.tolist()}
                              for d in self.unmatched]}


@dataclass(frozen=True)
class CommandedCorrection:
    """Whether each row was referred to its own commanded position, why, and the largest spread of a pose's
    commanded positions [µm] (``None``: none given)."""

    made: bool
    why: str
    largest_spread_um: float | None

    @classmethod
    def of(cls, figures: tuple[PoseFigures, ...]) -> CommandedCorrection:
        """The correction the figures made."""
        spreads = [f.commanded_spread_m for f in figures if f.commanded_spread_m is not None]
        if not spreads:
            return cls(False, "no commanded positions", None)
        made = any(f.commanded_corrected for f in figures)
        largest = um(max(spreads))
        if made:
            why = ("each row referred to its own commanded position, turned into the measuring frame by the "
                   "registration")
        elif largest == 0:
            why = "the commanded positions of each pose agree"
        else:
            why = "not made: the commanded positions within a pose differ, and without a registration they cannot " \
                  "be turned into the measuring frame; rows are used as measured"
        return cls(made, why, largest)


@dataclass(frozen=True, eq=False)
class MeasurementResult(Written):
    """The ISO 9283 figures of a measurement file.

    Attributes:
        file: the file, as given.
        sha256: its SHA-256 digest.
        measurements: its poses (for a raw stream, the dwells' cycles).
        segmentation: how a raw stream was cut into dwells, or ``None`` (a measurement file).
        frame: the measuring frame as ``registration=`` left it: registered to the world frame, or kept.
        figures: per pose, its figures.
        seed: seed of the bootstrap intervals of RP_l.
        noise_file: the noise-floor readings' file, or ``None``.
        floor: the instrument's noise floor, or ``None``.
        flags: the figures within 2x the floor.
        drifts: per pose, the drift of its series (:func:`~tribokin.measurement.drift.pose_drift`).
        independence: per pose, each series' lag-one autocorrelation and Ljung-Box test in time order
            (:func:`~tribokin.measurement.independence.pose_independence`).
        versions: the software that computed them (:func:`~tribokin.output.provenance.software_versions`).
    """

    file: str
    sha256: str
    measurements: Measurements
    segmentation: Segmentation | None
    frame: Frame
    figures: tuple[PoseFigures, ...]
    seed: int
    noise_file: str | None
    floor: NoiseFloor | None
    flags: tuple[Flag, ...]
    drifts: tuple[tuple, ...]
    independence: tuple[tuple[Independence, ...], ...]
    versions: dict = field(repr=False)

    @property
    def correction(self) -> CommandedCorrection:
        """The correction of rows to their own commanded positions."""
        return CommandedCorrection.of(self.figures)

    @property
    def registration(self) -> Registration | None:
        """The measuring frame's registration to the world frame, or ``None`` (kept as measured)."""
        return self.frame.registration

    @property
    def registration_why(self) -> str | None:
        """Why the frame is not registered (``None``: it is)."""
        return None if self.registration is not None else self.frame.why

    @property
    def timed(self) -> bool:
        """Whether the rows have times (``t_s``): the drift is then drawn over time (``drift.png``)."""
        return self.measurements.poses[0].series[0].times_s is not None

    def flag_names(self, pose: str, direction: str | None) -> list[str]:
        """The flagged figures of a pose's direction (``None``: across its directions)."""
        return [f.figure for f in self.flags if f.pose == pose and f.direction == direction]

    def rows(self) -> list[dict]:
        """``poses.csv``'s rows, one per pose and direction under ``run``'s names: ``name``, ``direction``, its
        figures (with ``barycenter_m`` and the noise flags), then the pose's."""
        rows = []
        for figures in self.figures:
            for row, direction in zip(figures.report_rows(), figures.directions, strict=True):
                rows.append({"name": row.pop("pose"), "direction": row.pop("direction"), "cycles": row.pop("cycles"),
                             "barycenter_m": direction.barycenter_m.tolist(), **row,
                             "noise_flags": " ".join(self.flag_names(figures.pose, direction.direction))})
        return rows

    def summary(self) -> dict:
        """The content of ``summary.json``."""
        floor = None if self.floor is None else {
            "file": self.noise_file, "readings": self.floor.readings, "RP_l_um": um(self.floor.RP_l_m),
            "std_um": (self.floor.std_m * UM_PER_M).tolist(), "flag_factor": 2.0, "rule": FLAG_RULE}
        rows = iter(self.rows())
        poses = []
        for figures, drift, tests in zip(self.figures, self.drifts, self.independence, strict=True):
            pose_rows = [next(rows) for _ in figures.directions]
            pose = {"name": figures.pose, "cycles": sum(d.cycles for d in figures.directions),
                    **{key: pose_rows[0][key] for key in POSE_KEYS}, "directions": {}}
            for row in pose_rows:
                pose["directions"][row["direction"]] = {key: value for key, value in row.items()
                                                        if key not in (*POSE_KEYS, "name", "direction")}
                pose["directions"][row["direction"]]["noise_flags"] = self.flag_names(figures.pose, row["direction"])
            for test in tests:
                pose["directions"][test.direction].update(test.report_fields())
            pose["drift"] = [d.report_row() for d in drift]
            pose["noise_flags"] = self.flag_names(figures.pose, None)
            poses.append(pose)
        correction = self.correction
        return {
            "settings": {
                "file": self.file, "sha256": self.sha256,
                "columns": list(self.measurements.columns) if self.segmentation is None else ["t_s", "x, y, z"],
                "segmentation": None if self.segmentation is None else self.segmentation.summary(),
                "registration": self.frame.summary(),
                "commanded_correction": {"made": correction.made, "why": correction.why,
                                         "largest_spread_um": correction.largest_spread_um},
                "bootstrap": {"resamples": BOOTSTRAP_RESAMPLES, "seed": self.seed, "interval": "percentile, 95 %"},
                "noise_floor": floor,
                "independence": independence_settings(),
            },
            "reproduce": {"versions": self.versions},
            "poses": poses,
        }


def read_input(path, segmenting: Segmenting | None) -> tuple[Measurements, Segmentation | None]:
    """The measurements of ``path``: a measurement file, or with ``segmenting`` a raw stream cut into dwells."""
    if segmenting is None:
        return read_measurements(path), None
    stream = read_stream(path)
    dwells = label_dwells(find_dwells(stream.times_s, stream.positions_m, segmenting.radius_m,
                                      segmenting.min_duration_s), segmenting.match_radius_m)
    return dwell_measurements(stream, dwells), Segmentation(segmenting, tuple(dwells))


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


def measure(path, seed: int = BOOTSTRAP_SEED, segmenting: Segmenting | None = None,
            noise_path=None, *, registration: Choice | Transform = "auto") -> MeasurementResult:
    """ISO 9283 figures of a measurement file (module docstring).

    Args:
        path: the measurement file (or, with ``segmenting``, a raw stream).
        seed: seed of the bootstrap intervals of RP_l.
        segmenting: find the dwells of a raw stream with these options.
        noise_path: readings of the robot standing still: figures within 2x of that spread are flagged.
        registration: the measuring frame: ``"auto"`` registers it by a best fit only where that is harmless
            (:mod:`tribokin.measurement.registration`), ``"none"`` keeps it, ``"best-fit"`` registers it (a
            :class:`~tribokin.measurement.registration.RegistrationWarning` where that absorbs accuracy), a
            :class:`~tribokin.measurement.registration.Transform` is applied as given.

    Returns:
        the figures and what they were computed from. A bad ``seed``, ``segmenting`` field or ``registration`` is a
        :class:`~tribokin.errors.SettingsError` naming it; a bad file, an :class:`~tribokin.errors.InputError`
        naming it.
    """
    seed = argument(seed_int, seed, "seed")
    segmenting = None if segmenting is None else segmenting.checked()
    registration = checked_choice(registration)
    check_memory(path, noise_path)
    measurements, segmentation = read_input(path, segmenting)
    floor = None if noise_path is None else noise_floor(read_stream(noise_path, require_time=False))
    check_measured_pose_names([pose.name for pose in measurements.poses], path, pose_figure_file)

    frame = choose_frame(measurements, registration)
    registration = frame.registration
    figures = measurement_figures(measurements, registration, seed=seed)
    flags = () if floor is None else tuple(flag_figures(figures, floor))
    drifts = tuple(tuple(pose_drift(pose, registration)) for pose in measurements.poses)
    independence = tuple(pose_independence(pose, registration) for pose in measurements.poses)
    return MeasurementResult(str(path), hashlib.sha256(Path(path).read_bytes()).hexdigest(), measurements,
                             segmentation, frame, tuple(figures), seed,
                             None if noise_path is None else str(noise_path), floor, flags, drifts,
                             independence, software_versions())
