"""ISO 9283 pose accuracy and repeatability of n cycles at one commanded pose, per approach direction.

RP and AP are figures of one unidirectional series (:func:`pose_metrics`); a pose approached from
several directions has them per direction, and vAP across directions (:func:`directional_metrics`).
Positions in [m], angles in [rad]. Orientation deviations a, b, c are the
components, about the world x, y, z axes, of the rotation vector taking the
commanded orientation to the reached one (``log3(R_j R_c^T)``). They agree with
the roll-pitch-yaw angles of that deviation rotation ``R_j R_c^T`` to first order:
each component differs by at most about theta²/4 [rad], theta its angle (under 3e-9 rad
for deviations up to 100 µrad). The standard differences the
roll-pitch-yaw angles of the reached and commanded orientations themselves
(a_j - a_c); those agree with a, b, c to the same order only where the commanded
orientation is close to the base's axes. Elsewhere they differ at first order, by
the Jacobian of the roll-pitch-yaw angles at R_c, which mixes the axes.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np


@dataclass(frozen=True)
class PoseMetrics:
    """ISO 9283 figures of the cycles of one pose from one approach direction (SI units).

    Attributes:
        barycenter_m: (3,) barycenter of the reached positions [m].
        AP_p_m: position accuracy |barycenter - commanded| [m].
        RP_l_m: position repeatability l_bar + 3 S_l [m].
        AP_abc_rad: (3,) orientation accuracy: the mean deviation a, b, c [rad] (the standard's a_bar - a_c,
            b_bar - b_c, c_bar - c_c where the two agree, see the module).
        RP_abc_rad: (3,) orientation repeatability 3 S_a, 3 S_b, 3 S_c [rad] of the deviations a, b, c (the
            standard's +/- value).
        distances_m: (n,) l_j = |x_j - barycenter| [m].
    """

    barycenter_m: np.ndarray
    AP_p_m: float
    RP_l_m: float
    AP_abc_rad: np.ndarray
    RP_abc_rad: np.ndarray
    distances_m: np.ndarray


def _coordinates(points: np.ndarray) -> np.ndarray:
    """(..., 3, n) view of (..., n, 3) points: reductions over the samples run along the last axis
    (contiguous for the fast engine's output, so the batched map figures stay cheap)."""
    return np.swapaxes(points, -1, -2)


def barycenter(positions: np.ndarray) -> np.ndarray:
    """Mean of (..., n, 3) positions [m] (or of any n points' coordinates, (..., n, d)), summed relative to the first
    so identical points give it exactly."""
    coordinates = _coordinates(positions)
    first = coordinates[..., :1]
    return (first + (coordinates - first).mean(axis=-1, keepdims=True))[..., 0]


def _offsets(positions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Barycenter (..., 3) [m] of (..., n, 3) positions and their offsets x_j - barycenter (..., 3, n) [m]."""
    centre = barycenter(positions)
    return centre, _coordinates(positions) - centre[..., None]


def _repeatability(offsets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """RP_l = l_bar + 3 S_l [m] and the distances l_j [m] of offsets (..., 3, n) from the barycenter."""
    distances = np.sqrt(np.einsum("...kn,...kn->...n", offsets, offsets))
    spread = distances.std(axis=-1, ddof=1) if distances.shape[-1] > 1 else 0.0
    return distances.mean(axis=-1) + 3 * spread, distances


def _covariance(offsets: np.ndarray) -> np.ndarray:
    """(..., 3, 3) covariance [m²] of offsets (..., 3, n) from the barycenter (n - 1; zero for one sample)."""
    return np.einsum("...kn,...ln->...kl", offsets, offsets) / max(offsets.shape[-1] - 1, 1)


def position_repeatability(positions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """RP_l = l_bar + 3 S_l [m] and the distances l_j [m] of (..., n, 3) positions (S_l with n - 1)."""
    return _repeatability(_offsets(positions)[1])


def orientation_repeatability(angles: np.ndarray) -> np.ndarray:
    """RP_a, RP_b, RP_c = 3 S_a, 3 S_b, 3 S_c [rad] of (..., n, 3) orientation deviations (S with n - 1)."""
    coordinates = _coordinates(angles)
    ddof = 1 if coordinates.shape[-1] > 1 else 0
    return 3 * (coordinates - coordinates[..., :1]).std(axis=-1, ddof=ddof)


def covariance_semi_axes(positions: np.ndarray) -> np.ndarray:
    """1-sigma semi-axes [m] of the covariance ellipsoid of (..., n, 3) positions, largest first."""
    return _semi_axes(_covariance(_offsets(positions)[1]))


def _semi_axes(covariance: np.ndarray) -> np.ndarray:
    """1-sigma semi-axes [m], largest first, of (..., 3, 3) covariances [m²]."""
    return np.sqrt(np.clip(np.linalg.eigvalsh(covariance), 0, None))[..., ::-1]


class PositionSpread(NamedTuple):
    """Position figures of batches of cycles (arrays over the batch axes).

    Attributes:
        barycenter_m: (..., 3) barycenter [m].
        RP_l_m: position repeatability l_bar + 3 S_l [m].
        largest_semi_axis_m: largest 1-sigma semi-axis of the covariance ellipsoid [m].
    """

    barycenter_m: np.ndarray
    RP_l_m: np.ndarray
    largest_semi_axis_m: np.ndarray


def position_spread(positions: np.ndarray) -> PositionSpread:
    """Barycenter, RP_l and largest covariance semi-axis of (..., n, 3) positions, from one set of offsets."""
    centre, offsets = _offsets(positions)
    return PositionSpread(centre, _repeatability(offsets)[0], _semi_axes(_covariance(offsets))[..., 0])


def variance_contributions(position_jacobian: np.ndarray, dq: np.ndarray) -> np.ndarray:
    """Share of the tool-position variance due to each joint (sums to 1; NaN without variance).

    Linearised: joint i adds var(dq_i) |J_i|^2 to the trace of the position
    covariance, J_i the (3,) column of the (..., 3, nv) position Jacobian [m/unit];
    ``dq`` (..., n, nv).
    """
    per_joint = np.swapaxes(dq, -1, -2)  # (..., nv, n): contiguous rows for the map's deviations
    variances = per_joint.var(axis=-1, ddof=1) if dq.shape[-2] > 1 else np.zeros(per_joint.shape[:-1])
    parts = variances * np.sum(position_jacobian ** 2, axis=-2)
    total = parts.sum(axis=-1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(total > 0, parts / np.where(total > 0, total, 1.0), np.nan)


def largest_distance(points_m: np.ndarray) -> float:
    """The largest distance between two of the (k, 3) points [m] (0 for fewer than two), over their distinct points:
    scipy's ``pdist`` without importing ``scipy.spatial`` into every command (``benchmarks/startup.py`` times it)."""
    distinct = np.unique(points_m, axis=0)
    differences = distinct[:, None, :] - distinct[None, :, :]
    return float(np.sqrt(np.einsum("ijk,ijk->ij", differences, differences).max(initial=0.0)))


def multidirectional_variation(barycenters_m: np.ndarray) -> float | None:
    """vAP_p [m]: largest distance between the (k, 3) barycenters reached from k approach directions.

    ``None`` for fewer than two directions.
    """
    return largest_distance(barycenters_m) if len(barycenters_m) > 1 else None


def pose_metrics(positions: np.ndarray, angles: np.ndarray, commanded_position: np.ndarray) -> PoseMetrics:
    """ISO 9283 metrics of n cycles from one approach direction.

    Args:
        positions: (n, 3) reached tool positions [m].
        angles: (n, 3) orientation deviations a, b, c from the commanded orientation [rad].
        commanded_position: (3,) [m].
    """
    centre = barycenter(positions)
    rp_l, distances = position_repeatability(positions)
    return PoseMetrics(
        barycenter_m=centre,
        AP_p_m=float(np.linalg.norm(centre - commanded_position)),
        RP_l_m=float(rp_l),
        AP_abc_rad=angles.mean(axis=0),
        RP_abc_rad=orientation_repeatability(angles),
        distances_m=distances,
    )


@dataclass(frozen=True)
class DirectionalMetrics:
    """ISO 9283 figures of a pose tested from one or more approach directions (SI units).

    Attributes:
        directions: label -> :class:`PoseMetrics` of that direction's cycles, in the order of the labels;
            a direction with fewer than two cycles has none (S_l needs n - 1 >= 1).
        vAP_p_m: largest distance between those directions' barycenters [m]; ``None`` with one direction.
        RP_l_all_directions_m: l_bar + 3 S_l of every cycle pooled, about their common barycenter [m].
    """

    directions: dict[str, PoseMetrics]
    vAP_p_m: float | None
    RP_l_all_directions_m: float


def directional_metrics(positions: np.ndarray, angles: np.ndarray, commanded_position: np.ndarray,
                        approach: np.ndarray, labels) -> DirectionalMetrics:
    """ISO 9283 metrics of n cycles at one pose, per approach direction and across them.

    Args:
        positions: (n, 3) reached tool positions [m].
        angles: (n, 3) orientation deviations a, b, c from the commanded orientation [rad].
        commanded_position: (3,) [m].
        approach: (n,) index into ``labels`` of each cycle's approach direction.
        labels: name of each approach direction (``"+x"``...).
    """
    directions = {label: pose_metrics(positions[approach == k], angles[approach == k], commanded_position)
                  for k, label in enumerate(labels) if np.count_nonzero(approach == k) > 1}
    centres = np.array([m.barycenter_m for m in directions.values()]).reshape(-1, 3)
    return DirectionalMetrics(directions, multidirectional_variation(centres),
                              float(position_repeatability(positions)[0]))


#: Corner signs of the cube's diagonal plane holding P2-P5 (ISO 9283 §6.2): the plane through the
#: opposite edges (-,-,·) and (+,+,·); P2 (-,-,+), P3 (+,+,+), P4 (+,+,-), P5 (-,-,-).
DIAGONAL_PLANE_CORNERS = np.array([[-1, -1, 1], [1, 1, 1], [1, 1, -1], [-1, -1, -1]], dtype=float)


def cube_test_positions(center_m, side_m: float) -> dict[str, np.ndarray]:
    """ISO 9283 test positions P1-P5 [m] of a cube with edges parallel to the world axes.

    P1 is the centre; P2-P5 lie on a diagonal plane at 10 % of the cube's
    diagonal from its corners: P = c + 0.8 (C - c), C a corner of that plane.
    """
    center = np.asarray(center_m, dtype=float)
    points = {"P1": center}
    for k, corner in enumerate(DIAGONAL_PLANE_CORNERS):
        points[f"P{k + 2}"] = center + 0.8 * (side_m / 2) * corner
    return points
