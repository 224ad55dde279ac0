"""Bearing loads of each joint from Pinocchio statics (RNEA with the robot at rest).

With the robot static, ``pin.rnea(model, data, q, 0, 0)`` fills ``data.f[i]``:
the wrench (force F [N], moment M [N·m] about the joint origin) that joint i
transmits to its subtree — gravity of every body it carries plus the payload —
in the joint frame; ``a`` is the joint's unit motion axis and ``L`` its
bearing span [m].

Free body of the subtree: split F into its axial part ``F_a = (F·a) a`` and
radial part ``F_r = F - F_a``, and M into its part about the axis
``M_a = (M·a) a`` and the tilting moment ``M_t = M - M_a``. Two supports at
``p± = ±(L/2) a`` take radial forces ``R±`` (⊥ a); the rest of the joint takes
F_a and M_a at the origin. Equilibrium of the subtree::

    R+ + R- = F_r                                  (forces)
    p+ × R+ + p- × R- = (L/2) a × (R+ - R-) = M_t  (moments about the origin)

Crossing the second with ``a`` (``a × (a × D) = -D`` for D ⊥ a) gives
``R+ - R- = (2/L) M_t × a``, so::

    R± = F_r / 2 ± (M_t × a) / L

The load that makes friction is the sum of the contact forces' magnitudes:

* revolute joint: two radial bearings at ±L/2 along the axis, a thrust bearing
  carrying F_a, the drive carrying M_a::

      N = |F_a| + |R+| + |R-|   (>= |F_a| + max(|F_r|, 2 |M_t| / L))

* prismatic joint: two carriages at ±L/2 along the rail, the drive carrying
  F_a. The carriages' R± carry F_r and the pitch and yaw moments M_t; the roll
  moment M_a cannot be carried by two points on the rail and needs a second
  span, the carriages' width across the rail. The study gives one span per
  joint, so the width is taken equal to L: roll adds a couple of two pad
  forces |M_a| / L each::

      N = |R+| + |R-| + 2 |M_a| / L

Summing magnitudes ignores that forces meeting on one pad may partly cancel.
The moment terms are what make friction, and so repeatability, depend on where
the robot is.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from tribokin.compiled import use_compiled
from tribokin.kinematics.chain import serial_chain
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
        self.configuration = robot.configuration  # Pinocchio's configuration of tribokin's q (the same joints)
        self.prismatic = np.ascontiguousarray(robot.joint_is_prismatic)  # contiguous, as the compiled path takes them
        self.span_m = np.broadcast_to(np.asarray(bearing_span_m, dtype=float), self.prismatic.shape).copy()
        self.axes = np.ascontiguousarray(robot.motion_axes, dtype=float)
        self.chain = serial_chain(robot)
        inertias = list(self.model.inertias)[1:]
        self.weights_N = np.array([i.mass for i in inertias])[:, None] * self.model.gravity.linear  # (nv, 3)
        self.centres_m = np.array([i.lever for i in inertias])  # (nv, 3) in each body's joint frame

    def wrenches(self, q) -> np.ndarray:
        """(nv, 6) static wrench (force [N], moment [N·m]) transmitted by each active joint, in its joint frame."""
        zero = np.zeros(self.model.nv)
        pin.rnea(self.model, self.data, self.configuration(q), zero, zero)
        return np.array([self.data.f[i].vector for i in range(1, self.model.njoints)])

    def chain_wrenches(self, q: np.ndarray, placements: np.ndarray | None = None) -> np.ndarray:
        """(k, nv, 6) :meth:`wrenches` at configurations (k, nv) of a serial chain, in one pass: joint i holds up the
        weights w_j of bodies j >= i, f_i = -Σ w_j and m_i = -Σ (c_j - o_i) × w_j in world axes (c_j the bodies'
        centres of mass, o_i the joint's origin), turned into joint i's frame; from the configurations' ``placements``
        (the chain's :meth:`~tribokin.kinematics.chain.SerialChain.tool_in_joint`) when given."""
        if placements is None:
            placements = self.chain.tool_in_joint(q)
        frames = self.chain.joints_in_world(placements)  # (k, nv, 4, 4)
        rotations, origins = frames[..., :3, :3], frames[..., :3, 3]
        centres = origins + (rotations @ self.centres_m[..., None])[..., 0]
        forces = -np.cumsum(self.weights_N[::-1], axis=0)[::-1]  # (nv, 3): the same at every configuration
        moments_about_world = -np.cumsum(np.cross(centres, self.weights_N)[:, ::-1], axis=1)[:, ::-1]
        moments = moments_about_world - np.cross(origins, forces)
        local = np.swapaxes(rotations, -1, -2)
        return np.concatenate([(local @ forces[..., None])[..., 0], (local @ moments[..., None])[..., 0]], axis=-1)

    def __call__(self, q, placements: np.ndarray | None = None) -> np.ndarray:
        """Bearing load N_i [N] of every active joint at configuration ``q`` (nv,), or (poses, nv) at
        configurations (poses, nv): for a serial chain (:func:`~tribokin.kinematics.chain.serial_chain`) from one
        batched statics pass (:meth:`chain_wrenches`, RNEA's to rounding; ``placements``: its ``tool_in_joint`` at
        the configurations, if already computed; compiled where :func:`~tribokin.compiled.use_compiled`), else by
        RNEA at each."""
        q = np.asarray(q, dtype=float)
        flat = q.reshape(-1, q.shape[-1])
        if self.chain is not None and use_compiled():
            from tribokin.kinematics.loads_kernels import chain_loads

            if placements is None:
                placements = self.chain.tool_in_joint(flat)
            loads = chain_loads(np.ascontiguousarray(placements, dtype=float), self.weights_N, self.centres_m,
                                self.axes, self.prismatic, self.span_m)
            return loads.reshape(q.shape[:-1] + (self.model.nv,))
        if self.chain is not None:
            wrenches = self.chain_wrenches(flat, placements)
        else:
            wrenches = np.array([self.wrenches(qi) for qi in flat]).reshape(-1, self.model.nv, 6)
        loads = support_loads(wrenches[..., :3], wrenches[..., 3:], self.axes, self.prismatic, self.span_m)
        return loads.reshape(q.shape[:-1] + (self.model.nv,))


def _along(vectors: np.ndarray, axes: np.ndarray) -> np.ndarray:
    """The part of ``vectors`` (..., 3) along the unit ``axes`` (..., 3)."""
    return np.sum(vectors * axes, axis=-1, keepdims=True) * axes


def support_forces(force, moment, axes, span_m) -> tuple[np.ndarray, np.ndarray]:
    """Radial forces R+ and R- [N] (..., 3) of the two supports at +-(L/2) a that carry the radial force and the
    tilting moment of the wrench (``force`` [N], ``moment`` [N·m] about the joint origin, (..., 3)) about the unit
    ``axes`` a (..., 3), with span ``span_m`` L (...) [m]: ``R± = F_r / 2 ± (M_t × a) / L``."""
    force, moment, axes = (np.asarray(v, dtype=float) for v in (force, moment, axes))
    radial = force - _along(force, axes)
    couple = np.cross(moment - _along(moment, axes), axes) / np.asarray(span_m, dtype=float)[..., None]
    return radial / 2 + couple, radial / 2 - couple


def support_loads(force, moment, axes, prismatic, span_m) -> np.ndarray:
    """Bearing load N [N] (...) of joints transmitting ``force`` [N] and ``moment`` [N·m] (..., 3) about the unit
    ``axes`` (..., 3): ``|F_a| + |R+| + |R-|`` for a revolute joint, ``|R+| + |R-| + 2 |M_a| / L`` for a prismatic
    one (``prismatic`` (...) bool), with span ``span_m`` L (...) [m] (module docstring)."""
    force, moment = np.asarray(force, dtype=float), np.asarray(moment, dtype=float)
    plus, minus = support_forces(force, moment, axes, span_m)
    axial_force = np.linalg.norm(_along(force, axes), axis=-1)
    roll = 2 * np.linalg.norm(_along(moment, axes), axis=-1) / np.asarray(span_m, dtype=float)
    return np.linalg.norm(plus, axis=-1) + np.linalg.norm(minus, axis=-1) + np.where(prismatic, roll, axial_force)
