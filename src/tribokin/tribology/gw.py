"""Greenwood-Williamson contact of a rough surface on a smooth flat, and Hertz per asperity.

Greenwood & Williamson (1966), "Contact of nominally flat surfaces", Proc. R.
Soc. A 295, 300-319: summits of equal radius R [m], Gaussian altitudes of rms
sigma_s [m], density eta [1/m^2] over the nominal area A_n [m^2]; the flat
sits at separation d [m] from the mean summit altitude, h = d / sigma_s.
Each summit of altitude z > d is a Hertz contact of interference z - d.
"""

from __future__ import annotations

import math

import numpy as np


def gw_F(n, h):
    """F_n(h) = (1/sqrt(2 pi)) * integral_h^inf (s - h)^n exp(-s^2/2) ds [-], vectorised.

    Closed form F_n(h) = Gamma(n+1)/sqrt(2 pi) * exp(-h^2/4) * D_{-n-1}(h), with
    D the parabolic cylinder function (``scipy.special.pbdv``); F_0 = erfc(h/sqrt 2)/2,
    F_1 = phi(h) - h F_0, F_2 = (1 + h^2) F_0 - h phi(h) follow from it.
    """
    from scipy import special  # here: a run that computes no contact does not import scipy.special

    n, h = np.broadcast_arrays(np.asarray(n, dtype=float), np.asarray(h, dtype=float))
    d, _ = special.pbdv(-n - 1, h)
    return special.gamma(n + 1) / math.sqrt(2 * math.pi) * np.exp(-h * h / 4) * d


def contact_count(density_m2, area_m2, h):
    """Expected number of summits in contact [-]: eta A_n F_0(h)."""
    return density_m2 * area_m2 * gw_F(0, h)


def real_area(density_m2, area_m2, radius_m, sigma_m, h):
    """Expected real contact area [m^2]: pi eta A_n R sigma_s F_1(h)."""
    return math.pi * density_m2 * area_m2 * radius_m * sigma_m * gw_F(1, h)


def load(density_m2, area_m2, radius_m, sigma_m, h, modulus_Pa):
    """Expected load carried by the summits [N]: (4/3) eta A_n E* R^1/2 sigma_s^3/2 F_3/2(h)."""
    return 4 / 3 * density_m2 * area_m2 * modulus_Pa * np.sqrt(radius_m) * sigma_m ** 1.5 * gw_F(1.5, h)


def hertz_load(radius_m, interference_m, modulus_Pa):
    """Hertz load of a sphere of radius R on a flat [N]: (4/3) E* R^1/2 delta^3/2 (0 where delta <= 0)."""
    delta = np.clip(interference_m, 0, None)
    return 4 / 3 * modulus_Pa * np.sqrt(radius_m) * delta ** 1.5


def hertz_area(radius_m, interference_m):
    """Hertz contact area [m^2]: pi R delta (0 where delta <= 0)."""
    return np.pi * radius_m * np.clip(interference_m, 0, None)


def plasticity_index(modulus_Pa, hardness_Pa, sigma_m, radius_m):
    """Greenwood-Williamson plasticity index psi = (E*/H) sqrt(sigma_s / R) [-]: elastic below 0.6, plastic above 1."""
    return modulus_Pa / hardness_Pa * np.sqrt(sigma_m / radius_m)
