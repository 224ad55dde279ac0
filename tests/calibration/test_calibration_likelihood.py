"""The likelihood's terms against independent densities (scipy.stats), and its analytic gradient."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.differentiate import jacobian
from scipy.linalg import helmert
from scipy.stats import multivariate_normal, wishart

from helpers.calibration_arm import arm_kinematics, arm_model, simulate
from tribokin.calibration.data import PoseData, SeriesData, stack
from tribokin.calibration.likelihood import (
    difference_loglik,
    log_likelihood,
    log_likelihood_and_gradient,
    wishart_logpdf,
)
from tribokin.calibration.model import JointModel, predict_series


def random_covariance(rng: np.random.Generator) -> np.ndarray:
    a = rng.normal(0.0, 1e-6, (3, 3))
    return a @ a.T + 1e-13 * np.eye(3)


def gaussian_series(cycles: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Covariance Σ, ``cycles`` points drawn from N(1, Σ) and their scatter about their mean."""
    rng = np.random.default_rng(cycles)
    covariance = random_covariance(rng)
    points = rng.multivariate_normal(np.ones(3), covariance, size=cycles)
    centred = points - points.mean(axis=0)
    return covariance, points, centred.T @ centred


@pytest.mark.parametrize("cycles", [4, 30])
def test_wishart_term_is_scipy_wishart_logpdf(cycles):
    covariance, _, scatter = gaussian_series(cycles)
    expected = wishart(df=cycles - 1, scale=covariance).logpdf(scatter)
    assert wishart_logpdf(scatter, cycles - 1, covariance) == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("cycles", [2, 3])
def test_short_series_term_is_density_of_orthonormal_contrasts(cycles):
    covariance, points, scatter = gaussian_series(cycles)
    expected = multivariate_normal(np.zeros(3), covariance).logpdf(helmert(cycles) @ points).sum()
    assert wishart_logpdf(scatter, cycles - 1, covariance) == pytest.approx(expected, rel=1e-9)


def test_difference_term_is_gaussian_density_of_differences_to_the_first_direction():
    rng = np.random.default_rng(7)
    series_per_pose = [3, 2, 1]
    pose_index = np.repeat(np.arange(3), series_per_pose)
    variances = np.array([random_covariance(rng) for _ in pose_index])
    means, shifts = rng.normal(0.0, 1e-5, (2, len(pose_index), 3))
    pose_matrix = (np.arange(3)[:, None] == pose_index).astype(float)
    value = difference_loglik(means, shifts, variances, pose_matrix)[0]
    for p in range(3):
        rows = np.flatnonzero(pose_index == p)
        first, others = rows[0], rows[1:]
        if not len(others):
            assert value[p] == pytest.approx(0.0, abs=1e-9)
            continue
        difference = (means[others] - means[first]).ravel()
        predicted = (shifts[others] - shifts[first]).ravel()
        covariance = np.kron(np.ones((len(others), len(others))), variances[first])
        for j, o in enumerate(others):
            covariance[3 * j:3 * j + 3, 3 * j:3 * j + 3] += variances[o]
        assert value[p] == pytest.approx(multivariate_normal(predicted, covariance).logpdf(difference), rel=1e-10)


@pytest.mark.parametrize("tie", ["none", "all"])
def test_gradient_is_the_numerical_derivative(tie):
    model = arm_model(fit_backlash=(True, False) * 3, tie=tie)
    data = stack(simulate(arm_kinematics(), np.random.default_rng(3)))
    theta = model.theta() + np.random.default_rng(4).normal(0.0, 0.2, len(model.theta()))
    numerical = jacobian(lambda t: log_likelihood(model, t, data), theta, initial_step=0.01).df
    analytic = log_likelihood_and_gradient(model, theta, data)[1]
    np.testing.assert_allclose(analytic, numerical, rtol=1e-5, atol=1e-6 * np.abs(analytic).max())


def test_predicted_series_is_the_spread_and_shift_of_simulated_joint_errors():
    rng = np.random.default_rng(11)
    jacobian_ = rng.normal(0.0, 0.4, (3, 4))
    stiffness, backlash = np.array([2e4, 5e4, 1e4, 3e4]), np.array([1e-5, 0.0, 3e-5, 2e-5])
    torque_mean, torque_std = np.array([0.5, 0.3, 0.8, 0.4]), np.array([0.1, 0.05, 0.2, 0.1])
    signs, joint_noise, noise = np.array([1.0, -1.0, 0.0, 1.0]), np.array([1e-6, 2e-6, 1e-6, 0.0]), 2e-6
    torque = rng.normal(torque_mean, torque_std, (400_000, 4))
    dq = signs * (torque / stiffness + backlash / 2) + rng.normal(0.0, 1.0, (400_000, 4)) * joint_noise
    points = dq @ jacobian_.T + rng.normal(0.0, noise, (400_000, 3))
    model = JointModel(tuple("abcd"), stiffness, backlash, noise, (True,) * 4, (False,) * 4, False,
                       joint_noise=joint_noise)
    covariance, shift = model.predict(jacobian_, signs, torque_mean, torque_std)
    np.testing.assert_allclose(covariance, np.cov(points.T), atol=0.01 * np.abs(covariance).max())
    np.testing.assert_allclose(shift, points.mean(axis=0), atol=0.01 * np.abs(shift).max())


def test_one_cycle_series_enters_through_its_barycentre_only():
    model = arm_model()
    poses = simulate(arm_kinematics(), np.random.default_rng(6))
    pose, (first, second, _) = poses[0], poses[0].series
    one_cycle = SeriesData(second.direction, second.signs, second.points_m[:1])
    data = stack([PoseData(pose.label, pose.jacobian, pose.torque_mean, pose.torque_std, (first, one_cycle))])
    assert wishart_logpdf(np.zeros((3, 3)), 0, random_covariance(np.random.default_rng(0))) == 0.0
    covariance, shift = predict_series(model.stiffness, model.backlash, model.noise_floor_m, data.jacobian,
                                       data.signs, data.torque_mean, data.torque_std)
    spread = wishart(df=29, scale=covariance[0]).logpdf(data.scatter_m2[0])
    difference = multivariate_normal(shift[1] - shift[0], covariance[0] / 30 + covariance[1]).logpdf(
        data.mean_m[1] - data.mean_m[0])
    assert log_likelihood(model, model.theta(), data) == pytest.approx(spread + difference, rel=1e-10)
