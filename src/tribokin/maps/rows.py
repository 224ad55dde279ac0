"""The IK of a map's targets (:mod:`tribokin.maps.grid`), along grid rows and then into holes from neighbours.

Cartesian targets are solved by inverse kinematics,
warm-started from a neighbour in an order that does not depend on how the rows are later
split into chunks: the first target of every row (the *row heads*) is solved in one sequence
from the start posture (:func:`solve_row_starts`), then each row is solved along its columns
from where it starts, a chunk's rows together (:func:`solve_rows`). So a row's configurations depend on the grid only.
A row whose head is not reached starts from the last head reached before it, on the branch of the rows before.

A target beyond the robot's reach (``grid.reach``, :mod:`tribokin.kinematics.reach`: the tool point's sphere, and with
the tool's orientation held the last joint's) is unreachable without any IK iteration, a row head too. IK cannot reach
such a target anyway, so every other target is solved along the same path as without the bounds.
"""

from __future__ import annotations

import math
from collections import defaultdict

import numpy as np
import pinocchio as pin

from tribokin.kinematics.chain import SerialChain, serial_chain
from tribokin.kinematics.ik import IKResult, solve_ik, solve_ik_batch, solve_ik_with_restarts
from tribokin.kinematics.reach import ReachSphere
from tribokin.kinematics.robot import Robot, wrap_angles
from tribokin.maps.grid import TargetGrid, axis_steps, grid_neighbours
from tribokin.streams import ik_restart_stream

#: Random restarts of the IK after a warm start fails (each costs up to 200 iterations).
IK_RESTARTS = 4
#: Reached targets a row's warm start extrapolates from (a polynomial of one degree less): an error of the
#: order of the step to the fourth power, so one iteration usually converges on fine grids.
EXTRAPOLATION_POINTS = 4


def _rotation(grid: TargetGrid) -> np.ndarray:
    """(3, 3) the tool orientation IK is given for the grid's targets (the identity when it is not held)."""
    return np.eye(3) if grid.rotation is None else grid.rotation


def _target(grid: TargetGrid, index: int) -> pin.SE3:
    return pin.SE3(_rotation(grid), grid.positions_m([index])[0])


def _solve_from(robot: Robot, grid: TargetGrid, index: int, q_start) -> IKResult:
    """One IK solve of target ``index`` from ``q_start``, without restarts."""
    return solve_ik(robot, _target(grid, index), q_start, position_only=grid.rotation is None)


def _solve(robot: Robot, grid: TargetGrid, index: int, q_start, pinocchio: bool = False) -> IKResult:
    """IK of target ``index`` from ``q_start``, then from seeded random restarts (Pinocchio's path when
    ``pinocchio``, :func:`~tribokin.kinematics.ik.solve_ik`)."""
    return solve_ik_with_restarts(robot, _target(grid, index), q_start, lambda: ik_restart_stream(index),
                                  IK_RESTARTS, position_only=grid.rotation is None, pinocchio=pinocchio)


def first_bound_beyond(grid: TargetGrid, positions_m) -> tuple[np.ndarray, np.ndarray]:
    """Which bound of the robot's reach (``grid.reach``) refuses each target at ``positions_m`` (k, 3) [m] first:
    (k,) its index in ``grid.reach`` (-1: none) and how far [m] the point it bounds lies beyond it (NaN: none)."""
    positions = np.asarray(positions_m, dtype=float).reshape(-1, 3)
    gaps = np.array([sphere.beyond_m(sphere.bounded_points_m(positions, grid.rotation)) for sphere in grid.reach])
    refused = ~np.isnan(gaps)
    first = np.where(refused.any(axis=0), np.argmax(refused, axis=0), -1)
    return first, gaps[np.maximum(first, 0), np.arange(len(positions))]


def beyond_reach_m(grid: TargetGrid, indices) -> np.ndarray:
    """(k,) how far [m] Cartesian targets ``indices`` lie beyond the robot's reach (:func:`first_bound_beyond`),
    NaN for those within it (and every target of a joint grid)."""
    if not grid.reach:
        return np.full(len(indices), np.nan)
    return first_bound_beyond(grid, grid.positions_m(indices))[1]


