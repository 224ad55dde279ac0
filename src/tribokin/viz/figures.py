"""Matplotlib figures of results (PNG), in micrometres."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.patches import Circle  # noqa: E402

from tribokin.results import UM_PER_M, PoseResult  # noqa: E402


def field_figure_name(pose_name: str) -> str:
    """File name of a pose's repeatability field: ``field_<pose>.png``."""
    return f"field_{pose_name}.png"


def _field_axes(deviations_um: np.ndarray) -> tuple[int, int]:
    """The two base axes along which the cloud spreads most (ties keep x, y, z order)."""
    spread = np.ptp(deviations_um, axis=0) if len(deviations_um) else np.zeros(3)
    order = np.argsort(-spread, kind="stable")
    return tuple(sorted(order[:2]))


def save_repeatability_field(pose: PoseResult, path: Path, title: str = "") -> None:
    """The paper's "repeatability field" (Fig. 10-13) of one pose, in µm.

    Left: the cycle cloud around the commanded position, the reference circle
    of the transmission offset epsilon_t, the dispersion band between the
    smallest and largest friction effect (epsilon_D1, epsilon_D2), the
    barycenter and the RP_l circle around it. Right: the distance of each cycle
    from the commanded position, with the same band.
    """
    deviations = (pose.positions_m - pose.commanded_position_m) * UM_PER_M
    barycenter = (pose.metrics.barycenter_m - pose.commanded_position_m) * UM_PER_M
    distances = np.linalg.norm(deviations, axis=1)
    eps_t = np.linalg.norm(pose.reference_position_m - pose.commanded_position_m) * UM_PER_M
    eps_d1, eps_d2 = distances.min(), distances.max()
    rp_l = pose.metrics.RP_l_m * UM_PER_M
    i, j = _field_axes(deviations)

    fig, (field, series) = plt.subplots(1, 2, figsize=(11, 4.8), gridspec_kw={"width_ratios": [1.1, 1]})
    band_colour, ref_colour = "#f4a261", "#264653"
    field.add_patch(Circle((0, 0), eps_d2, color=band_colour, alpha=0.35, lw=0,
                           label=f"dispersion band ε_D1–ε_D2 = {eps_d1:.2f}–{eps_d2:.2f} µm"))
    field.add_patch(Circle((0, 0), eps_d1, color="white", lw=0))
    field.add_patch(Circle((0, 0), eps_t, fill=False, ls="--", color=ref_colour, lw=1.2,
                           label=f"ε_t reference circle = {eps_t:.2f} µm"))
    field.add_patch(Circle((barycenter[i], barycenter[j]), rp_l, fill=False, color="#e63946", lw=1.2,
                           label=f"RP_l = {rp_l:.2f} µm around the barycenter"))
    field.scatter(deviations[:, i], deviations[:, j], s=14, color="#2a9d8f", alpha=0.8, zorder=3,
                  label=f"{pose.cycles} cycles")
    field.plot(0, 0, "k+", ms=12, mew=2, zorder=4, label="commanded position")
    field.plot(barycenter[i], barycenter[j], "x", color="#e63946", ms=9, mew=2, zorder=4,
               label=f"barycenter, AP_p = {pose.metrics.AP_p_m * UM_PER_M:.2f} µm")
    reach = max(eps_d2, eps_t, np.linalg.norm(barycenter) + rp_l, 1.0) * 1.15
    field.set_xlim(-reach, reach)
    field.set_ylim(-reach, reach)
    field.set_aspect("equal")
    field.set_xlabel(f"{'xyz'[i]} deviation [µm]")
    field.set_ylabel(f"{'xyz'[j]} deviation [µm]")
    field.set_title("repeatability field")
    field.grid(alpha=0.3)
    field.legend(loc="upper left", fontsize=7, framealpha=0.9)

    cycles = np.arange(1, pose.cycles + 1)
    series.axhspan(eps_d1, eps_d2, color=band_colour, alpha=0.35)
    series.axhline(eps_t, ls="--", color=ref_colour, lw=1.2)
    series.plot(cycles, distances, "o-", ms=3, lw=0.6, color="#2a9d8f")
    series.set_xlabel("cycle")
    series.set_ylabel("distance from commanded position [µm]")
    series.set_ylim(0, reach)
    series.set_title("each cycle")
    series.grid(alpha=0.3)
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
