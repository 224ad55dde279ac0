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
  From :data:`ASYMPTOTIC_CYCLES` cycles on, the band is E[RP_l] with the delta method's standard deviation and
  skewness (:func:`gaussian_band_skewness`) by Cornish-Fisher (:func:`skewed_band`), and the semi-axis E√λ̂₁ to
  order 1/n (:func:`expected_semi_axis`).
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
#: From this many cycles on, one test's RP_l band is taken from its spread and skewness (:func:`skewed_band`) and the
#: largest semi-axis from the covariance and its fourth moments (:func:`expected_semi_axis`): no shape table, no
#: sampled tests.
ASYMPTOTIC_CYCLES = 500
#: Percentiles [%] of one test's RP_l that bound the band.
BAND_PERCENTILES = (2.5, 97.5)
#: Shape-table nodes along each of its axes √(λ₂/λ₁) and √(λ₃/λ₂).
TABLE_NODES = 9
#: How near -1 the cubic's r = cos(3θ) may come before :func:`largest_eigenvalue` leaves the closed form to LAPACK:
#: there the two largest eigenvalues meet, and a rounding ε of r moves the largest by about p ε / √(2 (1 + r)).
DOUBLE_LARGEST = 1e-4
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


def _unit_moments(unit: np.ndarray, order: int = 4) -> tuple[np.ndarray, ...]:
    """E|w|^k, k = 1..``order`` (4 or 6), of w ~ N(0, diag(``unit``)). Stein's lemma, E[w_i g(w)] = λ_i E[∂_i g]:
    E[w_i² |w|] = λ_i E|w| + 2 λ_i² ∂E|w|/∂λ_i, so E|w|³ = Σ λ_i E|w| + 2 Σ λ_i² ∂_i E|w| and E|w|⁵ = Σ λ_i E[w_i² |w|³]
    = E|w|² E|w|³ + 3 Σ λ_i E[w_i² |w|]; the even ones are polynomials of the λ."""
    from scipy.special import elliprg  # here: the compiled path needs none of scipy.special

    m1 = _MEAN_NORM * elliprg(unit[..., 0], unit[..., 1], unit[..., 2])
    m2 = unit.sum(axis=-1)
    slopes = np.stack([_carlson_derivative(unit, i) for i in range(3)], axis=-1)
    m3 = m2 * m1 + 2 * _MEAN_NORM * (unit ** 2 * slopes).sum(axis=-1)
    m4 = m2 ** 2 + 2 * (unit ** 2).sum(axis=-1)
    if order == 4:
        return m1, m2, m3, m4
    m5 = m2 * m3 + 3 * (unit * (unit * m1[..., None] + 2 * _MEAN_NORM * unit ** 2 * slopes)).sum(axis=-1)
    m6 = m2 ** 3 + 6 * m2 * (unit ** 2).sum(axis=-1) + 8 * (unit ** 3).sum(axis=-1)
    return m1, m2, m3, m4, m5, m6


def norm_moments(lam: np.ndarray) -> tuple[np.ndarray, ...]:
    """E|w|^k, k = 1..4, of w ~ N(0, Σ) in 3-D, from the (..., 3) eigenvalues ``lam`` of Σ [m²]: [m^k].

    E|w| = 2 √(2/π) R_G(λ); E[|w| w_i²] = λ_i E|w| + 2 λ_i² ∂E|w|/∂λ_i (Gaussian integration by parts) gives E|w|³.
    """
    scale, unit = _scaled(lam)
    return tuple(m * scale ** k for k, m in enumerate(_unit_moments(unit), start=1))


def rp_l_from_moments(moments: tuple[np.ndarray, ...], cycles: int, shared: np.ndarray | None = None
                      ) -> tuple[np.ndarray, np.ndarray]:
    """E[RP_l] and the standard deviation of one test's RP_l [m] over tests of ``cycles`` cycles, from the first four
    moments E[l^k] [m^k] of one cycle's distance l to the barycentre, the cycles independent: to second order in the
    delta method, E[S_l] = σ (1 - Var(S_l²) / (8 σ⁴)), Var(RP_l) = (σ² + 9 (μ₄ - σ⁴) / (4 σ²) + 3 μ₃ / σ) / n.

    With ``shared`` (k, 3) [m²], the eigenvalues of U Σ̄ / n (:func:`barycentre_shares`): a test's barycentre is one
    draw ε ~ N(0, Σ̄ / n) shared by its cycles, which adds εᵀ U ε to its S_l² (to second order in ε); then
    E[S_l] = E√(σ² - tr(U Σ̄) / n + εᵀ U ε) (:func:`expected_root`) times the same factor (the mean only)."""
    n = cycles
    m1, m2, m3, m4 = moments
    variance = np.maximum(m2 - m1 ** 2, 0.0)
    central3 = m3 - 3 * m2 * m1 + 2 * m1 ** 3
    central4 = m4 - 4 * m3 * m1 + 6 * m2 * m1 ** 2 - 3 * m1 ** 4
    variance_of_s2 = central4 / n - variance ** 2 * (n - 3) / (n * (n - 1))
    sigma = np.sqrt(variance)
    with np.errstate(divide="ignore", invalid="ignore"):
        factor = 1 - np.where(variance > 0, variance_of_s2 / (8 * variance ** 2), 0.0)
        deviation = sigma if shared is None else expected_root(np.maximum(variance - shared.sum(axis=-1), 0.0), shared)
        mean = m1 + 3 * deviation * factor
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


