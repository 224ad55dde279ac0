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

from tribokin.cube import candidate_postures, holds_orientation
from tribokin.errors import InputError, closest_hint
from tribokin.ik import IKResult, solve_ik, solve_ik_with_restarts
from tribokin.robot import Robot

#: Random restarts of the IK after a warm start fails (each costs up to 200 iterations).
IK_RESTARTS = 4
#: Reached targets a row's warm start extrapolates from (a polynomial of one degree less): an error of the
#: order of the step to the fourth power, so one iteration usually converges on fine grids.
EXTRAPOLATION_POINTS = 4
#: Seed of the IK restarts: target ``index`` restarts from ``default_rng([IK_SEED, index])``.
IK_SEED = 9283


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
    """The targets of a map.

    Attributes:
        kind: ``"plane"``, ``"box"`` or ``"joint"``.
        axes: (columns, rows, layers) axes; ``None`` for a missing dimension (size 1).
        positions_m: (N, 3) commanded tool positions in the base frame [m].
        rotation: (3, 3) tool orientation held at every Cartesian target; ``None`` when the robot
            cannot hold it (position-only IK) and for joint grids.
        start_q: (nv,) start posture of the IK (Cartesian) or posture of the other joints (joint grids).
        joint_q: (N, nv) configurations of a joint grid [m or rad]; ``None`` for Cartesian grids.
        coordinates: per-target grid coordinates for reports, e.g. ``{"u_m": (N,), "v_m": (N,)}``.
    """

    kind: str
    axes: tuple[GridAxis, GridAxis | None, GridAxis | None]
    positions_m: np.ndarray
    rotation: np.ndarray | None
    start_q: np.ndarray
    joint_q: np.ndarray | None = None
    coordinates: dict | None = None

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
        return len(self.positions_m)

    def row_indices(self, row: int) -> np.ndarray:
        """Target indices of grid row ``row``."""
        return np.arange(row * self.row_length, (row + 1) * self.row_length)

    def describe(self) -> dict:
        """The grid for ``summary.json``: kind, shape, axes (name, unit, first, last) and orientation."""
        axes = [{"name": a.name, "unit": a.unit, "first": float(a.values[0]), "last": float(a.values[-1]),
                 "count": len(a.values)} for a in self.axes if a is not None]
        rpy = None if self.rotation is None else np.degrees(pin.rpy.matrixToRpy(self.rotation)).tolist()
        return {"kind": self.kind, "shape": list(self.shape), "axes": axes, "rpy_deg": rpy,
                "orientation_held": self.rotation is not None}


def _grid_values(bounds, count: int) -> np.ndarray:
    return np.linspace(bounds[0], bounds[1], count)


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
        vv, uu = np.meshgrid(v.values, u.values, indexing="ij")
        positions = (np.asarray(spec["origin_m"]) + uu.reshape(-1, 1) * np.asarray(spec["axis_u"])
                     + vv.reshape(-1, 1) * np.asarray(spec["axis_v"]))
        return TargetGrid("plane", (u, v, None), positions, rotation, start,
                          coordinates={"u_m": uu.ravel(), "v_m": vv.ravel()})
    x, y, z = (GridAxis(name, "m", _grid_values([low, high], count)) for name, low, high, count
               in zip("xyz", spec["min_m"], spec["max_m"], spec["resolution"]))
    zz, yy, xx = np.meshgrid(z.values, y.values, x.values, indexing="ij")
    positions = np.column_stack([xx.ravel(), yy.ravel(), zz.ravel()])
    return TargetGrid("box", (x, y, z), positions, rotation, start)


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
    axes += [None] * (3 - len(axes))
    present = [a for a in axes if a is not None]
    mesh = np.meshgrid(*[a.values for a in reversed(present)], indexing="ij")
    q = np.tile(start, (mesh[0].size, 1))
    for axis, values in zip(reversed(present), mesh):
        q[:, names.index(axis.name)] = values.ravel()
    positions = np.array([robot.tool_placement(qi).translation for qi in q])
    return TargetGrid("joint", tuple(axes), positions, None, start, joint_q=q)


