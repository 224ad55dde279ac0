"""Friction laws: moments against closed forms, sampling, validation, presets."""

import math
import os
import subprocess
import sys

import numpy as np
import pytest
from scipy import special, stats

from conftest import axis_study
from tribokin.errors import InputError, LawError, TribokinError
from tribokin.study.assembly import joint_models, load_robot
from tribokin.study.reading import load_study
from tribokin.tribology import (
    PRESETS,
    Constant,
    Empirical,
    FrictionLaw,
    Gaussian,
    Lognormal,
    Uniform,
    fitting,
    law_from_spec,
    laws,
    preset,
)

N = 200_000


def sample_moments(law, seed=0):
    x = law.rvs(size=N, random_state=np.random.default_rng(seed))
    return x.mean(), x.std()


def test_uniform_moments_closed_form():
    law = Uniform(0.09, 0.16)
    assert law.mean() == pytest.approx(0.125)
    assert law.std() == pytest.approx(0.07 / math.sqrt(12))
    assert law.support() == (0.09, 0.16)
    assert law.pdf(0.1) == pytest.approx(1 / 0.07)
    assert law.pdf(0.2) == 0
    mean, std = sample_moments(law)
    assert mean == pytest.approx(0.125, rel=2e-3)
    assert std == pytest.approx(0.07 / math.sqrt(12), rel=5e-3)


def test_gaussian_far_from_zero_keeps_its_parameters():
    law = Gaussian(0.1375, 0.0075)
    assert law.mean() == pytest.approx(0.1375, rel=1e-12)
    assert law.std() == pytest.approx(0.0075, rel=1e-9)
    assert law.pdf(0.1375) == pytest.approx(1 / (0.0075 * math.sqrt(2 * math.pi)), rel=1e-9)
    mean, std = sample_moments(law)
    assert mean == pytest.approx(0.1375, rel=1e-3)
    assert std == pytest.approx(0.0075, rel=5e-3)


def test_gaussian_is_truncated_at_zero():
    law = Gaussian(0.02, 0.05)
    x = law.rvs(size=N, random_state=np.random.default_rng(1))
    assert x.min() >= 0
    assert law.support()[0] == 0
    # truncated-normal mean: m + s * phi(alpha) / (1 - Phi(alpha)), alpha = -m/s
    alpha = -0.02 / 0.05
    phi = math.exp(-alpha ** 2 / 2) / math.sqrt(2 * math.pi)
    expected = 0.02 + 0.05 * phi / (0.5 * special.erfc(alpha / math.sqrt(2)))
    assert law.mean() == pytest.approx(expected, rel=1e-9)
    assert x.mean() == pytest.approx(expected, rel=5e-3)


def test_lognormal_matches_requested_mean_and_std():
    law = Lognormal(0.12, 0.02)
    assert law.mean() == pytest.approx(0.12, rel=1e-12)
    assert law.std() == pytest.approx(0.02, rel=1e-9)
    mean, std = sample_moments(law)
    assert mean == pytest.approx(0.12, rel=2e-3)
    assert std == pytest.approx(0.02, rel=1e-2)


def test_constant_and_empirical():
    assert np.all(Constant(0.12).rvs(size=5) == 0.12)
    assert Constant(0.12).std() == 0
    values = [0.10, 0.11, 0.13, 0.16]
    law = Empirical(values)
    x = law.rvs(size=N, random_state=np.random.default_rng(2))
    assert set(np.unique(x)) == set(values)
    assert law.mean() == pytest.approx(np.mean(values))
    assert law.std() == pytest.approx(np.std(values))
    assert x.mean() == pytest.approx(np.mean(values), rel=2e-3)
    assert law.support() == (0.10, 0.16)


def test_same_generator_state_same_draws():
    law = Gaussian(0.1, 0.01)
    a = law.rvs(size=10, random_state=np.random.default_rng(5))
    b = law.rvs(size=10, random_state=np.random.default_rng(5))
    assert np.array_equal(a, b)


@pytest.mark.parametrize("make, key", [
    (lambda: Uniform(0.2, 0.1), "low"),
    (lambda: Gaussian(0.1, -0.01), "std"),
    (lambda: Constant(-0.1), "mu"),
    (lambda: Lognormal(0.0, 0.01), "mean"),
    (lambda: Empirical([0.1]), "values"),
    (lambda: Uniform(float("nan"), 0.1), "low"),
    (lambda: Constant(10.5), "mu"),
    (lambda: Gaussian(0.1, 10 ** 400), "std"),
    (lambda: Lognormal(1e-300, 1.0), "mean"),
    (lambda: Empirical([0.1, 1e308]), "values"),
    (lambda: Empirical([0.1, 10 ** 400]), "values"),
])
def test_bad_parameters_raise_a_law_error_naming_the_parameter(make, key):
    with pytest.raises(LawError) as error:
        make()
    assert error.value.parameter == key and isinstance(error.value, TribokinError)


def test_presets_carry_provenance():
    assert set(PRESETS) == {"frictionless", "constant-0.12", "42CD4-raw", "42CD4-treated"}
    treated = preset("42CD4-treated")
    assert (treated.mean(), treated.std()) == pytest.approx((0.1375, 0.0075))
    assert "ASSUMPTION" in treated.provenance
    assert preset("42CD4-raw").support() == (0.09, 0.16)
    assert preset("frictionless").mean() == 0


