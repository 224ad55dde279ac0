"""Friction-coefficient laws: the cycle-to-cycle statistics of mu.

Each law has the shape of a frozen ``scipy.stats`` distribution --
``rvs(size, random_state)``, ``mean()``, ``std()``, ``support()``, ``pdf(x)``
-- so users need no new vocabulary; most delegate to ``scipy.stats``, made on first use (see :func:`_stats`).
Friction coefficients are dimensionless, never negative and at most ``MU_MAX``.

Every subclass that names its ``law`` is registered in ``LAWS`` as it is defined: study files
(``{ law = "<name>", <parameters> }``), ``describe()``, fitting (when it defines ``maximum_likelihood``)
and ``tribokin fit-friction``'s law files find it there, so a new law is one class.
"""

from __future__ import annotations

import math
import numbers

import numpy as np

from tribokin.checks import finite, within
from tribokin.errors import InputError, LawError

#: Largest friction coefficient a law may hold [-]: above, it is not sliding friction (clean metals in
#: vacuum reach a few).
MU_MAX = 10.0
#: Smallest friction coefficient [-] where a law needs one above zero (a lognormal's mean): no sliding contact has
#: less friction (superlubric ones reach about 1e-4).
MU_MIN = 1e-6


#: A friction coefficient: a finite number in [0, ``MU_MAX``].
coefficient = within(finite, 0.0, MU_MAX, "",
                     f"friction coefficients are never negative, and above {MU_MAX:g} they are "
                     "not sliding friction (clean metals in vacuum reach a few)")


def _check_coefficient(**values: float) -> None:
    """Each value a friction coefficient (:data:`coefficient`), else a :class:`LawError` naming it."""
    for key, value in values.items():
        try:
            coefficient(value, None, key)
        except InputError as error:
            raise LawError(error.message, key) from None


def _stats():
    """``scipy.stats``, imported when a law first needs its distribution (a density, a fit, or a moment without a
    closed form here): the import (``benchmarks/startup.py`` times it) falls in the serial start of a map command, and
    a map of a Gaussian or constant law needs none of these."""
    from scipy import stats
    return stats


#: Every friction law by the name study files give it, in the order the classes are defined.
LAWS: dict[str, type[FrictionLaw]] = {}


class FrictionLaw:
    """Base class: a law of the friction coefficient mu [-].

    Subclasses set ``law`` (the name in study files; a subclass that sets it is registered in ``LAWS``) and
    ``parameters`` (the keys a study file gives, in the order of the constructor's arguments), pass ``params`` and,
    for a law of zero width, ``value`` (every draw); the others make their frozen scipy distribution in
    :meth:`_distribution`, called on first use. They may draw faster than scipy in :meth:`_draw`; ``provenance``
    says where the numbers come from. A law that can be fitted to measured mu defines ``maximum_likelihood``.
    """

    law: str = ""
    parameters: tuple[str, ...] = ()
    #: What the law draws: ``"mu"``, or the study key of a friction torque [N·m] or force [N] (:class:`Scaled`).
    quantity: str = "mu"

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        if cls.law:
            LAWS[cls.law] = cls

    @classmethod
    def maximum_likelihood(cls, mu: np.ndarray):
        """(frozen scipy distribution, the law's parameters) fitted to the friction coefficients ``mu`` [-] by
        maximum likelihood, or ``None`` when the law is not fitted (this base: never) or cannot fit ``mu``."""
        return None

    def __init__(self, params: dict, provenance: str | None = None, value: float | None = None):
        self._value = value
        self.params = params
        self.provenance = provenance
        self._known = {}  # moments and support, computed once (scipy's cost far more than a lookup)

    def _once(self, name: str, compute):
        if name not in self._known:
            self._known[name] = compute()
        return self._known[name]

    def _distribution(self):
        """The law's frozen scipy distribution (laws of zero width have none)."""
        raise NotImplementedError

    @property
    def _dist(self):
        """:meth:`_distribution`, made once; ``None`` for a law of zero width."""
        return None if self._value is not None else self._once("dist", self._distribution)

    def rvs(self, size=None, random_state: np.random.Generator | None = None) -> np.ndarray:
        """Draw friction coefficients [-] with a NumPy generator."""
        if self._value is not None:
            return np.full(size if size is not None else (), self._value)
        return self._draw(size, np.random.default_rng(random_state))

    def _draw(self, size, rng: np.random.Generator) -> np.ndarray:
        return self._dist.rvs(size=size, random_state=rng)

    def mean(self) -> float:
        """Mean friction coefficient [-]."""
        return self._value if self._value is not None else self._once("mean", lambda: float(self._dist.mean()))

    def std(self) -> float:
        """Standard deviation of the friction coefficient [-]."""
        return 0.0 if self._value is not None else self._once("std", lambda: float(self._dist.std()))

    def support(self) -> tuple[float, float]:
        """Smallest and largest possible friction coefficient [-]."""
        if self._value is not None:
            return self._value, self._value
        low, high = self._once("support", self._dist.support)
        return max(float(low), 0.0), float(high)

    def pdf(self, x) -> np.ndarray:
        """Probability density at ``x`` [1/-] (a law of zero width: infinite at its value, zero elsewhere)."""
        if self._value is not None:
            return np.where(np.asarray(x) == self._value, np.inf, 0.0)
        return self._dist.pdf(x)

    def describe(self) -> dict:
        """Law name, parameters, moments and provenance, for reports."""
        return {
            "law": self.law,
            **self.params,
            "mean": self.mean(),
            "std": self.std(),
            "support": list(self.support()),
            "provenance": self.provenance,
        }

    def __eq__(self, other) -> bool:
        """Same law with the same parameters (provenance aside)."""
        return type(other) is type(self) and other.params == self.params

    __hash__ = None  # parameters may hold lists

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self.params.items() if k != "values")
        return f"{type(self).__name__}({args})"