def head_order(grid: TargetGrid) -> list[int]:
    """Grid rows in the order their heads are solved: row by row, each layer back and forth (a snake)."""
    layers, rows, _ = grid.shape
    order = []
    for layer in range(layers):
        sweep = range(rows) if layer % 2 == 0 else range(rows - 1, -1, -1)
        order += [layer * rows + row for row in sweep]
    return order


def solve_row_starts(robot: Robot, grid: TargetGrid) -> np.ndarray:
    """(rows, nv) where every grid row starts: its head (first target) solved from the last head reached before it
    in :func:`head_order` (the start posture for the first), or, for a head not reached (beyond the reach without
    any IK, :func:`beyond_reach_m`), that last head's configuration.

    On Pinocchio's path whatever the kernel path (:func:`~tribokin.kinematics.ik.solve_ik`'s ``pinocchio``), so that
    every row starts from the same bytes on both: a head solved from a distant head may pass near a singular
    configuration, where its path depends on every rounding."""
    if grid.kind == "joint":
        return grid.joint_q(np.arange(0, grid.size, grid.row_length))
    starts = np.empty((grid.row_count, robot.model.nv))
    beyond = ~np.isnan(beyond_reach_m(grid, np.arange(grid.row_count) * grid.row_length))
    q_start = grid.start_q
    for row in head_order(grid):
        if not beyond[row]:
            result = _solve(robot, grid, row * grid.row_length, q_start, pinocchio=True)
            if result.success:
                q_start = result.q
        starts[row] = q_start
    return starts


def extrapolate_rows(q: np.ndarray, streaks: np.ndarray, continuous: np.ndarray | None = None) -> np.ndarray:
    """Warm starts (rows, nv) [m or rad] for the next target of each row: the polynomial through the configurations
    ``q`` (rows, columns, nv) of the row's last reached targets, one step further. ``streaks`` (rows,): how many
    targets right before the next one were reached (up to ``EXTRAPOLATION_POINTS`` are used); NaN for the rows with
    fewer than two. ``continuous`` (nv,): joints whose angles (IK gives them in [-π, π]) are first unwrapped about the
    last target's, so a row crossing ±π extrapolates smoothly."""
    if continuous is not None and continuous.any() and q.shape[1]:
        q = np.where(continuous, q[:, -1:] + wrap_angles(q - q[:, -1:]), q)
    counts = np.minimum(streaks, EXTRAPOLATION_POINTS)
    if len(counts) and (counts == counts[0]).all() and counts[0] >= 2:  # every row alike (most columns): no masks
        return _polynomial_step(q, int(counts[0]))
    predicted = np.full((len(q), q.shape[2]), np.nan)
    for count in range(2, EXTRAPOLATION_POINTS + 1):
        rows = counts == count
        if rows.any():
            predicted[rows] = _polynomial_step(q[rows], count)
    return predicted


def _polynomial_step(q: np.ndarray, count: int) -> np.ndarray:
    """The polynomial through the last ``count`` configurations of each row of ``q`` (rows, columns, nv), one step
    further: sum over j of (-1)^(j+1) C(count, j) q[:, -j]."""
    return sum((-1) ** (j + 1) * math.comb(count, j) * q[:, -j] for j in range(1, count + 1))


def turned_into_limits(robot: Robot, q: np.ndarray) -> np.ndarray:
    """Warm starts ``q`` (k, nv) [m or rad] with the angle of each revolute joint whose limits span a whole turn or
    more (a UR arm's ±2π) turned by whole turns back within them when beyond (the same placements; the IK would
    clip it at the limit instead, and a row running into the limit would leave its branch for one rounding chose)."""
    lower, upper = robot.lower_limits, robot.upper_limits
    if not ((q > upper) | (q < lower)).any():  # none beyond its limits (NaN rows included): most columns
        return q
    multi_turn = ~robot.joint_is_prismatic & ~robot.continuous & (upper - lower >= 2 * math.pi)
    turns = np.where(q > upper, -np.ceil((q - upper) / (2 * math.pi)),
                     np.where(q < lower, np.ceil((lower - q) / (2 * math.pi)), 0.0))
    return np.where(multi_turn & (turns != 0), q + 2 * math.pi * turns, q)


