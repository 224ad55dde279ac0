"""Maximum-likelihood fits of friction laws to measured mu, ranked by AIC.

Normal, lognormal (location fixed at 0) and uniform laws are fitted with
``scipy.stats`` ``fit`` (maximum likelihood). AIC = 2k - 2 ln L ranks them
(lowest first). The Kolmogorov-Smirnov p-value of each fit is reported, but
it is optimistic: the parameters were fitted to the same data, so the
standard KS distribution overstates p (Lilliefors).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import stats

from tribokin.tribology.laws import FrictionLaw, Gaussian, Lognormal, Uniform


@dataclass(frozen=True)
class Fit:
    """One fitted law: name as in study files, its parameters, log-likelihood, AIC, KS p-value."""

    law: str
    params: dict
    log_likelihood: float
    aic: float
    ks_pvalue: float

    def to_law(self, provenance: str | None = None) -> FrictionLaw:
        """The fitted law as a tribokin friction law."""
        return {"gaussian": Gaussian, "lognormal": Lognormal, "uniform": Uniform}[self.law](**self.params,
                                                                                            provenance=provenance)


def _frozen_normal(x):
    loc, scale = stats.norm.fit(x)
    return stats.norm(loc, scale), {"mean": float(loc), "std": float(scale)}


def _frozen_lognormal(x):
    s, _, scale = stats.lognorm.fit(x, floc=0)
    mean = scale * math.exp(s * s / 2)
    return stats.lognorm(s, 0, scale), {"mean": float(mean), "std": float(mean * math.sqrt(math.expm1(s * s)))}


def _frozen_uniform(x):
    loc, scale = stats.uniform.fit(x)
    return stats.uniform(loc, scale), {"low": float(loc), "high": float(loc + scale)}


# law name -> (fitter returning a frozen scipy distribution and the law's parameters, number of parameters)
FITTERS = {"gaussian": (_frozen_normal, 2), "lognormal": (_frozen_lognormal, 2), "uniform": (_frozen_uniform, 2)}


def fit_laws(mu) -> list[Fit]:
    """Fit every law of ``FITTERS`` to the friction coefficients ``mu`` [-]; best (lowest AIC) first.

    The Gaussian parameters are those of the untruncated normal fit (tribokin
    truncates it at mu = 0, which changes nothing when mean >> std).
    """
    mu = np.asarray(mu, dtype=float)
    fits = []
    for name, (fitter, k) in FITTERS.items():
        if name == "lognormal" and np.any(mu <= 0):
            continue
        dist, params = fitter(mu)
        log_likelihood = float(np.sum(dist.logpdf(mu)))
        fits.append(Fit(name, params, log_likelihood, 2 * k - 2 * log_likelihood,
                        float(stats.kstest(mu, dist.cdf).pvalue)))
    return sorted(fits, key=lambda fit: fit.aic)
