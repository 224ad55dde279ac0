"""Expected ISO 9283 figures of a test of n cycles whose tool deviations are Gaussian, without sampling each test.

A test reaches y_j = b + w_j (j = 1..n), w_j ~ N(0, Σ) independent, b the bias of the mean deviation [m]. Its
figures (:mod:`tribokin.iso9283.metrics`) are RP_l = l̄ + 3 S_l with l_j = |y_j - ȳ|, AP_p = |ȳ - commanded|
and RP_a = 3 S_a per angle. Over tests:

- E[RP_l] (:func:`expected_rp_l`): y_j - ȳ ~ N(0, (n - 1)/n Σ), so E[l] = 2 √(2/π) R_G((n - 1)/n λ) (Carlson's
  symmetric integral of the eigenvalues λ of Σ); E[l³] from its derivatives, E[l²] and E[l⁴] from Gaussian
  moments; E[S_l] by the delta method to second order (the l_j treated as independent: their correlation through
  ȳ is O(1/n²)). Within 0.05 % of a 200 000-test Monte Carlo for n >= 30, 0.45 % at n = 10, 2 % at n = 5;
  used from :data:`ANALYTIC_MIN_CYCLES` cycles on, below that the table's mean.
- The 2.5 / 97.5 % band of one test's RP_l and the expected largest semi-axis of its covariance ellipsoid
  (:class:`ShapeTable`): RP_l / √λ₁ depends on n and the shape (λ₂/λ₁, λ₃/λ₁) only, so both are simulated once per
  run on a grid of shapes, every node from the same standard normal draws (so the table is smooth), and
  interpolated; each node's own Monte Carlo error is kept (relative standard errors, interpolated as the values).
  From :data:`ASYMPTOTIC_CYCLES` cycles on, the band is normal about E[RP_l] with the delta method's standard
  deviation (:func:`normal_band`) and the semi-axis √λ₁.
- E[AP_p] = E|b + ȳ|, ȳ ~ N(0, Σ/n) (:func:`expected_norm`).
- E[RP_a] = 3 c₄(n) σ_a exactly (:func:`c4`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from statistics import NormalDist

import numpy as np

from tribokin.compiled import use_compiled

#: Fewest cycles for which E[RP_l] is the delta method's (error under 0.5 %); fewer: the table's mean.
ANALYTIC_MIN_CYCLES = 10
#: From this many cycles on, one test's RP_l is taken as normal (:func:`normal_band`) and the largest semi-axis as the
#: population's (bias O(1/n)): no shape table, no sampled tests.
ASYMPTOTIC_CYCLES = 500
#: Percentiles [%] of one test's RP_l that bound the band.
BAND_PERCENTILES = (2.5, 97.5)
#: Shape-table nodes along each of its axes √(λ₂/λ₁) and √(λ₃/λ₂).
TABLE_NODES = 9
#: Tests of the shape table: about this many cycles in all at each node, at least ``TABLE_MIN_TESTS`` and at most
#: ``TABLE_MAX_TESTS`` tests.
TABLE_CYCLES, TABLE_MIN_TESTS, TABLE_MAX_TESTS = 120_000, 400, 16_000
#: Below this ratio of the noise's variance to |b|², E|b + w| is taken from its expansion to second order
#: (relative error about the ratio squared); above it, by quadrature.
EXPANSION_RATIO = 1e-3
#: Eigenvalues below this fraction of the largest are raised to it before the moments are taken.
EIGENVALUE_FLOOR = 1e-12
_MEAN_NORM = 2 * math.sqrt(2 / math.pi)  # E|z| of a standard normal 3-vector


def _carlson_derivative(lam: np.ndarray, i: int) -> np.ndarray:
    """∂R_G/∂λ_i of (..., 3) arguments: R_F/4 - λ_i R_D/12, the other two arguments first."""
    from scipy.special import elliprd, elliprf  # here: the compiled path needs none of scipy.special

    others = [lam[..., j] for j in range(3) if j != i]
    return elliprf(*others, lam[..., i]) / 4 - lam[..., i] * elliprd(*others, lam[..., i]) / 12


def _scaled(lam) -> tuple[np.ndarray, np.ndarray]:
    """(√λ_max, λ / λ_max with eigenvalues below ``EIGENVALUE_FLOOR`` raised to it) of (..., 3) eigenvalues: each
    moment scales as λ_max^(k/2), and R_F, R_D diverge where two eigenvalues vanish (a change of that order)."""
    lam = np.maximum(np.asarray(lam, dtype=float), 0.0)
    largest = lam.max(axis=-1)
    unit = np.maximum(lam / np.where(largest > 0, largest, 1.0)[..., None], EIGENVALUE_FLOOR)
    return np.sqrt(largest), unit


def _unit_moments(unit: np.ndarray) -> tuple[np.ndarray, ...]:
    from scipy.special import elliprg  # here: the compiled path needs none of scipy.special

    m1 = _MEAN_NORM * elliprg(unit[..., 0], unit[..., 1], unit[..., 2])
    m2 = unit.sum(axis=-1)
    slopes = np.stack([_carlson_derivative(unit, i) for i in range(3)], axis=-1)
    m3 = m2 * m1 + 2 * _MEAN_NORM * (unit ** 2 * slopes).sum(axis=-1)
    m4 = m2 ** 2 + 2 * (unit ** 2).sum(axis=-1)
    return m1, m2, m3, m4


def norm_moments(lam: np.ndarray) -> tuple[np.ndarray, ...]:
    """E|w|^k, k = 1..4, of w ~ N(0, Σ) in 3-D, from the (..., 3) eigenvalues ``lam`` of Σ [m²]: [m^k].

    E|w| = 2 √(2/π) R_G(λ); E[|w| w_i²] = λ_i E|w| + 2 λ_i² ∂E|w|/∂λ_i (Gaussian integration by parts) gives E|w|³.
    """
    scale, unit = _scaled(lam)
    return tuple(m * scale ** k for k, m in enumerate(_unit_moments(unit), start=1))


def rp_l_from_moments(moments: tuple[np.ndarray, ...], cycles: int) -> tuple[np.ndarray, np.ndarray]:
    """E[RP_l] and the standard deviation of one test's RP_l [m] over tests of ``cycles`` cycles, from the first four
    moments E[l^k] [m^k] of one cycle's distance l to the barycentre, the cycles independent: to second order in the
    delta method, E[S_l] = σ (1 - Var(S_l²) / (8 σ⁴)), Var(RP_l) = (σ² + 9 (μ₄ - σ⁴) / (4 σ²) + 3 μ₃ / σ) / n."""
    n = cycles
    m1, m2, m3, m4 = moments
    variance = np.maximum(m2 - m1 ** 2, 0.0)
    central3 = m3 - 3 * m2 * m1 + 2 * m1 ** 3
    central4 = m4 - 4 * m3 * m1 + 6 * m2 * m1 ** 2 - 3 * m1 ** 4
    variance_of_s2 = central4 / n - variance ** 2 * (n - 3) / (n * (n - 1))
    sigma = np.sqrt(variance)
    with np.errstate(divide="ignore", invalid="ignore"):
        mean = m1 + 3 * sigma * (1 - np.where(variance > 0, variance_of_s2 / (8 * variance ** 2), 0.0))
        spread = np.where(variance > 0, variance + 9 * (central4 - variance ** 2) / (4 * variance)
                          + 3 * central3 / sigma, 0.0) / n
    return mean, np.sqrt(np.maximum(spread, 0.0))


def expected_rp_l(lam: np.ndarray, cycles: int) -> tuple[np.ndarray, np.ndarray]:
    """E[RP_l] [m] of tests of ``cycles`` cycles with Gaussian deviations of covariance eigenvalues ``lam`` (..., 3)
    [m²] (:func:`rp_l_from_moments`: use from ``ANALYTIC_MIN_CYCLES`` cycles), and one test's standard deviation;
    compiled where :func:`~tribokin.compiled.use_compiled`."""
    n = cycles
    if use_compiled():
        from tribokin.iso9283 import gaussian_tests_kernels

        lam = np.asarray(lam, dtype=float)
        flat = np.ascontiguousarray(lam.reshape(-1, 3))
        mean, spread = gaussian_tests_kernels.expected_rp_l(flat, n, EIGENVALUE_FLOOR, _MEAN_NORM)
        return mean.reshape(lam.shape[:-1]), spread.reshape(lam.shape[:-1])
    scale, unit = _scaled(lam)
    mean, spread = rp_l_from_moments(_unit_moments((n - 1) / n * unit), n)
    return mean * scale, spread * scale


def normal_band(mean: np.ndarray, spread: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The ``BAND_PERCENTILES`` of a normal law of ``mean`` and standard deviation ``spread``: one test's RP_l band
    from ``ASYMPTOTIC_CYCLES`` cycles on (its skewness then moves them by under 0.5 %)."""
    z = NormalDist().inv_cdf(BAND_PERCENTILES[1] / 100)
    return mean - z * spread, mean + z * spread


