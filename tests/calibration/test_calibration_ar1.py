"""A joint group's ar1 from measured series in time order: synthetic series of a known AR(1) recover it within its
interval at the stated coverage, two groups are told apart by the series each dominates, a group dominating none and
series too short are a reason (one line) instead, and a series' shares are its joints' parts of the fitted model's
variance along its main axis."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tribokin.calibration.ar1 import DOMINANT, TimedSeries, fit_group_ar1, restricted_log_likelihood, timed_series
from tribokin.calibration.data import PoseData, SeriesData
from tribokin.calibration.model import JointModel

GROUP = [("joints.friction_torque_Nm", ("a",))]


def ar1(rho: float, shape: tuple[int, ...], rng: np.random.Generator) -> np.ndarray:
    """Stationary Gaussian AR(1) series of unit variance along the last axis of ``shape``."""
    x = np.empty(shape)
    x[..., 0] = rng.normal(0, 1, shape[:-1])
    for t in range(1, shape[-1]):
        x[..., t] = rho * x[..., t - 1] + rng.normal(0, math.sqrt(1 - rho * rho), shape[:-1])
    return x


def deviations(rhos, shares, series: int, cycles: int, rng: np.random.Generator) -> list[TimedSeries]:
    """``series`` series of ``cycles`` cycles: per group an AR(1) of ``rhos[g]`` weighted by its share, plus
    independent noise for the rest, on an offset (the barycentre) and a scale [m] of its own per series."""
    shares = np.asarray(shares, dtype=float)
    u = sum(math.sqrt(w) * ar1(rho, (series, cycles), rng) for rho, w in zip(rhos, shares, strict=True))
    u = u + math.sqrt(1 - shares.sum()) * rng.normal(size=(series, cycles))
    scale = rng.uniform(1e-6, 1e-5, (series, 1))
    return [TimedSeries(row, shares) for row in 0.3 + scale * u]


@pytest.mark.parametrize("rho", [0.0, 0.6])
def test_a_known_ar1_is_recovered_within_its_interval_at_its_coverage(rho):
    """100 data sets of 15 series of 30 cycles (the shipped UR5 file's layout), the group 0.8 of each series'
    variance: the 95 % intervals cover the truth 88-99.5 % of the time (96 % at both here with 200), and the mean
    estimate is within 4 standard errors of it (restricted likelihood: no short-series bias; plain r1 would be low by
    (1 + 4 rho)/n = 0.11 at 0.6)."""
    rng = np.random.default_rng(38)
    fits = [fit_group_ar1(deviations([rho], [0.8], 15, 30, rng), GROUP).groups[0].estimate for _ in range(100)]
    values = np.array([f.value for f in fits])
    coverage = np.mean([f.covers(rho) for f in fits])
    assert 0.88 <= coverage <= 0.995, coverage
    assert abs(values.mean() - rho) < 4 * values.std() / math.sqrt(len(values)), values.mean()
    assert all(f.low < f.value < f.high for f in fits)


def test_two_groups_are_told_apart_by_the_series_each_dominates_and_a_third_is_a_reason():
    """Half the series dominated by group A (rho 0.6), half by B (rho 0): each estimate covers its truth and is
    within 0.1 of it; C, at most 0.05 of any series, is not estimated and says why."""
    rng = np.random.default_rng(5)
    series = (deviations([0.6, 0.0, 0.9], [0.7, 0.1, 0.05], 15, 30, rng)
              + deviations([0.6, 0.0, 0.9], [0.1, 0.7, 0.05], 15, 30, rng))
    groups = [("joints.friction", ("a", "b")), ("joints.c.friction", ("c",)), ("joints.d.friction", ("d",))]
    fitted = fit_group_ar1(series, groups)
    a, b, c = fitted.groups
    assert fitted.reason == "" and fitted.series == 30 and fitted.longest == 30
    assert a.estimate.covers(0.6) and abs(a.estimate.value - 0.6) < 0.1 and a.series == 15
    assert b.estimate.covers(0.0) and abs(b.estimate.value) < 0.1 and b.series == 15
    assert c.estimate is None and c.largest_share == pytest.approx(0.05)
    assert c.reason.startswith("its joints give at most 0.05 of a series' deviations")


def test_series_too_short_are_one_line_naming_the_longest():
    """The IPA UR10 file's layout: 2-5 cycles per series. No estimate, one line saying why."""
    rng = np.random.default_rng(1)
    series = [TimedSeries(rng.normal(size=n), np.array([0.9])) for n in (2, 3, 5, 9, 3)]
    fitted = fit_group_ar1(series, GROUP)
    assert fitted.reason == ("no series has 10 or more cycles in time order (the longest has 9): too short to tell "
                             "one cycle's friction from the next's")
    assert "\n" not in fitted.reason and fitted.series == 0
    assert [g.estimate for g in fitted.groups] == [None]


def test_no_group_dominating_a_series_is_the_fit_s_reason():
    rng = np.random.default_rng(2)
    fitted = fit_group_ar1(deviations([0.5], [0.3], 5, 20, rng), GROUP)
    assert fitted.reason.startswith(f"no joint group gives {DOMINANT:g} or more of the deviations")
    assert fitted.groups[0].estimate is None
    no_friction = fit_group_ar1([TimedSeries(s.deviations_m, np.zeros(0)) for s in deviations([0.5], [0.3], 5, 20,
                                                                                                rng)], [])
    assert no_friction.groups == () and no_friction.reason.startswith("no joint group gives")


def test_the_likelihood_of_one_group_without_noise_is_the_ar1_restricted_likelihood():
    """One group, share 1: ℓ(ρ) is −½[(n − 1)·log(rᵀPr) + log|C| + log(1ᵀC⁻¹1)] with C the AR(1) correlation,
    here by its closed forms: |C| = (1 − ρ²)^(n−1), C⁻¹ tridiagonal (1, −ρ; 1 + ρ² inside)/(1 − ρ²); its gradient
    is the central difference's."""
    u = np.random.default_rng(3).normal(size=12)
    rho, n = 0.4, 12
    inverse = (np.diag(np.r_[1, np.full(n - 2, 1 + rho * rho), 1]) - rho * np.eye(n, k=1) - rho * np.eye(n, k=-1)
               ) / (1 - rho * rho)
    ones = np.ones(n)
    centred = u - u.mean()  # ℓ is the same for u + c·1; the dropped constants are those of u's own scale
    scaled = centred / np.sqrt(np.mean(centred ** 2))
    residual = scaled @ inverse @ scaled - (ones @ inverse @ scaled) ** 2 / (ones @ inverse @ ones)
    expected = -0.5 * ((n - 1) * math.log(residual) + (n - 1) * math.log(1 - rho * rho)
                       + math.log(ones @ inverse @ ones))
    value, gradient = restricted_log_likelihood(np.array([rho]), [TimedSeries(u, np.array([1.0]))])
    assert value == pytest.approx(expected, rel=1e-12)
    step = 1e-6
    ends = [restricted_log_likelihood(np.array([rho + h]), [TimedSeries(u, np.array([1.0]))])[0] for h in (step, -step)]
    assert gradient[0] == pytest.approx((ends[0] - ends[1]) / (2 * step), rel=1e-6)


def test_a_series_shares_are_its_joints_parts_of_the_model_s_variance_along_its_main_axis():
    """A gantry-like pose (joint i moves the tool along axis i): a cloud long along y is y's; its share is
    (σ_τ/k)² of y over that plus the noise floor², and the others' nearly 0; the deviations follow t_s's order."""
    model = JointModel(("x", "y", "z"), np.array([2e6, 1e6, 3e6]), np.zeros(3), 1e-6, (True,) * 3, (True,) * 3,
                       True, prismatic=(True,) * 3)
    rng = np.random.default_rng(4)
    points = np.column_stack([rng.normal(0, 1e-6, 20), rng.normal(0, 5e-6, 20), rng.normal(0, 1e-6, 20)])
    times = rng.permutation(20).astype(float)
    pose = PoseData("P1", np.eye(3), np.full(3, 20.0), np.full(3, 5.0),
                    (SeriesData("+", np.ones(3), points, times),))
    (series,) = timed_series(model, [pose], np.array([0, 1, 1]), 2)
    std = 5.0 / model.stiffness
    axis = np.linalg.eigh(np.cov(points.T))[1][:, -1]
    variance = (axis ** 2 * std ** 2)
    assert series.shares == pytest.approx([variance[0], variance[1:].sum()] / (variance.sum() + 1e-12))
    assert series.shares[1] > 0.9
    ordered = points[np.argsort(times)]
    assert series.deviations_m == pytest.approx((ordered - ordered.mean(axis=0)) @ axis * np.sign(
        series.deviations_m[0] * ((ordered[0] - ordered.mean(axis=0)) @ axis)))
