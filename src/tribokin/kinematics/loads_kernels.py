"""Compiled (numba) kernel of :class:`~tribokin.kinematics.loads.BearingLoads` on a serial chain: each joint's
bearing load from the chain's placements, configuration by configuration (statics of the weights carried, then the
two supports' forces), without a temporary array per configuration. It agrees with the NumPy path to rounding
(about 1e-15 relative).

Imported only on the compiled path (:func:`tribokin.compiled.use_compiled`).
"""

from __future__ import annotations

import math

import numpy as np

from tribokin.compiled import kernel


@kernel
def chain_loads(placements, weights, centres, axes, prismatic, span):
    """(k, n) bearing loads N [N] at k configurations of a serial chain of n joints, from their placements
    (k, n + 1, 4, 4) (:meth:`~tribokin.kinematics.chain.SerialChain.tool_in_joint`: the tool's in the world, then in
    each joint's frame). ``weights`` (n, 3) [N] and ``centres`` (n, 3) [m]: each body's weight in the world and centre
    of mass in its joint's frame; ``axes`` (n, 3) the unit motion axes; ``prismatic`` (n,) bool; ``span`` (n,) [m].
    As :meth:`~tribokin.kinematics.loads.BearingLoads.chain_wrenches` then
    :func:`~tribokin.kinematics.loads.support_loads`, from the tool down."""
    count, joints = placements.shape[0], placements.shape[1] - 1
    out = np.empty((count, joints))
    rotation = np.empty((3, 3))  # the joint's frame in the world
    origin = np.empty(3)
    back = np.empty(3)  # -R_in_jointᵀ p_in_joint
    centre = np.empty(3)  # the body's centre of mass in the world
    force = np.empty(3)  # minus the weights carried [N]
    moment = np.empty(3)  # their moment about the world's origin [N·m]
    about = np.empty(3)  # ... about the joint's origin
    local_force = np.empty(3)
    local_moment = np.empty(3)
    for k in range(count):
        tool = placements[k, 0]
        force[:] = 0.0
        moment[:] = 0.0
        for i in range(joints - 1, -1, -1):
            in_joint = placements[k, i + 1]
            for r in range(3):  # R_i = R_tool R_in_jointᵀ, o_i = p_tool - R_i p_in_joint
                for c in range(3):
                    rotation[r, c] = (tool[r, 0] * in_joint[c, 0] + tool[r, 1] * in_joint[c, 1]
                                      + tool[r, 2] * in_joint[c, 2])
            for c in range(3):
                back[c] = -(in_joint[0, c] * in_joint[0, 3] + in_joint[1, c] * in_joint[1, 3]
                            + in_joint[2, c] * in_joint[2, 3])
            for r in range(3):
                origin[r] = tool[r, 0] * back[0] + tool[r, 1] * back[1] + tool[r, 2] * back[2] + tool[r, 3]
            for r in range(3):
                centre[r] = origin[r] + (rotation[r, 0] * centres[i, 0] + rotation[r, 1] * centres[i, 1]
                                         + rotation[r, 2] * centres[i, 2])
            centre_x, centre_y, centre_z = centre[0], centre[1], centre[2]
            weight_x, weight_y, weight_z = weights[i, 0], weights[i, 1], weights[i, 2]
            force[0] -= weight_x
            force[1] -= weight_y
            force[2] -= weight_z
            moment[0] -= centre_y * weight_z - centre_z * weight_y
            moment[1] -= centre_z * weight_x - centre_x * weight_z
            moment[2] -= centre_x * weight_y - centre_y * weight_x
            about[0] = moment[0] - (origin[1] * force[2] - origin[2] * force[1])
            about[1] = moment[1] - (origin[2] * force[0] - origin[0] * force[2])
            about[2] = moment[2] - (origin[0] * force[1] - origin[1] * force[0])
            for c in range(3):  # into the joint's frame: R_iᵀ
                local_force[c] = rotation[0, c] * force[0] + rotation[1, c] * force[1] + rotation[2, c] * force[2]
                local_moment[c] = rotation[0, c] * about[0] + rotation[1, c] * about[1] + rotation[2, c] * about[2]
            out[k, i] = _support_load(local_force, local_moment, axes[i], prismatic[i], span[i])
    return out


@kernel
def _support_load(force, moment, axis, prismatic, span):
    """A joint's load N [N] from its wrench in its frame: ``|F_a| + |R+| + |R-|`` (revolute), ``|R+| + |R-| +
    2 |M_a| / L`` (prismatic), ``R± = F_r / 2 ± (M_t × a) / L``."""
    along_force = force[0] * axis[0] + force[1] * axis[1] + force[2] * axis[2]
    along_moment = moment[0] * axis[0] + moment[1] * axis[1] + moment[2] * axis[2]
    tilt_x = moment[0] - along_moment * axis[0]
    tilt_y = moment[1] - along_moment * axis[1]
    tilt_z = moment[2] - along_moment * axis[2]
    couple_x = (tilt_y * axis[2] - tilt_z * axis[1]) / span
    couple_y = (tilt_z * axis[0] - tilt_x * axis[2]) / span
    couple_z = (tilt_x * axis[1] - tilt_y * axis[0]) / span
    half_x = (force[0] - along_force * axis[0]) / 2
    half_y = (force[1] - along_force * axis[1]) / 2
    half_z = (force[2] - along_force * axis[2]) / 2
    load = (_norm(half_x + couple_x, half_y + couple_y, half_z + couple_z)
            + _norm(half_x - couple_x, half_y - couple_y, half_z - couple_z))
    if prismatic:
        return load + 2 * _norm(along_moment * axis[0], along_moment * axis[1], along_moment * axis[2]) / span
    return load + _norm(along_force * axis[0], along_force * axis[1], along_force * axis[2])


@kernel
def _norm(x, y, z):
    """|(x, y, z)|, its squares summed in order as NumPy's norm."""
    return math.sqrt(x * x + y * y + z * z)
