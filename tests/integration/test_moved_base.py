"""A robot whose base moves in the world, with its targets, measures the same (maps and poses)."""

import numpy as np
import pytest

from tribokin import run_study
from tribokin.maps.schema import map_figures

T_M = np.array([1.25, -0.75, 0.4])
STUDY = {
    "study": {"name": "placed", "cycles": 30, "seed": 11},
    "robot": {"name": "ur5", "payload_kg": 2.0},
    "joints": {"friction": {"preset": "42CD4-treated"}, "stiffness": 1.0e5, "bearing_span_m": 0.08},
    "map": {"kind": "plane", "origin_m": [0.0, -0.5, 0.1], "axis_u": [0, -1, 0], "axis_v": [0, 0, 1],
            "extent_u_m": [-0.2, 0.45], "extent_v_m": [0.0, 0.3], "resolution": [9, 6]},
    "poses": [{"name": "P1", "q": [0.3, -1.2, 1.1, -0.4, 1.2, 0.1]}],
}


def moved(study, base_xyz_m, shift_m):
    """``study`` with the base at ``base_xyz_m`` and the map's origin moved by ``shift_m``."""
    return {**study, "robot": {**study["robot"], "base_xyz_m": list(base_xyz_m)},
            "map": {**study["map"], "origin_m": list(np.add(study["map"]["origin_m"], shift_m))}}


@pytest.mark.parametrize("statistic", ["expected", "one-test"])
def test_moving_the_base_and_the_grid_together_gives_the_same_map(statistic):
    study = {**STUDY, "map": {**STUDY["map"], "statistic": statistic}}
    here, there = run_study(study).map, run_study(moved(study, T_M, T_M)).map
    assert np.allclose(there.positions_m - T_M, here.positions_m, rtol=0, atol=1e-15)
    q_here, q_there = here.q, there.q
    reached = here.reachable & there.reachable
    assert reached.sum() >= 20 and np.array_equal(here.reachable, there.reachable)
    same = reached & (np.abs(q_here - q_there).max(axis=1) <= 1e-9)
    a, b = here.reference, there.reference
    if a.has("method"):
        same &= a.read("method") == b.read("method")
    assert same.sum() >= 0.9 * reached.sum()  # the others are counted: here at most a tenth
    names = [figure.name for figure in map_figures(a.figure_set)]
    figures_here, figures_there = a.figures[same], b.figures[same]
    scale = np.maximum(np.abs(figures_here), 1e-300)
    worst = np.nanmax(np.abs(figures_there - figures_here) / scale, axis=0)
    assert np.all(worst <= 1e-6), dict(zip(names, worst, strict=True))
    assert np.allclose(b.normal_forces_N[same], a.normal_forces_N[same], rtol=1e-9, atol=0)


def test_a_base_at_the_origin_written_out_gives_the_same_bytes(tmp_path):
    from tribokin.output.writers import write_results

    for name, study in (("unset", STUDY), ("zero", moved(STUDY, [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]))):
        write_results(run_study(study), tmp_path / name)
    for file in ("map.csv", "poses.csv"):
        assert (tmp_path / "unset" / file).read_bytes() == (tmp_path / "zero" / file).read_bytes()


def test_a_pose_of_a_placed_robot_measures_the_same_and_sits_where_the_base_puts_it():
    """Joint-space poses: a base moved (and turned about the world's z, along gravity) changes only where they are."""
    turned = {**STUDY, "robot": {**STUDY["robot"], "base_xyz_m": list(T_M), "base_rpy_deg": [0.0, 0.0, 75.0]}}
    del turned["map"]
    plain = {**STUDY}
    del plain["map"]
    here, there = run_study(plain).poses[0], run_study(turned).poses[0]
    figures_here, figures_there = (next(iter(p.report_row()["directions"].values())) for p in (here, there))
    for key in ("RP_l_um", "AP_p_um", "RP_c_mdeg"):  # about the world's axes: a and b turn with the yaw, c does not
        assert figures_there[key] == pytest.approx(figures_here[key], rel=1e-9)
    yaw = np.radians(75.0)
    rotation = np.array([[np.cos(yaw), -np.sin(yaw), 0], [np.sin(yaw), np.cos(yaw), 0], [0, 0, 1]])
    assert np.allclose(there.positions_m, here.positions_m @ rotation.T + T_M, rtol=0, atol=1e-12)
