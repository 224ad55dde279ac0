"""A calibration's inputs with the robot's base placed and turned in the world: the tracker registered to the world,
configurations, Jacobians and approach signs the world's."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from helpers.measurement_files import write_csv
from tribokin.iso9283.cube import held_approach_signs
from tribokin.study.assembly import joint_models, load_robot
from tribokin.study.calibration_data import calibration_input, read_robot_measurements
from tribokin.study.reading import load_study

#: The UR5's base in the world: at BASE_M, rolled 20° and turned 120° (roll, then pitch, then yaw).
BASE_M, BASE_RPY_DEG = np.array([0.4, -0.3, 0.2]), [20.0, 0.0, 120.0]
TURN = Rotation.from_euler("xyz", BASE_RPY_DEG, degrees=True).as_matrix()
#: Three poses' commanded tool points in the base's own frame [m]; the file gives them in the world.
IN_BASE_M = np.array([[0.4, -0.2, 0.35], [0.3, -0.35, 0.3], [0.45, -0.1, 0.45]])
COMMANDED_M = IN_BASE_M @ TURN.T + BASE_M
#: The tracker's frame: a world point p is measured at TRACKER p + SHIFT_M.
TRACKER, SHIFT_M = Rotation.from_euler("xyz", [10.0, -20.0, 35.0], degrees=True), np.array([1.0, -2.0, 0.5])
#: Each series' cycles about the commanded point, in the world [µm] (they sum to zero: the barycentre is commanded).
CYCLES_UM = np.array([[3.0, 0.0, 1.0], [-3.0, 0.0, -1.0], [0.0, 4.0, 0.0], [0.0, -4.0, 0.0]])
DIRECTIONS = {"+x": np.array([1.0, 0.0, 0.0]), "-y": np.array([0.0, -1.0, 0.0])}

STUDY = {
    "study": {"name": "placed", "cycles": 5, "seed": 1},
    "robot": {"name": "ur5", "base_xyz_m": BASE_M.tolist(), "base_rpy_deg": BASE_RPY_DEG},
    "joints": {"stiffness": 1.0e5, "friction_torque_Nm": {"law": "gaussian", "mean": 1.0, "std": 0.25}},
    "calibration": {"fit": ["stiffness"], "noise_floor_m": 1.0e-6},
    "poses": [{"name": "P1", "q": [0.3, -1.2, 1.1, -0.4, 1.2, 0.1]}],
}


def test_a_placed_and_turned_robot_is_calibrated_in_the_world(tmp_path):
    rows = []
    for k, commanded in enumerate(COMMANDED_M):
        for direction in DIRECTIONS:
            for cycle, offset in enumerate(CYCLES_UM * 1e-6, start=1):
                measured = TRACKER.apply(commanded + offset) + SHIFT_M
                rows.append(",".join([f"P{k + 1}", direction, str(cycle),
                                      *(repr(float(v)) for v in (*measured, *commanded))]))
    path = write_csv(tmp_path, "pose,direction,cycle,x_m,y_m,z_m,cx_m,cy_m,cz_m", rows)
    study = load_study(STUDY)
    robot = load_robot(study, meshes=False)
    inputs = calibration_input(study, robot, joint_models(study, robot), read_robot_measurements(path, robot))

    # the tracker registered to the world: p = TRACKER⁻¹ (m − SHIFT)
    assert inputs.registration.rotation == pytest.approx(TRACKER.inv().as_matrix(), abs=1e-9)
    assert inputs.registration.translation_m == pytest.approx(-TRACKER.inv().apply(SHIFT_M), abs=1e-9)
    assert inputs.registration.rms_residual_m < 1e-9
    unplaced = load_robot(load_study({**STUDY, "robot": {"name": "ur5"}}), meshes=False)
    assert len(inputs.poses) == len(IN_BASE_M)
    for pose, q, commanded, in_base in zip(inputs.poses, inputs.configurations, COMMANDED_M, IN_BASE_M, strict=True):
        # IK of the world's commanded point: the unplaced UR5 reaches it in its own frame
        assert np.linalg.norm(robot.tool_placement(q).translation - commanded) < 1e-6
        assert np.linalg.norm(unplaced.tool_placement(q).translation - in_base) < 1e-6
        np.testing.assert_allclose(pose.jacobian, TURN @ unplaced.tool_jacobian(q)[:3], rtol=0, atol=1e-12)
        assert [s.direction for s in pose.series] == list(DIRECTIONS)
        for series, direction in zip(pose.series, DIRECTIONS.values(), strict=True):
            np.testing.assert_allclose(series.points_m, commanded + CYCLES_UM * 1e-6, rtol=0, atol=1e-12)
            turned_back = held_approach_signs(unplaced, q, TURN.T @ direction)[0]
            np.testing.assert_array_equal(series.signs, turned_back)
        assert not all(np.array_equal(s.signs, held_approach_signs(unplaced, q, d)[0])  # not the base's own axes
                       for s, d in zip(pose.series, DIRECTIONS.values(), strict=True))
