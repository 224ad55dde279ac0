"""ISO 9283's drift test simulated at a pose (``[drift]``, :mod:`tribokin.simulation.drift`): stationary friction
gives the absolute differences of two independent sets, computed here by an independent Monte Carlo; a warm-up moves
the barycentre by what the thermal model implies; a warm start is settled. Along the span (the drift figure's
series): every set's AP_p and RP_l and the joint's temperature are the thermal recursion's computed here (its closed
form where friction does not depend on temperature), and the end sets are the drift figures' own."""

from __future__ import annotations

import math

import numpy as np
import pytest

from conftest import AXIS_URDF, axis_study
from tribokin import run_study
from tribokin.kinematics.robot import load_urdf
from tribokin.simulation.drift import DriftTest, drift_tests
from tribokin.simulation.joint_errors import JointErrorModel, thermal_drive, torque_per_value
from tribokin.simulation.pose_test import PoseRunner, TestSettings, pose_task
from tribokin.tribology.friction_series import FrictionSeries, draw_series
from tribokin.tribology.laws import Gaussian
from tribokin.tribology.thermal import Thermal, power_per_value

MEAN, STD, LOAD_N, STIFFNESS = 0.12, 0.006, 100.0, 1.0e6  # axis_study's load and stiffness; mean 20 σ
SET, SPAN = 30, 360


def drift_study(friction: dict, **drift) -> dict:
    study = axis_study(friction=friction)
    study["study"]["cycle_time_s"] = 10.0
    study["drift"] = {"duration_s": SPAN * 10.0, "set_cycles": SET, **drift}
    return study


def drift_of(study: dict) -> dict:
    return run_study(study).poses[0].direction_figures("+")["drift"]


def independent_sets(rho: float, tests: int, rng) -> tuple[np.ndarray, np.ndarray]:
    """(tests,) |AP₁ − AP₂| and |RP_l₁ − RP_l₂| [µm] of two independent sets of SET cycles each, the lost motion's
    Gaussian AR(1) drawn here step by step, RP_l = l̄ + 3 S_l of the distances to the set's barycentre."""
    z = np.empty((2, tests, SET))
    z[..., 0] = rng.standard_normal((2, tests))
    for k in range(1, SET):
        z[..., k] = rho * z[..., k - 1] + math.sqrt(1 - rho * rho) * rng.standard_normal((2, tests))
    x = (MEAN + STD * z) * LOAD_N / STIFFNESS * 1e6  # [µm] along the axis
    distances = np.abs(x - x.mean(axis=-1, keepdims=True))
    rp_l = distances.mean(axis=-1) + 3 * distances.std(axis=-1, ddof=1)
    return np.abs(x[0].mean(axis=-1) - x[1].mean(axis=-1)), np.abs(rp_l[0] - rp_l[1])


@pytest.mark.parametrize("rho", [0.0, 0.9])
def test_stationary_friction_drifts_as_two_independent_sets_differ(rho):
    """No warm-up: the first and last sets 300 cycles apart are independent (0.9³⁰⁰ = 2e-14), so dAP_p and dRP_l are
    E|AP₁ − AP₂| and E|RP₁ − RP₂| of two independent sets (not 0): within 4 combined standard errors."""
    friction = {"law": "gaussian", "mean": MEAN, "std": STD, **({"ar1": rho} if rho else {})}
    drift = drift_of(drift_study(friction))
    ap, rp = independent_sets(rho, 100_000, np.random.default_rng(11))
    for name, values in (("dAP_p_um", ap), ("dRP_l_um", rp)):
        error = math.hypot(drift["mc_errors"][name] * drift[name], values.std(ddof=1) / math.sqrt(values.size))
        assert abs(drift[name] - values.mean()) <= 4 * error, (name, drift[name], values.mean(), error)
        assert drift["mc_errors"][name] <= 0.01
    assert drift["tests"] == 8_000 and drift["span_cycles"] == SPAN and drift["start"] == "cold"


