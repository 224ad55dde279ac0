"""Properties of every friction law, whatever its parameters: draws lie in the support, which is never
negative; sample moments converge to mean() and std(); negative parameters are refused.

Tolerances are 6 standard errors of the estimate from N draws (a false alarm about once in 5e8):
SE(mean) = std / sqrt(N); SE(sample std) = sqrt((m4 - s^4) / N) / (2 s) (delta method, m4 the
sample fourth central moment).
"""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tribokin.errors import LawError
from tribokin.tribology.laws import Constant, Empirical, Gaussian, Lognormal, Uniform

DRAWS = 50_000
mu = st.floats(0.0, 1.0, allow_subnormal=False)

# widths of 1e-6 and more (friction coefficients are measured to a few decimals; a zero width is
# test_zero_width_laws_are_constant's)
uniform = st.tuples(mu, mu).filter(lambda pair: abs(pair[0] - pair[1]) >= 1e-6).map(
    lambda pair: Uniform(min(pair), max(pair)))
# from far above zero (the plain normal law) down to mean 0 (half-normal: the truncation at zero matters)
gaussian = st.builds(Gaussian, st.floats(0.0, 0.5), st.floats(1e-4, 0.2))
# coefficient of variation up to 0.5: the fourth moment, hence the tolerance on std, stays moderate
lognormal = st.tuples(st.floats(0.01, 0.5), st.floats(0.001, 0.5)).map(lambda m_cv: Lognormal(m_cv[0],
                                                                                            m_cv[0] * m_cv[1]))
constant = st.builds(Constant, mu)
empirical = st.lists(mu, min_size=2, max_size=60).map(Empirical)
laws = st.one_of(uniform, gaussian, lognormal, constant, empirical)


@given(laws, st.integers(0, 2 ** 32 - 1))
def test_draws_lie_in_the_support_which_is_never_negative(law, seed):
    low, high = law.support()
    assert -1e-15 <= low <= high  # exactly 0 is test_truncated_gaussian_support_starts_at_zero's
    draws = law.rvs(size=DRAWS, random_state=np.random.default_rng(seed))
    assert draws.shape == (DRAWS,) and np.all(np.isfinite(draws))
    assert 0.0 <= draws.min() and low <= draws.min() and draws.max() <= high


@given(laws, st.integers(0, 2 ** 32 - 1))
def test_sample_moments_converge_to_mean_and_std(law, seed):
    draws = law.rvs(size=DRAWS, random_state=np.random.default_rng(seed))
    mean, std = law.mean(), law.std()
    low, high = law.support()
    assert std >= 0.0 and low - 1e-15 <= mean <= high + 1e-15  # the mean of equal values may round off by an ulp
    if std == 0.0:
        np.testing.assert_allclose(draws, mean, rtol=1e-12, atol=1e-15)
        return
    assert abs(draws.mean() - mean) <= 6 * std / math.sqrt(DRAWS) + 1e-12  # (+ rounding of the sums)
    s = draws.std()
    m4 = np.mean((draws - draws.mean()) ** 4)
    standard_error = math.sqrt(max(m4 - s ** 4, 0.0) / DRAWS) / (2 * s) if s > 0 else 0.0
    assert abs(s - std) <= 6 * standard_error + 1e-15  # (+ the std of equal values, rounded off)


@given(st.floats(-1e3, -1e-12), mu)
def test_negative_parameters_are_refused_naming_them(negative, valid):
    for make, key in ((lambda: Uniform(negative, valid), "low"), (lambda: Gaussian(valid, negative), "std"),
                      (lambda: Gaussian(negative, 0.01), "mean"), (lambda: Constant(negative), "mu"),
                      (lambda: Lognormal(negative, 0.01), "mean"), (lambda: Empirical([valid, negative]), "values")):
        with pytest.raises(LawError) as error:
            make()
        assert error.value.parameter == key


@given(mu, mu)
def test_inverted_bounds_are_refused(a, b):
    if a == b:
        return
    with pytest.raises(LawError, match="swap"):
        Uniform(max(a, b), min(a, b))


@pytest.mark.parametrize("law", [Uniform(0.12, 0.12), Gaussian(0.12, 0.0), Lognormal(0.12, 0.0)],
                         ids=["uniform", "gaussian", "lognormal"])
def test_zero_width_laws_are_constant(law):
    assert law.support() == (0.12, 0.12) and law.std() == 0.0 and law.mean() == 0.12
    assert np.all(law.rvs(size=10, random_state=np.random.default_rng(0)) == 0.12)
    assert law.pdf(0.12) == np.inf and law.pdf(0.13) == 0.0


def test_truncated_gaussian_support_starts_at_zero():
    assert Gaussian(0.466796875, 0.1796875).support()[0] >= 0.0