def influence_skewness(third: np.ndarray, variance: np.ndarray, shares: tuple[np.ndarray, np.ndarray],
                       means: tuple[np.ndarray, np.ndarray], cycles: int) -> np.ndarray:
    """The skewness of one test's RP_l = l̄ + 3 S_l over tests of ``cycles`` cycles to order 1/√n (the delta method
    over the two means of one cycle's (l, l²), ``means`` (E l, E l²) [m, m²]): (E h³ + 3 aᵀ H a) / (√n (E h²)^(3/2))
    from the influence h of one cycle (its ``third`` moment E h³ and ``variance`` E h²; [m³], [m²]), a = (E[h l],
    E[h l²]) centred (``shares``) and H the Hessian of l̄ + 3 √(n / (n - 1)) √(E l² - (E l)²) in the two means; 0
    where the variance is."""
    first, second = means
    factor = math.sqrt(cycles / (cycles - 1))
    sigma2 = second - first ** 2
    with np.errstate(divide="ignore", invalid="ignore"):
        inverse3 = np.where(sigma2 > 0, np.maximum(sigma2, 0.0) ** -1.5, 0.0)
        curvature = 3 * factor * inverse3 * (-second * shares[0] ** 2 + first * shares[0] * shares[1]
                                             - shares[1] ** 2 / 4)
        return np.where(variance > 0, (third + 3 * curvature) / math.sqrt(cycles) / variance ** 1.5, 0.0)


