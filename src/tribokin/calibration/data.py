"""Measured clouds and the kinematics at their poses, as plain arrays, and their sufficient statistics.

Points and Jacobians must be given in the same frame (any frame: the likelihood uses only
covariances and differences of barycentres, which a rigid change of frame turns alike).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np


@dataclass(frozen=True, eq=False)
class SeriesData:
    """One unidirectional series: the cycles measured after approaching from one direction.

    Attributes:
        direction: approach label.
        signs: (nv,) approach sign of each joint (+1, -1, or 0 for a joint that does not move).
        points_m: (n, 3) measured tool positions [m]. A one-cycle series (n = 1) has no spread but
            its barycentre still differs from the pose's other directions'.
        times_s: (n,) times of the readings [s] (their time order, where it is not the cycles'), or None.
    """

    direction: str
    signs: np.ndarray
    points_m: np.ndarray
    times_s: np.ndarray | None = None


@dataclass(frozen=True, eq=False)
class PoseData:
    """The series measured at one pose and the joint model's inputs there.

    Attributes:
        label: pose label.
        jacobian: (3, nv) position Jacobian of the tool point at the pose [m/rad | m/m].
        torque_mean: (nv,) mean friction torque (force) of each joint at the pose [N·m | N].
        torque_std: (nv,) its standard deviation [N·m | N].
        series: one or more unidirectional series.
    """

    label: str
    jacobian: np.ndarray
    torque_mean: np.ndarray
    torque_std: np.ndarray
    series: tuple[SeriesData, ...]


@dataclass(frozen=True, eq=False)
class SeriesStack:
    """All series of several poses stacked along a first axis of length m (series count).

    Attributes:
        jacobian: (m, 3, nv) the Jacobian of each series' pose.
        signs: (m, nv).
        torque_mean, torque_std: (m, nv) of each series' pose.
        cycles: (m,) number of cycles n.
        mean_m: (m, 3) barycentre of each series [m].
        scatter_m2: (m, 3, 3) sum over cycles of (x - mean)(x - mean)^T [m²].
        pose_index: (m,) index of each series' pose in ``poses``.
        poses: the pose labels.
    """

    jacobian: np.ndarray
    signs: np.ndarray
    torque_mean: np.ndarray
    torque_std: np.ndarray
    cycles: np.ndarray
    mean_m: np.ndarray
    scatter_m2: np.ndarray
    pose_index: np.ndarray
    poses: tuple[str, ...]

    @cached_property
    def pose_matrix(self) -> np.ndarray:
        """(n_poses, m) 1 where a series belongs to a pose, else 0."""
        return (np.arange(len(self.poses))[:, None] == self.pose_index[None, :]).astype(float)

    @cached_property
    def pose_centred_mean_m(self) -> np.ndarray:
        """(m, 3) each barycentre less the mean barycentre of its pose [m]."""
        pose_matrix = self.pose_matrix
        pose_centres = pose_matrix @ self.mean_m / pose_matrix.sum(axis=1)[:, None]
        return self.mean_m - pose_matrix.T @ pose_centres

    @cached_property
    def first_of_pose(self) -> np.ndarray:
        """(m,) index of the first series of each series' pose."""
        return np.array([np.flatnonzero(self.pose_index == p)[0] for p in self.pose_index])


def stack(poses: list[PoseData] | tuple[PoseData, ...]) -> SeriesStack:
    """Stack the series of ``poses`` and reduce each to its count, barycentre and scatter matrix.

    Raises:
        ValueError: a series without cycles, or arrays of inconsistent shapes.
    """
    rows = [(i, pose, series) for i, pose in enumerate(poses) for series in pose.series]
    nv = np.shape(poses[0].jacobian)[1]
    for _, pose, series in rows:
        if np.shape(pose.jacobian) != (3, nv) or np.shape(series.signs) != (nv,):
            raise ValueError(f"pose {pose.label!r}: the Jacobian must be (3, {nv}) and the signs ({nv},)")
        if np.ndim(series.points_m) != 2 or np.shape(series.points_m)[1] != 3 or len(series.points_m) < 1:
            raise ValueError(f"pose {pose.label!r}, direction {series.direction!r}: points must be (n >= 1, 3)")
    points = [np.asarray(s.points_m, dtype=float) for _, _, s in rows]
    means = np.array([p.mean(axis=0) for p in points])
    centred = [p - m for p, m in zip(points, means, strict=True)]
    return SeriesStack(
        jacobian=np.array([p.jacobian for _, p, _ in rows], dtype=float),
        signs=np.array([s.signs for _, _, s in rows], dtype=float),
        torque_mean=np.array([p.torque_mean for _, p, _ in rows], dtype=float),
        torque_std=np.array([p.torque_std for _, p, _ in rows], dtype=float),
        cycles=np.array([len(p) for p in points]),
        mean_m=means,
        scatter_m2=np.array([c.T @ c for c in centred]),
        pose_index=np.array([i for i, _, _ in rows]),
        poses=tuple(p.label for p in poses),
    )
