"""Drift of pose characteristics over a measured series (ISO 9283, "drift of pose characteristics").

The standard defines the drift of position accuracy and of position
repeatability as the change of each between the start and the end of a test
of duration T:

    dAP_p = |AP_p(t=1) - AP_p(t=T)|,    dRP_l = |RP_l(t=1) - RP_l(t=T)|,

and likewise dRP_a, dRP_b, dRP_c for orientation. Here AP and RP at the start
and at the end are those of the first and of the last ``cycles_per_set``
cycles of the series in time order (at most half of its cycles each, so the two
sets never share a cycle); a series needs four cycles. Positions are taken as
:func:`~tribokin.measurement.figures.pose_clouds` gives them (registered, and
referred to their own commanded positions, when a registration is given).
The standard's own test (the robot cycled from cold for hours, at one pose) is
not checked: these figures are what the file's times allow.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tribokin.iso9283.metrics import barycenter, orientation_repeatability, position_repeatability
from tribokin.measurement.contract import Pose, Series
from tribokin.measurement.figures import pose_clouds, position_accuracy, wrapped
from tribokin.measurement.registration import Registration
from tribokin.units import MDEG_PER_RAD, UM_PER_M

CYCLES_PER_SET = 10


@dataclass(frozen=True)
class Drift:
    """Drift of one series between its first and last set of cycles (SI).

    Attributes:
        direction: approach label of the series.
        cycles_per_set: cycles in each set.
        start_s, end_s: (2,) first and last time of the first and of the last set [s].
        dAP_p_m: |AP_p(first) - AP_p(last)| [m], or None without commanded positions.
        dRP_l_m: |RP_l(first) - RP_l(last)| [m].
        dRP_abc_rad: (3,) |RP_a/b/c(first) - RP_a/b/c(last)| [rad], or None without orientation.
        barycenter_shift_m: distance between the two sets' barycentres [m] (not an ISO figure).
    """

    direction: str
    cycles_per_set: int
    start_s: np.ndarray
    end_s: np.ndarray
    dAP_p_m: float | None
    dRP_l_m: float
    dRP_abc_rad: np.ndarray | None
    barycenter_shift_m: float

    def report_row(self) -> dict:
        """The drift under report names (µm, mdeg, s)."""
        row = {"direction": self.direction, "cycles_per_set": self.cycles_per_set,
               "first_set_s": self.start_s.tolist(), "last_set_s": self.end_s.tolist(),
               "dAP_p_um": None if self.dAP_p_m is None else self.dAP_p_m * UM_PER_M,
               "dRP_l_um": self.dRP_l_m * UM_PER_M}
        for k, axis in enumerate("abc"):
            row[f"dRP_{axis}_mdeg"] = None if self.dRP_abc_rad is None else float(self.dRP_abc_rad[k] * MDEG_PER_RAD)
        row["barycenter_shift_um"] = self.barycenter_shift_m * UM_PER_M
        return row


def series_drift(series: Series, positions_m: np.ndarray, commanded_m: np.ndarray | None,
                 cycles_per_set: int = CYCLES_PER_SET) -> Drift | None:
    """Drift of a series with times, from its (n, 3) ``positions_m`` [m] and the (n, 3) commanded positions
    they are referred to [m] (None: no dAP); None without times or below 4 cycles."""
    n = len(series.cycles)
    if series.times_s is None or n < 4:
        return None
    size = max(2, min(cycles_per_set, n // 2))
    order = np.argsort(series.times_s, kind="stable")
    first, last = order[:size], order[-size:]
    dap = None
    if commanded_m is not None:
        dap = abs(position_accuracy(positions_m[first], commanded_m[first])
                  - position_accuracy(positions_m[last], commanded_m[last]))
    drp_abc = None
    if series.angles_rad is not None:
        angles = wrapped(series.angles_rad)
        drp_abc = np.abs(orientation_repeatability(angles[first]) - orientation_repeatability(angles[last]))
    return Drift(
        direction=series.direction,
        cycles_per_set=size,
        start_s=series.times_s[first][[0, -1]],
        end_s=series.times_s[last][[0, -1]],
        dAP_p_m=dap,
        dRP_l_m=float(abs(position_repeatability(positions_m[first])[0]
                          - position_repeatability(positions_m[last])[0])),
        dRP_abc_rad=drp_abc,
        barycenter_shift_m=float(np.linalg.norm(barycenter(positions_m[first]) - barycenter(positions_m[last]))),
    )


def pose_drift(pose: Pose, registration: Registration | None = None,
               cycles_per_set: int = CYCLES_PER_SET) -> tuple[Drift, ...]:
    """Drift of each series of the pose that has times and four or more cycles."""
    clouds = pose_clouds(pose, registration)
    commanded = clouds.commanded_m or [None] * len(pose.series)
    drifts = (series_drift(series, points, reference, cycles_per_set)
              for series, points, reference in zip(pose.series, clouds.positions_m, commanded, strict=True))
    return tuple(d for d in drifts if d is not None)
