"""Bearing loads of each joint from Pinocchio statics (RNEA with the robot at rest).

With the robot static, ``pin.rnea(model, data, q, 0, 0)`` fills ``data.f[i]``:
the wrench (force F, moment M about the joint origin) that joint i transmits
to its subtree — gravity of every body it carries plus the payload — in the
joint frame. The component along the joint's motion is taken by the drive;
the rest is carried by the slide or bearing. With ``a`` the unit motion axis
and ``L`` the bearing span (distance between the two guide pads or bearings):

* prismatic joint: ``N = |F - (F·a) a| + |M| / L``   (the guide carries every moment)
* revolute joint:  ``N = |F| + |M - (M·a) a| / L``   (the bearing carries every force and the tilting moment)

The moment term is the extra pad force of a tilting moment shared over a
span L; it is what makes friction, and so repeatability, depend on where the
robot is.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from tribokin.kinematics.robot import Robot


def with_payload(robot: Robot, payload_kg: float) -> pin.Model:
    """A copy of the robot's model with a point mass ``payload_kg`` [kg] at the tool frame."""
    model = pin.Model(robot.model)
    if payload_kg > 0:
        frame = model.frames[robot.tool_frame_id]
        point_mass = pin.Inertia(payload_kg, np.zeros(3), np.zeros((3, 3)))
        model.inertias[frame.parentJoint] = model.inertias[frame.parentJoint] + frame.placement.act(point_mass)
    return model


class BearingLoads:
    """Computes N_i(q) [N] for every active joint of a robot.

    Args:
        robot: the robot (active joints 1-DoF).
        payload_kg: point mass carried at the tool frame [kg].
        bearing_span_m: (nv,) bearing span L of each joint [m].
    """

    def __init__(self, robot: Robot, payload_kg: float, bearing_span_m):
        self.model = with_payload(robot, payload_kg)
        self.data = self.model.createData()
        self.span_m = np.asarray(bearing_span_m, dtype=float)
        self.prismatic = robot.joint_is_prismatic
        self.axes = robot.motion_axes

    def wrenches(self, q) -> np.ndarray:
        """(nv, 6) static wrench (force [N], moment [N·m]) transmitted by each active joint, in its joint frame."""
        zero = np.zeros(self.model.nv)
        pin.rnea(self.model, self.data, np.asarray(q, dtype=float), zero, zero)
        return np.array([self.data.f[i].vector for i in range(1, self.model.njoints)])

    def __call__(self, q) -> np.ndarray:
        """Bearing load N_i [N] of every active joint at configuration ``q`` (nq,), or (poses, nv) at
        configurations (poses, nq)."""
        q = np.asarray(q, dtype=float)
        wrenches = np.array([self.wrenches(qi) for qi in q.reshape(-1, q.shape[-1])]).reshape(-1, self.model.nv, 6)
        force, moment = wrenches[..., :3], wrenches[..., 3:]
        prismatic = self.prismatic[:, None]
        along = np.sum(np.where(prismatic, force, moment) * self.axes, axis=-1, keepdims=True) * self.axes
        carried_force = force - np.where(prismatic, along, 0.0)
        carried_moment = moment - np.where(prismatic, 0.0, along)
        loads = np.linalg.norm(carried_force, axis=-1) + np.linalg.norm(carried_moment, axis=-1) / self.span_m
        return loads.reshape(q.shape[:-1] + (self.model.nv,))
