"""What a calibration fits: a study's joint model, and its robot's kinematics at the poses of a measurement file.

For each measured pose:

- its configuration: the mean of its rows' ``q_<joint>`` (the file must name every joint of the tool's chain; a
  continuous joint's mean is circular, :func:`read_robot_measurements`), else solved by IK from its mean commanded
  position (``cx, cy, cz``, world frame), the tool held at ``calibration.tool_rpy_deg`` when given, else for position
  only from the robot's reference posture;
- the position Jacobian of the tool point there, and the mean and standard deviation of every joint's friction
  torque (force) under the bearing loads at that configuration
  (:func:`~tribokin.simulation.joint_errors.friction_torque_moments`);
- its series: measured points in the world frame when the measuring frame is registered (as ``registration=`` chooses,
  :func:`~tribokin.measurement.registration.choose_frame`: re-taught commanded positions corrected as ``measure``
  does), else as measured; each with its joints' approach signs, from its direction label:

  :func:`~tribokin.iso9283.cube.label_approach_signs` (``+x``, ``-y``, ... or ``+0.58+0.58+0.58``: the tool point
  approached along that direction of the world frame with the tool's orientation held, a joint that does not move
  having sign 0; ``+`` or ``-``: every joint forwards or backwards); any other label (``start``) is an unknown
  approach, and its series is left out of the fit and listed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from tribokin.calibration.data import PoseData, SeriesData
from tribokin.calibration.model import JointModel, ParameterRanges
from tribokin.errors import InputError, located
from tribokin.iso9283.cube import label_approach_signs
from tribokin.kinematics.ik import solve_ik_with_restarts
from tribokin.kinematics.robot import Robot
from tribokin.measurement.contract import Measurements, Pose, read_measurements
from tribokin.measurement.figures import pose_clouds
from tribokin.measurement.registration import Choice, Frame, Registration, Transform, choose_frame
from tribokin.simulation.joint_errors import JointErrorModel, friction_torque_moments
from tribokin.streams import posture_search
from tribokin.study.assembly import study_runner
from tribokin.study.spec import Study, backlash, instrument_noise, stiffness

#: The ranges of a study's keys (joints.stiffness, joints.backlash, calibration.noise_floor_m): a fitted value
#: ``calibrated.toml`` writes stays within them.
STUDY_RANGES = ParameterRanges(stiffness=stiffness.bounds[:2], backlash=backlash.bounds[:2],
                               noise_floor_m=instrument_noise.bounds[:2])
#: Largest distance [m] between a pose's commanded position and the tool point at the configuration IK found.
IK_TOLERANCE_M = 1e-6


@dataclass(frozen=True)
class LeftOut:
    """A measured series the fit does not use, and why."""

    pose: str
    direction: str
    cycles: int
    why: str


@dataclass(frozen=True, eq=False)
class CalibrationInput:
    """A calibration's data and model.

    Attributes:
        model: the study's joint model with the parameters ``[calibration]`` frees.
        poses: per measured pose with a series of known approach (in file order) its kinematics, friction and
            series.
        configurations: (n_poses, nv) the configuration of each of ``poses`` [rad or m].
        configuration_source: how they were found (the file's ``q_`` columns, or IK of commanded positions).
        frame: the measuring frame as ``registration=`` left it: registered to the world, or kept (the points are
            then in the measuring frame).
        left_out: series without a known approach, not used.
    """

    model: JointModel
    poses: tuple[PoseData, ...]
    configurations: np.ndarray
    configuration_source: str
    frame: Frame
    left_out: tuple[LeftOut, ...]

    @property
    def registration(self) -> Registration | None:
        """The measuring frame's registration to the world, or ``None``."""
        return self.frame.registration


def read_robot_measurements(path, robot: Robot) -> Measurements:
    """The measurement file at ``path`` (:func:`~tribokin.measurement.contract.read_measurements`), its ``q_`` columns
    read as ``robot``'s joints: lengths [m] for prismatic ones, circular means of angles [rad] for continuous ones (rows
    on either side of ±π are one configuration)."""
    prismatic = [n for n, p in zip(robot.joint_names, robot.joint_is_prismatic, strict=True) if p]
    return read_measurements(path, prismatic=prismatic,
                             continuous=[n for n, c in zip(robot.joint_names, robot.continuous, strict=True) if c])


def calibration_model(study: Study, robot: Robot, models: list[JointErrorModel]) -> JointModel:
    """The study's stiffness, backlash and joint noise per joint, the ``[calibration]`` noise floor, which of
    them are free (``calibration.fit`` for ``calibration.joints``, ``calibration.tie``), and the study's ranges
    (:data:`STUDY_RANGES`), within which the fit holds them."""
    spec = study.calibration
    names = robot.joint_names
    chosen = names if spec.joints == "all" else spec.joints
    for name in chosen:
        if name not in names:
            raise InputError(f"unknown joint '{name}'; joints of {robot.label}: {', '.join(names)}", study.source,
                             "calibration.joints")
    free = tuple(name in chosen for name in names)
    noise = np.array([m.noise_std for m in models])
    return JointModel(
        joint_names=tuple(names), stiffness=np.array([m.stiffness for m in models]),
        backlash=np.array([m.backlash for m in models]),
        noise_floor_m=spec.noise_floor_m if spec.noise_floor_m is not None else 1e-6,
        fit_stiffness=free if "stiffness" in spec.fit else (False,) * len(names),
        fit_backlash=free if "backlash" in spec.fit else (False,) * len(names),
        fit_noise_floor="noise_floor" in spec.fit, tie=spec.tie, prismatic=tuple(robot.joint_is_prismatic),
        joint_noise=noise if noise.any() else None, ranges=STUDY_RANGES)


def _configuration_from_rows(robot: Robot, measurements: Measurements, pose: Pose) -> np.ndarray:
    order = [measurements.joints.index(name) for name in robot.joint_names]
    with located(measurements.source, f"q_ (pose '{pose.name}')"):
        return robot.check_configuration(pose.q[order])


def _configuration_by_ik(study: Study, robot: Robot, measurements: Measurements, pose: Pose) -> np.ndarray:
    commanded = pose.pooled("commanded_m").mean(axis=0)
    rpy = study.calibration.tool_rpy_deg
    rotation = np.eye(3) if rpy is None else pin.rpy.rpyToMatrix(*np.radians(rpy))
    result = solve_ik_with_restarts(robot, pin.SE3(rotation, commanded), robot.reference_q, posture_search(),
                                    position_only=rpy is None)
    if not result.success or result.position_error_m > IK_TOLERANCE_M:
        raise InputError(f"pose '{pose.name}': its commanded position {np.round(commanded, 6).tolist()} m is out of "
                         f"reach of {robot.label}'s tool point (closest {result.position_error_m * 1e3:.3g} mm); "
                         "check the robot, its tool offset and calibration.tool_rpy_deg, or give q_<joint> columns",
                         measurements.source, "cx_m")
    return result.q


def configurations(study: Study, robot: Robot, measurements: Measurements) -> tuple[np.ndarray, str]:
    """(n_poses, nv) the measured poses' configurations and how they were found (module docstring)."""
    names = robot.joint_names
    if measurements.joints:
        for name in measurements.joints:
            if name not in names:
                raise InputError(f"not a joint of {robot.label}'s tool chain ({', '.join(names)}); rename or "
                                 "remove it", measurements.source, f"q_{name}")
        missing = [name for name in names if name not in measurements.joints]
        if missing:
            raise InputError(f"missing column: the configuration needs every joint of the chain, "
                             f"{', '.join('q_' + n for n in names)}", measurements.source, f"q_{missing[0]}")
        qs = [_configuration_from_rows(robot, measurements, pose) for pose in measurements.poses]
        return np.array(qs), "the mean of each pose's q_<joint> columns"
    if measurements.poses[0].pooled("commanded_m") is None:
        raise InputError("calibrate needs each pose's joint configuration: q_<joint> columns, or commanded positions "
                         "cx_m, cy_m, cz_m to solve it by IK", measurements.source, "q_")
    rpy = study.calibration.tool_rpy_deg
    how = "inverse kinematics of each pose's mean commanded position, " + (
        f"the tool held at roll-pitch-yaw {list(rpy)} deg" if rpy is not None else
        "for position only from the robot's reference posture (calibration.tool_rpy_deg not given: the tool's "
        "orientation is not known)")
    return np.array([_configuration_by_ik(study, robot, measurements, pose) for pose in measurements.poses]), how


def _position_column(measurements: Measurements) -> str:
    """The measured position's first column in the file (``x_m`` or ``x_mm``)."""
    return next((name for name in measurements.columns if name.startswith("x_")), "x_m")


def calibration_input(study: Study, robot: Robot, models: list[JointErrorModel], measurements: Measurements,
                      registration: Choice | Transform = "auto") -> CalibrationInput:
    """The calibration's data and model (module docstring), the measuring frame as ``registration`` (checked) chooses;
    errors name the file and key at fault."""
    model = calibration_model(study, robot, models)
    qs, how = configurations(study, robot, measurements)
    frame = choose_frame(measurements, registration)
    registration = frame.registration
    runner = study_runner(study, robot, models)
    poses, kept, left_out = [], [], []
    for pose, q in zip(measurements.poses, qs, strict=True):
        forces = runner.normal_forces_at(q)
        torque_mean, torque_std = friction_torque_moments(models, robot.joint_is_prismatic, forces)
        series = []
        for measured, points in zip(pose.series, pose_clouds(pose, registration).positions_m, strict=True):
            signs = label_approach_signs(robot, q, measured.direction)
            if signs is None:
                left_out.append(LeftOut(pose.name, measured.direction, len(measured.cycles),
                                        "its direction label names no approach (+x, -y, ..., +0.58+0.58+0.58, + or -)"))
                continue
            if len(points) > 1 and not np.ptp(measured.positions_m, axis=0).any():
                raise InputError(f"pose {pose.name} '{measured.direction}': its {len(points)} cycles are all at the "
                                 "same point, which leaves the fit nothing to measure the joints' spread by; an "
                                 "instrument reads repeated positions with some spread: check the file (copied "
                                 "rows?)", measurements.source, _position_column(measurements))
            series.append(SeriesData(measured.direction, signs, np.asarray(points), measured.times_s))
        if series:
            poses.append(PoseData(pose.name, robot.tool_jacobian(q)[:3], torque_mean, torque_std, tuple(series)))
            kept.append(q)
    if len(poses) < 2:
        raise InputError(f"measures {len(poses)} pose{'' if len(poses) == 1 else 's'} with a known approach "
                         "direction; a calibration needs two or more (each pose's figures are predicted from a fit "
                         "to the others): measure more poses", measurements.source, "pose")
    if not any(len(s.points_m) > 1 for p in poses for s in p.series):
        raise InputError("no series of two or more cycles has a known approach direction; label directions +x, -y, "
                         "..., +0.58+0.58+0.58, + or -", measurements.source, "direction")
    return CalibrationInput(model, tuple(poses), np.array(kept), how, frame, tuple(left_out))
