"""Typed, frozen study specs: parsing builds them, overrides make new ones."""

import dataclasses
import hashlib
from pathlib import Path

import pytest

from conftest import GANTRY_MAP_TOML, axis_study
from tribokin import InputError, IsoCubeSpec, JointSpec, PoseSpec, RobotSpec, ScenarioSpec, Study  # exported for users
from tribokin.study.reading import load_study, parse_study_text, read_study_file

SCENARIOS = [{"name": "stiff", "joints": {"stiffness": 2.0e6}}, {"name": "own-seed", "study": {"seed": 9}}]


def map_study(**study) -> dict:
    mapping = axis_study(x={"backlash": 1e-6})
    return {**mapping, "study": {**mapping["study"], **study}, "poses": [{"name": "A", "q": [0.2]}],
            "iso_cube": {"side_m": 0.1},
            "map": {"kind": "joint", "joints": ["x"], "ranges": [[0.1, 0.3]], "counts": [3]}, "scenarios": SCENARIOS}


def test_a_study_and_every_part_of_it_are_typed_and_frozen():
    study = load_study(map_study())
    assert isinstance(study.robot, RobotSpec) and isinstance(study.joints, JointSpec)
    assert isinstance(study.poses[0], PoseSpec) and isinstance(study.iso_cube, IsoCubeSpec)
    assert isinstance(study.scenarios[0], ScenarioSpec) and isinstance(study.scenarios[0].study, Study)
    assert study.poses[0].q == (0.2,) and study.map.ranges == ((0.1, 0.3),)  # lists of the file as tuples
    for spec, name in [(study, "cycles"), (study, "scenarios"), (study, "sha256"), (study.robot, "payload_kg"),
                       (study.joints, "stiffness"), (study.poses[0], "q"), (study.iso_cube, "side_m"),
                       (study.map, "counts"), (study.scenarios[0], "study")]:
        with pytest.raises(dataclasses.FrozenInstanceError):
            setattr(spec, name, None)


def test_command_line_overrides_make_a_new_study_and_leave_the_given_one_as_it_was():
    study = load_study(map_study(cycles=30, seed=1))
    overridden = load_study(study, cycles=40, seed=5)
    assert (overridden.cycles, overridden.seed) == (40, 5)
    assert [(s.study.cycles, s.study.seed) for s in overridden.scenarios] == [(40, 5), (40, 9)]  # own seed kept
    assert (study.cycles, study.seed) == (30, 1)
    assert [(s.study.cycles, s.study.seed) for s in study.scenarios] == [(30, 1), (30, 9)]
    assert overridden.robot is study.robot and overridden.map is study.map  # the parts not overridden are shared


def test_the_file_hash_is_set_when_the_file_is_read(tmp_path):
    path = tmp_path / "gantry.toml"
    path.write_text(GANTRY_MAP_TOML)
    assert read_study_file(path).sha256 == hashlib.sha256(path.read_bytes()).hexdigest()
    assert load_study(axis_study()).sha256 is None


def test_a_joint_has_the_defaults_with_its_own_keys_and_a_refusal_names_the_key_that_set_them():
    study = load_study(axis_study(x={"backlash": 1e-6}, noise_std=2e-7))
    assert study.joint("x") == dataclasses.replace(study.joints, backlash=1e-6)
    assert study.joint("y") == study.joints and study.joints.noise_std == 2e-7
    assert study.joint_key("x", "backlash") == "joints.x.backlash"
    assert study.joint_key("x", "noise_std") == "joints.noise_std"
    assert study.robot.as_settings() == {"urdf": study.robot.urdf, "name": None, "tool_frame": "tool",
                                         "package_dirs": [], "payload_kg": 0.0}


def test_a_joints_own_friction_force_replaces_the_defaults_law_of_mu_and_names_its_key():
    force = {"law": "constant", "value": 30.0}
    study = load_study(axis_study(x={"friction_force_N": force}))
    assert study.joints.friction_key == "friction" and study.joints.friction_force_N is None
    joint = study.joint("x")
    assert joint.friction is None and joint.friction_force_N == force and joint.friction_key == "friction_force_N"
    assert study.joint_key("x", joint.friction_key) == "joints.x.friction_force_N"


def with_robot(study: dict, **robot) -> dict:
    return {**study, "robot": {**study["robot"], **robot}}


def test_a_tool_offset_is_kept_as_tuples_and_recorded_only_when_set():
    robot = load_study(with_robot(axis_study(), tool_offset_m=[0.01, -0.02, 0.1], tool_offset_rpy_deg=[0, 90, 0])).robot
    assert (robot.tool_offset_m, robot.tool_offset_rpy_deg) == ((0.01, -0.02, 0.1), (0.0, 90.0, 0.0))
    settings = robot.as_settings()
    assert settings["tool_offset_m"] == [0.01, -0.02, 0.1] and settings["tool_offset_rpy_deg"] == [0.0, 90.0, 0.0]
    assert RobotSpec(**settings).tool_offset_m == [0.01, -0.02, 0.1]  # as a view reads summary.json
    assert "tool_offset_m" not in load_study(axis_study()).robot.as_settings()  # summary.json as before


