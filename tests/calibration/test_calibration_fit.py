"""Maximum-likelihood fit: round trip against the truth, identifiability, frame independence."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from scipy.stats import chi2

from helpers.calibration_arm import BACKLASH, NOISE_FLOOR_M, STIFFNESS, arm_kinematics, arm_model, simulate
from helpers.profile_deviance import profile_deviance
from tribokin.calibration.data import stack
from tribokin.calibration.fit import fit, profile_interval
from tribokin.calibration.likelihood import log_likelihood

TRUTH = dict(zip(arm_model().names(), np.concatenate([STIFFNESS, BACKLASH, [NOISE_FLOOR_M]]), strict=True))
B_FIXED = dict(fit_backlash=(False,) * 6)


def covered(calibration) -> list[bool]:
    """For each identifiable parameter: its 95 % interval holds the truth."""
    return [p.ci95[0] <= TRUTH[p.name] <= p.ci95[1] for p in calibration.parameters if p.identifiable]


@pytest.fixture(scope="module")
def backlash_fixed():
    """The arm's data of seed 1 (stacked) and their fit with the backlashes fixed (every parameter identifiable)."""
    data = stack(simulate(arm_kinematics(), np.random.default_rng(1)))
    return data, fit(arm_model(**B_FIXED), data)


@pytest.fixture(scope="module")
def all_free():
    """The arm's data of seed 1 and their fit with every parameter free."""
    poses = simulate(arm_kinematics(), np.random.default_rng(1))
    return poses, fit(arm_model(), poses)


def test_round_trip_recovers_the_truth_within_the_intervals(backlash_fixed):
    _, calibration = backlash_fixed
    assert calibration.converged and calibration.rank == 7
    assert all(p.identifiable for p in calibration.parameters)
    assert all(covered(calibration))
    assert calibration.aic == pytest.approx(2 * 7 - 2 * calibration.log_likelihood)
    np.testing.assert_allclose(calibration.model.stiffness, STIFFNESS, rtol=0.3)


def test_pooled_intervals_of_identifiable_parameters_cover_the_truth():
    """120 seeded data sets, all 13 parameters free (stiffness, backlash per joint, noise floor): at least 720
    intervals, whose pooled coverage 0.90 lies about six binomial standard errors below 95 %."""
    kinematics, model = arm_kinematics(), arm_model()
    hits = [covered(fit(model, simulate(kinematics, np.random.default_rng([21, seed])))) for seed in range(120)]
    pooled = np.concatenate(hits)
    assert len(pooled) >= 720  # most parameters are identifiable in most repetitions
    assert pooled.mean() >= 0.90


def test_joint_whose_column_is_zero_is_named_not_identifiable():
    kinematics = [(np.where(np.arange(6) == 5, 0.0, j), t, s) for j, t, s in arm_kinematics()]
    poses = simulate(kinematics, np.random.default_rng(2))
    calibration = fit(arm_model(), poses)
    named = {p.name: p for p in calibration.parameters}
    for name in ("joints.j6.stiffness", "joints.j6.backlash"):
        assert not named[name].identifiable
        assert named[name].std_error is None and named[name].ci95 is None
        assert "does not move with this joint" in named[name].hint
    assert calibration.rank == 11
    assert named["joints.j5.stiffness"].identifiable and named["joints.j5.stiffness"].hint == ""
    assert profile_interval(calibration, poses, "joints.j6.stiffness") == (None, None)  # a flat profile


def test_profile_interval_of_a_well_determined_stiffness_is_close_to_its_wald_interval(all_free):
    poses, calibration = all_free
    wald = {p.name: p.ci95 for p in calibration.parameters}["joints.j4.stiffness"]
    np.testing.assert_allclose(profile_interval(calibration, poses, "joints.j4.stiffness"), wald, rtol=0.01)


def test_wald_interval_is_the_estimate_plus_minus_1_96_standard_errors_of_the_log_likelihood_s_curvature(
        backlash_fixed):
    """The Wald interval (``calibrate --intervals wald``) of every parameter is exp(θ̂ ± 1.96·se), se from the inverse
    of the Hessian of -log L in θ computed here independently: central second differences of log L's values (the fit
    differentiates its analytic gradient)."""
    data, calibration = backlash_fixed
    model, theta, step = calibration.nominal, calibration.theta, 1e-3
    shifts = np.eye(len(theta)) * step
    hessian = np.array([[-(log_likelihood(model, theta + a + b, data) - log_likelihood(model, theta + a - b, data)
                           - log_likelihood(model, theta - a + b, data) + log_likelihood(model, theta - a - b, data))
                         / (4 * step ** 2) for b in shifts] for a in shifts])
    se = np.sqrt(np.diag(np.linalg.inv(hessian)))
    for p, centre, error in zip(calibration.parameters, theta, se, strict=True):
        np.testing.assert_allclose(p.ci95, np.exp([centre - 1.959963984540054 * error,
                                                   centre + 1.959963984540054 * error]), rtol=1e-4)


