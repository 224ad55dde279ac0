"""Rigid registration of the measuring frame (a tracker's) to the world frame.

A least-squares rigid fit (rotation and translation, no scale) of the poses'
measured barycentres to their commanded positions, by
``scipy.spatial.transform.Rotation.align_vectors`` on the centred point sets
(the Kabsch solution). It needs commanded positions at three or more poses that
are not collinear; otherwise the frame cannot be registered.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tribokin.iso9283.metrics import barycenter
from tribokin.measurement.contract import Measurements

#: Poses are collinear when the second singular value of their centred commanded positions is below
#: this fraction of the first.
COLLINEAR_RATIO = 1e-6

UNAVAILABLE = "the measuring frame is not registered: that needs commanded positions at three or more poses " \
              "that are not on one line"


@dataclass(frozen=True)
class Registration:
    """``p_base = rotation @ p_measuring + translation_m``.

    Attributes:
        rotation: (3, 3) rotation of the measuring frame into the world frame.
        translation_m: (3,) [m].
        rms_residual_m: root mean square of |registered barycentre - commanded| over the poses [m].
        poses: names of the poses fitted.
    """

    rotation: np.ndarray
    translation_m: np.ndarray
    rms_residual_m: float
    poses: tuple[str, ...]

    def to_base(self, points_m: np.ndarray) -> np.ndarray:
        """(..., 3) points of the measuring frame in the world frame [m]."""
        return points_m @ self.rotation.T + self.translation_m


def register(measured_m: np.ndarray, commanded_m: np.ndarray, poses: tuple[str, ...] = ()) -> Registration | None:
    """Rigid least-squares fit of (k, 3) measured points to (k, 3) commanded points [m].

    None when fewer than three points are given or they are collinear (the rotation about their line
    is then undetermined).
    """
    if len(commanded_m) < 3:
        return None
    measured_centre, commanded_centre = measured_m.mean(axis=0), commanded_m.mean(axis=0)
    singular = np.linalg.svd(commanded_m - commanded_centre, compute_uv=False)
    if singular[1] <= COLLINEAR_RATIO * singular[0]:
        return None
    from scipy.spatial.transform import Rotation  # here: scipy.spatial's import is not free (benchmarks/startup.py)

    rotation = Rotation.align_vectors(commanded_m - commanded_centre, measured_m - measured_centre)[0].as_matrix()
    translation = commanded_centre - rotation @ measured_centre
    residual = measured_m @ rotation.T + translation - commanded_m
    return Registration(rotation, translation, float(np.sqrt(np.mean(np.sum(residual ** 2, axis=1)))),
                        tuple(poses))


def register_measurements(measurements: Measurements) -> Registration | None:
    """Register the frame on each pose's barycentre (all its rows) and mean commanded position.

    None without commanded positions or with fewer than three non-collinear poses (:data:`UNAVAILABLE`).
    """
    if measurements.poses[0].pooled("commanded_m") is None:
        return None
    measured = np.array([barycenter(p.pooled("positions_m")) for p in measurements.poses])
    commanded = np.array([p.pooled("commanded_m").mean(axis=0) for p in measurements.poses])
    return register(measured, commanded, tuple(p.name for p in measurements.poses))
