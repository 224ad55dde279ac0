"""A tribometer log as a time series: its steady cycles' lag-one autocorrelation (``ar1``) and their test of
independence (Ljung-Box), and its running-in curve fitted with AR(1) errors.

The running-in, mu_c = μ∞ + (start − μ∞)·exp(−c/τ) + e_c (c counted from the log's first cycle), is fitted by
maximum likelihood with e an AR(1) (Prais-Winsten's exact transformation; μ∞ and start are then linear, profiled
out; τ and the noise's φ found by Nelder-Mead from a grid of τ). Its intervals come from the whitened Jacobian:
cov = σ̂²·(J*ᵀJ*)⁻¹, the asymptotic covariance of a nonlinear regression with AR(1) errors (φ estimated
independently of the mean's parameters); τ's interval on log τ; Student's t quantile with the effective number of
cycles, n·(1 − φ)/(1 + φ), less the 3 parameters as degrees of freedom. Ignoring the autocorrelation (φ = 0) would
make them far too narrow: at φ = 0.9 a 95 % interval covers about a third of the time.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np
from scipy import optimize, stats

#: Two-sided 95 % normal quantile.
Z95 = float(stats.norm.ppf(0.975))
#: The Ljung-Box test's lags: min(10, cycles // 5) (Box, Jenkins & Reinsel's common choice for short series).
LJUNG_BOX_LAGS = 10
#: The running-in's τ is sought from this many cycles to this share of the log's length.
TAU_RANGE = (0.5, 0.5)
#: Below this p-value the steady cycles are not consistent with independence: ``ar1`` is written.
INDEPENDENCE_LEVEL = 0.05


@dataclass(frozen=True)
class Estimate:
    """An estimate and its 95 % interval."""

    value: float
    low: float
    high: float

    def covers(self, truth: float) -> bool:
        """The interval holds ``truth``."""
        return self.low <= truth <= self.high


@dataclass(frozen=True)
class LjungBox:
    """The Ljung-Box portmanteau test: Q = n(n + 2)·Σₖ₌₁ʰ r_k²/(n − k), chi-square with h degrees of freedom under
    independence."""

    q: float
    lags: int
    pvalue: float

    @property
    def independent(self) -> bool:
        """The cycles are consistent with independence at the 5 % level."""
        return self.pvalue >= INDEPENDENCE_LEVEL


def autocorrelations(x: np.ndarray, lags: int) -> np.ndarray:
    """The sample autocorrelations r_1 .. r_lags of ``x`` about its mean (Σ d_t·d_{t+k} / Σ d_t²)."""
    d = np.asarray(x, dtype=float) - np.mean(x)
    return np.array([d[:-k] @ d[k:] for k in range(1, lags + 1)]) / (d @ d)


def ljung_box(x: np.ndarray, lags: int | None = None) -> LjungBox:
    """The Ljung-Box test of ``x``'s independence over ``lags`` lags (default min(10, n // 5))."""
    n = len(x)
    lags = lags if lags is not None else max(1, min(LJUNG_BOX_LAGS, n // 5))
    r = autocorrelations(x, lags)
    q = float(n * (n + 2) * np.sum(r * r / (n - np.arange(1, lags + 1))))
    return LjungBox(q, lags, float(stats.chi2.sf(q, lags)))


def fit_ar1(x: np.ndarray) -> Estimate:
    """The lag-one autocorrelation of ``x`` and its 95 % interval: r₁ ± 1.96·√((1 − r₁²)/n), Bartlett's variance of
    r₁ for an AR(1) (1/n only under independence), clipped to (−1, 1)."""
    r = float(autocorrelations(x, 1)[0])
    half = Z95 * math.sqrt(max(1 - r * r, 0.0) / len(x))
    return Estimate(r, max(r - half, -1.0), min(r + half, 1.0))


@dataclass(frozen=True)
class RunInFit:
    """A running-in curve fitted with AR(1) errors: μ∞, start and τ [cycles] with 95 % intervals, the noise's
    lag-one correlation ``noise_ar1`` and its innovations' standard deviation ``innovation_std`` [-], the log's
    ``cycles``, and whether τ was ``identified`` (found within its range, not at an end of it)."""

    mu_inf: Estimate
    start: Estimate
    tau_cycles: Estimate
    noise_ar1: float
    innovation_std: float
    cycles: int
    identified: bool = True

    @property
    def significant(self) -> bool:
        """τ lies within its range and the start differs from the steady mean beyond its interval: there is a
        running-in to write."""
        return self.identified and not self.start.covers(self.mu_inf.value)

    def summary(self) -> dict:
        """As ``fit.json`` gives it."""
        return asdict(self)


def _whiten(a: np.ndarray, phi: float) -> np.ndarray:
    """Prais-Winsten's transformation along the first axis: √(1 − φ²)·a₀, then a_t − φ·a_{t−1}."""
    out = np.array(a, dtype=float)
    out[1:] -= phi * a[:-1]
    out[0] *= math.sqrt(1 - phi * phi)
    return out


def _profile(c: np.ndarray, mu: np.ndarray, tau: float, phi: float):
    """(μ∞, excess), residual sum of squares and −log-likelihood (σ profiled out) at (τ, φ): least squares on the
    whitened columns by their 2 × 2 normal equations."""
    ones, decay, target = _whiten(np.ones_like(c), phi), _whiten(np.exp(-c / tau), phi), _whiten(mu, phi)
    gram = np.array([[ones @ ones, ones @ decay], [ones @ decay, decay @ decay]])
    beta = np.linalg.solve(gram, [ones @ target, decay @ target])
    rss = float(np.sum((target - beta[0] * ones - beta[1] * decay) ** 2))
    return beta, rss, 0.5 * c.size * math.log(rss / c.size) - 0.5 * math.log(1 - phi * phi)


def fit_run_in(cycle: np.ndarray, mu: np.ndarray, autocorrelated: bool = True) -> RunInFit:
    """Fit μ∞ + (start − μ∞)·exp(−c/τ) to a log (``cycle``, ``mu`` [-]) with AR(1) errors (``autocorrelated``;
    ``False``: independent errors, φ = 0, what intervals that ignore the autocorrelation give). τ is sought within
    [``TAU_RANGE[0]``, ``TAU_RANGE[1]``·n]: a running-in shorter than a cycle, or longer than half the log, is not
    told from noise or a drift by the log; one at either end is not ``identified``.

    Returns:
        the estimates with their 95 % intervals; c counts from the log's first cycle, so ``start`` is mu there.
    """
    c = np.asarray(cycle, dtype=float) - cycle[0]
    mu = np.asarray(mu, dtype=float)
    n = c.size
    low, high = math.log(TAU_RANGE[0]), math.log(TAU_RANGE[1] * n)
    taus = np.exp(np.linspace(low, high, 48))
    tau0 = taus[int(np.argmin([_profile(c, mu, tau, 0.0)[2] for tau in taus]))]
    if autocorrelated:
        beta, _, _ = _profile(c, mu, tau0, 0.0)
        residual = mu - beta[0] - beta[1] * np.exp(-c / tau0)
        phi0 = float(np.clip(autocorrelations(residual, 1)[0], -0.95, 0.95))

        def objective(theta):
            inside = low <= theta[0] <= high and abs(theta[1]) < 10
            return _profile(c, mu, math.exp(theta[0]), math.tanh(theta[1]))[2] if inside else math.inf
        best = optimize.minimize(objective, [math.log(tau0), math.atanh(phi0)], method="Nelder-Mead",
                                 options={"xatol": 1e-4, "fatol": 1e-9, "maxiter": 2000})
        tau, phi = math.exp(best.x[0]), math.tanh(best.x[1])
    else:
        best = optimize.minimize_scalar(lambda t: _profile(c, mu, math.exp(t), 0.0)[2], bounds=(low, high),
                                        method="bounded", options={"xatol": 1e-6})
        tau, phi = math.exp(best.x), 0.0
    identified = low + 0.01 < math.log(tau) < high - 0.01
    (mu_inf, excess), rss, _ = _profile(c, mu, tau, phi)
    decay = np.exp(-c / tau)
    jacobian = _whiten(np.column_stack([np.ones_like(c), decay, excess * c / tau ** 2 * decay]), phi)
    variance = rss / (n - 3)
    cov = variance * np.linalg.pinv(jacobian.T @ jacobian)
    se_inf = math.sqrt(cov[0, 0])
    se_start = math.sqrt(cov[0, 0] + cov[1, 1] + 2 * cov[0, 1])
    se_log_tau = math.sqrt(cov[2, 2]) / tau
    start = mu_inf + excess
    z = float(stats.t.ppf(0.975, max(n * (1 - max(phi, 0.0)) / (1 + max(phi, 0.0)) - 3, 1.0)))
    return RunInFit(
        Estimate(float(mu_inf), float(mu_inf - z * se_inf), float(mu_inf + z * se_inf)),
        Estimate(float(start), float(start - z * se_start), float(start + z * se_start)),
        Estimate(tau, tau * math.exp(-z * se_log_tau), tau * math.exp(z * se_log_tau)),
        phi, math.sqrt(variance), n, identified)
