"""Large maps: heat maps, the 3-D scene and the report show every k-th target; the tables keep all."""

import json

import numpy as np
import pytest

from helpers.map_studies import gantry_map_study
from tribokin import run_study
from tribokin.output.writers import write_results
from tribokin.viz.contents import map_scene_layers
from tribokin.viz.maps import shown_targets


@pytest.fixture(scope="module")
def gantry_result():
    study = gantry_map_study()
    study["map"]["resolution"] = [9, 7]  # 7 rows (v) x 9 columns (u)
    return run_study(study)


@pytest.fixture(scope="module")
def gantry_map(gantry_result):
    return gantry_result.map


def test_heat_maps_show_every_target_up_to_their_limit_then_every_kth(gantry_map, monkeypatch):
    shown, strides = shown_targets(gantry_map.grid)
    assert strides == (1, 1, 1) and shown.shape == (1, 7, 9)
    monkeypatch.setattr("tribokin.viz.maps.PANEL_TARGETS", 4)
    shown, strides = shown_targets(gantry_map.grid)
    assert strides == (1, 3, 3) and shown.shape == (1, 3, 3)  # rows 0, 3, 6; columns 0, 3, 6
    np.testing.assert_array_equal(shown[0], [[0, 3, 6], [27, 30, 33], [54, 57, 60]])


def test_scene_layers_hold_at_most_their_limit_with_the_values_of_the_targets_shown(gantry_map, monkeypatch):
    full = map_scene_layers(gantry_map)[gantry_map.reference.name]
    assert full.stride == 1 and len(full.points_m) == 63
    monkeypatch.setattr("tribokin.viz.contents.SCENE_TARGETS", 12)
    layer = map_scene_layers(gantry_map)[gantry_map.reference.name]
    assert layer.stride == 3 and len(layer.points_m) == 9  # 3 x 3 of 7 x 9
    shown = gantry_map.grid.every((3, 3, 3)).ravel()
    np.testing.assert_array_equal(layer.points_m, gantry_map.positions_m[shown])
    np.testing.assert_array_equal(layer.values_um, gantry_map.reference.figure("RP_l_um")[shown])


def test_report_of_a_thinned_map_says_so_and_its_table_keeps_every_target(gantry_result, monkeypatch, tmp_path):
    monkeypatch.setattr("tribokin.viz.contents.SCENE_TARGETS", 12)
    monkeypatch.setattr("tribokin.viz.maps.PANEL_TARGETS", 4)
    out = write_results(gantry_result, tmp_path / "out", report="light")
    report = (out / "report.html").read_text()
    assert "the scene covers 1 in 3 targets along each grid axis" in report
    summary = json.loads((out / "summary.json").read_text())["map"]  # the exact figures, not the 9 targets drawn
    assert summary["count"] == 63
    spread = "".join(f"<td>{summary['RP_l_um'][key]:.3f}</td>" for key in ("min", "median", "max"))
    engines = f'<td class="text">first-order {summary["reachable"]}</td>'  # a gantry's first-order model is exact
    assert f"<td>{summary['reachable']} / 63</td>{spread}{engines}<td>0, 0</td></tr>" in report
    assert len((out / "map.csv").read_text().splitlines()) == 1 + 63


def test_colour_scales_keep_the_centre_in_the_middle():
    from tribokin.viz.maps import value_norm

    straddling = value_norm(np.array([0.5, 1.0, 3.0, np.nan]), centre=1.0)
    assert (straddling(0.5), straddling(1.0), straddling(3.0)) == pytest.approx((0.0, 0.5, 1.0))
    below = value_norm(np.array([0.25, 0.65]), centre=1.0)  # all better than the reference: none white
    assert (below(0.25), below(1.0), below(1.75)) == pytest.approx((0.0, 0.5, 1.0))
    plain = value_norm(np.array([2.0, 4.0]))
    assert (plain(2.0), plain(4.0)) == pytest.approx((0.0, 1.0))
    assert value_norm(np.array([1.0, 1.0]), centre=1.0)(1.0) == pytest.approx(0.0, abs=1e-6)


def plane_grid(origin_m, axis_u, axis_v, u_values, v_values):
    from tribokin.maps.grid import GridAxis, TargetGrid

    return TargetGrid("plane", (GridAxis("u", "m", np.array(u_values)), GridAxis("v", "m", np.array(v_values)), None),
                      None, np.zeros(3), np.array(origin_m, dtype=float),
                      np.array([axis_u, axis_v, [0, 0, 0]], dtype=float))