def gaussian_band_skewness(lam: np.ndarray, cycles: int) -> np.ndarray:
    """The skewness (..., ) of one test's RP_l over tests of ``cycles`` Gaussian cycles of covariance eigenvalues
    ``lam`` (..., 3) (:func:`influence_skewness`): a symmetric cloud's unit offsets average to 0, so one cycle's
    influence is h = g (l - E l) + g₂ (l² - E l²), g = 1 - 3 √(n / (n - 1)) E l / σ_l, g₂ = 3 √(n / (n - 1)) / (2 σ_l),
    its moments from E l^k, k = 1..6 (:func:`_unit_moments`; l the distance to the cycles' mean, the test's
    barycentre's own share being of order 1/n). About 0.03-0.08 at 500 cycles on UR5 clouds. Compiled where
    :func:`~tribokin.compiled.use_compiled`."""
    if use_compiled():
        from tribokin.iso9283 import gaussian_tests_kernels

        lam = np.asarray(lam, dtype=float)
        flat = np.ascontiguousarray(lam.reshape(-1, 3))
        return gaussian_tests_kernels.band_skewness(flat, cycles, EIGENVALUE_FLOOR, _MEAN_NORM).reshape(
            lam.shape[:-1])
    m1, m2, m3, m4, m5, m6 = _unit_moments(_scaled(lam)[1], order=6)
    factor = math.sqrt(cycles / (cycles - 1))
    sigma = np.sqrt(np.maximum(m2 - m1 ** 2, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        slope, slope2 = 1 - 3 * factor * m1 / sigma, 1.5 * factor / sigma
    variance_l, covariance, variance_l2 = m2 - m1 ** 2, m3 - m1 * m2, m4 - m2 ** 2
    third = (slope ** 3 * (m3 - 3 * m1 * m2 + 2 * m1 ** 3)
             + 3 * slope ** 2 * slope2 * (m4 - m2 ** 2 - 2 * m1 * m3 + 2 * m1 ** 2 * m2)
             + 3 * slope * slope2 ** 2 * (m5 - 2 * m2 * m3 - m1 * m4 + 2 * m1 * m2 ** 2)
             + slope2 ** 3 * (m6 - 3 * m2 * m4 + 2 * m2 ** 3))
    variance = slope ** 2 * variance_l + 2 * slope * slope2 * covariance + slope2 ** 2 * variance_l2
    shares = (slope * variance_l + slope2 * covariance, slope * covariance + slope2 * variance_l2)
    return np.where(sigma > 0, influence_skewness(third, variance, shares, (m1, m2), cycles), 0.0)


def skewed_band(mean: np.ndarray, spread: np.ndarray, skewness: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The ``BAND_PERCENTILES`` of one test's RP_l of ``mean``, standard deviation ``spread`` and ``skewness``
    (:func:`band_factors`)."""
    return tuple(mean + spread * factor for factor in band_factors(skewness))


def band_factors(skewness: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each end of the band (``BAND_PERCENTILES``) of a law of skewness γ (of order 1/√n), in standard deviations from
    its mean, by the Cornish-Fisher expansion to first order in γ: z + (z² - 1) γ / 6, z the normal's quantile."""
    return tuple(z + (z * z - 1) * skewness / 6 for z in (NormalDist().inv_cdf(p / 100) for p in BAND_PERCENTILES))


def gaussian_products(lam: np.ndarray) -> np.ndarray:
    """(k, 4, 4) the covariance of one Gaussian cycle's (y₁², y₂², y₁y₂, y₁y₃) in its covariance's eigenvector axes
    (:func:`expected_semi_axis`), from the eigenvalues ``lam`` (k, 3) [m²], largest first: diag(2λ₁², 2λ₂², λ₁λ₂,
    λ₁λ₃) [m⁴]."""
    lam = np.asarray(lam, dtype=float)
    products = np.zeros((len(lam), 4, 4))
    for i, value in enumerate((2 * lam[:, 0] ** 2, 2 * lam[:, 1] ** 2, lam[:, 0] * lam[:, 1], lam[:, 0] * lam[:, 2])):
        products[:, i, i] = value
    return products


def expected_semi_axis(lam: np.ndarray, products: np.ndarray, cycles: int) -> np.ndarray:
    """E√λ̂₁ [m] (k,): the expected largest 1σ semi-axis of one test's sample covariance (n - 1) over tests of
    ``cycles`` cycles, to order 1/n (from ``ASYMPTOTIC_CYCLES`` on), from the cycles' covariance's eigenvalues ``lam``
    (k, 3) [m²], largest first, and ``products`` (k, 4, 4) [m⁴], the covariance of one cycle's (y₁², y₂², y₁y₂, y₁y₃),
    y its offset in the eigenvectors' axes (:func:`gaussian_products` for a Gaussian's).

    To order 1/n the sample covariance's entries in those axes are normal about λ, their covariance ``products`` / n.
    The largest eigenvalue of its leading 2 × 2 block is (Ŝ₁₁ + Ŝ₂₂) / 2 + |((λ₁ - λ₂) / 2 + x, Ŝ₁₂)|, x = (a - b) / 2
    (a, b the errors of Ŝ₁₁, Ŝ₂₂): its mean takes E|(D + x, y)| of that 2-D normal (:func:`_expected_offset_norm`),
    right however near λ₂ comes to λ₁, where the perturbation series' E[y₁²y₂²] / (n (λ₁ - λ₂)) diverges; the third
    axis adds E|((λ₁ - λ₃) / 2, Ŝ₁₃)| - (λ₁ - λ₃) / 2 likewise; the square root takes -Var(Ŝ₁₁) / (8 E[λ̂₁]^(3/2)).
    Against Monte Carlo tests of 500 cycles (UR5 clouds, Gaussian and lognormal friction) it moves √λ₁ by -0.07 to
    +0.16 %, and leaves them within their standard errors of 0.04 %; where all three eigenvalues nearly meet it
    reads low (0.28 % at λ = (1, 0.98, 0.97))."""
    lam, products = np.asarray(lam, dtype=float), np.asarray(products, dtype=float) / cycles
    along = (products[:, 0, 0] + products[:, 1, 1] - 2 * products[:, 0, 1]) / 4
    shared = (products[:, 0, 2] - products[:, 1, 2]) / 2
    zero = np.zeros(len(lam))
    pair = _expected_offset_norm((lam[:, 0] - lam[:, 1]) / 2, along, products[:, 2, 2], shared)
    third = _expected_offset_norm((lam[:, 0] - lam[:, 2]) / 2, zero, products[:, 3, 3], zero)
    largest = (lam[:, 0] + lam[:, 1]) / 2 + pair + third - (lam[:, 0] - lam[:, 2]) / 2
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(largest > 0, np.sqrt(np.maximum(largest, 0.0)) - products[:, 0, 0] / (8 * largest ** 1.5),
                        0.0)


#: :func:`_expected_offset_norm` expands where the variances along and across the offset are within these fractions
#: of its square (the terms left out then under 1e-7 of it).
OFFSET_ALONG, OFFSET_ACROSS = 1e-2, 1e-3


def _expected_offset_norm(offset: np.ndarray, along: np.ndarray, across: np.ndarray, shared: np.ndarray
                          ) -> np.ndarray:
    """E|(D + x, y)| (k,) for (x, y) jointly normal about 0 of variances ``along`` and ``across`` and covariance
    ``shared``, D = ``offset`` ≥ 0 (their units: D's). Where p = Var x / D² ≤ ``OFFSET_ALONG`` and q = Var y / D² ≤
    ``OFFSET_ACROSS``: D + Var y / (2D) + (Var x Var y + 2 Cov²) / (2D³) - 3 Var y² / (8D³) (the expansion of
    √((D + x)² + y²) in x / D and y / D, leaving out terms of order p²q, pq², q³); elsewhere exactly
    (:func:`expected_norm`)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        square = offset * offset
        expand = (offset > 0) & (along <= OFFSET_ALONG * square) & (across <= OFFSET_ACROSS * square)
        result = np.where(expand, offset + across / (2 * offset)
                          + (along * across + 2 * shared * shared - 0.75 * across * across) / (2 * offset * square),
                          0.0)
    exact = ~expand
    if exact.any():
        centres = np.zeros((int(exact.sum()), 3))
        centres[:, 0] = offset[exact]
        covariances = np.zeros((len(centres), 3, 3))
        covariances[:, 0, 0], covariances[:, 1, 1] = along[exact], across[exact]
        covariances[:, 0, 1] = covariances[:, 1, 0] = shared[exact]
        result[exact] = expected_norm(centres, covariances)
    return result


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
            np.ascontiguousarray(np.broadcast_to(covariance, shape + (3, 3)).reshape(-1, 3, 3)), *NORM_RULE
            ).reshape(shape)
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
#: :func:`expected_norm`'s rule as its compiled kernel takes it: the expansion's ratio, the quadrature's times, weights
#: and step.
NORM_RULE = (EXPANSION_RATIO, _NODE_TIMES, _NODE_WEIGHTS, _LOG_STEP)


def _norm_by_quadrature(centre: np.ndarray, covariance: np.ndarray) -> np.ndarray:
    lam, vectors = np.linalg.eigh(covariance)
    beta2 = np.einsum("kij,ki->kj", vectors, centre) ** 2
    return _root_by_quadrature(np.zeros(len(lam)), np.maximum(lam, 0.0), beta2)


def _root_by_quadrature(constant: np.ndarray, lam: np.ndarray, beta2: np.ndarray) -> np.ndarray:
    """E√(a + Σ_i λ_i (z_i + β_i / √λ_i)²) (k,), z standard normal: (2√π)⁻¹ ∫₀^∞ (1 - e^{-ta} L(t)) t^{-3/2} dt, L the
    Laplace transform of the quadratic form, by the trapezoid rule on ``_LOG_NODES``; ``constant`` a (k,), ``lam``
    and ``beta2`` (k, 3) (any unit u: the result's √u)."""
    scale2 = np.maximum(constant + beta2.sum(axis=-1) + lam.sum(axis=-1), np.finfo(float).tiny)
    t = _NODE_TIMES[None, :, None] / scale2[:, None, None]
    log_transform = (-0.5 * np.log1p(2 * t * lam[:, None]) - t * beta2[:, None] / (1 + 2 * t * lam[:, None])).sum(-1)
    integrand = -np.expm1(log_transform - t[..., 0] * constant[:, None]) * _NODE_WEIGHTS
    return integrand.sum(axis=-1) * _LOG_STEP * np.sqrt(scale2) / (2 * math.sqrt(math.pi))


def expected_root(constant: np.ndarray, lam: np.ndarray) -> np.ndarray:
    """E√(a + εᵀ U ε) (k,) for ε ~ N(0, S): ``constant`` a (k,) >= 0, ``lam`` (k, 3) the eigenvalues of U S (their
    unit u: the result's √u); any number m of them, (k, m): E√(Σ λ_i z_i²) of a Gaussian quadratic form (a correlated
    series' sample standard deviation, :mod:`tribokin.maps.series_expected`; not all λ 0). Where a is at least
    ``ROOT_CONSTANT_SHARE`` of a + Σ λ (a test's shared barycentre, :func:`rp_l_from_moments`): on the coarser grid
    of :func:`sign_mixture` with its tails in closed form (:func:`_root_with_tails`); elsewhere
    :func:`_root_by_quadrature`."""
    constant, lam = np.asarray(constant, dtype=float), np.maximum(np.asarray(lam, dtype=float), 0.0)
    result = np.empty(constant.shape)
    ample = constant >= ROOT_CONSTANT_SHARE * (constant + lam.sum(axis=-1))
    result[ample] = _root_with_tails(constant[ample], lam[ample])
    result[~ample] = _root_by_quadrature(constant[~ample], lam[~ample], np.zeros(lam[~ample].shape))
    return result


#: Where a is at least this share of a + Σ λ, E√(a + Σ λ_i z_i²) is taken on a grid of the mixture's step
#: (:func:`_root_with_tails`): e^{-t a} then vanishes at the grid's last node (below e^-150), so its tail is t^{-1/2}'s
#: alone.
ROOT_CONSTANT_SHARE = 1e-5


def _root_with_tails(constant: np.ndarray, lam: np.ndarray) -> np.ndarray:
    """E√(a + Σ_i λ_i z_i²) (k,) as :func:`_root_by_quadrature` (no β), on a grid of :func:`sign_mixture`'s step
    (``MIXTURE_LOG_STEP``, from ``ROOT_LOG_START``; t in units of a + Σ λ) and its tails beyond in closed form, where a
    is at least ``ROOT_CONSTANT_SHARE`` of a + Σ λ: above the grid the integrand is t^{-1/2}, below it the series of
    1 - E e^{-tY} in E Y^k, k <= 4 (:func:`_root_rule`; Y = a + q, q = Σ λ_i z_i², its moments by
    :func:`_quadratic_form_moments`). Within 1.5e-10 of √a (λ = 0) and of a finer grid's (step
    0.125 to |u| = 40, tails added); :func:`_root_by_quadrature`, whose grid leaves out its tail beyond t = e^36, lies
    about 2e-8 below both. Compiled where :func:`~tribokin.compiled.use_compiled` (the same to rounding, through
    det(I + 2tΛ)'s elementary symmetric polynomials)."""
    if use_compiled():
        from tribokin.iso9283 import gaussian_tests_kernels

        return gaussian_tests_kernels.root_with_tails(np.ascontiguousarray(constant, dtype=float),
                                                      np.ascontiguousarray(lam, dtype=float), np.exp(_ROOT_LOGS),
                                                      MIXTURE_LOG_STEP, _mixture_tails()[0],
                                                      _lower_tails(ROOT_LOG_START))
    scale2 = np.maximum(constant + lam.sum(axis=-1), np.finfo(float).tiny)
    unit = lam / scale2[:, None]
    times = np.exp(_ROOT_LOGS)
    log_transform = -0.5 * np.log1p(2 * times[None, :, None] * unit[:, None, :]).sum(axis=-1) - np.outer(
        constant / scale2, times)
    total = (-np.expm1(log_transform) * times ** -0.5).sum(axis=-1)
    # Y = a + q a quadratic form whose extra term of λ = 0 and β² = a carries the constant
    zero = np.zeros((len(unit), 1))
    _, second, third, fourth, _ = (m[:, 0] for m in _quadratic_form_moments(
        np.hstack([unit, zero]), np.hstack([np.zeros_like(unit), (constant / scale2)[:, None]])[:, None]))
    total = _root_rule(total, second, third, fourth, _lower_tails(ROOT_LOG_START))
    return total * np.sqrt(scale2) / (2 * math.sqrt(math.pi))


#: The quadrature of :func:`sign_mixture`: the trapezoid rule on u = ln t (t in units of the mixture's E|x|²)
#: of this step, its nodes computed for |u| <= ``MIXTURE_LOG_RANGE`` and the grid's tails beyond summed in closed form
#: from the integrands' asymptotes (the rule's error about exp(-π² / step) ≈ 3e-9, the tails' below 1e-7, relative).
MIXTURE_LOG_STEP, MIXTURE_LOG_RANGE = 0.5, 16.0
#: Targets whose patterns and nodes the NumPy path holds at once.
MIXTURE_BLOCK = 512
_MIXTURE_LOGS = np.arange(-MIXTURE_LOG_RANGE, MIXTURE_LOG_RANGE + 1e-9, MIXTURE_LOG_STEP)


#: Where :func:`sign_mixture`'s grid starts (u = ln t): below it each integrand is its series in t, over the nodes
#: below summed in closed form (:func:`_lower_tails`): E|x| and E|x|³ from the patterns' E|x|^2k to k = 4 and 5, U to
#: second order in t. The series' error: within 2e-10 of the same rule carried twelve units further down, beside the
#: rule's own (about 3e-9); from -8 it was within 2e-13, at the cost of seven more nodes at which no pattern's L(t) is
#: yet negligible (the kernel a third slower on a UR5 plane's targets).
SIGN_LOG_START = -4.5
_SIGN_LOGS = _MIXTURE_LOGS[_MIXTURE_LOGS >= SIGN_LOG_START - 1e-9]
#: Where :func:`_root_with_tails`' grid starts: below it, the series of 1 - E e^{-tY} in E Y^k, k <= 4 (Y in units of
#: its mean; E Y^k may be as large as a χ²₁'s: 945 for k = 5).
ROOT_LOG_START = -8.0
_ROOT_LOGS = _MIXTURE_LOGS[_MIXTURE_LOGS >= ROOT_LOG_START - 1e-9]


def _lower_tails(start: float) -> np.ndarray:
    """Σ_{j >= 1} t_j^a over the nodes t_j = e^(``start`` - j h) below a grid of :func:`sign_mixture`'s step h that
    starts at u = ``start``, for a = 1/2, 3/2, 5/2, 7/2, 1, 2, 3."""
    return np.array([math.exp(a * start) / math.expm1(a * MIXTURE_LOG_STEP)
                     for a in (0.5, 1.5, 2.5, 3.5, 1.0, 2.0, 3.0)])


def _quadratic_form_moments(lam: np.ndarray, beta2: np.ndarray) -> tuple[np.ndarray, ...]:
    """E Q^k, k = 1..5, of Q = Σ_j λ_j (z_j + β_j / √λ_j)² (z standard normal): ``lam`` (k, 3) broadcast against
    ``beta2`` (k, patterns, 3) β², from the cumulants κ_r = 2^(r-1) (r-1)! Σ_j λ_j^(r-1) (λ_j + r β_j²)."""
    lam = lam[:, None, :]
    k1, k2, k3, k4, k5 = (2 ** (r - 1) * math.factorial(r - 1) * (lam ** (r - 1) * (lam + r * beta2)).sum(axis=-1)
                          for r in range(1, 6))
    return (k1, k2 + k1 ** 2, k3 + 3 * k2 * k1 + k1 ** 3, k4 + 4 * k3 * k1 + 3 * k2 ** 2 + 6 * k2 * k1 ** 2 + k1 ** 4,
            k5 + 5 * k4 * k1 + 10 * k3 * k2 + 10 * k3 * k1 ** 2 + 15 * k2 ** 2 * k1 + 10 * k2 * k1 ** 3 + k1 ** 5)


def _root_rule(inner: np.ndarray, second: np.ndarray, third: np.ndarray, fourth: np.ndarray, lower: np.ndarray
               ) -> np.ndarray:
    """(2√π)·E√Y on :func:`sign_mixture`'s grid (u = ln t) with its tails in closed form, Y in units of its mean
    (E Y = 1): ``inner`` the grid's Σ (1 - L(t)) t^{-1/2}; above the grid t^{-1/2}; below it (``lower``:
    :func:`_lower_tails`) t^{1/2} - t^{3/2} E Y² / 2 + t^{5/2} E Y³ / 6 - t^{7/2} E Y⁴ / 24 (``second``,
    ``third``, ``fourth``)."""
    return MIXTURE_LOG_STEP * (inner + _mixture_tails()[0] + lower[0] - second / 2 * lower[1] + third / 6 * lower[2]
                               - fourth / 24 * lower[3])


def _mixture_tails() -> tuple[float, float]:
    """Σ_{j > J} e^{-a j h} of the grid's nodes beyond ``MIXTURE_LOG_RANGE`` (h the step), for a = 1/2 and 3/2."""
    h, first = MIXTURE_LOG_STEP, _MIXTURE_LOGS[-1] + MIXTURE_LOG_STEP
    return tuple(math.exp(-a * first) / -math.expm1(-a * h) for a in (0.5, 1.5))


def sign_patterns(count: int) -> np.ndarray:
    """(2^(count - 1), count) the sign patterns ±1 of ``count`` joints with the first joint's +1 (a pattern and its
    opposite give the same norms)."""
    rows = np.arange(2 ** max(count - 1, 0))[:, None] >> np.arange(max(count - 1, 0))[None, :] & 1
    return np.column_stack([np.ones(len(rows)), 1.0 - 2.0 * rows]) if count else np.ones((1, 0))


def sign_mixture(columns: np.ndarray, covariance: np.ndarray) -> tuple[tuple[np.ndarray, ...], np.ndarray]:
    """E|x|^k, k = 1..4, (k,) each [m^k], and U = E[x xᵀ / |x|²] (k, 3, 3) of x = Σ_i s_i b_i + w: independent signs
    s_i = ±1 with equal odds, the (k, m, 3) ``columns`` b_i [m], w ~ N(0, S) of (k, 3, 3) ``covariance`` S [m²].
    Compiled where :func:`~tribokin.compiled.use_compiled`.

    A mean over the 2^(m - 1) sign patterns p (:func:`sign_patterns`) of Gaussian norm moments about c_p = Σ s_i b_i:
    E|x|² = |c|² + tr S, E|x|⁴ = (|c|² + tr S)² + 2 tr S² + 4 cᵀ S c; E|x| = (2√π)⁻¹ ∫ (1 - L(t)) t^{-3/2} dt and
    E|x|³ = 3 (4√π)⁻¹ ∫ (L(t) - 1 + t E|x|²) t^{-5/2} dt, with the Laplace transform L(t) = E e^{-t|x|²} =
    Π_i (1 + 2 t λ_i)^{-1/2} exp(-t β_i² / (1 + 2 t λ_i)) (λ, β: S's eigenvalues and c in its eigenvectors), on one
    grid of ``MIXTURE_LOG_STEP`` from ``SIGN_LOG_START`` for every pattern of a target, below it each integrand's
    series in t from the patterns' E|x|^2k (:func:`_quadratic_form_moments`); on b and S scaled by a power of two to
    order one. U from the same nodes: ∫₀^∞ E[x xᵀ e^{-t|x|²}] dt, whose integrand is L(t) (S_t + m_t m_tᵀ),
    S_t = S (I + 2 t S)⁻¹, m_t = (I + 2 t S)⁻¹ c_p (the Gaussian tilted by e^{-t|x|²}), below the grid to second
    order in t; its trace is 1 to about 1e-8.
    """
    columns, covariance = np.asarray(columns, dtype=float), np.asarray(covariance, dtype=float)
    magnitude = np.maximum(np.abs(columns).max(axis=(1, 2), initial=0.0),
                           np.sqrt(np.abs(np.diagonal(covariance, axis1=1, axis2=2)).max(axis=1, initial=0.0)))
    scale = np.exp2(np.round(np.log2(np.where(magnitude > 0, magnitude, 1.0))))  # to order one, exactly
    columns, covariance = columns / scale[:, None, None], covariance / scale[:, None, None] / scale[:, None, None]
    times, tails, lower = np.exp(_SIGN_LOGS), _mixture_tails(), _lower_tails(SIGN_LOG_START)
    if use_compiled():
        from tribokin.iso9283 import gaussian_tests_kernels

        *moments, directions = gaussian_tests_kernels.sign_mixture(np.ascontiguousarray(columns),
                                                                   np.ascontiguousarray(covariance), times,
                                                                   MIXTURE_LOG_STEP, *tails, lower)
    else:
        blocks = [_mixture_block(columns[start:start + MIXTURE_BLOCK], covariance[start:start + MIXTURE_BLOCK],
                                 times, tails, lower) for start in range(0, len(columns), MIXTURE_BLOCK)]
        empty = (np.empty(0),) * 4 + (np.empty((0, 3, 3)),)
        *moments, directions = [np.concatenate([block[i] for block in blocks]) if blocks else empty[i]
                                for i in range(5)]
    return tuple(moment * scale ** k for k, moment in enumerate(moments, start=1)), directions


def _mixture_block(columns: np.ndarray, covariance: np.ndarray, times: np.ndarray, tails: tuple[float, float],
                   lower: np.ndarray) -> tuple[np.ndarray, ...]:
    """:func:`sign_mixture` of a block of targets on the NumPy path: (targets, patterns, nodes) at once."""
    lam, vectors = np.linalg.eigh(covariance)
    lam = np.maximum(lam, 0.0)
    scale2 = np.einsum("kmi,kmi->k", columns, columns) + lam.sum(axis=-1)
    unit2 = np.where(scale2 > 0, scale2, 1.0)
    lam = lam / unit2[:, None]
    beta = np.einsum("pm,kmi,kij->kpj", sign_patterns(columns.shape[1]), columns, vectors) / np.sqrt(unit2)[:, None,
                                                                                                            None]
    beta2 = beta ** 2
    second, fourth, sixth, eighth, tenth = _quadratic_form_moments(lam, beta2)  # (k, patterns): E|x|^2k, scale2 units
    grown = 2 * times[None, :, None] * lam[:, None, :]  # (k, nodes, 3)
    log_transform = (-0.5 * np.log1p(grown).sum(axis=-1)[:, None, :]
                     - times * np.einsum("kpj,ktj->kpt", beta2, 1 / (1 + grown)))  # (k, patterns, nodes)
    less_one = np.expm1(log_transform)
    first = (-less_one * times ** -0.5).sum(axis=-1).mean(axis=-1)
    third = ((less_one + times * second[..., None]) * times ** -1.5).sum(axis=-1).mean(axis=-1)
    half, three_halves = tails
    mean_fourth, mean_sixth, mean_eighth, mean_tenth = (m.mean(axis=-1) for m in (fourth, sixth, eighth, tenth))
    first = _root_rule(first, mean_fourth, mean_sixth, mean_eighth, lower)  # E|x|² = 1 in these units
    third = MIXTURE_LOG_STEP * (third + half - three_halves + mean_fourth / 2 * lower[0] - mean_sixth / 6 * lower[1]
                                + mean_eighth / 24 * lower[2] - mean_tenth / 120 * lower[3])
    scale = np.sqrt(np.where(scale2 > 0, scale2, 0.0))
    weight = less_one + 1  # L(t), (k, patterns, nodes)
    tilt = 1 / (1 + grown)  # (k, nodes, 3)
    products = beta[..., :, None] * beta[..., None, :]  # (k, patterns, 3, 3)
    pairs = np.swapaxes(weight, 1, 2) @ products.reshape(*beta.shape[:2], 9)
    inner = (tilt[..., :, None] * tilt[..., None, :] * pairs.reshape(*pairs.shape[:2], 3, 3)
             + (weight.sum(axis=1)[..., None] * lam[:, None] * tilt)[..., None] * np.eye(3))  # (k, nodes, 3, 3)
    spread, summed = lam[:, :, None] * np.eye(3), products.sum(axis=1)
    pairwise = lam[:, :, None] + lam[:, None, :]
    second_sum, weighted = second.sum(axis=1)[:, None, None], np.einsum("kp,kpij->kij", second, products)
    below = (lower[4] * (beta.shape[1] * spread + summed)  # t L(t) (S_t + m_t m_tᵀ) to second order in t, below
             - lower[5] * (second_sum * spread + weighted + 2 * beta.shape[1] * spread ** 2 + 2 * pairwise * summed)
             + lower[6] * (fourth.sum(axis=1)[:, None, None] / 2 * spread
                           + np.einsum("kp,kpij->kij", fourth, products) / 2
                           + 2 * (second_sum * spread ** 2 + pairwise * weighted)
                           + 4 * (beta.shape[1] * spread ** 3 + (pairwise ** 2 - lam[:, :, None] * lam[:, None, :])
                                  * summed)))
    inner = (np.einsum("t,ktij->kij", times, inner) + below) * MIXTURE_LOG_STEP / beta.shape[1]
    directions = np.where((scale2 > 0)[:, None, None], vectors @ inner @ np.swapaxes(vectors, 1, 2), 0.0)
    return (first / (2 * math.sqrt(math.pi)) * scale, scale2, 3 * third / (4 * math.sqrt(math.pi)) * scale ** 3,
            mean_fourth * scale2 ** 2, directions)


def barycentre_shares(directions: np.ndarray, pooled: np.ndarray, cycles: int) -> np.ndarray:
    """The eigenvalues (k, 3) [m²] of U Σ̄ / n (``directions`` U (k, 3, 3), ``pooled`` Σ̄ (k, 3, 3) [m²], n
    ``cycles``): a test's shared barycentre ε ~ N(0, Σ̄ / n) adds εᵀ U ε to its S_l² (:func:`rp_l_from_moments`).

    S_l² = mean_j l_j² - l̄², l_j = |d_j - ε| (d_j a cycle's offset from the cycles' mean, ε = mean_j d_j): mean_j l_j²
    = mean_j |d_j|² - |ε|² exactly, and l_j = |d_j| - û_jᵀ ε + O(ε² / |d_j|), so S_l² ≈ Var_j |d_j| + εᵀ Cov_j(û) ε
    less terms in the spread of |d_j| (which vanish where it is small beside Σ̄, the only case the term counts:
    then Cov_j(û) → U = E[û ûᵀ], ū being of order ε / |d|). Compiled where :func:`~tribokin.compiled.use_compiled`
    (Jacobi's eigenvalues for LAPACK's: the same to rounding of the largest)."""
    if use_compiled():
        from tribokin.iso9283 import gaussian_tests_kernels

        return gaussian_tests_kernels.barycentre_shares(np.ascontiguousarray(directions, dtype=float),
                                                        np.ascontiguousarray(pooled, dtype=float), float(cycles))
    lam, vectors = np.linalg.eigh(pooled)
    root = vectors * np.sqrt(np.maximum(lam, 0.0))[:, None, :] @ np.swapaxes(vectors, 1, 2)
    return np.linalg.eigvalsh(root @ directions @ root) / cycles


def rp_l_from_mixture(moments: tuple[np.ndarray, ...], directions: np.ndarray, pooled: np.ndarray, cycles: int
                      ) -> np.ndarray:
    """E[RP_l] [m] (k,) of :func:`rp_l_from_moments` with the barycentre a test's cycles share from
    :func:`sign_mixture`'s ``directions`` U (k, 3, 3) and the cycles' ``pooled`` covariance Σ̄ (k, 3, 3) [m²]
    (:func:`barycentre_shares`); compiled where :func:`~tribokin.compiled.use_compiled`, in one kernel per target (the
    same to rounding)."""
    if use_compiled():
        from tribokin.iso9283 import gaussian_tests_kernels

        mean = gaussian_tests_kernels.mixture_rp_l(*(np.ascontiguousarray(m, dtype=float) for m in moments),
                                                   np.ascontiguousarray(directions, dtype=float),
                                                   np.ascontiguousarray(pooled, dtype=float), cycles,
                                                   np.exp(_ROOT_LOGS), MIXTURE_LOG_STEP, _mixture_tails()[0],
                                                   _lower_tails(ROOT_LOG_START), ROOT_CONSTANT_SHARE)
        rest = np.flatnonzero(np.isnan(mean))  # E√(a + εᵀ U ε) with a below its share: the quadrature's
        if len(rest):
            mean[rest] = rp_l_from_moments(tuple(m[rest] for m in moments), cycles,
                                           barycentre_shares(directions[rest], pooled[rest], cycles))[0]
        return mean
    return rp_l_from_moments(moments, cycles, barycentre_shares(directions, pooled, cycles))[0]


#: Gauss-Legendre nodes on either side of the kink of :func:`expected_maximum`'s integral, and how many standard
#: deviations either side of its mean the integral spans (the normal's mass beyond: 1e-15).
MAXIMUM_NODES, MAXIMUM_SPAN = 32, 8.0
_LEGENDRE = np.polynomial.legendre.leggauss(MAXIMUM_NODES)
#: :func:`expected_maximum`'s rule as its compiled kernel takes it: the nodes and weights on [-1, 1], the span.
MAXIMUM_RULE = (*_LEGENDRE, MAXIMUM_SPAN)


def expected_maximum(mean: np.ndarray, covariance: np.ndarray) -> np.ndarray:
    """E[max(Y_1, Y_2, Y_3)] (k,) of jointly normal Y of ``mean`` (k, 3) and ``covariance`` (k, 3, 3) (their unit).

    With D = Y_2 - Y_1 and W = Y_3 - Y_1: E[max Y] = E[Y_1] + E_D[E[max(max(0, D), W) | D]], the inner expectation
    in closed form (W | D is normal: E[max(a, W)] = a + (m - a) Φ((m - a)/s) + s φ((m - a)/s)), the outer over D by
    Gauss-Legendre on either side of its kink D = 0 (each side smooth: within 2e-11 on a UR5 plane's close pairs of
    approach directions; where W given D spreads far less than D, its turn where W meets max(0, D) is narrower than
    the nodes resolve, up to 5e-4 off on random covariances). Where one Y lies
    ``MAXIMUM_SPAN`` standard deviations of its differences below both others (it is the largest with probability
    below 1e-15: two approach directions with the same joint signs, whose own distance is about 0), the other two's
    largest in closed form (Clark 1961): μ_a Φ(α) + μ_b Φ(-α) + θ φ(α), θ² = Var(Y_a - Y_b), α = (μ_a - μ_b) / θ.
    """
    from scipy.special import ndtr  # here: only a map's close pairs of approach directions need it

    mean, covariance = np.asarray(mean, dtype=float), np.asarray(covariance, dtype=float)
    out = np.empty(len(mean))
    rest = np.ones(len(mean), dtype=bool)
    for low, (a, b) in enumerate(((1, 2), (0, 2), (0, 1))):
        spreads = [np.sqrt(np.maximum(covariance[:, i, i] + covariance[:, low, low] - 2 * covariance[:, i, low], 0.0))
                   for i in (a, b)]
        two = rest & (mean[:, a] - mean[:, low] >= MAXIMUM_SPAN * spreads[0]) & (
            mean[:, b] - mean[:, low] >= MAXIMUM_SPAN * spreads[1])
        theta = np.sqrt(np.maximum(covariance[two, a, a] + covariance[two, b, b] - 2 * covariance[two, a, b], 0.0))
        with np.errstate(divide="ignore", invalid="ignore"):
            alpha = (mean[two, a] - mean[two, b]) / theta
            clark = (mean[two, a] * ndtr(alpha) + mean[two, b] * ndtr(-alpha)
                     + theta * np.exp(-alpha ** 2 / 2) / math.sqrt(2 * math.pi))
        out[two] = np.where(theta > 0, clark, np.maximum(mean[two, a], mean[two, b]))
        rest &= ~two
    out[rest] = _maximum_by_quadrature(mean[rest], covariance[rest])
    return out


def _maximum_by_quadrature(mean: np.ndarray, covariance: np.ndarray) -> np.ndarray:
    """:func:`expected_maximum` over D by Gauss-Legendre."""
    from scipy.special import ndtr

    c = covariance
    mean_d, mean_w = mean[:, 1] - mean[:, 0], mean[:, 2] - mean[:, 0]
    var_d = np.maximum(c[:, 1, 1] + c[:, 0, 0] - 2 * c[:, 0, 1], 0.0)
    var_w = np.maximum(c[:, 2, 2] + c[:, 0, 0] - 2 * c[:, 0, 2], 0.0)
    shared = c[:, 1, 2] - c[:, 0, 1] - c[:, 0, 2] + c[:, 0, 0]
    sd_d = np.sqrt(var_d)
    slope = np.divide(shared, var_d, out=np.zeros_like(var_d), where=var_d > 0)
    sd_w = np.sqrt(np.maximum(var_w - slope * shared, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        kink = np.clip(np.where(sd_d > 0, -mean_d / sd_d, np.where(mean_d < 0, MAXIMUM_SPAN, -MAXIMUM_SPAN)),
                       -MAXIMUM_SPAN, MAXIMUM_SPAN)
    t, w = _LEGENDRE
    sides = [(np.full_like(kink, -MAXIMUM_SPAN), kink), (kink, np.full_like(kink, MAXIMUM_SPAN))]
    x = np.concatenate([(high - low)[:, None] / 2 * t + (high + low)[:, None] / 2 for low, high in sides], axis=1)
    weights = np.concatenate([(high - low)[:, None] / 2 * w for low, high in sides], axis=1) * np.exp(-x ** 2 / 2)
    d = mean_d[:, None] + sd_d[:, None] * x
    floor = np.maximum(d, 0.0)
    excess = mean_w[:, None] + slope[:, None] * sd_d[:, None] * x - floor
    spread = sd_w[:, None]
    with np.errstate(divide="ignore", invalid="ignore"):
        z = np.where(spread > 0, excess / spread, np.where(excess > 0, np.inf, -np.inf))
        inner = floor + np.where(spread > 0, excess * ndtr(z) + spread * np.exp(-z ** 2 / 2) / math.sqrt(2 * math.pi),
                                 np.maximum(excess, 0.0))
    return mean[:, 0] + (weights * inner).sum(axis=1) / weights.sum(axis=1)


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


def largest_eigenvalue(matrices: np.ndarray) -> np.ndarray:
    """(...,) the largest eigenvalue of symmetric (..., 3, 3) ``matrices`` (their unit), to within 2e-14 of LAPACK's:
    in closed form, the trigonometric solution of the characteristic cubic (λ = q + 2 p cos(arccos(r) / 3),
    q = tr A / 3, p² = |A - q I|²_F / 6, r = det((A - q I) / p) / 2) of each matrix scaled by its largest entry (a
    tenth of LAPACK's time for many small matrices), and LAPACK's where the two largest eigenvalues (nearly) meet
    (r < ``DOUBLE_LARGEST`` - 1), where the cubic's angle loses up to half the digits."""
    size = np.abs(matrices).max(axis=(-2, -1))
    size = np.where(size > 0, size, 1.0)
    unit = matrices / size[..., None, None]
    q = np.trace(unit, axis1=-2, axis2=-1) / 3
    d0, d1, d2 = unit[..., 0, 0] - q, unit[..., 1, 1] - q, unit[..., 2, 2] - q
    a01, a02, a12 = unit[..., 0, 1], unit[..., 0, 2], unit[..., 1, 2]
    p = np.sqrt((d0 * d0 + d1 * d1 + d2 * d2 + 2 * (a01 * a01 + a02 * a02 + a12 * a12)) / 6)
    d0, d1, d2, a01, a02, a12 = (x / np.where(p > 0, p, 1.0) for x in (d0, d1, d2, a01, a02, a12))  # B = (A - q I) / p
    r = np.clip((d0 * (d1 * d2 - a12 * a12) - a01 * (a01 * d2 - a12 * a02) + a02 * (a01 * a12 - d1 * a02)) / 2, -1, 1)
    largest = q + 2 * p * np.cos(np.arccos(r) / 3)
    double = (r < DOUBLE_LARGEST - 1) & (p > 0)
    if double.any():
        largest[double] = np.linalg.eigvalsh(unit[double])[:, -1]
    return largest * size


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
                semi_axis = np.sqrt(np.maximum(largest_eigenvalue(covariances * np.outer(scale, scale)), 0.0))
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
    square = centred * centred
    variance = square.mean(axis=-1)
    s = np.sqrt(variance)
    spread = variance > 0
    skew = np.divide((square * centred).mean(axis=-1), variance * s, out=np.zeros_like(s), where=spread)
    kurtosis = np.divide((square * square).mean(axis=-1), variance * variance, out=np.full_like(s, 3.0),
                         where=spread) - 3
    slope = 1 + z * skew / 3 + (z ** 2 - 1) * kurtosis / 8 - (6 * z ** 2 - 5) * skew ** 2 / 36
    error = math.sqrt(p * (1 - p) / n) * s * np.maximum(slope, 0.1) / NormalDist().pdf(z)
    return np.divide(error, np.abs(value), out=np.zeros_like(error), where=value != 0)
