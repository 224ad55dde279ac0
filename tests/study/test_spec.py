"""Typed, frozen study specs: parsing builds them, overrides make new ones."""

import dataclasses
import hashlib

import pytest

from conftest import GANTRY_MAP_TOML, axis_study
from tribokin import IsoCubeSpec, JointSpec, PoseSpec, RobotSpec, ScenarioSpec, Study  # exported for users
from tribokin.study.reading import load_study, read_study_file

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
