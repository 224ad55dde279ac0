"""Leave-one-pose-out prediction of RP_l and vAP against the truth's expected figures."""

from __future__ import annotations

import numpy as np
import pytest

from helpers.calibration_arm import arm_kinematics, arm_model, simulate
from tribokin.calibration import cross_validation
from tribokin.calibration.cross_validation import leave_one_pose_out, position_repeatability, predict_pose
from tribokin.calibration.data import PoseData, SeriesData
from tribokin.calibration.fit import fit


def test_position_repeatability_by_hand():
    cloud = np.array([[1.0, 0, 0], [-1, 0, 0], [0, 3, 0], [0, -3, 0]])  # l = 1, 1, 3, 3 about the origin
    expected = 2 + 3 * np.sqrt(4 / 3)
    assert position_repeatability(cloud) == pytest.approx(expected)
    np.testing.assert_allclose(position_repeatability(np.stack([cloud, 2 * cloud])), [expected, 2 * expected])


def truth_expected_figures(kinematics, tests: int = 400) -> tuple[np.ndarray, np.ndarray]:
    """Mean RP_l (pose, direction) and vAP (pose,) over ``tests`` simulated 30-cycle tests at the truth."""
    rng = np.random.default_rng(99)
    rp_l, vap = [], []
    for _ in range(tests):
        poses = simulate(kinematics, rng)
        rp_l.append([[position_repeatability(s.points_m) for s in p.series] for p in poses])
        centres = [np.array([s.points_m.mean(axis=0) for s in p.series]) for p in poses]
        vap.append([np.linalg.norm(c[:, None] - c[None], axis=-1).max() for c in centres])
    return np.mean(rp_l, axis=0), np.mean(vap, axis=0)


def test_held_out_poses_are_predicted_within_ten_percent_of_the_truths_expected_figures():
    kinematics = arm_kinematics()
    poses = simulate(kinematics, np.random.default_rng(8))
    predictions = leave_one_pose_out(arm_model(), poses, draws=1000)
    expected_rp_l, expected_vap = truth_expected_figures(kinematics)
    predicted_rp_l = np.array([[f.predicted_m for f in p.RP_l] for p in predictions])
    np.testing.assert_allclose(predicted_rp_l, expected_rp_l, rtol=0.10)
    np.testing.assert_allclose([p.vAP.predicted_m for p in predictions], expected_vap, rtol=0.10)
    for pose, prediction in zip(poses, predictions, strict=True):
        assert prediction.directions == ("+", "-", "x")
        assert [f.measured_m for f in prediction.RP_l] == [position_repeatability(s.points_m) for s in pose.series]
    figures = [f for p in predictions for f in (*p.RP_l, p.vAP)]
    inside = [f.interval_m[0] <= f.measured_m <= f.interval_m[1] for f in figures]
    assert sum(inside) >= len(figures) - 2  # 95 % prediction intervals of 20 figures


def test_predictions_are_the_same_for_the_same_seed():
    poses = simulate(arm_kinematics(), np.random.default_rng(8))
    first, second = (leave_one_pose_out(arm_model(fit_backlash=(False,) * 6), poses, draws=200, seed=4)
                     for _ in range(2))
    assert first == second


def test_a_one_cycle_series_has_no_predicted_rp_but_counts_in_vap():
    poses = simulate(arm_kinematics(), np.random.default_rng(8))
    pose, (first, second, third) = poses[0], poses[0].series
    short = PoseData(pose.label, pose.jacobian, pose.torque_mean, pose.torque_std,
                     (first, second, SeriesData(third.direction, third.signs, third.points_m[:1])))
    calibration = fit(arm_model(fit_backlash=(False,) * 6), [short, *poses[1:]])
    prediction = predict_pose(calibration, short, np.random.default_rng(0), draws=200)
    assert prediction.RP_l[2] is None and prediction.RP_l[0] is not None
    centres = np.array([first.points_m.mean(axis=0), second.points_m.mean(axis=0), third.points_m[0]])
    assert prediction.vAP.measured_m == pytest.approx(np.linalg.norm(centres[:, None] - centres[None], axis=-1).max())


def test_predictions_drawn_in_blocks_are_those_of_one_draw(monkeypatch):
    """Tests simulated one at a time, a few at a time, or all at once: the same normal draws in the same order."""
    poses = simulate(arm_kinematics(), np.random.default_rng(8))
    calibration = fit(arm_model(fit_backlash=(False,) * 6), poses)
    predictions = []
    for block_cycles in (1, 1000, 10 ** 9):
        monkeypatch.setattr(cross_validation, "PREDICTION_BLOCK_CYCLES", block_cycles)
        predictions.append(predict_pose(calibration, poses[0], np.random.default_rng(5), draws=300))
    assert predictions[0] == predictions[1] == predictions[2]