@pytest.mark.parametrize("robot, key, message", [
    ({"tool_offset_m": [0.0, 0.1]}, "robot.tool_offset_m", "needs 3 numbers (got 2)"),
    ({"tool_offset_m": [0.0, "0.1", 0.0]}, "robot.tool_offset_m[1]", "must be a number"),
    ({"tool_offset_m": [0.0, 0.0, 10.5]}, "robot.tool_offset_m[2]", "between -10 and 10 m"),
    ({"tool_offset_rpy_deg": [0.0, 400.0, 0.0]}, "robot.tool_offset_rpy_deg[1]", "within one turn"),
])
def test_a_bad_tool_offset_is_a_one_line_error_naming_its_key(robot, key, message):
    with pytest.raises(InputError) as error:
        load_study(with_robot(axis_study(), **robot))
    assert error.value.key == key and message in error.value.message and "\n" not in str(error.value)


def test_a_joint_maps_scenario_may_not_move_the_tool_point():
    study = map_study()
    study["scenarios"] = [*SCENARIOS, {"name": "probe", "robot": {"tool_offset_m": [0.0, 0.0, 0.1]}}]
    with pytest.raises(InputError, match="joint map's targets .* robot.payload_kg only") as error:
        load_study(study)
    assert error.value.key == "scenarios[2].robot.tool_offset_m"


def plane_study(*scenarios: dict) -> dict:
    """The gantry's plane map (a URDF with a tool frame and a payload) with these scenarios."""
    return {**parse_study_text(GANTRY_MAP_TOML, "gantry.toml", Path(".")).mapping, "scenarios": list(scenarios)}


def test_the_reference_scenario_keeps_the_studys_robot():
    study = plane_study({"name": "moved", "robot": {"base_xyz_m": [0.1, 0.0, 0.0]}}, {"name": "b"})
    with pytest.raises(InputError, match="first scenario is the reference") as error:
        load_study(study)
    assert error.value.key == "scenarios[0].robot.base_xyz_m"
    load_study(plane_study({"name": "heavy", "robot": {"payload_kg": 9.0}}, {"name": "b"}))  # its payload may change


def test_a_scenario_naming_another_robot_takes_none_of_the_studys_robot_identity_and_keeps_the_rest():
    study = plane_study({"name": "gantry"}, {"name": "moved", "robot": {"base_xyz_m": [0.1, 0.0, 0.0]}},
                        {"name": "ur10", "robot": {"name": "ur10", "tool_offset_m": [0.0, 0.0, 0.1]}})
    study["robot"]["base_rpy_deg"] = [0.0, 0.0, 90.0]
    gantry, moved, ur10 = (s.study.robot for s in load_study(study).scenarios)
    assert moved == dataclasses.replace(gantry, base_xyz_m=(0.1, 0.0, 0.0))
    assert (ur10.name, ur10.urdf, ur10.tool_frame, ur10.package_dirs) == ("ur10", None, None, ())
    assert (ur10.payload_kg, ur10.base_rpy_deg, ur10.tool_offset_m) == (5.0, (0.0, 0.0, 90.0), (0.0, 0.0, 0.1))


def test_a_scenarios_xacro_arguments_merge_into_the_studys_key_by_key():
    study = plane_study({"name": "a"}, {"name": "longer", "robot": {"xacro_args": {"forearm_m": "0.5"}}})
    study["robot"] = {"urdf": "arm.urdf.xacro", "xacro_args": {"upper_arm_m": "0.4", "forearm_m": "0.3"}}
    longer = load_study(study).scenarios[1].study.robot
    assert longer.xacro_args == {"upper_arm_m": "0.4", "forearm_m": "0.5"}


@pytest.mark.parametrize("robot, key, message", [
    ({"tool_framme": "tool"}, "scenarios[1].robot.tool_framme", "did you mean 'tool_frame'"),
    ({"base_xyz_m": [0.0, 0.0]}, "scenarios[1].robot.base_xyz_m", "needs 3 numbers"),
    ({"name": "ur10", "urdf": "arm.urdf"}, "scenarios[1].robot", "exactly one of"),
    ({"xacro_args": {"a": "1"}}, "scenarios[1].robot.xacro_args", "only a xacro file"),
    ({"xacro_args": {"a": 1}}, "scenarios[1].robot.xacro_args.a", "must be a string"),
])
def test_a_scenarios_robot_keys_are_checked_as_robot_is(robot, key, message):
    with pytest.raises(InputError) as error:
        load_study(plane_study({"name": "a"}, {"name": "b", "robot": robot}))
    assert error.value.key == key and message in error.value.message, error.value


