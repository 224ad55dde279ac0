"""Propagation of joint deviations to the tool pose through Pinocchio kinematics."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import pinocchio as pin

from tribokin.fast_propagation import DEFAULT_TOLERANCE, tool_deviations_fast, truncation_bound, \
    tool_twists
from tribokin.robot import Robot


def tool_deviations_exact(robot: Robot, q: np.ndarray, dq: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Tool poses by exact forward kinematics, one Pinocchio call per sample (the reference engine).

    Args:
        robot: the robot; its active joints are all 1-DoF, so q + dq is the configuration reached.
        q: (nq,) commanded configuration [m or rad].
        dq: (n, nv) joint deviations of each cycle [m or rad].

    Returns:
        positions (n, 3) of the tool frame in the world frame [m], and orientation
        deviations (n, 3) [rad]: the rotation vector ``log3(R_j R_c^T)`` from the
        commanded orientation R_c (at ``q``) to the reached one, in world axes.
    """
    model, data, frame = robot.model, robot.data, robot.tool_frame_id
    commanded_rotation = robot.tool_placement(q).rotation
    positions = np.empty((len(dq), 3))
    angles = np.empty((len(dq), 3))
    for j, q_reached in enumerate(np.asarray(q, dtype=float) + dq):
        pin.forwardKinematics(model, data, q_reached)
        placement = pin.updateFramePlacement(model, data, frame)
        positions[j] = placement.translation
        angles[j] = pin.log3(placement.rotation @ commanded_rotation.T)
    return positions, angles



def tool_deviations(robot: Robot, q: np.ndarray, dq: np.ndarray, engine: str = "fast"):
    """Tool positions [m] and orientation deviations [rad] of each cycle.

    ``engine = "fast"``: the truncated product of exponentials
    (:mod:`tribokin.fast_propagation`), unless its truncation bound exceeds
    ``DEFAULT_TOLERANCE`` (deviations far beyond friction's), then the exact engine.
    ``engine = "exact"``: one Pinocchio forward-kinematics call per cycle.
    """
    if engine == "fast":
        fast = tool_deviations_fast(robot, q, dq)
        if fast.bound.position_m <= DEFAULT_TOLERANCE and fast.bound.angle_rad <= DEFAULT_TOLERANCE:
            return fast.positions, fast.angles
    return tool_deviations_exact(robot, q, dq)


class ExactDiscrepancy(NamedTuple):
    """Largest difference between the fast and the exact engine on checked samples.

    Attributes:
        position_m: max over samples of |fast - exact| tool position [m].
        angle_rad: max over samples of |fast - exact| rotation vector [rad].
        samples: number of samples compared.
    """

    position_m: float
    angle_rad: float
    samples: int


def max_deviation_from_exact(robot: Robot, q: np.ndarray, dq: np.ndarray, m: int = 32,
                             tolerance_m: float = DEFAULT_TOLERANCE, tolerance_rad: float = DEFAULT_TOLERANCE
                             ) -> ExactDiscrepancy:
    """Check the fast engine against exact Pinocchio FK on the first ``m`` samples of a batch.

    The fast engine runs at the order it would choose for the whole batch.

    Args:
        robot, q, dq: as for :func:`tool_deviations_fast` (``dq`` is the whole batch).
        m: number of samples to check.
        tolerance_m, tolerance_rad: as for :func:`tool_deviations_fast`.

    Returns:
        the largest position [m] and rotation-vector [rad] differences, and the sample count.
    """
    dq = np.asarray(dq, dtype=float)
    order = truncation_bound(tool_twists(robot, q), dq, None, tolerance_m, tolerance_rad).order
    checked = dq[:m]
    fast = tool_deviations_fast(robot, q, checked, order=order)
    positions, angles = tool_deviations_exact(robot, q, checked)
    if not len(checked):
        return ExactDiscrepancy(0.0, 0.0, 0)
    return ExactDiscrepancy(float(np.linalg.norm(fast.positions - positions, axis=1).max()),
                            float(np.linalg.norm(fast.angles - angles, axis=1).max()), len(checked))
