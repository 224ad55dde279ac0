"""The logarithm of rotations and rigid motions and its Jacobian for many at once, in NumPy: Pinocchio's ``log3``,
``log6`` and ``Jlog6`` (as in Pinocchio 4, branch for branch, series expansions included), so that a batch agrees
with them to rounding. (Pinocchio's ``log3`` first makes the rotation orthonormal again, a change of the order of
1e-16 for the rotations given here, which are; here a trace that rounding took past 3 counts as 3.)

A rigid motion is a rotation (3, 3) and a translation (3,) [m]; its logarithm is a motion vector (linear [m],
angular [rad]), as Pinocchio's ``Motion.vector``.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

EPSILON = np.finfo(float).eps
#: Pinocchio's ``TaylorSeriesExpansion<double>::precision<2>()`` and ``precision<3>()``: near these angles [rad] (or
#: traces this close to 3 or -1) its formulas switch to series expansions.
PRECISION_2 = EPSILON ** (1 / 3)
PRECISION_3 = EPSILON ** (1 / 4)
#: ``v @ _SKEW_BASIS`` is ``[v]×`` (3, 3) flattened, for vectors ``v`` (..., 3).
_SKEW_BASIS = np.array([pin.skew(axis) for axis in np.eye(3)]).reshape(3, 9)


def skew(vectors: np.ndarray) -> np.ndarray:
    """(..., 3, 3) matrices ``[v]×`` (``[v]× u = v × u``) of ``vectors`` (..., 3)."""
    return (vectors @ _SKEW_BASIS).reshape(*vectors.shape[:-1], 3, 3)


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(k, 3) cross products of ``a`` and ``b`` (k, 3)."""
    return (skew(a) @ b[:, :, None])[:, :, 0]


def _unskew(matrices: np.ndarray) -> np.ndarray:
    """(k, 3) the vector of the antisymmetric part of ``matrices`` (k, 3, 3) (Pinocchio's ``unSkew``)."""
    return matrices.reshape(-1, 9) @ (0.5 * _SKEW_BASIS.T)  # each sums two entries (the rest by 0: exact)


def _log3(rotations: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Rotation vectors (k, 3) [rad] of ``rotations`` (k, 3, 3) (``pin.log3``), their angles (k,) [rad] in [0, π], and
    the rotations' traces (k,) and squared norms of their antisymmetric parts' vectors (k,) (sin² of the angles).

    Within about ``PRECISION_2`` of a half turn (a trace below ``-1 + 2 PRECISION_2``) each is Pinocchio's own
    ``log3``, one by one (rare)."""
    trace = rotations[:, 0, 0] + rotations[:, 1, 1] + rotations[:, 2, 2]
    cos = (trace - 1) / 2
    expansion = np.sqrt(np.maximum(2 * (1 - cos), 0.0) + EPSILON**2)
    angles = np.where(trace <= 3 - PRECISION_2,
                      np.where(trace >= -1 + PRECISION_2, np.arccos(np.clip(cos, -1.0, 1.0)), np.pi - expansion),
                      expansion)
    antisymmetric = _unskew(rotations)
    squared = (antisymmetric * antisymmetric).sum(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        scale = np.where(angles >= PRECISION_2, angles / np.sin(angles), 1 + squared / 6 + squared * squared * 3 / 40)
    vectors = scale[:, None] * antisymmetric
    for k in np.flatnonzero(cos < -1 + PRECISION_2):
        vectors[k] = pin.log3(rotations[k])
        angles[k] = np.linalg.norm(vectors[k])
    return vectors, angles, trace, squared


def log3(rotations: np.ndarray) -> np.ndarray:
    """Rotation vectors (k, 3) [rad] of ``rotations`` (k, 3, 3): ``pin.log3`` of each, to rounding (near no turn, to
    about 1e-15 of the angle)."""
    return _log3(rotations)[0]


def log6(rotations: np.ndarray, translations: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Logarithms (k, 6) of the rigid motions ``rotations`` (k, 3, 3), ``translations`` (k, 3) [m] (``pin.log6``),
    and the angles (k,) [rad] of their rotations (as ``log3`` finds them, for :func:`jlog6`)."""
    angular, angles, trace, squared = _log3(rotations)
    near = trace >= 3 - PRECISION_2
    with np.errstate(divide="ignore", invalid="ignore"):  # 0/0 at no turn, where the series replace the formulas
        sin, cos = np.sin(angles), np.cos(angles)
        alpha = np.where(near, 1 - squared / 12 - squared * squared / 720, angles * sin / (2 * (1 - cos)))
        beta = np.where(near, 1 / 12 + squared / 720, 1 / (angles * angles) - sin / (2 * angles * (1 - cos)))
    along = (angular * translations).sum(axis=1)
    linear = alpha[:, None] * translations - 0.5 * _cross(angular, translations) + (beta * along)[:, None] * angular
    return np.concatenate([linear, angular], axis=1), angles


def jlog6(rotation_vectors: np.ndarray, angles: np.ndarray, translations: np.ndarray) -> np.ndarray:
    """Jacobians (k, 6, 6) of :func:`log6` (``pin.Jlog6``) at the rigid motions of rotation vectors
    ``rotation_vectors`` (k, 3) [rad] and angles ``angles`` (k,) [rad] (as :func:`log6` gives them) and translations
    ``translations`` (k, 3) [m]."""
    w, p = rotation_vectors, translations
    angles_squared = angles * angles
    small = angles < PRECISION_3
    series = 1 / 12 + angles_squared / 720
    with np.errstate(divide="ignore", invalid="ignore"):  # 0/0 at no turn, where the series replace the formulas
        sin, cos = np.sin(angles), np.cos(angles)
        half_cotangent = sin / (1 - cos)  # cot(θ/2); the rest in Pinocchio's order of operations
        inverse = 1 / angles
        inverse_squared, inverse_2_2cos = inverse * inverse, 1 / (2 * (1 - cos))
        rotation_beta = np.where(small, series, 1 / angles_squared - half_cotangent / (2 * angles))
        diagonal = np.where(small, 0.5 * (2 - angles_squared / 6), 0.5 * (angles * half_cotangent))
        beta = np.where(small, series, inverse_squared - sin * inverse * inverse_2_2cos)
        beta_dot_over_theta = np.where(small, 1 / 360, -2 * inverse_squared * inverse_squared
                                       + (1 + sin * inverse) * inverse_squared * inverse_2_2cos)
    along = (w * p).sum(axis=1)
    identity = np.eye(3)
    rotation_block = (rotation_beta[:, None, None] * w[:, :, None] * w[:, None, :]
                      + diagonal[:, None, None] * identity + skew(0.5 * w))  # Jlog3
    towards = ((beta_dot_over_theta * along)[:, None] * w
               - (angles_squared * beta_dot_over_theta + 2 * beta)[:, None] * p)
    coupling = (towards[:, :, None] * w[:, None, :] + (beta[:, None] * w)[:, :, None] * p[:, None]
                + (along * beta)[:, None, None] * identity + skew(0.5 * p))
    jacobians = np.zeros((len(angles), 6, 6))
    jacobians[:, :3, :3] = jacobians[:, 3:, 3:] = rotation_block
    jacobians[:, :3, 3:] = coupling @ rotation_block
    return jacobians
