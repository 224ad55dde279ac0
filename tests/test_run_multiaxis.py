"""Multi-axis studies: every robot, loads from statics, the ISO cube and the figures beyond ISO."""

import copy

import numpy as np
import pytest

import tribokin.maps.expected_figures as expected
from conftest import ROOT
from tribokin import run_study
from tribokin.iso9283.metrics import position_repeatability
from tribokin.kinematics.robot import TESTED_ROBOTS


def arm_study(robot, **joints):
    return {
        "study": {"cycles": 30, "seed": 4},
        "robot": robot,
        "joints": {"friction": {"preset": "42CD4-raw"}, "stiffness": 1.0e5, **joints},
        "iso_cube": {"side_m": 0.1},
    }


@pytest.mark.parametrize("name", TESTED_ROBOTS)
def test_frictionless_is_perfectly_repeatable_on_every_robot(name):
    study = arm_study({"name": name}, friction={"preset": "frictionless"})
    study["iso_cube"]["side_m"] = 0.04  # small enough for the so100's reach
    result = run_study(study, cycles=10)
    for row in (row for pose in result.poses for row in pose.direction_rows()):
        assert row["RP_l_um"] == 0.0 and row["RP_a_mdeg"] == 0.0
        assert row["AP_p_um"] < 1e-3  # IK residual only


def test_repeatability_scales_as_one_over_k_and_linearly_in_fixed_load():
    study = arm_study({"name": "ur5"}, normal_force_N=300.0)
    base = run_study(study).table()["RP_l_um"]
    stiffer = copy.deepcopy(study)
    stiffer["joints"]["stiffness"] = 2.0e5
    heavier = copy.deepcopy(study)
    heavier["joints"]["normal_force_N"] = 900.0
    # exact to first order; forward kinematics adds terms relatively of the order of dq (~1e-5)
    assert run_study(stiffer).table()["RP_l_um"] == pytest.approx(base / 2, rel=1e-4)
    assert run_study(heavier).table()["RP_l_um"] == pytest.approx(base * 3, rel=1e-4)


def test_cube_poses_report_iso_and_beyond():
    result = run_study(arm_study({"name": "ur5", "payload_kg": 3.0}))
    assert [p.name for p in result.poses] == ["P1", "P2", "P3", "P4", "P5"]
    for pose in result.poses:
        assert pose.directions == ("+x", "+y", "+z")
        rows = pose.direction_rows()
        assert [row["direction"] for row in rows] == ["+x", "+y", "+z"] and [row["cycles"] for row in rows] == [30] * 3
        for row in rows:
            shares = [row[f"contribution_{j}"] for j in result.settings["joints"]]
            assert sum(shares) == pytest.approx(1.0)
            assert row["vAP_p_um"] is not None and row["vAP_p_um"] > 0
            low, high = row["RP_l_95_um"]
            assert low < high
            axes = row["ellipsoid_semi_axes_um"]
            assert axes == sorted(axes, reverse=True) and axes[0] > 0
    loads = np.array([p.normal_forces_N for p in result.poses])
    assert np.ptp(loads, axis=0).max() > 1.0  # bearing loads depend on where the arm is


@pytest.mark.parametrize("approach, labels", [("unidirectional", ["+x", "+y", "+z"]),
                                              ("bidirectional", ["+x", "-x", "+y", "-y", "+z", "-z"])])
def test_cube_poses_give_iso_figures_per_approach_direction(approach, labels):
    """Each direction's figures are those of its own cycles; vAP_p and the pooled RP_l span all of them,
    and the pooled cloud's RP_l is far above any one direction's (its barycenters lie apart)."""
    study = arm_study({"name": "ur5", "payload_kg": 3.0})
    study["study"]["approach"] = approach
    pose = run_study(study, cycles=20).poses[0]
    assert list(pose.directions) == labels and pose.cycles == 20 * len(labels)
    assert np.bincount(pose.approach).tolist() == [20] * len(labels)
    if approach == "unidirectional":
        assert pose.approach.tolist() == np.repeat(np.arange(3), 20).tolist()  # one series after another
    row = pose.report_row()
    centres = []
    for k, label in enumerate(labels):
        mine = pose.positions_m[pose.approach == k]
        figures = row["directions"][label]
        centres.append(mine.mean(axis=0))
        assert figures["barycenter_m"] == pytest.approx(centres[-1].tolist(), abs=1e-15)
        assert figures["RP_l_um"] == pytest.approx(position_repeatability(mine)[0] * 1e6, rel=1e-12)
        assert figures["AP_p_um"] == pytest.approx(np.linalg.norm(centres[-1] - pose.commanded_position_m) * 1e6)
    gaps = [np.linalg.norm(a - b) for a in centres for b in centres]
    assert row["vAP_p_um"] == pytest.approx(max(gaps) * 1e6, rel=1e-9)
    assert row["RP_l_all_directions_um"] == pytest.approx(position_repeatability(pose.positions_m)[0] * 1e6)
    assert row["RP_l_all_directions_um"] > 3 * max(f["RP_l_um"] for f in row["directions"].values())


def test_payload_raises_loads_and_dispersion():
    light = run_study(arm_study({"name": "ur5"}))
    heavy = run_study(arm_study({"name": "ur5", "payload_kg": 5.0}))
    assert np.all(heavy.poses[0].normal_forces_N[:3] > light.poses[0].normal_forces_N[:3])
    assert heavy.table()["RP_l_um"][0] > light.table()["RP_l_um"][0]


