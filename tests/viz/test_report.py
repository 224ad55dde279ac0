"""report.html: self-contained (no network), with the colour bar, tables and figures; scene.npz round trip."""

import base64
import copy
import re

import numpy as np
import pytest

from conftest import ROOT, axis_study
from helpers.map_studies import gantry_map_study
from helpers.viz_layers import CUBE, UNIFORM_AXIS, grid_layers
from tribokin.output.writers import write_results
from tribokin.run import run_study
from tribokin.viz.maps import map_figure_names
from tribokin.viz.report import input_values, joint_table, write_report
from tribokin.viz.scene_file import load_scene_inputs

NETWORK = re.compile(r"""(src|href)\s*=\s*["']?\s*(https?:)?//|url\(\s*["']?(https?:)?//"""
                     r"""|@import|fetch\(\s*["']https?:""", re.IGNORECASE)


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    out = tmp_path_factory.mktemp("report") / "out"
    result = run_study(copy.deepcopy(UNIFORM_AXIS))
    write_results(result, out, map_layers=grid_layers(), cube=CUBE)
    return out, result


def test_report_has_colour_bar_tables_and_figures(written):
    out, result = written
    page = (out / "report.html").read_text(encoding="utf-8")
    assert "RP_l [µm]" in page and "1.000 µm" in page and "8.000 µm" in page  # colour bar range
    assert "unreachable target" in page
    row = result.poses[0].direction_rows()[0]
    assert f"{row['RP_l_um']:.3f}" in page and f"{row['AP_p_um']:.3f}" in page and "RP_a [mdeg]" in page
    assert "<td>P1</td><td>+</td>" in page and "RP_l all directions [µm]" in page
    assert "Map statistics" not in page  # layers drawn, but no map among the results to give statistics of
    pngs = re.findall(r'src="data:image/png;base64,([^"]+)"', page)
    assert [base64.b64decode(p) for p in pngs] == [(out / "field_P1.png").read_bytes()]
    magnification = float(np.load(out / "scene.npz")["magnification"])
    assert f"×{magnification:g}" in page


def test_the_legend_and_the_iso_table_follow_the_scene_before_the_inputs(written):
    """Read without scrolling far: the colour bars and the ISO table come right after the 3-D view."""
    page = (written[0] / "report.html").read_text(encoding="utf-8")
    order = [page.index(part) for part in ('<iframe title="3-D scene"', "<h2>RP_l maps</h2>",
                                           "<h2>ISO 9283 figures per pose</h2>", "<h2>Inputs</h2>", "<h2>Figures</h2>")]
    assert order == sorted(order)


def test_two_identical_runs_write_the_same_bytes_report_included(written, tmp_path):
    out, _ = written
    write_results(run_study(copy.deepcopy(UNIFORM_AXIS)), tmp_path / "again", map_layers=grid_layers(), cube=CUBE)
    names = sorted(p.name for p in out.iterdir())
    assert names == sorted(p.name for p in (tmp_path / "again").iterdir()) and "report.html" in names
    for name in names:
        assert (tmp_path / "again" / name).read_bytes() == (out / name).read_bytes(), name


def test_report_makes_no_network_request(written):
    out, _ = written
    page = (out / "report.html").read_text(encoding="utf-8")
    srcdoc = re.search(r'srcdoc="([^"]*)"', page).group(1)
    assert "MeshCat.Viewer" in srcdoc and len(srcdoc) > 500_000  # the viewer is inlined, not linked
    assert not NETWORK.search(page.replace(srcdoc, "")), NETWORK.search(page.replace(srcdoc, ""))
    assert not NETWORK.search(srcdoc.replace("&quot;", '"').replace("&amp;", "&"))
    assert not [p for p in out.iterdir() if p.name.startswith(".")]  # no temporary file left


