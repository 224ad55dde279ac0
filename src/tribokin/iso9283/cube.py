"""The ISO 9283 test cube placed on a robot: P1-P5 as joint configurations, and their approach directions."""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from tribokin.compiled import use_compiled
from tribokin.iso9283.metrics import cube_test_positions
from tribokin.kinematics.ik import solve_ik_with_restarts
from tribokin.kinematics.robot import Robot
from tribokin.streams import posture_search

#: Cartesian approach directions of a cube pose, each followed by its opposite: label -> the tool's
#: direction of travel along the world axes. Unidirectional tests use the + ones (ISO 9283's three
#: directions for vAP), bidirectional and random tests all six.
APPROACH_DIRECTIONS = {f"{sign}{axis}": sign_value * row for axis, row in zip("xyz", np.eye(3), strict=True)
                       for sign, sign_value in (("+", 1.0), ("-", -1.0))}
#: The six approach directions' unit vectors, in the order of :data:`APPROACH_DIRECTIONS`.
APPROACH_VECTORS = tuple(APPROACH_DIRECTIONS.values())


class UnreachableCube(ValueError):
    """No cube with all of P1-P5 reachable: the message names the first pose out of reach (a study adds its file
    and key)."""


@dataclass(frozen=True)
class CubePose:
    """One ISO test pose: name, target position [m], configuration ``q`` and the joints' approach signs
    (6, nv), one row per :data:`APPROACH_DIRECTIONS`."""

    name: str
    position_m: np.ndarray
    q: np.ndarray
    approach_signs: np.ndarray


def position_manipulability(robot: Robot, q) -> float:
    """Yoshikawa manipulability sqrt(det(J J^T)) of the tool position [m^3 per unit^3]."""
    jacobian = robot.tool_jacobian(q)[:3]
    return float(np.sqrt(max(np.linalg.det(jacobian @ jacobian.T), 0.0)))


def candidate_postures(robot: Robot, samples: int = 256, keep: int = 4) -> list[np.ndarray]:
    """Well-conditioned working postures, best first: the reference posture and random
    postures within the limits (:func:`~tribokin.streams.posture_search`), ranked by the manipulability of the tool
    position."""
    rng = posture_search()
    candidates = [robot.reference_q] + [robot.random_configuration(rng) for _ in range(samples)]
    scores = np.round([position_manipulability(robot, q) for q in candidates], 9)
    return [candidates[i] for i in np.argsort(-scores, kind="stable")[:keep]]


def joint_approach_signs(robot: Robot, q, directions=APPROACH_VECTORS) -> np.ndarray:
    """(m, nv) direction of travel of each joint when the tool approaches along each Cartesian direction.

    The joint velocities that move the tool along ``d`` (least-squares, ``pinv(J_position) d``)
    give the signs; a joint that does not move takes +1.
    """
    jacobian = robot.tool_jacobian(q)[:3]
    velocities = np.linalg.pinv(jacobian) @ np.asarray(directions).T
    signs = np.sign(np.round(velocities.T, 12))
    signs[signs == 0] = 1.0
    return signs


#: A joint turning slower than this fraction of the fastest joint on an approach does not move there (sign 0).
STILL_RTOL = 1e-9
#: A tool Jacobian is of full rank where its smallest singular value exceeds this (:func:`holds_orientation`).
RANK_TOLERANCE = 1e-6


def held_approach_signs(robot: Robot, q, directions) -> np.ndarray:
    """(m, nv) direction of travel of each joint (+1, -1, or 0 for a joint that does not move) when the tool
    point approaches ``q``'s position along each unit direction (m, 3) of the world frame.

    The joint velocities are the least-norm ones that move the tool point along ``d`` while holding the tool's
    orientation (``pinv(J) [d, 0]``, J the 6-row tool Jacobian) where the robot can (:func:`holds_orientation`),
    else along ``d`` alone (``pinv(J_position) d``). A joint that does not move keeps sign 0: it adds no lost
    motion on that approach (unlike :func:`joint_approach_signs`, which the simulated cube uses).
    """
    return approach_signs_from_jacobians(robot.tool_jacobian(q)[None], directions)[0]