def test_tie_all_makes_identifiable_what_per_joint_stiffness_is_not():
    """One pose, one direction: a 3 × 3 covariance cannot give six stiffnesses and a noise floor."""
    kinematics = arm_kinematics(poses=1)
    poses = simulate(kinematics, np.random.default_rng(3), cycles=200, directions={"+": np.ones(6)})
    per_joint = fit(arm_model(**B_FIXED), poses)
    assert not all(p.identifiable for p in per_joint.parameters)
    assert any('tie = "all"' in p.hint for p in per_joint.parameters)
    tied = fit(arm_model(**B_FIXED, tie="all"), poses)
    assert [p.name for p in tied.parameters] == ["joints.stiffness_factor", "noise_floor_m"]
    assert tied.rank == 2 and all(p.identifiable for p in tied.parameters)


def test_rotating_and_shifting_the_measurements_changes_no_fitted_value():
    kinematics, model = arm_kinematics(), arm_model(**B_FIXED)
    rotation = Rotation.from_euler("xyz", [30, -50, 110], degrees=True).as_matrix()
    base = fit(model, simulate(kinematics, np.random.default_rng(5)))
    moved = fit(model, simulate(kinematics, np.random.default_rng(5), rotation=rotation,
                                shift_m=np.array([1.5, -2.0, 0.3])))
    np.testing.assert_allclose([p.value for p in moved.parameters], [p.value for p in base.parameters], rtol=1e-9)
    np.testing.assert_allclose([p.std_error for p in moved.parameters], [p.std_error for p in base.parameters],
                               rtol=1e-4)


def test_backlash_absent_from_the_data_is_not_reported_as_known():
    backlash = BACKLASH.copy()
    backlash[1] = 0.0
    calibration = fit(arm_model(), simulate(arm_kinematics(), np.random.default_rng(0), backlash=backlash))
    named = {p.name: p for p in calibration.parameters}["joints.j2.backlash"]
    assert not named.identifiable and "fix its value" in named.hint


def test_a_fit_is_held_within_the_model_ranges_and_says_so_at_their_ends():
    """Truth beyond the ranges (j1's stiffness 6e4 > 3e4, backlashes 1-3e-5 > 1e-5 rad): the fit holds those at the
    range's end, names them not identifiable there (never determined), and the rest is fitted as before."""
    from dataclasses import replace

    from tribokin.calibration.fit import RANGE_HINT
    from tribokin.calibration.model import ParameterRanges

    poses = simulate(arm_kinematics(), np.random.default_rng(1))
    model = replace(arm_model(), stiffness=np.full(6, 2e4), backlash=np.full(6, 5e-6),
                    ranges=ParameterRanges(stiffness=(1e3, 3e4), backlash=(0.0, 1e-5)))
    calibration = fit(model, poses)
    named = {p.name: p for p in calibration.parameters}
    assert np.all(calibration.model.stiffness <= 3e4) and np.all(calibration.model.backlash <= 1e-5)
    held = named["joints.j1.stiffness"]
    assert held.value == pytest.approx(3e4, rel=1e-12) and calibration.model.stiffness[0] == held.value
    assert not held.identifiable and held.hint == RANGE_HINT
    for joint in ("j1", "j2", "j3", "j4", "j5", "j6"):
        backlash = named[f"joints.{joint}.backlash"]
        assert backlash.identifiable or backlash.value < 1e-5 or backlash.hint == RANGE_HINT
    free = named["joints.j4.stiffness"]  # truth 1.2e4, inside the range: determined as without it
    unbounded = {p.name: p for p in fit(replace(model, ranges=ParameterRanges()), poses).parameters}
    assert free.identifiable and free.value == pytest.approx(unbounded["joints.j4.stiffness"].value, rel=0.2)


def test_profile_interval_ends_are_where_the_profile_deviance_reaches_the_chi2_quantile(all_free):
    """At each end, the other parameters re-fitted by another optimiser give 2·(log L̂ - log L) = χ²₁(0.95): a
    weakly and a well determined stiffness, and the least determined identifiable backlash."""
    poses, calibration = all_free
    for name in ("joints.j1.stiffness", "joints.j5.stiffness", "joints.j2.backlash"):
        for end in profile_interval(calibration, poses, name):
            deviance = profile_deviance(calibration, stack(poses), name, end)
            assert deviance == pytest.approx(chi2.ppf(0.95, 1), abs=2e-3), (name, end)
