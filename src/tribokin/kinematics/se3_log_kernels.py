"""Compiled (numba) logarithm of one rigid motion and its Jacobian: :mod:`tribokin.kinematics.se3_log`'s ``log6`` and
``jlog6`` (Pinocchio's ``log6`` and ``Jlog6``) branch for branch, series expansions included, for the IK kernel
(:mod:`tribokin.kinematics.ik_kernels`); they agree with it to rounding.

Within about ``PRECISION_2`` of a half turn (a trace below ``-1 + 2 PRECISION_2``) the rotation's logarithm is
Pinocchio's own ``log3`` (:func:`log3_pinocchio`, as ``se3_log`` calls ``pin.log3`` there): the rotation made
orthonormal again, its axis from the diagonal's largest entry, its angle from ``atan2``.

Imported only on the compiled path (:func:`tribokin.compiled.use_compiled`). Rotations are (3, 3), vectors (3,),
C-contiguous float64 arrays. numba's cache checks only the file that defines a kernel: after editing this module,
delete the ``*.nbi``/``*.nbc`` files under ``__pycache__`` beside :mod:`tribokin.kinematics.ik_kernels`, which calls it.
"""

from __future__ import annotations

import math

import numpy as np

from tribokin.compiled import kernel
from tribokin.kinematics.se3_log import EPSILON, PRECISION_2, PRECISION_3


@kernel
def _angle_over_sin(angle, squared):
    """θ / sin θ of angle ``angle`` [rad], below ``PRECISION_2`` its series in ``squared`` (sin² θ)."""
    return angle / math.sin(angle) if angle >= PRECISION_2 else 1.0 + squared / 6.0 + squared * squared * 3.0 / 40.0


@kernel
def log3_pinocchio(rotation, out):
    """Pinocchio's ``log3`` of ``rotation`` (3, 3) into ``out`` (3,) [rad], every branch (Pinocchio 4.1's
    ``log3_impl``)."""
    normed = np.empty((3, 3))  # renormalize_rotation_matrix: columns 0 and 1 scaled to unit length, then crossed
    for column in range(2):
        norm = math.sqrt(rotation[0, column] * rotation[0, column] + rotation[1, column] * rotation[1, column]
                         + rotation[2, column] * rotation[2, column])
        for row in range(3):
            normed[row, column] = rotation[row, column] / norm
    for target, first, second in ((2, 0, 1), (0, 1, 2)):
        for row in range(3):
            row_1, row_2 = (row + 1) % 3, (row + 2) % 3
            normed[row, target] = normed[row_1, first] * normed[row_2, second] - normed[row_2, first] * normed[
                row_1, second]
    trace = normed[0, 0] + normed[1, 1] + normed[2, 2]
    cos = (trace - 1.0) / 2.0
    if cos >= -1.0 + PRECISION_2:
        expansion = math.sqrt(2.0 * (1.0 - cos) + EPSILON * EPSILON)
        if trace > 3.0 - PRECISION_2:
            angle = expansion
        else:
            angle = math.acos(cos) if trace >= -1.0 + PRECISION_2 else math.pi - expansion
        x, y, z = ((normed[2, 1] - normed[1, 2]) / 2.0, (normed[0, 2] - normed[2, 0]) / 2.0,
                   (normed[1, 0] - normed[0, 1]) / 2.0)
        squared = x * x + y * y + z * z
        scale = _angle_over_sin(angle, squared)
        out[0], out[1], out[2] = scale * x, scale * y, scale * z
        return
    values = np.empty(3)
    for axis in range(3):
        values[axis] = 2.0 * normed[axis, axis] - trace + 1.0
    if values[0] >= values[1]:
        first = 0 if values[0] >= values[2] else 2
    else:
        first = 1 if values[1] >= values[2] else 2
    second, third = (first + 1) % 3, (first + 2) % 3  # compute_theta_axis<first>
    sign = 1.0 if normed[third, second] >= normed[second, third] else -1.0
    s = math.sqrt(values[first] + EPSILON + EPSILON * EPSILON) * sign
    out[first] = s / 2.0
    out[second] = 1.0 / (2.0 * s) * (normed[second, first] + normed[first, second])
    out[third] = 1.0 / (2.0 * s) * (normed[third, first] + normed[first, third])
    w = 1.0 / (2.0 * s) * (normed[third, second] - normed[second, third])
    norm = math.sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2])
    angle = 2.0 * math.atan2(norm, w)
    for axis in range(3):
        out[axis] = angle * (out[axis] / norm)


