"""Studies of robots with continuous joints (Kinova's Gen3, example-robot-data's kinova): poses and maps as with the
joints made revolute within ±1000 rad, a map row whose IK crosses ±π, and outputs that give one angle per joint."""

import csv
import json
import subprocess
import sys

import numpy as np
import pytest

from conftest import GEN3_URDF
from helpers.measurement_files import write_csv
from helpers.robots import wide_revolute_urdf
from tribokin import InputError, run_study
from tribokin.kinematics.robot import load_urdf, wrap_angles
from tribokin.measurement.contract import read_measurements
from tribokin.study.calibration_data import read_robot_measurements

#: Gen3's continuous joints among its seven.
CONTINUOUS = np.array([True, False, True, False, True, False, True])
#: Joint 1 at π: the tool behind the base, pointing down at (-0.48, 0.03, 0.28) m.
BEHIND = [3.14159, 0.6, 0.0, 1.6, 0.0, 1.0, 0.0]


def gen3_study(urdf, **sections) -> dict:
    return {"study": {"cycles": 30, "seed": 2}, "robot": {"urdf": str(urdf), "tool_frame": "tool_frame",
                                                          "payload_kg": 1.0},
            "joints": {"friction": {"preset": "42CD4-raw"}, "stiffness": 5.0e4}, **sections}


def test_poses_are_those_of_the_joints_made_wide_revolute(tmp_path):
    poses = {"poses": [{"name": "turned", "q": [4.0, 0.5, -3.5, 1.2, 7.0, -0.6, -3.2]},
                       {"name": "behind", "q": BEHIND}]}
    continuous = run_study(gen3_study(GEN3_URDF, **poses))
    revolute = run_study(gen3_study(wide_revolute_urdf(tmp_path), **poses))
    for got, expected in zip(continuous.poses, revolute.poses, strict=True):
        np.testing.assert_array_equal(got.q, expected.q)  # one angle per joint, as given (4 and 7 rad kept)
        np.testing.assert_allclose(got.normal_forces_N, expected.normal_forces_N, rtol=1e-12)
        np.testing.assert_allclose(got.positions_m, expected.positions_m, rtol=0, atol=1e-15)
        for row, other in zip(got.direction_rows(), expected.direction_rows(), strict=True):
            assert row["RP_l_um"] == pytest.approx(other["RP_l_um"], rel=1e-9) and row["RP_l_um"] > 0


def test_a_map_row_crosses_pi_as_the_wide_revolute_joints_turn_past_it(tmp_path):
    plane = {"map": {"kind": "plane", "origin_m": [-0.48, 0.0, 0.28], "axis_u": [0, 1, 0], "axis_v": [1, 0, 0],
                     "extent_u_m": [-0.2, 0.2], "extent_v_m": [-0.05, 0.05], "resolution": [9, 3],
                     "start_q": BEHIND}}
    continuous = run_study(gen3_study(GEN3_URDF, **plane)).map
    revolute = run_study(gen3_study(wide_revolute_urdf(tmp_path), **plane)).map
    assert continuous.reachable.all() and revolute.reachable.all()
    turned = revolute.q[:, 0]  # joint_1 past π along every row
    assert turned.min() < 2.8 and turned.max() > 3.4
    assert np.abs(continuous.q[:, CONTINUOUS]).max() <= np.pi  # IK gives continuous angles in [-π, π]
    np.testing.assert_allclose(continuous.q, np.where(CONTINUOUS, wrap_angles(revolute.q), revolute.q), rtol=0,
                               atol=1e-12)
    reference = next(iter(continuous.scenarios))
    np.testing.assert_allclose(continuous.scenarios[reference].figure("RP_l_um"),
                               revolute.scenarios[reference].figure("RP_l_um"), rtol=1e-9)


