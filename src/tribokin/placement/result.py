"""A placement search's results: per candidate base placement, the targets it reaches and its RP_l statistics, and
the ranking.

The ranking: a candidate reaching at least ``min_reachable`` of the targets ranks before every one that does not; then
the lower objective first (a candidate reaching no target has none and comes last), objectives equal to
``RANK_DIGITS`` significant digits tying (physically equal placements differ in the last digits, from the IK's
convergence); then the lower candidate index.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from tribokin.study.placement_spec import Candidate, PlacementSpec, turned_rpy_deg
from tribokin.study.spec import Study

#: Significant digits of the objective that rank candidates.
RANK_DIGITS = 9
#: The statistics of RP_l kept per candidate, in the order of :attr:`PlacementResult.RP_l_um`'s columns.
STATISTICS = ("mean", "p95", "max")


@dataclass(frozen=True)
class PlacementResult:
    """Every candidate of a search (:meth:`~tribokin.study.placement_spec.PlacementSpec.search`) and its figures.

    Attributes:
        study: the study searched (its ``placement``, and its text's source for ``best.toml``).
        candidates: in the search's order.
        target_count: targets of the task region (the ``[map]``), reachable or not.
        reachable: (n,) targets each candidate reaches.
        RP_l_um: (n, 3) mean, 95th percentile (linear interpolation, as :func:`numpy.percentile`) and maximum of the
            expected RP_l over the targets each candidate reaches [µm] (NaN: it reaches none).
    """

    study: Study = field(repr=False)
    candidates: list[Candidate]
    target_count: int
    reachable: np.ndarray
    RP_l_um: np.ndarray

    @property
    def spec(self) -> PlacementSpec:
        """The ``[placement]`` searched."""
        return self.study.placement

    @property
    def fraction(self) -> np.ndarray:
        """(n,) share of the targets each candidate reaches [-]."""
        return self.reachable / self.target_count

    @property
    def meets_min_reachable(self) -> np.ndarray:
        """(n,) whether each candidate reaches at least ``min_reachable`` of the targets."""
        return self.fraction >= self.spec.min_reachable

    @property
    def meeting_min_reachable(self) -> int:
        """How many candidates reach at least ``min_reachable`` of the targets."""
        return int(self.meets_min_reachable.sum())

    @property
    def objective_um(self) -> np.ndarray:
        """(n,) the ranking statistic of each candidate's RP_l [µm] (NaN: no target reached)."""
        return self.RP_l_um[:, STATISTICS.index(self.spec.objective)]

    @property
    def order(self) -> np.ndarray:
        """Candidate indices, best first (module docstring)."""
        objective = np.array([np.inf if np.isnan(v) else float(f"{v:.{RANK_DIGITS}g}") for v in self.objective_um])
        return np.lexsort((np.arange(len(self.candidates)), objective, ~self.meets_min_reachable))

    @property
    def ranks(self) -> np.ndarray:
        """(n,) each candidate's rank, 1 the best."""
        ranks = np.empty(len(self.candidates), dtype=int)
        ranks[self.order] = np.arange(1, len(self.candidates) + 1)
        return ranks

    @property
    def best(self) -> Candidate:
        return self.candidates[int(self.order[0])]

    def rpy_deg(self, candidate: Candidate) -> tuple[float, float, float]:
        """The base's roll, pitch, yaw in the world [deg] at ``candidate``: the study's, turned by its yaw."""
        return turned_rpy_deg(self.study.robot.base_rpy_deg, candidate.yaw_deg)

    def describe(self, candidate: Candidate) -> dict:
        """``candidate`` as ``summary.json`` gives it."""
        i = candidate.index
        return {"candidate": i, "base_xyz_m": list(candidate.base_xyz_m), "yaw_deg": candidate.yaw_deg,
                "base_rpy_deg": list(self.rpy_deg(candidate)), "reachable_targets": int(self.reachable[i]),
                "reachable_fraction": float(self.fraction[i]),
                "meets_min_reachable": bool(self.meets_min_reachable[i]), "rank": int(self.ranks[i]),
                "RP_l_um": {name: _number(value) for name, value in zip(STATISTICS, self.RP_l_um[i], strict=True)}}

    def summary(self) -> dict:
        """The ``placement`` block of ``summary.json``."""
        return {"objective": self.spec.objective, "min_reachable": self.spec.min_reachable,
                "candidates": len(self.candidates), "targets": self.target_count,
                "meeting_min_reachable": self.meeting_min_reachable,
                "yaw_deg": list(self.spec.yaw_deg), "best": self.describe(self.best)}

    def columns(self) -> dict[str, np.ndarray]:
        """``placement.csv``'s columns, one row per candidate, best first: the candidate's index, base position [m],
        added yaw [deg], the targets it reaches (count and share), RP_l's statistics [µm] (the objective's first),
        whether it meets ``min_reachable``, and its rank."""
        order = self.order
        positions = np.array([c.base_xyz_m for c in self.candidates])[order]
        statistics = sorted(STATISTICS, key=lambda name: name != self.spec.objective)
        return {"candidate": order, "base_x_m": positions[:, 0], "base_y_m": positions[:, 1],
                "base_z_m": positions[:, 2], "yaw_deg": np.array([c.yaw_deg for c in self.candidates])[order],
                "reachable_fraction": self.fraction[order], "reachable_targets": self.reachable[order],
                **{f"RP_l_{name}_um": self.RP_l_um[order, STATISTICS.index(name)] for name in statistics},
                "meets_min_reachable": self.meets_min_reachable[order], "rank": self.ranks[order]}


def _number(value: float) -> float | None:
    return None if np.isnan(value) else float(value)
