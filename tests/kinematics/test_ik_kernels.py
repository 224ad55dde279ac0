"""The compiled IK kernel's single solves against Pinocchio's solve_ik (the NumPy path): steps from a rotation within
a hair of a half turn (Pinocchio's own log3 branch), the stall rule (patience), and Pinocchio's path kept on request."""

import numpy as np
import pinocchio as pin
import pytest

from tribokin.kinematics.ik import solve_ik
from tribokin.kinematics.robot import load_example_robot
from tribokin.kinematics.se3_log import PRECISION_2

START = np.array([0.0, -1.2, 1.6, -2.0, -1.57, 0.0])


@pytest.fixture(scope="module")
def ur5():
    return load_example_robot("ur5")


def on_both_paths(monkeypatch, *arguments, **options):
    """``solve_ik(*arguments, **options)`` on the NumPy path (Pinocchio), then compiled."""
    results = []
    for path in ("numpy", "compiled"):
        monkeypatch.setenv("TRIBOKIN_KERNELS", path)
        results.append(solve_ik(*arguments, **options))
    return results


def assert_same(expected, found, atol: float = 1e-12):
    np.testing.assert_allclose(found.q, expected.q, rtol=0, atol=atol)
    assert found.success == expected.success
    for name in ("position_error_m", "angle_error_rad"):
        assert getattr(found, name) == pytest.approx(getattr(expected, name), rel=1e-9, abs=1e-13)


@pytest.mark.parametrize("gap_rad", [1e-3, 1e-6, 0.0])
def test_steps_from_nearly_a_half_turn_follow_pinocchio(ur5, monkeypatch, gap_rad):
    """The target turned by π - gap from the start's tool frame: a trace within ``2 PRECISION_2`` of -1, where the
    logarithm is Pinocchio's log3 (axis from the largest diagonal entry, angle by atan2); the formula away from a half
    turn divides by sin θ there and would miss by far more than 1e-12."""
    tool = ur5.tool_placement(START)
    axis = np.array([1.0, 2.0, 2.0]) / 3.0
    target = pin.SE3(tool.rotation @ pin.exp3((np.pi - gap_rad) * axis),
                     ur5.tool_placement(START + [0.2, 0.1, -0.1, 0.1, 0.2, 0.1]).translation)
    assert np.trace(tool.rotation.T @ target.rotation) < -1 + 2 * PRECISION_2
    for iterations in (0, 1, 2):
        expected, found = on_both_paths(monkeypatch, ur5, target, START, iterations=iterations)
        assert_same(expected, found)
    assert found.angle_error_rad > 1.8  # two steps still far from the target: the branch was taken at each start
    if gap_rad < 1e-3:  # and on to the end (from 1e-3 the solve crosses a singular configuration: see solve_ik)
        expected, found = on_both_paths(monkeypatch, ur5, target, START)
        assert expected.success and found.success
        assert_same(expected, found)


@pytest.mark.parametrize("position_only", [True, False])
def test_patience_stops_where_pinocchios_solve_stops(ur5, monkeypatch, position_only):
    """Damping 1000 (steps of about 0.1 % of the error): the stall rule stops the solve after 3 iterations (position
    only) or after about 200 (the pose: the first steps make more progress), where solve_ik's stops."""
    target = ur5.tool_placement(START + [0.3, 0.2, -0.3, 0.2, 0.3, 0.2])
    options = dict(position_only=position_only, damping=1000.0)
    expected, found = on_both_paths(monkeypatch, ur5, target, START, patience=3, **options)
    assert_same(expected, found)
    without = solve_ik(ur5, target, START, **options)
    assert np.abs(without.q - found.q).max() > 1e-6  # it did stop early
    if position_only:
        np.testing.assert_array_equal(found.q, solve_ik(ur5, target, START, iterations=3, **options).q)


def test_pinocchios_path_on_request(ur5, monkeypatch):
    """From a stretched arm to a target 0.8 m away, the iterates cross singular configurations: compiled, the solve ends
    elsewhere than Pinocchio's (rounding magnified), and with ``pinocchio`` exactly where it does."""
    stretched = np.array([0.0, -np.pi / 2, 0.0, -np.pi / 2, 0.0, 0.0])
    target = pin.SE3(pin.rpy.rpyToMatrix(np.pi, 0.0, np.pi / 2), np.array([0.3, -0.5, 0.1]))
    expected, compiled = on_both_paths(monkeypatch, ur5, target, stretched)
    assert np.abs(compiled.q - expected.q).max() > 1e-6  # (seen: Pinocchio's reaches it, the kernel's does not)
    found = solve_ik(ur5, target, stretched, pinocchio=True)
    assert found.q.tobytes() == expected.q.tobytes() and found.position_error_m == expected.position_error_m
