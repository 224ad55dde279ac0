"""Results of a study: per-pose samples and ISO 9283 figures, in SI inside, µm/mdeg in reports."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from tribokin.iso9283 import PoseMetrics

if TYPE_CHECKING:
    from tribokin.robot import Robot

UM_PER_M = 1e6
MDEG_PER_RAD = 180e3 / np.pi


@dataclass
class PoseResult:
    """Everything sampled and measured at one commanded pose.

    Attributes:
        name: pose name. q: (nv,) commanded configuration [m or rad].
        commanded_position_m: (3,) [m]. commanded_rotation: (3, 3).
        reference_position_m: (3,) tool position with the joint offsets only (epsilon_t), no friction [m].
        positions_m: (n, 3) reached tool positions [m].
        angles_rad: (n, 3) orientation deviations a, b, c from the commanded orientation [rad].
        approach: (n,) approach-direction index of each cycle.
        mu: (n, nv) friction coefficients drawn [-]. dq: (n, nv) joint deviations [m or rad].
        normal_forces_N: (nv,) bearing loads [N].
        metrics: the ISO 9283 figures.
    """

    name: str
    q: np.ndarray
    commanded_position_m: np.ndarray
    commanded_rotation: np.ndarray
    reference_position_m: np.ndarray
    positions_m: np.ndarray
    angles_rad: np.ndarray
    approach: np.ndarray
    mu: np.ndarray
    dq: np.ndarray
    normal_forces_N: np.ndarray
    metrics: PoseMetrics
    extra: dict = field(default_factory=dict)

    @property
    def cycles(self) -> int:
        return len(self.positions_m)

    def report_row(self) -> dict:
        """The pose's figures under the report names (µm, mdeg), as in ``summary.json``."""
        m = self.metrics
        row = {
            "name": self.name,
            "q": self.q.tolist(),
            "cycles": self.cycles,
            "commanded_position_m": self.commanded_position_m.tolist(),
            "barycenter_m": m.barycenter_m.tolist(),
            "AP_p_um": m.AP_p_m * UM_PER_M,
            "RP_l_um": m.RP_l_m * UM_PER_M,
        }
        for axis, ap in zip("abc", m.AP_abc_rad):
            row[f"AP_{axis}_mdeg"] = float(ap * MDEG_PER_RAD)
        for axis, rp in zip("abc", m.RP_abc_rad):
            row[f"RP_{axis}_mdeg"] = float(rp * MDEG_PER_RAD)
        row["vAP_p_um"] = None if m.vAP_p_m is None else m.vAP_p_m * UM_PER_M
        row["normal_forces_N"] = self.normal_forces_N.tolist()
        row.update(self.extra)
        return row


@dataclass
class StudyResult:
    """Results of a whole study: ``poses`` in file order, plus what produced them (``robot``, for views)."""

    name: str
    poses: list[PoseResult]
    settings: dict
    robot: Robot | None = field(default=None, repr=False)

    def pose(self, name: str) -> PoseResult:
        """The pose called ``name``."""
        return next(p for p in self.poses if p.name == name)

    def table(self) -> dict[str, np.ndarray]:
        """Per-pose figures as columns: ``{"RP_l_um": array([...]), ...}`` (scalar figures only)."""
        rows = [p.report_row() for p in self.poses]
        return {key: np.array([r[key] if r[key] is not None else np.nan for r in rows])
                for key, value in rows[0].items() if value is None or isinstance(value, (int, float, str))}

    def summary(self) -> dict:
        """The content of ``summary.json``."""
        return {"study": self.settings, "poses": [p.report_row() for p in self.poses]}