def test_plane_heat_maps_are_labelled_in_world_frame_coordinates_and_mark_the_base():
    from tribokin.viz.maps import BaseMark, panel_frame

    # a horizontal plane at z = 0.1 m: u along +y, v along -x; offsets u -0.6..0.6, v -0.2..0.6 (steps 0.2)
    grid = plane_grid([0.0, 0.0, 0.1], [0, 1, 0], [-1, 0, 0], np.linspace(-0.6, 0.6, 7), np.linspace(-0.2, 0.6, 5))
    frame = panel_frame(grid, *grid.axes[:2])
    assert (frame.xlabel, frame.ylabel, frame.plane) == ("y (world) [m]", "x (world) [m]", "z (world) = 0.1 m")
    # y = u from -0.6 to 0.6; x = -v from 0.2 down to -0.6; cells 0.2 wide around each target
    assert frame.extent == pytest.approx((-0.7, 0.7, 0.3, -0.7))
    assert frame.bases == (BaseMark("robot base", (0.0, 0.0, 0.0), (0.0, 0.0)),)

    away = plane_grid([0.2, -0.5, 0.3], [1, 0, 0], [0, 0, 1], [0.0, 0.2, 0.4], [0.0, 0.1])
    frame = panel_frame(away, *away.axes[:2])
    assert (frame.xlabel, frame.ylabel, frame.plane) == ("x (world) [m]", "z (world) [m]", "y (world) = -0.5 m")
    assert frame.extent == pytest.approx((0.1, 0.7, 0.25, 0.45))  # x 0.2..0.6, z 0.3..0.4
    assert frame.bases == (BaseMark("robot base", (0.0, 0.0, 0.0), None),)  # the base (x 0, z 0) lies outside

    # an oblique axis keeps the offset u from the origin; the base lies 0.5 m behind the origin along it
    oblique = plane_grid([0.3, 0.4, 0.5], [0.6, 0.8, 0], [0, 0, 1], [-1.0, 1.0], [-1.0, 0.0])
    frame = panel_frame(oblique, *oblique.axes[:2])
    assert frame.xlabel == "u [m] along (0.6, 0.8, 0) from (0.3, 0.4, 0.5) m (world)"
    assert frame.ylabel == "z (world) [m]"
    assert frame.bases[0].at == pytest.approx((-0.5, 0.0)) and frame.extent == pytest.approx((-2.0, 2.0, -1.0, 1.0))


def test_box_and_joint_grids_keep_their_axes():
    from tribokin.maps.grid import GridAxis, TargetGrid
    from tribokin.viz.maps import panel_frame

    box = TargetGrid("box", (GridAxis("x", "m", np.array([-0.2, 0.2])), GridAxis("y", "m", np.array([-0.1, 0.3])),
                             GridAxis("z", "m", np.array([0.5]))), None, np.zeros(3), np.zeros(3), np.eye(3))
    frame = panel_frame(box, *box.axes[:2])
    assert (frame.xlabel, frame.ylabel, frame.plane, frame.layer) == ("x (world) [m]", "y (world) [m]", "",
                                                                      "z (world)")
    assert frame.extent == pytest.approx((-0.4, 0.4, -0.3, 0.5)) and frame.bases[0].at == (0.0, 0.0)
    joint = TargetGrid("joint", (GridAxis("shoulder", "rad", np.array([0.0, 1.0])), None, None), None, np.zeros(2))
    frame = panel_frame(joint, joint.axes[0], None)
    assert (frame.xlabel, frame.ylabel, frame.bases) == ("shoulder [rad]", None, ())


#: A UR5 placed at (0.3, 0.2, 0) m and turned 30° about the world's z, mapped over a horizontal plane around its base
#: (the middle target, right over the base, out of reach).
PLACED_XYZ_M, PLACED_RPY_DEG = [0.3, 0.2, 0.0], [0.0, 0.0, 30.0]
PLACED = {
    "study": {"name": "placed", "cycles": 10, "seed": 3},
    "robot": {"name": "ur5", "base_xyz_m": PLACED_XYZ_M, "base_rpy_deg": PLACED_RPY_DEG},
    "joints": {"friction": {"preset": "42CD4-treated"}, "stiffness": 1.0e5},
    "map": {"kind": "plane", "origin_m": [0.3, 0.2, 0.1], "axis_u": [1, 0, 0], "axis_v": [0, 1, 0],
            "extent_u_m": [-0.5, 0.5], "extent_v_m": [-0.5, 0.5], "resolution": [3, 3], "rpy_deg": [180, 0, 90]},
}


