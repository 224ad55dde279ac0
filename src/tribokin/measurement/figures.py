"""ISO 9283 figures of measured poses: per pose and approach direction, and across directions.

Per unidirectional series of two or more cycles: RP_l, the 1-sigma covariance
ellipsoid, a bootstrap 95 % interval of RP_l, AP_p (with commanded positions)
and RP_a/b/c (with orientation). Per pose: vAP_p between the barycentres of
those series and RP_l of the pooled cloud of all its rows (one-cycle series included).

Frames: with a :class:`~tribokin.measurement.registration.Registration` the
positions are first moved into the world frame; without one they are used as
measured, so AP_p is right only when the instrument measures in the world frame.

Re-taught commanded positions: with a registration, each row is referred to its
own commanded position, x'_j = x_j - (c_j - c_bar) with c_bar the pose's mean
commanded position; without one the rows are used as measured (``commanded_corrected``
False) and ``commanded_spread_m`` says by how much the commanded positions differed.
AP_p = |mean_j (x'_j - c_bar)| = |mean_j (x_j - c_j)| over the series either way.

Bootstrap interval of RP_l: percentile bootstrap over cycles: ``resamples`` draws
of n cycles with replacement from the series' n, from
``numpy.random.default_rng([seed, pose index, series index])`` (same numbers every run);
the interval runs from the 2.5th to the 97.5th percentile of their RP_l. The draws are made and measured in
blocks of resamples of about ``BOOTSTRAP_BLOCK_CYCLES`` cycles in all (at least one resample), in the order of one
draw of them all, so a series of any length takes a bounded memory (:func:`bootstrap_bytes`) and the same
numbers as one draw.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from tribokin.iso9283.metrics import (
    barycenter,
    covariance_semi_axes,
    largest_distance,
    multidirectional_variation,
    orientation_repeatability,
    position_repeatability,
)
from tribokin.measurement.contract import Measurements, Pose, Series
from tribokin.measurement.registration import Registration
from tribokin.units import MDEG_PER_RAD, UM_PER_M, um

BOOTSTRAP_RESAMPLES = 2000
BOOTSTRAP_SEED = 9283
#: Cycles of the bootstrap's resamples drawn and measured at once (a few tens of MiB).
BOOTSTRAP_BLOCK_CYCLES = 2 ** 19
#: Bytes per cycle of a block of resamples: its index (8), its positions (24), their offsets (24), distances (8),
#: rounded up for NumPy's temporaries.
BOOTSTRAP_BYTES_PER_CYCLE = 128


@dataclass(frozen=True)
class DirectionFigures:
    """ISO 9283 figures of one unidirectional series (SI).

    Attributes:
        direction: approach label.
        cycles: number of cycles.
        barycenter_m: (3,) barycentre [m] (world frame when registered).
        RP_l_m: l_bar + 3 S_l [m]; None for a series too short for RP (one cycle).
        RP_l_ci95_m: (low, high) percentile-bootstrap 95 % interval of RP_l [m], or None.
        semi_axes_m: (3,) 1-sigma semi-axes of the covariance ellipsoid, largest first [m], or None.
        AP_p_m: |mean (x_j - c_j)| [m], or None without commanded positions.
        RP_abc_rad: (3,) 3 S_a, 3 S_b, 3 S_c [rad] about the measuring frame's axes, or None.
    """

    direction: str
    cycles: int
    barycenter_m: np.ndarray
    RP_l_m: float | None
    RP_l_ci95_m: tuple[float, float] | None
    semi_axes_m: np.ndarray | None
    AP_p_m: float | None
    RP_abc_rad: np.ndarray | None

    @property
    def too_short(self) -> bool:
        """One cycle: no RP of its own."""
        return self.RP_l_m is None


@dataclass(frozen=True)
class PoseFigures:
    """ISO 9283 figures of one measured pose (SI).

    Attributes:
        pose: pose label.
        directions: figures of each series, in file order.
        vAP_p_m: largest distance between the barycentres of its series of two or more cycles [m];
            None with fewer than two such series.
        RP_l_all_directions_m: l_bar + 3 S_l of the pooled cloud of all its rows [m].
        commanded_spread_m: largest distance between two of its rows' commanded positions [m], or None.
        commanded_corrected: rows were referred to their own commanded positions (needs a registration
            and commanded positions that differ).
        registered: positions were moved into the world frame by a registration.
    """

    pose: str
    directions: tuple[DirectionFigures, ...]
    vAP_p_m: float | None
    RP_l_all_directions_m: float
    commanded_spread_m: float | None
    commanded_corrected: bool
    registered: bool

    def report_rows(self) -> list[dict]:
        """One row per direction under the report names of ``run`` (µm, mdeg), pose figures on each row."""
        rows = []
        for d in self.directions:
            row = {"pose": self.pose, "direction": d.direction, "cycles": d.cycles,
                   "too_short_for_RP": d.too_short,
                   "RP_l_um": um(d.RP_l_m), "AP_p_um": um(d.AP_p_m)}
            for axis, value in zip("abc", d.RP_abc_rad if d.RP_abc_rad is not None else (None,) * 3, strict=True):
                row[f"RP_{axis}_mdeg"] = None if value is None else float(value * MDEG_PER_RAD)
            row["RP_l_95_um"] = None if d.RP_l_ci95_m is None else [v * UM_PER_M for v in d.RP_l_ci95_m]
            row["ellipsoid_semi_axes_um"] = None if d.semi_axes_m is None else (d.semi_axes_m * UM_PER_M).tolist()
            row.update(vAP_p_um=um(self.vAP_p_m), RP_l_all_directions_um=um(self.RP_l_all_directions_m),
                       commanded_spread_um=um(self.commanded_spread_m),
                       commanded_corrected=self.commanded_corrected, registered=self.registered)
            rows.append(row)
        return rows


def at_once(cycles: int, block_cycles: int) -> int:
    """Resamples (or simulated tests) of ``cycles`` cycles each drawn and measured at once: about ``block_cycles``
    cycles in all, at least one."""
    return max(1, block_cycles // max(1, cycles))


def bootstrap_bytes(cycles: int, resamples: int = BOOTSTRAP_RESAMPLES) -> int:
    """Bytes the bootstrap of a series of ``cycles`` holds at once (a block of resamples) [bytes]."""
    return min(resamples, at_once(cycles, BOOTSTRAP_BLOCK_CYCLES)) * cycles * BOOTSTRAP_BYTES_PER_CYCLE


def rp_l_interval(positions_m: np.ndarray, resamples: int, rng: np.random.Generator) -> tuple[float, float]:
    """Percentile-bootstrap 95 % interval of RP_l [m] of (n, 3) positions: ``resamples`` draws of n
    cycles with replacement, 2.5th and 97.5th percentiles of their RP_l (drawn and measured in blocks of
    :func:`at_once` resamples, the numbers of one draw of them all)."""
    n = len(positions_m)
    block = at_once(n, BOOTSTRAP_BLOCK_CYCLES)
    rp_l = np.empty(resamples)
    for start in range(0, resamples, block):
        draws = rng.integers(0, n, size=(min(block, resamples - start), n))
        rp_l[start:start + len(draws)], _ = position_repeatability(positions_m[draws])
    low, high = np.percentile(rp_l, [2.5, 97.5])
    return float(low), float(high)


def position_accuracy(positions_m: np.ndarray, commanded_m: np.ndarray) -> float:
    """AP_p = |mean_j (x_j - c_j)| [m] of (n, 3) positions and their rows' commanded positions."""
    return float(np.linalg.norm(barycenter(positions_m - commanded_m)))


