"""Compiled (numba) kernels of :class:`~tribokin.kinematics.chain.SerialChain`: the tool frame's placements in the
world and in each joint's frame (or in the world only), and its Jacobians, configuration by configuration in loops
over 4 × 4 and 3 × 3 matrices (no temporary array per configuration). They agree with the chain's NumPy path to
rounding (seen: 1e-15 at most on the UR5, Panda, gantry and Gen3): the links' products are taken from the tool
towards the base one at a time, where NumPy doubles its steps (``tool_in_world``: from the base towards the tool,
as NumPy's).

``joints_in_world`` takes placements only; the others also the chain's ``terms``
(:attr:`~tribokin.kinematics.chain.SerialChain.kernel_terms`): ``base``, ``turn_cos``, ``turn_sin``, ``slide``
(n + 1, 4, 4), ``turn_skews`` (n, 3, 3), ``slide_axes`` and ``turn_axes`` (n, 3), C-contiguous float64 arrays.

Imported only on the compiled path (:func:`tribokin.compiled.use_compiled`). numba's cache checks only the file that
defines a kernel: after editing this module, delete the ``*.nbi``/``*.nbc`` files under ``__pycache__`` beside the
modules whose kernels call these (:mod:`tribokin.kinematics.ik_kernels`).
"""

from __future__ import annotations

import math

import numpy as np

from tribokin.compiled import kernel


@kernel
def link_at(terms, link, angle, out):
    """Link ``link`` of the chain at ``angle`` [m or rad] into ``out`` (4, 4): ``base + cos(q)·turn_cos +
    sin(q)·turn_sin + q·slide``, homogeneous [m]."""
    base, turn_cos, turn_sin, slide = terms[0], terms[1], terms[2], terms[3]
    cos, sin = math.cos(angle), math.sin(angle)
    for row in range(3):
        for column in range(4):
            out[row, column] = (base[link, row, column] + cos * turn_cos[link, row, column]
                                + sin * turn_sin[link, row, column] + angle * slide[link, row, column])
    for column in range(4):  # (0, 0, 0, 1): no term moves it
        out[3, column] = base[link, 3, column]


@kernel
def placements_at(q, terms, out):
    """The tool frame's placements at one configuration ``q`` (n,) [m or rad] into ``out`` (n + 1, 4, 4): in the
    world (index 0) and in each joint's frame after its motion (index ``i + 1``), homogeneous [m]."""
    joints = q.shape[0]
    for link in range(joints + 1):  # the tool's at q = 0
        link_at(terms, link, q[link] if link < joints else 0.0, out[link])
    for link in range(joints - 1, -1, -1):  # each link times the product of those after it, row by row in place
        for row in range(3):
            a0, a1, a2, a3 = out[link, row, 0], out[link, row, 1], out[link, row, 2], out[link, row, 3]
            for column in range(4):
                out[link, row, column] = (a0 * out[link + 1, 0, column] + a1 * out[link + 1, 1, column]
                                          + a2 * out[link + 1, 2, column])
            out[link, row, 3] += a3


@kernel
def local_jacobian_at(placements, terms, out):
    """The tool Jacobian in the tool frame (Pinocchio's ``LOCAL``: rows linear [m/unit], angular [rad/unit]) into
    ``out`` (6, n), from one configuration's :func:`placements_at` ``placements`` (n + 1, 4, 4)."""
    turn_skews, slide_axes, turn_axes = terms[4], terms[5], terms[6]
    for joint in range(turn_axes.shape[0]):
        in_joint, skew = placements[joint + 1], turn_skews[joint]
        x, y, z = in_joint[0, 3], in_joint[1, 3], in_joint[2, 3]
        # the tool's velocity per unit of the joint, in the joint's frame
        linear_x = (skew[0, 0] * x + skew[0, 1] * y + skew[0, 2] * z) + slide_axes[joint, 0]
        linear_y = (skew[1, 0] * x + skew[1, 1] * y + skew[1, 2] * z) + slide_axes[joint, 1]
        linear_z = (skew[2, 0] * x + skew[2, 1] * y + skew[2, 2] * z) + slide_axes[joint, 2]
        for row in range(3):  # turned into the tool's frame
            out[row, joint] = in_joint[0, row] * linear_x + in_joint[1, row] * linear_y + in_joint[2, row] * linear_z
            out[3 + row, joint] = (in_joint[0, row] * turn_axes[joint, 0] + in_joint[1, row] * turn_axes[joint, 1]
                                   + in_joint[2, row] * turn_axes[joint, 2])