def c4(cycles: int) -> float:
    """E[S] / σ of the sample standard deviation (n - 1) of ``cycles`` Gaussian values."""
    n = cycles
    return math.sqrt(2 / (n - 1)) * math.exp(math.lgamma(n / 2) - math.lgamma((n - 1) / 2))


def expected_norm(centre: np.ndarray, covariance: np.ndarray) -> np.ndarray:
    """E|c + w| [m] for w ~ N(0, S): ``centre`` c (..., 3) [m], ``covariance`` S (..., 3, 3) [m²].

    Where tr S < ``EXPANSION_RATIO`` |c|²: |c| + (tr S - ĉᵀ S ĉ) / (2 |c|). Elsewhere exactly, by the trapezoid rule
    on a log scale of E|x| = (2√π)⁻¹ ∫₀^∞ (1 - E e^{-t|x|²}) t^{-3/2} dt, whose Laplace transform is closed-form.
    Computed on c and S scaled by a power of two to order one (exactly), so that sizes from 1e-300 to 1e300 m
    neither underflow nor overflow; 0 where c and S are. Compiled where :func:`~tribokin.compiled.use_compiled`.
    """
    centre, covariance = np.asarray(centre, dtype=float), np.asarray(covariance, dtype=float)
    if use_compiled():
        from tribokin.iso9283 import gaussian_tests_kernels

        shape = np.broadcast_shapes(centre.shape[:-1], covariance.shape[:-2])
        return gaussian_tests_kernels.expected_norm(
            np.ascontiguousarray(np.broadcast_to(centre, shape + (3,)).reshape(-1, 3)),
            np.ascontiguousarray(np.broadcast_to(covariance, shape + (3, 3)).reshape(-1, 3, 3)), EXPANSION_RATIO,
            _NODE_TIMES, _NODE_WEIGHTS, _LOG_STEP).reshape(shape)
    magnitude = np.maximum(np.abs(centre).max(axis=-1),
                           np.sqrt(np.abs(np.diagonal(covariance, axis1=-2, axis2=-1)).max(axis=-1)))
    zero = ~(magnitude > 0)
    scale = np.exp2(np.round(np.log2(np.where(zero, 1.0, magnitude))))
    centre = centre / scale[..., None]
    covariance = covariance / scale[..., None, None] / scale[..., None, None]
    size2 = np.einsum("...i,...i->...", centre, centre)
    trace = np.trace(covariance, axis1=-2, axis2=-1)
    result = np.zeros(size2.shape)
    near = ~zero & (trace < EXPANSION_RATIO * size2)
    if near.any():
        c, s = centre[near], covariance[near]
        size = np.sqrt(size2[near])
        along = np.einsum("ki,kij,kj->k", c, s, c) / size2[near]
        result[near] = size + (trace[near] - along) / (2 * size)
    far = ~zero & ~near
    if far.any():
        result[far] = _norm_by_quadrature(centre[far], covariance[far])
    return result * scale


