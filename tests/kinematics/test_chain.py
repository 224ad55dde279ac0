"""The tool frame's placement and Jacobian of a serial chain, for many configurations at once, against Pinocchio's
one-configuration results on every tested robot and the shipped gantries; chains NumPy cannot compute are refused."""

import numpy as np
import pinocchio as pin
import pytest

from conftest import AXIS_URDF, ROOT
from helpers.robots import GANTRY_URDF, random_q, screw_robot
from tribokin.kinematics.chain import serial_chain
from tribokin.kinematics.robot import TESTED_ROBOTS, Robot, load_example_robot, load_urdf, rigid_placement

#: The gantry of the propagation tests (its ram slides along -z: Pinocchio's PrismaticUnaligned) with its spindle
#: turning about a skewed axis (RevoluteUnaligned).
SKEWED_URDF = GANTRY_URDF.replace('<axis xyz="0 0 1"/>', '<axis xyz="0.6 0.8 0"/>')


def urdf_robot(tmp_path, text: str) -> Robot:
    path = tmp_path / "robot.urdf"
    path.write_text(text)
    return load_urdf(path, "tool")


ROBOTS = {
    **{name: lambda tmp_path, name=name: load_example_robot(name) for name in TESTED_ROBOTS},
    "ur5 with a tool offset": lambda tmp_path: load_example_robot(
        "ur5", tool_offset=rigid_placement([0.05, -0.1, 0.2], [10, 20, 30])),
    "gantry": lambda tmp_path: load_urdf(ROOT / "urdf" / "cartesian_xyz.urdf", "tool"),
    "axis": lambda tmp_path: load_urdf(AXIS_URDF, "tool"),
    "gantry with a spindle": lambda tmp_path: urdf_robot(tmp_path, GANTRY_URDF),
    "gantry with a skewed spindle": lambda tmp_path: urdf_robot(tmp_path, SKEWED_URDF),
}





@pytest.mark.parametrize("name", ROBOTS)
def test_placements_and_jacobians_match_pinocchio(name, tmp_path):
    robot = ROBOTS[name](tmp_path)
    chain = serial_chain(robot)
    q = random_q(robot, 50)
    placements = chain.tool_in_joint(q)
    jacobians = chain.tool_jacobians(placements)
    assert placements.shape == (50, robot.model.nv + 1, 4, 4) and jacobians.shape == (50, 6, robot.model.nv)
    for qi, placement, jacobian in zip(q, placements, jacobians, strict=True):
        tool = robot.tool_placement(qi)
        np.testing.assert_allclose(placement[0], tool.homogeneous, rtol=0, atol=1e-12)
        rotation = np.kron(np.eye(2), tool.rotation)  # the tool frame's axes to the base's, for both halves
        np.testing.assert_allclose(rotation @ jacobian, robot.tool_jacobian(qi), rtol=0, atol=1e-12)
        pin.computeJointJacobians(robot.model, robot.data, robot.configuration(qi))  # as solve_ik asks for it
        local = pin.getFrameJacobian(robot.model, robot.data, robot.tool_frame_id, pin.LOCAL)
        np.testing.assert_allclose(jacobian, np.reshape(local, (6, -1)), rtol=0, atol=1e-12)
        for joint, in_joint in zip(range(1, robot.model.njoints), placement[1:], strict=True):
            np.testing.assert_allclose(in_joint, (robot.data.oMi[joint].inverse() * tool).homogeneous, atol=1e-12)
    np.testing.assert_allclose(chain.tool_in_world(q), placements[:, 0], rtol=0, atol=1e-14)  # the links' product
    assert chain.tool_in_joint(q[:0]).shape == (0, robot.model.nv + 1, 4, 4)
    assert chain.tool_in_world(q[:0]).shape == (0, 4, 4)
    world = chain.world_jacobians(placements)
    joints = chain.joints_in_world(placements)
    for qi, jacobian, frames in zip(q, world, joints, strict=True):
        np.testing.assert_allclose(jacobian, robot.tool_jacobian(qi), rtol=0, atol=1e-12)
        pin.forwardKinematics(robot.model, robot.data, robot.configuration(qi))
        for joint, frame in zip(range(1, robot.model.njoints), frames, strict=True):
            np.testing.assert_allclose(frame, robot.data.oMi[joint].homogeneous, rtol=0, atol=1e-12)


def test_each_configuration_is_computed_alone():
    """A configuration's placement and Jacobian, to the bit, whatever the others in the batch."""
    chain = serial_chain(load_example_robot("ur5"))
    q = random_q(chain.robot, 40)
    together = chain.tool_in_joint(q)
    for k in (0, 17, 39):
        alone = chain.tool_in_joint(q[k:k + 1])
        assert alone.tobytes() == together[k:k + 1].tobytes()
        assert chain.tool_jacobians(alone).tobytes() == chain.tool_jacobians(together)[k:k + 1].tobytes()


def test_a_joint_that_is_not_an_axis_joint_has_no_chain():
    assert serial_chain(screw_robot()) is None
