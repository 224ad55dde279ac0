"""Workspace maps: targets, IK, per-target physics against hand statics and single-pose runs."""

import copy
import math
import pickle

import numpy as np
import pytest

from conftest import ROOT
from helpers.map_studies import MU, K, gantry_loads_by_hand, gantry_map_study
from tribokin import InputError, run_study
from tribokin.execution import executor_for
from tribokin.simulation.pose_test import PoseRunner, joint_space_task
from tribokin.streams import map_target_stream
from tribokin.study.assembly import joint_models, load_robot
from tribokin.study.reading import load_study


def test_gantry_with_fixed_loads_gives_a_flat_map_and_flags_unreachable_targets():
    result = run_study(gantry_map_study(normal_force_N=500.0))
    workspace_map = result.map
    assert result.poses == [] and workspace_map.grid.shape == (1, 4, 8)
    u = workspace_map.grid.coordinates(np.arange(workspace_map.grid.size))["u_m"]
    np.testing.assert_array_equal(workspace_map.reachable, u < 0.65)
    assert all(r.startswith(("no IK solution", "beyond the robot's reach")) for r in workspace_map.reasons()[u > 0.65])
    ap = workspace_map.reference.figure("AP_p_um")
    assert np.all(np.isnan(ap[u > 0.65]))
    # every axis lost mu N / k each way: each direction's cycles on one point, x_c +/- delta (1, 1, 1), so AP_p =
    # sqrt(3) delta everywhere, from each direction, and RP_l = 0
    delta_um = MU * 500.0 / K * 1e6
    for name in ("AP_p_um", "AP_p_plus_um", "AP_p_minus_um"):
        np.testing.assert_allclose(workspace_map.reference.figure(name)[u < 0.65], math.sqrt(3) * delta_um, rtol=1e-6)
    np.testing.assert_allclose(workspace_map.reference.figure("RP_l_um")[u < 0.65], 0.0, atol=1e-9)
    summary = result.summary()["map"]
    assert (summary["count"], summary["reachable"], summary["unreachable"], summary["cycles"]) == (32, 28, 4, 10)
    assert summary["AP_p_um"]["min"] == pytest.approx(summary["AP_p_um"]["max"], rel=1e-6)
    statistics = result.map.statistics()  # the typed figures the summary is made of
    assert (statistics.count, statistics.reachable, statistics.RP_l_um.as_dict()) == (32, 28, summary["RP_l_um"])
    assert [(s.name, s.RP_l_um, s.wins, s.reachable) for s in statistics.scenarios] == [
        (result.map.reference.name, statistics.RP_l_um, None, None)]
    assert statistics.reached_by_any is statistics.RP_l_change_um is statistics.AP_p_change_um is None


def test_a_maps_summary_computed_on_a_worker_is_the_one_computed_here():
    """summarise_on: a worker of a local pool computes the statistics (its copy of the map carries none, nor this
    process's computation under way), statistics() waits for them; the same as computed here."""
    here = run_study(gantry_map_study(normal_force_N=500.0)).map
    there = run_study(gantry_map_study(normal_force_N=500.0)).map
    with executor_for(2) as pool:
        there.summarise_on(pool)
        assert pickle.loads(pickle.dumps(there))._statistics is None
        assert there.statistics() == here.statistics() and there._statistics is there.statistics()
        assert there.summary() is there.statistics().summary





def test_gantry_map_with_loads_from_statics_follows_hand_statics():
    result = run_study(gantry_map_study())
    workspace_map, scenario = result.map, result.map.reference
    ok = workspace_map.reachable
    y = workspace_map.positions_m[:, 1]
    n_x, n_y, n_z = gantry_loads_by_hand(y)
    np.testing.assert_allclose(scenario.normal_forces_N[ok, 0], n_x[ok], rtol=1e-9)
    np.testing.assert_allclose(scenario.normal_forces_N[ok, 1], n_y, rtol=1e-9)
    np.testing.assert_allclose(scenario.normal_forces_N[ok, 2], n_z, atol=1e-9)
    ap = scenario.figure("AP_p_um")  # each direction's cycles on one point: AP_p its distance, RP_l 0
    np.testing.assert_allclose(ap[ok], np.hypot(MU * n_x[ok] / K, MU * n_y / K) * 1e6, rtol=1e-6)
    np.testing.assert_allclose(scenario.figure("RP_l_um")[ok], 0.0, atol=1e-9)
    # the X load, hence AP_p, grows with y and does not change along x
    by_row = ap.reshape(4, 8)[:, :7]
    assert np.all(np.diff(by_row[:, 0]) > 0.05) and np.ptp(by_row, axis=1).max() < 1e-6


def test_box_map_layers_and_joint_map_configurations():
    study = gantry_map_study()
    study["map"] = {"kind": "box", "min_m": [0.3, 0.1, 0.25], "max_m": [0.5, 0.5, 0.45], "resolution": [2, 3, 2]}
    box = run_study(study).map
    assert box.grid.shape == (2, 3, 2) and box.reachable.all()
    np.testing.assert_allclose(box.positions_m[7], [0.5, 0.1, 0.45])  # index (layer 1, row 0, column 1)
    np.testing.assert_allclose(box.q[7], [0.3, 0.1, 0.25], atol=1e-9)  # tool = (0.2 + q_x, q_y, 0.2 + q_z)
    n_x = gantry_loads_by_hand(box.positions_m[:, 1])[0]
    np.testing.assert_allclose(box.reference.normal_forces_N[:, 0], n_x, rtol=1e-9)

    study["map"] = {"kind": "joint", "joints": ["z", "y"], "ranges": [[0.0, 0.4], [0.1, 0.3]], "counts": [3, 2]}
    joint = run_study(study).map
    assert joint.grid.shape == (1, 2, 3) and joint.reachable.all()
    np.testing.assert_allclose(joint.q[4], [0.3, 0.3, 0.2])  # x at the reference posture (mid-range)
    np.testing.assert_allclose(joint.positions_m[4], [0.5, 0.3, 0.4], atol=1e-12)