def test_the_heat_maps_mark_a_placed_base_where_it_is_and_name_world_axes():
    """The marker sits at robot.base_xyz_m's x and y (main's code drew it at the world's origin, (0, 0))."""
    from tribokin.viz.maps import map_figures_drawn

    workspace_map = run_study(PLACED).map
    assert not workspace_map.reachable[4] and workspace_map.reachable.sum() == 8  # the grey hole over the base
    for name, figure in map_figures_drawn(workspace_map, "placed").items():
        panel = figure.axes[0]
        (marker,) = panel.lines
        assert np.array(marker.get_data()).ravel().tolist() == PLACED_XYZ_M[:2], name
        assert [text.get_text() for text in panel.texts] == ["robot base"]
        assert (panel.get_xlabel(), panel.get_ylabel(), panel.get_title()) == (
            "x (world) [m]", "y (world) [m]", "plane z (world) = 0.1 m")


def test_a_turned_base_is_projected_onto_an_oblique_panel_and_one_outside_is_named():
    """A vertical plane along the turned base's own x axis, 0.4 m out and 0.3 m up: the base's origin lies
    0.4 m behind the plane's origin along u (scipy's rotation of the study's numbers, not tribokin's), at the world's
    z = 0 (a world axis shows its world coordinate)."""
    from scipy.spatial.transform import Rotation

    from tribokin.maps.grid import make_grid
    from tribokin.study.assembly import load_robot
    from tribokin.study.reading import load_study
    from tribokin.viz.maps import grid_image, panel_frame

    turn = Rotation.from_euler("xyz", PLACED_RPY_DEG, degrees=True).as_matrix()
    along = turn @ [1.0, 0.0, 0.0]
    origin = np.array(PLACED_XYZ_M) + turn @ [0.4, 0.0, 0.3]
    study = load_study({**PLACED, "map": {"kind": "plane", "origin_m": origin.tolist(), "axis_u": along.tolist(),
                                          "axis_v": [0, 0, 1], "extent_u_m": [-0.6, 0.2], "extent_v_m": [-0.4, 0.2],
                                          "resolution": [5, 4]}})
    robot = load_robot(study, meshes=False)
    grid = make_grid(robot, study.map)
    frame = panel_frame(grid, *grid.axes[:2])
    offset = np.array(PLACED_XYZ_M) - origin
    assert frame.bases[0].at == pytest.approx((offset @ along, PLACED_XYZ_M[2]), abs=1e-12)
    assert frame.bases[0].at == pytest.approx((-0.4, 0.0), abs=1e-12)
    assert frame.xlabel.startswith("u [m] along (0.866, 0.5, 0) from") and frame.xlabel.endswith(" m (world)")
    assert frame.ylabel == "z (world) [m]"

    study = load_study({**PLACED, "map": {**PLACED["map"], "origin_m": [1.0, 1.0, 0.1], "extent_u_m": [0.0, 0.2],
                                          "extent_v_m": [0.0, 0.2]}})
    grid = make_grid(robot, study.map)
    assert panel_frame(grid, *grid.axes[:2]).bases[0].at is None
    figure = grid_image(grid, lambda shown: np.ones(len(shown)), "RP_l [µm]", "far")
    assert "robot base at (0.3, 0.2, 0) m (world), outside the panels" in figure.get_suptitle()
    assert not figure.axes[0].lines


