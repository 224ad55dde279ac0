"""tools/ur5_tracker_data.py: the synthetic UR5 tracker measurement is a valid measurement file, its physics is the
stated model (checked against forward kinematics computed here), its noise has the stated spread, it is
reproducible, and ``tribokin measure`` registers its tracker frame."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest

from conftest import ROOT, load_tool
from tribokin.cli import main as tribokin_main
from tribokin.iso9283.cube import held_approach_signs
from tribokin.measurement.contract import read_measurements

ur5_tracker_data = load_tool("ur5_tracker_data")
Truth = ur5_tracker_data.Truth

COMMITTED = ROOT / "studies" / "data" / "ur5-tracker.csv"
ZERO6 = (0.0,) * 6


def _rotation_xyz(rpy_deg):
    """Rz(yaw) Ry(pitch) Rx(roll), written out."""
    roll, pitch, yaw = np.radians(rpy_deg)
    rx = np.array([[1, 0, 0], [0, np.cos(roll), -np.sin(roll)], [0, np.sin(roll), np.cos(roll)]])
    ry = np.array([[np.cos(pitch), 0, np.sin(pitch)], [0, 1, 0], [-np.sin(pitch), 0, np.cos(pitch)]])
    rz = np.array([[np.cos(yaw), -np.sin(yaw), 0], [np.sin(yaw), np.cos(yaw), 0], [0, 0, 1]])
    return rz @ ry @ rx


@pytest.fixture(scope="module", autouse=True)
def numpy_path():
    """The committed file was written on the NumPy kernel path (its cube poses' IK through Pinocchio): the compiled
    path agrees with it to rounding, not to the bit (:mod:`tribokin.compiled`)."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("TRIBOKIN_KERNELS", "numpy")
        yield


@pytest.fixture(scope="module")
def robot():
    return ur5_tracker_data.ur5()


@pytest.fixture(scope="module")
def poses(robot):
    return ur5_tracker_data.cube_poses(robot)


def _to_base(truth, rows):
    """(n, 3) measured points of ``rows`` moved back into the base frame with the true tracker frame [m]."""
    measured = np.array([row.measured_m for row in rows])
    return (measured - np.array(truth.tracker_translation_m)) @ _rotation_xyz(truth.tracker_rpy_deg)


def _text_and_numbers(path):
    """The file's lines with the numbers of its data rows left out, and those numbers [(rows, 12)]."""
    lines = path.read_text().splitlines()
    head = next(i for i, line in enumerate(lines) if not line.startswith("#")) + 1  # comments and column names
    rows = [line.split(",") for line in lines[head:]]
    return lines[:head] + [",".join(row[:3]) for row in rows], np.array([[float(v) for v in row[3:]] for row in rows])


def test_the_committed_file_is_a_measurement_file_of_five_poses_three_series_of_30(robot, poses):
    measurements = read_measurements(COMMITTED)
    assert [p.name for p in measurements.poses] == ["P1", "P2", "P3", "P4", "P5"]
    assert measurements.joints == ur5_tracker_data.JOINTS == tuple(robot.joint_names)
    for pose, cube_pose in zip(measurements.poses, poses, strict=True):
        assert [s.direction for s in pose.series] == ["+x", "+y", "+z"]
        assert all(s.cycles.tolist() == list(range(1, 31)) for s in pose.series)
        assert pose.q_spread == 0.0  # every row holds the same q, the cube's, to rounding (its IK's, a few ulps):
        np.testing.assert_allclose(pose.q, cube_pose.q, rtol=0, atol=1e-13)
        np.testing.assert_allclose(pose.pooled("commanded_m"), np.tile(cube_pose.position_m, (90, 1)), atol=1e-10)
    numbers = _text_and_numbers(COMMITTED)[1]  # every row's commanded position is the kinematics of its q, to the bit
    assert all(np.all(row[3:6] == robot.tool_placement(row[6:]).translation) for row in numbers)
    comments = [line for line in COMMITTED.read_text().splitlines() if line.startswith("#")]
    assert comments[0].startswith("# SYNTHETIC DATA")
    assert any("--seed 9283" in line for line in comments)
    assert any("stiffness_Nm_per_rad = [60000.0, 35000.0, 50000.0, 12000.0, 12000.0, 10000.0]" in line
               for line in comments)


def test_the_committed_file_is_what_the_script_writes(tmp_path):
    """The same text, and the same numbers to rounding: the cube poses' IK solves through LAPACK, whose OpenBLAS
    kernels are chosen per processor (``OPENBLAS_CORETYPE``), so another processor's file differs in the last bits.
    On one machine the same seed gives the same bytes (the test below)."""
    assert ur5_tracker_data.main(["--out", str(tmp_path / "u.csv")]) == 0
    text, numbers = _text_and_numbers(tmp_path / "u.csv")
    committed_text, committed_numbers = _text_and_numbers(COMMITTED)
    assert text == committed_text
    np.testing.assert_allclose(numbers, committed_numbers, rtol=1e-13, atol=1e-15)


def test_without_noise_backlash_and_friction_spread_each_point_is_the_rotated_kinematics_of_the_lost_motion(
        robot, poses):
    truth = Truth(friction_torque_std_Nm=ZERO6, backlash_rad=ZERO6, noise_std_m=0.0)
    rotation = _rotation_xyz(truth.tracker_rpy_deg)
    np.testing.assert_allclose(truth.tracker_rotation(), rotation, atol=1e-15)
    np.testing.assert_allclose(rotation.T @ rotation, np.eye(3), atol=1e-15)
    assert np.linalg.det(rotation) == pytest.approx(1.0, abs=1e-15)
    rows = ur5_tracker_data.simulate(truth, cycles=3, poses=poses)
    assert len(rows) == 5 * 3 * 3
    lost_rad = np.array(truth.friction_torque_mean_Nm) / np.array(truth.stiffness_Nm_per_rad)
    directions = {"+x": [1, 0, 0], "+y": [0, 1, 0], "+z": [0, 0, 1]}
    offsets = {}
    for row in rows:
        pose = next(p for p in poses if p.name == row.pose)
        signs = held_approach_signs(robot, pose.q, [directions[row.direction]])[0]
        offsets.setdefault(row.pose, row.joint_offset_rad)
        np.testing.assert_array_equal(row.joint_offset_rad, offsets[row.pose])
        expected = rotation @ robot.tool_placement(pose.q + signs * lost_rad + row.joint_offset_rad).translation \
            + np.array(truth.tracker_translation_m)
        np.testing.assert_allclose(row.measured_m, expected, rtol=0, atol=1e-12)
    assert 3e-5 < np.std(np.array(list(offsets.values()))) < 3e-4  # eps ~ 1e-4 rad, one draw per pose


def test_with_everything_at_zero_the_points_registered_back_are_the_commanded_positions(poses):
    truth = Truth(friction_torque_mean_Nm=ZERO6, friction_torque_std_Nm=ZERO6, backlash_rad=ZERO6,
                  joint_offset_std_rad=0.0, noise_std_m=0.0)
    rows = ur5_tracker_data.simulate(truth, cycles=2, poses=poses)
    np.testing.assert_allclose(_to_base(truth, rows), [row.commanded_m for row in rows], rtol=0, atol=1e-12)


def test_with_only_instrument_noise_the_pooled_spread_about_the_series_barycentres_is_the_noise(poses):
    truth = replace(Truth(), friction_torque_std_Nm=ZERO6)
    rows = ur5_tracker_data.simulate(truth, poses=poses)
    points = _to_base(truth, rows)
    series = [(row.pose, row.direction) for row in rows]
    residuals = np.vstack([points[[s == key for s in series]] - points[[s == key for s in series]].mean(axis=0)
                           for key in dict.fromkeys(series)])
    dof = len(rows) - len(set(series))
    pooled_std_m = np.sqrt((residuals ** 2).sum(axis=0) / dof)
    standard_error_m = truth.noise_std_m / np.sqrt(2 * dof)
    assert np.all(np.abs(pooled_std_m - truth.noise_std_m) < 4 * standard_error_m), pooled_std_m


def test_same_seed_same_bytes_other_seed_other_file_and_no_overwrite_without_force(tmp_path, capsys):
    first, second, other = tmp_path / "a.csv", tmp_path / "b.csv", tmp_path / "c.csv"
    assert ur5_tracker_data.main(["--out", str(first), "--seed", "7"]) == 0
    assert ur5_tracker_data.main(["--out", str(second), "--seed", "7"]) == 0
    assert ur5_tracker_data.main(["--out", str(other), "--seed", "8"]) == 0
    assert first.read_bytes() == second.read_bytes() != other.read_bytes()
    capsys.readouterr()
    before = first.read_bytes()
    assert ur5_tracker_data.main(["--out", str(first), "--seed", "8"]) == 2
    error = capsys.readouterr().err
    assert error == f"ur5_tracker_data: error: {first}: exists; give another --out or add --force\n"
    assert first.read_bytes() == before
    assert ur5_tracker_data.main(["--out", str(first), "--seed", "8", "--force"]) == 0
    assert first.read_bytes() == other.read_bytes()


def test_tribokin_measure_registers_the_tracker_frame_to_within_the_offsets_effect(tmp_path):
    assert tribokin_main(["measure", str(COMMITTED), "--out", str(tmp_path / "m"), "--report", "none"]) == 0
    registration = json.loads((tmp_path / "m" / "summary.json").read_text())["settings"]["registration"]
    assert registration["made"] is True
    truth = Truth()
    rows = ur5_tracker_data.simulate(truth)
    points = _to_base(truth, rows)
    deviation_m = [points[[r.pose == name for r in rows]].mean(axis=0) - rows[i].commanded_m
                   for i, name in enumerate(r.pose for r in rows) if i == 0 or rows[i - 1].pose != name]
    true_rms_um = 1e6 * np.sqrt(np.mean(np.sum(np.square(deviation_m), axis=1)))
    # The true frame leaves the barycentres' offsets (~75 um here, from eps ~ 1e-4 rad and the mean lost
    # motion); the least-squares frame leaves no more, and absorbs part of them with its six degrees of freedom.
    assert 0.5 * true_rms_um < registration["rms_residual_um"] <= true_rms_um
    found = np.array(registration["rotation"])
    angle_rad = np.arccos((np.trace(found @ _rotation_xyz(truth.tracker_rpy_deg)) - 1) / 2)
    assert angle_rad < 1e-3
