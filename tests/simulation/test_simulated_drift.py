"""ISO 9283's drift test simulated at a pose (``[drift]``, :mod:`tribokin.simulation.drift`): stationary friction
gives the absolute differences of two independent sets, computed here by an independent Monte Carlo; a warm-up moves
the barycentre by what the thermal model implies; a warm start is settled."""

from __future__ import annotations

import math

import numpy as np
import pytest

from conftest import axis_study
from tribokin import run_study

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


def thermal_lost_motion(start_C: float) -> np.ndarray:
    """(SPAN,) the lost motion [µm] of a constant friction warming 0.5 % less per kelvin, cycle by cycle."""
    temperature, out = start_C, []
    for _ in range(SPAN):
        mu = MEAN * (1 - 0.005 * (temperature - 20.0))
        out.append(mu * LOAD_N / STIFFNESS * 1e6)
        settled = 20.0 + 2.0 * mu * LOAD_N * 0.5 / 10.0
        temperature = settled + (temperature - settled) * math.exp(-10.0 / 600.0)
    return np.array(out)


def test_a_warm_up_moves_the_barycentre_by_what_the_thermal_model_implies():
    """A constant friction (0.6 W, 1.2 K at most: 0.5 % of the lost motion): every test the same, dAP_p the two
    sets' barycentres' distance computed here from the thermal recursion, dRP_l their RP_l's difference; warm
    (settled at the start), nothing moves."""
    friction = {"law": "constant", "mu": MEAN, "thermal": {"time_constant_s": 600.0, "resistance_K_per_W": 2.0,
                                                          "mu_per_K": -0.005}}
    study = drift_study(friction)
    study["joints"]["travel_per_cycle"] = 0.5
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