def _solve_from_warm_starts(robot: Robot, chain: SerialChain | None, grid: TargetGrid, indices: np.ndarray,
                            positions_m: np.ndarray, q_starts: np.ndarray) -> IKResult:
    """IK of targets ``indices`` (k > 0) at ``positions_m`` (k, 3) [m] from ``q_starts`` (k, nv), without restarts:
    all at once (:func:`~tribokin.kinematics.ik.solve_ik_batch`) given the robot's ``chain``, else one by one."""
    if chain is None:
        results = [_solve_from(robot, grid, index, q) for index, q in zip(indices, q_starts, strict=True)]
        return IKResult(*(np.array([getattr(r, name) for r in results])
                          for name in ("q", "position_error_m", "angle_error_rad", "success")))
    return solve_ik_batch(chain, _rotation(grid), positions_m, q_starts, position_only=grid.rotation is None)


#: How the IK reached a target (a map's ``ik_route`` column; a joint map's targets need no IK: ``UNREACHED``): not
#: at all; warm-started along its row (:func:`extrapolate_rows`); from its row's last reached configuration (where
#: the row starts, first); after random restarts; from a reached neighbour's configuration
#: (:func:`fill_from_neighbours`).
UNREACHED, ALONG_ROW, FROM_LAST_REACHED, AFTER_RESTARTS, FROM_NEIGHBOUR = range(5)
#: The routes by the names ``summary.json`` counts them under.
IK_ROUTES = {"warm_started_along_row": ALONG_ROW, "from_last_reached": FROM_LAST_REACHED,
             "after_restarts": AFTER_RESTARTS, "from_neighbours": FROM_NEIGHBOUR}


def solve_rows(robot: Robot, grid: TargetGrid, rows, starts, batched: bool = True) -> tuple[np.ndarray, np.ndarray,
                                                                                             np.ndarray, np.ndarray]:
    """Configurations of grid rows ``rows``, each from where it starts (``starts`` (rows, nv) [m or rad],
    :func:`solve_row_starts`), column by column.

    Each target is warm-started from the polynomial through its row's last reached targets when two or more right
    before it were reached (:func:`extrapolate_rows`; a multi-turn joint's angle beyond a limit turned back within it,
    :func:`turned_into_limits`), the rows' targets of a column together
    (:func:`~tribokin.kinematics.ik.solve_ik_batch`; one by one when ``batched`` is False or NumPy cannot compute the
    robot's chain, :func:`~tribokin.kinematics.chain.serial_chain`); a target this does not solve is solved from its
    row's last reached configuration (where the row starts, first), then from seeded random restarts, one by one.
    A row's configurations depend on where it starts and the grid only, not on the other rows solved with it. Targets
    beyond the robot's reach are not solved (:func:`beyond_reach_m`).

    Returns:
        q (rows, columns, nv) [m or rad] (NaN where unreachable), reachable (rows, columns), and for unreachable
        targets how close the IK came (rows, columns, 2): position error [m], orientation error [rad] (NaN
        for reachable targets, and the orientation when it is not held; beyond the reach, how far beyond [m]
        the first bound that refuses it (:func:`first_bound_beyond`), and NaN), and how each was reached (rows,
        columns) (:data:`IK_ROUTES`).
    """
    indices = np.array([grid.row_indices(row) for row in rows], dtype=int).reshape(-1, grid.row_length)
    closest = np.full((*indices.shape, 2), np.nan)
    routes = np.full(indices.shape, UNREACHED, dtype=np.int8)
    if grid.kind == "joint":
        return (grid.joint_q(indices.ravel()).reshape(*indices.shape, -1), np.ones(indices.shape, dtype=bool), closest,
                routes)
    nv = robot.model.nv
    chain = serial_chain(robot) if batched else None
    positions = np.array([grid.positions_m(row) for row in indices]).reshape(*indices.shape, 3)  # row by row, as alone
    closest[..., 0] = [beyond_reach_m(grid, row) for row in indices]
    q = np.full((*indices.shape, nv), np.nan)
    reachable = np.zeros(indices.shape, dtype=bool)
    q_start = np.array(starts, dtype=float).reshape(len(indices), nv)
    streaks = np.zeros(len(indices), dtype=int)  # targets reached right before the column, in each row
    for column in range(grid.row_length):
        within = np.isnan(closest[:, column, 0])
        predicted = turned_into_limits(robot, extrapolate_rows(q[:, :column], streaks, robot.continuous))
        warm = np.flatnonzero(within & ~np.isnan(predicted[:, 0]))
        if len(warm):
            first = _solve_from_warm_starts(robot, chain, grid, indices[warm, column], positions[warm, column],
                                            predicted[warm])
            reached = warm[first.success]
            reachable[reached, column], routes[reached, column] = True, ALONG_ROW
            q[reached, column] = q_start[reached] = first.q[first.success]
        for row in np.flatnonzero(within & ~reachable[:, column]):  # from its last reached target, then restarts
            result = _solve(robot, grid, indices[row, column], q_start[row])
            reachable[row, column] = result.success
            if result.success:
                q[row, column] = q_start[row] = result.q
                routes[row, column] = AFTER_RESTARTS if result.restarts else FROM_LAST_REACHED
            else:
                closest[row, column] = result.position_error_m, np.nan if grid.rotation is None else \
                    result.angle_error_rad
        streaks = np.where(reachable[:, column], streaks + 1, 0)
    return q, reachable, closest, routes


