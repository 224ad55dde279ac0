"""The tool frame's placement and Jacobian at many configurations at once, for a robot's serial chain: in NumPy, or
compiled (:mod:`tribokin.kinematics.chain_kernels`) when :func:`tribokin.compiled.use_compiled` says so.

The reduced models of :mod:`tribokin.kinematics.robot` are serial chains of 1-DoF joints. When every joint turns about
or slides along a fixed axis of its own frame (Pinocchio's RX, RY, RZ, RevoluteUnaligned, their continuous RUBX, RUBY,
RUBZ, RevoluteUnboundedUnaligned, and PX, PY, PZ, PrismaticUnaligned), :func:`serial_chain` gives the chain's constants,
:meth:`SerialChain.tool_in_joint` the tool frame's placement (Pinocchio's ``forwardKinematics`` and
``updateFramePlacement``) and :meth:`SerialChain.tool_jacobians` its Jacobian (``getFrameJacobian``) for a batch of
configurations, as Pinocchio gives them one configuration at a time (to rounding, about 1e-15). For any other joint type
(a helical joint, a mimic joint) :func:`serial_chain` gives ``None``, and callers keep Pinocchio's one-configuration
path.

Each link of the chain is a homogeneous transform (4 × 4): joint ``i``'s placement in its parent's frame times its
motion, ``base + cos(q_i)·turn_cos + sin(q_i)·turn_sin + q_i·slide`` (Rodrigues' formula for a turning joint, a
translation along the axis for a sliding one; a continuous joint's ``q_i`` is its angle, tribokin's value), and last the
tool frame's placement in the last joint's frame. The products of the links from each joint to the tool
(``tool_in_joint``) give both the tool's placement (from the first) and each joint's column of the tool Jacobian, in a
few batched matrix products (a doubling scan; the compiled kernels take them one at a time, a difference of rounding).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import pinocchio as pin

from tribokin.compiled import use_compiled
from tribokin.kinematics.robot import Robot

#: Pinocchio joint models whose motion is a rotation about, or a translation along, a fixed axis of their frame.
AXIS_JOINTS = frozenset({"JointModelRX", "JointModelRY", "JointModelRZ", "JointModelRevoluteUnaligned",
                         "JointModelRUBX", "JointModelRUBY", "JointModelRUBZ", "JointModelRevoluteUnboundedUnaligned",
                         "JointModelPX", "JointModelPY", "JointModelPZ", "JointModelPrismaticUnaligned"})


def _kernels():
    """:mod:`tribokin.kinematics.chain_kernels` on the compiled path (imported then), else ``None``."""
    if not use_compiled():
        return None
    from tribokin.kinematics import chain_kernels

    return chain_kernels


@dataclass(frozen=True)
class SerialChain:
    """A serial chain of ``n`` axis joints (:data:`AXIS_JOINTS`) and the tool frame, as ``n + 1`` links
    ``base + cos(q)·turn_cos + sin(q)·turn_sin + q·slide`` (4 × 4 each; the tool's with ``q = 0``).

    Attributes:
        robot: the robot whose chain this is.
        base, turn_cos, turn_sin, slide: (n + 1, 4, 4) the links' terms [m in the translations].
        turn_skews: (n, 3, 3) ``[axis]×`` of each turning joint in its own frame (zero for a sliding one).
        slide_axes: (n, 3) unit axis of each sliding joint in its own frame (zero for a turning one).
        turn_axes: (n, 3) unit axis of each turning joint in its own frame (zero for a sliding one).
    """

    robot: Robot
    base: np.ndarray
    turn_cos: np.ndarray
    turn_sin: np.ndarray
    slide: np.ndarray
    turn_skews: np.ndarray
    slide_axes: np.ndarray
    turn_axes: np.ndarray

    def tool_in_joint(self, q) -> np.ndarray:
        """(k, n + 1, 4, 4) the tool frame's placement (homogeneous, [m]) in the world frame (index 0: as
        ``robot.tool_placement``) and in each joint's frame after its motion (index ``i + 1`` for joint ``i``), at
        configurations ``q`` (k, nv) [m or rad]."""
        q = np.asarray(q, dtype=float).reshape(-1, len(self.turn_axes))
        if kernels := _kernels():
            return kernels.tool_in_joint(np.ascontiguousarray(q), self.kernel_terms)
        links = self._links(q)
        step = 1
        while step < len(self.base):  # links[:, i] becomes the product of links i to i + 2 step - 1 (or the last)
            links[:, :-step] = links[:, :-step] @ links[:, step:]
            step *= 2
        return links

    def tool_in_world(self, q) -> np.ndarray:
        """(k, 4, 4) the tool frame's placement (homogeneous, [m]) in the world at configurations ``q`` (k, nv)
        [m or rad]: :meth:`tool_in_joint`'s index 0 to rounding, the product of the links from the base to the tool
        only (measured on the UR5 and Panda: 0.5-0.6 of :meth:`tool_in_joint`'s time in NumPy, 0.4 compiled)."""
        q = np.asarray(q, dtype=float).reshape(-1, len(self.turn_axes))
        if kernels := _kernels():
            return kernels.tool_in_world(np.ascontiguousarray(q), self.kernel_terms)
        links = self._links(q)
        placements = links[:, 0]
        for link in range(1, len(self.base)):
            placements = placements @ links[:, link]
        return placements

    def _links(self, q: np.ndarray) -> np.ndarray:
        """(k, n + 1, 4, 4) the links at configurations ``q`` (k, nv) [m or rad]: ``base + cos(q)·turn_cos +
        sin(q)·turn_sin + q·slide``, the tool's at ``q = 0``."""
        angles = np.zeros((len(q), len(self.base)))
        angles[:, :-1] = q
        base, terms = self._link_terms
        links = np.empty((len(q), *base.shape))
        links[:] = base
        for factor, term in terms:  # in rows of 16
            links += (np.cos(angles) if factor == "cos" else np.sin(angles) if factor == "sin" else angles)[..., None] \
                * term
        return links.reshape(len(q), len(self.base), 4, 4)

    @cached_property
    def kernel_terms(self) -> tuple[np.ndarray, ...]:
        """The chain's arrays the compiled kernels take (:mod:`tribokin.kinematics.chain_kernels`), C-contiguous:
        ``base``, ``turn_cos``, ``turn_sin``, ``slide``, ``turn_skews``, ``slide_axes``, ``turn_axes``."""
        return tuple(np.ascontiguousarray(term, dtype=float) for term in (
            self.base, self.turn_cos, self.turn_sin, self.slide, self.turn_skews, self.slide_axes, self.turn_axes))

    @cached_property
    def _link_terms(self) -> tuple[np.ndarray, tuple[tuple[str, np.ndarray], ...]]:
        """The links' terms as (n + 1, 16) rows, for :meth:`tool_in_joint`: ``base``, and ``(factor, term)`` for
        ``turn_cos``, ``turn_sin``, ``slide`` (factor ``"cos"``, ``"sin"``, ``"q"``) except those that are zero
        throughout. A zero term adds ±0, which changes no partial sum unless one is -0, and none is unless ``base``
        holds a -0: then every term is kept."""
        rows = len(self.base), 16
        negative_zero = bool(np.any((self.base == 0) & np.signbit(self.base)))
        terms = zip(("cos", "sin", "q"), (self.turn_cos, self.turn_sin, self.slide), strict=True)
        return self.base.reshape(rows), tuple((factor, term.reshape(rows)) for factor, term in terms
                                              if negative_zero or term.any())

    def tool_jacobians(self, placements: np.ndarray) -> np.ndarray:
        """(k, 6, nv) Jacobians of the tool frame in the tool frame (Pinocchio's ``LOCAL``: rows linear [m/unit],
        angular [rad/unit]) at the configurations whose :meth:`tool_in_joint` are ``placements``."""
        if kernels := _kernels():
            return kernels.tool_jacobians(np.ascontiguousarray(placements), self.kernel_terms)
        in_joints = placements[:, 1:]
        linear = (self.turn_skews @ in_joints[..., :3, 3:])[..., 0] + self.slide_axes  # the tool's velocity per unit
        motions = np.stack([linear, np.broadcast_to(self.turn_axes, linear.shape)], axis=-1)  # (k, n, 3, 2)
        in_tool = np.swapaxes(in_joints[..., :3, :3], -1, -2) @ motions
        return in_tool.transpose(0, 3, 2, 1).reshape(len(placements), 6, len(self.turn_axes))

    def world_jacobians(self, placements: np.ndarray) -> np.ndarray:
        """(k, 6, nv) the tool Jacobians of :meth:`tool_jacobians` in world axes (Pinocchio's ``LOCAL_WORLD_ALIGNED``,
        as ``robot.tool_jacobian``)."""
        if kernels := _kernels():
            return kernels.world_jacobians(np.ascontiguousarray(placements), self.kernel_terms)
        local = self.tool_jacobians(placements)
        rotation = placements[:, 0, :3, :3]
        return np.concatenate([rotation @ local[:, :3], rotation @ local[:, 3:]], axis=1)

    @staticmethod
    def joints_in_world(placements: np.ndarray) -> np.ndarray:
        """(k, n, 4, 4) each joint frame's placement in the world after its motion (as ``data.oMi``), from the
        :meth:`tool_in_joint` ``placements``: the tool's in the world times the inverse of the tool's in the joint."""
        if kernels := _kernels():
            return kernels.joints_in_world(np.ascontiguousarray(placements))
        in_joint = placements[:, 1:]
        inverse = np.zeros_like(in_joint)
        rotation_t = np.swapaxes(in_joint[..., :3, :3], -1, -2)
        inverse[..., :3, :3] = rotation_t
        inverse[..., :3, 3] = -(rotation_t @ in_joint[..., :3, 3:])[..., 0]
        inverse[..., 3, 3] = 1.0
        return placements[:, :1] @ inverse


def serial_chain(robot: Robot) -> SerialChain | None:
    """The :class:`SerialChain` of ``robot``, or ``None`` when a joint is not an axis joint (:data:`AXIS_JOINTS`) or the
    joints are not one chain, in the order of ``q``, that carries the tool frame on its last joint; built at the first
    call and kept on ``robot`` (a map asks for it at every row; ``benchmarks/startup.py`` times building it)."""
    if "_serial_chain" not in robot.__dict__:
        robot.__dict__["_serial_chain"] = _build_serial_chain(robot)
    return robot.__dict__["_serial_chain"]


def _build_serial_chain(robot: Robot) -> SerialChain | None:
    model = robot.model
    joints = list(model.joints)[1:]
    order = list(range(len(joints)))
    serial = list(model.parents)[1:] == order and [j.idx_v for j in joints] == order and \
        model.frames[robot.tool_frame_id].parentJoint == len(joints)
    if not serial or any(joint.shortname() not in AXIS_JOINTS for joint in joints):
        return None
    placements = [p.homogeneous for p in list(model.jointPlacements)[1:]]
    placements.append(model.frames[robot.tool_frame_id].placement.homogeneous)
    placements = np.array(placements)
    rotations = placements[:, :3, :3]
    turning = np.append(~robot.joint_is_prismatic, False)[:, None, None]
    sliding = np.append(robot.joint_is_prismatic, False)[:, None]
    axes = np.vstack([robot.motion_axes, np.zeros(3)])
    skews = np.array([pin.skew(axis) for axis in axes])
    outer = axes[:, :, None] * axes[:, None, :]
    terms = np.zeros((4, len(axes), 4, 4))  # base, turn_cos, turn_sin, slide
    terms[0] = placements
    terms[0, :, :3, :3] = np.where(turning, rotations @ outer, rotations)
    terms[1, :, :3, :3] = np.where(turning, rotations - rotations @ outer, 0.0)
    terms[2, :, :3, :3] = np.where(turning, rotations @ skews, 0.0)
    terms[3, :, :3, 3] = np.where(sliding, (rotations @ axes[..., None])[..., 0], 0.0)
    joint_turning = turning[:-1]
    return SerialChain(robot, *terms, np.where(joint_turning, skews[:-1], 0.0),
                       np.where(sliding[:-1], axes[:-1], 0.0), np.where(joint_turning[..., 0], axes[:-1], 0.0))