_LOG_NODES = np.arange(-36.0, 36.0 + 1e-9, 0.25)  # u = ln t + ln scale²: the integrand decays as e^{-|u|/2}
_LOG_STEP = float(_LOG_NODES[1] - _LOG_NODES[0])
_NODE_TIMES, _NODE_WEIGHTS = np.exp(_LOG_NODES), np.exp(-_LOG_NODES / 2)  # e^u, e^{-u/2}


def _norm_by_quadrature(centre: np.ndarray, covariance: np.ndarray) -> np.ndarray:
    lam, vectors = np.linalg.eigh(covariance)
    lam = np.maximum(lam, 0.0)
    beta2 = np.einsum("kij,ki->kj", vectors, centre) ** 2
    scale2 = np.maximum(beta2.sum(axis=-1) + lam.sum(axis=-1), np.finfo(float).tiny)
    t = _NODE_TIMES[None, :, None] / scale2[:, None, None]
    log_transform = (-0.5 * np.log1p(2 * t * lam[:, None]) - t * beta2[:, None] / (1 + 2 * t * lam[:, None])).sum(-1)
    integrand = -np.expm1(log_transform) * _NODE_WEIGHTS
    return integrand.sum(axis=-1) * _LOG_STEP * np.sqrt(scale2) / (2 * math.sqrt(math.pi))


