"""Friction coefficient of a greased rough contact, cycle by cycle (mixed lubrication).

Model (a load-sharing rule in the spirit of Johnson, Greenwood & Poon, 1972,
"A simple theory of asperity contact in elastohydrodynamic lubrication",
Wear 19, 91-108): the grease film holds the smooth counter-face (the pin,
taken as smooth and flat: ASSUMPTION) at the separation h_film [m] from the
mean line of the surface. The summits above h_film touch it, each a Hertz
contact of interference z - h_film, and carry P_a; the film carries the rest.
If the summits alone can carry the normal load W (P_a >= W), the film has
broken down (boundary regime) and they carry it all:

    share = min(1, P_a / W),   mu = share * mu_boundary + (1 - share) * mu_film

Cycle-to-cycle variability: every cycle the pin meets a fresh patch of the
surface of apparent area A_n, so the summits in contact are drawn again from
the profile's statistics: their number is Poisson of mean D_s A_n F_0(h)
(GW; summits form a Poisson field), their altitudes follow the Gaussian of
eq. (1) above h_film, their radii the lognormal of eq. (2).

Constants (defaults):

- E* = 115 GPa, steel on steel (42CD4 on 100C6: E = 210 GPa, nu = 0.3).
- mu_boundary = 0.16 and mu_film = 0.09: ASSUMPTION, the extremes of the
  paper's measured greased 42CD4/100C6 friction (Fig. 6, 0.09-0.16) taken
  as the pure asperity and pure film limits; in the range 0.04-0.25 usual
  for greased steel.

Limitations: elastic Hertz summits (steel summits usually have a plasticity
index psi > 1, see ``gw.plasticity_index``: their load per interference is
overestimated); film thickness given, not computed from the grease rheology.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import stats

from tribokin.tribology import gw
from tribokin.tribology.surfaces import SurfaceStatistics

STEEL_MODULUS_PA = 115e9     # E*, steel on steel (NOTES.md)
MU_BOUNDARY = 0.16           # asperity-dominated limit (paper Fig. 6, raw 42CD4, upper end)
MU_FILM = 0.09               # film-dominated limit (paper Fig. 6, raw 42CD4, lower end)
_CHUNK = 2_000_000           # summits drawn at once


@dataclass(frozen=True)
class Lubrication:
    """Film separation [m] and the friction coefficients [-] of the asperity and film parts of the load."""

    film_thickness_m: float
    mu_boundary: float = MU_BOUNDARY
    mu_film: float = MU_FILM


def mean_contacts(surface: SurfaceStatistics, area_m2: float, separation_m: float) -> float:
    """Mean number of summits of an apparent area ``area_m2`` [m²] above ``separation_m`` [m] (GW: D_s A F_0(h))."""
    return float(gw.contact_count(surface.summit_density_m2, area_m2, (separation_m - surface.Alt_m) / surface.SAlt_m))


def asperity_loads(surface: SurfaceStatistics, area_m2: float, separation_m: float, cycles: int,
                   rng: np.random.Generator, modulus_Pa: float = STEEL_MODULUS_PA) -> np.ndarray:
    """Load carried by the summits touching a flat at ``separation_m`` [N], one value per cycle.

    Its expectation is the GW load ``gw.load`` with sqrt(R) replaced by its mean over the radius law.
    """
    h = (separation_m - surface.Alt_m) / surface.SAlt_m
    counts = rng.poisson(mean_contacts(surface, area_m2, separation_m), cycles)
    above = stats.truncnorm(h, np.inf, surface.Alt_m, surface.SAlt_m)
    loads = np.empty(cycles)
    start = 0
    while start < cycles:
        stop = start + max(1, min(cycles - start, _CHUNK // max(1, counts.max())))
        width = counts[start:stop].max(initial=0)
        z = above.rvs(size=(stop - start, width), random_state=rng)
        radius = surface.radius_law().rvs(size=(stop - start, width), random_state=rng)
        touching = np.arange(width) < counts[start:stop, None]
        loads[start:stop] = np.sum(np.where(touching, gw.hertz_load(radius, z - separation_m, modulus_Pa), 0), axis=1)
        start = stop
    return loads


def friction_per_cycle(surface: SurfaceStatistics, normal_force_N: float, area_m2: float, lubrication: Lubrication,
                       cycles: int, rng: np.random.Generator,
                       modulus_Pa: float = STEEL_MODULUS_PA) -> tuple[np.ndarray, np.ndarray]:
    """Friction coefficient [-] and asperity share of the load [-] of each cycle."""
    loads = asperity_loads(surface, area_m2, lubrication.film_thickness_m, cycles, rng, modulus_Pa)
    share = np.minimum(1.0, loads / normal_force_N)
    return share * lubrication.mu_boundary + (1 - share) * lubrication.mu_film, share

