"""Maximum-likelihood fits recover the generating law and AIC picks it."""

import numpy as np
import pytest
from scipy import stats

from tribokin.tribology.fitting import fit_laws

N = 20_000


def samples(name, seed=0):
    rng = np.random.default_rng(seed)
    return {"gaussian": lambda: rng.normal(0.1375, 0.0075, N),
            "lognormal": lambda: rng.lognormal(np.log(0.12), 0.3, N),
            "uniform": lambda: rng.uniform(0.09, 0.16, N)}[name]()


@pytest.mark.parametrize("name", ["gaussian", "lognormal", "uniform"])
def test_aic_picks_the_generating_law(name):
    fits = fit_laws(samples(name))
    assert fits[0].law == name
    assert [f.aic for f in fits] == sorted(f.aic for f in fits)
    assert fits[0].ks_pvalue > 1e-3


def test_parameters_recovered():
    by_law = {f.law: f for f in fit_laws(samples("gaussian"))}
    assert by_law["gaussian"].params["mean"] == pytest.approx(0.1375, abs=4 * 0.0075 / np.sqrt(N))
    assert by_law["gaussian"].params["std"] == pytest.approx(0.0075, rel=0.02)
    by_law = {f.law: f for f in fit_laws(samples("uniform"))}
    assert by_law["uniform"].params["low"] == pytest.approx(0.09, abs=1e-4)
    assert by_law["uniform"].params["high"] == pytest.approx(0.16, abs=1e-4)
    lognormal = {f.law: f for f in fit_laws(samples("lognormal"))}["lognormal"]
    exact = stats.lognorm(0.3, 0, 0.12)       # mean and std of mu itself
    assert lognormal.params["mean"] == pytest.approx(exact.mean(), rel=0.01)
    assert lognormal.params["std"] == pytest.approx(exact.std(), rel=0.03)
    law = lognormal.to_law()
    assert law.mean() == pytest.approx(lognormal.params["mean"])


def test_aic_is_two_k_minus_two_log_likelihood():
    x = samples("gaussian")[:500]
    gauss = {f.law: f for f in fit_laws(x)}["gaussian"]
    assert gauss.aic == pytest.approx(4 - 2 * np.sum(stats.norm.logpdf(x, x.mean(), x.std())))
