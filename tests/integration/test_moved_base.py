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


@pytest.mark.parametrize(("statistic", "directional"), [("expected", True), ("one-test", False)])
def test_moving_the_base_and_the_grid_together_gives_the_same_map(statistic, directional):
    """Every column of map.csv's figures, the directional ones (vAP_p, RP_l_multi) included: a translation changes
    no direction of the world, so approaches along +x, +y, +z are the same joint motions."""
    study = {**STUDY, "map": {**STUDY["map"], "statistic": statistic, "directional": directional}}
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
    assert not directional or {"vAP_p_um", "RP_l_multi_um"} <= set(names)
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


def test_vap_p_of_a_turned_base_is_approached_along_the_worlds_axes():
    """The gantry turned 135° about z, constant μ: each prismatic joint's lost motion is μ N / k in the direction it
    travels (a joint that does not move: none). Along the world's +x the base's x and y joints both run backwards,
    along +y x forwards and y backwards, along +z only z, which carries no load: the +x and +y barycentres lie
    2 μ N_x / k apart, the farthest pair. Approached along the base's axes instead, vAP_p would be
    hypot(μ N_x / k, μ N_y / k) (what the unturned gantry gives), 0.51 of it."""
    from scipy.spatial.transform import Rotation

    from helpers.map_studies import MU, K, gantry_loads_by_hand, gantry_map_study

    t_m, yaw_deg = np.array([1.0, 0.5, 0.1]), 135.0
    turn = Rotation.from_euler("z", yaw_deg, degrees=True).as_matrix()
    study = gantry_map_study()
    study["study"]["approach"] = "unidirectional"
    study["robot"].update(base_xyz_m=t_m.tolist(), base_rpy_deg=[0.0, 0.0, yaw_deg])
    study["map"] = {"kind": "plane", "origin_m": (turn @ [0.3, 0.1, 0.3] + t_m).tolist(),
                    "axis_u": (turn @ [1, 0, 0]).tolist(), "axis_v": (turn @ [0, 1, 0]).tolist(),
                    "extent_u_m": [0.0, 0.4], "extent_v_m": [0.0, 0.4], "resolution": [2, 3], "directional": True}
    workspace_map = run_study(study).map
    assert workspace_map.reachable.all()
    in_base = (workspace_map.positions_m - t_m) @ turn  # the targets in the base's frame: its y is the y joint's q
    n_x, n_y, _ = gantry_loads_by_hand(in_base[:, 1])
    lost_x, lost_y = MU * n_x / K, MU * n_y / K
    vap = workspace_map.reference.figure("vAP_p_um")
    np.testing.assert_allclose(vap, 2 * lost_x * 1e6, rtol=1e-9)
    assert np.all(vap > 1.9 * np.hypot(lost_x, lost_y) * 1e6)


def test_the_cube_of_a_placed_and_turned_robot_sits_and_is_approached_in_the_world():
    """A UR5 on a wall (rolled 90°, turned 30°, at T_M): the study's cube centre and its edges are the world's, P1–P5
    where ISO 9283 puts them about that centre; the same configurations put the unplaced UR5's tool at the base-frame
    positions scipy's rotation gives, and each cube approach (+x ... -z of the world) is the unplaced UR5's along the
    direction turned back into its base frame."""
    from scipy.spatial.transform import Rotation

    from tribokin.iso9283.cube import APPROACH_DIRECTIONS, joint_approach_signs
    from tribokin.study.assembly import load_robot, pose_tasks
    from tribokin.study.reading import load_study

    rpy_deg = [90.0, 0.0, 30.0]
    turn = Rotation.from_euler("xyz", rpy_deg, degrees=True).as_matrix()  # roll, then pitch, then yaw: R_z R_y R_x
    centre_m = turn @ [0.35, -0.1, 0.35] + T_M  # a cube in front of the arm, in the world
    side_m = 0.1
    plain = {k: v for k, v in STUDY.items() if k not in ("map", "poses")}
    placed = {**plain, "robot": {**STUDY["robot"], "base_xyz_m": list(T_M), "base_rpy_deg": rpy_deg},
              "iso_cube": {"center_m": centre_m.tolist(), "side_m": side_m}}
    study = load_study(placed)
    robot = load_robot(study, meshes=False)
    tasks, cube = pose_tasks(study, robot)
    assert cube["center_m"] == pytest.approx(centre_m.tolist(), abs=1e-12) and cube["side_m"] == side_m
    corners = {"P1": (0, 0, 0), "P2": (-1, -1, 1), "P3": (1, 1, 1), "P4": (1, 1, -1), "P5": (-1, -1, -1)}
    unplaced = load_robot(load_study({**plain, "iso_cube": {}}), meshes=False)
    for task in tasks:
        expected = centre_m + 0.8 * side_m / 2 * np.array(corners[task.name])  # 10 % of the diagonal from the corner
        assert np.linalg.norm(robot.tool_placement(task.q).translation - expected) < 1e-6
        assert np.linalg.norm(unplaced.tool_placement(task.q).translation - turn.T @ (expected - T_M)) < 1e-6
        assert task.labels == tuple(APPROACH_DIRECTIONS)
        turned_back = np.array([turn.T @ APPROACH_DIRECTIONS[label] for label in task.labels])
        np.testing.assert_array_equal(task.directions, joint_approach_signs(unplaced, task.q, turned_back))
        assert not np.array_equal(task.directions, joint_approach_signs(unplaced, task.q))  # the base's own axes
