"""The library under `run_study`: a robot made in code from a `pin.Model`, its joint models, a pose's test and a map
give, to the bit, what a study loading the same URDF by file gives; the library's errors name no file, the study's
do."""

from __future__ import annotations

import pickle

import numpy as np
import pinocchio as pin
import pytest

import tribokin
from conftest import ROOT
from tribokin.maps.grid import GridError
from tribokin.maps.schema import MapLayout
from tribokin.study.map_spec import BoxMap, PlaneMap

URDF = ROOT / "urdf" / "cartesian_xyz.urdf"
Q = [0.3, 0.2, 0.1]


def study(**extra) -> dict:
    """A gantry study of one pose and a small box map (27 targets)."""
    return {"study": {"name": "round-trip", "cycles": 20, "seed": 7, **extra},
            "robot": {"urdf": str(URDF), "tool_frame": "tool", "payload_kg": 5.0},
            "joints": {"friction": {"preset": "42CD4-raw"}, "stiffness": 2.0e7, "bearing_span_m": 0.2,
                       "z": {"friction": {"preset": "42CD4-treated"}}},
            "poses": [{"name": "P", "q": Q}],
            "map": {"kind": "box", "min_m": [0.2, 0.0, 0.2], "max_m": [0.8, 0.6, 0.7], "resolution": [3, 3, 3]}}


def library_robot() -> tribokin.Robot:
    return tribokin.Robot.from_pinocchio(pin.buildModelFromUrdf(str(URDF)), tool_frame="tool")


def library_joints(robot):
    return tribokin.joint_models(robot, friction=tribokin.preset("42CD4-raw"), stiffness=2.0e7, bearing_span_m=0.2,
                                 joints={"z": {"friction": tribokin.preset("42CD4-treated")}})


@pytest.fixture(scope="module")
def by_file():
    return tribokin.run_study(study(), meshes=False)


def test_a_robot_from_a_pin_model_is_the_urdf_s_reduced_the_same_way():
    robot, loaded = library_robot(), tribokin.Robot.from_urdf(URDF, "tool", meshes=False)
    assert robot.joint_names == loaded.joint_names and robot.tool_frame == loaded.tool_frame
    assert np.array_equal(robot.reference_q, loaded.reference_q)
    assert robot.origin["source"] == "pinocchio model" and robot.origin["nq"] == 3
    assert robot.origin["kinematics_sha256"] == loaded.origin["kinematics_sha256"]
    q = np.array(Q)
    assert np.array_equal(robot.tool_placement(q).homogeneous, loaded.tool_placement(q).homogeneous)


def test_a_robot_pickles_as_its_kinematics():
    robot = library_robot()
    copy = pickle.loads(pickle.dumps(robot))
    assert copy.origin == robot.origin and np.array_equal(copy.reference_q, robot.reference_q)
    assert np.array_equal(copy.tool_jacobian(Q), robot.tool_jacobian(Q))


def test_a_pose_from_python_equals_the_study_s_to_the_bit(by_file):
    robot = library_robot()
    pose = tribokin.pose_test(robot, library_joints(robot), Q, name="P", cycles=20, seed=7, payload_kg=5.0)
    expected = by_file.poses[0]
    for name in ("positions_m", "angles_rad", "dq", "mu", "approach", "normal_forces_N", "commanded_position_m"):
        assert np.array_equal(getattr(pose, name), getattr(expected, name)), name
    assert pose.report_row() == expected.report_row()
    assert pose.direction_extra == expected.direction_extra


def test_a_map_from_python_equals_the_study_s_to_the_bit(by_file):
    robot = library_robot()
    spec = BoxMap(min_m=(0.2, 0.0, 0.2), max_m=(0.8, 0.6, 0.7), resolution=(3, 3, 3))
    result = tribokin.workspace_map(robot, library_joints(robot), spec, name="round-trip", cycles=20, seed=7,
                                    payload_kg=5.0)
    columns = MapLayout.shared(3, 1, "expected").columns()
    assert len(columns) > 5
    for name in columns:
        assert np.array_equal(result.read(name), by_file.map.read(name), equal_nan=True), name
    assert result.summary() == by_file.map.summary()


