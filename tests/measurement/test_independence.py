"""A measured series' test of independence: a known AR(1) correlation is covered by its interval and refused
independence, independent cycles are not, the Ljung-Box p of one series equals a hand computation, short or
pointlike series have none, and the series is taken in time order."""

from __future__ import annotations

import math

import numpy as np

from tribokin.measurement.contract import Series
from tribokin.measurement.independence import MIN_CYCLES, deviations, series_independence

#: The main axis of the synthetic clouds (a unit vector).
AXIS = np.array([2.0, -1.0, 2.0]) / 3.0


def series(positions_m: np.ndarray, times_s: np.ndarray | None = None) -> Series:
    """A series of the rows ``positions_m`` [m], cycles 1..n."""
    n = len(positions_m)
    return Series("+x", np.arange(1, n + 1), np.arange(n), positions_m, None, None, None, times_s)


def cloud(along: np.ndarray, rng: np.random.Generator, across_m: float = 1e-8) -> np.ndarray:
    """Positions about a point: ``along`` [m] on :data:`AXIS`, independent noise of ``across_m`` on every axis."""
    return np.array([0.4, -0.2, 0.35]) + along[:, None] * AXIS + rng.normal(0, across_m, (len(along), 3))


def ar1(rho: float, shape: tuple[int, int], rng: np.random.Generator, std: float = 5e-6) -> np.ndarray:
    """Stationary Gaussian AR(1) series along the last axis of ``shape``: lag-one correlation ``rho``, standard
    deviation ``std``."""
    x = np.empty(shape)
    x[..., 0] = rng.normal(0, std, shape[:-1])
    for t in range(1, shape[-1]):
        x[..., t] = rho * x[..., t - 1] + rng.normal(0, std * math.sqrt(1 - rho * rho), shape[:-1])
    return x


def judged(along: np.ndarray, rng: np.random.Generator) -> list:
    """The test of each row of ``along`` as a series (:func:`cloud`)."""
    return [series_independence(series(points), points) for points in (cloud(a, rng) for a in along)]


def test_a_known_ar1_correlation_is_covered_and_not_independent():
    # 200 series of 500 cycles at ρ = 0.6: the 95 % interval covers 0.6 about 95 % of the time (r₁'s bias,
    # −(1 + 4ρ)/n = −0.007, is a fifth of its standard error), and every series is refused independence.
    tests = judged(ar1(0.6, (200, 500), np.random.default_rng(38)), np.random.default_rng(39))
    coverage = np.mean([t.lag1.covers(0.6) for t in tests])
    assert 0.90 <= coverage <= 0.99, coverage  # a binomial 200 draws at 0.95: ±0.03 at 2 standard errors
    assert not any(t.ljung_box.independent for t in tests)
    assert all(t.lag1.high - t.lag1.low < 0.16 for t in tests)  # 2·1.96·√((1 − r₁²)/500): 0.140 at r₁ = 0.6


def test_independent_cycles_are_consistent_with_independence():
    # 200 series of 50 independent cycles: Ljung-Box keeps its 5 % level, the interval covers 0 about 95 %.
    tests = judged(np.random.default_rng(9283).normal(0, 5e-6, (200, 50)), np.random.default_rng(1))
    independent = np.mean([t.ljung_box.independent for t in tests])
    assert 0.90 <= independent <= 0.99, independent
    assert 0.90 <= np.mean([t.lag1.covers(0.0) for t in tests]) <= 0.995
    assert {t.ljung_box.lags for t in tests} == {10}


def test_the_ljung_box_p_of_one_series_is_the_hand_computation():
    along = np.array([3, -1, 4, 1, -5, 9, -2, 6, -5, 3, 5, -8]) * 1e-6
    points = np.array([0.4, -0.2, 0.35]) + along[:, None] * AXIS  # on one line: the deviations are ±(along − mean)
    test = series_independence(series(points), points)
    d = along - along.mean()
    n = len(d)
    r = [sum(d[t] * d[t + k] for t in range(n - k)) / sum(v * v for v in d) for k in (1, 2)]
    q = n * (n + 2) * (r[0] ** 2 / (n - 1) + r[1] ** 2 / (n - 2))  # 12 // 5 = 2 lags
    assert test.ljung_box.lags == 2
    assert math.isclose(test.ljung_box.q, q, rel_tol=1e-9)
    assert math.isclose(test.ljung_box.pvalue, math.exp(-q / 2), rel_tol=1e-9)  # chi-square, 2 dof: exp(−Q/2)
    assert math.isclose(test.lag1.value, r[0], rel_tol=1e-9)
    half = 1.959963984540054 * math.sqrt((1 - r[0] ** 2) / n)
    assert math.isclose(test.lag1.low, max(r[0] - half, -1.0), rel_tol=1e-9)  # clipped to (−1, 1)
    assert math.isclose(test.lag1.high, r[0] + half, rel_tol=1e-9)


def test_a_series_too_short_or_at_one_point_has_no_test():
    rng = np.random.default_rng(1)
    short = cloud(rng.normal(0, 5e-6, MIN_CYCLES - 1), rng)
    assert series_independence(series(short), short).lag1 is None
    long_enough = cloud(rng.normal(0, 5e-6, MIN_CYCLES), rng)
    assert series_independence(series(long_enough), long_enough).ljung_box is not None
    still = np.tile([0.1, 0.2, 0.3], (20, 1))
    test = series_independence(series(still), still)
    assert test.lag1 is None and test.ljung_box is None
    assert test.report_fields() == dict.fromkeys(("lag1_autocorrelation", "lag1_interval", "ljung_box_q",
                                                  "ljung_box_lags", "ljung_box_p", "independent"))


def test_the_series_is_taken_in_time_order():
    rng = np.random.default_rng(2)
    points = cloud(ar1(0.9, (60,), rng), rng)
    shuffled = rng.permutation(60)  # cycle numbers in another order than the times
    times = shuffled.astype(float)  # row i is the shuffled[i]-th reading in time
    in_time = series_independence(series(points[shuffled], times), points[shuffled])
    in_cycles = series_independence(series(points), points)
    assert in_time == in_cycles
    assert in_time.lag1.value > 0.5


def test_the_deviations_are_signed_offsets_along_the_main_axis():
    along = np.array([-3.0, 1.0, 2.0]) * 1e-6
    u = deviations(np.array([0.4, -0.2, 0.35]) + along[:, None] * AXIS)
    assert np.allclose(abs(u), abs(along), atol=1e-15) and u[0] * u[2] < 0
