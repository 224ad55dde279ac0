"""Friction laws from the mappings written in study files.

``{ preset = "42CD4-treated" }``, ``{ law = "gaussian", mean = 0.1375, std = 0.0075 }``,
``{ law = "uniform", low = 0.09, high = 0.16 }``, ``{ law = "constant", mu = 0.12 }``,
``{ law = "lognormal", mean = 0.12, std = 0.01 }``, ``{ law = "empirical", values = [...] }``.
"""

from __future__ import annotations

from pathlib import Path

from tribokin.errors import InputError, closest_hint
from tribokin.tribology.laws import Constant, Empirical, FrictionLaw, Gaussian, Lognormal, Uniform
from tribokin.tribology.presets import preset

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
    return cls(*(spec[k] for k in keys))


# How a spec is recognised: the first of these keys present in it.
SPEC_KINDS = {"preset": _from_preset, "law": _from_law}


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
        inner = f"{key}.{error.key}" if error.key else key
        raise InputError(error.message, error.source or source, inner) from None
