"""Friction as a time series (tribology.friction_series): the known answers of issue 38 at the library's level.

Each check draws 10⁵-10⁶ values at once (seeded: the same numbers every run) and compares them with a closed form:
E[S²] of a Gaussian AR(1), the copula's marginal (Kolmogorov-Smirnov; an empirical law's frequencies, chi-square)
and its lag-one correlation (within 4 standard errors of ``ar1`` over 10⁶ independent pairs, the error estimated
from 100 batches), and the copula's correlation function against the closed forms of the uniform and lognormal
laws and of a two-valued empirical law.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from tribokin.errors import LawError
from tribokin.tribology.friction_series import (
    FrictionSeries,
    RunIn,
    copula_correlation,
    draw_series,
    expected_sample_variance,
    latent_correlation,
    latent_series,
    normal_quantile,
)
from tribokin.tribology.laws import Constant, Empirical, Gaussian, Lognormal, Scaled, Uniform

#: A Gaussian law with mean >= 6σ (the 42CD4-treated preset's), a truncated one (mean 1.5σ), and the others.
GAUSSIAN = Gaussian(0.1375, 0.0075)
TRUNCATED = Gaussian(0.03, 0.02)
UNIFORM = Uniform(0.09, 0.16)
LOGNORMAL = Lognormal(0.12, 0.04)
EMPIRICAL = Empirical([0.10, 0.12, 0.12, 0.13, 0.15, 0.15, 0.15, 0.19])


@pytest.mark.parametrize("ar1, tests", [(0.5, 30_000), (0.9, 60_000), (0.99, 120_000)])
def test_sample_variance_of_a_gaussian_ar1_is_the_closed_form(ar1, tests):
    """E[S²] = σ²·(1 − 2/(n(n − 1))·Σₖ (n − k)·ρᵏ) for 30 cycles, within 1 %, the check's own standard error at
    most 0.3 % (120 000 tests at ρ = 0.99)."""
    mu = draw_series(GAUSSIAN, FrictionSeries(ar1=ar1), tests, 30, np.random.default_rng(38)).values
    variances = mu.var(axis=1, ddof=1)
    expected = expected_sample_variance(GAUSSIAN.params["std"], ar1, 30)
    error = variances.std(ddof=1) / math.sqrt(tests) / expected
    assert error <= 0.003
    assert variances.mean() / expected == pytest.approx(1, abs=0.01)
    assert expected < GAUSSIAN.params["std"] ** 2 * (0.9 if ar1 > 0.5 else 1)  # correlation shrinks it


def test_the_closed_form_of_independent_cycles_is_the_variance():
    assert expected_sample_variance(2.0, 0.0, 30) == 4.0
    # n = 3, ρ = 0.5: 1 − 2/6·(2·0.5 + 1·0.25) = 1 − 1.25/3
    assert expected_sample_variance(1.0, 0.5, 3) == pytest.approx(1 - 1.25 / 3)


def lag_one(law, ar1, pairs=1_000_000, seed=7):
    """μ's lag-one correlation over ``pairs`` independent series of two cycles, its standard error (100 batches)
    and the values."""
    mu = draw_series(law, FrictionSeries(ar1=ar1), pairs, 2, np.random.default_rng(seed)).values
    batches = [np.corrcoef(part[:, 0], part[:, 1])[0, 1] for part in np.split(mu, 100)]
    return np.corrcoef(mu[:, 0], mu[:, 1])[0, 1], np.std(batches, ddof=1) / 10, mu


@pytest.mark.parametrize("law", [UNIFORM, TRUNCATED, LOGNORMAL], ids=["uniform", "truncated", "lognormal"])
@pytest.mark.parametrize("ar1", [0.5, 0.9, 0.99])
def test_copula_keeps_the_marginal_and_reaches_ar1(law, ar1):
    estimate, error, mu = lag_one(law, ar1)
    assert abs(estimate - ar1) <= 4 * error
    assert error < 2e-3 * (1 - ar1 ** 2)  # at 0.99: 4e-5, far below the 0.001 the test must see
    assert stats.kstest(mu[:100_000, 1], law._dist.cdf).pvalue > 1e-3  # the second cycle of independent series


def test_the_check_sees_the_latent_correlation_left_at_ar1():
    """A uniform law through a latent correlation of 0.99 itself has a lag-one correlation of 0.99 − 0.0010: 4
    standard errors of 10⁶ pairs are far smaller, so the test above would fail it."""
    z = latent_series(1_000_000, 2, 0.99, np.random.default_rng(7))
    mu = normal_quantile(UNIFORM, z)
    naive = np.corrcoef(mu[:, 0], mu[:, 1])[0, 1]
    _, error, _ = lag_one(UNIFORM, 0.99)
    assert 0.99 - naive > 20 * error
    assert 6 / math.pi * math.asin(0.99 / 2) == pytest.approx(0.99 - 0.00101, abs=1e-5)


def test_copula_correlation_against_closed_forms():
    """Uniform: (6/π)·arcsin(r/2); lognormal: (e^(s²r) − 1)/(e^(s²) − 1); two equally likely values (a step at 0):
    (2/π)·arcsin r (the orthant probability); from r = −0.999 to 0.9999."""
    r = np.array([-0.999, -0.7, -0.2, 0.1, 0.5, 0.9, 0.99, 0.9999])
    s2 = LOGNORMAL._sigma_log ** 2
    assert copula_correlation(UNIFORM)(r) == pytest.approx(6 / np.pi * np.arcsin(r / 2), abs=1e-12)
    assert copula_correlation(LOGNORMAL)(r) == pytest.approx(np.expm1(s2 * r) / math.expm1(s2), abs=1e-12)
    assert copula_correlation(Empirical([0.1, 0.2]))(r) == pytest.approx(2 / np.pi * np.arcsin(r), abs=2e-5)


def test_a_few_valued_law_reaches_ar1_by_its_exact_correlation():
    """Three values, each 1/3: cov(r) = Σᵢⱼ dᵢdⱼ·∫₀ʳ φ₂(tᵢ, tⱼ; s) ds (Plackett's identity, by quad), tᵢ = Φ⁻¹(i/3),
    dᵢ the jumps between values. ``ar1`` = 0.99 needs a latent correlation of 0.99975, whose series needs far more
    than the first 4000 Hermite terms: the solved r gives 0.99 to 1e-10."""
    from scipy.integrate import quad
    from scipy.special import ndtri

    law = Empirical([0.10, 0.12, 0.15])
    thresholds, jumps = ndtri(np.array([1 / 3, 2 / 3])), np.diff(law.values)

    def exact(r):
        def density(s, h, k):
            return math.exp(-(h * h - 2 * s * h * k + k * k) / (2 * (1 - s * s))) / (2 * math.pi * math.sqrt(1 - s * s))
        cov = sum(jumps[i] * jumps[j] * quad(density, 0, r, args=(thresholds[i], thresholds[j]), epsabs=1e-14,
                                              epsrel=1e-13, limit=500)[0] for i in range(2) for j in range(2))
        return cov / law.values.var()
    r = latent_correlation(law, 0.99)
    assert r > 0.9997
    assert exact(r) == pytest.approx(0.99, abs=1e-10)
    assert copula_correlation(law)(0.9) == pytest.approx(exact(0.9), abs=1e-13)


def test_gaussian_law_beyond_six_sigma_is_a_gaussian_ar1():
    assert latent_correlation(GAUSSIAN, 0.9) == 0.9
    z = np.linspace(-5, 5, 11)
    assert normal_quantile(GAUSSIAN, z) == pytest.approx(0.1375 + 0.0075 * z, abs=1e-12)
    assert latent_correlation(TRUNCATED, 0.9) > 0.9  # the truncation bends the map: the latent one is solved


def test_empirical_law_keeps_its_frequencies_and_reaches_ar1():
    values = draw_series(EMPIRICAL, FrictionSeries(ar1=0.9), 100_000, 4, np.random.default_rng(3)).values[:, 3]
    levels, counts = np.unique(EMPIRICAL.values, return_counts=True)
    observed = np.array([np.sum(values == level) for level in levels])
    assert observed.sum() == values.size
    assert stats.chisquare(observed, counts / counts.sum() * values.size).pvalue > 1e-3
    for ar1 in (0.5, 0.9, 0.99):
        estimate, error, _ = lag_one(EMPIRICAL, ar1, seed=11)
        assert abs(estimate - ar1) <= 4 * error


def test_scaled_law_is_its_inner_law_scaled():
    torque = Scaled(UNIFORM, 1024.0, "friction_torque_Nm")
    z = np.linspace(-3, 3, 7)
    assert normal_quantile(torque, z) == pytest.approx(1024 * normal_quantile(UNIFORM, z))
    assert latent_correlation(torque, 0.9) == latent_correlation(UNIFORM, 0.9)


def test_an_ar1_the_law_cannot_reach_is_refused():
    """A lognormal law's most negative lag-one correlation is −exp(−σ_log²) (its latent one at −1)."""
    floor = -math.exp(-LOGNORMAL._sigma_log ** 2)
    assert copula_correlation(LOGNORMAL)(-1.0) == pytest.approx(floor)
    assert latent_correlation(LOGNORMAL, floor + 0.01) > -1
    wide = Lognormal(0.12, 0.2)  # σ_log² = ln(1 + (0.2/0.12)²) = 1.329: nothing below −0.2647
    with pytest.raises(LawError, match=r"below -0\.2647, the most negative") as error:
        latent_correlation(wide, -0.5)
    assert error.value.parameter == "ar1"
    with pytest.raises(LawError, match="zero width") as error:
        latent_correlation(Constant(0.1), 0.5)
    assert latent_correlation(UNIFORM, -0.99) == pytest.approx(2 * math.sin(-0.99 * math.pi / 6))


def test_run_in_offset_and_age():
    """The mean over tests follows μ∞ + (start − μ∞)·exp(−(age + k)/τ); the per-test offset's spread shows in the
    spread of the tests' means."""
    series = FrictionSeries(run_in=RunIn(0.2, 10.0), age_cycles=5.0, steady_mean_std=0.01)
    mu = draw_series(GAUSSIAN, series, 100_000, 40, np.random.default_rng(2)).values
    curve = GAUSSIAN.mean() + (0.2 - GAUSSIAN.mean()) * np.exp(-(5 + np.arange(40)) / 10)
    assert mu.mean(axis=0) == pytest.approx(curve, abs=4 * 0.0125 / math.sqrt(100_000))
    tail = mu[:, 30:].mean(axis=1)  # the offset, (1 − e^(−(age + k)/τ)) of it, and the law's spread over 10 cycles
    settled = np.mean(1 - np.exp(-(5 + np.arange(30, 40)) / 10))
    assert tail.var() == pytest.approx((0.01 * settled) ** 2 + GAUSSIAN.std() ** 2 / 10, rel=0.02)


def test_independent_series_are_the_laws_own_draws():
    drawn = draw_series(UNIFORM, FrictionSeries(), 3, 4, np.random.default_rng(1)).values
    assert np.array_equal(drawn, UNIFORM.rvs((3, 4), np.random.default_rng(1)))


@pytest.mark.parametrize("values, parameter", [
    ({"ar1": 1.0}, "ar1"), ({"ar1": float("nan")}, "ar1"), ({"age_cycles": -1.0}, "age_cycles"),
    ({"steady_mean_std": -0.1}, "steady_mean_std"), ({"age_cycles": 100.0}, "age_cycles"),
])
def test_bad_series_values_are_refused_naming_them(values, parameter):
    with pytest.raises(LawError) as error:
        FrictionSeries(**values)
    assert error.value.parameter == parameter
    with pytest.raises(LawError, match="> 0 cycles") as error:
        RunIn(0.2, -1.0)
    assert error.value.parameter == "run_in.tau_cycles"
