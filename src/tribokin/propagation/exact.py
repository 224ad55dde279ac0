"""Propagation of joint deviations to the tool pose through Pinocchio kinematics."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import pinocchio as pin

from tribokin.kinematics.chain import serial_chain
from tribokin.kinematics.robot import Robot
from tribokin.kinematics.se3_log import log3
from tribokin.propagation.poe import (
    DEFAULT_TOLERANCE,
    TruncationBound,
    evaluate_polynomial,
    tool_twists,
    truncation_bound,
)

#: Samples per batched pass of exact FK (:func:`tool_deviations_exact`): its temporaries stay within a few MB
#: (the links, ``BLOCK`` × (nv + 1) × 16 floats: 1.8 MB for six joints) however many samples there are.
BLOCK = 2048


def tool_deviations_exact(robot: Robot, q: np.ndarray, dq: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Tool poses by exact forward kinematics (the reference engine): for a serial chain
    (:func:`~tribokin.kinematics.chain.serial_chain`) in batched passes of ``BLOCK`` samples, Pinocchio's to rounding
    (about 1e-15 m and rad); for any other robot one Pinocchio call per sample.

    Args:
        robot: the robot; its active joints are all 1-DoF, so q + dq is the configuration reached (for a continuous
            joint too: its angle, :meth:`~tribokin.kinematics.robot.Robot.configuration`).
        q: (nv,) commanded configuration [m or rad].
        dq: (n, nv) joint deviations of each cycle [m or rad].

    Returns:
        positions (n, 3) of the tool frame in the world frame [m], and orientation
        deviations (n, 3) [rad]: the rotation vector ``log3(R_j R_c^T)`` from the
        commanded orientation R_c (at ``q``) to the reached one, in world axes.
    """
    q, dq = np.asarray(q, dtype=float), np.asarray(dq, dtype=float)
    chain = serial_chain(robot)
    if chain is None:
        return tool_deviations_pinocchio(robot, q, dq)
    commanded_rotation = chain.tool_in_world(q)[0, :3, :3]
    positions, angles = np.empty((len(dq), 3)), np.empty((len(dq), 3))
    for start in range(0, len(dq), BLOCK):
        placements = chain.tool_in_world(q + dq[start:start + BLOCK])
        positions[start:start + BLOCK] = placements[:, :3, 3]
        rotations = placements[:, :3, :3].reshape(-1, 3) @ commanded_rotation.T  # the rows of each R_j R_c^T
        angles[start:start + BLOCK] = log3(rotations.reshape(-1, 3, 3))
    return positions, angles