def eigenvalues(matrices: np.ndarray) -> np.ndarray:
    """(..., 3) ascending eigenvalues of symmetric (..., 3, 3) ``matrices`` (their unit): LAPACK's
    (``np.linalg.eigvalsh``), or by Jacobi rotations where :func:`~tribokin.compiled.use_compiled` (the same to
    rounding of the largest)."""
    matrices = np.asarray(matrices, dtype=float)
    if not use_compiled():
        return np.linalg.eigvalsh(matrices)
    from tribokin.iso9283 import gaussian_tests_kernels

    flat = np.ascontiguousarray(matrices.reshape(-1, 3, 3))
    return gaussian_tests_kernels.eigenvalues(flat).reshape(matrices.shape[:-1])


def standardised_shape(lam: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(scale √λ₁ [m], shape (√(λ₂/λ₁), √(λ₃/λ₂)) in [0, 1]²) of eigenvalues ``lam`` (..., 3) [m²] (any order)."""
    ordered = np.sqrt(np.maximum(np.sort(np.asarray(lam, dtype=float), axis=-1)[..., ::-1], 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        shape = np.stack([np.where(ordered[..., 0] > 0, ordered[..., 1] / ordered[..., 0], 0.0),
                          np.where(ordered[..., 1] > 0, ordered[..., 2] / ordered[..., 1], 0.0)], axis=-1)
    return ordered[..., 0], np.clip(shape, 0.0, 1.0)


@dataclass(frozen=True)
class ShapeTable:
    """One test's RP_l over √λ₁ (its mean, its ``BAND_PERCENTILES``) and its covariance ellipsoid's expected
    largest semi-axis over √λ₁, at ``TABLE_NODES``² shapes, for tests of ``cycles`` Gaussian cycles.

    Attributes:
        cycles: cycles per test. tests: tests simulated at each node.
        mean, low, high, semi_axis: (nodes, nodes) values at the shapes (√(λ₂/λ₁), √(λ₃/λ₂)).
        errors: (4, nodes, nodes) the Monte Carlo standard errors of ``mean``, ``low``, ``high`` and ``semi_axis``
            relative to their values (:func:`mean_error`, :func:`percentile_error`).
    """

    cycles: int
    tests: int
    mean: np.ndarray
    low: np.ndarray
    high: np.ndarray
    semi_axis: np.ndarray
    errors: np.ndarray

    @classmethod
    def simulate(cls, cycles: int, rng: np.random.Generator) -> ShapeTable:
        """The table of tests of ``cycles`` cycles, every node from the same standard normal draws of ``rng``."""
        tests = min(max(TABLE_MIN_TESTS, math.ceil(TABLE_CYCLES / cycles)), TABLE_MAX_TESTS)
        draws = rng.standard_normal((tests, cycles, 3))
        offsets = draws - draws.mean(axis=1, keepdims=True)
        squares = (offsets ** 2).reshape(-1, 3)  # a node scales the axes: its distances² are these, weighted
        covariances = np.einsum("tni,tnj->tij", offsets, offsets) / max(cycles - 1, 1)
        axis = np.linspace(0.0, 1.0, TABLE_NODES)
        values = np.empty((4, TABLE_NODES, TABLE_NODES))
        errors = np.empty((4, TABLE_NODES, TABLE_NODES))
        for i, a in enumerate(axis):
            for j, b in enumerate(axis):
                scale = np.array([1.0, a, a * b])
                distances = np.sqrt(squares @ scale ** 2).reshape(tests, cycles)
                rp = distances.mean(axis=1) + 3 * distances.std(axis=1, ddof=1)
                semi_axis = np.sqrt(np.maximum(np.linalg.eigvalsh(covariances * np.outer(scale, scale))[:, -1], 0.0))
                values[:, i, j] = rp.mean(), *np.percentile(rp, BAND_PERCENTILES), semi_axis.mean()
                errors[:, i, j] = (mean_error(rp), *(percentile_error(rp, p) for p in BAND_PERCENTILES),
                                   mean_error(semi_axis))
        return cls(cycles, tests, *values, errors)

    def at(self, shape: np.ndarray) -> tuple[np.ndarray, ...]:
        """(mean, low, high, semi_axis) over √λ₁ at shapes (..., 2) (:func:`standardised_shape`), interpolated.

        ``scipy.interpolate`` is imported here, by the runs of fewer than :data:`ASYMPTOTIC_CYCLES` cycles that use a
        table, before a map's workers start (``benchmarks/startup.py`` times the import)."""
        return self._interpolated((self.mean, self.low, self.high, self.semi_axis), shape)

    def errors_at(self, shape: np.ndarray) -> tuple[np.ndarray, ...]:
        """The relative Monte Carlo standard errors of :meth:`at`'s four values at shapes (..., 2), interpolated."""
        return self._interpolated(tuple(self.errors), shape)

    @staticmethod
    def _interpolated(tables: tuple[np.ndarray, ...], shape: np.ndarray) -> tuple[np.ndarray, ...]:
        from scipy.interpolate import RegularGridInterpolator

        axis = np.linspace(0.0, 1.0, TABLE_NODES)
        return tuple(RegularGridInterpolator((axis, axis), values)(shape) for values in tables)


def mean_error(values: np.ndarray) -> np.ndarray:
    """Standard error of the mean of ``values`` (..., N) relative to it (0 where the mean is)."""
    mean = values.mean(axis=-1)
    error = values.std(axis=-1, ddof=1) / math.sqrt(values.shape[-1])
    return np.divide(error, np.abs(mean), out=np.zeros_like(error), where=mean != 0)


def percentile_error(values: np.ndarray, percentile: float) -> np.ndarray:
    """Standard error of the ``percentile`` of ``values`` (..., N) (any order) relative to it (0 where the percentile
    is). √(p (1 - p) / N) / f(q), the density f at the percentile q from the Cornish-Fisher expansion of the values'
    standard deviation s, skewness γ and excess kurtosis κ, q = m + s w(z), w(z) = z + (z² - 1) γ / 6 +
    (z³ - 3 z) κ / 24 - (2 z³ - 5 z) γ² / 36 (so f(q) = φ(z) / (s w'(z))): smooth in the values, where the spacing of
    the order statistics about the percentile is as noisy as the few of them."""
    n = values.shape[-1]
    p = percentile / 100
    value = np.percentile(values, percentile, axis=-1)
    z = NormalDist().inv_cdf(p)
    centred = values - values.mean(axis=-1, keepdims=True)
    s = np.sqrt(np.mean(centred ** 2, axis=-1))
    unit = np.divide(centred, s[..., None], out=np.zeros_like(centred), where=s[..., None] > 0)
    skew, kurtosis = np.mean(unit ** 3, axis=-1), np.mean(unit ** 4, axis=-1) - 3
    slope = 1 + z * skew / 3 + (z ** 2 - 1) * kurtosis / 8 - (6 * z ** 2 - 5) * skew ** 2 / 36
    error = math.sqrt(p * (1 - p) / n) * s * np.maximum(slope, 0.1) / NormalDist().pdf(z)
    return np.divide(error, np.abs(value), out=np.zeros_like(error), where=value != 0)
