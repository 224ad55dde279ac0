"""Map targets: the grid of tool poses (or joint configurations) a workspace map measures, and their IK.

A grid has the shape (layers, rows, columns); target ``index = (layer * rows + row) * columns + column``
and *grid row* ``layer * rows + row``. Cartesian targets are solved by inverse kinematics,
warm-started from a neighbour in an order that does not depend on how the rows are later
split into chunks: the first target of every row (the *row heads*) is solved in one sequence
from the start posture (:func:`solve_row_heads`), then each row is solved along its columns
from its head (:func:`solve_row`). So a row's configurations depend on the grid only.
"""

from __future__ import annotations

import math
from collections import defaultdict
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from tribokin.iso9283.cube import candidate_postures, holds_orientation
from tribokin.errors import InputError, closest_hint
from tribokin.kinematics.ik import IKResult, solve_ik, solve_ik_with_restarts
from tribokin.kinematics.robot import Robot

#: Random restarts of the IK after a warm start fails (each costs up to 200 iterations).
IK_RESTARTS = 4
#: Reached targets a row's warm start extrapolates from (a polynomial of one degree less): an error of the
#: order of the step to the fourth power, so one iteration usually converges on fine grids.
EXTRAPOLATION_POINTS = 4
#: Seed of the IK restarts: target ``index`` restarts from ``default_rng([IK_SEED, index])``.
IK_SEED = 9283
#: Grid values and target positions are rounded to 1e-GRID_DECIMALS [m or rad], so that they are the decimals
#: the user wrote (``-0.55``, not ``-0.5499999999999999``).
GRID_DECIMALS = 12


@dataclass(frozen=True)
class GridAxis:
    """One axis of a grid: ``name`` (``"u"``, ``"x"``, a joint name), ``unit`` (``"m"``, ``"rad"``) and values."""

    name: str
    unit: str
    values: np.ndarray

    @property
    def label(self) -> str:
        return f"{self.name} [{self.unit}]"


@dataclass
class TargetGrid:
    """The targets of a map. Per-target values are computed for the indices asked, never for the whole
    grid at once, so a grid of any size costs nothing until its targets are solved.

    Attributes:
        kind: ``"plane"``, ``"box"`` or ``"joint"``.
        axes: (columns, rows, layers) axes; ``None`` for a missing dimension (size 1).
        rotation: (3, 3) tool orientation held at every Cartesian target; ``None`` when the robot
            cannot hold it (position-only IK) and for joint grids.
        start_q: (nv,) start posture of the IK (Cartesian) or posture of the other joints (joint grids).
        origin_m: (3,) position of the target at axis values 0 [m] (Cartesian grids).
        directions: (3, 3) base-frame direction of the column, row and layer axes, one per row
            (Cartesian grids): a target's position is ``origin_m + (column, row, layer values) @ directions``.
        joint_columns: index in ``q`` of the joint of each axis present (joint grids).
    """

    kind: str
    axes: tuple[GridAxis, GridAxis | None, GridAxis | None]
    rotation: np.ndarray | None
    start_q: np.ndarray
    origin_m: np.ndarray | None = None
    directions: np.ndarray | None = None
    joint_columns: tuple[int, ...] = ()

    @property
    def shape(self) -> tuple[int, int, int]:
        """(layers, rows, columns)."""
        columns, rows, layers = (1 if a is None else len(a.values) for a in self.axes)
        return layers, rows, columns

    @property
    def row_count(self) -> int:
        """Number of grid rows (all layers)."""
        layers, rows, _ = self.shape
        return layers * rows

    @property
    def row_length(self) -> int:
        return self.shape[2]

    @property
    def size(self) -> int:
        layers, rows, columns = self.shape
        return layers * rows * columns

    def row_indices(self, row: int) -> np.ndarray:
        """Target indices of grid row ``row``."""
        return np.arange(row * self.row_length, (row + 1) * self.row_length)

    def axis_values(self, indices) -> np.ndarray:
        """(k, 3) values of the column, row and layer axes at targets ``indices`` (0 for a missing axis)."""
        layer, row, column = np.unravel_index(np.asarray(indices, dtype=int), self.shape)
        return np.column_stack([np.zeros(len(k)) if axis is None else axis.values[k]
                                for axis, k in zip(self.axes, (column, row, layer))])

    def positions_m(self, indices) -> np.ndarray:
        """(k, 3) commanded tool positions of Cartesian targets ``indices`` in the base frame [m], rounded to
        1e-12 m (:func:`grid_rounded`)."""
        return grid_rounded(self.origin_m + self.axis_values(indices) @ self.directions)

    def joint_q(self, indices) -> np.ndarray:
        """(k, nv) configurations of joint-grid targets ``indices`` [m or rad]."""
        q = np.tile(self.start_q, (len(indices), 1))
        q[:, list(self.joint_columns)] = self.axis_values(indices)[:, :len(self.joint_columns)]
        return q

    def coordinates(self, indices) -> dict[str, np.ndarray]:
        """Grid coordinates of targets ``indices`` for reports: ``u_m``, ``v_m`` on a plane, else none."""
        if self.kind != "plane":
            return {}
        values = self.axis_values(indices)
        return {"u_m": values[:, 0], "v_m": values[:, 1]}

    def every(self, strides: tuple[int, int, int]) -> np.ndarray:
        """(layers', rows', columns') indices of every ``strides``-th target along (layers, rows, columns),
        from the first."""
        kept = [np.arange(0, size, stride) for size, stride in zip(self.shape, strides)]
        return np.ravel_multi_index(np.ix_(*kept), self.shape)

    def thinned(self, most: int) -> tuple[np.ndarray, int]:
        """Indices (layers', rows', columns') of at most about ``most`` targets spread over the grid, every
        k-th along each axis, and k (1: all of them)."""
        stride = 1
        while math.prod(math.ceil(size / stride) for size in self.shape) > most:
            stride += 1
        return self.every((stride, stride, stride)), stride

    def describe(self) -> dict:
        """The grid for ``summary.json``: kind, shape, axes (name, unit, first, last) and orientation."""
        axes = [{"name": a.name, "unit": a.unit, "first": float(a.values[0]), "last": float(a.values[-1]),
                 "count": len(a.values)} for a in self.axes if a is not None]
        rpy = None if self.rotation is None else np.degrees(pin.rpy.matrixToRpy(self.rotation)).tolist()
        return {"kind": self.kind, "shape": list(self.shape), "axes": axes, "rpy_deg": rpy,
                "orientation_held": self.rotation is not None}


