"""Named friction laws with their provenance.

The tribometer campaign of the source paper (Lakhal et al., "Contribution to
analysis and friction exploitation ... industrial robot repeatability", §3-4):
42CD4 steel plate against a 100C6 steel pin, Mobilux EP2 grease, 80 mm/s,
1 Hz, 40 mm stroke, 1 h, normal loads 40 N and 150 N.
"""

from __future__ import annotations

from tribokin.errors import LawError, closest_hint
from tribokin.tribology.laws import Constant, FrictionLaw, Gaussian, Uniform

_CAMPAIGN = "paper's tribometer campaign (42CD4 plate / 100C6 pin, Mobilux EP2 grease, 40 N and 150 N)"

PRESETS: dict[str, tuple[str, callable]] = {
    "frictionless": (
        "paper Fig. 10: mu = 0, the reference case (RP = 0)",
        lambda p: Constant(0.0, provenance=p),
    ),
    "constant-0.12": (
        "paper Fig. 11: constant mu = 0.12",
        lambda p: Constant(0.12, provenance=p),
    ),
    "42CD4-raw": (
        f"{_CAMPAIGN}: raw steel spans 0.09-0.16, uniform histogram (Fig. 7)",
        lambda p: Uniform(0.09, 0.16, provenance=p),
    ),
    "42CD4-treated": (
        f"{_CAMPAIGN}: treated steel spans 0.115-0.16, Gaussian histogram (Fig. 7); "
        "ASSUMPTION: the span is taken as +/-3 sigma, giving mean 0.1375 and sigma 0.0075",
        lambda p: Gaussian(0.1375, 0.0075, provenance=p),
    ),
}


def preset(name: str) -> FrictionLaw:
    """The friction law called ``name`` (see ``PRESETS``), with its provenance."""
    if name not in PRESETS:
        raise LawError(f"unknown friction preset '{name}'{closest_hint(name, list(PRESETS))}; "
                       f"valid presets: {', '.join(PRESETS)}", "preset")
    provenance, make = PRESETS[name]
    return make(f"preset '{name}': {provenance}")