@kernel
def tool_in_joint(q, terms):
    """(k, n + 1, 4, 4) :func:`placements_at` of each configuration of ``q`` (k, n) [m or rad]."""
    out = np.empty((q.shape[0], q.shape[1] + 1, 4, 4))
    for k in range(q.shape[0]):
        placements_at(q[k], terms, out[k])
    return out


@kernel
def tool_in_world(q, terms):
    """(k, 4, 4) the tool frame's placement in the world (homogeneous [m]) at each configuration of ``q`` (k, n)
    [m or rad]: the product of the links from the base to the tool, taken in that order, and no other product."""
    joints = q.shape[1]
    out = np.empty((q.shape[0], 4, 4))
    link = np.empty((4, 4))
    for k in range(q.shape[0]):
        placement = out[k]
        link_at(terms, 0, q[k, 0], placement)
        for index in range(1, joints + 1):  # times each next link, row by row in place; the tool's at q = 0
            link_at(terms, index, q[k, index] if index < joints else 0.0, link)
            for row in range(3):
                a0, a1, a2, a3 = placement[row, 0], placement[row, 1], placement[row, 2], placement[row, 3]
                for column in range(4):
                    placement[row, column] = a0 * link[0, column] + a1 * link[1, column] + a2 * link[2, column]
                placement[row, 3] += a3
    return out


@kernel
def tool_jacobians(placements, terms):
    """(k, 6, n) :func:`local_jacobian_at` of each configuration's ``placements`` (k, n + 1, 4, 4)."""
    out = np.empty((placements.shape[0], 6, placements.shape[1] - 1))
    for k in range(placements.shape[0]):
        local_jacobian_at(placements[k], terms, out[k])
    return out


@kernel
def world_jacobians(placements, terms):
    """(k, 6, n) the tool Jacobians of :func:`tool_jacobians` in world axes (``LOCAL_WORLD_ALIGNED``)."""
    out = tool_jacobians(placements, terms)
    column = np.empty(3)
    for k in range(placements.shape[0]):
        rotation = placements[k, 0]
        for joint in range(out.shape[2]):
            for half in (0, 3):
                for row in range(3):
                    column[row] = out[k, half + row, joint]
                for row in range(3):
                    out[k, half + row, joint] = (rotation[row, 0] * column[0] + rotation[row, 1] * column[1]
                                                 + rotation[row, 2] * column[2])
    return out


@kernel
def joints_in_world(placements):
    """(k, n, 4, 4) each joint frame's placement in the world after its motion (``data.oMi``): the tool's in the
    world times the inverse of the tool's in the joint, from ``placements`` (k, n + 1, 4, 4)."""
    out = np.zeros((placements.shape[0], placements.shape[1] - 1, 4, 4))
    inverse = np.zeros((3, 4))
    for k in range(placements.shape[0]):
        tool = placements[k, 0]
        for joint in range(out.shape[1]):
            in_joint = placements[k, joint + 1]
            for row in range(3):  # [Rᵀ, -Rᵀ t]
                for column in range(3):
                    inverse[row, column] = in_joint[column, row]
                inverse[row, 3] = -(in_joint[0, row] * in_joint[0, 3] + in_joint[1, row] * in_joint[1, 3]
                                    + in_joint[2, row] * in_joint[2, 3])
            for row in range(3):
                for column in range(4):
                    out[k, joint, row, column] = (tool[row, 0] * inverse[0, column] + tool[row, 1] * inverse[1, column]
                                                  + tool[row, 2] * inverse[2, column])
                out[k, joint, row, 3] += tool[row, 3]
            out[k, joint, 3, 3] = 1.0
    return out