def test_a_scenario_with_another_base_marks_its_own_and_comparisons_mark_both(monkeypatch, tmp_path):
    from tribokin.viz import maps

    study = gantry_map_study()
    study["map"]["resolution"] = [3, 2]
    study["scenarios"] = [{"name": "here"}, {"name": "moved", "robot": {"base_xyz_m": [0.05, -0.1, 0.0]}},
                          {"name": "same", "joints": {"friction": {"law": "constant", "mu": 0.03}}}]
    workspace_map = run_study(study).map
    saved = {}
    monkeypatch.setattr(maps, "save_grid_image", lambda grid, values, path, label, title, **options:
                        saved.update({path.name: options.get("bases")}))
    maps.save_map_figures(workspace_map, tmp_path, "study")
    as_lists = {name: None if bases is None else {k: v.tolist() for k, v in bases.items()}
                for name, bases in saved.items()}
    assert as_lists["map_RP_l.png"] is None  # the reference's grid's own base, at the origin
    assert as_lists["map_RP_l_moved.png"] == {"robot base": [0.05, -0.1, 0.0]}
    assert as_lists["map_RP_l_same.png"] == {"robot base": [0.0, 0.0, 0.0]}
    both = {"here base": [0.0, 0.0, 0.0], "moved base": [0.05, -0.1, 0.0]}
    assert as_lists["map_RP_l_ratio_moved.png"] == as_lists["map_RP_l_diff_moved.png"] == both
    assert as_lists["map_RP_l_ratio_same.png"] == {"robot base": [0.0, 0.0, 0.0]}
    assert as_lists["map_winner.png"] == {"here, same base": [0.0, 0.0, 0.0], "moved base": [0.05, -0.1, 0.0]}


@pytest.fixture(scope="module")
def scenario_map():
    study = gantry_map_study()
    study["joints"]["friction"] = {"law": "uniform", "low": 0.1, "high": 0.14}  # each direction's cloud spreads
    study["scenarios"] = [{"name": "raw"}, {"name": "low", "joints": {"friction": {"law": "uniform", "low": 0.025,
                                                                                  "high": 0.035}}},
                          {"name": "high", "joints": {"friction": {"law": "uniform", "low": 0.25, "high": 0.35}}}]
    return run_study(study).map


def test_rp_l_maps_of_all_scenarios_share_one_colour_scale_and_ratios_keep_their_own(scenario_map, monkeypatch,
                                                                                    tmp_path):
    from tribokin.viz import maps

    workspace_map = scenario_map
    values = [s.figure("RP_l_um") for s in workspace_map.scenarios.values()]
    norm = maps.rp_l_norm(workspace_map)
    assert (norm.vmin, norm.vmax) == (min(np.nanmin(v) for v in values), max(np.nanmax(v) for v in values))
    assert norm.vmin == np.nanmin(values[1]) and norm.vmax == np.nanmax(values[2])  # from two other scenarios
    saved, titles = {}, {}
    monkeypatch.setattr(maps, "save_grid_image", lambda grid, values, path, label, title, **options:
                        saved.update({path.name: options}) or titles.update({path.name: title}))
    maps.save_map_figures(workspace_map, tmp_path, "study")
    for name in ("map_RP_l.png", "map_RP_l_low.png"):  # bidirectional: the titles say which direction's RP_l
        assert "RP_l (the larger of the + and − approach directions')" in titles[name]
    rp_l = [saved[name]["norm"] for name in ("map_RP_l.png", "map_RP_l_low.png", "map_RP_l_high.png")]
    assert all((n.vmin, n.vmax) == (norm.vmin, norm.vmax) for n in rp_l)
    assert saved["map_RP_l_ratio_low.png"].get("norm") is None and saved["map_RP_l_ratio_low.png"]["centre"] == 1.0


def test_map_figures_come_in_reading_order(scenario_map):
    from tribokin.viz.maps import map_figure_names

    assert map_figure_names(scenario_map) == [  # the directional figures' by default, after the test's
        "map_RP_l.png", "map_dominant_joint.png", "map_RP_l_hi.png", "map_vAP_p.png", "map_RP_l_multi.png",
        "map_RP_l_low.png", "map_RP_l_high.png",
        "map_RP_l_ratio_low.png",
        "map_RP_l_ratio_high.png", "map_RP_l_diff_low.png", "map_RP_l_diff_high.png", "map_winner.png"]