def grid_rounded(values: np.ndarray) -> np.ndarray:
    """``values`` rounded to ``GRID_DECIMALS`` decimals, without ``-0.0``."""
    return np.round(values, GRID_DECIMALS) + 0.0


def _grid_values(bounds, count: int) -> np.ndarray:
    """``count`` values ``low + i·(high − low)/(count − 1)`` from ``bounds`` = [low, high] (``low`` alone for
    one), rounded (:func:`grid_rounded`): both ends exact."""
    low, high = bounds
    step = (high - low) / (count - 1) if count > 1 else 0.0
    return grid_rounded(low + np.arange(count) * step)


def make_grid(robot: Robot, spec: dict, source=None) -> TargetGrid:
    """The targets a validated ``[map]`` table describes, for ``robot``."""
    if spec["start_q"] is not None:
        start = robot.check_configuration(spec["start_q"], source, "map.start_q")
    elif spec["kind"] == "joint":
        start = robot.reference_q.copy()
    else:
        start = candidate_postures(robot, keep=1)[0]
    if spec["kind"] == "joint":
        return _joint_grid(robot, spec, start, source)
    rotation = None
    if holds_orientation(robot, start):
        rpy = spec["rpy_deg"]
        rotation = robot.tool_placement(start).rotation.copy() if rpy is None else pin.rpy.rpyToMatrix(*np.radians(rpy))
    elif spec["rpy_deg"] is not None:
        raise InputError(f"{robot.label} cannot hold the tool's orientation (fewer than 6 independent joints at the "
                         "start posture); remove map.rpy_deg", source, "map.rpy_deg")
    if spec["kind"] == "plane":
        u = GridAxis("u", "m", _grid_values(spec["extent_u_m"], spec["resolution"][0]))
        v = GridAxis("v", "m", _grid_values(spec["extent_v_m"], spec["resolution"][1]))
        directions = np.array([spec["axis_u"], spec["axis_v"], [0.0, 0.0, 0.0]], dtype=float)
        return TargetGrid("plane", (u, v, None), rotation, start, np.asarray(spec["origin_m"], dtype=float),
                          directions)
    x, y, z = (GridAxis(name, "m", _grid_values([low, high], count)) for name, low, high, count
               in zip("xyz", spec["min_m"], spec["max_m"], spec["resolution"]))
    return TargetGrid("box", (x, y, z), rotation, start, np.zeros(3), np.eye(3))