#: Targets whose reachable flags are scanned at once when looking for holes beside reached targets.
SCAN_TARGETS = 1 << 16


def holes_beside_reached(grid: TargetGrid, read) -> list[int]:
    """Unreachable targets with a reached neighbour, in increasing order; ``read("reachable", slice)``
    gives the flags, read in blocks of ``SCAN_TARGETS`` (and the neighbours either side)."""
    strides = axis_steps(grid.shape)
    reach = max(step for size, step in strides if size > 1) if grid.size > 1 else 0
    holes = []
    for first in range(0, grid.size, SCAN_TARGETS):
        indices = np.arange(first, min(first + SCAN_TARGETS, grid.size))
        low = max(0, first - reach)
        window = read("reachable", slice(low, min(grid.size, indices[-1] + 1 + reach)))
        beside = np.zeros(len(indices), dtype=bool)
        for position, (size, step) in zip(np.unravel_index(indices, grid.shape), strides, strict=True):
            for offset in (-1, 1):
                inside = (position + offset >= 0) & (position + offset < size)
                beside[inside] |= window[indices[inside] + offset * step - low]
        holes += indices[beside & ~window[indices - low]].tolist()
    return holes


def _within_reach(grid: TargetGrid, indices: list[int]) -> list[int]:
    return [index for index, gap in zip(indices, beyond_reach_m(grid, indices), strict=True) if np.isnan(gap)]


def first_tries(grid: TargetGrid, read) -> list[tuple[int, int]]:
    """``(target, neighbour)``: the IK solves :func:`fill_from_neighbours` starts with, each target it starts with (a
    hole beside a reached target, within reach) from each of its neighbours reached along the rows, in the order it
    tries them (it makes them all but those after a target's first success). Solved beforehand, elsewhere
    (:func:`solve_tries`), and passed to it, they change nothing but the time it takes."""
    if grid.kind == "joint":
        return []
    tries = []
    for index in _within_reach(grid, holes_beside_reached(grid, read)):
        neighbours = grid_neighbours(grid, index)
        tries += [(index, neighbour)
                  for neighbour, reached in zip(neighbours, read("reachable", neighbours), strict=True) if reached]
    return tries


def solve_tries(robot: Robot, grid: TargetGrid, tries: list[tuple[int, np.ndarray]]) -> list[IKResult]:
    """The IK of each ``(target, configuration)`` of ``tries`` from that configuration, as :func:`fill_from_neighbours`
    solves it."""
    return [_solve_from(robot, grid, index, q) for index, q in tries]


