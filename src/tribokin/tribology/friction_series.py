"""Friction as a time series: a joint's friction drawn for (tests, cycles), advancing once per ISO cycle.

The steady state is a stationary series whose marginal is the joint's law and whose lag-one autocorrelation is
``ar1`` (that of the values themselves, what a log shows): a Gaussian-copula AR(1). A latent Gaussian AR(1) z of
lag-one correlation r goes through the law's quantile function, value = F⁻¹(Φ(z)), so every cycle's value has the
law's marginal exactly; r is solved so that corr(F⁻¹(Φ(z₁)), F⁻¹(Φ(z₂))) = ``ar1`` (:func:`latent_correlation`).
For a Gaussian law with mean >= 6σ the map is linear to 1e-9 (its truncation at 0 holds 1e-9 of the mass), so the
series is a Gaussian AR(1) and r = ``ar1``. For an empirical law the quantile function is a step function (each
measured value drawn with probability 1/n exactly): the values keep their frequencies, and the correlation, solved
exactly for steps (as many Hermite terms as the latent correlation needs), is reached by a path that dwells on a
value while z stays within its step; few distinct values mean a lag-one correlation nearer 1 needs a latent one
nearer still (two values: ``ar1`` = (2/π)·arcsin r).

On the steady state: ``steady_mean_std``, a per-test Gaussian offset of its mean (the test-to-test spread of a
tribometer campaign's steady means); ``run_in``, the mean approached from ``start``,
μ∞ + (start − μ∞)·exp(−cycle/τ), cycle counted from ``age_cycles`` at a test's first cycle; ``thermal``, a factor of
the joint's temperature (:mod:`~tribokin.tribology.thermal`). Values are never below 0. SciPy is imported where a
function needs it: a study without time keys imports none of it (``tests/test_package.py``).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, replace

import numpy as np

from tribokin.errors import LawError
from tribokin.tribology.laws import Empirical, FrictionLaw, Gaussian, Lognormal, Scaled, Uniform
from tribokin.tribology.thermal import Thermal

#: The keys of a joint's friction that make it a time series (a study file's and a law file's).
TIME_KEYS = ("ar1", "run_in", "age_cycles", "steady_mean_std", "thermal")
#: A Gaussian law's mean at least this many standard deviations: its truncation at 0 is negligible (1e-9 of the
#: mass) and its series is a Gaussian AR(1) with the latent correlation equal to ``ar1``.
GAUSSIAN_UNTRUNCATED_SIGMAS = 6.0
#: Gauss-Hermite nodes and Hermite terms of a continuous law's copula correlation (its coefficients fall fast).
_NODES, _CONTINUOUS_TERMS = 240, 160
#: Hermite terms of an empirical law's copula correlation (its coefficients fall as k^(-3/4); the rest is summed as
#: the tail the series must have, see :func:`_step_correlation`): at first, and at most (a latent correlation r
#: needs about 25/(1 − r) terms for r^terms < 1e-9).
_STEP_TERMS, _MAX_STEP_TERMS = 4000, 100_000


@dataclass(frozen=True)
class RunIn:
    """The steady mean approached from ``start`` (in the law's quantity: mu, or N·m, N) over ``tau_cycles``."""

    start: float
    tau_cycles: float

    def __post_init__(self):
        if not (math.isfinite(self.start) and self.start >= 0):
            raise LawError(f"must be a finite number >= 0 (got {self.start}): friction is never negative",
                           "run_in.start")
        if not (math.isfinite(self.tau_cycles) and self.tau_cycles > 0):
            raise LawError(f"must be > 0 cycles (got {self.tau_cycles}); remove run_in for none",
                           "run_in.tau_cycles")


@dataclass(frozen=True)
class FrictionSeries:
    """How a joint's friction moves from cycle to cycle (all optional; the defaults: independent draws).

    Attributes:
        ar1: lag-one autocorrelation of the values in the steady state, in (−1, 1).
        run_in: the running-in from its start to the steady mean, or ``None``.
        age_cycles: cycles the joint has run before a test's first cycle [-], >= 0.
        steady_mean_std: standard deviation of a test's steady mean about the law's [the law's unit], >= 0.
        thermal: the joint's warm-up and mu's dependence on it, or ``None``.
    """

    ar1: float = 0.0
    run_in: RunIn | None = None
    age_cycles: float = 0.0
    steady_mean_std: float = 0.0
    thermal: Thermal | None = None

    def __post_init__(self):
        if not (math.isfinite(self.ar1) and -1 < self.ar1 < 1):
            raise LawError(f"must lie strictly between -1 and 1 (got {self.ar1}): a lag-one autocorrelation of ±1 "
                           "never changes (or only flips)", "ar1")
        for key in ("age_cycles", "steady_mean_std"):
            value = getattr(self, key)
            if not (math.isfinite(value) and value >= 0):
                raise LawError(f"must be a finite number >= 0 (got {value})", key)
        if self.age_cycles and self.run_in is None:
            raise LawError("places a test on its running-in, and there is none: give run_in, or remove age_cycles",
                           "age_cycles")

    @property
    def independent(self) -> bool:
        """Every cycle an independent draw of the law: no key changes anything."""
        return self.ar1 == 0 and self.run_in is None and self.steady_mean_std == 0 and self.thermal is None


@dataclass(frozen=True)
class FrictionState:
    """Where a test's friction series start: each running-in joint's age and each warming joint's temperature.

    Attributes:
        age_cycles: cycles every running-in joint has run before the test [-], >= 0 (``None``: each joint's own
            ``age_cycles``); a joint without ``run_in`` has no age.
        after_s: how long the joints have run their cycle from cold [s], >= 0: 0 cold (ambient), ``math.inf`` warm
            (settled, :meth:`~tribokin.tribology.thermal.Thermal.settled_C`), else the warm-up's temperature then
            (:meth:`~tribokin.tribology.thermal.Thermal.after_C`), driven by the law's mean (the steady state's: a
            running-in during the warm-up is not counted).
    """

    age_cycles: float | None = None
    after_s: float = 0.0

    def __post_init__(self):
        if self.age_cycles is not None and not (math.isfinite(self.age_cycles) and self.age_cycles >= 0):
            raise LawError(f"must be a finite number >= 0 (got {self.age_cycles})", "age_cycles")
        if not (self.after_s >= 0):  # math.inf: warm
            raise LawError(f"must be a number >= 0 s (got {self.after_s})", "after_s")

    def start(self, law: FrictionLaw, series: FrictionSeries, power_per_value_W: float | None,
              cycle_time_s: float | None) -> tuple[FrictionSeries, float | None]:
        """A joint's ``series`` at this state's age, and its temperature [°C] at the test's first cycle (``None``:
        ambient), its friction ``law``'s mean dissipating ``power_per_value_W`` [W] per unit every ``cycle_time_s``
        [s] (:func:`draw_series`' arguments)."""
        if self.age_cycles is not None and series.run_in is not None:
            series = replace(series, age_cycles=self.age_cycles)
        if series.thermal is None or self.after_s == 0:
            return series, None
        return series, series.thermal.after_C(power_per_value_W, law.mean(), self.after_s, cycle_time_s)

    def describe(self) -> dict:
        """The state as a study gives it: ``{"age_cycles": ..., "after_s": ...}``, ``after_s`` "warm" when settled."""
        after = "warm" if math.isinf(self.after_s) else self.after_s
        return {"after_s": after} if self.age_cycles is None else {"age_cycles": self.age_cycles, "after_s": after}


#: A test from each joint's own age at ambient temperature, and from the temperature its mean friction settles it at.
COLD, WARM = FrictionState(), FrictionState(after_s=math.inf)


@dataclass(frozen=True, eq=False)
class Drawn:
    """Values drawn for (tests, cycles): ``values`` in the law's quantity, and each cycle's starting joint
    temperature ``temperature_C`` [°C] (``None`` without ``thermal``)."""

    values: np.ndarray
    temperature_C: np.ndarray | None = None


def normal_quantile(law: FrictionLaw, z: np.ndarray) -> np.ndarray:
    """F⁻¹(Φ(z)): the law's value whose probability below is that of the standard normal below ``z``.

    Closed forms, stable in both tails, for the registered laws; the law's scipy ``ppf`` for any other. An
    empirical law's values each take 1/n of the probability (the step function of its sorted values)."""
    from scipy import special

    z = np.asarray(z, dtype=float)
    if isinstance(law, Scaled):
        return law.scale * normal_quantile(law.inner, z)
    if law.std() == 0:
        return np.full(z.shape, law.mean())
    if isinstance(law, Uniform):
        return law.params["low"] + (law.params["high"] - law.params["low"]) * special.ndtr(z)
    if isinstance(law, Gaussian):  # truncated below at 0: 1 − F = Φ(mean/σ)·Φ(−z), exact in the upper tail
        mean, std = law.params["mean"], law.params["std"]
        return mean - std * special.ndtri(special.ndtr(mean / std) * special.ndtr(-z))
    if isinstance(law, Lognormal):
        return np.exp(math.log(law._median) + law._sigma_log * z)
    if isinstance(law, Empirical):
        ordered = np.sort(law.values)
        return ordered[np.minimum((ordered.size * special.ndtr(z)).astype(np.int64), ordered.size - 1)]
    return law._dist.ppf(special.ndtr(z))


def _base(law: FrictionLaw) -> FrictionLaw:
    return law.inner if isinstance(law, Scaled) else law


def _hermite_rows(x: np.ndarray, terms: int):
    """The normalised probabilists' Hermite polynomials h_k(x) = He_k(x)/√k!, k = 0 .. terms − 1, one row at a
    time (the stable three-term recurrence)."""
    previous, current = np.zeros_like(x), np.ones_like(x)
    for k in range(terms):
        yield current
        previous, current = current, (x * current - math.sqrt(k) * previous) / math.sqrt(k + 1)


@functools.cache
def _gauss_hermite() -> tuple[np.ndarray, np.ndarray]:
    """``_NODES`` Gauss-Hermite nodes and weights of the standard normal density (the weights sum to 1)."""
    nodes, weights = np.polynomial.hermite_e.hermegauss(_NODES)
    return nodes, weights / math.sqrt(2 * math.pi)


def _continuous_coefficients(law: FrictionLaw) -> np.ndarray:
    """c_k = E[g(Z)·h_k(Z)], k >= 1, g = F⁻¹∘Φ, by Gauss-Hermite quadrature: cov(g(Z₁), g(Z₂)) = Σ r^k c_k²
    (Mehler's expansion of the bivariate normal density)."""
    nodes, weights = _gauss_hermite()
    weighted = weights * normal_quantile(law, nodes)
    return np.array([weighted @ h for h in _hermite_rows(nodes, _CONTINUOUS_TERMS)])[1:]


def _step_coefficients(law: Empirical, terms: int) -> np.ndarray:
    """c_k, k >= 1, of an empirical law's step function g = Σ d_j·1{z > t_j} (+ its least value): jumps d_j between
    consecutive sorted values at t_j = Φ⁻¹(j/n); E[1{Z > t}·h_k(Z)] = φ(t)·h_{k−1}(t)/√k, exactly."""
    from scipy import special

    ordered = np.sort(law.values)
    jumps = np.diff(ordered)
    at = np.flatnonzero(jumps > 0)
    t = special.ndtri((at + 1) / ordered.size)
    weighted = jumps[at] * np.exp(-0.5 * t * t) / math.sqrt(2 * math.pi)
    rows = np.array([weighted @ h for h in _hermite_rows(t, terms - 1)])
    return rows / np.sqrt(np.arange(1, terms))


def copula_correlation(law: FrictionLaw, terms: int = _STEP_TERMS):
    """μ's lag-one correlation as a function of the latent one, corr(g(Z₁), g(Z₂)) for (Z₁, Z₂) standard normals
    of correlation r, g = F⁻¹∘Φ; r in [−1, 1], vectorised. ``None`` for a law of zero width.

    Continuous laws: Σₖ rᵏ c_k² / Σₖ c_k² (Mehler), coefficients by Gauss-Hermite quadrature. Empirical laws: the
    step function's exact coefficients up to ``terms``, the rest of the variance (known exactly) spread over
    the higher terms as their k^(−3/2) decay, their sum weighted by rᵏ; at r = −1, the exact correlation of the
    sorted values with their reverse; ``terms`` of them."""
    law = _base(law)
    if law.std() == 0:
        return None
    if isinstance(law, Empirical):
        return _step_correlation(law, terms)
    squares = _continuous_coefficients(law) ** 2
    variance, powers = squares.sum(), np.arange(1, squares.size + 1)

    def correlation(r):
        r = np.asarray(r, dtype=float)
        return (np.power.outer(r, powers) @ squares) / variance
    return correlation


def _step_correlation(law: Empirical, terms: int):
    from scipy import special

    squares = _step_coefficients(law, terms) ** 2
    variance = float(law.values.var())
    rest = max(variance - squares.sum(), 0.0)
    powers = np.arange(1, squares.size + 1)
    ordered = np.sort(law.values)
    lowest = float(np.mean((ordered - ordered.mean()) * (ordered[::-1] - ordered.mean())) / variance)
    tail_total = float(special.zeta(1.5, terms))

    def tail(r: float) -> float:
        if abs(r) < 1e-300:
            return 0.0
        count = int(min(max(60.0 / max(1.0 - abs(r), 1e-12), 10.0), 2e6))
        k = terms + np.arange(count, dtype=float)
        return float(np.sum(np.sign(r) ** k * np.exp(k * math.log(abs(r)) - 1.5 * np.log(k)))) / tail_total

    def correlation(r):
        r = np.asarray(r, dtype=float)
        out = np.empty(r.shape)
        for i, value in np.ndenumerate(r):
            if value <= -1:
                out[i] = lowest
            elif value >= 1:
                out[i] = 1.0
            else:
                out[i] = (np.power(value, powers) @ squares + rest * tail(value)) / variance
        return out
    return correlation


def latent_correlation(law: FrictionLaw, ar1: float) -> float:
    """The latent Gaussian AR(1)'s lag-one correlation r whose copula gives the law's values a lag-one correlation
    ``ar1`` (brentq on :func:`copula_correlation`); ``ar1`` itself for a Gaussian law with mean >= 6σ; a
    :class:`LawError` naming ``ar1`` when the law cannot reach it (below its correlation at r = −1, e.g. a
    lognormal's −exp(−σ_log²)) or has no spread."""
    base = _base(law)
    if ar1 == 0:
        return 0.0
    if base.std() == 0:
        raise LawError(f"a law of zero width ({base!r}) has no spread to correlate: remove ar1", "ar1")
    if isinstance(base, Gaussian) and base.params["mean"] >= GAUSSIAN_UNTRUNCATED_SIGMAS * base.params["std"]:
        return float(ar1)
    terms = _STEP_TERMS
    while True:
        r = _solved(copula_correlation(base, terms), ar1, base.law)
        if not isinstance(base, Empirical) or abs(r) ** terms < 1e-9 or terms >= _MAX_STEP_TERMS:
            return r
        terms = min(math.ceil(25 / (1 - abs(r))), _MAX_STEP_TERMS)  # a step law's terms until r^terms is negligible


def _solved(correlation, ar1: float, law: str) -> float:
    """The r in [−1, 1] where ``correlation(r)`` = ``ar1``, or a :class:`LawError` when ``ar1`` lies below its
    value at −1."""
    from scipy.optimize import brentq

    lowest = float(correlation(-1.0))
    if ar1 <= lowest:
        raise LawError(f"{ar1:g} is below {lowest:.4g}, the most negative lag-one correlation a {law} law of these "
                       "parameters can have (its values reversed through the copula): use a larger ar1", "ar1")
    return float(brentq(lambda r: float(correlation(r)) - ar1, -1.0, 1.0, xtol=1e-13, rtol=1e-13))


def latent_series(tests: int, cycles: int, r: float, rng: np.random.Generator) -> np.ndarray:
    """A stationary Gaussian AR(1) of unit variance and lag-one correlation ``r``, (tests, cycles): z₀ ~ N(0, 1),
    z_k = r·z_{k−1} + √(1 − r²)·ε_k (:func:`ar1_filter` of standard normal shocks)."""
    return ar1_filter(rng.standard_normal((tests, cycles)), r)


def ar1_filter(shocks: np.ndarray, r: float) -> np.ndarray:
    """The stationary Gaussian AR(1) of unit variance and lag-one correlation ``r`` made of standard normal
    ``shocks`` (..., cycles) (overwritten): z₀ = ε₀, z_k = r·z_{k−1} + √(1 − r²)·ε_k, so cov(z_i, z_j) = r^|i−j|
    exactly (scipy's lfilter along the last axis)."""
    from scipy.signal import lfilter

    scale = math.sqrt(1.0 - r * r)
    shocks[..., 0] /= scale  # the first value is z₀ itself
    return lfilter([scale], [1.0, -r], shocks, axis=-1)


def draw_series(law: FrictionLaw, series: FrictionSeries, tests: int, cycles: int, rng: np.random.Generator,
                power_per_value_W: float | None = None, cycle_time_s: float | None = None,
                start_C: float | None = None) -> Drawn:
    """The law's values for ``tests`` tests of ``cycles`` cycles each, as ``series`` makes them move.

    Args:
        law: the joint's friction law (of mu, or a :class:`~tribokin.tribology.laws.Scaled` torque or force).
        series: its time keys; independent ones draw ``law.rvs((tests, cycles))`` as they are.
        tests: independent tests (rows).
        cycles: cycles per test (columns), one ISO cycle each.
        rng: the random stream (offsets, then the latent series or the draws).
        power_per_value_W: friction power [W] per unit of the law's value (:func:`~tribokin.tribology.thermal.
            power_per_value`); required with ``thermal``.
        cycle_time_s: one cycle's duration [s]; required with ``thermal``.
        start_C: every test's joint temperature at its first cycle [°C] (``None``: ambient, a cold start).

    Returns:
        the values and, with ``thermal``, each cycle's temperature at its start.
    """
    thermal = series.thermal
    if thermal is not None and (power_per_value_W is None or cycle_time_s is None):
        raise LawError("needs the joint's motion: its travel per cycle and the cycle time", "thermal")
    if series.independent:
        return Drawn(law.rvs((tests, cycles), rng))
    offset = rng.normal(0.0, series.steady_mean_std, (tests, 1)) if series.steady_mean_std > 0 else 0.0
    if series.ar1 == 0:
        values = law.rvs((tests, cycles), rng)
    else:
        values = normal_quantile(law, latent_series(tests, cycles, latent_correlation(law, series.ar1), rng))
    values = values + offset
    if series.run_in is not None:
        decay = np.exp(-(series.age_cycles + np.arange(cycles)) / series.run_in.tau_cycles)
        values = values + (series.run_in.start - (law.mean() + offset)) * decay
    values = np.maximum(values, 0.0)
    if thermal is None:
        return Drawn(values)
    temperature = np.empty((tests, cycles))
    now = np.full(tests, thermal.ambient_C if start_C is None else float(start_C))
    for cycle in range(cycles):  # each cycle heats the next: vectorised over the tests
        temperature[:, cycle] = now
        values[:, cycle] *= thermal.factor(now)
        now = thermal.step(now, values[:, cycle] * power_per_value_W, cycle_time_s)
    return Drawn(values, temperature)


def expected_sample_variance(std: float, ar1: float, cycles: int) -> float:
    """E[S²] of ``cycles`` consecutive values of a stationary AR(1) of standard deviation ``std`` and lag-one
    correlation ``ar1``: σ²·(1 − 2/(n(n − 1))·Σₖ₌₁ⁿ⁻¹ (n − k)·ρᵏ)."""
    n = cycles
    k = np.arange(1, n)
    return std * std * (1.0 - 2.0 / (n * (n - 1)) * float(np.sum((n - k) * ar1 ** k)))


def lag_correlations(ar1: float, cycles: int) -> np.ndarray:
    """(cycles, cycles) the correlations ar1^|i − j| of a stationary AR(1)'s values at cycles i and j."""
    lags = np.abs(np.subtract.outer(np.arange(cycles), np.arange(cycles)))
    return np.power(float(ar1), lags)
