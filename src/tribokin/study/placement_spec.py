"""The ``[placement]`` of a study: the robot base positions and yaws searched for the one that serves the task
region (the study's ``[map]``) most repeatably.

The spec knows its candidates and their order; its values are checked when the study is read
(:mod:`tribokin.study.spec`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: ``placement.objective``: the statistic of the expected RP_l over a candidate's reachable targets that ranks it.
OBJECTIVES = ("p95", "max", "mean")

#: A box's base positions are rounded to 1e-DECIMALS m (as a map's grid values,
#: :data:`tribokin.maps.grid.GRID_DECIMALS`).
DECIMALS = 12

Vector3 = tuple[float, float, float]


@dataclass(frozen=True)
class Candidate:
    """One base placement searched: its place in the search (``index``), the base's position in the world
    ``base_xyz_m`` [m] and ``yaw_deg`` [deg], the turn about the world's vertical added to ``robot.base_rpy_deg``."""

    index: int
    base_xyz_m: Vector3
    yaw_deg: float


@dataclass(frozen=True)
class PlacementSpec:
    """The ``[placement]`` table: base positions as an explicit list ``candidates`` [m], or a box from
    ``base_xyz_m_min`` to ``base_xyz_m_max`` [m] in ``resolution`` = (nx, ny, nz) points (end points included);
    each tried at every ``yaw_deg`` [deg]; ranked by ``objective`` (:data:`OBJECTIVES`) of the expected RP_l over the
    targets a candidate reaches, a candidate reaching fewer than ``min_reachable`` [-] of the targets after every one
    that does."""

    candidates: tuple[Vector3, ...] | None
    base_xyz_m_min: Vector3 | None
    base_xyz_m_max: Vector3 | None
    resolution: tuple[int, int, int] | None
    yaw_deg: tuple[float, ...]
    objective: str
    min_reachable: float

    def positions_m(self) -> np.ndarray:
        """(n, 3) base positions [m]: the list as given, or the box's points, x fastest, then y, then z, rounded to
        ``DECIMALS`` decimals (the decimals the user wrote: ``-0.1``, not ``-0.09999999999999998``)."""
        if self.candidates is not None:
            return np.array(self.candidates, dtype=float)
        axes = [np.round(low + np.arange(count) * ((high - low) / (count - 1) if count > 1 else 0.0), DECIMALS) + 0.0
                for low, high, count in zip(self.base_xyz_m_min, self.base_xyz_m_max, self.resolution, strict=True)]
        z, y, x = np.meshgrid(axes[2], axes[1], axes[0], indexing="ij")
        return np.column_stack([x.ravel(), y.ravel(), z.ravel()])

    @property
    def candidate_count(self) -> int:
        """Positions × yaws."""
        positions = len(self.candidates) if self.candidates is not None else int(np.prod(self.resolution))
        return positions * len(self.yaw_deg)

    def search(self) -> list[Candidate]:
        """Every candidate, in the search's order: each position (:meth:`positions_m`) at each yaw, yaws fastest."""
        return [Candidate(p * len(self.yaw_deg) + k, tuple(float(v) for v in position), float(yaw))
                for p, position in enumerate(self.positions_m()) for k, yaw in enumerate(self.yaw_deg)]


def turned_rpy_deg(base_rpy_deg: Vector3 | None, yaw_deg: float) -> Vector3:
    """``robot.base_rpy_deg`` (``None``: zero) with ``yaw_deg`` [deg] added to its yaw, brought within ±360°
    (a whole turn less where the sum passes it), as a study may write it."""
    roll, pitch, yaw = base_rpy_deg or (0.0, 0.0, 0.0)
    turned = yaw + yaw_deg
    if abs(turned) > 360.0:
        turned -= 360.0 if turned > 0 else -360.0
    return float(roll), float(pitch), float(turned)
