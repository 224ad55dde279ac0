"""A joint's friction as a time series in pose tests (issue 38): the cycles' sample variance of a Gaussian AR(1)
against its closed form, through the runner's draws; ``ar1 = 0`` is the independent draws' run to the byte; the
warm-up's power from the pose's load, travel and cycle time."""

from __future__ import annotations

import math

import numpy as np
import pytest

from conftest import AXIS_URDF, axis_study
from tribokin import run_study
from tribokin.errors import JointModelError, SettingsError
from tribokin.kinematics.robot import load_urdf
from tribokin.simulation.joint_errors import JointErrorModel
from tribokin.simulation.pose_test import PoseRunner, TestSettings, pose_task
from tribokin.tribology.friction_series import FrictionSeries, expected_sample_variance
from tribokin.tribology.laws import Constant, Gaussian
from tribokin.tribology.thermal import Thermal

MEAN, STD, LOAD_N, STIFFNESS = 0.12, 0.006, 150.0, 2e6  # mean 20 σ: the Gaussian's truncation at 0 is nil


@pytest.fixture(scope="module")
def axis():
    return load_urdf(AXIS_URDF, "tool")


def deviations(robot, model: JointErrorModel, tests: int, cycles: int, seed: int, **settings) -> np.ndarray:
    """(tests, cycles) the axis's deviations [m] drawn as a pose test draws them (:meth:`PoseRunner.deviations`)."""
    runner = PoseRunner(TestSettings(cycles, **settings), robot, [model])
    task = pose_task(robot, "P1", [0.2], normal_force_N=LOAD_N)
    dq, _ = runner.deviations(task, runner.normal_forces(task), np.ones((tests * cycles, 1)),
                              np.random.default_rng(seed), tests)
    return dq.reshape(tests, cycles)


@pytest.mark.parametrize(("rho", "tests"), [(0.5, 100_000), (0.9, 100_000), (0.99, 100_000)])
def test_the_cycles_sample_variance_is_the_ar1_s(axis, rho, tests):
    """E[S²] = σ²(1 − 2/(n(n − 1)) Σₖ (n − k) ρᵏ) of 30 cycles, σ the lost motion's (μ's times N/k): the tests'
    mean within 1 %, with tests enough that the check's own standard error is within 0.3 %."""
    model = JointErrorModel(Gaussian(mean=MEAN, std=STD), STIFFNESS, series=FrictionSeries(ar1=rho))
    s2 = deviations(axis, model, tests, 30, seed=int(rho * 100)).var(axis=1, ddof=1)
    expected = expected_sample_variance(STD * LOAD_N / STIFFNESS, rho, 30)
    error = s2.std(ddof=1) / math.sqrt(tests) / expected
    assert error <= 0.003, error
    assert abs(s2.mean() / expected - 1) <= 0.01, (s2.mean() / expected, error)
    independent = expected_sample_variance(STD * LOAD_N / STIFFNESS, 0.0, 30)
    assert expected < 0.95 * independent  # the check sees the correlation (0.94 of the independent's at 0.5)


def test_ar1_zero_is_the_independent_run_to_the_byte():
    """A joint friction giving ``ar1 = 0`` and nothing else draws what the law alone draws: every figure of the pose,
    simulated and expected, equal."""
    plain = run_study(axis_study(friction={"preset": "42CD4-raw"}))
    zero = run_study(axis_study(friction={"preset": "42CD4-raw", "ar1": 0.0}))
    for a, b in zip(plain.poses, zero.poses, strict=True):
        assert np.array_equal(a.dq, b.dq) and np.array_equal(a.positions_m, b.positions_m)
        assert a.report_row() == b.report_row() and a.direction_rows() == b.direction_rows()
        assert a.direction_figures("+") == b.direction_figures("+")


def test_a_correlated_series_tightens_the_simulated_and_expected_test(axis):
    """ar1 = 0.99: both the pose's test and its expected RP_l come from cycles that move together, far below the
    independent ones' (E[S²] at 0.99 is 0.13 of the independent's over 30 cycles)."""
    figures = {}
    for ar1 in (0.0, 0.99):
        result = run_study(axis_study(friction={"law": "gaussian", "mean": MEAN, "std": STD, "ar1": ar1})).poses[0]
        figures[ar1] = result.direction_figures("+")
    ratio = figures[0.99]["expected_RP_l_um"] / figures[0.0]["expected_RP_l_um"]
    assert 0.25 < ratio < 0.5, ratio
    assert figures[0.99]["RP_l_95_um"][1] < figures[0.0]["RP_l_95_um"][0]


def test_the_warm_up_heats_by_the_pose_s_friction_power(axis):
    """A constant friction that falls 0.5 % per kelvin: each cycle's lost motion is μ·f(T)·N/k, T stepped by
    the power μ·f(T)·N × travel / cycle time over each cycle (computed here cycle by cycle)."""
    thermal = Thermal(time_constant_s=600.0, resistance_K_per_W=2.0, mu_per_K=-0.005)
    model = JointErrorModel(Constant(mu=MEAN), STIFFNESS, series=FrictionSeries(thermal=thermal),
                            travel_per_cycle=0.5)
    drawn = deviations(axis, model, 2, 200, seed=0, cycle_time_s=5.0)
    temperature, expected = 20.0, []
    for _ in range(200):
        mu = MEAN * (1 - 0.005 * (temperature - 20.0))
        expected.append(mu * LOAD_N / STIFFNESS)
        settled = 20.0 + 2.0 * mu * LOAD_N * 0.5 / 5.0
        temperature = settled + (temperature - settled) * math.exp(-5.0 / 600.0)
    assert np.allclose(drawn, np.array(expected)[None], rtol=1e-12, atol=0)  # each test from a cold joint
    assert drawn[0, -1] < 0.99 * drawn[0, 0]  # warmed by 200 cycles: less friction


def test_a_warm_up_needs_the_cycle_time_and_travel(axis):
    thermal = FrictionSeries(thermal=Thermal(600.0, 2.0, mu_per_K=-0.005))
    with pytest.raises(JointModelError, match="travel_per_cycle"):
        JointErrorModel(Constant(mu=MEAN), STIFFNESS, series=thermal)
    model = JointErrorModel(Constant(mu=MEAN), STIFFNESS, series=thermal, travel_per_cycle=0.5)
    with pytest.raises(SettingsError, match="cycle_time_s"):
        PoseRunner(TestSettings(30), axis, [model])
