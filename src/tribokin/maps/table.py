"""A map's tables: one per scenario, one row per target, in index order; the columns ``map.csv`` has, by header.

The writers (:mod:`tribokin.output.writers`: CSV or Parquet) and the conversions (:mod:`tribokin.maps.frames`:
pandas, xarray) take their values from here, so they hold the same numbers. ``workspace_map`` is a
:class:`~tribokin.maps.result.MapResult` and ``scenario`` one of its :class:`~tribokin.maps.result.ScenarioMap`
(not imported: the result converts itself through this module).
"""

from __future__ import annotations

import numpy as np

from tribokin.maps.expected_figures import TARGET_ENGINES, stated_figures
from tribokin.maps.schema import (
    CHANGE_FIGURES,
    change_bound_name,
    change_error_name,
    figure_index,
    mc_error_name,
    table_figures,
)
from tribokin.study.names import map_table_file


def reached_by_cells(workspace_map, scenario, targets: slice) -> np.ndarray:
    """The ``reached_by`` cells of ``scenario``'s table at ``targets``: ``both``, ``<scenario> only``,
    ``<reference> only`` or ``neither`` (:meth:`~tribokin.maps.result.MapResult.reached_by`)."""
    cells = np.array(["both", f"{scenario.name} only", f"{workspace_map.reference.name} only", "neither"], dtype=object)
    return cells[workspace_map.reached_by(scenario, targets)]


def map_table_columns(workspace_map, scenario, targets: slice) -> dict[str, np.ndarray]:
    """``scenario``'s table at ``targets``, by header: position [m], reachable (by its robot), the figures (µm, mdeg),
    the change from the map's state to its ``compare`` state (:data:`~tribokin.maps.schema.CHANGE_FIGURES`), an
    expected map's engine, its bound [nm, nrad] and each sampled figure's relative Monte Carlo standard error
    (:func:`~tribokin.maps.schema.mc_error_name`; a change's in µm, :func:`~tribokin.maps.schema.change_error_name`,
    and its bound from the engines' bounds [µm], :func:`~tribokin.maps.schema.change_bound_name`),
    ratio and difference of RP_l to the reference scenario (other
    scenarios), who reaches the target (a scenario measured with another robot than the reference's), grid
    coordinates, q_<joint> [m or rad],
    normal_force_<joint>_N [N] (its robot's joints), and the reason a target is unreachable. Floats (NaN: no
    value), booleans, or Python strings (object arrays)."""
    positions = workspace_map.read("position_m", targets)
    figures = scenario.read("figures", targets)
    columns = {"x_m": positions[:, 0], "y_m": positions[:, 1], "z_m": positions[:, 2],
               "reachable": scenario.read_robot("reachable", targets)}
    columns.update({name: scenario.dominant_joint_names(targets) if name == "dominant_joint"
                    else figures[:, figure_index(name, scenario.figure_set, scenario.both_directions)]
                    for name in table_figures(scenario.figure_set, scenario.both_directions)})
    if scenario.change:
        columns.update({name: scenario.change_figure(name, targets) for name in CHANGE_FIGURES})
    if scenario.figure_set != "one-test":
        engines = scenario.read("engine", targets)
        bound = scenario.read("engine_bound", targets) * 1e9
        reachable = columns["reachable"]
        columns["engine"] = np.where(reachable, np.array([*TARGET_ENGINES], dtype=object)[engines], "").astype(object)
        columns["engine_bound_nm"] = np.where(reachable, bound[:, 0], np.nan)
        columns["engine_bound_nrad"] = np.where(reachable, bound[:, 1], np.nan)
        mc_errors = scenario.read("mc_errors", targets)
        columns.update({mc_error_name(name): np.where(reachable, mc_errors[:, figure_index(
            name, scenario.figure_set, scenario.both_directions)], np.nan)
            for name in stated_figures(scenario.figure_set, scenario.both_directions)})
        if scenario.change:
            columns.update({change_error_name(name): scenario.change_error(name, targets) for name in CHANGE_FIGURES})
            columns.update({change_bound_name(name): scenario.change_bound(name, targets) for name in CHANGE_FIGURES})
    if scenario is not workspace_map.reference:
        columns["RP_l_ratio"] = workspace_map.ratio_RP_l(scenario, targets)
        columns["RP_l_diff_um"] = workspace_map.diff_RP_l_um(scenario, targets)
    if scenario.robot != workspace_map.reference.robot:
        columns["reached_by"] = reached_by_cells(workspace_map, scenario, targets)
    columns.update(workspace_map.grid.coordinates(np.arange(targets.start, targets.stop)))
    q, forces = scenario.read_robot("q", targets), scenario.read("normal_forces_N", targets)
    columns.update({f"q_{name}": q[:, i] for i, name in enumerate(scenario.joint_names)})
    columns.update({f"normal_force_{name}_N": forces[:, i] for i, name in enumerate(scenario.joint_names)})
    columns["reason"] = workspace_map.reasons(targets, scenario)
    return columns


def map_table_name(workspace_map, scenario, table_format: str = "csv") -> str:
    """``map.csv`` for the reference scenario, ``map_<scenario>.csv`` for the others (``.parquet`` in that
    ``table_format``)."""
    return map_table_file(None if scenario is workspace_map.reference else scenario.name, table_format)
