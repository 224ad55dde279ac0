"""Results of one pose: its samples and ISO 9283 figures, in SI inside, µm/mdeg in reports."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from tribokin.errors import import_extra
from tribokin.iso9283.metrics import DirectionalMetrics
from tribokin.kinematics.robot import Robot
from tribokin.output.dispatch import result_figures, result_scene
from tribokin.units import MDEG_PER_RAD, UM_PER_M


@dataclass(frozen=True)
class PoseResult:
    """Everything sampled and measured at one commanded pose, from each of its approach directions.

    Attributes:
        name: pose name. q: (nv,) commanded configuration [m or rad].
        commanded_position_m: (3,) [m]. commanded_rotation: (3, 3).
        reference_position_m: (3,) tool position with the joint offsets only (epsilon_t), no friction [m].
        positions_m: (n, 3) reached tool positions [m], every direction's cycles.
        angles_rad: (n, 3) orientation deviations a, b, c from the commanded orientation [rad].
        directions: label of each approach direction tested (``"+"``, ``"+x"``...).
        approach: (n,) index into ``directions`` of each cycle's approach direction.
        mu: (n, nv) friction coefficients drawn [-]. dq: (n, nv) joint deviations [m or rad].
        normal_forces_N: (nv,) bearing loads [N].
        metrics: the ISO 9283 figures, per direction and across directions.
        extra: further figures of the pose. direction_extra: further figures per direction label.
        joint_names: the active joints, in the order of ``q`` (names the columns of :meth:`to_pandas`).
        robot: the robot tested, which the 3-D scene draws (:meth:`_repr_html_`; ``None``: no scene).
    """

    name: str
    q: np.ndarray
    commanded_position_m: np.ndarray
    commanded_rotation: np.ndarray
    reference_position_m: np.ndarray
    positions_m: np.ndarray
    angles_rad: np.ndarray
    directions: tuple[str, ...]
    approach: np.ndarray
    mu: np.ndarray
    dq: np.ndarray
    normal_forces_N: np.ndarray
    metrics: DirectionalMetrics
    extra: dict = field(default_factory=dict)
    direction_extra: dict[str, dict] = field(default_factory=dict)
    joint_names: tuple[str, ...] = ()
    robot: Robot | None = field(default=None, repr=False, compare=False)

    def samples(self) -> dict[str, np.ndarray]:
        """The arrays of one value (row) per cycle, by name: what ``samples.npz`` keeps of the pose."""
        return {"positions_m": self.positions_m, "angles_rad": self.angles_rad, "dq": self.dq, "mu": self.mu,
                "approach": self.approach}

    @property
    def cycles(self) -> int:
        """Cycles at the pose, all directions together."""
        return len(self.positions_m)

    def direction_figures(self, label: str) -> dict:
        """The ISO 9283 figures (µm, mdeg) of the cycles from approach direction ``label``."""
        m = self.metrics.directions[label]
        figures = {
            "cycles": int(np.count_nonzero(self.approach == self.directions.index(label))),
            "barycenter_m": m.barycenter_m.tolist(),
            "AP_p_um": m.AP_p_m * UM_PER_M,
            "RP_l_um": m.RP_l_m * UM_PER_M,
        }
        for axis, ap in zip("abc", m.AP_abc_rad, strict=True):
            figures[f"AP_{axis}_mdeg"] = float(ap * MDEG_PER_RAD)
        for axis, rp in zip("abc", m.RP_abc_rad, strict=True):
            figures[f"RP_{axis}_mdeg"] = float(rp * MDEG_PER_RAD)
        figures.update(self.direction_extra.get(label, {}))
        return figures

    def report_row(self) -> dict:
        """The pose's figures under the report names (µm, mdeg), as in ``summary.json``: the pose's own,
        those across its directions, and ``directions``, label -> :meth:`direction_figures`."""
        m = self.metrics
        return {
            "name": self.name,
            "cycles": self.cycles,
            "commanded_position_m": self.commanded_position_m.tolist(),
            "vAP_p_um": None if m.vAP_p_m is None else m.vAP_p_m * UM_PER_M,
            "RP_l_all_directions_um": m.RP_l_all_directions_m * UM_PER_M,
            "q": self.q.tolist(),
            "normal_forces_N": self.normal_forces_N.tolist(),
            **self.extra,
            "directions": {label: self.direction_figures(label) for label in m.directions},
        }

    def direction_rows(self) -> list[dict]:
        """One flat row per approach direction: ``name``, ``direction``, that direction's figures, then
        the pose's (its ``cycles`` those of the direction), as in ``poses.csv``."""
        pose = self.report_row()
        directions = pose.pop("directions")
        del pose["name"], pose["cycles"]
        return [{"name": self.name, "direction": label, **figures, **pose} for label, figures in directions.items()]

    def to_pandas(self):
        """The pose's rows of ``poses.csv`` (one per approach direction, :meth:`direction_rows`) as a pandas DataFrame:
        the same columns and numbers (units in the names: ``RP_l_um``, ``q_<joint>``), NaN where the file's cell is
        empty; a pose's own friction law is its ``describe()`` dict, whose text the file holds (pandas:
        ``pip install 'tribokin[data]'``)."""
        return pose_frame(self.direction_rows(), list(self.joint_names))

    def figures(self) -> dict:
        """The pose's repeatability field (the PNG ``tribokin run`` writes of it, titled with its name) as a
        matplotlib ``Figure``, by its file name in an output folder (``pose_<name>.png``)."""
        return result_figures(self)  # viz.notebook.pose_figures

    def _repr_html_(self) -> str | None:
        """A notebook's view: the robot at the pose with its cycle cloud, the report's 3-D scene inline (no server,
        offline); ``None`` (text) when the robot is not known."""
        return result_scene(self)  # viz.notebook.pose_scene


