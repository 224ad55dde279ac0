"""Map targets: the grid of tool poses (or joint configurations) a workspace map measures.

A grid has the shape (layers, rows, columns); target ``index = (layer * rows + row) * columns + column``
and *grid row* ``layer * rows + row``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from tribokin.errors import ConfigurationError, TribokinError, closest_hint
from tribokin.iso9283.cube import candidate_postures, holds_orientation
from tribokin.kinematics.reach import ReachSphere, last_joint_sphere, reach_sphere
from tribokin.kinematics.robot import Robot
from tribokin.study.map_spec import JointMap, MapSpec, PlaneMap

#: Grid values and target positions are rounded to 1e-GRID_DECIMALS [m or rad], so that they are the decimals
#: the user wrote (``-0.55``, not ``-0.5499999999999999``).
GRID_DECIMALS = 12


class GridError(TribokinError, ValueError):
    """A map spec that does not fit the robot; ``key`` names the spec's field at fault (``"rpy_deg"``,
    ``"joints[0]"``), for a study to name its file and key."""

    def __init__(self, message: str, key: str):
        super().__init__(message)
        self.key = key


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
        directions: (3, 3) world-frame direction of the column, row and layer axes, one per row
            (Cartesian grids): a target's position is ``origin_m + (column, row, layer values) @ directions``.
        joint_columns: index in ``q`` of the joint of each axis present (joint grids).
        reach: bounds of the robot's reach (Cartesian grids; none for joint grids): a sphere the tool point never
            leaves (:func:`tribokin.kinematics.reach.reach_sphere`), then, when the grid holds the tool's
            orientation, one the origin of the last joint's frame never leaves
            (:func:`tribokin.kinematics.reach.last_joint_sphere`); no IK is tried for a target beyond either.
        base_m: (3,) where the robot's base origin lies in the world [m] (:attr:`Robot.base_m
            <tribokin.kinematics.robot.Robot.base_m>`; Cartesian grids), which heat maps mark.
    """

    kind: str
    axes: tuple[GridAxis, GridAxis | None, GridAxis | None]
    rotation: np.ndarray | None
    start_q: np.ndarray
    origin_m: np.ndarray | None = None
    directions: np.ndarray | None = None
    joint_columns: tuple[int, ...] = ()
    reach: tuple[ReachSphere, ...] = ()
    base_m: np.ndarray = field(default_factory=lambda: np.zeros(3))

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
                                for axis, k in zip(self.axes, (column, row, layer), strict=True)])

    def positions_m(self, indices) -> np.ndarray:
        """(k, 3) commanded tool positions of Cartesian targets ``indices`` in the world frame [m], rounded to
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
        kept = [np.arange(0, size, stride) for size, stride in zip(self.shape, strides, strict=True)]
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


def make_grid(robot: Robot, spec: MapSpec, like: TargetGrid | None = None) -> TargetGrid:
    """The targets a validated ``[map]`` describes, for ``robot``; a :class:`GridError` if they do not fit it (its
    joints, their limits, the start posture, a tool orientation it cannot hold). ``like``: the same Cartesian
    targets' grid for another robot (the study's), whose held orientation (or none) this one holds."""
    if spec.start_q is not None:
        try:
            start = robot.check_configuration(spec.start_q)
        except ConfigurationError as error:
            raise GridError(str(error), "start_q") from None
    elif isinstance(spec, JointMap):
        start = robot.reference_q.copy()
    else:
        start = candidate_postures(robot, keep=1)[0]
    if isinstance(spec, JointMap):
        return _joint_grid(robot, spec, start)
    rotation = None
    holds = holds_orientation(robot, start)
    if like is not None:
        if like.rotation is not None and not holds:
            raise GridError(f"{robot.label} cannot hold the tool's orientation (fewer than 6 independent joints at "
                            "the start posture), which the map holds for the study's robot", "rpy_deg")
        rotation = like.rotation
    elif holds:
        rpy = spec.rpy_deg
        rotation = robot.tool_placement(start).rotation.copy() if rpy is None else pin.rpy.rpyToMatrix(*np.radians(rpy))
    elif spec.rpy_deg is not None:
        raise GridError(f"{robot.label} cannot hold the tool's orientation (fewer than 6 independent joints at the "
                        "start posture); remove map.rpy_deg", "rpy_deg")
    reach = (reach_sphere(robot),) if rotation is None else (reach_sphere(robot), last_joint_sphere(robot))
    if isinstance(spec, PlaneMap):
        u = GridAxis("u", "m", _grid_values(spec.extent_u_m, spec.resolution[0]))
        v = GridAxis("v", "m", _grid_values(spec.extent_v_m, spec.resolution[1]))
        directions = np.array([spec.axis_u, spec.axis_v, [0.0, 0.0, 0.0]], dtype=float)
        return TargetGrid("plane", (u, v, None), rotation, start, np.asarray(spec.origin_m, dtype=float),
                          directions, reach=reach, base_m=robot.base_m)
    x, y, z = (GridAxis(name, "m", _grid_values([low, high], count)) for name, low, high, count
               in zip("xyz", spec.min_m, spec.max_m, spec.resolution, strict=True))
    return TargetGrid("box", (x, y, z), rotation, start, np.zeros(3), np.eye(3), reach=reach, base_m=robot.base_m)


def _joint_grid(robot: Robot, spec: JointMap, start: np.ndarray) -> TargetGrid:
    names = robot.joint_names
    axes = []
    for i, (joint, bounds, count) in enumerate(zip(spec.joints, spec.ranges, spec.counts, strict=True)):
        if joint not in names:
            raise GridError(f"unknown joint '{joint}'{closest_hint(joint, names)}; joints of {robot.label}: "
                            f"{', '.join(names)}", f"joints[{i}]")
        k = names.index(joint)
        low, high = robot.lower_limits[k], robot.upper_limits[k]
        if bounds[0] < low or bounds[1] > high:
            raise GridError(f"[{bounds[0]:g}, {bounds[1]:g}] leaves the limits of joint '{joint}' "
                            f"[{low:g}, {high:g}]", f"ranges[{i}]")
        axes.append(GridAxis(joint, "m" if robot.joint_is_prismatic[k] else "rad", _grid_values(bounds, count)))
    columns = tuple(names.index(axis.name) for axis in axes)
    return TargetGrid("joint", tuple(axes + [None] * (3 - len(axes))), None, start, joint_columns=columns)


def target_positions_m(robot: Robot, grid: TargetGrid, indices, q: np.ndarray) -> np.ndarray:
    """(k, 3) positions of targets ``indices`` [m]: commanded (Cartesian grids), or reached at their
    configurations ``q`` (k, nv) (joint grids)."""
    if grid.kind == "joint":
        return np.array([robot.tool_placement(qi).translation for qi in q]).reshape(len(q), 3)
    return grid.positions_m(indices)


def axis_steps(shape: tuple[int, int, int]) -> tuple[tuple[int, int], ...]:
    """(size, index step) of the layer, row and column axes of a grid of ``shape`` (layers, rows, columns)."""
    layers, rows, columns = shape
    return (layers, rows * columns), (rows, columns), (columns, 1)


def grid_neighbours(grid: TargetGrid, index: int) -> list[int]:
    """Indices of the targets next to ``index`` along each grid axis (up to 6), in increasing order."""
    neighbours = []
    for position, (size, step) in zip(np.unravel_index(index, grid.shape), axis_steps(grid.shape), strict=True):
        for offset in (-1, 1):
            if 0 <= position + offset < size:
                neighbours.append(index + offset * step)
    return sorted(neighbours)

