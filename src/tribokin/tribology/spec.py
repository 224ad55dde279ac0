"""Friction laws from the mappings written in study files.

``{ preset = "42CD4-treated" }``, ``{ law = "gaussian", mean = 0.1375, std = 0.0075 }``,
``{ law = "uniform", low = 0.09, high = 0.16 }``, ``{ law = "constant", mu = 0.12 }``,
``{ law = "lognormal", mean = 0.12, std = 0.01 }``, ``{ law = "empirical", values = [...] }``,
``{ file = "law.toml" }`` (a law written by ``tribokin fit-friction``),
``{ log = "tribometer.csv", running_in = 50 }`` (the trimmed measured mu, resampled),
``{ surface = "profile.csv", normal_force_N = 150, contact_area_m2 = 1e-6, film_thickness_m = 1.2e-6 }``
(mu simulated cycle by cycle from the profile's asperities, see ``contact``).
File names are relative to the study file; each must resolve (symlinks followed) inside one of the folders the
caller allows (``roots``: by default the folder they are relative to) before it is opened
(:func:`~tribokin.confinement.confined_file`).
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

import numpy as np

from tribokin.checks import finite, nested_too_deep, seed_int, whole_number, within
from tribokin.confinement import confined_file
from tribokin.errors import InputError, LawError, closest_hint
from tribokin.tribology import laws
from tribokin.tribology.laws import MU_MAX, MU_MIN, Constant, Empirical, FrictionLaw, Scaled
from tribokin.tribology.presets import preset

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib


def _from_preset(spec: dict, base_dir: Path, roots: tuple[Path, ...]) -> FrictionLaw:
    _only_keys(spec, ("preset",))
    return preset(spec["preset"])


def _from_law(spec: dict, base_dir: Path, roots: tuple[Path, ...]) -> FrictionLaw:
    name, known = spec["law"], laws.LAWS
    if name not in known:
        raise InputError(f"unknown law '{name}'{closest_hint(str(name), list(known))}; valid laws: "
                         f"{', '.join(known)}", key="law")
    law = known[name]
    _only_keys(spec, ("law",) + law.parameters)
    missing = [k for k in law.parameters if k not in spec]
    if missing:
        raise InputError(f"law '{name}' needs {', '.join(missing)}", key=missing[0])
    return law(*(spec[k] for k in law.parameters))  # checks the parameters


def _from_file(spec: dict, base_dir: Path, roots: tuple[Path, ...]) -> FrictionLaw:
    _only_keys(spec, ("file",))
    path = base_dir / str(spec["file"])
    real = confined_file(path, roots, None, "file", "not found; write it with `tribokin fit-friction`")
    try:
        text = real.read_text(encoding="utf-8")
        mapping = tomllib.loads(text)
    except UnicodeDecodeError as error:
        raise InputError(f"not valid TOML: not UTF-8 text (at byte {error.start})", path) from None
    except ValueError as error:  # also a number of more than 4300 digits
        where = re.search(r"\(at (line \d+, column \d+|end of document)\)", str(error))  # tomllib quotes keys: not them
        raise InputError(f"not valid TOML{' at ' + where.group(1) if where else ''}: expected a law file as "
                         "`tribokin fit-friction` writes it (law = \"...\" and its parameters)", path) from None
    except RecursionError:
        raise nested_too_deep(text, path) from None
    if "file" in mapping:  # one level only: a law file naming itself, or a ring of them, would never end
        raise InputError("a law file holds the law itself (law = ..., preset = ..., log = ...), not another law "
                         "file; point the study at the file this key names directly", path, "file")
    law = law_from_spec(mapping, path, "", path.parent, roots)
    law.provenance = law.provenance or f"law file {path} (its comments say where it comes from)"
    return law


def _from_log(spec: dict, base_dir: Path, roots: tuple[Path, ...]) -> FrictionLaw:
    from tribokin.tribology.tribometer import read_log, steady_state

    _only_keys(spec, ("log", "running_in"))
    path = base_dir / str(spec["log"])
    confined_file(path, roots, None, "log")
    log = read_log(path)
    mu, trimmed = steady_state(log, spec.get("running_in"))
    how = "given" if "running_in" in spec else "detected"
    return Empirical(mu, provenance=f"tribometer log {log.source}: {mu.size} cycles after {trimmed} running-in "
                                    f"cycles ({how})")


SURFACE_REQUIRED = ("normal_force_N", "contact_area_m2", "film_thickness_m")
#: key -> check of the numbers of a surface law: each within its physical range.
SURFACE_NUMBERS = {
    "normal_force_N": within(finite, 1e-3, 1e7, "N", "tribometers load from millinewtons; no bearing carries 1000 t"),
    "contact_area_m2": within(finite, 1e-12, 1e-2, "m²",
                              "a pin's apparent contact spans a square micrometre to 100 cm²"),
    "film_thickness_m": within(finite, 1e-9, 1e-3, "m",
                               "lubricant films run from nanometres to a tenth of a millimetre"),
    "mu_boundary": within(finite, MU_MIN, MU_MAX, "", "the friction coefficients a law may hold"),
    "mu_film": within(finite, MU_MIN, MU_MAX, "", "the friction coefficients a law may hold"),
    "modulus_Pa": within(finite, 1e6, 1.2e12, "Pa",
                         "contact moduli run from rubber's megapascals to diamond's 1.2e12 Pa"),
}
#: key -> (default, check) of the whole numbers of a surface law.
SURFACE_COUNTS = {"cycles": (1000, within(whole_number, 1, 10 ** 6, "", "a surface law simulates up to a million "
                                                                          "cycles")),
                  "seed": (0, seed_int)}
#: Most summits a surface law may draw (contacts per cycle × cycles): about a minute's work.
MAX_SUMMIT_DRAWS = 1e8


def _number(spec: dict, key: str, default: float | None = None) -> float:
    """``spec[key]`` (else ``default``), a number within its range (``SURFACE_NUMBERS``)."""
    value = spec.get(key, default)
    if value is None:
        raise InputError("is required for a surface friction law", key=key)
    return SURFACE_NUMBERS[key](value, None, key)


def _count(spec: dict, key: str) -> int:
    default, check = SURFACE_COUNTS[key]
    return check(spec.get(key, default), None, key)


def _from_surface(spec: dict, base_dir: Path, roots: tuple[Path, ...]) -> FrictionLaw:
    from tribokin.tribology import contact
    from tribokin.tribology.surfaces import profile_statistics

    optional = {"mu_boundary": contact.MU_BOUNDARY, "mu_film": contact.MU_FILM, "modulus_Pa": contact.STEEL_MODULUS_PA}
    _only_keys(spec, ("surface",) + SURFACE_REQUIRED + tuple(optional) + tuple(SURFACE_COUNTS))
    values = {key: _number(spec, key) for key in SURFACE_REQUIRED}
    values.update({key: _number(spec, key, default) for key, default in optional.items()})
    values.update({key: _count(spec, key) for key in SURFACE_COUNTS})
    path = base_dir / str(spec["surface"])
    confined_file(path, roots, None, "surface")
    surface = profile_statistics(path)
    contacts = contact.mean_contacts(surface, values["contact_area_m2"], values["film_thickness_m"])
    if contacts * values["cycles"] > MAX_SUMMIT_DRAWS:
        raise InputError(f"{values['contact_area_m2']:g} m² puts {contacts:.3g} summits of {surface.source} in "
                         f"contact per cycle, {contacts * values['cycles']:.3g} draws over {values['cycles']} cycles; "
                         f"at most {MAX_SUMMIT_DRAWS:g}: use a smaller area or fewer cycles", key="contact_area_m2")
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
            raise InputError(f"unknown key '{key}'{closest_hint(key, list(allowed))}; "
                             f"allowed here: {', '.join(allowed)}", key=key)


def law_from_spec(spec, source: str | Path | None = None, key: str = "friction",
                  base_dir: str | Path = ".", roots=None) -> FrictionLaw:
    """Build the friction law a study file describes.

    Args:
        spec: the mapping, e.g. ``{"preset": "42CD4-raw"}``; a ``FrictionLaw`` passes through.
        source: file the mapping came from, for error messages.
        key: dotted key of the mapping in that file, for error messages.
        base_dir: folder that relative file names in the mapping are resolved against.
        roots: folders the files the mapping names must lie in (symlinks followed); ``None``: ``base_dir``.
    """
    if isinstance(spec, FrictionLaw):
        return spec
    if not isinstance(spec, dict):
        raise InputError(f"must be a table such as {{ preset = \"42CD4-raw\" }} (got {spec!r})", source, key)
    kind = next((k for k in SPEC_KINDS if k in spec), None)
    if kind is None:
        raise InputError(f"needs one of the keys {', '.join(SPEC_KINDS)}", source, key)
    try:
        return SPEC_KINDS[kind](spec, Path(base_dir), tuple(Path(r) for r in (roots or (base_dir,))))
    except LawError as error:
        raise InputError(error.message, source, ".".join(part for part in (key, error.parameter) if part)) from None
    except InputError as error:
        if error.source is not None:
            raise  # already names its own file (a law file, a log, a profile) and the key inside it
        inner = ".".join(part for part in (key, error.key) if part)
        raise InputError(error.message, source, inner) from None


def scaled_law_from_spec(spec: dict, scale: float, quantity: str, source: str | Path | None = None,
                         key: str = "friction") -> Scaled:
    """A law of a friction torque [N·m] or force [N] (``quantity``) written as ``{ law = ..., ... }`` with its values
    in that unit (a constant one as ``{ law = "constant", value = ... }``), held as ``scale`` times a law of the
    values divided by ``scale`` (their range is the caller's to check)."""
    if not isinstance(spec, dict) or "law" not in spec:
        raise InputError(f"must be a table such as {{ law = \"gaussian\", mean = 0.3, std = 0.05 }} (got {spec!r})",
                         source, key)
    inner = {name: value if name == "law" else np.divide(value, scale).tolist() for name, value in spec.items()}
    if spec["law"] == "constant":
        if "mu" in spec or "value" not in spec:
            raise InputError('a constant torque or force is written { law = "constant", value = ... }', source,
                             f"{key}.{'mu' if 'mu' in spec else 'value'}")
        inner = {"mu" if name == "value" else name: value for name, value in inner.items()}
    return Scaled(law_from_spec(inner, source, key), scale, quantity)
