"""Large maps: heat maps, the 3-D scene and the report show every k-th target; the tables keep all."""

import numpy as np
import pytest

from test_workspace import gantry_map_study
from tribokin import run_study
from tribokin.output import map_scene_layers, write_results
from tribokin.viz.maps import shown_targets


@pytest.fixture(scope="module")
def gantry_map():
    study = gantry_map_study()
    study["map"]["resolution"] = [9, 7]  # 7 rows (v) x 9 columns (u)
    return run_study(study).map


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
    monkeypatch.setattr("tribokin.output.SCENE_TARGETS", 12)
    layer = map_scene_layers(gantry_map)[gantry_map.reference.name]
    assert layer.stride == 3 and len(layer.points_m) == 9  # 3 x 3 of 7 x 9
    shown = gantry_map.grid.every((3, 3, 3)).ravel()
    np.testing.assert_array_equal(layer.points_m, gantry_map.positions_m[shown])
    np.testing.assert_array_equal(layer.values_um, gantry_map.reference.figure("RP_l_um")[shown])


def test_report_of_a_thinned_map_says_so_and_its_table_keeps_every_target(gantry_map, monkeypatch, tmp_path):
    monkeypatch.setattr("tribokin.output.SCENE_TARGETS", 12)
    monkeypatch.setattr("tribokin.viz.maps.PANEL_TARGETS", 4)
    result = run_study(gantry_map_study() | {"map": {**gantry_map_study()["map"], "resolution": [9, 7]}})
    out = write_results(result, tmp_path / "out", report="light")
    report = (out / "report.html").read_text()
    assert "1 in 3 targets along each grid axis" in report and "9 / 9" in report
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