def tool_deviations_pinocchio(robot: Robot, q: np.ndarray, dq: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`tool_deviations_exact` by one Pinocchio forward-kinematics call per sample: for a robot with no serial
    chain (and the reference loop ``benchmarks/propagation.py`` times the batched passes against)."""
    model, data, frame = robot.model, robot.data, robot.tool_frame_id
    commanded_rotation = robot.tool_placement(q).rotation
    positions = np.empty((len(dq), 3))
    angles = np.empty((len(dq), 3))
    for j, q_reached in enumerate(robot.configuration(q + dq)):
        pin.forwardKinematics(model, data, q_reached)
        placement = pin.updateFramePlacement(model, data, frame)
        positions[j] = placement.translation
        angles[j] = pin.log3(placement.rotation @ commanded_rotation.T)
    return positions, angles


def tool_deviations(robot: Robot, q: np.ndarray, dq: np.ndarray, engine: str = "fast"):
    """Tool positions [m] and orientation deviations [rad] of each cycle, (n, 3) each.

    ``engine = "fast"``: the truncated product of exponentials
    (:mod:`tribokin.propagation.poe`), unless its truncation bound exceeds
    ``DEFAULT_TOLERANCE`` (deviations far beyond friction's), then the exact engine.
    ``engine = "exact"``: exact forward kinematics for every cycle (:func:`tool_deviations_exact`).
    """
    q = np.asarray(q, dtype=float)
    twists, translations = tool_frames(robot, q[None])
    positions, angles = tool_deviations_at_poses(robot, q[None], np.asarray(dq, dtype=float)[None], engine,
                                                 twists, translations)
    return positions[0], angles[0]


def tool_frames(robot: Robot, qs: np.ndarray, placements: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Joint twists about the tool origin (poses, 6, nv) and tool positions (poses, 3) [m]
    at configurations (poses, nv);
    for a serial chain (:func:`~tribokin.kinematics.chain.serial_chain`) in one batched pass, Pinocchio's to rounding,
    from the configurations' ``placements`` (its :meth:`~tribokin.kinematics.chain.SerialChain.tool_in_joint`) when
    given."""
    chain = serial_chain(robot)
    if chain is not None:
        if placements is None:
            placements = chain.tool_in_joint(np.asarray(qs, dtype=float).reshape(-1, robot.model.nv))
        return chain.world_jacobians(placements), placements[:, 0, :3, 3].copy()
    return (np.array([tool_twists(robot, q) for q in qs]).reshape(len(qs), 6, robot.model.nv),
            np.array([robot.tool_placement(q).translation for q in qs]).reshape(len(qs), 3))


def engine_orders(twists: np.ndarray, dq: np.ndarray, engine: str = "fast", lowest_order: int = 1) -> TruncationBound:
    """The engine :func:`tool_deviations_at_poses` uses at each pose, and its bound over every sample of the pose.

    Args:
        twists: (poses, 6, nv) the poses' joint twists.
        dq: (poses, n, nv) deviations [m or rad].
        engine: ``"fast"``: the lowest truncation order from ``lowest_order`` on whose bound is within
            ``DEFAULT_TOLERANCE``, else exact FK; ``"exact"``: exact FK.
        lowest_order: the lowest truncation order ``"fast"`` may choose.

    Returns:
        (poses,) arrays: the order (0: exact FK) and its bounds [m, rad] on |engine - exact| (0 for exact FK).
    """
    if engine != "fast":
        return TruncationBound(np.zeros(len(twists), dtype=int), np.zeros(len(twists)), np.zeros(len(twists)))
    bound = truncation_bound(twists, dq, lowest_order=lowest_order)
    fast = (bound.position_m <= DEFAULT_TOLERANCE) & (bound.angle_rad <= DEFAULT_TOLERANCE)
    return TruncationBound(np.where(fast, bound.order, 0), np.where(fast, bound.position_m, 0.0),
                           np.where(fast, bound.angle_rad, 0.0))


def tool_deviations_at_poses(robot: Robot, qs: np.ndarray, dq: np.ndarray, engine: str, twists: np.ndarray,
                             translations: np.ndarray, used: TruncationBound | None = None
                             ) -> tuple[np.ndarray, np.ndarray]:
    """:func:`tool_deviations` at several poses at once; each pose's values depend on its own inputs only.

    Args:
        robot: the robot.
        qs: (poses, nv) commanded configurations.
        dq: (poses, n, nv) deviations [m or rad].
        engine: ``"fast"`` or ``"exact"`` (:func:`engine_orders`).
        twists: the poses' joint twists (:func:`tool_frames`).
        translations: the poses' tool positions (:func:`tool_frames`).
        used: the engine of each pose (:func:`engine_orders`), when already chosen.

    Returns:
        positions [m] and angles [rad], (poses, n, 3) each (views of (poses, 3, n) arrays).
    """
    poses, n = dq.shape[:2]  # outputs: (poses, n, 3) views of (poses, 3, n) memory, as the fast engine gives
    positions, angles = np.swapaxes(np.empty((poses, 3, n)), 1, 2), np.swapaxes(np.empty((poses, 3, n)), 1, 2)
    orders = np.atleast_1d((engine_orders(twists, dq, engine) if used is None else used).order)
    fast = orders > 0
    if fast.any():
        positions[fast], angles[fast] = evaluate_polynomial(twists[fast], translations[fast], dq[fast], orders[fast])
    for p in np.flatnonzero(~fast):
        positions[p], angles[p] = tool_deviations_exact(robot, qs[p], dq[p])
    return positions, angles


class EngineBound(NamedTuple):
    """The error bound of the engine :func:`tool_deviations` used for a batch of samples at one pose.

    Attributes:
        engine: ``"fast"`` (the truncated product of exponentials) or ``"exact"`` (exact FK for every sample).
        order: the fast engine's truncation order (0 for exact FK).
        position_m, angle_rad: its bound on |engine - exact| over every sample [m, rad] (0 for exact FK: rounding
            only, about 1e-15 m).
    """

    engine: str
    order: int
    position_m: float
    angle_rad: float


def engine_bound(robot: Robot, q: np.ndarray, dq: np.ndarray, engine: str = "fast") -> EngineBound:
    """The engine ``tool_deviations(robot, q, dq, engine)`` uses for every sample of ``dq`` (n, nv), and its bound."""
    used = engine_orders(tool_twists(robot, q)[None], np.asarray(dq, dtype=float)[None], engine)
    order = int(used.order[0])
    return EngineBound("fast" if order else "exact", order, float(used.position_m[0]), float(used.angle_rad[0]))