class Constant(FrictionLaw):
    """The same mu every cycle (the paper's Fig. 11 uses mu = 0.12, Fig. 10 mu = 0)."""

    law = "constant"
    parameters = ("mu",)

    def __init__(self, mu: float, provenance: str | None = None):
        _check_coefficient(mu=mu)
        super().__init__({"mu": float(mu)}, provenance, value=float(mu))


class Uniform(FrictionLaw):
    """mu uniform on [low, high]: grease-dominated contacts (paper §4.2)."""

    law = "uniform"
    parameters = ("low", "high")

    def __init__(self, low: float, high: float, provenance: str | None = None):
        _check_coefficient(low=low, high=high)
        if low > high:
            raise LawError(f"low ({low}) is above high ({high}): swap them", "low")
        super().__init__({"low": float(low), "high": float(high)}, provenance,
                         value=None if high > low else float(low))

    def _distribution(self):
        return _stats().uniform(loc=self.params["low"], scale=self.params["high"] - self.params["low"])

    def _draw(self, size, rng: np.random.Generator) -> np.ndarray:
        return rng.uniform(self.params["low"], self.params["high"], size)

    @classmethod
    def maximum_likelihood(cls, mu: np.ndarray):
        stats = _stats()
        loc, scale = stats.uniform.fit(mu)
        return stats.uniform(loc, scale), {"low": float(loc), "high": float(loc + scale)}


class Gaussian(FrictionLaw):
    """mu Gaussian with ``mean`` and ``std``, truncated at mu = 0.

    Friction cannot be negative, so the normal law is truncated at zero
    (``scipy.stats.truncnorm``); ``mean()`` and ``std()`` are those of the
    truncated law, within 1 % of the parameters when ``mean`` >= 3 ``std``,
    in closed form. Asperity-dominated contacts (paper §4.2).
    """

    law = "gaussian"
    parameters = ("mean", "std")

    def __init__(self, mean: float, std: float, provenance: str | None = None):
        _check_coefficient(mean=mean, std=std)
        super().__init__({"mean": float(mean), "std": float(std)}, provenance, value=None if std > 0 else float(mean))

    def _distribution(self):
        mean, std = self.params["mean"], self.params["std"]
        return _stats().truncnorm(a=-mean / std, b=np.inf, loc=mean, scale=std)

    def _standard_moments(self) -> tuple[float, float]:
        """Mean and variance of the standard normal truncated below at a = -mean/std <= 0: lambda and
        1 + lambda (a - lambda), lambda = phi(a) / (1 - Phi(a)), the formulas ``scipy.stats.truncnorm`` evaluates."""
        a = -self.params["mean"] / self.params["std"]
        hazard = math.exp(-0.5 * a * a) / math.sqrt(2 * math.pi) / (0.5 * math.erfc(a / math.sqrt(2)))  # Phi(-a)
        return hazard, 1.0 + hazard * (a - hazard)

    def mean(self) -> float:
        if self._value is not None:
            return self._value
        return self.params["mean"] + self.params["std"] * self._standard_moments()[0]

    def std(self) -> float:
        if self._value is not None:
            return 0.0
        return self.params["std"] * math.sqrt(self._standard_moments()[1])

    def support(self) -> tuple[float, float]:
        return (self._value, self._value) if self._value is not None else (0.0, math.inf)

    def _draw(self, size, rng: np.random.Generator) -> np.ndarray:
        """Normal draws, each negative one drawn again: exactly the truncated law, and since
        ``mean >= 0`` at least half of the draws are kept (far faster than inverting its cdf)."""
        mean, std = self.params["mean"], self.params["std"]
        mu = np.asarray(rng.normal(mean, std, size), dtype=float)
        rejected = np.flatnonzero(mu < 0)
        while rejected.size:
            mu.flat[rejected] = rng.normal(mean, std, rejected.size)
            rejected = rejected[mu.flat[rejected] < 0]
        return mu

    @classmethod
    def maximum_likelihood(cls, mu: np.ndarray):
        """The untruncated normal fit (the law truncates it at mu = 0, which changes nothing when mean >> std)."""
        stats = _stats()
        loc, scale = stats.norm.fit(mu)
        return stats.norm(loc, scale), {"mean": float(loc), "std": float(scale)}


