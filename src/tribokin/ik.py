"""Inverse kinematics of the tool frame: damped least squares within joint limits."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from tribokin.robot import Robot


@dataclass(frozen=True)
class IKResult:
    """Outcome of one IK solve: ``q`` [m or rad], residual position [m] and angle [rad] errors."""

    q: np.ndarray
    position_error_m: float
    angle_error_rad: float
    success: bool


def solve_ik(robot: Robot, target: pin.SE3, q_start, position_tol_m: float = 1e-10, angle_tol_rad: float = 1e-9,
             position_only: bool = False, iterations: int = 200, damping: float = 1e-6) -> IKResult:
    """Configuration that puts the tool frame at ``target``, from ``q_start``.

    Damped least squares on the frame error ``log6(M^-1 M_target)`` (tool frame),
    each step clipped to the joint limits. ``position_only`` ignores orientation.
    """
    model, data, frame = robot.model, robot.data, robot.tool_frame_id
    lower, upper = robot.lower_limits, robot.upper_limits
    q = np.clip(np.asarray(q_start, dtype=float), lower, upper)
    rows = slice(0, 3) if position_only else slice(0, 6)
    for _ in range(iterations):
        pin.forwardKinematics(model, data, q)
        current = pin.updateFramePlacement(model, data, frame)
        error = pin.log6(current.actInv(target)).vector
        position_error = np.linalg.norm(target.translation - current.translation)
        angle_error = np.linalg.norm(error[3:])
        if position_error < position_tol_m and (position_only or angle_error < angle_tol_rad):
            return IKResult(q, position_error, angle_error, True)
        jacobian = pin.computeFrameJacobian(model, data, q, frame, pin.LOCAL)
        jacobian = (pin.Jlog6(current.actInv(target)) @ jacobian)[rows]
        step = jacobian.T @ np.linalg.solve(jacobian @ jacobian.T + damping * np.eye(jacobian.shape[0]), error[rows])
        q = np.clip(q + step, lower, upper)
    pin.forwardKinematics(model, data, q)
    current = pin.updateFramePlacement(model, data, frame)
    position_error = np.linalg.norm(target.translation - current.translation)
    angle_error = np.linalg.norm(pin.log3(current.rotation.T @ target.rotation))
    success = position_error < position_tol_m * 10 and (position_only or angle_error < angle_tol_rad * 10)
    return IKResult(q, position_error, angle_error, success)


def solve_ik_with_restarts(robot: Robot, target: pin.SE3, q_start, rng: np.random.Generator, restarts: int = 8,
                           **options) -> IKResult:
    """:func:`solve_ik` from ``q_start``, then from random configurations within limits until one succeeds."""
    best = solve_ik(robot, target, q_start, **options)
    lower, upper = robot.lower_limits, robot.upper_limits
    for _ in range(restarts):
        if best.success:
            break
        attempt = solve_ik(robot, target, rng.uniform(lower, upper), **options)
        if attempt.success or attempt.position_error_m < best.position_error_m:
            best = attempt
    return best
