"""Inverse kinematics of the tool frame: damped least squares within joint limits."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from scipy.linalg.lapack import dposv

from tribokin.kinematics.robot import Robot

#: Iterations in a row without progress after which an IK solve gives up.
STALL_ITERATIONS = 20


@dataclass(frozen=True)
class IKResult:
    """Outcome of one IK solve: ``q`` [m or rad], residual position [m] and angle [rad] errors."""

    q: np.ndarray
    position_error_m: float
    angle_error_rad: float
    success: bool


def solve_ik(robot: Robot, target: pin.SE3, q_start, position_tol_m: float = 1e-10, angle_tol_rad: float = 1e-9,
             position_only: bool = False, iterations: int = 200, damping: float = 1e-6,
             patience: int | None = None) -> IKResult:
    """Configuration that puts the tool frame at ``target``, from ``q_start``.

    Damped least squares on the frame error ``log6(M^-1 M_target)`` (tool frame),
    each step clipped to the joint limits. ``position_only`` ignores orientation. Gives up
    after ``iterations``, or, given a ``patience``, once that many iterations in a row have not
    cut the error [m + rad] by 0.1 % (stuck at a joint limit or in a local minimum).
    """
    model, data, frame = robot.model, robot.data, robot.tool_frame_id
    lower, upper = robot.lower_limits, robot.upper_limits
    q = np.minimum(np.maximum(np.asarray(q_start, dtype=float), lower), upper)  # np.clip, without its overhead
    goal = target.translation
    regularisation = damping * np.eye(3 if position_only else 6)  # rows of the error: position (and angle)
    best, stalled = math.inf, 0
    for iteration in range(iterations + 1):
        pin.computeJointJacobians(model, data, q)  # forward kinematics and joint Jacobians in one pass
        current = pin.updateFramePlacement(model, data, frame)
        gap = goal - current.translation
        position_error = math.sqrt(gap @ gap)
        if position_only:
            angle_error = 0.0
            converged = position_error < position_tol_m
        else:
            error_motion = current.actInv(target)
            error = pin.log6(error_motion).vector
            angle_error = math.sqrt(error[3:] @ error[3:])
            converged = position_error < position_tol_m and angle_error < angle_tol_rad
        stalled = 0 if position_error + angle_error < 0.999 * best else stalled + 1
        best = min(best, position_error + angle_error)
        if converged or iteration == iterations or (patience is not None and stalled >= patience):
            break
        jacobian = pin.getFrameJacobian(model, data, frame, pin.LOCAL)
        if position_only:  # translation error in the tool frame, d(position)/dq in the tool frame
            error, jacobian = current.rotation.T @ gap, jacobian[:3]
        else:
            jacobian = pin.Jlog6(error_motion) @ jacobian
        _, step, _ = dposv(jacobian @ jacobian.T + regularisation, error)  # SPD: Cholesky, without numpy's checks
        step = jacobian.T @ step
        q = np.minimum(np.maximum(q + step, lower), upper)
    success = converged or (position_error < position_tol_m * 10
                            and (position_only or angle_error < angle_tol_rad * 10))
    return IKResult(q, position_error, angle_error, success)


def solve_ik_with_restarts(robot: Robot, target: pin.SE3, q_start, rng, restarts: int = 8,
                           **options) -> IKResult:
    """:func:`solve_ik` from ``q_start``, then from random configurations within limits until one succeeds
    (each restart given up once it stalls for ``STALL_ITERATIONS``).

    ``rng``: a :class:`numpy.random.Generator`, or a function making one (called only if a restart is needed).
    """
    best = solve_ik(robot, target, q_start, **options)
    lower, upper = robot.lower_limits, robot.upper_limits
    for _ in range(restarts):
        if best.success:
            break
        rng = rng() if callable(rng) else rng
        attempt = solve_ik(robot, target, rng.uniform(lower, upper), patience=STALL_ITERATIONS, **options)
        if attempt.success or attempt.position_error_m < best.position_error_m:
            best = attempt
    return best