def test_a_directional_maps_scene_has_its_figures_as_layers_each_quantity_on_its_own_scale():
    """vAP_p and RP_l_multi are tens of times RP_l: on RP_l's scale they would all look alike, so each quantity has
    its own colour scale (and colour bar)."""
    from tribokin.study.assembly import load_robot
    from tribokin.study.reading import load_study
    from tribokin.viz.scene import build_scene
    from tribokin.viz.static import static_visualizer

    study = gantry_map_study()
    study["map"].update(resolution=[5, 4], directional=True)
    workspace_map = run_study(study).map
    layers = map_scene_layers(workspace_map)
    name = workspace_map.reference.name
    assert list(layers) == [name, f"{name} vAP_p", f"{name} RP_l_multi"]
    np.testing.assert_array_equal(layers[f"{name} vAP_p"].values_um, workspace_map.reference.figure("vAP_p_um"))
    robot = load_robot(load_study(study))
    info = build_scene(static_visualizer(), robot, workspace_map.first_reachable_q(), [], layers, variant="light")
    assert list(info.colour_scales) == ["RP_l", "vAP_p", "RP_l_multi"]
    for quantity, scale in info.colour_scales.items():
        values = np.concatenate([layer.values_um for layer in layers.values() if layer.quantity == quantity])
        assert (scale.low_um, scale.high_um) == (np.nanmin(values), np.nanmax(values))


@pytest.fixture(scope="module")
def two_robots():
    """A UR5 plane whose far edge only the UR10 of the second scenario reaches."""
    from helpers.map_studies import UR5_PLANE

    return run_study({**UR5_PLANE, "scenarios": [{"name": "ur5"}, {"name": "ur10", "robot": {"name": "ur10"}}]})


def test_comparisons_with_another_robot_mark_the_targets_one_robot_reaches_and_the_winner_says_among_which(
        two_robots, monkeypatch, tmp_path):
    from matplotlib.image import imread

    from tribokin.viz import maps

    workspace_map = two_robots.map
    saved, looked_at = {}, "map_RP_l_ratio_ur10.png"
    real = maps.save_grid_image
    # the figure whose pixels are looked at below is drawn; the others' options are recorded (the next test's report
    # draws them all)
    monkeypatch.setattr(maps, "save_grid_image", lambda grid, values, path, label, title, **options:
                        saved.update({path.name: (values, options)})
                        or (path.name == looked_at and real(grid, values, path, label, title, **options)))
    maps.save_map_figures(workspace_map, tmp_path, "study")
    everything = np.arange(workspace_map.grid.size)
    reached_by = workspace_map.reached_by(workspace_map.scenarios["ur10"], everything)
    for name in ("map_RP_l_ratio_ur10.png", "map_RP_l_diff_ur10.png"):
        marks = saved[name][1]["marks"]
        assert marks.labels == ("reached by ur10 only", "reached by ur5 only")
        np.testing.assert_array_equal(marks.values(everything),
                                      np.select([reached_by == 1, reached_by == 2], [0, 1], -1))
        assert saved[name][1]["grey"] == "reached by neither"
    assert (reached_by == 1).any()  # the UR10 reaches the far edge, the UR5 does not: drawn in gold
    pixels = imread(tmp_path / looked_at)[..., :3]
    assert np.all(np.abs(pixels - np.array([1.0, 0xd7 / 255, 0.0])) < 0.01, axis=-1).sum() > 1000
    winner_values, winner = saved["map_winner.png"]
    assert winner["grey"] == "reached by no scenario"
    np.testing.assert_array_equal(winner_values(everything)[reached_by == 1], 1)  # won by the UR10, which alone reaches
    assert "marks" not in saved["map_RP_l_ur10.png"][1]


def test_the_report_says_which_robot_each_scenario_used_and_what_each_reaches(two_robots, tmp_path):
    out = write_results(two_robots, tmp_path / "out", report="light")
    report = (out / "report.html").read_text()
    summary = json.loads((out / "summary.json").read_text())
    assert [s.get("robot") for s in summary["study"]["scenarios"]] == [None, "ur10"]
    assert summary["study"]["scenarios"][1]["robot_spec"]["name"] == "ur10"
    assert "<th>robot</th>" in report and "<td>ur5 (the study&#x27;s)</td>" in report and "<td>ur10</td>" in report
    for scenario in summary["map"]["scenarios"]:
        assert f"<td>{scenario['name']}</td><td>{scenario['reachable']} / {summary['map']['count']}</td>" in report
    assert summary["map"]["scenarios"][1]["reachable"] > summary["map"]["scenarios"][0]["reachable"]