#: poses.csv columns of the vector figures that are not per joint or per world axis: key -> element names.
POSE_VECTOR_COLUMNS = {"ellipsoid_semi_axes_um": ("ellipsoid_semi_axis_1_um", "ellipsoid_semi_axis_2_um",
                                                  "ellipsoid_semi_axis_3_um"),
                       "RP_l_95_um": ("RP_l_95_low_um", "RP_l_95_high_um"),
                       "RP_l_95_mc_error": ("RP_l_95_low_mc_error", "RP_l_95_high_mc_error")}


def pose_table_row(row: dict, joints: list[str], missing="") -> dict:
    """A flat poses.csv row of a report row (:meth:`PoseResult.direction_rows`): positions split into ``_x_m, _y_m,
    _z_m``, ``q`` into ``q_<joint>``, bearing loads into ``normal_force_<joint>_N``, the other vectors as in
    ``POSE_VECTOR_COLUMNS``; a figure there is none of is ``missing`` (poses.csv: an empty cell)."""
    flat = {}
    for key, value in row.items():
        if key == "q":
            flat.update({f"q_{joint}": v for joint, v in zip(joints, value, strict=True)})
        elif key == "normal_forces_N":
            flat.update({f"normal_force_{joint}_N": v for joint, v in zip(joints, value, strict=True)})
        elif key in POSE_VECTOR_COLUMNS:
            flat.update(zip(POSE_VECTOR_COLUMNS[key], value or (missing,) * len(POSE_VECTOR_COLUMNS[key]), strict=True))
        elif key == "drift":  # its figures and settings; their errors and bands in summary.json only
            flat.update({f"drift_{name}": v for name, v in value.items() if not isinstance(v, dict)})
        elif isinstance(value, list) and key.endswith("_m"):
            flat.update({f"{key[:-2]}_{axis}_m": v for axis, v in zip("xyz", value, strict=True)})
        else:
            flat[key] = missing if value is None else value
    return flat


def pose_frame(rows: list[dict], joints: list[str]):
    """The rows of poses.csv (report rows, :func:`pose_table_row`) as a pandas DataFrame, its columns in the order of
    their first appearance, an empty cell NaN."""
    pandas = import_extra("pandas", "to_pandas()")
    flat = [pose_table_row(row, joints, np.nan) for row in rows]
    return pandas.DataFrame(flat, columns=list(dict.fromkeys(key for row in flat for key in row)))
