"""A study's joint model fitted to a measurement file, and its predictions (``tribokin calibrate``).

Everything is read and checked first (the study and its ``[calibration]``, the robot, the memory, the measurement
file, the pose names that become file names, the configurations); then the maximum-likelihood fit
(:func:`tribokin.calibration.fit.fit`) with a profile-likelihood 95 % interval of every identifiable parameter,
the predicted figures at the measured poses (from the fit to all of them, and left out one at a time), the
calibrated study (its text, parsed and checked as ``tribokin run`` checks it) and, when the study has a ``[map]``,
the calibrated study's workspace map: a :class:`CalibrationResult`, which writes ``calibration.json``,
``comparison.csv``, ``calibrated.toml``, ``clouds_<pose>.png``, ``parity.png``, the map's figures and, unless
``report == "none"``, ``report.html``.

With ``fit_ar1``, each joint friction group's lag-one autocorrelation (the ``ar1`` key) is fitted from the series'
time order too (:mod:`tribokin.calibration.ar1`, the groups :func:`~tribokin.study.assembly.friction_groups`), given
in ``calibration.json`` (``ar1``) and written into ``calibrated.toml``'s friction tables, or the reason the
measurements allow none. The stiffness, backlash and noise floor are fitted as before, as if the cycles were
independent (:data:`AR1_LIMITATION`).
"""

from __future__ import annotations

import hashlib
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import NamedTuple

import numpy as np

from tribokin.calibration.ar1 import METHOD as AR1_METHOD
from tribokin.calibration.ar1 import MIN_CYCLES, Ar1Fit, GroupAr1, fit_group_ar1, timed_series
from tribokin.calibration.blas_threads import single_threaded_blas
from tribokin.calibration.cross_validation import (
    DRAWS,
    PosePrediction,
    PredictedFigure,
    leave_one_pose_out,
    predict_pose,
    prediction_bytes,
)
from tribokin.calibration.data import PoseData
from tribokin.calibration.fit import Calibration, ParameterEstimate, fit, profile_interval
from tribokin.checks import argument, seed_int
from tribokin.errors import InputError, SettingsError
from tribokin.execution import local_workers
from tribokin.kinematics.robot import Robot
from tribokin.maps import budget
from tribokin.maps.budget import check_parts
from tribokin.maps.result import MapResult
from tribokin.maps.schema import MapLayout, study_approaches
from tribokin.measured.written import Written
from tribokin.measurement.contract import file_size
from tribokin.measurement.registration import Choice, Transform, checked_choice
from tribokin.output.provenance import software_versions
from tribokin.run import run_study
from tribokin.study.assembly import (
    check_names,
    friction_groups,
    joint_models,
    load_robot,
    map_robots,
    pose_tasks,
    refuse_series,
    study_runner,
)
from tribokin.study.calibrated_study import WrittenFrictionKey, WrittenValue, calibrated_study_text
from tribokin.study.calibration_data import CalibrationInput, calibration_input, read_robot_measurements
from tribokin.study.names import calibrated_pose_names, check_measured_pose_names, cloud_figure_file
from tribokin.study.reading import parse_study_text, read_study_file
from tribokin.study.spec import ISO_CUBE_POSES, Study
from tribokin.units import UM_PER_M, um

PARITY_FIGURE = "parity.png"
SEED = 9283
#: Per kind of interval (``calibrate(..., intervals=)``, ``--intervals``): what ``calibration.json`` says of it, and
#: the label beside an interval in the printed table, ``calibrated.toml``'s comments and the report.
INTERVALS = {
    "profile": ("profile likelihood (chi-squared, 1 degree of freedom, 95 %); Wald in log space beside it",
                "profile likelihood"),
    "wald": ("Wald in log space, value x exp(+-1.96 standard errors of log value) from the observed information "
             "(intervals 'wald': no profile likelihood)", "Wald, log scale"),
}
PREDICTION_METHOD = (f"expected figure of one test at the fitted values (mean over {DRAWS} simulated tests of the "
                     "measured cycles, first-order model); 95 % prediction interval: 2.5th-97.5th percentile over "
                     f"{DRAWS} tests, each at parameters drawn from the fit's approximate posterior (parameter "
                     "uncertainty and test-to-test spread)")


