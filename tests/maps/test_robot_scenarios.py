"""Scenarios measured with robots of their own: another robot, its base placed elsewhere, a tool offset, xacro
arguments. Each solves its own IK of the same world-frame targets."""

import csv
import io
import json

import numpy as np
import pytest

from conftest import ROOT, STUDIES
from helpers.map_studies import UR5_PLANE
from tribokin import run_study
from tribokin.execution import executor_for
from tribokin.maps import mapping
from tribokin.output.writers import map_table_name, write_map_table, write_summary
from tribokin.study.reading import read_study_file


def with_scenarios(study: dict, *scenarios: dict) -> dict:
    return {**study, "scenarios": [{"name": "reference"}, *scenarios]}


def tables(result, folder) -> dict[str, str]:
    """summary.json and every map table of ``result``, as written."""
    folder.mkdir()
    write_summary(result, folder)
    for scenario in result.map.scenarios.values():
        write_map_table(result.map, scenario, folder / map_table_name(result.map, scenario))
    return {path.name: path.read_bytes().decode() for path in folder.iterdir()}


def without_columns(table: str, *names: str) -> str:
    """A CSV table's text without columns ``names`` (those it has), written back as the writer writes it."""
    rows = list(csv.reader(io.StringIO(table)))
    kept = [i for i, name in enumerate(rows[0]) if name not in names]
    out = io.StringIO()
    csv.writer(out).writerows([[row[i] for i in kept] for row in rows])
    return out.getvalue()


COMPARED = ("RP_l_ratio", "RP_l_diff_um", "reached_by")


def vertical(*scenarios: dict) -> dict:
    """studies/panda-map-vertical.toml at 15 × 19 targets, where IK fills holes from neighbours, with ``scenarios``."""
    study = read_study_file(STUDIES / "panda-map-vertical.toml").mapping
    return {**study, "map": {**study["map"], "resolution": [15, 19]}, "scenarios": [{"name": "reference"}, *scenarios]}


def test_a_base_moved_by_zero_solves_its_own_ik_and_gives_the_same_bytes(tmp_path, monkeypatch):
    filled = []
    real = mapping.fill_from_neighbours
    monkeypatch.setattr(mapping, "fill_from_neighbours", lambda *args: filled.append(real(*args)) or filled[-1])
    plain = run_study(vertical({"name": "same"}), cycles=10)
    zero_study = vertical({"name": "same", "robot": {"base_xyz_m": [0.0, 0.0, 0.0]}})
    zero = run_study(zero_study, cycles=10)
    assert (plain.map.robot_count, zero.map.robot_count) == (1, 2)  # the zero base is another robot, solved anew
    assert len(filled[0]) > 0 and [list(f) for f in filled[1:]] == [list(filled[0])] * 2  # its holes filled alike
    with executor_for(workers=2) as executor:  # its holes' first tries solved on the workers
        on_workers = tables(run_study(zero_study, cycles=10, executor=executor), tmp_path / "workers")
    plain, zero = tables(plain, tmp_path / "plain"), tables(zero, tmp_path / "zero")
    assert on_workers == zero
    assert zero["map.csv"] == plain["map.csv"]
    assert without_columns(zero["map_same.csv"], "reached_by") == plain["map_same.csv"]
    assert {row["reached_by"] for row in csv.DictReader(io.StringIO(zero["map_same.csv"]))} == {"both", "neither"}
    summaries = [json.loads(text)["map"] for text in (plain["summary.json"], zero["summary.json"])]
    assert summaries[1].pop("reached_by_any") == summaries[1]["reachable"]
    for scenario in summaries[1]["scenarios"]:
        assert scenario.pop("reached_only_by_this") == scenario.pop("reached_only_by_reference") == 0
        assert scenario.pop("reachable") == summaries[1]["reachable"]
        assert scenario.pop("ik") == summaries[1]["ik"]  # the same routes to the same configurations
    assert summaries[1] == summaries[0]


@pytest.mark.parametrize("override", [{"name": "ur10"}, {"base_xyz_m": [0.1, -0.05, 0.02], "base_rpy_deg": [0, 0, 30]},
                                      {"tool_offset_m": [0.0, 0.02, 0.1]}], ids=["ur10", "base", "tool"])
def test_a_scenarios_figures_are_those_of_a_study_of_its_robot_alone(tmp_path, override):
    """Independent of the scenario machinery: the same robot as the study's own, without scenarios."""
    study = with_scenarios(UR5_PLANE, {"name": "other", "robot": override})
    compared = tables(run_study(study), tmp_path / "compared")
    alone = tables(run_study({**UR5_PLANE, "robot": {**UR5_PLANE["robot"], **override}}), tmp_path / "alone")
    assert without_columns(compared["map_other.csv"], *COMPARED) == alone["map.csv"]
    summary = json.loads(compared["summary.json"])["map"]
    other = summary["scenarios"][1]
    assert other["reachable"] == json.loads(alone["summary.json"])["map"]["reachable"]
    reached = {name: np.array([row["reachable"] == "true" for row in csv.DictReader(io.StringIO(compared[name]))])
               for name in ("map.csv", "map_other.csv")}
    assert other["reached_only_by_this"] == np.sum(reached["map_other.csv"] & ~reached["map.csv"])
    assert other["reached_only_by_reference"] == np.sum(reached["map.csv"] & ~reached["map_other.csv"])
    assert summary["reached_by_any"] == np.sum(reached["map.csv"] | reached["map_other.csv"])
    if override == {"name": "ur10"}:  # the plane's far edge: beyond the UR5's reach, within the UR10's
        assert other["reached_only_by_this"] > 0 and other["reached_only_by_reference"] == 0