def test_spec_errors_point_inside_the_mapping():
    with pytest.raises(InputError, match="did you mean '42CD4-raw'") as error:
        law_from_spec({"preset": "42CD4-rw"}, "s.toml", "joints.friction")
    assert error.value.key == "joints.friction.preset"
    with pytest.raises(InputError) as error:
        law_from_spec({"law": "uniform", "low": 0.2, "high": 0.1}, "s.toml", "joints.friction")
    assert error.value.key == "joints.friction.low"
    with pytest.raises(InputError, match="unknown key 'sigma'"):
        law_from_spec({"law": "gaussian", "mean": 0.1, "sigma": 0.1}, "s.toml")


@pytest.mark.parametrize("mean, std", [(0.0, 0.05), (0.02, 0.05), (0.1375, 0.0075)])
def test_gaussian_sampler_follows_the_truncated_law(mean, std):
    """The sampler redraws negative values: its samples must follow scipy's truncated normal."""
    from scipy import stats

    law = Gaussian(mean, std)
    x = law.rvs(size=(400, 50), random_state=np.random.default_rng(11))
    assert x.shape == (400, 50) and x.min() >= 0
    truncated = stats.truncnorm(a=-mean / std, b=np.inf, loc=mean, scale=std)
    assert stats.kstest(x.ravel(), truncated.cdf).pvalue > 1e-3


def test_the_registry_lists_every_law_by_its_name():
    assert list(laws.LAWS) == ["constant", "uniform", "gaussian", "lognormal", "empirical"]
    assert all(law.law == name and law.parameters for name, law in laws.LAWS.items())


def test_a_law_defined_in_one_class_parses_from_a_study_and_is_fitted(monkeypatch):
    monkeypatch.setattr(laws, "LAWS", dict(laws.LAWS))  # the class below registers itself for this test only

    class Triangular(FrictionLaw):
        law = "triangular"
        parameters = ("low", "mode", "high")

        def __init__(self, low, mode, high, provenance=None):
            super().__init__({"low": low, "mode": mode, "high": high}, provenance)

        def _distribution(self):
            low, mode, high = (self.params[key] for key in self.parameters)
            return stats.triang((mode - low) / (high - low), loc=low, scale=high - low)

        @classmethod
        def maximum_likelihood(cls, mu):
            c, loc, scale = stats.triang.fit(mu)
            return stats.triang(c, loc, scale), {"low": loc, "mode": loc + c * scale, "high": loc + scale}

    spec = {"law": "triangular", "low": 0.09, "mode": 0.1, "high": 0.14}
    study = load_study(axis_study(friction=spec))
    (model,) = joint_models(study, load_robot(study))
    assert model.friction == Triangular(0.09, 0.1, 0.14)
    assert model.friction.describe()["mean"] == pytest.approx((0.09 + 0.1 + 0.14) / 3)
    with pytest.raises(InputError, match="law 'triangular' needs high") as error:
        law_from_spec({"law": "triangular", "low": 0.09, "mode": 0.1}, "s.toml", "joints.friction")
    assert error.value.key == "joints.friction.high"
    mu = model.friction.rvs(size=2000, random_state=np.random.default_rng(0))
    fit = next(f for f in fitting.fit_laws(mu) if f.law == "triangular")
    assert type(fit.to_law()) is Triangular and fit.params["mode"] == pytest.approx(0.1, abs=0.01)


@pytest.mark.parametrize("mean, std", [(0.0, 0.05), (0.02, 0.05), (0.03, 0.01), (0.1375, 0.0075), (1e-300, 1e-3),
                                       (0.5, 1e-300), (10.0, 10.0)])
def test_truncated_gaussian_closed_forms_are_scipys(mean, std):
    truncated = stats.truncnorm(a=-mean / std, b=np.inf, loc=mean, scale=std)
    with np.errstate(over="ignore"):  # scipy squares a = -mean/std: 5e299 overflows, harmlessly
        scipys = truncated.mean(), truncated.std(), truncated.pdf(mean + std)
    law = Gaussian(mean, std)
    assert (law.mean(), law.std(), law.pdf(mean + std)) == pytest.approx(scipys, rel=1e-12)
    assert law.support() == (0.0, math.inf)  # scipy's lower end, mean - std·(mean/std), may round off zero


def test_moments_and_draws_of_the_closed_form_laws_do_not_import_scipy_stats():
    """scipy.stats takes about 0.3 s to import: a map of these laws needs none of it."""
    code = ("import sys, numpy as np; from tribokin.tribology import Constant, Gaussian, Uniform, preset; "
            "laws = [Gaussian(0.1, 0.01), Gaussian(0.1, 0.0), Uniform(0.1, 0.1), Constant(0.1), "
            "preset('42CD4-treated')]; "
            "[(law.describe(), law.rvs(3, np.random.default_rng(0))) for law in laws]; "
            "assert 'scipy.stats' not in sys.modules, 'imported'; Gaussian(0.1, 0.01).pdf(0.1); "
            "assert 'scipy.stats' in sys.modules, 'never imported'")
    subprocess.run([sys.executable, "-c", code], check=True, env=os.environ | {"PYTHONPATH": os.pathsep.join(sys.path)})


def test_truncated_gaussian_moments_are_within_one_percent_of_the_parameters_from_three_std():
    law = Gaussian(0.03, 0.01)  # mean = 3 std: the docstring's bound
    assert law.mean() == pytest.approx(0.03, rel=0.01) and law.std() == pytest.approx(0.01, rel=0.01)
    assert law.std() != pytest.approx(0.01, rel=1e-3)  # truncated: not the parameter itself
    assert Gaussian(0.01, 0.01).mean() != pytest.approx(0.01, rel=0.01)  # nearer zero the bound does not hold