def _parameter_entry(estimate: ParameterEstimate, profile: tuple[float | None, float | None] | None) -> dict:
    """A parameter in ``calibration.json``: values only where the data determine it; ``kept_value``, for the others,
    the fit's value that ``calibrated.toml`` keeps for its predictions (not a measured value)."""
    if not estimate.identifiable:
        return {"name": estimate.name, "unit": estimate.unit, "value": None, "std_error": None, "ci95": None,
                "ci95_wald": None, "identifiable": False, "hint": estimate.hint, "kept_value": estimate.value}
    return {"name": estimate.name, "unit": estimate.unit, "value": estimate.value, "std_error": estimate.std_error,
            "ci95": list(profile), "ci95_wald": list(estimate.ci95), "identifiable": True, "hint": "",
            "kept_value": None}


def _figure(figure: PredictedFigure | None) -> dict | None:
    if figure is None:
        return None
    return {"measured_um": um(figure.measured_m), "predicted_um": um(figure.predicted_m),
            "ci95_um": [um(v) for v in figure.interval_m]}


def _prediction_entry(prediction: PosePrediction) -> dict:
    return {"pose": prediction.pose,
            "RP_l": {d: _figure(f) for d, f in zip(prediction.directions, prediction.RP_l, strict=True)},
            "vAP_p": _figure(prediction.vAP)}


class Compared(NamedTuple):
    """A measured figure beside its predictions: by the fit to every pose and by the fit without this pose."""

    pose: str
    direction: str
    figure: str
    cycles: int
    fitted: PredictedFigure
    held_out: PredictedFigure

    def row(self) -> dict:
        """A row of ``comparison.csv`` [µm]."""
        fitted, held_out = self.fitted, self.held_out
        return {"pose": self.pose, "direction": self.direction, "figure": self.figure, "cycles": self.cycles,
                "measured_um": um(fitted.measured_m), "predicted_um": um(fitted.predicted_m),
                "predicted_low_um": um(fitted.interval_m[0]), "predicted_high_um": um(fitted.interval_m[1]),
                "held_out_predicted_um": um(held_out.predicted_m), "held_out_low_um": um(held_out.interval_m[0]),
                "held_out_high_um": um(held_out.interval_m[1])}


def _compared(inputs: CalibrationInput, fitted: tuple[PosePrediction, ...], held_out: tuple[PosePrediction, ...]
              ) -> tuple[Compared, ...]:
    """Per pose and direction RP_l, per pose vAP_p (direction ``all``); one-cycle series have no RP_l."""
    compared = []
    for pose, all_poses, others in zip(inputs.poses, fitted, held_out, strict=True):
        pairs = [(d, "RP_l", len(s.points_m), a, o) for d, s, a, o in
                 zip(all_poses.directions, pose.series, all_poses.RP_l, others.RP_l, strict=True)]
        pairs.append(("all", "vAP_p", sum(len(s.points_m) for s in pose.series), all_poses.vAP, others.vAP))
        compared += [Compared(pose.label, *pair) for pair in pairs if pair[3] is not None]
    return tuple(compared)


