"""Compiled (numba) inverse kinematics of a serial chain: :func:`tribokin.kinematics.ik.solve_ik`'s iteration for each
of k targets to its end, through the chain's kernels (:mod:`tribokin.kinematics.chain_kernels`) and the rigid-motion
logarithm's (:mod:`tribokin.kinematics.se3_log_kernels`, Pinocchio's own ``log3`` near a half turn, so no target is
left to Python). Its iterates differ from ``solve_ik``'s by rounding only: ``solve_ik``'s replay of a cycle of
iterates gives what iterating on gives, so this just iterates.

Imported only on the compiled path (:func:`tribokin.compiled.use_compiled`). numba's cache checks only this file:
after editing the kernels it calls, delete the ``*.nbi``/``*.nbc`` files under this folder's ``__pycache__``.
"""

from __future__ import annotations

import math

import numpy as np

from tribokin.compiled import kernel
from tribokin.kinematics.chain_kernels import local_jacobian_at, placements_at
from tribokin.kinematics.se3_log_kernels import jlog6, log6


@kernel
def _clipped(value, lower, upper):
    """``value`` within [``lower``, ``upper``] (NaN stays NaN, as NumPy's ``minimum(maximum(...))``)."""
    if value < lower:
        return lower
    return upper if value > upper else value


@kernel
def _solve_spd(system, size, right, out):
    """``out[:size]`` = the solution of ``system[:size, :size] x = right[:size]`` (symmetric positive definite:
    Cholesky, ``system``'s lower triangle overwritten by its factor)."""
    for j in range(size):
        for i in range(j, size):
            value = system[i, j]
            for k in range(j):
                value -= system[i, k] * system[j, k]
            system[i, j] = math.sqrt(value) if i == j else value / system[j, j]
    for i in range(size):  # L y = right
        value = right[i]
        for k in range(i):
            value -= system[i, k] * out[k]
        out[i] = value / system[i, i]
    for i in range(size - 1, -1, -1):  # Lᵀ x = y
        value = out[i]
        for k in range(i + 1, size):
            value -= system[k, i] * out[k]
        out[i] = value / system[i, i]


@kernel
def solve(q_start, goals, rotation, terms, lower, upper, position_tol, angle_tol, position_only, iterations, damping,
          patience):
    """Damped-least-squares IK of k targets, each to its end: the tool frame at ``goals`` (k, 3) [m] turned by
    ``rotation`` (3, 3) (ignored when ``position_only``), from ``q_start`` (k, n) [m or rad], within ``lower`` and
    ``upper`` (n,) (±inf for a continuous joint), for the chain of ``terms``
    (:attr:`~tribokin.kinematics.chain.SerialChain.kernel_terms`). Each target stops once its errors are below
    ``position_tol`` [m] and ``angle_tol`` [rad], after ``iterations``, or, given a ``patience`` >= 0, once that many
    iterations in a row have not cut its error [m + rad] by 0.1 %.

    Returns:
        (k, n) configurations [m or rad] (continuous angles not wrapped), (k,) position errors [m], (k,) angle errors
        [rad] (0 when ``position_only``), (k,) success (:func:`tribokin.kinematics.ik._succeeded`'s rule).
    """
    count, joints = q_start.shape
    rows = 3 if position_only else 6
    q = np.empty((count, joints))
    position_errors, angle_errors = np.empty(count), np.zeros(count)
    success = np.empty(count, dtype=np.bool_)
    placements, local = np.empty((joints + 1, 4, 4)), np.empty((6, joints))
    jacobian, log_jacobian = np.empty((6, joints)), np.empty((6, 6))
    relative, gap, error = np.empty((3, 3)), np.empty(3), np.empty(6)
    system, solution = np.empty((6, 6)), np.empty(6)
    for target in range(count):
        current = q[target]
        for joint in range(joints):
            current[joint] = _clipped(q_start[target, joint], lower[joint], upper[joint])
        best, stalled = math.inf, 0
        for iteration in range(iterations + 1):
            placements_at(current, terms, placements)
            tool = placements[0]
            dx, dy, dz = goals[target, 0] - tool[0, 3], goals[target, 1] - tool[1, 3], goals[target, 2] - tool[2, 3]
            position_error = math.sqrt(dx * dx + dy * dy + dz * dz)
            for axis in range(3):  # the gap in the tool frame
                gap[axis] = dx * tool[0, axis] + dy * tool[1, axis] + dz * tool[2, axis]
            angle_error, angle = 0.0, 0.0
            if position_only:
                for axis in range(3):
                    error[axis] = gap[axis]
            else:  # log6 of the target in the tool frame
                for row in range(3):
                    for column in range(3):
                        relative[row, column] = (tool[0, row] * rotation[0, column] + tool[1, row] * rotation[1, column]
                                                 + tool[2, row] * rotation[2, column])
                angle = log6(relative, gap, error)
                angle_error = math.sqrt(error[3] * error[3] + error[4] * error[4] + error[5] * error[5])
            converged = position_error < position_tol and angle_error < angle_tol
            progress = position_error + angle_error
            stalled = 0 if progress < 0.999 * best else stalled + 1
            if progress < best:
                best = progress
            if converged or iteration == iterations or (patience >= 0 and stalled >= patience):
                break
            local_jacobian_at(placements, terms, local)
            if position_only:
                for row in range(3):
                    for joint in range(joints):
                        jacobian[row, joint] = local[row, joint]
            else:
                jlog6(error[3:], angle, gap, log_jacobian)
                for row in range(6):
                    for joint in range(joints):
                        value = 0.0
                        for k in range(6):
                            value += log_jacobian[row, k] * local[k, joint]
                        jacobian[row, joint] = value
            for row in range(rows):  # J Jᵀ + damping I
                for column in range(row + 1):
                    value = 0.0
                    for joint in range(joints):
                        value += jacobian[row, joint] * jacobian[column, joint]
                    system[row, column] = value + damping if row == column else value
            _solve_spd(system, rows, error, solution)
            for joint in range(joints):  # q + Jᵀ x, clipped to the limits
                value = 0.0
                for row in range(rows):
                    value += jacobian[row, joint] * solution[row]
                current[joint] = _clipped(current[joint] + value, lower[joint], upper[joint])
        position_errors[target], angle_errors[target] = position_error, angle_error
        success[target] = converged or (position_error < position_tol * 10 and angle_error < angle_tol * 10)
    return q, position_errors, angle_errors, success
