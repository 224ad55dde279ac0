"""The measuring instrument's own spread, from readings of a robot standing still, and the figures it swamps.

The readings of a still target spread only by the instrument (and the room):
their l_bar + 3 S_l is the smallest RP_l the instrument can tell apart from
zero, and their largest per-axis standard deviation is the scale below which a 1-sigma
semi-axis is the instrument's as much as the robot's. A figure within ``factor`` (2) times the matching
floor is flagged: RP_l per direction, RP_l of all directions and vAP_p against
the RP_l floor; ellipsoid semi-axes against the largest per-axis deviation.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tribokin.errors import InputError
from tribokin.iso9283.metrics import position_repeatability
from tribokin.measurement.contract import Stream
from tribokin.measurement.figures import PoseFigures

FLAG_FACTOR = 2.0


@dataclass(frozen=True)
class NoiseFloor:
    """Spread of still readings (SI).

    Attributes:
        readings: number of readings.
        RP_l_m: l_bar + 3 S_l of the readings [m].
        std_m: (3,) standard deviation along x, y, z (n - 1) [m].
    """

    readings: int
    RP_l_m: float
    std_m: np.ndarray


@dataclass(frozen=True)
class Flag:
    """A figure within the flag factor of the noise floor.

    Attributes:
        pose: pose label.
        direction: approach label, or None for a figure across directions.
        figure: report name of the figure (e.g. ``"RP_l_um"``).
        value_m: the figure [m].
        floor_m: the floor it was compared with [m].
    """

    pose: str
    direction: str | None
    figure: str
    value_m: float
    floor_m: float


def noise_floor(stream: Stream) -> NoiseFloor:
    """Noise floor of a still-standing measurement (two readings at least)."""
    if len(stream.positions_m) < 2:
        raise InputError("a noise-floor measurement needs two readings at least", stream.source)
    rp_l, _ = position_repeatability(stream.positions_m)
    return NoiseFloor(len(stream.positions_m), float(rp_l), stream.positions_m.std(axis=0, ddof=1))


def flag_figures(figures: tuple[PoseFigures, ...], floor: NoiseFloor, factor: float = FLAG_FACTOR) -> tuple[Flag, ...]:
    """Every figure of ``figures`` at or below ``factor`` times its floor (module docstring), in pose order."""
    semi_axis_floor = float(floor.std_m.max())
    flags = []
    for pose in figures:
        checks = [(d.direction, "RP_l_um", d.RP_l_m, floor.RP_l_m) for d in pose.directions]
        checks += [(d.direction, f"ellipsoid_semi_axis_{k + 1}_um", axis, semi_axis_floor)
                   for d in pose.directions if d.semi_axes_m is not None for k, axis in enumerate(d.semi_axes_m)]
        checks += [(None, "RP_l_all_directions_um", pose.RP_l_all_directions_m, floor.RP_l_m),
                   (None, "vAP_p_um", pose.vAP_p_m, floor.RP_l_m)]
        flags += [Flag(pose.pose, direction, name, float(value), floor_m)
                  for direction, name, value, floor_m in checks
                  if value is not None and value <= factor * floor_m]
    return tuple(flags)
