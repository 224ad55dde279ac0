"""Maximum-likelihood fits of friction laws to measured mu, ranked by AIC.

Every law of ``LAWS`` that defines ``maximum_likelihood`` is fitted (normal, lognormal with location fixed
at 0, uniform: ``scipy.stats`` ``fit``). AIC = 2k - 2 ln L ranks them (lowest first), k the number of the
law's parameters. The Kolmogorov-Smirnov p-value of each fit is reported, but it is optimistic: the
parameters were fitted to the same data, so the standard KS distribution overstates p (Lilliefors).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import stats

from tribokin.tribology import laws
from tribokin.tribology.laws import FrictionLaw


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
        return laws.LAWS[self.law](**self.params, provenance=provenance)


def fit_laws(mu) -> list[Fit]:
    """Fit every law of ``LAWS`` that can be fitted to the friction coefficients ``mu`` [-]; best (lowest AIC)
    first."""
    mu = np.asarray(mu, dtype=float)
    fits = []
    for name, law in laws.LAWS.items():
        fitted = law.maximum_likelihood(mu)
        if fitted is None:
            continue
        dist, params = fitted
        log_likelihood = float(np.sum(dist.logpdf(mu)))
        fits.append(Fit(name, params, log_likelihood, 2 * len(law.parameters) - 2 * log_likelihood,
                        float(stats.kstest(mu, dist.cdf).pvalue)))
    return sorted(fits, key=lambda fit: fit.aic)
