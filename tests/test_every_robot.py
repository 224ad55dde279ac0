"""Every robot `tribokin robots` lists runs a pose study at its reference posture, or is refused on one line with the
reason: a floating-base legged robot or humanoid, a floating body without joints, a description Pinocchio cannot read,
a joint without travel."""

import re

import numpy as np
import pytest

from tribokin import InputError, run_study
from tribokin.errors import RobotDescriptionError
from tribokin.kinematics.robot import example_robot_names, load_example_robot

#: The reasons a robot may be refused for, as the refusal words them.
REFUSALS = (r"has a floating base \(joint '\w+'\) and its longest chains of joints are separate limbs",
            r"has a floating base \(joint '\w+'\) and no joint moving a frame: nothing to measure",
            r"example-robot-data cannot load '\w+': its description is an SDF file",
            r"joint '\w+' moves the tool, but its limits \[0, 0\] leave it no travel")


@pytest.fixture(scope="module")
def loaded() -> dict:
    """Each robot's Robot, or the RobotDescriptionError that refuses it (each loaded once for both tests)."""
    outcomes = {}
    for name in example_robot_names():
        try:
            outcomes[name] = load_example_robot(name)
        except RobotDescriptionError as error:
            outcomes[name] = error
    return outcomes


@pytest.mark.parametrize("name", example_robot_names())
def test_every_robot_runs_a_pose_study_or_is_refused_with_the_reason(name, loaded):
    study = {"study": {"cycles": 2}, "robot": {"name": name},  # a Gaussian law: expected figures in closed form
             "joints": {"friction": {"preset": "42CD4-treated"}, "stiffness": 1.0e5}}
    robot = error = loaded[name]
    if isinstance(error, RobotDescriptionError):
        assert any(re.search(reason, str(error)) for reason in REFUSALS), str(error)
        with pytest.raises(InputError, match=r"^<mapping>: robot(\.tool_frame|\.name)?: ") as refused:
            run_study({**study, "poses": [{"q": [0.0]}]})
        assert str(error) in str(refused.value) and "\n" not in str(refused.value)
        return
    assert np.all((robot.lower_limits <= robot.reference_q) & (robot.reference_q <= robot.upper_limits))
    result = run_study({**study, "poses": [{"name": "reference", "q": robot.reference_q.tolist()}]})
    assert result.settings["tool_frame"] == robot.tool_frame
    assert all(np.isfinite(row["RP_l_um"]) for row in result.poses[0].direction_rows())


def test_which_robots_are_refused(loaded):
    refused = {name for name, outcome in loaded.items() if isinstance(outcome, RobotDescriptionError)}
    assert {"anymal", "solo12", "talos", "hector", "double_pendulum"} <= refused
    assert not refused & {"ur5", "panda", "kinova", "tiago", "tiago_dual", "anymal_kinova", "b1_z1", "baxter",
                          "double_pendulum_continuous", "so100", "z1"}