def approach_signs_from_jacobians(jacobians: np.ndarray, directions) -> np.ndarray:
    """:func:`held_approach_signs` of (k, 6, nv) tool Jacobians: (k, m, nv). Compiled where
    :func:`~tribokin.compiled.use_compiled`, for the Jacobians surely of full rank (:func:`surely_full_rank`); the
    others, and all on the NumPy path, by :func:`_approach_signs`."""
    directions = np.atleast_2d(np.asarray(directions, dtype=float))
    if jacobians.shape[2] < 6 or not use_compiled():
        return _approach_signs(jacobians, directions)
    from tribokin.iso9283.cube_kernels import held_signs

    signs, sure = held_signs(np.ascontiguousarray(jacobians, dtype=float), np.ascontiguousarray(directions),
                             (2 * RANK_TOLERANCE) ** 2, STILL_RTOL)
    signs = np.swapaxes(signs, 1, 2)  # laid out as the NumPy path's: the einsums summing over them round alike
    if not sure.all():
        signs[~sure] = _approach_signs(jacobians[~sure], directions)
    return signs


def _approach_signs(jacobians: np.ndarray, directions: np.ndarray) -> np.ndarray:
    """:func:`approach_signs_from_jacobians` in NumPy, of unit ``directions`` (m, 3)."""
    holds = np.zeros(len(jacobians), dtype=bool)
    if jacobians.shape[2] >= 6:  # full rank, as holds_orientation decides (np.linalg.matrix_rank's tolerance)
        holds = surely_full_rank(jacobians)
        unsure = ~holds
        if unsure.any():
            holds[unsure] = np.sum(np.linalg.svd(jacobians[unsure], compute_uv=False) > RANK_TOLERANCE, axis=-1) == 6
    velocities = np.empty((len(jacobians), jacobians.shape[2], len(directions)))
    if holds.any():  # pinv(J) = Jᵀ (J Jᵀ)⁻¹ at full row rank
        held = jacobians[holds]
        square = held @ np.swapaxes(held, 1, 2)
        moves = np.vstack([directions.T, np.zeros((3, len(directions)))])
        moves = np.broadcast_to(moves, (len(held), *moves.shape))
        velocities[holds] = np.swapaxes(held, 1, 2) @ np.linalg.solve(square, moves)
    if not holds.all():
        velocities[~holds] = np.linalg.pinv(jacobians[~holds, :3]) @ directions.T
    velocities = np.swapaxes(velocities, 1, 2)
    still = np.abs(velocities) <= STILL_RTOL * np.abs(velocities).max(axis=2, keepdims=True)
    return np.where(still, 0.0, np.sign(velocities))


def surely_full_rank(jacobians: np.ndarray) -> np.ndarray:
    """(k,) where (k, 6, nv) tool Jacobians are surely of full rank (smallest singular value above
    ``RANK_TOLERANCE``), without their SVD: det(J Jᵀ) = Π σ_i² and every σ_i² <= tr(J Jᵀ), so σ_6² >= det / tr⁵;
    sure where that bound exceeds twice the tolerance, squared (the LU determinant's rounding is far within the
    factor 4 there). Elsewhere (False) the SVD decides."""
    square = jacobians @ np.swapaxes(jacobians, 1, 2)
    trace = np.trace(square, axis1=1, axis2=2)
    return np.linalg.det(square) > (2 * RANK_TOLERANCE) ** 2 * trace ** 5


#: A direction label written as three signed decimal numbers, e.g. ``+0.58-0.58+0.58``.
VECTOR_LABEL = re.compile(r"^([+-]\d+(?:\.\d*)?)([+-]\d+(?:\.\d*)?)([+-]\d+(?:\.\d*)?)$")
#: Joint-space approach labels: every joint travelling forwards or backwards.
JOINT_SPACE_SIGNS = {"+": 1.0, "-": -1.0}