def test_the_library_s_range_error_names_no_file_the_study_s_does():
    robot = library_robot()
    soft = tribokin.joint_models(robot, friction=tribokin.Constant(0.5), stiffness=1.0)
    with pytest.raises(tribokin.JointRangeError) as library:
        tribokin.pose_test(robot, soft, Q, payload_kg=5.0)
    assert not isinstance(library.value, tribokin.InputError) and library.value.joint == "x"
    mapping = study()
    mapping["joints"] = {"friction": {"law": "constant", "mu": 0.5}, "stiffness": 1.0}
    del mapping["map"]  # its rows' starts are checked first
    with pytest.raises(tribokin.InputError) as located:
        tribokin.run_study(mapping, meshes=False)
    assert located.value.source == "<mapping>" and located.value.key == "joints.stiffness"
    assert located.value.message == library.value.message


@pytest.mark.parametrize(("values", "joint", "part"), [
    ({"stiffness": 2e7}, "x", "friction"),
    ({"friction": "0.1", "stiffness": 2e7}, "x", "friction"),
    ({"stiffness": -1.0}, "x", "stiffness"),
    ({"stiffness": 2e7, "backlash": float("nan")}, "x", "backlash"),
    ({"stiffness": 2e7, "joints": {"w": {}}}, "w", None),
    ({"stiffness": 2e7, "stifness": 1.0}, None, "stifness"),
])
def test_joint_models_refuse_bad_values_naming_the_joint_and_the_value(values, joint, part):
    if part != "friction":
        values["friction"] = tribokin.Constant(0.1)
    with pytest.raises(tribokin.JointModelError) as refused:
        tribokin.joint_models(library_robot(), **values)
    assert (refused.value.joint, refused.value.part) == (joint, part)


@pytest.mark.parametrize(("settings", "argument"), [({"cycles": 1}, "cycles"), ({"approach": "sideways"}, "approach"),
                                                    ({"engine": "quick"}, "engine"), ({"seed": -1}, "seed"),
                                                    ({"payload_kg": -1.0}, "payload_kg")])
def test_a_bad_setting_is_a_settings_error_naming_it(settings, argument):
    robot = library_robot()
    with pytest.raises(tribokin.SettingsError) as refused:
        tribokin.pose_test(robot, library_joints(robot), Q, **settings)
    assert refused.value.argument == argument


def test_a_bad_reference_posture_is_refused():
    with pytest.raises(tribokin.RobotDescriptionError) as refused:
        tribokin.Robot.from_pinocchio(pin.buildModelFromUrdf(str(URDF)), reference_q=[0.0, 0.0])
    assert refused.value.argument == "reference_q"


def test_errors_pickle_with_their_attributes():
    error = pickle.loads(pickle.dumps(tribokin.JointRangeError("too far", "x", "stiffness")))
    assert (type(error), error.message, error.joint, error.part) == (tribokin.JointRangeError, "too far", "x",
                                                                     "stiffness")


