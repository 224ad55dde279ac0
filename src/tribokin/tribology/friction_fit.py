"""Friction laws fitted to a tribometer log (``tribokin fit-friction``): the steady state's maximum-likelihood fits,
ranked by AIC, its lag-one autocorrelation and test of independence, and the running-in curve
(:mod:`~tribokin.tribology.series_fit`), as a :class:`FrictionFitResult` that writes ``law.toml``, ``fit.json`` and
its figures."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from tribokin.errors import InputError, LawError
from tribokin.output.dispatch import write_folder
from tribokin.tribology.columns import quiet_numerics
from tribokin.tribology.fitting import Fit, fit_laws
from tribokin.tribology.laws import LAWS, MU_MIN
from tribokin.tribology.series_fit import Estimate, LjungBox, RunInFit, fit_ar1, fit_run_in, ljung_box
from tribokin.tribology.tribometer import TribometerLog, read_log, steady_state

#: What ``fit.json`` says of its fits.
FIT_NOTE = "maximum-likelihood fits ranked by AIC; KS p-values are optimistic (parameters fitted to the same data)"


def _toml_number(value: float) -> str:
    return repr(float(f"{value:.6g}"))


def _toml_value(value) -> str:
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{key} = {_toml_value(v)}" for key, v in value.items()) + " }"
    return _toml_number(value)


def inline_law(fit: Fit, time_keys: dict | None = None) -> str:
    """The fitted law as a study-file inline table, e.g. ``{ law = "gaussian", mean = 0.1375, std = 0.0075 }``,
    followed by its ``time_keys`` (``ar1 = 0.8``, ``run_in = { start = ..., tau_cycles = ... }``)."""
    keys = [f"{key} = {_toml_number(fit.params[key])}" for key in LAWS[fit.law].parameters]
    keys += [f"{key} = {_toml_value(value)}" for key, value in (time_keys or {}).items()]
    return f'{{ law = "{fit.law}", {", ".join(keys)} }}'


@dataclass(frozen=True, eq=False)
class FrictionFitResult:
    """The laws fitted to a tribometer log's steady state.

    Attributes:
        log: the log's file, as given.
        cycle: every cycle's number [-].
        mu: every cycle's friction coefficient [-].
        running_in_cycles: cycles trimmed at the start.
        running_in: how their count was set, ``"given"`` or ``"detected"``.
        fits: the maximum-likelihood fits, best (lowest AIC) first.
        ar1: the steady cycles' lag-one autocorrelation, with its 95 % interval (Bartlett's, for an AR(1)).
        ljung_box: the steady cycles' Ljung-Box test of independence.
        run_in_fit: the running-in curve fitted with AR(1) errors to the whole log (``None``: no cycle trimmed).
    """

    log: str
    cycle: np.ndarray
    mu: np.ndarray
    running_in_cycles: int
    running_in: str
    fits: tuple[Fit, ...]
    ar1: Estimate | None = None
    ljung_box: LjungBox | None = None
    run_in_fit: RunInFit | None = None

    @property
    def steady(self) -> np.ndarray:
        """The steady state's friction coefficients [-]: the cycles after the running-in."""
        return self.mu[self.running_in_cycles:]

    @property
    def chosen(self) -> Fit:
        """The best fit (lowest AIC)."""
        return self.fits[0]

    @property
    def time_keys(self) -> dict:
        """The time keys the log supports: ``ar1`` when its steady cycles are not consistent with independence
        (Ljung-Box, 5 %), ``run_in`` when the fitted start differs from the steady mean beyond its interval; empty
        when neither applies."""
        keys = {}
        if self.ljung_box is not None and not self.ljung_box.independent:
            keys["ar1"] = self.ar1.value
        if self.run_in_fit is not None and self.run_in_fit.significant:
            keys["run_in"] = {"start": self.run_in_fit.start.value, "tau_cycles": self.run_in_fit.tau_cycles.value}
        return keys

    @property
    def inline(self) -> str:
        """The chosen law and its time keys as a study-file inline table (:func:`inline_law`)."""
        return inline_law(self.chosen, self.time_keys)

    @property
    def name(self) -> str:
        """The log's file name, which the law's provenance and the figures' titles give."""
        return Path(self.log).name

    def law_toml(self) -> str:
        """``law.toml``: the chosen law as TOML keys, with provenance and the AIC table as comments."""
        provenance = (f"{self.name}, {self.steady.size} cycles after {self.running_in_cycles} running-in cycles "
                      f"({self.running_in})")
        lines = [f"# Friction law written by `tribokin fit-friction`: {provenance}.",
                 "# Maximum-likelihood fits ranked by AIC (lowest first). KS p-values are optimistic:",
                 "# the parameters were fitted to the same data.",
                 *(f"#   {f.law:<10} AIC = {f.aic:12.2f}   KS p = {f.ks_pvalue:.3g}   "
                   + ", ".join(f"{k} = {_toml_number(v)}" for k, v in f.params.items()) for f in self.fits),
                 *self._time_key_comments(),
                 '# Use it in a study: friction = { file = "law.toml" } (path relative to the study file).',
                 f'law = "{self.chosen.law}"',
                 *(f"{key} = {_toml_number(self.chosen.params[key])}" for key in LAWS[self.chosen.law].parameters)]
        return "\n".join(lines) + "\n"

    def _time_key_comments(self) -> list[str]:
        """``law.toml``'s lines on the time keys the log supports (none when none applies), as comments: a law file
        holds the law alone, and a study gives the time keys beside it (``friction = { file = "law.toml", ar1 = ...
        }``)."""
        keys = self.time_keys
        if not keys:
            return []
        box, ar1, run_in = self.ljung_box, self.ar1, self.run_in_fit
        lines = ["# Time keys the log supports; a study gives them beside this file, e.g.",
                 '# friction = { file = "law.toml", ar1 = ... } (a law file holds the law alone):']
        if "ar1" in keys:
            lines.append(f"#   ar1 = {_toml_number(ar1.value)}   95 % {ar1.low:.3g} to {ar1.high:.3g}; Ljung-Box Q = "
                         f"{box.q:.4g} over {box.lags} lags, p = {box.pvalue:.3g}: not independent")
        if "run_in" in keys:
            lines.append(f"#   run_in = {_toml_value(keys['run_in'])}   95 %: start {run_in.start.low:.4g} to "
                         f"{run_in.start.high:.4g}, tau {run_in.tau_cycles.low:.3g} to {run_in.tau_cycles.high:.3g} "
                         f"cycles (AR(1) noise, phi = {run_in.noise_ar1:.3g})")
        return lines

    def summary(self) -> dict:
        """The content of ``fit.json``."""
        steady = self.steady
        return {"log": self.log, "cycles": int(self.mu.size), "running_in_cycles": self.running_in_cycles,
                "running_in": self.running_in, "steady_cycles": int(steady.size), "mean": float(steady.mean()),
                "std": float(steady.std(ddof=1)), "chosen": self.chosen.law, "inline": self.inline,
                "fits": [{"law": f.law, **f.params, "log_likelihood": f.log_likelihood, "aic": f.aic,
                          "ks_pvalue": f.ks_pvalue} for f in self.fits],
                "note": FIT_NOTE,
                "ar1": None if self.ar1 is None else asdict(self.ar1),
                "ljung_box": None if self.ljung_box is None else {**asdict(self.ljung_box),
                                                                  "independent": self.ljung_box.independent},
                "run_in_fit": None if self.run_in_fit is None else self.run_in_fit.summary(),
                "time_keys": self.time_keys}

    def to_pandas(self):
        """The fits as a pandas DataFrame, one row per law, best first: ``law``, its parameters, ``log_likelihood``,
        ``aic``, ``ks_pvalue`` (``fit.json``'s ``fits``; pandas: ``pip install 'tribokin[data]'``)."""
        from tribokin.errors import import_extra

        return import_extra("pandas", "to_pandas()").DataFrame(self.summary()["fits"])

    def write(self, folder, force: bool = False) -> Path:
        """Write the files ``tribokin fit-friction`` writes into ``folder`` (``law.toml``, ``fit.json``,
        ``mu_cycles.png``, ``mu_histogram.png``): all at once, its lock held, refused
        (:class:`~tribokin.errors.InputError`) if it exists, unless ``force``.

        Returns:
            the folder written.
        """
        return write_folder(self, folder, force)  # output.tribology.write_friction_fit