def _written_values(inputs: CalibrationInput, calibration: Calibration,
                    intervals: dict[str, tuple[float | None, float | None]], label: str) -> list[WrittenValue]:
    """The joint keys of ``calibrated.toml``: every joint parameter ``[calibration]`` frees, at the fit's value,
    each with a comment saying what is known of it (its interval's kind as ``label``)."""
    model, fitted = inputs.model, calibration.model
    estimates = {e.name: e for e in calibration.parameters}
    values = []
    for i, joint in enumerate(model.joint_names):
        for key, free in (("stiffness", model.fit_stiffness[i]), ("backlash", model.fit_backlash[i])):
            if not free:
                continue
            name = "joints.stiffness_factor" if key == "stiffness" and model.tied else f"joints.{joint}.{key}"
            estimate = estimates[name]
            unit = "N/m" if model.prismatic[i] and key == "stiffness" else "N·m/rad" if key == "stiffness" else \
                "m" if model.prismatic[i] else "rad"
            if not estimate.identifiable:
                values.append(WrittenValue(joint, key, float(getattr(fitted, key)[i]),
                                           "the fit's value, kept for the predictions it makes: not identifiable "
                                           f"from the measurements ({estimate.hint})"))
                continue
            low, high = intervals[name]
            factor = f" (common factor {estimate.value:.4g} of the study's value)" if name.endswith("factor") else ""
            if name.endswith("factor"):
                low, high = (None if v is None else v * float(model.stiffness[i]) for v in (low, high))
            shown = ", ".join("unbounded" if v is None else f"{v:.4g}" for v in (low, high))
            values.append(WrittenValue(joint, key, float(getattr(fitted, key)[i]),
                                       f"fitted{factor}: 95 % interval [{shown}] {unit} ({label})"))
    return values


#: What the fit of the stiffness, backlash and noise floor assumes of the cycles (``calibration.json``'s
#: ``ar1.limitation``).
AR1_LIMITATION = ("the stiffness, backlash and noise floor are fitted as if each series' cycles were independent "
                  "(Wishart likelihood of its scatter): with correlated friction a short series' scatter is smaller "
                  "than the friction's spread (for an AR(1), E[S^2] = sigma^2 (1 - 2/(n(n - 1)) sum_k (n - k) "
                  "rho^k)), so the stiffness is then overestimated")


def _ar1_fit(study: Study, robot: Robot, poses: list[PoseData], calibration: Calibration) -> Ar1Fit:
    """Each friction group's ``ar1`` from the series (their points in the world frame) and the fitted model."""
    groups = friction_groups(study, robot.joint_names)
    index = {joint: g for g, (_, joints) in enumerate(groups) for joint in joints}
    group_of_joint = np.array([index.get(joint, -1) for joint in robot.joint_names])
    return fit_group_ar1(timed_series(calibration.model, poses, group_of_joint, len(groups)), groups)


def _ar1_group_entry(group: GroupAr1) -> dict:
    estimate = group.estimate
    return {"key": group.group, "joints": list(group.joints), "value": None if estimate is None else estimate.value,
            "ci95": None if estimate is None else [estimate.low, estimate.high], "series": group.series,
            "largest_share": group.largest_share, "reason": group.reason or None}


def _ar1_entry(fitted: Ar1Fit) -> dict:
    """``calibration.json``'s ``ar1``."""
    return {"method": AR1_METHOD, "min_cycles": MIN_CYCLES, "series": fitted.series, "longest_series": fitted.longest,
            "reason": fitted.reason or None, "groups": [_ar1_group_entry(g) for g in fitted.groups],
            "limitation": AR1_LIMITATION}


def _written_ar1(fitted: Ar1Fit | None) -> tuple[WrittenFrictionKey, ...]:
    """The ``ar1`` keys ``calibrated.toml`` writes: each estimated group's, in its friction table."""
    if fitted is None:
        return ()
    written = []
    for group in fitted.groups:
        if group.estimate is None:
            continue
        path = group.group.split(".")
        joint, friction = (None, path[1]) if len(path) == 2 else (path[1], path[2])
        estimate = group.estimate
        written.append(WrittenFrictionKey(joint, friction, "ar1", estimate.value,
                                          f"ar1 fitted from the measured series' time order: 95 % interval "
                                          f"[{estimate.low:.3g}, {estimate.high:.3g}] (profile likelihood, "
                                          f"{group.series} series)"))
    return tuple(written)


def ar1_lines(fitted: Ar1Fit) -> list[str]:
    """What the console says of the ``ar1`` fit: one line if the time order allows none, else one per group."""
    if fitted.reason:
        return [f"ar1: not fitted: {fitted.reason}"]
    lines = []
    for group in fitted.groups:
        joints = ", ".join(group.joints)
        if group.estimate is None:
            lines.append(f"ar1 {group.group} ({joints}): not fitted: {group.reason}")
            continue
        e = group.estimate
        lines.append(f"ar1 {group.group} ({joints}): {e.value:.3f}, 95 % interval [{e.low:.3f}, {e.high:.3f}] "
                     f"(profile likelihood; {group.series} series)")
    return lines


