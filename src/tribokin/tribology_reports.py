"""Measurement files -> friction laws and reports on disk (``tribokin fit-friction`` and ``tribokin surface``).

Each command reads its file, computes, then writes its output folder all at
once with :func:`tribokin.output.writers.atomic_folder` (nothing is written on error).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from tribokin.checks import positive, within
from tribokin.errors import InputError, LawError
from tribokin.output.folder import atomic_folder, check_output_folder
from tribokin.tribology.columns import quiet_numerics
from tribokin.tribology.fitting import Fit, fit_laws
from tribokin.tribology.laws import LAWS, MU_MIN
from tribokin.tribology.surfaces import find_peaks, level, profile_statistics, read_profile
from tribokin.tribology.tribometer import read_log, steady_state


def _toml_number(value: float) -> str:
    return repr(float(f"{value:.6g}"))


def inline_law(fit: Fit) -> str:
    """The fitted law as a study-file inline table, e.g. ``{ law = "gaussian", mean = 0.1375, std = 0.0075 }``."""
    keys = ", ".join(f"{key} = {_toml_number(fit.params[key])}" for key in LAWS[fit.law].parameters)
    return f'{{ law = "{fit.law}", {keys} }}'


def law_toml(fit: Fit, fits: list[Fit], provenance: str) -> str:
    """``law.toml``: the chosen law as TOML keys, with provenance and the AIC table as comments."""
    lines = [f"# Friction law written by `tribokin fit-friction`: {provenance}.",
             "# Maximum-likelihood fits ranked by AIC (lowest first). KS p-values are optimistic:",
             "# the parameters were fitted to the same data.",
             *(f"#   {f.law:<10} AIC = {f.aic:12.2f}   KS p = {f.ks_pvalue:.3g}   "
               + ", ".join(f"{k} = {_toml_number(v)}" for k, v in f.params.items()) for f in fits),
             '# Use it in a study: friction = { file = "law.toml" } (path relative to the study file).',
             f'law = "{fit.law}"',
             *(f"{key} = {_toml_number(fit.params[key])}" for key in LAWS[fit.law].parameters)]
    return "\n".join(lines) + "\n"


def fit_friction(log_path, out, running_in: int | None = None, force: bool = False) -> dict:
    """Fit friction laws to a tribometer log and write law.toml, fit.json, mu_cycles.png, mu_histogram.png.

    Returns the content of fit.json.
    """
    from tribokin.viz.tribology import save_mu_histogram, save_mu_per_cycle

    check_output_folder(out, force)
    log = read_log(log_path)
    mu, trimmed = steady_state(log, running_in)
    fits = _checked_fits(mu, log.source)
    how = "given" if running_in is not None else "detected"
    provenance = f"{Path(log_path).name}, {mu.size} cycles after {trimmed} running-in cycles ({how})"
    report = {"log": str(log_path), "cycles": int(log.mu.size), "running_in_cycles": trimmed,
              "running_in": how, "steady_cycles": int(mu.size), "mean": float(mu.mean()), "std": float(mu.std(ddof=1)),
              "chosen": fits[0].law, "inline": inline_law(fits[0]),
              "fits": [{"law": f.law, **f.params, "log_likelihood": f.log_likelihood, "aic": f.aic,
                        "ks_pvalue": f.ks_pvalue} for f in fits],
              "note": "maximum-likelihood fits ranked by AIC; KS p-values are optimistic (parameters fitted to the "
                      "same data)"}
    with atomic_folder(out, force) as folder:
        (folder / "law.toml").write_text(law_toml(fits[0], fits, provenance), encoding="utf-8")
        (folder / "fit.json").write_text(json.dumps(report, indent=2) + "\n", encoding="utf-8")
        save_mu_per_cycle(log.cycle, log.mu, trimmed, folder / "mu_cycles.png", f"{Path(log_path).name}")
        save_mu_histogram(mu, fits, folder / "mu_histogram.png", f"{Path(log_path).name}: steady state")
    return report


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


area = within(positive, 1e-12, 1.0, "m²", "eq. (6) counts summits on a square micrometre (a summit or two) up to a "
              "square metre (a whole plate)")
#: Largest finite end of the eq. (6) ranges [m]: summit heights and radii are far below a metre.
RANGE_LIMIT_M = 1.0


def _check_surface_options(area_m2, z_range_m, radius_range_m):
    """The options of ``tribokin surface``, checked: A_a in ``area``'s range, each range [low, high] with
    low <= high, finite ends within ±``RANGE_LIMIT_M``, radii >= 0 (either end of a range may be infinite)."""
    area_m2 = area(area_m2, "command line", "--area-m2")
    ranges = []
    for key, bounds in (("--z-range-m", z_range_m), ("--radius-range-m", radius_range_m)):
        low, high = (_bound(value, f"{key}[{i}]") for i, value in enumerate(bounds))
        if not low <= high:
            raise InputError(f"must be low high with low <= high (got {low:g} {high:g})", "command line", key)
        ranges.append((low, high))
    if ranges[1][0] < 0:
        raise InputError(f"radii must be >= 0 (got {ranges[1][0]:g})", "command line", "--radius-range-m")
    return area_m2, ranges[0], ranges[1]


def _bound(value, key: str) -> float:
    if isinstance(value, float) and math.isnan(value):
        raise InputError("must be a number or an infinity, not nan", "command line", key)
    if math.isfinite(value) and abs(value) > RANGE_LIMIT_M:
        raise InputError(f"must be within ±{RANGE_LIMIT_M:g} m, or an infinity (got {value:g}): summit heights and "
                         "radii are far below a metre; write inf for no bound", "command line", key)
    return float(value)


def surface_report(profile_path, out, area_m2: float = 1e-6, z_range_m=(-np.inf, np.inf),
                   radius_range_m=(0.0, np.inf), force: bool = False) -> dict:
    """Asperity statistics of a profile and eq. (6)'s count; writes surface.json, profile.png, p_z_R.png.

    Returns the content of surface.json.
    """
    from tribokin.viz.tribology import save_asperity_density, save_profile

    check_output_folder(out, force)
    area_m2, z_range_m, radius_range_m = _check_surface_options(area_m2, z_range_m, radius_range_m)
    surface = profile_statistics(profile_path)
    x, z = read_profile(profile_path)
    levelled = level(x, z)
    count = surface.asperity_count(area_m2, z_range_m, radius_range_m)
    finite = lambda pair: [float(v) if np.isfinite(v) else None for v in pair]  # noqa: E731 (JSON has no inf)
    report = {**surface.summary(),
              "AR_definition": "mean spacing of consecutive local maxima (1 / profile peak density), not ISO 12085 "
                               "motifs",
              "radius_definition": "R* = R / 1 µm, ln R* ~ N(b, a^2) (eq. 2)",
              "asperity_count": {"area_m2": area_m2, "z_range_m": finite(z_range_m),
                                 "radius_range_m": finite(radius_range_m), "count": count}}
    with atomic_folder(out, force) as folder:
        (folder / "surface.json").write_text(json.dumps(report, indent=2) + "\n", encoding="utf-8")
        save_profile(x, levelled, find_peaks(levelled), folder / "profile.png", Path(profile_path).name)
        save_asperity_density(surface, folder / "p_z_R.png", f"{Path(profile_path).name}: p(z, R)")
    return report
