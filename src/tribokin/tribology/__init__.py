"""Tribology: friction-coefficient laws and their sources. Knows nothing of robots."""

from tribokin.tribology.gw import gw_F
from tribokin.tribology.laws import LAWS, Constant, Empirical, FrictionLaw, Gaussian, Lognormal, Uniform
from tribokin.tribology.presets import PRESETS, preset
from tribokin.tribology.spec import law_from_spec

__all__ = ["LAWS", "Constant", "Empirical", "FrictionLaw", "Gaussian", "Lognormal", "Uniform", "PRESETS", "preset",
           "law_from_spec", "gw_F"]