def _header(study_path, measurements_path, calibration: Calibration, noise: str | None) -> list[str]:
    lines = [f"Calibrated by `tribokin calibrate {study_path} --measurements {measurements_path}`:",
             "the study's file with the fitted joint values written in (comments give each value's 95 % interval).",
             f"Fit: maximum likelihood, log L = {calibration.log_likelihood:.6g}, AIC = {calibration.aic:.6g}, "
             f"information rank {calibration.rank} of {len(calibration.parameters)}; details in calibration.json.",
             "Values the measurements cannot determine are the fit's, kept for its predictions, and say so."]
    if noise is not None:
        lines.append(f"The instrument's noise floor (not part of the robot's model): {noise}.")
    return lines


def _noise_text(calibration: Calibration, intervals: dict) -> str | None:
    estimate = next((e for e in calibration.parameters if e.name == "noise_floor_m"), None)
    if estimate is None:
        return None
    if not estimate.identifiable:
        return "not identifiable from these measurements"
    low, high = intervals["noise_floor_m"]
    shown = ", ".join("unbounded" if v is None else f"{v * UM_PER_M:.4g}" for v in (low, high))
    return f"{estimate.value * UM_PER_M:.4g} µm, 95 % interval [{shown}] µm"


#: What a calibration does with a measuring frame that is not registered.
UNREGISTERED = ("the measuring frame's rotation is fitted with the model and profiled out (the fit uses the clouds' "
                "shapes and the differences of their barycentres, which do not depend on the frame)")
#: What a registration's residual is to a calibration.
RESIDUAL_NOTE = ("the residual is the robot's geometric error (absolute accuracy), which friction does not explain: "
                 "barycentres serve only to register the frame, never as terms of the fit")


def _registration_entry(inputs: CalibrationInput, calibration: Calibration) -> dict:
    entry = inputs.frame.summary()
    if inputs.registration is None:
        return {**entry, "why": f"{entry['why']}; {UNREGISTERED}", "fitted_rotation": calibration.rotation.tolist()}
    return {**entry, "note": RESIDUAL_NOTE}


def _in_base_frame(pose: PoseData, calibration: Calibration) -> PoseData:
    """``pose`` with its points turned into the world frame by the fit's rotation when the frame was unknown
    (``x_base = Rᵀ x`` up to a shift, which the figures do not show)."""
    if calibration.rotation is None:
        return pose
    return replace(pose, series=tuple(replace(s, points_m=np.asarray(s.points_m) @ calibration.rotation)
                                      for s in pose.series))


def _written_pose_names(study, measured: list[str], source) -> dict[str, str]:
    """The name ``calibrated.toml`` gives each measured pose, checked with the study's name rules before any fit
    (:func:`~tribokin.study.names.calibrated_pose_names`)."""
    own = [(f"poses[{i}].name", p.name) for i, p in enumerate(study.poses)]
    cube = [("iso_cube", name) for name in ISO_CUBE_POSES] if study.iso_cube is not None else []
    return dict(zip(measured, calibrated_pose_names(own + cube, measured, source), strict=True))


def _written_poses(inputs: CalibrationInput, names: dict[str, str]) -> tuple:
    """The measured poses as ``calibrated.toml`` writes them: (name, configuration, approach labels)."""
    return tuple((names[pose.label], q.tolist(), [s.direction for s in pose.series])
                 for pose, q in zip(inputs.poses, inputs.configurations, strict=True))


def _check_runnable(calibrated, robot) -> None:
    """The checks ``tribokin run`` makes of ``calibrated.toml``'s study before it samples (its joint models, names, and
    every pose's loads within the joints' ranges), made before anything is written."""
    runner = study_runner(calibrated, robot, joint_models(calibrated, robot))
    tasks, _ = pose_tasks(calibrated, robot)
    check_names(calibrated, tasks)
    for task in tasks:
        runner.normal_forces(task)