class Lognormal(FrictionLaw):
    """mu lognormal with the given ``mean`` and ``std`` of mu itself (not of log mu)."""

    law = "lognormal"
    parameters = ("mean", "std")

    def __init__(self, mean: float, std: float, provenance: str | None = None):
        _check_coefficient(mean=mean, std=std)
        if mean < MU_MIN:
            raise LawError(f"must be > 0, at least {MU_MIN:g}, for a lognormal law (got {mean}): "
                           "no sliding contact has less friction (superlubric ones reach about 1e-4)", "mean")
        sigma_log = math.sqrt(math.log1p((std / mean) ** 2))
        median = mean / math.sqrt(1 + (std / mean) ** 2)
        super().__init__({"mean": float(mean), "std": float(std)}, provenance, value=None if std > 0 else float(mean))
        self._median, self._sigma_log = median, sigma_log

    def _distribution(self):
        return _stats().lognorm(s=self._sigma_log, scale=self._median)

    def _draw(self, size, rng: np.random.Generator) -> np.ndarray:
        return rng.lognormal(math.log(self._median), self._sigma_log, size)

    @classmethod
    def maximum_likelihood(cls, mu: np.ndarray):
        """Location fixed at 0; ``None`` when a value is <= 0 (outside the law's support)."""
        if np.any(mu <= 0):
            return None
        stats = _stats()
        s, _, scale = stats.lognorm.fit(mu, floc=0)
        mean = scale * math.exp(s * s / 2)
        return stats.lognorm(s, 0, scale), {"mean": float(mean), "std": float(mean * math.sqrt(math.expm1(s * s)))}


class Empirical(FrictionLaw):
    """Resamples measured friction coefficients (bootstrap, with replacement).

    ``mean()``/``std()`` are those of the values (population std), the
    support is their range and ``pdf`` a histogram density.
    """

    law = "empirical"
    parameters = ("values",)

    def __init__(self, values, provenance: str | None = None):
        if not isinstance(values, np.ndarray) and (not isinstance(values, (list, tuple)) or any(
                isinstance(v, bool) or not isinstance(v, numbers.Real) for v in values)):
            raise LawError(f"must be a list of numbers (got {values!r})", "values")
        try:
            values = np.asarray(values, dtype=float).ravel()
        except (ValueError, OverflowError):  # a ragged list, a whole number past 1e308
            raise LawError("must be a list of numbers", "values") from None
        if values.size < 2:
            raise LawError(f"needs at least 2 measured values (got {values.size})", "values")
        if not np.all(np.isfinite(values)):
            raise LawError("must all be finite numbers", "values")
        _check_coefficient(values=float(values.min()))
        _check_coefficient(values=float(values.max()))
        self.values = values
        super().__init__({"values": values.tolist()}, provenance)

    def _distribution(self):
        return _stats().rv_histogram(np.histogram(self.values, bins="auto"), density=True)

    def _draw(self, size, rng: np.random.Generator) -> np.ndarray:
        return rng.choice(self.values, size=size, replace=True)

    def mean(self) -> float:
        return float(self.values.mean())

    def std(self) -> float:
        return float(self.values.std())

    def support(self) -> tuple[float, float]:
        return float(self.values.min()), float(self.values.max())

    def describe(self) -> dict:
        described = super().describe()
        described["values"] = f"{self.values.size} measured values"
        return described


class Scaled(FrictionLaw):
    """``scale`` times the draws of ``law``: a law of a friction torque [N·m] or force [N] (``quantity`` names which)
    held as a law of values within a friction coefficient's range; a power-of-two ``scale`` keeps it exact."""

    def __init__(self, law: FrictionLaw, scale: float, quantity: str):
        self.inner, self.scale, self.quantity, self.law = law, float(scale), quantity, law.law
        super().__init__({"value" if k == "mu" else k: np.multiply(v, scale).tolist()
                                for k, v in law.params.items()}, law.provenance)

    def __eq__(self, other) -> bool:
        """The same law scaled alike (a gaussian and a lognormal of the same numbers are not the same law)."""
        return type(other) is type(self) and (other.inner, other.scale) == (self.inner, self.scale)

    def rvs(self, size=None, random_state: np.random.Generator | None = None) -> np.ndarray:
        return self.scale * self.inner.rvs(size, random_state)

    def mean(self) -> float:
        return self.scale * self.inner.mean()

    def std(self) -> float:
        return self.scale * self.inner.std()

    def support(self) -> tuple[float, float]:
        low, high = self.inner.support()
        return self.scale * low, self.scale * high

    def pdf(self, x) -> np.ndarray:
        return self.inner.pdf(np.asarray(x) / self.scale) / self.scale

    def describe(self) -> dict:
        """As the law's, with ``quantity`` first and its values scaled (a constant's ``mu`` named ``value``; measured
        values still counted, not listed)."""
        summary = {k: v for k, v in self.inner.describe().items() if k in self.params and isinstance(v, str)}
        return {"quantity": self.quantity, **super().describe(), **summary}