def test_targets_reached_by_one_robot_only_are_won_by_it_and_marked_in_its_table(tmp_path):
    result = run_study(with_scenarios(UR5_PLANE, {"name": "ur10", "robot": {"name": "ur10"}}))
    written = tables(result, tmp_path / "out")
    rows = list(csv.DictReader(io.StringIO(written["map_ur10.csv"])))
    reference = [row["reachable"] == "true" for row in csv.DictReader(io.StringIO(written["map.csv"]))]
    expected = {(True, True): "both", (True, False): "ur10 only", (False, True): "reference only",
                (False, False): "neither"}
    assert [row["reached_by"] for row in rows] == [expected[row["reachable"] == "true", ref]
                                                   for row, ref in zip(rows, reference, strict=True)]
    only = np.array([row["reached_by"] == "ur10 only" for row in rows])
    assert only.any() and all(row["RP_l_ratio"] == row["RP_l_diff_um"] == "" and row["RP_l_um"] != ""
                              for row, one in zip(rows, only, strict=True) if one)
    joints = result.map.scenarios["ur10"].joint_names
    assert [name for name in rows[0] if name.startswith("q_")] == [f"q_{joint}" for joint in joints]
    winners = result.map.winners()
    assert np.all(winners[only] == 1)  # won by the only robot that reaches them
    assert np.all(winners[~np.array(reference) & ~only] == -1)  # reached by neither
    statistics, summary = result.map.statistics(), result.map.summary()  # typed, and summary.json's made of them
    assert [(s.name, s.reachable, s.wins) for s in statistics.scenarios] == [
        ("reference", sum(reference), np.sum(winners == 0)), ("ur10", sum(row["reachable"] == "true" for row in rows),
                                                             np.sum(winners == 1))]
    assert [s.RP_l_um.as_dict() for s in statistics.scenarios] == [s["RP_l_um"] for s in summary["scenarios"]]
    assert statistics.reached_by_any == summary["reached_by_any"] == np.sum(np.array(reference) | only)


def two_link(**xacro_args) -> dict:
    """The shipped two-link arm (xacro) on a map of its own plane, z = 0, position only."""
    return {
        "study": {"name": "two-link", "cycles": 30, "seed": 1},
        "robot": {"urdf": str(ROOT / "urdf/two_link_description/urdf/two_link.urdf.xacro"),
                  "package_dirs": [str(ROOT / "urdf")], "tool_frame": "tool", "payload_kg": 1.0,
                  "xacro_args": {"upper_arm_m": "0.5", "forearm_m": "0.35", **xacro_args}},
        "joints": {"friction": {"preset": "42CD4-treated"}, "stiffness": 2.0e4},
        "map": {"kind": "plane", "origin_m": [0.0, 0.0, 0.0], "axis_u": [1, 0, 0], "axis_v": [0, 1, 0],
                "extent_u_m": [-0.05, 1.05], "extent_v_m": [0.02, 0.5], "resolution": [23, 7]},
    }


def test_a_longer_forearm_as_a_xacro_argument_reaches_as_far_as_its_links(tmp_path):
    """Reach of a planar two-link arm in closed form: |L1 - L2| <= r <= L1 + L2, and r at least the elbow's limit
    allows (r² = L1² + L2² + 2 L1 L2 cos 2.6); targets within 5 mm of either bound are left out."""
    study = {**two_link(), "scenarios": [{"name": "as-built"},
                                         {"name": "long-forearm", "robot": {"xacro_args": {"forearm_m": "0.5"}}}]}
    workspace = run_study(study).map
    r = np.hypot(*workspace.positions_m[:, :2].T)
    for scenario, forearm in zip(workspace.scenarios.values(), (0.35, 0.5), strict=True):
        shortest = np.sqrt(0.5**2 + forearm**2 + 2 * 0.5 * forearm * np.cos(2.6))
        clear = (np.abs(r - shortest) > 5e-3) & (np.abs(r - 0.5 - forearm) > 5e-3)
        reached = scenario.read_robot("reachable")
        np.testing.assert_array_equal(reached[clear], ((r >= shortest) & (r <= 0.5 + forearm))[clear])
    assert workspace.summary()["scenarios"][1]["reached_only_by_this"] > 0


def test_the_shipped_what_if_studies_compare_what_they_say():
    """studies/what-if-robots.toml: most targets reached by both, the far edge by the UR10 only;
    studies/what-if-placement.toml: each placement reaches other targets and changes RP_l."""
    robots = run_study(STUDIES / "what-if-robots.toml", cycles=5).map.summary()
    ur5, ur10 = robots["scenarios"]
    assert ur10["reached_only_by_reference"] == 0 and 0 < ur10["reached_only_by_this"] < ur5["reachable"]
    assert robots["reached_by_any"] == robots["count"]
    placement = run_study(STUDIES / "what-if-placement.toml", cycles=5).map.summary()
    for moved in placement["scenarios"][1:]:
        assert moved["reached_only_by_reference"] > 0
        assert moved["RP_l_ratio"]["min"] < 0.5 < 2 < moved["RP_l_ratio"]["max"]
    assert all(count > 0 for count in placement["wins"].values())
