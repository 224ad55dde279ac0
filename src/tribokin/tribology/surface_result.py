"""Asperity statistics of a surface profile and eq. (6)'s count of its asperities (``tribokin surface``), as a
:class:`SurfaceResult` that writes ``surface.json`` and its figures."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tribokin.checks import argument, positive, within
from tribokin.errors import SettingsError
from tribokin.output.dispatch import write_folder
from tribokin.tribology.surfaces import SurfaceStatistics, analyse_profile, level, read_profile

area = within(positive, 1e-12, 1.0, "m²", "eq. (6) counts summits on a square micrometre (a summit or two) up to a "
              "square metre (a whole plate)")
#: Largest finite end of the eq. (6) ranges [m]: summit heights and radii are far below a metre.
RANGE_LIMIT_M = 1.0


@dataclass(frozen=True, eq=False)
class SurfaceResult:
    """A profile's asperity statistics and eq. (6)'s count.

    Attributes:
        profile: the profile's file, as given.
        x_m: positions along the profile [m].
        levelled_m: heights, the least-squares line taken off [m].
        statistics: the asperity statistics (eqs. 1-2).
        area_m2: the apparent area A_a of eq. (6) [m²].
        z_range_m: the summit altitude range of eq. (6) [m] (either end may be infinite).
        radius_range_m: the radius range of eq. (6) [m].
        count: eq. (6)'s count of asperities [-].
    """

    profile: str
    x_m: np.ndarray
    levelled_m: np.ndarray
    statistics: SurfaceStatistics
    area_m2: float
    z_range_m: tuple[float, float]
    radius_range_m: tuple[float, float]
    count: float

    @property
    def name(self) -> str:
        """The profile's file name, which the figures' titles give."""
        return Path(self.profile).name

    def summary(self) -> dict:
        """The content of ``surface.json`` (an infinite end of a range as ``null``: JSON has no infinity)."""
        finite = lambda pair: [float(v) if np.isfinite(v) else None for v in pair]  # noqa: E731
        return {**self.statistics.summary(),
                "AR_definition": "mean spacing of consecutive local maxima (1 / profile peak density), not ISO 12085 "
                                 "motifs",
                "radius_definition": "R* = R / 1 µm, ln R* ~ N(b, a^2) (eq. 2)",
                "asperity_count": {"area_m2": self.area_m2, "z_range_m": finite(self.z_range_m),
                                   "radius_range_m": finite(self.radius_range_m), "count": self.count}}

    def write(self, folder, force: bool = False) -> Path:
        """Write the files ``tribokin surface`` writes into ``folder`` (``surface.json``, ``profile.png``,
        ``p_z_R.png``): all at once, its lock held, refused (:class:`~tribokin.errors.InputError`) if it exists,
        unless ``force``.

        Returns:
            the folder written.
        """
        return write_folder(self, folder, force)  # output.tribology.write_surface


def check_options(area_m2, z_range_m, radius_range_m) -> tuple[float, tuple[float, float], tuple[float, float]]:
    """Eq. (6)'s options, checked: A_a in ``area``'s range, each range [low, high] with low <= high, finite ends
    within ±``RANGE_LIMIT_M``, radii >= 0 (either end of a range may be infinite); a
    :class:`~tribokin.errors.SettingsError` names the argument (``area_m2``, ``z_range_m[0]``, ``radius_range_m``)."""
    area_m2 = argument(area, area_m2, "area_m2")
    ranges = []
    for key, bounds in (("z_range_m", z_range_m), ("radius_range_m", radius_range_m)):
        low, high = (_bound(value, f"{key}[{i}]") for i, value in enumerate(bounds))
        if not low <= high:
            raise SettingsError(f"must be low high with low <= high (got {low:g} {high:g})", key)
        ranges.append((low, high))
    if ranges[1][0] < 0:
        raise SettingsError(f"radii must be >= 0 (got {ranges[1][0]:g})", "radius_range_m")
    return area_m2, ranges[0], ranges[1]


def _bound(value, key: str) -> float:
    if isinstance(value, float) and math.isnan(value):
        raise SettingsError("must be a number or an infinity, not nan", key)
    if math.isfinite(value) and abs(value) > RANGE_LIMIT_M:
        raise SettingsError(f"must be within ±{RANGE_LIMIT_M:g} m, or an infinity (got {value:g}): summit heights "
                            "and radii are far below a metre; write inf for no bound", key)
    return float(value)


def analyse_surface(profile, area_m2: float = 1e-6, z_range_m=(-np.inf, np.inf),
                    radius_range_m=(0.0, np.inf)) -> SurfaceResult:
    """Asperity statistics of a profile and eq. (6)'s count of asperities.

    Args:
        profile: the profile's CSV file (``x_m, z_m``).
        area_m2: the apparent area A_a [m²].
        z_range_m: summit altitudes (low, high) counted [m].
        radius_range_m: summit radii (low, high) counted [m].

    Returns:
        the statistics, the count and the levelled profile.
    """
    area_m2, z_range_m, radius_range_m = check_options(area_m2, z_range_m, radius_range_m)
    x, z = read_profile(profile)
    statistics = analyse_profile(x, z, str(profile))
    count = statistics.asperity_count(area_m2, z_range_m, radius_range_m)
    return SurfaceResult(str(profile), x, level(x, z), statistics, area_m2, z_range_m, radius_range_m, count)
