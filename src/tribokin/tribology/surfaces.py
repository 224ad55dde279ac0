"""Surface profiles -> asperity statistics of the source paper (§4.2, eq. 1-6).

From a measured profile z(x) (CSV columns ``x_m, z_m``):

- levelling: the least-squares line is subtracted (form and tilt removed);
- peaks: every local maximum of the levelled profile (z_i > z_{i-1} and
  z_i >= z_{i+1}); these are profile *peaks*, used as the summits of the
  surface as the paper does (Nayak's distinction, paper §4.2);
- AR: the mean spacing of consecutive peaks, i.e. 1 / (profile peak density
  D_1). SIMPLIFICATION: ISO 12085 motifs combine and drop small peaks and no
  Python implementation exists, so this AR is the raw-peak spacing (shorter
  than a motif AR), which is what Nayak's D_s = 1.2 D_1^2 assumes;
- summit altitudes: Gaussian fit (Alt, SAlt) of the peak heights, eq. (1);
- radii: R = 1 / |z''| at each peak from a least-squares parabola through the
  peak and its two neighbours on each side; lognormal fit of
  R* = R / (1 µm), eq. (2): ln R* ~ N(b, a^2);
- D_s = 1.2 / AR^2 [1/m^2] (Nayak), and eq. (6): the number of asperities of
  an apparent area A_a with summit in [z1, z2] and radius in [R1, R2].
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np
from scipy import stats

from tribokin.errors import InputError
from tribokin.tribology.columns import quiet_numerics, read_columns

RADIUS_UNIT_M = 1e-6   # R* = R / RADIUS_UNIT_M in eq. (2)
STENCIL = 2            # neighbours on each side of a peak in its parabola fit
MIN_POINTS = 50
#: column -> (largest |value| [m], why); and the finest spacing of x [m] (no profilometer resolves below atoms).
PROFILE_LIMITS_M = {"x_m": (10.0, "a profile is millimetres to metres long"),
                    "z_m": (1.0, "roughness heights are micrometres")}
MIN_SPACING_M = 1e-10


@dataclass(frozen=True)
class SurfaceStatistics:
    """Asperity statistics of a profile (SI units; a, b of eq. 2 dimensionless, R* = R / 1 µm)."""

    source: str
    length_m: float
    rq_m: float
    peaks: int
    AR_m: float
    summit_density_m2: float
    Alt_m: float
    SAlt_m: float
    radius_a: float
    radius_b: float

    def altitude_law(self):
        """Frozen scipy normal law of summit altitude z [m], eq. (1)."""
        return stats.norm(self.Alt_m, self.SAlt_m)

    def radius_law(self):
        """Frozen scipy lognormal law of the radius R [m], eq. (2) rescaled from R* to R."""
        return stats.lognorm(self.radius_a, 0, RADIUS_UNIT_M * math.exp(self.radius_b))

    def density(self, z_m, radius_m):
        """p(z, R) = p1(z) p2(R) [1/m^2], the paper's Fig. 9 (p2 in 1/m, i.e. per metre of R)."""
        return self.altitude_law().pdf(z_m) * self.radius_law().pdf(radius_m)

    def asperity_count(self, area_m2, z_range_m=(-np.inf, np.inf), radius_range_m=(0.0, np.inf)) -> float:
        """Eq. (6): asperities of the apparent area A_a [m^2] with z in z_range [m], R in radius_range [m].

        (1.2 A_a / AR^2) times the double integral of p(z, R) = p1(z) p2(R) over the ranges, which the independence
        of altitude and radius makes the product of each law's probability of its range (each from the tail that
        keeps its digits).
        """
        return (self.summit_density_m2 * area_m2 * _probability_between(self.altitude_law(), *z_range_m)
                * _probability_between(self.radius_law(), *radius_range_m))

    def summary(self) -> dict:
        """The statistics as a JSON-ready mapping."""
        return asdict(self)


def _probability_between(law, low: float, high: float) -> float:
    """P(low < X < high) of a frozen scipy law, from its upper tail above the median (where 1 - cdf would lose the
    digits) and its lower tail below."""
    if low >= law.median():
        return float(law.sf(low) - law.sf(high))
    return float(law.cdf(high) - law.cdf(low))