def thermal_recursion(start_C: float, per_K: float = -0.005) -> tuple[np.ndarray, np.ndarray]:
    """(SPAN,) the lost motion [µm] of a constant friction warming ``per_K`` relative change per kelvin, and the
    temperature [°C] at each cycle's start, cycle by cycle."""
    temperature, out, temperatures = start_C, [], []
    for _ in range(SPAN):
        temperatures.append(temperature)
        mu = MEAN * (1 + per_K * (temperature - 20.0))
        out.append(mu * LOAD_N / STIFFNESS * 1e6)
        settled = 20.0 + 2.0 * mu * LOAD_N * 0.5 / 10.0
        temperature = settled + (temperature - settled) * math.exp(-10.0 / 600.0)
    return np.array(out), np.array(temperatures)


def thermal_lost_motion(start_C: float) -> np.ndarray:
    """(SPAN,) the lost motion [µm] of a constant friction warming 0.5 % less per kelvin, cycle by cycle."""
    return thermal_recursion(start_C)[0]


def thermal_study(per_K: float) -> dict:
    """A constant friction heating its joint (0.6 W over 2 K/W, τ = 600 s), ``per_K`` relative change per kelvin."""
    friction = {"law": "constant", "mu": MEAN, "thermal": {"time_constant_s": 600.0, "resistance_K_per_W": 2.0,
                                                          "mu_per_K": per_K}}
    study = drift_study(friction)
    study["joints"]["travel_per_cycle"] = 0.5
    return study


def rp_l(sets: np.ndarray) -> np.ndarray:
    """RP_l = l̄ + 3 S_l of each row's (k, n) values along one axis."""
    distances = np.abs(sets - sets.mean(axis=-1, keepdims=True))
    return distances.mean(axis=-1) + 3 * distances.std(axis=-1, ddof=1)


def test_a_warm_up_moves_the_barycentre_by_what_the_thermal_model_implies():
    """A constant friction (0.6 W, 1.2 K at most: 0.5 % of the lost motion): every test the same, dAP_p the two
    sets' barycentres' distance computed here from the thermal recursion, dRP_l their RP_l's difference; warm
    (settled at the start), nothing moves."""
    study = thermal_study(-0.005)
    cold = drift_of(study)
    lost = thermal_lost_motion(20.0)
    first, last = lost[:SET], lost[-SET:]
    assert cold["dAP_p_um"] == pytest.approx(abs(first.mean() - last.mean()), rel=1e-9)
    spread = [np.abs(s - s.mean()) for s in (first, last)]
    rp_l = [d.mean() + 3 * d.std(ddof=1) for d in spread]
    assert cold["dRP_l_um"] == pytest.approx(abs(rp_l[0] - rp_l[1]), rel=1e-6)
    assert cold["dAP_p_um"] > 0.004 * lost[0] and cold["mc_errors"]["dAP_p_um"] < 1e-9
    study["drift"]["start"] = "warm"
    assert drift_of(study)["dAP_p_um"] < 1e-9 * lost[0]


def test_the_sets_are_a_set_apart_from_the_start_set_to_the_end_set():
    """At most 5 sets, as many as fit without overlapping, the first and last the drift figures' own."""
    assert DriftTest(SPAN, SET).set_starts().tolist() == [0, 82, 165, 248, 330]
    assert DriftTest(100, 30).set_starts().tolist() == [0, 35, 70]
    assert DriftTest(60, 30).set_starts().tolist() == [0, 30]
    for span in range(20, 200):
        starts = DriftTest(span, 10).set_starts()
        assert starts[0] == 0 and starts[-1] == span - 10 and np.all(np.diff(starts) >= 10), span