def _joint_grid(robot: Robot, spec: dict, start: np.ndarray, source) -> TargetGrid:
    names = robot.joint_names
    axes = []
    for i, (joint, bounds, count) in enumerate(zip(spec["joints"], spec["ranges"], spec["counts"])):
        if joint not in names:
            raise InputError(f"unknown joint '{joint}'{closest_hint(joint, names)}; joints of {robot.label}: "
                             f"{', '.join(names)}", source, f"map.joints[{i}]")
        k = names.index(joint)
        low, high = robot.lower_limits[k], robot.upper_limits[k]
        if bounds[0] < low or bounds[1] > high:
            raise InputError(f"[{bounds[0]:g}, {bounds[1]:g}] leaves the limits of joint '{joint}' "
                             f"[{low:g}, {high:g}]", source, f"map.ranges[{i}]")
        axes.append(GridAxis(joint, "m" if robot.joint_is_prismatic[k] else "rad", _grid_values(bounds, count)))
    columns = tuple(names.index(axis.name) for axis in axes)
    return TargetGrid("joint", tuple(axes + [None] * (3 - len(axes))), None, start, joint_columns=columns)


def target_positions_m(robot: Robot, grid: TargetGrid, indices, q: np.ndarray) -> np.ndarray:
    """(k, 3) positions of targets ``indices`` [m]: commanded (Cartesian grids), or reached at their
    configurations ``q`` (k, nv) (joint grids)."""
    if grid.kind == "joint":
        return np.array([robot.tool_placement(qi).translation for qi in q]).reshape(len(q), 3)
    return grid.positions_m(indices)


def _target(grid: TargetGrid, index: int) -> pin.SE3:
    return pin.SE3(np.eye(3) if grid.rotation is None else grid.rotation, grid.positions_m([index])[0])


def _solve_from(robot: Robot, grid: TargetGrid, index: int, q_start) -> IKResult:
    """One IK solve of target ``index`` from ``q_start``, without restarts."""
    return solve_ik(robot, _target(grid, index), q_start, position_only=grid.rotation is None)


def _solve(robot: Robot, grid: TargetGrid, index: int, q_start) -> IKResult:
    """IK of target ``index`` from ``q_start``, then from seeded random restarts."""
    return solve_ik_with_restarts(robot, _target(grid, index), q_start, lambda: np.random.default_rng([IK_SEED, index]),
                                  IK_RESTARTS, position_only=grid.rotation is None)


def head_order(grid: TargetGrid) -> list[int]:
    """Grid rows in the order their heads are solved: row by row, each layer back and forth (a snake)."""
    layers, rows, _ = grid.shape
    order = []
    for layer in range(layers):
        sweep = range(rows) if layer % 2 == 0 else range(rows - 1, -1, -1)
        order += [layer * rows + row for row in sweep]
    return order


def solve_row_heads(robot: Robot, grid: TargetGrid) -> np.ndarray:
    """(rows, nv) warm start of every grid row: its first target solved from the previous head
    (the start posture for the first; the last reachable head after an unreachable one)."""
    if grid.kind == "joint":
        return grid.joint_q(np.arange(0, grid.size, grid.row_length))
    heads = np.empty((grid.row_count, robot.model.nv))
    q_start = grid.start_q
    for row in head_order(grid):
        result = _solve(robot, grid, row * grid.row_length, q_start)
        heads[row] = result.q
        if result.success:
            q_start = result.q
    return heads


def extrapolate_row(q: np.ndarray, reachable: np.ndarray) -> np.ndarray | None:
    """Warm start [m or rad] for the next target of a row: the polynomial through the configurations ``q``
    (k, nv) of the last reached targets in a row (up to ``EXTRAPOLATION_POINTS``), one step further;
    ``None`` when fewer than two targets right before the next one were reached."""
    count = 0
    while count < min(EXTRAPOLATION_POINTS, len(q)) and reachable[len(q) - 1 - count]:
        count += 1
    if count < 2:
        return None
    return sum((-1) ** (j + 1) * math.comb(count, j) * q[len(q) - j] for j in range(1, count + 1))


