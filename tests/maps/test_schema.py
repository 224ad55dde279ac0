"""One schema of map figures: the store's columns, the bytes a target takes and map.csv's columns follow it."""

import csv

import numpy as np

from tribokin.maps import schema
from tribokin.maps.grid import GridAxis, TargetGrid
from tribokin.maps.result import MapResult, ScenarioMap
from tribokin.maps.schema import MapFigure, MapLayout
from tribokin.maps.store import ChunkStore
from tribokin.output.writers import write_map_table


def map_table_header(tmp_path, statistic: str, scenarios: int = 1) -> list[str]:
    """The header of map.csv of a 2-target joint map with one joint, written through the store."""
    tmp_path.mkdir()
    grid = TargetGrid("joint", (GridAxis("x", "m", np.array([0.0, 0.1])), None, None), None, np.zeros(1),
                      joint_columns=(0,))
    store = ChunkStore(tmp_path / "store", "key", MapLayout.shared(1, scenarios, statistic).columns(), grid.size)
    store.write(slice(None), {"reachable": np.ones(2, bool), "closest": np.zeros((2, 2)),
                              "scenario0_dominant_joint": np.zeros(2, int)})
    workspace_map = MapResult((grid,), ["x"], store, {"raw": ScenarioMap("raw", 5, 0, ["x"], store, statistic)})
    write_map_table(workspace_map, workspace_map.reference, tmp_path / "map.csv")
    with open(tmp_path / "map.csv", newline="") as handle:
        return next(csv.reader(handle))


def test_the_store_the_estimate_and_map_csv_follow_the_figures_of_the_schema(tmp_path, monkeypatch):
    assert MapLayout.shared(2, 3, "one-test").columns()["scenario2_figures"] == ((7,), "f8")
    assert MapLayout.shared(2, 3, "one-test").bytes_per_target == 8 * (3 + 2 + 2) + 1 + 1 + 3 * 8 * (7 + 2 + 1)
    header = map_table_header(tmp_path / "before", "one-test")
    assert header[:12] == ["x_m", "y_m", "z_m", "reachable", "RP_l_um", "AP_p_um", "RP_a_mdeg", "RP_b_mdeg",
                           "RP_c_mdeg", "largest_semi_axis_um", "dominant_joint", "dominant_share"]

    monkeypatch.setattr(schema, "ALL_FIGURES", (*schema.ALL_FIGURES, MapFigure("flatness_um")))
    assert MapLayout.shared(2, 3, "one-test").columns()["scenario2_figures"] == ((8,), "f8")
    assert MapLayout.shared(2, 3, "one-test").bytes_per_target == 8 * (3 + 2 + 2) + 1 + 1 + 3 * 8 * (8 + 2 + 1)
    assert map_table_header(tmp_path / "after", "one-test") == header[:10] + ["flatness_um"] + header[10:]


def test_an_expected_map_has_its_band_its_directional_figures_and_how_they_were_computed(tmp_path):
    """Besides the one-test figures: the RP_l band (and when directional vAP_p and RP_l_multi); and per scenario the
    method, fallbacks, engine (1 byte), engine bound (2 values), figure errors and Monte Carlo errors (one per figure)
    columns; map.csv gives the engine, its bound and the test's figures' Monte Carlo errors after the figures."""
    assert MapLayout.shared(2, 1, "expected").columns()["scenario0_figures"] == ((9,), "f8")
    assert MapLayout.shared(2, 1, "directional").columns()["scenario0_figures"] == ((11,), "f8")
    assert MapLayout.shared(2, 1, "directional").columns()["scenario0_figure_errors"] == ((11,), "f8")
    assert MapLayout.shared(2, 1, "directional").bytes_per_target == \
        8 * (3 + 2 + 2) + 1 + 1 + 8 * (11 + 2 + 1) + 8 * (1 + 1 + 2 + 11 + 11) + 1
    assert map_table_header(tmp_path / "expected", "directional")[4:27] == [
        "RP_l_um", "RP_l_lo_um", "RP_l_hi_um", "AP_p_um", "vAP_p_um", "RP_l_multi_um", "RP_a_mdeg", "RP_b_mdeg",
        "RP_c_mdeg", "largest_semi_axis_um", "dominant_joint", "dominant_share", "engine", "engine_bound_nm",
        "engine_bound_nrad", "RP_l_mc_error", "RP_l_lo_mc_error", "RP_l_hi_mc_error", "AP_p_mc_error",
        "RP_a_mc_error", "RP_b_mc_error", "RP_c_mc_error", "largest_semi_axis_mc_error"]
    assert "engine" not in map_table_header(tmp_path / "one-test", "one-test")


def test_each_robot_of_the_scenarios_keeps_its_own_configurations_and_the_budget_counts_them():
    from conftest import STUDIES
    from tribokin.maps.budget import estimate
    from tribokin.study.reading import load_study

    layout = MapLayout((6, 7), (0, 1, 1), "one-test")  # a 6-joint robot's scenario, two of a 7-joint one
    columns = layout.columns()
    assert columns["q"] == ((6,), "f8") and columns["robot1_q"] == ((7,), "f8")
    assert columns["scenario0_normal_forces_N"] == ((6,), "f8") and columns["scenario2_normal_forces_N"] == ((7,), "f8")
    assert layout.bytes_per_target == (8 * 3 + (8 * (6 + 2) + 2) + (8 * (7 + 2) + 2) + 8 * (7 + 6 + 1)
                                       + 2 * 8 * (7 + 7 + 1))
    assert sorted(layout.columns(1)) == sorted(f"{prefix}_{name}" for prefix, names in (
        ("robot1", ("q", "reachable", "closest", "ik_route")),
        ("scenario1", ("figures", "normal_forces_N", "dominant_joint")),
        ("scenario2", ("figures", "normal_forces_N", "dominant_joint"))) for name in names)
    study = load_study(STUDIES / "what-if-robots.toml")
    shared = dict((key, size) for size, key, _ in estimate(study, 6, []))
    layout = MapLayout((6, 6), (0, 1), study.map.figure_set)
    own = dict((key, size) for size, key, _ in estimate(study, 6, [], layout=layout))
    assert own["map.resolution"] > shared["map.resolution"]  # the second robot's configurations, held and stored