def approach_vector(label: str) -> np.ndarray | None:
    """The unit direction of the world frame a Cartesian approach label names (``+x``, ``-z``, or three signed
    numbers such as ``+0.58+0.58+0.58``, normalised), else None."""
    if label in APPROACH_DIRECTIONS:
        return APPROACH_DIRECTIONS[label]
    match = VECTOR_LABEL.match(label)
    if match is None:
        return None
    vector = np.array([float(v) for v in match.groups()])
    norm = np.linalg.norm(vector)
    return vector / norm if norm > 0 else None


def known_approach(label: str) -> bool:
    """Whether :func:`label_approach_signs` knows the approach ``label`` names."""
    return label in JOINT_SPACE_SIGNS or approach_vector(label) is not None


def label_approach_signs(robot: Robot, q, label: str) -> np.ndarray | None:
    """(nv,) the joints' approach signs of a direction label: ``+``/``-`` every joint forwards/backwards (joint
    space); a Cartesian label (:func:`approach_vector`) the tool point approached along it with the tool's
    orientation held (:func:`held_approach_signs`); None for any other label (an unknown approach)."""
    if label in JOINT_SPACE_SIGNS:
        return np.full(robot.model.nv, JOINT_SPACE_SIGNS[label])
    vector = approach_vector(label)
    return None if vector is None else held_approach_signs(robot, q, vector)[0]


def holds_orientation(robot: Robot, q) -> bool:
    """Whether the robot can move its tool in all 6 directions at ``q`` (full-rank Jacobian)."""
    return robot.model.nv >= 6 and np.linalg.matrix_rank(robot.tool_jacobian(q), tol=RANK_TOLERANCE) == 6


def _solve_cube(robot, center, side, rotation, start, rng, position_only):
    """Poses P1-P5 of one cube, or the first unreachable one as (name, position, IK result)."""
    poses = []
    for name, position in cube_test_positions(center, side).items():
        result = solve_ik_with_restarts(robot, pin.SE3(rotation, position), start, rng, position_only=position_only)
        if not result.success:
            return None, (name, position, result)
        poses.append(CubePose(name, position, result.q, joint_approach_signs(robot, result.q)))
    return poses, None


def place_cube(robot: Robot, center_m=None, side_m: float | None = None, rpy_deg=None,
               rng: np.random.Generator | None = None) -> tuple[list[CubePose], dict]:
    """Solve P1-P5 of the ISO cube by IK, with the tool held at one orientation.

    Defaults: centre at the tool position of a well-conditioned posture (see
    :func:`candidate_postures`), orientation the tool's there, side the largest of
    0.4, 0.3, 0.2, 0.1, 0.05 m with all five poses reachable. A robot that cannot
    hold its tool's orientation everywhere (fewer than 6 independent joints) is
    solved for position only. An unreachable pose is an :class:`UnreachableCube` naming it.

    Returns:
        the five poses and the cube actually used (``center_m``, ``side_m``, ``rpy_deg``,
        ``orientation_held``).
    """
    rng = rng or posture_search()
    sides = [side_m] if side_m is not None else [0.4, 0.3, 0.2, 0.1, 0.05]
    failure = None
    for start in candidate_postures(robot, keep=1 if center_m is not None else 4):
        home = robot.tool_placement(start)
        center = home.translation.copy() if center_m is None else np.asarray(center_m, dtype=float)
        rotation = home.rotation.copy() if rpy_deg is None else pin.rpy.rpyToMatrix(*np.radians(rpy_deg))
        position_only = not holds_orientation(robot, start)
        if center_m is not None:
            start = solve_ik_with_restarts(robot, pin.SE3(rotation, center), start, rng, position_only=position_only).q
        for side in sides:
            poses, failure = _solve_cube(robot, center, side, rotation, start, rng, position_only)
            if poses is not None:
                rpy = np.degrees(pin.rpy.matrixToRpy(rotation)).tolist()
                return poses, {"center_m": center.tolist(), "side_m": side, "rpy_deg": rpy,
                               "orientation_held": not position_only}
    name, position, result = failure
    raise UnreachableCube(f"ISO pose {name} at {np.round(position, 4).tolist()} m is unreachable with this tool "
                          f"orientation within the joint limits (closest {result.position_error_m * 1e3:.3g} mm); "
                          "move or shrink the cube")