def solve_row(robot: Robot, grid: TargetGrid, row: int, head_q) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Configurations of grid row ``row``, each target warm-started from the last reachable one (``head_q`` first),
    extrapolated along the row when two or more targets right before it were reached (:func:`extrapolate_row`).

    Returns:
        q (columns, nv) [m or rad] (NaN where unreachable), reachable (columns,), and for unreachable
        targets how close the IK came (columns, 2): position error [m], orientation error [rad] (NaN
        for reachable targets, and the orientation when it is not held).
    """
    indices = grid.row_indices(row)
    closest = np.full((len(indices), 2), np.nan)
    if grid.kind == "joint":
        return grid.joint_q(indices), np.ones(len(indices), dtype=bool), closest
    q = np.full((len(indices), robot.model.nv), np.nan)
    reachable = np.zeros(len(indices), dtype=bool)
    q_start = np.asarray(head_q, dtype=float)
    for k, index in enumerate(indices):
        result = None
        predicted = extrapolate_row(q[:k], reachable[:k])
        if predicted is not None:
            result = _solve_from(robot, grid, index, predicted)
        if result is None or not result.success:
            result = _solve(robot, grid, index, q_start)
        reachable[k] = result.success
        if result.success:
            q[k] = q_start = result.q
        else:
            closest[k] = result.position_error_m, np.nan if grid.rotation is None else result.angle_error_rad
    return q, reachable, closest


def axis_steps(shape: tuple[int, int, int]) -> tuple[tuple[int, int], ...]:
    """(size, index step) of the layer, row and column axes of a grid of ``shape`` (layers, rows, columns)."""
    layers, rows, columns = shape
    return (layers, rows * columns), (rows, columns), (columns, 1)


def grid_neighbours(grid: TargetGrid, index: int) -> list[int]:
    """Indices of the targets next to ``index`` along each grid axis (up to 6), in increasing order."""
    neighbours = []
    for position, (size, step) in zip(np.unravel_index(index, grid.shape), axis_steps(grid.shape)):
        for offset in (-1, 1):
            if 0 <= position + offset < size:
                neighbours.append(index + offset * step)
    return sorted(neighbours)


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
        for position, (size, step) in zip(np.unravel_index(indices, grid.shape), strides):
            for offset in (-1, 1):
                inside = (position + offset >= 0) & (position + offset < size)
                beside[inside] |= window[indices[inside] + offset * step - low]
        holes += indices[beside & ~window[indices - low]].tolist()
    return holes


def fill_from_neighbours(robot: Robot, grid: TargetGrid, read) -> dict[int, np.ndarray]:
    """Retry unreachable targets from the configurations of their reached neighbours.

    Rows are solved independently, so a target missed along its row (the IK left for another
    branch, or a joint limit cut the way) may still be reachable from the row beside it. Targets
    are retried in index order, again whenever a neighbour is newly reached, until none changes:
    the outcome depends on the grid only (not on how rows were split into chunks).

    Args:
        read: ``read(column, index)`` of the rows' results: ``"reachable"`` (N,) flags and ``"q"``
            (N, nv) configurations [m or rad] (e.g. :meth:`~tribokin.maps.store.ChunkStore.read`).

    Returns:
        the configurations of the targets newly reached, by index in increasing order.
    """
    if grid.kind == "joint":
        return {}
    filled = {}

    def reached(indices: list[int]) -> np.ndarray:
        return read("reachable", indices) | np.isin(indices, list(filled))

    pending = holes_beside_reached(grid, read)
    tried = defaultdict(set)  # target -> neighbours it was tried from
    while pending:
        index = pending.pop(0)
        neighbours = grid_neighbours(grid, index)
        for neighbour, was_reached in zip(neighbours, reached(neighbours)):
            if not was_reached or neighbour in tried[index]:
                continue
            tried[index].add(neighbour)
            result = _solve_from(robot, grid, index, filled[neighbour] if neighbour in filled else read("q", neighbour))
            if result.success:
                filled[index] = result.q
                around = grid_neighbours(grid, index)
                pending += [other for other, done in zip(around, reached(around)) if not done and other not in pending]
                pending.sort()
                break
    return dict(sorted(filled.items()))


def unreachable_reason(position_error_m: float, angle_error_rad: float) -> str:
    """Why IK failed, for the map's ``reason`` column: how close it came [m, rad] (angle NaN when
    the orientation is not held; position NaN: the target was reached, no reason)."""
    if np.isnan(position_error_m):
        return ""
    closest = f"closest {position_error_m * 1e3:.3g} mm"
    if not np.isnan(angle_error_rad):
        closest += f", {np.degrees(angle_error_rad):.3g} deg"
    return f"no IK solution within the joint limits from the warm start and {IK_RESTARTS} restarts ({closest})"