def check_memory(measurements_path, available: int | None = None) -> None:
    """An :class:`InputError` naming the measurement file if calibrating with it needs more memory than is
    ``available`` [bytes] (default: what the machine has), estimated from its size before it is read: its reading
    and the predictions at a series as long as the file (a block of simulated tests,
    :func:`~tribokin.calibration.cross_validation.prediction_bytes`); the fits hold a few numbers per series."""
    size = file_size(measurements_path)
    check_parts([(size.reading_bytes, f"reading its {size.lines:,} lines"),
                 (prediction_bytes(size.lines), "the predictions' simulated tests")],
                "calibrating with this file", "split it into several files", measurements_path, "rows", available)


@dataclass(frozen=True, eq=False)
class CalibrationResult(Written):
    """A study's joint model fitted to measured clouds, its intervals and predictions, and the calibrated study.

    Attributes:
        study_file: the study's file, as given.
        measurements_file: the measurement file, as given.
        measurements_sha256: its SHA-256 digest.
        study: the study read.
        robot: its robot (kinematics only).
        inputs: the calibration's data and model (per measured pose its configuration, Jacobian, series).
        calibration: the fit.
        intervals: per identifiable parameter, its 95 % interval (``None``: unbounded), of ``interval_kind``.
        fitted: per pose, its figures predicted by the fit to every pose.
        held_out: per pose, its figures predicted by the fit to the other poses.
        seed: seed of the predictions' simulated tests.
        calibrated: the calibrated study (its values the fit's), as ``calibrated.toml`` reads from ``out``.
        map: the calibrated study's workspace map (``None``: the study has no ``[map]``).
        versions: the software that computed them.
        header: ``calibrated.toml``'s header comment lines (the command, the fit).
        values: the joint values ``calibrated.toml`` writes, each with its comment.
        written_poses: the measured poses ``calibrated.toml`` adds: (name, configuration, approach labels).
        study_text: the study file's own text, which ``calibrated.toml`` keeps.
        interval_kind: ``"profile"`` (profile likelihood) or ``"wald"`` (Wald in log space) intervals.
    """

    study_file: str
    measurements_file: str
    measurements_sha256: str
    study: Study = field(repr=False)
    robot: Robot = field(repr=False)
    inputs: CalibrationInput = field(repr=False)
    calibration: Calibration = field(repr=False)
    intervals: dict[str, tuple[float | None, float | None]]
    fitted: tuple[PosePrediction, ...]
    held_out: tuple[PosePrediction, ...]
    seed: int
    calibrated: Study = field(repr=False)
    map: MapResult | None = field(repr=False)
    versions: dict = field(repr=False)
    header: tuple[str, ...] = field(repr=False)
    values: tuple[WrittenValue, ...] = field(repr=False)
    written_poses: tuple = field(repr=False)
    study_text: str = field(repr=False)
    interval_kind: str = "profile"
    ar1: Ar1Fit | None = None

    @property
    def registration_why(self) -> str | None:
        """Why the measuring frame is not registered (``None``: it is)."""
        return None if self.inputs.registration is not None else f"{self.inputs.frame.why}; {UNREGISTERED}"

    @property
    def compared(self) -> tuple[Compared, ...]:
        """Per pose and direction RP_l, per pose vAP_p (direction ``all``): measured, and predicted with and without
        the pose (``comparison.csv``'s rows)."""
        return _compared(self.inputs, self.fitted, self.held_out)

    def rows(self) -> list[dict]:
        """``comparison.csv``'s rows [µm]."""
        return [c.row() for c in self.compared]

    def calibrated_text(self, out) -> str:
        """``calibrated.toml``'s text for the folder ``out`` (its relative paths name the same files from there)."""
        path = Path(self.study_file)
        return calibrated_study_text(self.study_text, path.parent, Path(out), list(self.header), list(self.values),
                                     list(self.written_poses), _written_ar1(self.ar1))

    def poses_in_base_frame(self) -> list[PoseData]:
        """The measured poses, their points in the world frame (turned by the fit's rotation when the frame was
        unknown), as the clouds' figures draw them."""
        return [_in_base_frame(p, self.calibration) for p in self.inputs.poses]

    def summary(self) -> dict:
        """The content of ``calibration.json``."""
        study, inputs, calibration = self.study, self.inputs, self.calibration
        return {
            "settings": {
                "study": self.study_file, "study_sha256": study.sha256, "measurements": self.measurements_file,
                "measurements_sha256": self.measurements_sha256,
                "robot": self.robot.label, "tool_frame": self.robot.tool_frame, "joints": self.robot.joint_names,
                "fit": list(study.calibration.fit), "fitted_joints": study.calibration.joints if
                study.calibration.joints == "all" else list(study.calibration.joints), "tie": study.calibration.tie,
                "configurations": {"source": inputs.configuration_source,
                                   "q": {p.label: q.tolist()
                                         for p, q in zip(inputs.poses, inputs.configurations, strict=True)}},
                "left_out": [asdict(item) for item in inputs.left_out],
                "intervals": INTERVALS[self.interval_kind][0], "predictions": PREDICTION_METHOD, "seed": self.seed,
            },
            "parameters": [_parameter_entry(e, self.intervals.get(e.name)) for e in calibration.parameters],
            "log_likelihood": calibration.log_likelihood, "aic": calibration.aic,
            "information": {"rank": calibration.rank, "free_parameters": len(calibration.parameters),
                            "condition_number": calibration.condition_number, "converged": calibration.converged},
            "registration": _registration_entry(inputs, calibration),
            "predictions": [_prediction_entry(p) for p in self.fitted],
            "cross_validation": [_prediction_entry(p) for p in self.held_out],
            **({} if self.ar1 is None else {"ar1": _ar1_entry(self.ar1)}),
            "reproduce": {"versions": self.versions},
        }


