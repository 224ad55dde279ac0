"""Propagation of joint deviations to the tool pose through Pinocchio kinematics."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from tribokin.robot import Robot


def tool_deviations_exact(robot: Robot, q: np.ndarray, dq: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Tool poses by exact forward kinematics, one Pinocchio call per sample (the reference engine).

    Args:
        robot: the robot; its active joints are all 1-DoF, so q + dq is the configuration reached.
        q: (nq,) commanded configuration [m or rad].
        dq: (n, nv) joint deviations of each cycle [m or rad].

    Returns:
        positions (n, 3) of the tool frame in the world frame [m], and orientation
        deviations (n, 3) [rad]: the rotation vector ``log3(R_j R_c^T)`` from the
        commanded orientation R_c (at ``q``) to the reached one, in world axes.
    """
    model, data, frame = robot.model, robot.data, robot.tool_frame_id
    commanded_rotation = robot.tool_placement(q).rotation
    positions = np.empty((len(dq), 3))
    angles = np.empty((len(dq), 3))
    for j, q_reached in enumerate(np.asarray(q, dtype=float) + dq):
        pin.forwardKinematics(model, data, q_reached)
        placement = pin.updateFramePlacement(model, data, frame)
        positions[j] = placement.translation
        angles[j] = pin.log3(placement.rotation @ commanded_rotation.T)
    return positions, angles


ENGINES = {"exact": tool_deviations_exact}


def tool_deviations(robot: Robot, q: np.ndarray, dq: np.ndarray, engine: str = "exact"):
    """Tool positions [m] and orientation deviations [rad] of each cycle, by the named engine."""
    return ENGINES[engine](robot, q, dq)