def test_scene_inputs_round_trip(written):
    out, result = written
    inputs = load_scene_inputs(out)
    assert list(inputs.map_layers) == ["baseline", "treated"]
    for label, layer in grid_layers().items():
        np.testing.assert_array_equal(inputs.map_layers[label].points_m, layer.points_m)
        np.testing.assert_array_equal(inputs.map_layers[label].values_um, layer.values_um)
    assert inputs.cube == CUBE
    np.testing.assert_array_equal(inputs.poses[0].positions_m, result.poses[0].positions_m)
    np.testing.assert_array_equal(inputs.q, result.poses[0].q)
    assert inputs.robot.joint_names == result.robot.joint_names


def test_the_inputs_show_a_tool_offset_and_a_view_loads_the_robot_with_its_tool_point(tmp_path):
    study = axis_study()
    study["robot"]["tool_offset_m"] = [0.0, 0.0, 0.1]
    result = run_study(study)
    assert input_values(result)["tool point offset"] == "(0, 0, 0.1) m, roll, pitch, yaw (0, 0, 0)° in tool"
    assert "tool point offset" not in input_values(run_study(axis_study()))
    write_results(result, tmp_path / "out", report="light")
    assert "<th>tool point offset</th>" in (tmp_path / "out" / "report.html").read_text(encoding="utf-8")
    robot = load_scene_inputs(tmp_path / "out").robot
    assert robot.tool_frame == "tool_tool_point"
    assert robot.tool_placement([0.2]).translation == pytest.approx(result.poses[0].commanded_position_m)


def test_report_none_writes_neither_report_nor_scene(tmp_path):
    write_results(run_study(copy.deepcopy(UNIFORM_AXIS)), tmp_path / "out", report="none")
    assert (tmp_path / "out" / "summary.json").exists()
    assert not (tmp_path / "out" / "report.html").exists() and not (tmp_path / "out" / "scene.npz").exists()


def test_light_report_of_ur5_is_far_smaller_than_full(tmp_path):
    study = {"robot": {"name": "ur5"},
             "joints": {"friction": {"preset": "42CD4-raw"}, "stiffness": 2e5, "normal_force_N": 200.0},
             "poses": [{"q": [0.0, -1.2, 1.4, -1.8, -1.57, 0.0]}]}
    result = run_study(study, cycles=10)
    full, _ = write_report(result, result.robot, tmp_path, variant="full")
    full_size = full.stat().st_size
    light, _ = write_report(result, result.robot, tmp_path, variant="light")
    assert light.stat().st_size < 0.3 * full_size
    assert 1.2e6 < light.stat().st_size and full_size > 5e6


#: the gantry through a path with "..", two scenarios (one heavier), and 5 kg payload
SCENARIO_STUDY = gantry_map_study(friction={"law": "uniform", "low": 0.1, "high": 0.14}) | {"scenarios": [
    {"name": "raw"}, {"name": "heavy", "robot": {"payload_kg": 8.0},
                      "joints": {"z": {"friction": {"law": "constant", "mu": 0.05}}}}]}
SCENARIO_STUDY["robot"] = {**SCENARIO_STUDY["robot"],
                           "urdf": str(ROOT / "tests" / ".." / "urdf" / "cartesian_xyz.urdf")}


@pytest.fixture(scope="module")
def map_only(tmp_path_factory):
    result = run_study(copy.deepcopy(SCENARIO_STUDY))
    out = write_results(result, tmp_path_factory.mktemp("map") / "out", report="light")
    return (out / "report.html").read_text(encoding="utf-8"), result