@single_threaded_blas()
def calibrate(study, measurements, seed: int = SEED, *, out=None, executor=None, progress=None,
              registration: Choice | Transform = "auto", intervals: str = "profile", fit_ar1: bool = False
              ) -> CalibrationResult:
    """Fit the study's joint model to the measurements (module docstring), on one BLAS thread
    (:mod:`tribokin.calibration.blas_threads`): the same bytes on any machine.

    Args:
        study: the study's file (TOML) with a ``[calibration]`` section.
        measurements: the measurement file (docs/measurement.md).
        seed: seed of the predictions' simulated tests.
        out: the folder ``calibrated.toml`` will be written in, from which the calibrated study is read and checked
            (default: the study's folder); :meth:`CalibrationResult.write` writes its paths for the folder it writes.
        executor: where the calibrated study's map's chunks run (``run_study``).
        progress: the map's progress callback (``run_study``).
        registration: the measuring frame: ``"auto"`` registers it by a best fit only where that is harmless
            (:mod:`tribokin.measurement.registration`), ``"none"`` fits its rotation with the model (profiled out),
            ``"best-fit"`` registers it (a :class:`~tribokin.measurement.registration.RegistrationWarning` where that
            absorbs accuracy), a :class:`~tribokin.measurement.registration.Transform` is applied as given.
        intervals: the identifiable parameters' 95 % intervals: ``"profile"`` (profile likelihood,
            :func:`~tribokin.calibration.fit.profile_interval`: a few seconds of re-fits) or ``"wald"`` (Wald in log
            space, ``value·exp(±1.96·se)`` with se the standard error of log value from the observed information:
            no re-fit, symmetric in log space, less exact where the likelihood is not Gaussian in log space).
        fit_ar1: also fit each joint friction group's ``ar1`` from the series' time order (module docstring), or
            say why the measurements allow none (a ``[map]`` of the calibrated study draws each fitted ``ar1``).

    Returns:
        the fit, its intervals and predictions, and the calibrated study (and its map). A bad ``seed``,
        ``registration`` or ``intervals`` is a :class:`~tribokin.errors.SettingsError` naming it; bad files, an
        :class:`~tribokin.errors.InputError` naming the file and key.
    """
    study_path, measurements_path = Path(study), measurements
    out = study_path.parent if out is None else Path(out)
    seed = argument(seed_int, seed, "seed")
    registration = checked_choice(registration)
    if not isinstance(intervals, str) or intervals not in INTERVALS:
        raise SettingsError(f"must be one of {', '.join(INTERVALS)} (got {intervals!r})", "intervals")
    if not isinstance(fit_ar1, bool):
        raise SettingsError(f"must be True or False (got {fit_ar1!r})", "fit_ar1")
    study = read_study_file(study_path)
    if study.calibration is None:
        raise InputError("no [calibration] section: add one naming what to fit (fit = [\"stiffness\", ...])",
                         study.source, "calibration")
    refuse_series(study, "a calibration", "remove the key to calibrate the joints' independent-cycle model")
    robot = load_robot(study, meshes=False)  # no robot drawn
    models = joint_models(study, robot)
    only_map = replace(study, poses=(), iso_cube=None, calibration=None)
    if study.map is not None:  # the calibrated study's map: its memory checked before the fit, as run checks it
        budget.check_memory(only_map, robot.model.nv, [], local_workers(executor),
                            layout=MapLayout.of(map_robots(only_map, robot), study.map.figure_set,
                                                study_approaches(only_map)))
    check_memory(measurements_path)
    measurements = read_robot_measurements(measurements_path, robot)
    check_measured_pose_names([pose.name for pose in measurements.poses], measurements_path, cloud_figure_file)
    names = _written_pose_names(study, [pose.name for pose in measurements.poses], measurements_path)
    inputs = calibration_input(study, robot, models, measurements, registration)
    if not inputs.model.names():
        raise InputError("nothing to fit for these joints", study.source, "calibration.joints")

    frame = "registered" if inputs.registration is not None else "unknown"
    calibration = fit(inputs.model, inputs.poses, frame=frame)
    interval_kind, intervals = intervals, {
        e.name: profile_interval(calibration, inputs.poses, e.name) if intervals == "profile" else e.ci95
        for e in calibration.parameters if e.identifiable}
    fitted = tuple(predict_pose(calibration, pose, np.random.default_rng([seed, i]))
                   for i, pose in enumerate(inputs.poses))
    held_out = leave_one_pose_out(inputs.model, inputs.poses, seed=seed, frame=frame)
    values = _written_values(inputs, calibration, intervals, INTERVALS[interval_kind][1])
    header = _header(study_path, measurements_path, calibration, _noise_text(calibration, intervals))
    ar1 = _ar1_fit(study, robot, [_in_base_frame(p, calibration) for p in inputs.poses], calibration) \
        if fit_ar1 else None
    if ar1 is not None:
        header.append("ar1: each friction group's lag-one autocorrelation fitted from the series' time order where "
                      "they allow it (calibration.json's ar1); the other values are fitted as if cycles were "
                      "independent.")
    study_text = study_path.read_text(encoding="utf-8")
    poses = _written_poses(inputs, names)
    workspace_map = None
    try:
        text = calibrated_study_text(study_text, study_path.parent, out, header, values, list(poses),
                                     _written_ar1(ar1))
        calibrated = parse_study_text(text, out / "calibrated.toml", out)
        _check_runnable(calibrated, robot)
        if calibrated.map is not None:
            only_map = replace(calibrated, poses=(), iso_cube=None, calibration=None)
            workspace_map = run_study(only_map, executor=executor, progress=progress, meshes=False).map
    except InputError as error:
        if error.source != str(out / "calibrated.toml"):
            raise
        raise InputError(f"the fitted values make a study that `tribokin run` refuses ({error.key}: {error.message}); "
                         "nothing is written: fix the values the measurements cannot determine, or check the data",
                         measurements_path, "calibration") from None
    return CalibrationResult(str(study_path), str(measurements_path),
                             hashlib.sha256(Path(measurements_path).read_bytes()).hexdigest(), study, robot, inputs,
                             calibration, intervals, fitted, held_out, seed, calibrated, workspace_map,
                             software_versions(), tuple(header), tuple(values), poses, study_text, interval_kind,
                             ar1)
