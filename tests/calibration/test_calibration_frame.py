"""Fit in an unregistered measuring frame: gradient, invariance to rigid motions, coverage, precision."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.differentiate import jacobian
from scipy.spatial.transform import Rotation

from helpers.calibration_arm import BACKLASH, NOISE_FLOOR_M, STIFFNESS, arm_kinematics, arm_model, simulate
from tribokin.calibration.cross_validation import leave_one_pose_out
from tribokin.calibration.data import stack
from tribokin.calibration.fit import fit, profile_interval
from tribokin.calibration.frame import profile_information, to_base, unknown_frame_log_likelihood_and_gradient

TRUTH = dict(zip(arm_model().names(), np.concatenate([STIFFNESS, BACKLASH, [NOISE_FLOOR_M]]), strict=True))
B_FIXED = dict(fit_backlash=(False,) * 6)
SHIFT_M = np.array([1.5, -2.0, 0.3])


def tracker_poses(seed, rotation: Rotation, shift_m=SHIFT_M, **options):
    """The arm's clouds measured in a frame turned by ``rotation``, the Jacobians left in the base frame."""
    return simulate(arm_kinematics(), np.random.default_rng(seed), rotation=rotation.as_matrix(), shift_m=shift_m,
                    registered=False, **options)


def angle_deg(first: np.ndarray, second: np.ndarray) -> float:
    return float(np.degrees(Rotation.from_matrix(first.T @ second).magnitude()))


@pytest.mark.parametrize("rotation_vector", [[0.0, 0.0, 0.0], [0.4, -0.7, 0.3]])
def test_gradient_in_theta_and_rotation_is_the_numerical_derivative(rotation_vector):
    model = arm_model(fit_backlash=(True, False) * 3)
    data = stack(tracker_poses(3, Rotation.from_euler("xyz", [20, 60, -45], degrees=True)))
    theta = model.theta() + np.random.default_rng(4).normal(0.0, 0.2, len(model.theta()))
    parameters = np.append(theta, rotation_vector)
    reference = Rotation.from_euler("zyx", [10, 50, -30], degrees=True)

    def value(x):
        return unknown_frame_log_likelihood_and_gradient(model, x, data, reference)[0]

    numerical = jacobian(value, parameters, initial_step=0.01).df
    analytic = unknown_frame_log_likelihood_and_gradient(model, parameters, data, reference)[1]
    np.testing.assert_allclose(analytic, numerical, rtol=1e-5, atol=1e-6 * np.abs(analytic).max())


def test_profile_information_inverts_to_the_theta_block_of_the_joint_inverse():
    factor = np.random.default_rng(0).normal(size=(9, 9))
    information = factor @ factor.T
    np.testing.assert_allclose(np.linalg.inv(profile_information(information)), np.linalg.inv(information)[:6, :6],
                               rtol=1e-9)


def test_rigid_motions_of_the_measurements_change_no_fitted_value():
    model = arm_model(**B_FIXED)
    base = fit(model, tracker_poses(5, Rotation.identity(), shift_m=None), frame="unknown")
    for seed, shift in ((1, SHIFT_M), (2, np.array([-3.0, 0.7, 2.0]))):
        motion = Rotation.random(rng=np.random.default_rng(seed))
        moved = fit(model, tracker_poses(5, motion, shift_m=shift), frame="unknown")
        np.testing.assert_allclose([p.value for p in moved.parameters], [p.value for p in base.parameters],
                                   rtol=1e-9)
        np.testing.assert_allclose([p.std_error for p in moved.parameters], [p.std_error for p in base.parameters],
                                   rtol=1e-4)
        assert moved.log_likelihood == pytest.approx(base.log_likelihood, rel=1e-9)
        assert angle_deg(moved.rotation, motion.as_matrix() @ base.rotation) < 1e-6


def test_recovers_the_measuring_frames_rotation():
    motion = Rotation.random(rng=np.random.default_rng(7))
    calibration = fit(arm_model(), tracker_poses(8, motion), frame="unknown")
    assert calibration.converged and calibration.rotation.shape == (3, 3)
    assert angle_deg(calibration.rotation, motion.as_matrix()) < 1.0


