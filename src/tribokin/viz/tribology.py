"""Matplotlib figures of tribological measurements (PNG): the paper's Fig. 6, 7 and 9."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from tribokin.viz.canvas import agg_figure

UM_PER_M = 1e6


def save_mu_per_cycle(cycle, mu, running_in: int, path: Path, title: str = "") -> None:
    """Friction coefficient against cycles, running-in shaded (paper Fig. 6)."""
    fig = agg_figure(figsize=(8, 4))
    ax = fig.subplots()
    ax.plot(cycle, mu, lw=0.6, color="tab:blue", label="mu per cycle")
    if running_in:
        ax.axvspan(cycle[0], cycle[running_in - 1], color="0.85", label=f"running-in ({running_in} cycles, trimmed)")
    ax.axhline(np.median(mu[running_in:]), color="k", lw=1, ls="--", label="steady-state median")
    ax.set(xlabel="cycle [-]", ylabel="friction coefficient mu [-]", title=title or "Friction coefficient per cycle")
    ax.legend(loc="upper right")
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def save_mu_histogram(mu, fits, path: Path, title: str = "") -> None:
    """Histogram of the steady-state mu with the fitted densities, best (lowest AIC) first (paper Fig. 7)."""
    fig = agg_figure(figsize=(7, 4.5))
    ax = fig.subplots()
    ax.hist(mu, bins="auto", density=True, color="0.8", edgecolor="0.5", label=f"measured ({len(mu)} cycles)")
    grid = np.linspace(mu.min() - 0.1 * np.ptp(mu), mu.max() + 0.1 * np.ptp(mu), 400)
    for fit in fits:
        ax.plot(grid, fit.to_law().pdf(grid), lw=1.8, label=f"{fit.law} (AIC {fit.aic:.1f})")
    ax.set(xlabel="friction coefficient mu [-]", ylabel="probability density [1/-]",
           title=title or "Histogram of the friction coefficient")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def save_asperity_density(surface, path: Path, title: str = "") -> None:
    """p(z, R) of the summits over altitude [µm] and radius [µm] (paper Fig. 9)."""
    z = np.linspace(surface.Alt_m - 3 * surface.SAlt_m, surface.Alt_m + 3 * surface.SAlt_m, 120)
    radius = np.linspace(*surface.radius_law().ppf([0.001, 0.99]), 120)
    zz, rr = np.meshgrid(z, radius)
    density = surface.density(zz, rr) * 1e-12  # per µm of z and per µm of R
    fig = agg_figure(figsize=(7.5, 5.5))
    ax = fig.add_subplot(projection="3d")
    ax.plot_surface(rr * UM_PER_M, zz * UM_PER_M, density, cmap="viridis", linewidth=0)
    ax.set(xlabel="radius R [µm]", ylabel="summit altitude z [µm]", zlabel="p(z, R) [1/µm²]",
           title=title or "Density of asperities p(z, R)")
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def save_profile(x, z, peaks, path: Path, title: str = "") -> None:
    """The levelled profile with its peaks, in µm over mm."""
    fig = agg_figure(figsize=(9, 3))
    ax = fig.subplots()
    ax.plot(x * 1e3, z * UM_PER_M, lw=0.6)
    ax.plot(x[peaks] * 1e3, z[peaks] * UM_PER_M, "v", ms=3, color="tab:red", label=f"{len(peaks)} peaks")
    ax.set(xlabel="x [mm]", ylabel="z [µm]", title=title or "Levelled profile")
    ax.legend(loc="upper right")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