def wrapped(angles_rad: np.ndarray) -> np.ndarray:
    """(n, 3) angles as deviations from the first row, wrapped to [-pi, pi) [rad]."""
    return (angles_rad - angles_rad[0] + np.pi) % (2 * np.pi) - np.pi


def _direction_figures(series: Series, positions_m: np.ndarray, commanded_m: np.ndarray | None, resamples: int,
                       rng: np.random.Generator) -> DirectionFigures:
    ap = None if commanded_m is None else position_accuracy(positions_m, commanded_m)
    if series.too_short:
        return DirectionFigures(series.direction, 1, barycenter(positions_m), None, None, None, ap, None)
    rp_l, _ = position_repeatability(positions_m)
    return DirectionFigures(
        direction=series.direction,
        cycles=len(series.cycles),
        barycenter_m=barycenter(positions_m),
        RP_l_m=float(rp_l),
        RP_l_ci95_m=rp_l_interval(positions_m, resamples, rng),
        semi_axes_m=covariance_semi_axes(positions_m),
        AP_p_m=ap,
        RP_abc_rad=None if series.angles_rad is None else orientation_repeatability(wrapped(series.angles_rad)),
    )


class Clouds(NamedTuple):
    """A pose's series as the figures use them (module docstring).

    Attributes:
        positions_m: per series, (n, 3) positions [m].
        commanded_m: per series, (n, 3) commanded position each row is referred to [m]
            (the pose's mean when corrected), or None without commanded positions.
        commanded_spread_m: largest distance between two of the pose's commanded positions [m], or None.
        commanded_corrected: rows were referred to their own commanded positions.
    """

    positions_m: list[np.ndarray]
    commanded_m: list[np.ndarray] | None
    commanded_spread_m: float | None
    commanded_corrected: bool