def fit_friction(log, running_in: int | None = None) -> FrictionFitResult:
    """Fit friction laws to a tribometer log's steady state.

    Args:
        log: a :class:`~tribokin.tribology.tribometer.TribometerLog` or its file (``cycle, mu`` or
            ``friction_force_N, normal_force_N``).
        running_in: cycles to trim at the start (``None``: detected).

    Returns:
        the fits, best first, the steady cycles' lag-one autocorrelation and Ljung-Box test, the running-in fitted
        with AR(1) errors when cycles were trimmed, and the log they came from.
    """
    log = log if isinstance(log, TribometerLog) else read_log(log)
    mu, trimmed = steady_state(log, running_in)
    fits = _checked_fits(mu, log.source)
    return FrictionFitResult(log.source, log.cycle, log.mu, trimmed, "given" if running_in is not None else "detected",
                             tuple(fits), fit_ar1(mu), ljung_box(mu),
                             fit_run_in(log.cycle, log.mu) if trimmed > 0 else None)


def _checked_fits(mu: np.ndarray, source: str) -> list[Fit]:
    """``fit_laws(mu)``, each fit finite and a valid law, else an error naming the log's ``mu``."""
    if mu.mean() < MU_MIN:
        raise InputError(f"the steady-state mean mu is {mu.mean():g}, below {MU_MIN:g}: no sliding contact "
                         "has so little friction; check the units", source, "mu")
    if np.ptp(mu) == 0:
        raise InputError(f"every steady-state cycle has mu = {mu[0]:g}: there is no spread to fit; use "
                         f'{{ law = "constant", mu = {mu[0]:g} }}', source, "mu")
    with quiet_numerics():
        fits = fit_laws(mu)
    for fit in fits:
        try:
            if not all(math.isfinite(v) for v in [*fit.params.values(), fit.aic]):
                raise LawError(f"parameters {fit.params}, AIC {fit.aic}", fit.law)
            fit.to_law()
        except LawError as error:
            raise InputError(f"the {fit.law} fit to the {mu.size} steady-state cycles is not a valid law "
                             f"({error.parameter}: {error.message}); check the values", source, "mu") from None
    return fits
