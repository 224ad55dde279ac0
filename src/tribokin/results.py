"""Results of a study: per-pose samples and ISO 9283 figures, in SI inside, µm/mdeg in reports."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from tribokin.iso9283 import PoseMetrics

if TYPE_CHECKING:
    from tribokin.robot import Robot
    from tribokin.targets import TargetGrid

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


#: Scalar figures of every map target, in map.csv order (µm, mdeg; ``dominant_share`` in [0, 1]).
MAP_FIGURES = ("RP_l_um", "AP_p_um", "RP_a_mdeg", "RP_b_mdeg", "RP_c_mdeg", "largest_semi_axis_um",
               "dominant_share")


def spread(values: np.ndarray) -> dict:
    """``{min, median, max}`` of the finite values (``None`` each when there are none)."""
    values = values[np.isfinite(values)]
    if not len(values):
        return {"min": None, "median": None, "max": None}
    return {"min": float(values.min()), "median": float(np.median(values)), "max": float(values.max())}


@dataclass
class ScenarioMap:
    """One scenario's figures at every target of a map; NaN where the target is unreachable.

    Attributes:
        name: scenario name. cycles: cycles per target.
        figures: (N, len(MAP_FIGURES)) columns as named by ``MAP_FIGURES``.
        normal_forces_N: (N, nv) bearing load of each joint [N].
        dominant_joint: (N,) index of the joint with the largest share of the position variance (-1: none).
    """

    name: str
    cycles: int
    figures: np.ndarray
    normal_forces_N: np.ndarray
    dominant_joint: np.ndarray

    def figure(self, name: str) -> np.ndarray:
        """The (N,) column ``name`` of ``MAP_FIGURES``."""
        return self.figures[:, MAP_FIGURES.index(name)]


@dataclass
class MapResult:
    """A workspace map: the targets, their configurations, and each scenario's figures there.

    Attributes:
        grid: the targets (positions [m], axes, held orientation).
        joint_names: active joints, in the order of ``q``.
        q: (N, nv) configurations [m or rad]; NaN where unreachable.
        reachable: (N,) whether IK reached the target. reasons: (N,) why not ("" when reachable; Python
            strings, so a long reason does not widen every row).
        scenarios: one :class:`ScenarioMap` per scenario; the first is the reference of comparisons.
    """

    grid: TargetGrid
    joint_names: list[str]
    q: np.ndarray
    reachable: np.ndarray
    reasons: np.ndarray
    scenarios: list[ScenarioMap]

    @property
    def reference(self) -> ScenarioMap:
        return self.scenarios[0]

    def ratio_RP_l(self, scenario: ScenarioMap) -> np.ndarray:
        """RP_l of ``scenario`` over the reference's [-] (NaN where the reference's is 0 or unreachable)."""
        reference = self.reference.figure("RP_l_um")
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(reference > 0, scenario.figure("RP_l_um") / reference, np.nan)

    def diff_RP_l_um(self, scenario: ScenarioMap) -> np.ndarray:
        """RP_l of ``scenario`` minus the reference's [µm]."""
        return scenario.figure("RP_l_um") - self.reference.figure("RP_l_um")

    def winners(self) -> np.ndarray:
        """(N,) index of the scenario with the smallest RP_l at each target; -1 for a tie or unreachable."""
        rp = np.column_stack([s.figure("RP_l_um") for s in self.scenarios])
        best = np.argmin(np.where(np.isnan(rp), np.inf, rp), axis=1)
        ties = (rp == rp.min(axis=1, keepdims=True)).sum(axis=1) > 1
        return np.where(self.reachable & ~ties, best, -1)

    def summary(self) -> dict:
        """The ``map`` block of ``summary.json``."""
        reference = self.reference
        dominant = reference.dominant_joint[self.reachable]
        block = {
            **self.grid.describe(),
            "count": int(self.grid.size),
            "reachable": int(self.reachable.sum()),
            "unreachable": int((~self.reachable).sum()),
            "cycles": reference.cycles,
            "RP_l_um": spread(reference.figure("RP_l_um")),
            "AP_p_um": spread(reference.figure("AP_p_um")),
            "dominant_joint_counts": {name: int((dominant == i).sum()) for i, name in enumerate(self.joint_names)},
        }
        if len(self.scenarios) > 1:
            winners = self.winners()
            block["scenarios"] = [{
                "name": s.name,
                "cycles": s.cycles,
                "RP_l_um": spread(s.figure("RP_l_um")),
                "RP_l_ratio": spread(self.ratio_RP_l(s)),
                "RP_l_diff_um": spread(self.diff_RP_l_um(s)),
            } for s in self.scenarios]
            block["wins"] = {s.name: int((winners == i).sum()) for i, s in enumerate(self.scenarios)}
            block["ties"] = int(((winners == -1) & self.reachable).sum())
        return block


#: What ``summary.json`` records the versions of (``reproduce.versions``), besides Python and tribokin:
#: name in the summary -> distribution.
RECORDED_DISTRIBUTIONS = {"numpy": "numpy", "scipy": "scipy", "pinocchio": "pin",
                          "example-robot-data": "example-robot-data"}


def software_versions() -> dict[str, str | None]:
    """Versions of Python, tribokin and ``RECORDED_DISTRIBUTIONS`` (``None``: not installed)."""
    import platform
    from importlib import metadata

    from tribokin import __version__

    versions = {"tribokin": __version__, "python": platform.python_version()}
    for name, distribution in RECORDED_DISTRIBUTIONS.items():
        try:
            versions[name] = metadata.version(distribution)
        except metadata.PackageNotFoundError:
            versions[name] = None
    return versions


@dataclass
class StudyResult:
    """Results of a whole study: ``poses`` in file order, the workspace ``map`` (if any), and what
    produced them (``robot``, for views; ``reproduce``: seed, study file hash, versions, command line)."""

    name: str
    poses: list[PoseResult]
    settings: dict
    robot: Robot | None = field(default=None, repr=False)
    map: MapResult | None = None
    reproduce: dict = field(default_factory=dict)

    def display_configuration(self) -> np.ndarray:
        """Where to draw the robot [m or rad]: the first pose, else the first reachable map target,
        else the robot's reference posture."""
        if self.poses:
            return self.poses[0].q
        if self.map is not None and self.map.reachable.any():
            return self.map.q[np.argmax(self.map.reachable)]
        return self.robot.reference_q

    def pose(self, name: str) -> PoseResult:
        """The pose called ``name``."""
        return next(p for p in self.poses if p.name == name)

    def table(self) -> dict[str, np.ndarray]:
        """Per-pose figures as columns: ``{"RP_l_um": array([...]), ...}`` (scalar figures only)."""
        rows = [p.report_row() for p in self.poses]
        if not rows:
            return {}
        return {key: np.array([r[key] if r[key] is not None else np.nan for r in rows])
                for key, value in rows[0].items() if value is None or isinstance(value, (int, float, str))}

    def summary(self) -> dict:
        """The content of ``summary.json``."""
        summary = {"study": self.settings, "reproduce": self.reproduce, "poses": [p.report_row() for p in self.poses]}
        if self.map is not None:
            summary["map"] = self.map.summary()
        return summary