def test_pooled_intervals_of_identifiable_parameters_cover_the_truth():
    """60 seeded data sets, each in its own random frame, all 13 parameters free: at least 500 intervals (most
    parameters are identifiable in most data sets), whose pooled coverage 0.90 lies about five binomial standard
    errors below 95 %."""
    model, hits = arm_model(), []
    for seed in range(60):
        motion = Rotation.random(rng=np.random.default_rng([22, seed]))
        calibration = fit(model, tracker_poses([21, seed], motion), frame="unknown")
        hits += [p.ci95[0] <= TRUTH[p.name] <= p.ci95[1] for p in calibration.parameters if p.identifiable]
    assert len(hits) >= 500
    assert np.mean(hits) >= 0.90


def test_registered_fit_of_the_same_data_is_at_least_as_precise():
    """In the frame the unknown-frame fit found, the registered fit has the same optimum (up to the weak prior's
    pull, whose centres, the two fits' moment starts, differ: (se/σ)²·|θ̂ - start| ≤ 0.01²·6.9/6.9² here) and the
    information of θ alone; profiling the rotation out can only lose information."""
    model = arm_model()
    poses = tracker_poses(9, Rotation.random(rng=np.random.default_rng(9)))
    unknown = fit(model, poses, frame="unknown")
    registered = fit(model, to_base(stack(poses), unknown.rotation))
    np.testing.assert_allclose(registered.theta, unknown.theta, rtol=0, atol=2e-3)
    pairs = [(u.std_error, r.std_error) for u, r in zip(unknown.parameters, registered.parameters, strict=True)
             if u.std_error is not None]
    assert len(pairs) >= 10
    assert all(u >= r * (1 - 1e-6) for u, r in pairs)
    assert any(u > 1.05 * r for u, r in pairs)


def test_profile_interval_refits_the_rotation():
    poses = tracker_poses(1, Rotation.random(rng=np.random.default_rng(1)))
    calibration = fit(arm_model(), poses, frame="unknown")
    wald = {p.name: p.ci95 for p in calibration.parameters}["joints.j4.stiffness"]
    np.testing.assert_allclose(profile_interval(calibration, poses, "joints.j4.stiffness"), wald, rtol=0.01)


def test_held_out_predictions_compare_frame_invariant_figures():
    model = arm_model(**B_FIXED)
    measured = simulate(arm_kinematics(), np.random.default_rng(8))
    tracker = tracker_poses(8, Rotation.random(rng=np.random.default_rng(3)))
    unknown = leave_one_pose_out(model, tracker, draws=200, frame="unknown")
    registered = leave_one_pose_out(model, measured, draws=200)
    for u, r in zip(unknown, registered, strict=True):
        np.testing.assert_allclose([f.measured_m for f in u.RP_l], [f.measured_m for f in r.RP_l], rtol=1e-9)
        assert u.vAP.measured_m == pytest.approx(r.vAP.measured_m, rel=1e-9)
        np.testing.assert_allclose([f.predicted_m for f in (*u.RP_l, u.vAP)],
                                   [f.predicted_m for f in (*r.RP_l, r.vAP)], rtol=0.05)


def test_one_direction_per_pose_fits_from_the_spread_alone():
    """No barycentre difference: the rotation comes from the ellipsoids' axes at several poses."""
    motion = Rotation.random(rng=np.random.default_rng(4))
    poses = tracker_poses(4, motion, cycles=200, directions={"+": np.ones(6)})
    calibration = fit(arm_model(**B_FIXED, tie="all"), poses, frame="unknown")
    assert all(p.identifiable for p in calibration.parameters)
    assert angle_deg(calibration.rotation, motion.as_matrix()) < 5.0


def test_unknown_frame_name_is_refused():
    with pytest.raises(ValueError, match="frame must be one of"):
        fit(arm_model(), simulate(arm_kinematics(poses=1), np.random.default_rng(0)), frame="tracker")