def pose_clouds(pose: Pose, registration: Registration | None) -> Clouds:
    """The pose's series registered (with a registration) and referred to their own commanded positions
    (with a registration and commanded positions that differ)."""
    positions = [s.positions_m if registration is None else registration.to_base(s.positions_m)
                 for s in pose.series]
    commanded = pose.pooled("commanded_m")
    if commanded is None:
        return Clouds(positions, None, None, False)
    spread = largest_distance(commanded)
    if registration is None or spread == 0:
        return Clouds(positions, [s.commanded_m for s in pose.series], spread, False)
    mean = commanded.mean(axis=0)
    return Clouds([points - (s.commanded_m - mean) for points, s in zip(positions, pose.series, strict=True)],
                  [np.broadcast_to(mean, s.commanded_m.shape) for s in pose.series], spread, True)


def pose_figures(pose: Pose, registration: Registration | None = None, resamples: int = BOOTSTRAP_RESAMPLES,
                 seed: int = BOOTSTRAP_SEED, pose_index: int = 0) -> PoseFigures:
    """Figures of one pose; the bootstrap draws from ``default_rng([seed, pose_index, series index])``."""
    clouds = pose_clouds(pose, registration)
    commanded = clouds.commanded_m or [None] * len(pose.series)
    directions = tuple(
        _direction_figures(series, points, reference, resamples, np.random.default_rng([seed, pose_index, k]))
        for k, (series, points, reference) in enumerate(zip(pose.series, clouds.positions_m, commanded, strict=True)))
    long_enough = [points for series, points in zip(pose.series, clouds.positions_m, strict=True)
                   if not series.too_short]
    vap = multidirectional_variation(np.array([barycenter(points) for points in long_enough]))
    rp_all, _ = position_repeatability(np.concatenate(clouds.positions_m))
    return PoseFigures(pose.name, directions, vap, float(rp_all), clouds.commanded_spread_m,
                       clouds.commanded_corrected, registration is not None)


def measurement_figures(measurements: Measurements, registration: Registration | None = None,
                        resamples: int = BOOTSTRAP_RESAMPLES, seed: int = BOOTSTRAP_SEED) -> tuple[PoseFigures, ...]:
    """Figures of every pose, in file order."""
    return tuple(pose_figures(pose, registration, resamples, seed, index)
                 for index, pose in enumerate(measurements.poses))