@kernel
def log6(rotation, translation, out):
    """The logarithm of the rigid motion ``rotation`` (3, 3), ``translation`` (3,) [m] into ``out`` (6,) (linear [m],
    angular [rad]); returns the angle of its rotation [rad] (as :func:`tribokin.kinematics.se3_log.log6` does)."""
    trace = rotation[0, 0] + rotation[1, 1] + rotation[2, 2]
    cos = (trace - 1.0) / 2.0
    x, y, z = ((rotation[2, 1] - rotation[1, 2]) * 0.5, (rotation[0, 2] - rotation[2, 0]) * 0.5,
               (rotation[1, 0] - rotation[0, 1]) * 0.5)
    squared = x * x + y * y + z * z
    if cos < -1.0 + PRECISION_2:
        log3_pinocchio(rotation, out[3:])
        angle = math.sqrt(out[3] * out[3] + out[4] * out[4] + out[5] * out[5])
    else:
        expansion = math.sqrt(max(2.0 * (1.0 - cos), 0.0) + EPSILON * EPSILON)
        if trace <= 3.0 - PRECISION_2:
            angle = math.acos(min(max(cos, -1.0), 1.0)) if trace >= -1.0 + PRECISION_2 else math.pi - expansion
        else:
            angle = expansion
        scale = _angle_over_sin(angle, squared)
        out[3], out[4], out[5] = scale * x, scale * y, scale * z
    if trace >= 3.0 - PRECISION_2:
        alpha = 1.0 - squared / 12.0 - squared * squared / 720.0
        beta = 1.0 / 12.0 + squared / 720.0
    else:
        sin, cos_angle = math.sin(angle), math.cos(angle)
        alpha = angle * sin / (2.0 * (1.0 - cos_angle))
        beta = 1.0 / (angle * angle) - sin / (2.0 * angle * (1.0 - cos_angle))
    wx, wy, wz = out[3], out[4], out[5]
    px, py, pz = translation[0], translation[1], translation[2]
    along = beta * (wx * px + wy * py + wz * pz)
    out[0] = alpha * px - 0.5 * (wy * pz - wz * py) + along * wx
    out[1] = alpha * py - 0.5 * (wz * px - wx * pz) + along * wy
    out[2] = alpha * pz - 0.5 * (wx * py - wy * px) + along * wz
    return angle


@kernel
def jlog6(rotation_vector, angle, translation, out):
    """The Jacobian of :func:`log6` into ``out`` (6, 6) at the rigid motion of rotation vector ``rotation_vector``
    (3,) [rad] and angle ``angle`` [rad] (as :func:`log6` gives them) and translation ``translation`` (3,) [m]."""
    w, p = rotation_vector, translation
    angle_squared = angle * angle
    if angle < PRECISION_3:
        rotation_beta = beta = 1.0 / 12.0 + angle_squared / 720.0
        diagonal = 0.5 * (2.0 - angle_squared / 6.0)
        beta_dot_over_theta = 1.0 / 360.0
    else:
        sin, cos = math.sin(angle), math.cos(angle)
        half_cotangent = sin / (1.0 - cos)
        inverse = 1.0 / angle
        inverse_squared, inverse_2_2cos = inverse * inverse, 1.0 / (2.0 * (1.0 - cos))
        rotation_beta = 1.0 / angle_squared - half_cotangent / (2.0 * angle)
        diagonal = 0.5 * (angle * half_cotangent)
        beta = inverse_squared - sin * inverse * inverse_2_2cos
        beta_dot_over_theta = (-2.0 * inverse_squared * inverse_squared
                               + (1.0 + sin * inverse) * inverse_squared * inverse_2_2cos)
    along = w[0] * p[0] + w[1] * p[1] + w[2] * p[2]
    towards_scale = beta_dot_over_theta * along
    p_scale = angle_squared * beta_dot_over_theta + 2.0 * beta
    for row in range(3):  # Jlog3 in both diagonal blocks; the coupling (kept in the lower-left block for now)
        towards = towards_scale * w[row] - p_scale * p[row]
        for column in range(3):
            out[row, column] = rotation_beta * w[row] * w[column] + (diagonal if row == column else 0.0)
            out[3 + row, column] = towards * w[column] + beta * w[row] * p[column] + (
                along * beta if row == column else 0.0)
    for row, column, sign in ((0, 1, -1.0), (0, 2, 1.0), (1, 2, -1.0)):  # + [w/2]×, [p/2]×
        other = 3 - row - column
        out[row, column] += sign * (0.5 * w[other])
        out[column, row] -= sign * (0.5 * w[other])
        out[3 + row, column] += sign * (0.5 * p[other])
        out[3 + column, row] -= sign * (0.5 * p[other])
    for row in range(3):  # upper right: coupling · Jlog3; then the lower blocks: 0 and Jlog3
        for column in range(3):
            out[row, 3 + column] = (out[3 + row, 0] * out[0, column] + out[3 + row, 1] * out[1, column]
                                    + out[3 + row, 2] * out[2, column])
    for row in range(3):
        for column in range(3):
            out[3 + row, 3 + column] = out[row, column]
            out[3 + row, column] = 0.0