def ur5_map_study(cycles=30):
    return {
        "study": {"cycles": cycles, "seed": 11},
        "robot": {"name": "ur5", "payload_kg": 3.0},
        "joints": {"friction": {"preset": "42CD4-raw"}, "stiffness": 1.0e5, "bearing_span_m": 0.08},
        "map": {"kind": "plane", "origin_m": [0.0, -0.55, 0.2], "axis_u": [1, 0, 0], "axis_v": [0, 0, 1],
                "extent_u_m": [-0.1, 0.1], "extent_v_m": [0.0, 0.1], "resolution": [3, 2], "statistic": "one-test"},
    }


def test_arm_map_targets_equal_single_pose_runs():
    """Each target is an ordinary pose: exactly so with its own stream (map_target_stream(seed, index)) through
    the single-pose path, and statistically against `run_study` poses at the map's q (other streams)."""
    cycles = 4000
    workspace_map = run_study(ur5_map_study(cycles)).map
    assert workspace_map.reachable.all() and workspace_map.grid.rotation is not None
    robot = load_robot(load_study(ur5_map_study()))
    for index, q in enumerate(workspace_map.q):
        reached = robot.tool_placement(q)
        np.testing.assert_allclose(reached.translation, workspace_map.grid.positions_m([index])[0], atol=1e-9)
        np.testing.assert_allclose(reached.rotation, workspace_map.grid.rotation, atol=1e-8)

    study = load_study(ur5_map_study(cycles))
    runner = PoseRunner(study, robot, joint_models(study, robot))
    for index in (0, 5):
        pose = runner.measure(joint_space_task("P", workspace_map.q[index]), map_target_stream(11, index))
        assert workspace_map.reference.figure("RP_l_um")[index] == pose.metrics.directions["+"].RP_l_m * 1e6

    poses = run_study(_poses_study(workspace_map.q, cycles))
    for index, pose in enumerate(poses.poses):
        row = pose.direction_rows()[0]
        np.testing.assert_array_equal(workspace_map.reference.normal_forces_N[index], pose.normal_forces_N)
        assert workspace_map.reference.figure("RP_l_um")[index] == pytest.approx(row["RP_l_um"], rel=0.06)
        assert workspace_map.reference.figure("AP_p_um")[index] == pytest.approx(row["AP_p_um"], rel=0.03)
        assert workspace_map.reference.figure("largest_semi_axis_um")[index] == pytest.approx(
            row["ellipsoid_semi_axes_um"][0], rel=0.06)
        shares = [row[f"contribution_{j}"] for j in workspace_map.joint_names]
        assert workspace_map.reference.dominant_joint[index] == int(np.argmax(shares))


def _poses_study(qs, cycles):
    study = ur5_map_study(cycles)
    del study["map"]
    study["poses"] = [{"q": q.tolist()} for q in qs]
    return study


@pytest.mark.parametrize("edit, key", [
    (lambda m: m.pop("kind"), "map.kind"),
    (lambda m: m.update(kind="cylinder"), "map.kind"),
    (lambda m: m.update(axis_u=[2, 0, 0]), "map.axis_u"),
    (lambda m: m.update(axis_v=[1, 0, 0]), "map.axis_v"),
    (lambda m: m.update(resolution=[3]), "map.resolution"),
    (lambda m: m.update(extent_v_m=[0.1, 0.1]), "map.extent_v_m"),
    (lambda m: m.update(min_m=[0, 0, 0]), "map.min_m"),
    (lambda m: m.update(rpy_deg=[180, 0, 0]), "map.rpy_deg"),
    (lambda m: m.clear() or m.update(kind="joint", joints=["x", "w"], ranges=[[0, 0.5], [0, 0.5]], counts=[2, 2]),
     "map.joints[1]"),
    (lambda m: m.clear() or m.update(kind="joint", joints=["x"], ranges=[[0, 1]], counts=[2]), "map.ranges[0]"),
    (lambda m: m.clear() or m.update(kind="joint", joints=["x", "y"], ranges=[[0, 0.1]], counts=[2, 2]),
     "map.ranges"),
])
def test_bad_map_tables_name_the_key(edit, key):
    study = gantry_map_study(normal_force_N=100.0)
    edit(study["map"])
    with pytest.raises(InputError) as error:
        run_study(study)
    assert error.value.key == key


def test_study_without_poses_needs_a_map():
    study = gantry_map_study()
    del study["map"]
    with pytest.raises(InputError, match=r"\[map\]"):
        run_study(copy.deepcopy(study))


def test_shipped_studies_are_valid():
    for path in sorted((ROOT / "studies").glob("*.toml")):
        study = load_study(path)
        assert study.cycles >= 1, path
