"""The serial chain's compiled kernels against its NumPy path and Pinocchio: placements in the world and in each joint,
Jacobians in the tool frame and in world axes, joint frames in the world, on the UR5, the Panda, the bundled gantry
(prismatic) and Kinova's Gen3 (continuous joints, angles beyond ±π); and the NumPy path never loads numba."""

import os
import subprocess
import sys

import numpy as np
import pinocchio as pin
import pytest

from conftest import GEN3_URDF, ROOT
from helpers.robots import random_q
from tribokin.kinematics.chain import serial_chain
from tribokin.kinematics.robot import load_example_robot, load_urdf

ROBOTS = {
    "ur5": lambda: load_example_robot("ur5"),
    "panda": lambda: load_example_robot("panda"),
    "gantry": lambda: load_urdf(ROOT / "urdf" / "cartesian_xyz.urdf", "tool"),
    "gen3": lambda: load_urdf(GEN3_URDF),
}


def chain_outputs(chain, q) -> dict[str, np.ndarray]:
    placements = chain.tool_in_joint(q)
    return {"tool_in_joint": placements, "tool_in_world": chain.tool_in_world(q),
            "tool_jacobians": chain.tool_jacobians(placements), "world_jacobians": chain.world_jacobians(placements),
            "joints_in_world": chain.joints_in_world(placements)}


@pytest.mark.parametrize("name", ROBOTS)
def test_the_compiled_chain_agrees_with_numpy_and_pinocchio(name, monkeypatch):
    robot = ROBOTS[name]()
    chain = serial_chain(robot)
    q = random_q(robot, 30, seed=7)
    if robot.continuous.any():
        q[:, robot.continuous] *= 2.0  # continuous angles up to ±8 rad
        assert np.abs(q[:, robot.continuous]).max() > 2 * np.pi
    outputs = {}
    for path in ("numpy", "compiled"):
        monkeypatch.setenv("TRIBOKIN_KERNELS", path)
        outputs[path] = chain_outputs(chain, q)
    for key, expected in outputs["numpy"].items():
        assert outputs["compiled"][key].shape == expected.shape
        np.testing.assert_allclose(outputs["compiled"][key], expected, rtol=0, atol=1e-12 * np.abs(expected).max(),
                                   err_msg=key)
    compiled = outputs["compiled"]
    for k in range(0, len(q), 6):  # and Pinocchio's, one configuration at a time
        configuration = robot.configuration(q[k])
        pin.computeJointJacobians(robot.model, robot.data, configuration)
        tool = pin.updateFramePlacement(robot.model, robot.data, robot.tool_frame_id)
        np.testing.assert_allclose(compiled["tool_in_joint"][k, 0], tool.homogeneous, rtol=0, atol=1e-12)
        np.testing.assert_allclose(compiled["tool_in_world"][k], tool.homogeneous, rtol=0, atol=1e-12)
        local = pin.getFrameJacobian(robot.model, robot.data, robot.tool_frame_id, pin.LOCAL)
        np.testing.assert_allclose(compiled["tool_jacobians"][k], local, rtol=0, atol=1e-12)
        aligned = pin.getFrameJacobian(robot.model, robot.data, robot.tool_frame_id, pin.LOCAL_WORLD_ALIGNED)
        np.testing.assert_allclose(compiled["world_jacobians"][k], aligned, rtol=0, atol=1e-12)
        for joint in range(1, robot.model.njoints):
            np.testing.assert_allclose(compiled["joints_in_world"][k, joint - 1], robot.data.oMi[joint].homogeneous,
                                       rtol=0, atol=1e-12)
            np.testing.assert_allclose(compiled["tool_in_joint"][k, joint],
                                       (robot.data.oMi[joint].inverse() * tool).homogeneous, rtol=0, atol=1e-12)


def test_the_numpy_path_never_loads_numba():
    """A map row's IK (batch, single solves, restarts) and the chain's kernels on the NumPy path, in a fresh process."""
    script = """
import sys
import numpy as np
from tribokin.kinematics.chain import serial_chain
from tribokin.maps import rows
from tribokin.maps.grid import make_grid
from tribokin.study.assembly import load_robot
from tribokin.study.reading import load_study
study = load_study(sys.argv[1])
robot = load_robot(study)
grid = make_grid(robot, study.map, None)
starts = rows.solve_row_starts(robot, grid)
assert rows.solve_rows(robot, grid, [0, 1], starts[:2])[1].all()
chain = serial_chain(robot)
placements = chain.tool_in_joint(np.zeros((2, 3)))
chain.world_jacobians(placements), chain.joints_in_world(placements)
assert "numba" not in sys.modules, "numba loaded"
"""
    environment = {**os.environ, "TRIBOKIN_KERNELS": "numpy", "PYTHONPATH": str(ROOT / "src")}
    done = subprocess.run([sys.executable, "-c", script, str(ROOT / "studies" / "gantry-map.toml")], env=environment,
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