def test_the_sets_along_the_span_follow_the_thermal_recursion():
    """Constant friction warming 0.5 % less per kelvin: every test the same, so each set's AP_p and RP_l along the
    span are those of the lost motion the thermal recursion gives here, the end sets' changes are summary.json's dAP_p
    and dRP_l, and the joint's temperature at every cycle the recursion's (no Monte Carlo spread)."""
    result = run_study(thermal_study(-0.005))
    drift, figures = result.drifts[0], result.poses[0].direction_figures("+")["drift"]
    lost, temperature = thermal_recursion(20.0)
    sets = lost[drift.set_starts[:, None] + np.arange(SET)]
    series = drift.directions["+"]
    assert series.AP_p_m * 1e6 == pytest.approx(sets.mean(axis=1), rel=1e-9)
    assert series.RP_l_m * 1e6 == pytest.approx(rp_l(sets), rel=1e-6)
    assert abs(series.AP_p_m[-1] - series.AP_p_m[0]) * 1e6 == pytest.approx(figures["dAP_p_um"], rel=1e-9)
    assert abs(series.RP_l_m[-1] - series.RP_l_m[0]) * 1e6 == pytest.approx(figures["dRP_l_um"], rel=1e-9)
    assert np.all(series.AP_p_change_error_m < 1e-15) and np.all(drift.temperature_error_C < 1e-9)
    assert drift.temperature_C[:, 0] == pytest.approx(temperature, abs=1e-9)
    assert drift.joints == tuple(result.settings["joints"]) and drift.pose == "P1"
    assert drift.set_times_s == pytest.approx((drift.set_starts + SET / 2) * 10.0)


def test_the_temperature_curve_is_the_closed_form_and_a_warm_start_stays_settled():
    """Friction that does not depend on temperature dissipates a constant 0.6 W: T(t) = 20 + R·P·(1 − exp(−t/τ)) at
    each cycle's start t = 10 s·k; warm, every cycle at 20 + R·P."""
    study = thermal_study(0.0)
    power = MEAN * LOAD_N * 0.5 / 10.0
    cold = run_study(study).drifts[0]
    closed = 20.0 + 2.0 * power * (1 - np.exp(-cold.cycle_times_s / 600.0))
    assert cold.temperature_C[:, 0] == pytest.approx(closed, abs=1e-9)
    study["drift"]["start"] = "warm"
    warm = run_study(study).drifts[0]
    assert warm.temperature_C[:, 0] == pytest.approx(np.full(SPAN, 20.0 + 2.0 * power), abs=1e-9)


def test_each_tests_end_sets_are_its_drift_figures_inputs():
    """Random friction (AR(1) 0.9, warming): in each simulated test, dRP_l and dAP_p are the changes of its end sets'
    RP_l and AP_p (along one axis, AP_p is the barycentre's offset), and the temperatures' mean over the tests is
    that of the draws' own warm-up (draw_series from the same stream), to the bit: the temperatures the draws were
    taken at, not recomputed."""
    axis = load_urdf(AXIS_URDF, "tool")
    thermal = Thermal(600.0, 2.0, mu_per_K=-0.005)
    model = JointErrorModel(Gaussian(mean=MEAN, std=STD), STIFFNESS, normal_force_N=LOAD_N, travel_per_cycle=0.5,
                            series=FrictionSeries(ar1=0.9, thermal=thermal))
    runner = PoseRunner(TestSettings(SET, cycle_time_s=10.0), axis, [model])
    task = pose_task(axis, "P1", [0.2])
    block = drift_tests(runner, task, runner.normal_forces(task), np.ones(1), DriftTest(SPAN, SET), 200,
                        np.random.default_rng(5))
    assert block.AP_p_m.shape == block.RP_l_m.shape == (200, 5)
    assert block.figures["dRP_l_um"] == pytest.approx(np.abs(block.RP_l_m[:, -1] - block.RP_l_m[:, 0]) * 1e6,
                                                      rel=1e-12)
    assert block.figures["dAP_p_um"] == pytest.approx(np.abs(block.AP_p_m[:, -1] - block.AP_p_m[:, 0]) * 1e6,
                                                      rel=1e-9)
    power = thermal_drive(model, torque_per_value([model], axis.joint_is_prismatic, [LOAD_N])[0], 10.0)[0]
    assert power == pytest.approx(power_per_value(0.5, 10.0, LOAD_N), rel=1e-15)  # N at a prismatic joint
    drawn = draw_series(model.friction, model.series, 200, SPAN, np.random.default_rng(5), power, 10.0)
    assert np.array_equal(block.temperature_C[:, 0], drawn.temperature_C.mean(axis=0))
    assert block.temperature_squares[:, 0] == pytest.approx(drawn.temperature_C.var(axis=0) * 200, rel=1e-6,
                                                            abs=1e-18)
