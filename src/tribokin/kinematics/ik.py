"""Inverse kinematics of the tool frame: damped least squares within joint limits, for one target
(:func:`solve_ik`, Pinocchio) or many at once (:func:`solve_ik_batch`, NumPy, :mod:`tribokin.kinematics.chain`); on the
compiled path (:func:`tribokin.compiled.use_compiled`) both run :func:`tribokin.kinematics.ik_kernels.solve` for a robot
with a serial chain (:func:`~tribokin.kinematics.chain.serial_chain`), every target to its end.

A continuous joint has no limits: its angle is never clipped, and a solution gives it in [-π, π]
(:meth:`~tribokin.kinematics.robot.Robot.wrapped`). Steps add to tribokin's joint values (one per joint), which is
Pinocchio's ``integrate`` for every joint, the continuous ones included."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
import pinocchio as pin

from tribokin.compiled import use_compiled
from tribokin.kinematics.chain import SerialChain, serial_chain
from tribokin.kinematics.robot import Robot
from tribokin.kinematics.se3_log import jlog6, log6

#: Iterations in a row without progress after which an IK solve gives up.
STALL_ITERATIONS = 20
#: Iterations :func:`solve_ik_batch` takes for all its targets together on the NumPy path; a target still iterating
#: after them goes on alone (from a warm start most converge in one or two, and a few slow ones would keep a whole
#: batch's cost per iteration going for up to ``iterations``).
BATCH_ITERATIONS = 4


@dataclass(frozen=True)
class IKResult:
    """Outcome of one IK solve: ``q`` [m or rad], residual position [m] and angle [rad] errors (of a batch's,
    :func:`solve_ik_batch`: (k, nv) and (k,) arrays), and the random restarts it took (:func:`solve_ik_with_restarts`;
    0 when solved from the start given, or not solved)."""

    q: np.ndarray
    position_error_m: float | np.ndarray
    angle_error_rad: float | np.ndarray
    success: bool | np.ndarray
    restarts: int = 0


def solve_ik(robot: Robot, target: pin.SE3, q_start, position_tol_m: float = 1e-10, angle_tol_rad: float = 1e-9,
             position_only: bool = False, iterations: int = 200, damping: float = 1e-6,
             patience: int | None = None, pinocchio: bool = False) -> IKResult:
    """Configuration that puts the tool frame at ``target``, from ``q_start``.

    Damped least squares on the frame error ``log6(M^-1 M_target)`` (tool frame),
    each step clipped to the joint limits; the solution's continuous angles wrapped into [-π, π]. ``position_only``
    ignores orientation. Gives up
    after ``iterations``, or, given a ``patience``, once that many iterations in a row have not
    cut the error [m + rad] by 0.1 % (stuck at a joint limit or in a local minimum).

    An iterate depends on the one before only, so once ``q`` comes back to an earlier iterate to the bit (a solve
    that cannot converge often does, within about 50 iterations), the iterates go round the same cycle: the rest of
    the solve reads them back instead of computing them again (the same result, sooner).

    On the compiled path, a robot with a serial chain is solved by :func:`tribokin.kinematics.ik_kernels.solve` (the
    same iterates to rounding), unless ``pinocchio``. Rounding is all that differs, but at a nearly singular
    configuration far from the target (where a solve that fails ends, or where it passes) a step divides by about
    ``damping`` (a squared singular value near 0 plus it): a rounding difference of 1e-16 becomes one of about 1e-10,
    iterates that do not converge magnify it further, and within some 20 steps the two paths go different ways (the
    solve ends elsewhere, or on another branch). ``pinocchio`` keeps Pinocchio's path for solves whose end must be the
    NumPy path's.
    """
    chain = serial_chain(robot) if use_compiled() and not pinocchio else None
    if chain is not None:
        solved = _solve_compiled(chain, target.rotation, target.translation, q_start, position_tol_m, angle_tol_rad,
                                 position_only, iterations, damping, patience)
        return IKResult(solved.q[0], float(solved.position_error_m[0]), float(solved.angle_error_rad[0]),
                        bool(solved.success[0]))
    model, data, frame = robot.model, robot.data, robot.tool_frame_id
    lower, upper = robot.lower_limits, robot.upper_limits
    q = np.minimum(np.maximum(np.asarray(q_start, dtype=float), lower), upper)  # np.clip, without its overhead
    goal = target.translation
    regularisation = damping * np.eye(3 if position_only else 6)  # rows of the error: position (and angle)
    best, stalled = math.inf, 0
    seen, iterates, cycle = {}, [], None  # iteration of each q met (by its bytes); (q, errors) of each; (start, length)
    for iteration in range(iterations + 1):
        if cycle is None:
            first = seen.setdefault(q.tobytes(), iteration)
            cycle = None if first == iteration else (first, iteration - first)
        if cycle is not None:  # the iterate of the cycle's start this many iterations on
            q, position_error, angle_error = iterates[cycle[0] + (iteration - cycle[0]) % cycle[1]]
        else:
            # forward kinematics and Jacobians in one pass
            pin.computeJointJacobians(model, data, robot.configuration(q))
            current = pin.updateFramePlacement(model, data, frame)
            gap = goal - current.translation
            position_error = math.sqrt(gap @ gap)
            angle_error = 0.0
            if not position_only:
                error_motion = current.actInv(target)
                error = pin.log6(error_motion).vector
                angle_error = math.sqrt(error[3:] @ error[3:])
            iterates.append((q, position_error, angle_error))
        converged = position_error < position_tol_m and angle_error < angle_tol_rad
        stalled = 0 if position_error + angle_error < 0.999 * best else stalled + 1
        best = min(best, position_error + angle_error)
        if converged or iteration == iterations or (patience is not None and stalled >= patience):
            break
        if cycle is not None:
            continue
        jacobian = pin.getFrameJacobian(model, data, frame, pin.LOCAL)
        if position_only:  # translation error in the tool frame, d(position)/dq in the tool frame
            error, jacobian = current.rotation.T @ gap, jacobian[:3]
        else:
            jacobian = pin.Jlog6(error_motion) @ jacobian
        step = jacobian.T @ np.linalg.solve(jacobian @ jacobian.T + regularisation, error)
        q = np.minimum(np.maximum(q + step, lower), upper)
    return IKResult(robot.wrapped(q), position_error, angle_error, _succeeded(converged, position_error, angle_error,
                                                                              position_tol_m, angle_tol_rad))


def _succeeded(converged, position_error_m, angle_error_rad, position_tol_m: float, angle_tol_rad: float):
    """Whether an IK solve succeeded: it converged, or it ended within ten times the tolerances (the angle error is 0
    when the orientation is not held); scalars or arrays."""
    return converged | ((position_error_m < position_tol_m * 10) & (angle_error_rad < angle_tol_rad * 10))


def solve_ik_with_restarts(robot: Robot, target: pin.SE3, q_start, rng, restarts: int = 8,
                           **options) -> IKResult:
    """:func:`solve_ik` from ``q_start``, then from random configurations within limits
    (:meth:`~tribokin.kinematics.robot.Robot.random_configuration`) until one succeeds (each restart given up once it
    stalls for ``STALL_ITERATIONS``).

    ``rng``: a :class:`numpy.random.Generator`, or a function making one (called only if a restart is needed).
    """
    best = solve_ik(robot, target, q_start, **options)
    for restart in range(1, restarts + 1):
        if best.success:
            break
        rng = rng() if callable(rng) else rng
        attempt = solve_ik(robot, target, robot.random_configuration(rng), patience=STALL_ITERATIONS, **options)
        if attempt.success:
            return replace(attempt, restarts=restart)
        if attempt.position_error_m < best.position_error_m:
            best = attempt
    return best


def solve_ik_batch(chain: SerialChain, rotation: np.ndarray, positions_m: np.ndarray, q_start: np.ndarray,
                   position_tol_m: float = 1e-10, angle_tol_rad: float = 1e-9, position_only: bool = False,
                   iterations: int = 200, damping: float = 1e-6) -> IKResult:
    """:func:`solve_ik` of ``chain``'s robot for k targets at once (without ``patience``): the tool frame at
    ``positions_m`` (k, 3) [m], turned by ``rotation`` (3, 3) in the world frame (ignored when ``position_only``), from
    ``q_start`` (k, nv) [m or rad].

    The same iteration, error, damping, clipping, wrapping, convergence tests and success rule as :func:`solve_ik`,
    each target stopping when it converges: on the compiled path every iteration by
    :func:`tribokin.kinematics.ik_kernels.solve`; else in NumPy (:class:`~tribokin.kinematics.chain.SerialChain`,
    :mod:`~tribokin.kinematics.se3_log`) for its first ``BATCH_ITERATIONS`` iterations, then alone through
    :func:`solve_ik` from where it is. Its iterates differ from :func:`solve_ik`'s by rounding only, and do not depend
    on the other targets of the batch.
    """
    if use_compiled():
        return _solve_compiled(chain, rotation, positions_m, q_start, position_tol_m, angle_tol_rad, position_only,
                               iterations, damping, None)
    lower, upper = chain.robot.lower_limits, chain.robot.upper_limits
    goals = np.asarray(positions_m, dtype=float).reshape(-1, 3)
    q = np.minimum(np.maximum(np.array(q_start, dtype=float).reshape(len(goals), len(lower)), lower), upper)
    position_error, angle_error = np.zeros(len(goals)), np.zeros(len(goals))
    converged = np.zeros(len(goals), dtype=bool)
    regularisation = damping * np.eye(3 if position_only else 6)
    active = np.arange(len(goals))
    for iteration in range(min(iterations + 1, BATCH_ITERATIONS)):
        placements = chain.tool_in_joint(q[active])
        current_rotations = placements[:, 0, :3, :3]
        gaps = goals[active] - placements[:, 0, :3, 3]
        position_error[active] = distances = np.sqrt((gaps * gaps).sum(axis=1))
        local_gaps = (gaps[:, None, :] @ current_rotations)[:, 0]  # the gap in the tool frame
        errors, angles = local_gaps, 0.0
        if not position_only:
            errors, turns = log6(np.swapaxes(current_rotations, 1, 2) @ rotation, local_gaps)
            angle_error[active] = angles = np.sqrt((errors[:, 3:] * errors[:, 3:]).sum(axis=1))
        converged[active] = done = (distances < position_tol_m) & (angles < angle_tol_rad)
        going = ~done & (iteration < iterations)
        active, errors, placements = active[going], errors[going], placements[going]
        if not len(active):
            break
        jacobians = chain.tool_jacobians(placements)
        if position_only:
            jacobians = jacobians[:, :3]
        else:
            jacobians = jlog6(errors[:, 3:], turns[going], local_gaps[going]) @ jacobians
        systems = jacobians @ np.swapaxes(jacobians, 1, 2) + regularisation
        steps = (np.swapaxes(jacobians, 1, 2) @ np.linalg.solve(systems, errors[..., None]))[..., 0]
        q[active] = np.minimum(np.maximum(q[active] + steps, lower), upper)
    success = _succeeded(converged, position_error, angle_error, position_tol_m, angle_tol_rad)
    for k in active:  # still iterating: the rest alone
        alone = solve_ik(chain.robot, pin.SE3(rotation, goals[k]), q[k], position_tol_m, angle_tol_rad,
                         position_only, iterations - BATCH_ITERATIONS, damping)
        q[k], position_error[k], angle_error[k], success[k] = alone.q, alone.position_error_m, alone.angle_error_rad, \
            alone.success
    return IKResult(chain.robot.wrapped(q), position_error, angle_error, success)


def _solve_compiled(chain: SerialChain, rotation, positions_m, q_start, position_tol_m: float, angle_tol_rad: float,
                    position_only: bool, iterations: int, damping: float, patience: int | None) -> IKResult:
    """:func:`tribokin.kinematics.ik_kernels.solve` of k targets at ``positions_m`` (k, 3) [m] turned by ``rotation``
    (3, 3) from ``q_start`` (k, nv) [m or rad], its arguments in the types it is compiled for (one signature); the
    solutions' continuous angles wrapped into [-π, π]."""
    from tribokin.kinematics import ik_kernels

    robot = chain.robot
    goals = np.ascontiguousarray(positions_m, dtype=float).reshape(-1, 3)
    starts = np.ascontiguousarray(q_start, dtype=float).reshape(len(goals), len(robot.lower_limits))
    q, position_error, angle_error, success = ik_kernels.solve(
        starts, goals, np.ascontiguousarray(rotation, dtype=float), chain.kernel_terms, robot.lower_limits,
        robot.upper_limits, float(position_tol_m), float(angle_tol_rad), bool(position_only), int(iterations),
        float(damping), -1 if patience is None else int(patience))
    return IKResult(robot.wrapped(q), position_error, angle_error, success)
