"""A calibration's inputs (``calibration_input``): the measuring frame as ``registration`` chooses it (registered by
a best fit where ``auto`` finds that harmless, kept for the fit to profile its rotation out (``none``, or too few
poses), or turned by a given transform exactly); with the robot's base placed and turned in the world, the tracker
registered to the world, configurations, Jacobians and approach signs the world's."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from helpers.measurement_files import GANTRY_CALIBRATE, write_csv
from tribokin.errors import InputError
from tribokin.iso9283.cube import held_approach_signs
from tribokin.measurement.registration import NO_COMMANDED, RegistrationWarning, Transform
from tribokin.study.assembly import joint_models, load_robot
from tribokin.study.calibration_data import calibration_input, read_robot_measurements
from tribokin.study.reading import load_study, read_study_file

#: Five configurations of the gantry [m], spread in its box.
QS = np.array([[0.1, 0.2, 0.3], [0.3, 0.2, 0.1], [0.2, 0.4, 0.2], [0.1, 0.1, 0.1], [0.3, 0.4, 0.3]])
TRACKER = Rotation.from_euler("xyz", [5.0, -10.0, 60.0], degrees=True).as_matrix()
SHIFT_M = np.array([0.8, -1.5, 0.3])


@pytest.fixture(scope="module")
def gantry(tmp_path_factory):
    folder = tmp_path_factory.mktemp("gantry")
    (folder / "study.toml").write_text(GANTRY_CALIBRATE, encoding="utf-8")
    study = read_study_file(folder / "study.toml")
    robot = load_robot(study, meshes=False)
    return folder, study, robot, joint_models(study, robot)


def gantry_file(folder, robot, poses: int = 5, commanded: bool = True):
    """Each pose approached from + and - (4 cycles each, µm apart), read in a tracker frame turned and shifted from
    the base (p_tracker = Rᵀ (p - t)), with ``q_`` columns and, if ``commanded``, the tool point commanded."""
    header = "pose,cycle,direction,x_m,y_m,z_m,q_x,q_y,q_z" + (",cx_m,cy_m,cz_m" if commanded else "")
    rows = []
    for p, q in enumerate(QS[:poses]):
        tool = robot.tool_placement(q).translation
        for direction, sign in (("+", 1), ("-", -1)):
            for cycle in range(1, 5):
                point = (tool + sign * 1e-5 + 1e-6 * ((cycle + np.arange(3) + p) % 3) - SHIFT_M) @ TRACKER
                rows.append(",".join([f"P{p + 1}", str(cycle), direction, *map(repr, point.tolist()),
                                      *map(repr, q.tolist()), *(map(repr, tool.tolist()) if commanded else ())]))
    return write_csv(folder, header, rows, name=f"gantry-{poses}-{commanded}.csv")


def inputs(gantry, registration="auto", **file):
    folder, study, robot, models = gantry
    measurements = read_robot_measurements(gantry_file(folder, robot, **file), robot)
    return calibration_input(study, robot, models, measurements, registration), measurements


def test_auto_registers_five_spread_poses_into_the_base_frame(gantry):
    data, measurements = inputs(gantry)
    assert data.frame.choice == "auto" and data.registration is not None and data.frame.warning is None
    registration = data.registration
    np.testing.assert_allclose(registration.rotation, TRACKER, atol=1e-5)  # the barycentres' µm pattern moves it
    np.testing.assert_allclose(registration.translation_m, SHIFT_M, atol=1e-5)
    for pose, measured in zip(data.poses, measurements.poses, strict=True):
        for series, raw in zip(pose.series, measured.series, strict=True):
            np.testing.assert_allclose(series.points_m, raw.positions_m @ registration.rotation.T
                                       + registration.translation_m, rtol=0, atol=1e-15)


def test_none_and_too_few_poses_keep_the_tracker_frame_for_the_fit_to_profile_out(gantry):
    for data, _ in (inputs(gantry, "none"), inputs(gantry, poses=3), inputs(gantry, commanded=False)):
        assert data.registration is None
        raw = read_robot_measurements(gantry_file(gantry[0], gantry[2]), gantry[2])
        np.testing.assert_array_equal(data.poses[0].series[0].points_m, raw.poses[0].series[0].positions_m)
    assert "uses 6 of their 9 coordinates" in inputs(gantry, poses=3)[0].frame.why
    assert inputs(gantry, commanded=False)[0].frame.why == NO_COMMANDED


def test_best_fit_on_three_poses_warns_and_a_given_transform_is_applied_exactly(gantry):
    with pytest.warns(RegistrationWarning, match="6 of their 9 coordinates"):
        data, _ = inputs(gantry, "best-fit", poses=3)
    np.testing.assert_allclose(data.registration.rotation, TRACKER, atol=1e-5)
    rotation = Rotation.from_euler("z", 60.0, degrees=True).as_matrix()  # not the tracker's: applied as given
    data, measurements = inputs(gantry, Transform(rotation, np.array([0.1, 0.2, 0.3]), "frame.toml"), commanded=False)
    assert data.frame.choice == "given" and data.registration.rms_residual_m is None
    points = measurements.poses[1].series[1].positions_m
    np.testing.assert_array_equal(data.poses[1].series[1].points_m, points @ rotation.T + [0.1, 0.2, 0.3])


def test_best_fit_without_commanded_positions_is_refused_naming_the_file(gantry):
    with pytest.raises(InputError, match="registration 'best-fit' needs commanded positions") as error:
        inputs(gantry, "best-fit", commanded=False)
    assert error.value.key == "cx_m" and error.value.source.endswith("gantry-5-False.csv")


#: The UR5's base in the world: at BASE_M, rolled 20° and turned 120° (roll, then pitch, then yaw).
BASE_M, BASE_RPY_DEG = np.array([0.4, -0.3, 0.2]), [20.0, 0.0, 120.0]
TURN = Rotation.from_euler("xyz", BASE_RPY_DEG, degrees=True).as_matrix()
#: Three poses' commanded tool points in the base's own frame [m]; the file gives them in the world.
IN_BASE_M = np.array([[0.4, -0.2, 0.35], [0.3, -0.35, 0.3], [0.45, -0.1, 0.45]])
COMMANDED_M = IN_BASE_M @ TURN.T + BASE_M
#: The tracker's frame: a world point p is measured at PLACED_TRACKER p + PLACED_SHIFT_M.
PLACED_TRACKER = Rotation.from_euler("xyz", [10.0, -20.0, 35.0], degrees=True)
PLACED_SHIFT_M = np.array([1.0, -2.0, 0.5])
#: Each series' cycles about the commanded point, in the world [µm] (they sum to zero: the barycentre is commanded).
CYCLES_UM = np.array([[3.0, 0.0, 1.0], [-3.0, 0.0, -1.0], [0.0, 4.0, 0.0], [0.0, -4.0, 0.0]])
PLACED_DIRECTIONS = {"+x": np.array([1.0, 0.0, 0.0]), "-y": np.array([0.0, -1.0, 0.0])}

PLACED_STUDY = {
    "study": {"name": "placed", "cycles": 5, "seed": 1},
    "robot": {"name": "ur5", "base_xyz_m": BASE_M.tolist(), "base_rpy_deg": BASE_RPY_DEG},
    "joints": {"stiffness": 1.0e5, "friction_torque_Nm": {"law": "gaussian", "mean": 1.0, "std": 0.25}},
    "calibration": {"fit": ["stiffness"], "noise_floor_m": 1.0e-6},
    "poses": [{"name": "P1", "q": [0.3, -1.2, 1.1, -0.4, 1.2, 0.1]}],
}


def test_a_placed_and_turned_robot_is_calibrated_in_the_world(tmp_path):
    rows = []
    for k, commanded in enumerate(COMMANDED_M):
        for direction in PLACED_DIRECTIONS:
            for cycle, offset in enumerate(CYCLES_UM * 1e-6, start=1):
                measured = PLACED_TRACKER.apply(commanded + offset) + PLACED_SHIFT_M
                rows.append(",".join([f"P{k + 1}", direction, str(cycle),
                                      *(repr(float(v)) for v in (*measured, *commanded))]))
    path = write_csv(tmp_path, "pose,direction,cycle,x_m,y_m,z_m,cx_m,cy_m,cz_m", rows)
    study = load_study(PLACED_STUDY)
    robot = load_robot(study, meshes=False)
    inputs = calibration_input(study, robot, joint_models(study, robot), read_robot_measurements(path, robot),
                              registration="best-fit")  # three poses: auto would keep the frame

    # the tracker registered to the world: p = PLACED_TRACKER⁻¹ (m − PLACED_SHIFT_M)
    assert inputs.registration.rotation == pytest.approx(PLACED_TRACKER.inv().as_matrix(), abs=1e-9)
    assert inputs.registration.translation_m == pytest.approx(-PLACED_TRACKER.inv().apply(PLACED_SHIFT_M), abs=1e-9)
    assert inputs.registration.rms_residual_m < 1e-9
    unplaced = load_robot(load_study({**PLACED_STUDY, "robot": {"name": "ur5"}}), meshes=False)
    assert len(inputs.poses) == len(IN_BASE_M)
    for pose, q, commanded, in_base in zip(inputs.poses, inputs.configurations, COMMANDED_M, IN_BASE_M, strict=True):
        # IK of the world's commanded point: the unplaced UR5 reaches it in its own frame
        assert np.linalg.norm(robot.tool_placement(q).translation - commanded) < 1e-6
        assert np.linalg.norm(unplaced.tool_placement(q).translation - in_base) < 1e-6
        np.testing.assert_allclose(pose.jacobian, TURN @ unplaced.tool_jacobian(q)[:3], rtol=0, atol=1e-12)
        assert [s.direction for s in pose.series] == list(PLACED_DIRECTIONS)
        for series, direction in zip(pose.series, PLACED_DIRECTIONS.values(), strict=True):
            np.testing.assert_allclose(series.points_m, commanded + CYCLES_UM * 1e-6, rtol=0, atol=1e-12)
            turned_back = held_approach_signs(unplaced, q, TURN.T @ direction)[0]
            np.testing.assert_array_equal(series.signs, turned_back)
        assert not all(np.array_equal(s.signs, held_approach_signs(unplaced, q, d)[0])  # not the base's own axes
                       for s, d in zip(pose.series, PLACED_DIRECTIONS.values(), strict=True))
