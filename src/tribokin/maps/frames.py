"""A map's figures as pandas and xarray objects, holding exactly the numbers of its tables (``map*.csv``).

pandas and xarray are an optional extra (``pip install 'tribokin[data]'``), imported when a conversion is asked
for. ``workspace_map`` is a :class:`~tribokin.maps.result.MapResult` (not imported: it converts itself through this
module); its whole columns are read into memory.
"""

from __future__ import annotations

import numpy as np

from tribokin.errors import import_extra
from tribokin.maps.table import map_table_columns

#: A column's unit, by the suffix of its name in ``map.csv`` (none of these: dimensionless, or text).
UNITS = {"_um": "µm", "_mdeg": "mdeg", "_nm": "nm", "_nrad": "nrad", "_m": "m", "_N": "N"}
#: ``map.csv``'s columns that are coordinates of the grid's targets in the Dataset, not variables.
POSITION_COLUMNS = ("x_m", "y_m", "z_m")


def unit(name: str) -> str:
    """The unit of column ``name`` (``RP_l_um`` -> ``µm``), ``"1"`` for a number without one, ``""`` otherwise."""
    for suffix, symbol in UNITS.items():
        if name.endswith(suffix):
            return symbol
    return "1" if name in ("RP_l_ratio", "dominant_share") else ""


def scenario_table(workspace_map, scenario) -> dict[str, np.ndarray]:
    """``scenario``'s whole table (:func:`~tribokin.maps.table.map_table_columns`), read block by block."""
    parts = [map_table_columns(workspace_map, scenario, part) for part in workspace_map.blocks()]
    return {name: np.concatenate([part[name] for part in parts]) for name in parts[0]}


def merged_columns(tables: list[dict]) -> list[str]:
    """Every column of ``tables`` once, each table's in its own order (one placed after the column before it in the
    first table, by length, that has it)."""
    order = []
    for table in sorted(tables, key=len, reverse=True):
        names = list(table)
        for i, name in enumerate(names):
            if name not in order:
                order.insert(order.index(names[i - 1]) + 1 if i else 0, name)
    return order


def map_frame(workspace_map):
    """Every scenario's table, one after the other, as one tidy pandas DataFrame: a ``scenario`` column, then the
    table's columns (those only some scenarios have, such as ``RP_l_ratio`` or ``reached_by``, are empty, NaN, for
    the others), indexed by ``target`` (its row in ``map*.csv``)."""
    pandas = import_extra("pandas", "to_pandas()")
    tables = {scenario.name: scenario_table(workspace_map, scenario) for scenario in workspace_map.scenarios.values()}
    frame = pandas.concat([pandas.DataFrame({"scenario": np.full(workspace_map.grid.size, name, dtype=object), **table})
                           for name, table in tables.items()])
    frame = frame[["scenario", *merged_columns(list(tables.values()))]]
    frame.index.name = "target"
    return frame


def robot_names(workspace_map) -> list[str]:
    """A name for each robot the scenarios are measured with: the first scenario measured with it."""
    names = {}
    for scenario in workspace_map.scenarios.values():
        names.setdefault(scenario.robot, scenario.name)
    return [names[robot] for robot in range(workspace_map.robot_count)]


def missing_like(values: np.ndarray) -> np.ndarray:
    """A column where a scenario has none of ``values``: NaN (floats), ``""`` (text)."""
    return np.full(values.shape, np.nan if values.dtype.kind == "f" else "", dtype=values.dtype)


def map_dataset(workspace_map):
    """The map as an xarray Dataset on its grid's axes (a plane's ``v``, ``u`` [m] in its own frame; a box's ``z``,
    ``y``, ``x`` [m]; a joint map's joints [rad or m], the last axis of each fastest), the targets' positions
    ``x_m``, ``y_m``, ``z_m`` [m] as coordinates; per ``scenario``, one variable per column of its table
    (``RP_l_um``, ..., ``reachable``, ``dominant_joint``, ``reason``; NaN or ``""`` for a scenario whose table has
    none); ``q`` [m or rad] on a ``joint`` dimension and ``normal_force_N`` [N] on it per scenario, or, when the
    scenarios change the robot, ``q_<robot>`` and ``normal_force_N_<robot>`` on ``joint_<robot>`` for each robot
    (named by the first scenario measured with it; NaN for the scenarios of other robots). Units in each
    variable's ``units`` attribute."""
    xarray = import_extra("xarray", "to_xarray()")
    grid, scenarios = workspace_map.grid, list(workspace_map.scenarios.values())
    axes = [axis for axis in reversed(grid.axes) if axis is not None]
    dims = tuple(axis.name for axis in axes)
    shape = tuple(len(axis.values) for axis in axes)
    tables = [scenario_table(workspace_map, scenario) for scenario in scenarios]

    def on_grid(values: np.ndarray) -> np.ndarray:
        return values.reshape(shape + values.shape[1:])

    coords = {axis.name: (axis.name, axis.values, {"units": axis.unit}) for axis in axes}
    coords.update({name: (dims, on_grid(tables[0][name]), {"units": "m"}) for name in POSITION_COLUMNS})
    coords["scenario"] = ("scenario", np.array([scenario.name for scenario in scenarios], dtype=object))
    joint_columns = {f"{prefix}{joint}{suffix}" for scenario in scenarios for joint in scenario.joint_names
                     for prefix, suffix in (("q_", ""), ("normal_force_", "_N"))}
    skipped = set(POSITION_COLUMNS) | set(grid.coordinates([])) | joint_columns
    names = [name for name in merged_columns(tables) if name not in skipped]
    variables = {}
    for name in names:
        like = next(table[name] for table in tables if name in table)
        values = np.stack([table.get(name, missing_like(like)) for table in tables])
        variables[name] = (("scenario",) + dims, on_grid_stack(values, shape), {"units": unit(name)})
    robots = robot_names(workspace_map)
    for robot, label in enumerate(robots):
        own = [s for s, scenario in enumerate(scenarios) if scenario.robot == robot]
        joints = scenarios[own[0]].joint_names
        suffix = "" if len(robots) == 1 else f"_{label}"
        joint = f"joint{suffix}"
        coords[joint] = (joint, np.array(joints, dtype=object))
        q = np.column_stack([tables[own[0]][f"q_{name}"] for name in joints])
        variables[f"q{suffix}"] = (dims + (joint,), on_grid(q), {"units": "m or rad (prismatic or revolute joint)"})
        forces = np.full((len(scenarios), grid.size, len(joints)), np.nan)
        for s in own:
            forces[s] = np.column_stack([tables[s][f"normal_force_{name}_N"] for name in joints])
        variables[f"normal_force_N{suffix}"] = (("scenario",) + dims + (joint,), on_grid_stack(forces, shape),
                                                {"units": "N"})
    attrs = {"kind": grid.kind, "figure_set": scenarios[0].figure_set, "cycles": scenarios[0].cycles,
             "orientation_held": int(grid.rotation is not None)}
    return xarray.Dataset(variables, coords, attrs)


def on_grid_stack(values: np.ndarray, shape: tuple[int, ...]) -> np.ndarray:
    """(scenarios, N, ...) values as (scenarios, *shape, ...)."""
    return values.reshape(values.shape[:1] + shape + values.shape[2:])