def read_profile(path) -> tuple[np.ndarray, np.ndarray]:
    """Positions x [m] and heights z [m] of a profile CSV (``x_m, z_m``); x must increase strictly."""
    columns, lines = read_columns(path, (("x_m", "z_m"),), MIN_POINTS)
    for key, (largest, why) in PROFILE_LIMITS_M.items():
        beyond = np.abs(columns[key]) > largest
        if beyond.any():
            row = int(np.argmax(beyond))
            raise InputError(f"line {lines[row]} holds {columns[key][row]:g} m, beyond ±{largest:g} m: {why}; check "
                             "the units", path, key)
    x = columns["x_m"]
    steps = np.diff(x)
    if np.any(steps <= 0):
        raise InputError(f"must increase strictly; line {lines[np.argmax(steps <= 0) + 1]} does not", path, "x_m")
    if np.any(steps < MIN_SPACING_M):
        row = int(np.argmax(steps < MIN_SPACING_M))
        raise InputError(f"line {lines[row + 1]} lies {steps[row]:g} m after the one before; points closer than "
                         f"{MIN_SPACING_M:g} m are below atomic size: check the units", path, "x_m")
    return x, columns["z_m"]


def level(x, z) -> np.ndarray:
    """Heights [m] about the least-squares line through the profile."""
    return z - np.polyval(np.polyfit(x, z, 1), x)


def find_peaks(z) -> np.ndarray:
    """Indices of the local maxima of a profile, away from its ends by ``STENCIL`` points."""
    i = np.arange(STENCIL, len(z) - STENCIL)
    return i[(z[i] > z[i - 1]) & (z[i] >= z[i + 1])]


def peak_curvatures(x, z, peaks) -> np.ndarray:
    """z'' at each peak [1/m]: least-squares parabola through the peak and ``STENCIL`` neighbours each side."""
    offsets = np.arange(-STENCIL, STENCIL + 1)
    t = x[peaks[:, None] + offsets] - x[peaks][:, None]
    design = np.stack([np.ones_like(t), t, t * t], axis=-1)                  # (peaks, points, 3)
    normal = np.einsum("pki,pkj->pij", design, design)
    rhs = np.einsum("pki,pk->pi", design, z[peaks[:, None] + offsets])
    return 2 * np.linalg.solve(normal, rhs[..., None])[:, 2, 0]


def analyse_profile(x, z, source: str = "<profile>") -> SurfaceStatistics:
    """Asperity statistics of a profile x [m], z [m] (see the module docstring for each definition).

    Statistics that come out infinite, NaN or of zero spread (heights too small for floating point)
    are an :class:`InputError` naming the file's ``z_m``."""
    with quiet_numerics():
        z = level(x, z)
        peaks = find_peaks(z)
        curvature = peak_curvatures(x, z, peaks) if peaks.size else np.empty(0)
        curved = curvature < 0
        if peaks.size < 10 or curved.sum() < 10:
            raise InputError(f"has {peaks.size} peaks ({curved.sum()} curved); at least 10 are needed for the "
                             "statistics: give a longer or finer profile", source, "z_m")
        AR = float((x[peaks[-1]] - x[peaks[0]]) / (peaks.size - 1))
        Alt, SAlt = stats.norm.fit(z[peaks])
        a, _, scale = stats.lognorm.fit(-1 / curvature[curved] / RADIUS_UNIT_M, floc=0)
        statistics = (float(np.sqrt(np.mean(z * z))), 1.2 / AR ** 2, float(Alt), float(SAlt), float(a),
                      math.log(scale) if scale > 0 else math.nan)
    if not all(math.isfinite(v) for v in statistics) or SAlt <= 0 or a <= 0:
        raise InputError("its summit statistics are not finite numbers of some spread (rms, D_s, Alt, SAlt, a, b = "
                         f"{', '.join(f'{v:.3g}' for v in statistics)}): check the heights' units", source, "z_m")
    rq, density, Alt, SAlt, a, b = statistics
    return SurfaceStatistics(source, float(x[-1] - x[0]), rq, int(peaks.size), AR, density, Alt, SAlt, a, b)


def profile_statistics(path) -> SurfaceStatistics:
    """Read a profile CSV and return its asperity statistics."""
    x, z = read_profile(path)
    return analyse_profile(x, z, str(path))
