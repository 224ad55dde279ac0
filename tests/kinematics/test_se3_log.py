"""The logarithm of rigid motions and its Jacobian, many at once (NumPy) and one at a time (the IK kernel's, compiled),
against Pinocchio's log6 and Jlog6: random motions, turns small enough for each of its series expansions, and turns of
nearly half a turn."""

import numpy as np
import pinocchio as pin
import pytest

from tribokin.kinematics import se3_log
from tribokin.kinematics.se3_log import PRECISION_2, PRECISION_3


def compiled_logs(rotations: np.ndarray, translations: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``se3_log.log6``'s outputs from the compiled kernel, motion by motion."""
    from tribokin.kinematics import se3_log_kernels

    logs, angles = np.empty((len(rotations), 6)), np.empty(len(rotations))
    for k, (rotation, translation) in enumerate(zip(rotations, translations, strict=True)):
        angles[k] = se3_log_kernels.log6(rotation, translation, logs[k])
    return logs, angles


def compiled_jacobians(rotation_vectors: np.ndarray, angles: np.ndarray, translations: np.ndarray) -> np.ndarray:
    """``se3_log.jlog6``'s outputs from the compiled kernel, motion by motion."""
    from tribokin.kinematics import se3_log_kernels

    jacobians = np.empty((len(angles), 6, 6))
    for k in range(len(angles)):
        se3_log_kernels.jlog6(np.ascontiguousarray(rotation_vectors[k]), angles[k], translations[k], jacobians[k])
    return jacobians


#: Each implementation's (log6, jlog6).
IMPLEMENTATIONS = {"numpy": (se3_log.log6, se3_log.jlog6), "compiled": (compiled_logs, compiled_jacobians)}


def motions(angles_rad, seed: int = 2) -> list[pin.SE3]:
    """Rigid motions turning by ``angles_rad`` about random axes, with random translations of about 1 m."""
    rng = np.random.default_rng(seed)
    axes = rng.normal(size=(len(angles_rad), 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    return [pin.SE3(pin.exp3(angle * axis), rng.normal(size=3)) for angle, axis in zip(angles_rad, axes, strict=True)]


def differences(placements: list[pin.SE3], implementation: str) -> tuple[np.ndarray, np.ndarray]:
    """Largest differences of ``implementation``'s from ``pin.log6`` and ``pin.Jlog6``, per motion."""
    log6, jlog6 = IMPLEMENTATIONS[implementation]
    rotations = np.array([m.rotation for m in placements])
    translations = np.array([m.translation for m in placements])
    logs, angles = log6(rotations, translations)
    jacobians = jlog6(logs[:, 3:], angles, translations)
    return (np.array([np.abs(log - pin.log6(m).vector).max() for log, m in zip(logs, placements, strict=True)]),
            np.array([np.abs(jacobian - pin.Jlog6(m)).max()
                      for jacobian, m in zip(jacobians, placements, strict=True)]))


@pytest.mark.parametrize("implementation", IMPLEMENTATIONS)
def test_log6_and_its_jacobian_match_pinocchio(implementation):
    """Agreement to rounding, up to the conditioning of the formulas just beyond the series' thresholds: there they
    cancel terms of order 1/θ², so that a one-ulp difference in sin θ or cos θ (NumPy's against the C library's)
    moves them by about 1e-17 / θ²."""
    thresholds = np.outer([PRECISION_2, PRECISION_3, np.sqrt(2 * PRECISION_2)], [0.5, 0.99, 1.01, 2]).ravel()
    angles = np.concatenate([10 ** np.random.default_rng(1).uniform(-12, np.log10(2.8), 2000), [0.0], thresholds])
    log_difference, jacobian_difference = differences(motions(angles), implementation)
    with np.errstate(divide="ignore"):
        tolerance = 1e-13 + 1e-16 / angles**2
    assert np.all(log_difference <= tolerance) and np.all(jacobian_difference <= tolerance)
    assert np.all(np.maximum(log_difference, jacobian_difference)[angles < PRECISION_3] < 1e-15)  # the series


@pytest.mark.parametrize("implementation", IMPLEMENTATIONS)
def test_near_a_half_turn_they_match_to_the_conditioning(implementation):
    """Within 0.35 rad of a half turn the logarithm is ill-conditioned: rounding of the rotation (1e-16) moves it by
    about 1e-16 / (π - θ)²; within 0.0035 rad (a trace within ``PRECISION_2`` of -1) it is Pinocchio's own."""
    gaps = np.array([0.35, 0.1, 0.03, 1e-2, 3e-3, 1e-4, 1e-7, 0.0])
    log_difference, jacobian_difference = differences(motions(np.pi - gaps), implementation)
    assert np.all(np.maximum(log_difference, jacobian_difference) < 1e-14 / np.maximum(gaps, 3e-3) ** 2)


def test_log3_of_small_turns_holds_their_angle_to_rounding():
    """``log3`` of rotations by 1e-12 to 1 rad (exact FK's orientation deviations: friction turns by 1e-6 to 1e-4
    rad) against ``pin.log3``, to 1e-15 of the angle below 1e-6 rad (measured 5e-16), and against the rotation vector
    each rotation was made from, to 1e-12 of the angle throughout (measured: 5e-13 near 2e-3 rad, as ``pin.log3``;
    ``pin.log3`` also 2e-13 near 1e-4 rad, where this is within 1.2e-14)."""
    rng = np.random.default_rng(3)
    vectors = 10 ** rng.uniform(-12, 0, 3000)[:, None] * rng.normal(size=(3000, 3))
    angles = np.linalg.norm(vectors, axis=1)
    rotations = np.array([pin.exp3(vector) for vector in vectors])
    logs = se3_log.log3(rotations)
    to_pinocchio = np.linalg.norm(logs - np.array([pin.log3(rotation) for rotation in rotations]), axis=1) / angles
    assert to_pinocchio[angles < 1e-6].max() <= 1e-15
    assert (np.linalg.norm(logs - vectors, axis=1) / angles).max() <= 1e-12