def test_a_ur5_pose_from_example_robot_data_s_pin_model_equals_the_study_s_to_the_bit():
    from example_robot_data import load

    wrapper = load("ur5")
    robot = tribokin.Robot.from_pinocchio(wrapper.model, "tool0", wrapper.visual_model, wrapper.collision_model,
                                          reference_q=wrapper.q0)
    q = [0.1, -1.2, 1.4, -1.7, -1.5, 0.3]
    joints = tribokin.joint_models(robot, friction=tribokin.Gaussian(0.12, 0.02), stiffness=1.0e5,
                                   friction_radius_m=0.03, backlash=1e-5)
    pose = tribokin.pose_test(robot, joints, q, name="A", cycles=12, seed=3, approach="bidirectional", payload_kg=3.0)
    mapping = {"study": {"name": "ur5", "cycles": 12, "seed": 3, "approach": "bidirectional"},
               "robot": {"name": "ur5", "tool_frame": "tool0", "payload_kg": 3.0},
               "joints": {"friction": {"law": "gaussian", "mean": 0.12, "std": 0.02}, "stiffness": 1.0e5,
                          "friction_radius_m": 0.03, "backlash": 1e-5},
               "poses": [{"name": "A", "q": q}]}
    expected = tribokin.run_study(mapping).poses[0]
    loaded = tribokin.Robot.from_example_robot_data("ur5", "tool0")
    assert np.array_equal(robot.reference_q, loaded.reference_q) and robot.visual_model is not None
    assert robot.origin["kinematics_sha256"] == loaded.origin["kinematics_sha256"]
    for name in ("positions_m", "angles_rad", "dq", "mu", "approach", "normal_forces_N"):
        assert np.array_equal(getattr(pose, name), getattr(expected, name)), name
    assert pose.report_row() == expected.report_row()


def test_scenarios_from_python_equal_the_study_s_to_the_bit():
    mapping = study()
    mapping["scenarios"] = [{"name": "raw"}, {"name": "stiff", "joints": {"stiffness": 1.0e8}, "study": {"seed": 8}}]
    expected = tribokin.run_study(mapping, meshes=False).map
    robot = library_robot()
    stiff = tribokin.joint_models(robot, friction=tribokin.preset("42CD4-raw"), stiffness=1.0e8, bearing_span_m=0.2,
                                  joints={"z": {"friction": tribokin.preset("42CD4-treated")}})
    spec = BoxMap(min_m=(0.2, 0.0, 0.2), max_m=(0.8, 0.6, 0.7), resolution=(3, 3, 3))
    scenarios = [tribokin.MapScenario("raw"), tribokin.MapScenario(
        "stiff", joints=stiff, settings=tribokin.TestSettings(cycles=20, seed=8, payload_kg=5.0))]
    result = tribokin.workspace_map(robot, library_joints(robot), spec, scenarios=scenarios, cycles=20, seed=7,
                                    payload_kg=5.0)
    for name in MapLayout.shared(3, 2, "expected").columns():
        assert np.array_equal(result.read(name), expected.read(name), equal_nan=True), name
    ratio = result.ratio_RP_l(result.scenarios["stiff"])
    assert np.nanmax(np.abs(ratio - 0.2)) < 0.05  # five times stiffer, a fifth of the lost motion (other seed)


def test_a_map_that_does_not_fit_the_robot_is_a_grid_error_in_code_and_located_in_a_study():
    robot = library_robot()
    plane = PlaneMap(origin_m=(0.5, 0.3, 0.4), axis_u=(1.0, 0.0, 0.0), axis_v=(0.0, 1.0, 0.0), extent_u_m=(-0.1, 0.1),
                     extent_v_m=(-0.1, 0.1), resolution=(3, 3), rpy_deg=(0.0, 90.0, 0.0))
    with pytest.raises(GridError) as library:
        tribokin.workspace_map(robot, library_joints(robot), plane)
    assert isinstance(library.value, tribokin.TribokinError) and library.value.key == "rpy_deg"
    mapping = study()
    mapping["map"] = {"kind": "plane", "origin_m": [0.5, 0.3, 0.4], "axis_u": [1.0, 0.0, 0.0],
                      "axis_v": [0.0, 1.0, 0.0], "extent_u_m": [-0.1, 0.1], "extent_v_m": [-0.1, 0.1],
                      "resolution": [3, 3], "rpy_deg": [0.0, 90.0, 0.0]}
    with pytest.raises(tribokin.InputError) as located:
        tribokin.run_study(mapping, meshes=False)
    assert (located.value.source, located.value.key) == ("<mapping>", "map.rpy_deg")
    assert library.value.message.startswith("cartesian_xyz cannot hold")  # the robot's label: its model's name
    assert located.value.message == library.value.message.replace("cartesian_xyz", str(URDF), 1)
