"""Whether a measured series' cycles are independent: the lag-one autocorrelation of its deviations with its 95 %
interval, and the Ljung-Box portmanteau test (:mod:`tribokin.tribology.series_fit`, as ``fit-friction`` gives them
for a tribometer log).

A series is taken in time order: by ``t_s`` where the rows have times (a stable sort), else in cycle order.

Deviations: each cycle's signed offset from the series' barycentre along the cloud's main axis (the eigenvector of
the largest semi-axis of its covariance ellipsoid), u_j = (x_j − x̄)·e₁ [m]. Signed, because a correlated friction
moves the tool to one side of its barycentre for many cycles and then to the other: in the linear model a joint's
friction moves it along one direction, so u_j is the friction's own AR(1) and keeps its lag-one correlation ρ.
The distance l_j = |x_j − x̄| that RP_l is built from drops the side: for a Gaussian AR(1) its lag-one correlation
is (2/π)(ρ·asin ρ + √(1 − ρ²) − 1)/(1 − 2/π), 0.33 at ρ = 0.6, about ρ², and a 30-cycle test would miss most of
it. x̄ and e₁ depend on the set of cycles, not on their order, so under independence the order of u_j is as
random as the cycles' and the test keeps its level.

A series of fewer than :data:`MIN_CYCLES` cycles, or whose cycles all lie at one point, has no figures (``None``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tribokin.measurement.contract import Pose, Series
from tribokin.measurement.figures import pose_clouds
from tribokin.measurement.registration import Registration
from tribokin.tribology.series_fit import INDEPENDENCE_LEVEL, Estimate, LjungBox, fit_ar1, ljung_box

#: The fewest cycles a series is tested on: Ljung-Box then has 2 lags (min(10, n // 5)) and Bartlett's interval of
#: r₁ a half-width of at most 0.62.
MIN_CYCLES = 10
#: ``summary.json``'s ``settings.independence.deviations``.
DEVIATIONS = "each cycle's signed offset from the series' barycentre along the cloud's main axis, in time order"


@dataclass(frozen=True)
class Independence:
    """A series' test of independence.

    Attributes:
        direction: approach label of the series.
        cycles: its cycles.
        lag1: the deviations' lag-one autocorrelation with its 95 % interval (Bartlett's AR(1) variance
            (1 − r₁²)/n), or ``None`` (too short, or no spread).
        ljung_box: the Ljung-Box test over min(10, n // 5) lags, or ``None``.
    """

    direction: str
    cycles: int
    lag1: Estimate | None
    ljung_box: LjungBox | None

    def report_fields(self) -> dict:
        """``summary.json``'s fields of the series (``None`` where untested)."""
        lag1, box = self.lag1, self.ljung_box
        return {"lag1_autocorrelation": None if lag1 is None else lag1.value,
                "lag1_interval": None if lag1 is None else [lag1.low, lag1.high],
                "ljung_box_q": None if box is None else box.q,
                "ljung_box_lags": None if box is None else box.lags,
                "ljung_box_p": None if box is None else box.pvalue,
                "independent": None if box is None else box.independent}


def main_axis(positions_m: np.ndarray) -> np.ndarray:
    """(3,) the unit eigenvector of the largest eigenvalue of (n, 3) positions' scatter about their barycentre."""
    offsets = positions_m - positions_m.mean(axis=0)
    return np.linalg.eigh(offsets.T @ offsets)[1][:, -1]


def deviations(positions_m: np.ndarray) -> np.ndarray:
    """(n,) signed offsets [m] of (n, 3) positions from their barycentre along their covariance's main axis."""
    return (positions_m - positions_m.mean(axis=0)) @ main_axis(positions_m)


def time_order(n: int, times_s: np.ndarray | None) -> np.ndarray:
    """(n,) the indices of a series' n cycles in time order: by ``times_s`` (a stable sort) where given, else as
    they are (cycle order)."""
    return np.arange(n) if times_s is None else np.argsort(times_s, kind="stable")


def series_independence(series: Series, positions_m: np.ndarray) -> Independence:
    """The test of a series from its (n, 3) ``positions_m`` [m] (as the figures take them), in time order."""
    n = len(series.cycles)
    if n < MIN_CYCLES:
        return Independence(series.direction, n, None, None)
    if np.all(positions_m == positions_m[0]):
        return Independence(series.direction, n, None, None)
    u = deviations(positions_m[time_order(n, series.times_s)])
    return Independence(series.direction, n, fit_ar1(u), ljung_box(u))


def pose_independence(pose: Pose, registration: Registration | None = None) -> tuple[Independence, ...]:
    """The test of each series of the pose, in its order, on the positions the figures take
    (:func:`~tribokin.measurement.figures.pose_clouds`)."""
    clouds = pose_clouds(pose, registration)
    return tuple(series_independence(series, points)
                 for series, points in zip(pose.series, clouds.positions_m, strict=True))


def independence_settings() -> dict:
    """``summary.json``'s ``settings.independence``: what was tested and how."""
    return {"deviations": DEVIATIONS, "min_cycles": MIN_CYCLES, "lag1_interval": "95 %, Bartlett: (1 - r1^2)/n",
            "ljung_box_lags": "min(10, cycles // 5)", "level": INDEPENDENCE_LEVEL}
