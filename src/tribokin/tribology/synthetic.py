"""Synthetic microgeometry and tribometer logs, for examples and tests.

A profile mixes a turned surface (a sinusoid of the feed period: quasi-periodic)
and a ground one (a stationary Gaussian random process with a Gaussian
autocorrelation R(tau) = Rq^2 exp(-tau^2 / l^2): quasi-random) with one
parameter, the randomness r in [0, 1]:

    z(x) = Rq * (sqrt(1 - r) * sqrt(2) sin(2 pi x / feed + phase) + sqrt(r) * g(x))

g has unit variance, so z has rms Rq for every r. The spectral moments of g
are m2 = 2 / l^2 and m4 = 12 / l^4 [1/m^2, 1/m^4], so its expected density of
local maxima (Rice, Nayak) is D_1 = sqrt(m4 / m2) / (2 pi) = sqrt(6) / (2 pi l).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tribokin.errors import InputError


@dataclass(frozen=True)
class ProfileRecipe:
    """Parameters of a synthetic profile: lengths [m], randomness [-], seed."""

    randomness: float
    rq_m: float = 0.8e-6
    feed_m: float = 100e-6
    correlation_length_m: float = 10e-6
    spacing_m: float = 1e-6
    points: int = 4000
    seed: int = 0


def gaussian_process(points: int, spacing_m: float, correlation_length_m: float,
                     rng: np.random.Generator) -> np.ndarray:
    """Unit-variance stationary Gaussian process with autocorrelation exp(-tau^2 / l^2), sampled every spacing.

    White noise filtered in the Fourier domain (circular, on a record four
    times longer than returned so that the wrap-around does not show).
    """
    n = 4 * points
    k = 2 * np.pi * np.fft.rfftfreq(n, spacing_m)                          # [rad/m]
    amplitude = np.sqrt(np.exp(-(k * correlation_length_m) ** 2 / 4))       # sqrt of the PSD, up to a constant
    g = np.fft.irfft(np.fft.rfft(rng.standard_normal(n)) * amplitude, n)[:points]
    variance = (amplitude[0] ** 2 + 2 * np.sum(amplitude[1:] ** 2)) / n  # Parseval, one-sided spectrum
    return g / math.sqrt(variance)


def synthetic_profile(recipe: ProfileRecipe) -> tuple[np.ndarray, np.ndarray]:
    """Positions x [m] and heights z [m] of a profile from quasi-periodic (r = 0) to quasi-random (r = 1)."""
    if not 0 <= recipe.randomness <= 1:
        raise InputError(f"must be in [0, 1] (got {recipe.randomness})", key="randomness")
    rng = np.random.default_rng(recipe.seed)
    x = np.arange(recipe.points) * recipe.spacing_m
    periodic = math.sqrt(2) * np.sin(2 * np.pi * x / recipe.feed_m + rng.uniform(0, 2 * np.pi))
    random = gaussian_process(recipe.points, recipe.spacing_m, recipe.correlation_length_m, rng)
    r = recipe.randomness
    return x, recipe.rq_m * (math.sqrt(1 - r) * periodic + math.sqrt(r) * random)


# The three reference microgeometries shipped in tribokin/data/profiles/ (from quasi-periodic to quasi-random).
REFERENCE_PROFILES = {
    "turned": ProfileRecipe(randomness=0.05, seed=1),
    "intermediate": ProfileRecipe(randomness=0.5, seed=2),
    "ground": ProfileRecipe(randomness=1.0, seed=3),
}


def synthetic_log(cycles: int = 3600, mean: float = 0.1375, std: float = 0.0075, running_in_excess: float = 0.04,
                  running_in_cycles: float = 60.0, normal_force_N: float = 150.0,
                  seed: int = 0) -> dict[str, np.ndarray]:
    """A tribometer log: mu = mean + excess * exp(-cycle / tau) + N(0, std), as friction and normal forces [N].

    Defaults: the treated-42CD4 preset's statistics at 150 N, 1 h at 1 Hz,
    with a running-in that decays over ~tau = 60 cycles.
    """
    rng = np.random.default_rng(seed)
    cycle = np.arange(1, cycles + 1)
    mu = mean + running_in_excess * np.exp(-cycle / running_in_cycles) + rng.normal(0, std, cycles)
    return {"cycle": cycle, "friction_force_N": mu * normal_force_N, "normal_force_N": np.full(cycles, normal_force_N)}
