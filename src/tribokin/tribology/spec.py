"""Friction laws from the mappings written in study files.

``{ preset = "42CD4-treated" }``, ``{ law = "gaussian", mean = 0.1375, std = 0.0075 }``,
``{ law = "uniform", low = 0.09, high = 0.16 }``, ``{ law = "constant", mu = 0.12 }``,
``{ law = "lognormal", mean = 0.12, std = 0.01 }``, ``{ law = "empirical", values = [...] }``,
``{ file = "law.toml" }`` (a law written by ``tribokin fit-friction``),
``{ log = "tribometer.csv", running_in = 50 }`` (the trimmed measured mu, resampled),
``{ surface = "profile.csv", normal_force_N = 150, contact_area_m2 = 1e-6, film_thickness_m = 1.2e-6 }``
(mu simulated cycle by cycle from the profile's asperities, see ``contact``).
File names are relative to the study file.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

from tribokin.errors import InputError, closest_hint
from tribokin.tribology.laws import Constant, Empirical, FrictionLaw, Gaussian, Lognormal, Uniform
from tribokin.tribology.presets import preset

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

LAWS = {
    "constant": (Constant, ("mu",)),
    "uniform": (Uniform, ("low", "high")),
    "gaussian": (Gaussian, ("mean", "std")),
    "lognormal": (Lognormal, ("mean", "std")),
    "empirical": (Empirical, ("values",)),
}


def _from_preset(spec: dict, base_dir: Path) -> FrictionLaw:
    _only_keys(spec, ("preset",))
    return preset(spec["preset"])


def _from_law(spec: dict, base_dir: Path) -> FrictionLaw:
    name = spec["law"]
    if name not in LAWS:
        raise InputError(f"unknown law '{name}'{closest_hint(str(name), list(LAWS))}; valid laws: {', '.join(LAWS)}",
                         key="law")
    cls, keys = LAWS[name]
    _only_keys(spec, ("law",) + keys)
    missing = [k for k in keys if k not in spec]
    if missing:
        raise InputError(f"law '{name}' needs {', '.join(missing)}", key=missing[0])
    if name == "empirical":
        _check_values(spec["values"])
    return cls(*(spec[k] for k in keys))  # checks the parameters


def _check_values(values) -> None:
    """Measured values must be a list of numbers (the law checks they are finite and >= 0)."""
    if not isinstance(values, list) or any(isinstance(v, bool) or not isinstance(v, (int, float)) for v in values):
        raise InputError(f"must be a list of numbers (got {values!r})", key="values")


def _from_file(spec: dict, base_dir: Path) -> FrictionLaw:
    _only_keys(spec, ("file",))
    path = base_dir / str(spec["file"])
    if not path.is_file():
        raise InputError(f"law file '{path}' not found; write it with `tribokin fit-friction`", key="file")
    try:
        mapping = tomllib.loads(path.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as error:
        raise InputError(f"not valid TOML: {error}", path) from None
    law = law_from_spec(mapping, path, "", path.parent)
    law.provenance = law.provenance or f"law file {path} (its comments say where it comes from)"
    return law


def _from_log(spec: dict, base_dir: Path) -> FrictionLaw:
    from tribokin.tribology.tribometer import read_log, steady_state

    _only_keys(spec, ("log", "running_in"))
    log = read_log(base_dir / str(spec["log"]))
    mu, trimmed = steady_state(log, spec.get("running_in"))
    how = "given" if "running_in" in spec else "detected"
    return Empirical(mu, provenance=f"tribometer log {log.source}: {mu.size} cycles after {trimmed} running-in "
                                    f"cycles ({how})")


SURFACE_REQUIRED = ("normal_force_N", "contact_area_m2", "film_thickness_m")
SURFACE_COUNTS = {"cycles": (1000, 1), "seed": (0, 0)}  # key -> (default, smallest value)


def _positive(spec: dict, key: str, default: float | None = None) -> float:
    value = spec.get(key, default)
    if value is None:
        raise InputError("is required for a surface friction law", key=key)
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
        raise InputError(f"must be a number > 0 (got {value!r})", key=key)
    return float(value)


def _count(spec: dict, key: str) -> int:
    default, smallest = SURFACE_COUNTS[key]
    value = spec.get(key, default)
    if isinstance(value, bool) or not isinstance(value, int) or value < smallest:
        raise InputError(f"must be a whole number >= {smallest} (got {value!r})", key=key)
    return value


def _from_surface(spec: dict, base_dir: Path) -> FrictionLaw:
    from tribokin.tribology import contact
    from tribokin.tribology.surfaces import profile_statistics

    optional = {"mu_boundary": contact.MU_BOUNDARY, "mu_film": contact.MU_FILM, "modulus_Pa": contact.STEEL_MODULUS_PA}
    _only_keys(spec, ("surface",) + SURFACE_REQUIRED + tuple(optional) + tuple(SURFACE_COUNTS))
    values = {key: _positive(spec, key) for key in SURFACE_REQUIRED}
    values.update({key: _positive(spec, key, default) for key, default in optional.items()})
    values.update({key: _count(spec, key) for key in SURFACE_COUNTS})
    surface = profile_statistics(base_dir / str(spec["surface"]))
    lubrication = contact.Lubrication(values["film_thickness_m"], values["mu_boundary"], values["mu_film"])
    mu, share = contact.friction_per_cycle(surface, values["normal_force_N"], values["contact_area_m2"], lubrication,
                                           values["cycles"], np.random.default_rng(values["seed"]),
                                           values["modulus_Pa"])
    provenance = (f"simulated from surface profile {surface.source} (D_s = {surface.summit_density_m2:.3g} 1/m^2, "
                  f"SAlt = {surface.SAlt_m:.3g} m): {values['cycles']} cycles at {values['normal_force_N']} N, "
                  f"film {values['film_thickness_m']:.3g} m, mean asperity load share {share.mean():.3f}")
    if np.ptp(mu) == 0:
        return Constant(float(mu[0]), provenance=provenance)
    return Empirical(mu, provenance=provenance)


# How a spec is recognised: the first of these keys present in it.
SPEC_KINDS = {"preset": _from_preset, "law": _from_law, "file": _from_file, "log": _from_log,
              "surface": _from_surface}


def _only_keys(spec: dict, allowed: tuple[str, ...]) -> None:
    for key in spec:
        if key not in allowed:
            raise InputError(f"unknown key '{key}'{closest_hint(key, list(allowed))}; allowed here: {', '.join(allowed)}",
                             key=key)


def law_from_spec(spec, source: str | Path | None = None, key: str = "friction",
                  base_dir: str | Path = ".") -> FrictionLaw:
    """Build the friction law a study file describes.

    Args:
        spec: the mapping, e.g. ``{"preset": "42CD4-raw"}``; a ``FrictionLaw`` passes through.
        source: file the mapping came from, for error messages.
        key: dotted key of the mapping in that file, for error messages.
        base_dir: folder that relative file names in the mapping are resolved against.
    """
    if isinstance(spec, FrictionLaw):
        return spec
    if not isinstance(spec, dict):
        raise InputError(f"must be a table such as {{ preset = \"42CD4-raw\" }} (got {spec!r})", source, key)
    kind = next((k for k in SPEC_KINDS if k in spec), None)
    if kind is None:
        raise InputError(f"needs one of the keys {', '.join(SPEC_KINDS)}", source, key)
    try:
        return SPEC_KINDS[kind](spec, Path(base_dir))
    except InputError as error:
        if error.source is not None:
            raise  # already names its own file (a law file, a log, a profile) and the key inside it
        inner = ".".join(part for part in (key, error.key) if part)
        raise InputError(error.message, source, inner) from None
