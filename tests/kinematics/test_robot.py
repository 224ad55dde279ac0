"""Robots: example-robot-data arms and URDFs, reduced to the tool's chain; errors list valid names."""

import numpy as np
import pytest

from conftest import ROOT
from tribokin.errors import RobotDescriptionError
from tribokin.kinematics.robot import TESTED_ROBOTS, load_example_robot, load_urdf


@pytest.mark.parametrize("name", TESTED_ROBOTS)
def test_example_robots_load_with_one_dof_chains(name):
    robot = load_example_robot(name)
    assert robot.model.nq == robot.model.nv == len(robot.joint_names) >= 5
    q = np.clip(robot.reference_q, robot.lower_limits, robot.upper_limits)
    assert np.all(np.isfinite(robot.tool_placement(q).translation))
    assert robot.tool_frame == [f.name for f in robot.model.frames][-1] or robot.tool_frame


def test_panda_fingers_are_locked():
    panda = load_example_robot("panda")
    assert panda.joint_names == [f"panda_joint{i}" for i in range(1, 8)]


def test_unknown_robot_and_frame_list_the_valid_ones():
    with pytest.raises(RobotDescriptionError, match="did you mean 'ur5'.*valid names: .*panda.*ur10") as error:
        load_example_robot("ur55")
    assert error.value.argument == "name" and "\n" not in str(error.value)
    with pytest.raises(RobotDescriptionError, match="tool0") as error:
        load_example_robot("ur5", tool_frame="tool9")
    assert error.value.argument == "tool_frame"


def test_missing_and_malformed_urdf(tmp_path):
    with pytest.raises(RobotDescriptionError, match="not found") as error:
        load_urdf(tmp_path / "none.urdf")
    assert error.value.argument == "path"
    bad = tmp_path / "bad.urdf"
    bad.write_text("<robot name='x'><link name='a'></robot>")
    with pytest.raises(RobotDescriptionError, match="cannot read URDF"):
        load_urdf(bad)


def test_gantry_kinematics():
    gantry = load_urdf(ROOT / "urdf" / "cartesian_xyz.urdf")
    assert gantry.joint_names == ["x", "y", "z"] and gantry.tool_frame == "tool"
    assert gantry.joint_is_prismatic.all()
    assert gantry.tool_placement([0.1, 0.2, 0.3]).translation == pytest.approx([0.3, 0.2, 0.5])
    assert gantry.lower_limits.tolist() == [0, 0, 0] and min(gantry.upper_limits) >= 0.5