def fill_from_neighbours(robot: Robot, grid: TargetGrid, read,
                         solved: dict[tuple[int, int], IKResult] | None = None) -> dict[int, np.ndarray]:
    """Retry unreachable targets from the configurations of their reached neighbours.

    Rows are solved independently, so a target missed along its row (the IK left for another
    branch, or a joint limit cut the way) may still be reachable from the row beside it. Targets
    are retried in index order, again whenever a neighbour is newly reached, until none changes:
    the outcome depends on the grid only (not on how rows were split into chunks).

    Args:
        robot: the robot whose IK solves the retries.
        grid: the map's targets.
        read: ``read(column, index)`` of the rows' results: ``"reachable"`` (N,) flags and ``"q"``
            (N, nv) configurations [m or rad] (e.g. :meth:`~tribokin.maps.store.ChunkStore.read`).
        solved: the IK of some ``(target, neighbour)`` tries from a neighbour reached along the rows, solved
            beforehand (:func:`first_tries`, :func:`solve_tries`); the others are solved here.

    Returns:
        the configurations of the targets newly reached, by index in increasing order.
    """
    if grid.kind == "joint":
        return {}
    filled, solved = {}, solved or {}

    def reached(indices: list[int]) -> np.ndarray:
        return read("reachable", indices) | np.isin(indices, list(filled))

    pending = _within_reach(grid, holes_beside_reached(grid, read))
    tried = defaultdict(set)  # target -> neighbours it was tried from
    while pending:
        index = pending.pop(0)
        neighbours = grid_neighbours(grid, index)
        for neighbour, was_reached in zip(neighbours, reached(neighbours), strict=True):
            if not was_reached or neighbour in tried[index]:
                continue
            tried[index].add(neighbour)
            if neighbour in filled:
                result = _solve_from(robot, grid, index, filled[neighbour])
            else:
                result = solved.get((index, neighbour)) or _solve_from(robot, grid, index, read("q", neighbour))
            if result.success:
                filled[index] = result.q
                around = grid_neighbours(grid, index)
                pending += _within_reach(grid, [other for other, done in zip(around, reached(around), strict=True)
                                                if not done and other not in pending])
                pending.sort()
                break
    return dict(sorted(filled.items()))


def unreachable_reasons(grid: TargetGrid, positions_m: np.ndarray, closest: np.ndarray) -> np.ndarray:
    """Why each target is unreachable, for the map's ``reason`` column, as Python strings (``""``: reached), from
    the targets' positions (k, 3) [m] and how close the IK came to them (k, 2) [m, rad] (:func:`solve_rows`)."""
    bounds, gaps = first_bound_beyond(grid, positions_m) if grid.reach else (np.full(len(closest), -1), None)
    reasons = np.full(len(closest), "", dtype=object)
    for k in np.flatnonzero((bounds < 0) & ~np.isnan(closest[:, 0])):  # the others were reached: no reason
        reasons[k] = unreachable_reason(*closest[k])
    for b, reach in enumerate(grid.reach):
        beyond = np.flatnonzero(bounds == b)
        reasons[beyond] = beyond_reach_reasons(reach, gaps[beyond])
    return reasons


def beyond_reach_reasons(reach: ReachSphere, gaps_m: np.ndarray) -> list[str]:
    """Why each target is unreachable whose point bounded by ``reach`` (the tool point, or with the tool's orientation
    held the last joint's origin) lies ``gaps_m`` (k,) [m] beyond it."""
    centre = ", ".join(f"{value:.4g}" for value in reach.centre_m + 0.0)
    if reach.offset_m is None:
        before, after = "beyond the robot's reach: ", (f" m from ({centre}) m, where the tool point never goes farther "
                                                        f"than {reach.radius_m:.4g} m (no IK tried)")
    else:
        before = f"beyond the robot's reach with the tool's orientation held: {reach.point} would be "
        after = f" m from ({centre}) m, where it never goes farther than {reach.radius_m:.4g} m (no IK tried)"
    return [f"{before}{distance:.4g}{after}" for distance in (reach.radius_m + np.asarray(gaps_m)).tolist()]


def unreachable_reason(position_error_m: float, angle_error_rad: float) -> str:
    """Why IK failed, for the map's ``reason`` column: how close it came [m, rad] (angle NaN when
    the orientation is not held; position NaN: the target was reached, no reason)."""
    if np.isnan(position_error_m):
        return ""
    closest = f"closest {position_error_m * 1e3:.3g} mm"
    if not np.isnan(angle_error_rad):
        closest += f", {np.degrees(angle_error_rad):.3g} deg"
    return f"no IK solution within the joint limits from the warm start and {IK_RESTARTS} restarts ({closest})"