def _target(grid: TargetGrid, index: int) -> pin.SE3:
    return pin.SE3(np.eye(3) if grid.rotation is None else grid.rotation, grid.positions_m[index])


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
    if grid.joint_q is not None:
        return grid.joint_q[::grid.row_length].copy()
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


def solve_row(robot: Robot, grid: TargetGrid, row: int, head_q) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """Configurations of grid row ``row``, each target warm-started from the last reachable one (``head_q`` first),
    extrapolated along the row when two or more targets right before it were reached (:func:`extrapolate_row`).

    Returns:
        q (columns, nv) [m or rad] (NaN where unreachable), reachable (columns,) and the reason
        each unreachable target failed (``""`` for reachable ones).
    """
    indices = grid.row_indices(row)
    if grid.joint_q is not None:
        return grid.joint_q[indices].copy(), np.ones(len(indices), dtype=bool), [""] * len(indices)
    q = np.full((len(indices), robot.model.nv), np.nan)
    reachable = np.zeros(len(indices), dtype=bool)
    reasons = []
    q_start = np.asarray(head_q, dtype=float)
    for k, index in enumerate(indices):
        result = None
        predicted = extrapolate_row(q[:k], reachable[:k])
        if predicted is not None:
            result = _solve_from(robot, grid, index, predicted)
        if result is None or not result.success:
            result = _solve(robot, grid, index, q_start)
        reachable[k] = result.success
        reasons.append("" if result.success else unreachable_reason(result, grid.rotation is None))
        if result.success:
            q[k] = q_start = result.q
    return q, reachable, reasons


def grid_neighbours(grid: TargetGrid, index: int) -> list[int]:
    """Indices of the targets next to ``index`` along each grid axis (up to 6), in increasing order."""
    layers, rows, columns = grid.shape
    layer, rest = divmod(index, rows * columns)
    row, column = divmod(rest, columns)
    neighbours = []
    for position, size, step in ((layer, layers, rows * columns), (row, rows, columns), (column, columns, 1)):
        for offset in (-1, 1):
            if 0 <= position + offset < size:
                neighbours.append(index + offset * step)
    return sorted(neighbours)


def fill_from_neighbours(robot: Robot, grid: TargetGrid, q: np.ndarray, reachable: np.ndarray) -> list[int]:
    """Retry unreachable targets from the configurations of their reached neighbours, in place.

    Rows are solved independently, so a target missed along its row (the IK left for another
    branch, or a joint limit cut the way) may still be reachable from the row beside it. Targets
    are retried in index order, again whenever a neighbour is newly reached, until none changes:
    the outcome depends on the grid only (not on how rows were split into chunks).

    Args:
        q: (N, nv) configurations [m or rad], NaN where unreachable; filled in where solved.
        reachable: (N,) flags, set where solved.

    Returns:
        the indices newly reached, in increasing order.
    """
    if grid.joint_q is not None:
        return []
    pending = sorted(i for i in np.flatnonzero(~reachable) if any(reachable[grid_neighbours(grid, i)]))
    tried = defaultdict(set)  # target -> neighbours it was tried from
    filled = []
    while pending:
        index = pending.pop(0)
        for neighbour in grid_neighbours(grid, index):
            if not reachable[neighbour] or neighbour in tried[index]:
                continue
            tried[index].add(neighbour)
            result = _solve_from(robot, grid, index, q[neighbour])
            if result.success:
                q[index], reachable[index] = result.q, True
                filled.append(index)
                for other in grid_neighbours(grid, index):
                    if not reachable[other] and other not in pending:
                        pending.append(other)
                pending.sort()
                break
    return sorted(filled)


def unreachable_reason(result: IKResult, position_only: bool) -> str:
    """Why IK failed, for the map's ``reason`` column."""
    closest = f"closest {result.position_error_m * 1e3:.3g} mm"
    if not position_only:
        closest += f", {np.degrees(result.angle_error_rad):.3g} deg"
    return f"no IK solution within the joint limits from the warm start and {IK_RESTARTS} restarts ({closest})"