def test_outputs_give_one_angle_per_joint(tmp_path):
    study = tmp_path / "gen3.toml"
    study.write_text(f"""
[study]
cycles = 10
[robot]
urdf = "{GEN3_URDF}"
[joints]
friction = {{ preset = "42CD4-raw" }}
stiffness = 5.0e4
[[poses]]
name = "P"
q = [4.0, 0.5, -3.5, 1.2, 7.0, -0.6, -3.2]
[map]
kind = "joint"
joints = ["joint_1", "joint_2"]
ranges = [[-4.0, 4.0], [-0.5, 0.5]]
counts = [5, 2]
start_q = {BEHIND}
""")
    out = tmp_path / "out"
    done = subprocess.run([sys.executable, "-m", "tribokin", "run", study, "--out", out, "--report", "none"],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    names = [f"q_joint_{i}" for i in range(1, 8)]
    assert ("tool frame: tool_frame (the default: the end of the longest chain), moved by "
            f"{', '.join(name[2:] for name in names)}\n") in done.stdout
    with open(out / "poses.csv", newline="") as file:
        rows = list(csv.DictReader(file))
    assert [key for key in rows[0] if key.startswith("q_")] == names
    assert [float(rows[0][name]) for name in names] == [4.0, 0.5, -3.5, 1.2, 7.0, -0.6, -3.2]
    summary = json.loads((out / "summary.json").read_text())
    assert summary["poses"][0]["q"] == [4.0, 0.5, -3.5, 1.2, 7.0, -0.6, -3.2] and summary["study"]["joints"] == [
        name[2:] for name in names]
    assert summary["study"]["tool_frame"] == "tool_frame" and summary["study"]["robot_spec"]["tool_frame"] is None
    with open(out / "map.csv", newline="") as file:
        targets = list(csv.DictReader(file))
    assert [key for key in targets[0] if key.startswith("q_")] == names
    assert [float(t["q_joint_1"]) for t in targets[:5]] == [-4.0, -2.0, 0.0, 2.0, 4.0]  # the grid, not wrapped
    assert all(t["reachable"] == "true" for t in targets) and len(targets) == 10


def test_example_robot_datas_kinova_runs_a_pose_study_and_a_map():
    study = {"study": {"cycles": 30, "seed": 1}, "robot": {"name": "kinova"},
             "joints": {"friction": {"preset": "42CD4-raw"}, "stiffness": 2.0e4}}
    poses = run_study({**study, "iso_cube": {"side_m": 0.1}})
    assert poses.settings["joints"] == [f"j2s6s200_joint_{i}" for i in range(1, 7)]
    assert [p.name for p in poses.poses] == ["P1", "P2", "P3", "P4", "P5"]
    assert all(row["RP_l_um"] > 0 for pose in poses.poses for row in pose.direction_rows())
    plane = {"kind": "plane", "origin_m": poses.settings["iso_cube"]["center_m"], "axis_u": [1, 0, 0],
             "axis_v": [0, 1, 0], "extent_u_m": [-0.05, 0.05], "extent_v_m": [-0.05, 0.05], "resolution": [3, 3]}
    workspace = run_study({**study, "map": plane}).map
    assert workspace.reachable.all() and workspace.q.shape == (9, 6)


def test_a_calibrations_q_columns_take_a_continuous_joint_across_pi_as_one_angle(tmp_path):
    header = "pose,cycle,x_m,y_m,z_m," + ",".join(f"q_joint_{i}" for i in range(1, 8))
    path = write_csv(tmp_path, header, [f"P,{cycle},0.4,0.0,0.3,{joint_1},0.5,0,1,0,0.2,0"
                                        for cycle, joint_1 in ((1, 3.1412), (2, -3.1412))])  # 0.0008 rad apart
    measured = read_robot_measurements(path, load_urdf(GEN3_URDF))
    assert abs(wrap_angles(measured.poses[0].q[0] - np.pi)) < 1e-12 and measured.poses[0].q_spread < 1e-3
    with pytest.raises(InputError, match="differ by 6.28 rad"):  # read as a plain angle: two configurations
        read_measurements(path)