def compared_scenarios_map():
    """The axis's joint map (3 targets, 10 cycles) whose friction runs in and is correlated, new against 5 000 cycles
    of age, for a reference and a stiffer scenario (``map.compare``)."""
    from conftest import axis_study

    study = axis_study(friction={"preset": "42CD4-raw", "ar1": 0.5, "run_in": {"start": 0.3, "tau_cycles": 20}},
                       stiffness=2.0e6)
    study["study"]["cycles"] = 10
    study["map"] = {"kind": "joint", "joints": ["x"], "ranges": [[0.1, 0.3]], "counts": [3], "directional": False,
                    "state": {"age_cycles": 0}, "compare": {"age_cycles": 5000}}
    study["scenarios"] = [{"name": "raw"}, {"name": "stiff", "joints": {"stiffness": 4.0e6}}]
    return run_study(study)


def test_every_scenario_of_a_map_comparing_two_states_has_its_change_maps_on_one_scale(monkeypatch, tmp_path):
    """``map.compare`` with scenarios: the reference's change maps and each other scenario's
    (``map_<change>_<scenario>.png``, after the ratios and differences), each change's maps on one colour scale
    centred on 0 over every scenario's values, drawing each scenario's own changes; the report shows them in that
    order."""
    from tribokin.viz import maps

    result = compared_scenarios_map()
    workspace_map = result.map
    assert maps.map_figure_names(workspace_map) == [
        "map_RP_l.png", "map_dominant_joint.png", "map_RP_l_hi.png", "map_RP_l_change.png", "map_AP_p_change.png",
        "map_RP_l_stiff.png", "map_RP_l_ratio_stiff.png", "map_RP_l_diff_stiff.png", "map_RP_l_change_stiff.png",
        "map_AP_p_change_stiff.png", "map_winner.png"]
    drawn = {}
    monkeypatch.setattr(maps, "save_grid_image", lambda grid, values, path, label, title, **options:
                        drawn.update({path.name: (values(np.arange(3)), title, options)}))
    maps.save_map_figures(workspace_map, tmp_path, "study")
    reference, stiff = workspace_map.scenarios.values()
    for name, file in (("RP_l_change_um", "RP_l_change"), ("AP_p_change_um", "AP_p_change")):
        values = np.concatenate([reference.change_figure(name), stiff.change_figure(name)])
        assert np.all(values < 0) and not np.array_equal(*np.split(values, 2))  # run in: less, by the stiffness
        np.testing.assert_array_equal(drawn[f"map_{file}.png"][0], reference.change_figure(name))
        np.testing.assert_array_equal(drawn[f"map_{file}_stiff.png"][0], stiff.change_figure(name))
        norms = [drawn[f][2]["norm"] for f in (f"map_{file}.png", f"map_{file}_stiff.png")]
        assert all((n.vmin, n.vmax) == (values.min(), -values.min()) for n in norms)  # all below 0: centred on it
        assert all("(colour scale shared by all scenarios)" in drawn[f][1]
                   for f in (f"map_{file}.png", f"map_{file}_stiff.png"))
        assert ", stiff " in drawn[f"map_{file}_stiff.png"][1]
    monkeypatch.undo()
    out = write_results(result, tmp_path / "out", report="light")
    page = (out / "report.html").read_text(encoding="utf-8")
    shown = [name for name in maps.map_figure_names(workspace_map) if f"<h3>{name}</h3>" in page]
    assert shown == maps.map_figure_names(workspace_map) and (out / "map_AP_p_change_stiff.png").stat().st_size > 5000
    header = (out / "map_stiff.csv").read_text().splitlines()[0].split(",")
    assert {"RP_l_change_um", "RP_l_change_mc_error_um", "RP_l_change_engine_bound_um"} <= set(header)
    summary = json.loads((out / "summary.json").read_text(encoding="utf-8"))["map"]
    spreads = [" / ".join(f"{summary[name][key]:.3f}" for key in ("min", "median", "max"))
               for name in ("RP_l_change_um", "AP_p_change_um")]
    computed = summary["computed"]["raw"]  # what the reference's changes rest on, as the command prints it
    rests_on = ", ".join(f"{stem} {computed[f'{stem}_change_max_mc_error_um']:.3g} / "
                         f"{computed[f'{stem}_change_max_engine_bound_um']:.3g}" for stem in ("RP_l", "AP_p"))
    assert (f"<p>Change from map.state to map.compare (the first scenario), min / median / max [µm]: RP_l "
            f"{spreads[0]}, AP_p {spreads[1]}; largest Monte Carlo standard error / engine bound [µm]: {rests_on}.</p>"
            ) in page