def test_rp_interval_brackets_the_long_run_value():
    study = {"study": {"cycles": 30, "seed": 2}, "robot": {"urdf": str(ROOT / "urdf" / "prismatic_axis.urdf")},
             "joints": {"friction": {"preset": "42CD4-raw"}, "stiffness": 2e6, "normal_force_N": 150.0},
             "poses": [{"q": [0.2]}]}
    low, high = run_study(study).poses[0].direction_figures("+")["RP_l_95_um"]
    w = 150 * 0.07 / (2 * 2e6) * 1e6
    # the long-run value 1.366 w lies inside a 30-cycle test's 95 % range, which is wide
    assert low < 1.366 * w < high and high - low > 0.1 * w


def test_fast_and_exact_engines_give_the_same_study_figures(monkeypatch):
    """The cube's simulated tests, and each direction's expected figures, sampled through exact FK under
    ``engine = "exact"`` (few sampled tests: about 8 µs a sample): the first-order model's on the same common random
    numbers to 1e-6."""
    monkeypatch.setattr(expected, "SAMPLED_CYCLES", 3_000)
    monkeypatch.setattr(expected, "MAX_BAND_FACTOR", 1)
    fast = arm_study({"name": "panda", "payload_kg": 1.0})
    exact = copy.deepcopy(fast)
    exact["study"]["engine"] = "exact"
    fast_result, exact_result = run_study(fast), run_study(exact)
    for a, b in zip(fast_result.poses, exact_result.poses, strict=True):
        assert np.abs(a.positions_m - b.positions_m).max() < 1e-9  # 1 nm
        assert a.report_row()["engine_max_deviation_nm"] < 1.0
        for label, figures in a.direction_extra.items():
            ours = {key: value for key, value in b.direction_extra[label].items() if key.startswith("expected_")}
            assert len(ours) >= 7 and ours == pytest.approx({key: figures[key] for key in ours}, rel=1e-6)
    assert fast_result.table()["RP_l_um"] == pytest.approx(exact_result.table()["RP_l_um"], abs=1e-3)


def ur5_pose_study(**robot):
    return {"study": {"cycles": 30, "seed": 4}, "robot": {"name": "ur5", **robot},
            "joints": {"friction": {"preset": "42CD4-raw"}, "stiffness": 1.0e5, "normal_force_N": 300.0},
            "poses": [{"name": "P1", "q": [0.0, -1.2, 1.4, -1.8, -1.57, 0.0]}]}


def test_a_zero_tool_offset_changes_no_figure_and_a_real_one_moves_the_point_measured():
    flange = run_study(ur5_pose_study())
    zero = run_study(ur5_pose_study(tool_offset_m=[0, 0, 0]))
    probe = run_study(ur5_pose_study(tool_offset_m=[0.05, 0.0, 0.1], tool_offset_rpy_deg=[0.0, 90.0, 0.0]))
    assert zero.settings["tool_frame"] == "tool0_tool_point" and flange.settings["tool_frame"] == "tool0"
    assert zero.settings["robot_spec"]["tool_offset_m"] == [0, 0, 0]
    assert "tool_offset_m" not in flange.settings["robot_spec"]
    np.testing.assert_array_equal(zero.poses[0].positions_m, flange.poses[0].positions_m)
    for key, column in flange.table().items():
        np.testing.assert_array_equal(zero.table()[key], column, err_msg=key)
    moved = probe.poses[0].commanded_position_m - flange.poses[0].commanded_position_m
    assert np.linalg.norm(moved) == pytest.approx(np.hypot(0.05, 0.1), rel=1e-12)
    rp, rp_probe = flange.table()["RP_l_um"][0], probe.table()["RP_l_um"][0]
    assert abs(rp_probe - rp) > 0.03 * rp


def test_poses_with_approach_directions_move_only_the_joints_each_approach_moves():
    """[[poses]] directions: each label is a unidirectional series (whatever the study's approach); on a
    straight Cartesian approach with the tool's orientation held, a joint that does not move loses no motion."""
    study = arm_study({"name": "ur5"})
    del study["iso_cube"]
    q = [0.1, -1.0, 1.2, -0.8, 1.3, 0.1]
    study["poses"] = [{"name": "held", "q": q, "directions": ["+z", "+x", "-0.6+0.8+0.0"]}]
    pose = run_study(study, cycles=12).poses[0]
    assert list(pose.directions) == ["+z", "+x", "-0.6+0.8+0.0"] and np.bincount(pose.approach).tolist() == [12] * 3
    vertical = pose.dq[pose.approach == 0]
    # a vertical approach lies in the arm's plane: pan, wrist_2 and wrist_3 stay still (tests/iso9283/test_cube.py)
    assert np.all(vertical[:, [0, 4, 5]] == 0.0) and np.all(vertical[:, 1:4] != 0.0)
    assert np.all(pose.dq[pose.approach == 1] != 0.0)


@pytest.mark.parametrize("directions, key, message", [
    (["+x", "up"], "poses[0].directions[1]", "'up' names no approach"),
    (["+x", "+x"], "poses[0].directions[1]", "named twice"),
    ([], "poses[0].directions", "at least one"),
])
def test_bad_pose_directions_are_one_line_errors(directions, key, message):
    from tribokin import InputError

    study = arm_study({"name": "ur5"})
    study["poses"] = [{"q": [0.1, -1.0, 1.2, -0.8, 1.3, 0.1], "directions": directions}]
    with pytest.raises(InputError) as error:
        run_study(study, cycles=5)
    assert error.value.key == key and message in error.value.message