def test_report_shows_the_inputs_with_normalised_paths(map_only):
    page, _ = map_only
    for row in ("<th>robot</th><td>" + str((ROOT / "urdf" / "cartesian_xyz.urdf").resolve()) + "</td>",
                "<th>tool frame</th><td>tool</td>", "<th>payload</th><td>5 kg</td>",
                "<th>cycles</th><td>10 per map target</td>", "<th>approach</th><td>bidirectional</td>",
                "<th>map targets</th><td>plane through (0.2, 0, 0.3) m: u along (1, 0, 0) 0 to 0.7 m (8 values); "
                "v along (0, 1, 0) 0 to 0.6 m (4 values)</td>"):
        assert row in page
    assert "/../" not in page.split("<iframe")[0]
    # the gantry's three prismatic joints share one model: stiffness, loads from statics, bearing span, law
    assert ('<td>x, y, z</td><td>prismatic</td><td>2e7 N/m</td><td>from statics</td><td>–</td>'
            '<td>0.2 m</td><td>0 m</td><td>0 m</td><td>0 m</td><td class="text">uniform (low 0.1, high 0.14): '
            'mean 0.12, std 0.0115</td>') in page
    assert '<td>heavy</td><td class="text">robot.payload_kg = 8.0\njoints.z.friction.law = &quot;constant&quot;' \
           '\njoints.z.friction.mu = 0.05</td>' in page
    assert '<td>raw</td><td class="text">none: the study as written</td>' in page


def test_map_statistics_are_those_of_summary_json(map_only):
    page, result = map_only
    summary = result.map.summary()
    assert "<p>Approached from both directions: RP_l, its band, AP_p and RP_a/b/c: the larger of the + and - " in page
    raw, heavy = (s["RP_l_um"] for s in summary["scenarios"])
    for name, spread, change in (("raw", raw, "+0.0 %"),
                                 ("heavy", heavy, f"{100 * (heavy['median'] / raw['median'] - 1):+.1f} %")):
        cells = "".join(f"<td>{spread[key]:.3f}</td>" for key in ("min", "median", "max"))
        computed = summary["computed"][name]
        engines = ", ".join(f"{engine} {count}" for engine, count in computed["engine_targets"].items() if count)
        bounds = f"{computed['engine_max_deviation_nm']:.3g}, {computed['engine_max_angle_deviation_nrad']:.3g}"
        assert (f"<td>{name}</td><td>{summary['reachable']} / {summary['count']}</td>{cells}<td class=\"text\">"
                f"{engines}</td><td>{bounds}</td><td>{change}</td>") in page


def test_map_only_report_has_no_pose_table_and_no_cloud_magnification(map_only):
    page, _ = map_only
    assert "ISO 9283 figures per pose" not in page and "RP_l [µm]</th><th>AP_p" not in page
    assert "clouds" not in page.split("<iframe")[0] and "magnified" not in page


def test_figures_come_in_reading_order_poses_in_study_order_first(map_only, tmp_path):
    page, result = map_only
    assert re.findall(r"<h3>([^<]+\.png)</h3>", page) == map_figure_names(result.map)
    study = copy.deepcopy(SCENARIO_STUDY) | {"poses": [{"name": "P2", "q": [0.1, 0.2, 0.1]},
                                                       {"name": "P10", "q": [0.2, 0.2, 0.1]}]}
    study["map"]["resolution"] = [2, 2]
    result = run_study(study)
    page = (write_results(result, tmp_path / "out", report="light") / "report.html").read_text(encoding="utf-8")
    assert re.findall(r"<h3>([^<]+\.png)</h3>", page) == ["field_P2.png", "field_P10.png", "map_RP_l.png",
                                                          "map_dominant_joint.png", "map_RP_l_hi.png",
                                                          "map_vAP_p.png", "map_RP_l_multi.png",  # by default
                                                          "map_RP_l_heavy.png",
                                                          "map_RP_l_ratio_heavy.png", "map_RP_l_diff_heavy.png",
                                                          "map_winner.png"]


def test_the_joint_table_heads_its_law_column_by_what_the_laws_draw():
    study = axis_study(stiffness=2.0e6)
    mu = run_study(study).settings
    del study["joints"]["friction"]
    study["joints"]["friction_force_N"] = {"law": "constant", "value": 30.0}
    force = run_study(study).settings
    assert "friction coefficient μ" in joint_table(mu, [True]) and "friction law" not in joint_table(mu, [True])
    assert "friction law" in joint_table(force, [True]) and "friction_force_N" in joint_table(force, [True])
