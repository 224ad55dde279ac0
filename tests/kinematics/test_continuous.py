"""Continuous joints (Pinocchio's RUBX/Y/Z: cosine and sine in its configuration) as revolute joints without limits:
Kinova's Gen3 against the same URDF with its continuous joints made revolute within ±1000 rad, whose configuration is
one angle per joint as tribokin's: placements, Jacobians, the batched chain, bearing loads, propagated deviations and
IK across ±π agree."""

import numpy as np
import pinocchio as pin
import pytest

from conftest import GEN3_URDF
from helpers.robots import wide_revolute_urdf
from tribokin.errors import ConfigurationError
from tribokin.kinematics.chain import serial_chain
from tribokin.kinematics.ik import solve_ik, solve_ik_batch
from tribokin.kinematics.loads import BearingLoads
from tribokin.kinematics.robot import load_urdf, wrap_angles
from tribokin.propagation.exact import tool_deviations, tool_deviations_exact

CONTINUOUS = ["joint_1", "joint_3", "joint_5", "joint_7"]





@pytest.fixture
def gen3_pair(tmp_path):
    """(continuous Gen3, the same with wide revolute joints), both measured at the default tool frame."""
    return load_urdf(GEN3_URDF), load_urdf(wide_revolute_urdf(tmp_path), "tool_frame")


def configurations(count: int, seed: int = 3) -> np.ndarray:
    """(count, 7) Gen3 configurations [rad]: the limited joints within their limits, the continuous ones over three
    turns (beyond ±π)."""
    rng = np.random.default_rng(seed)
    limits = np.array([3 * np.pi, 2.2, 3 * np.pi, 2.5, 3 * np.pi, 2.0, 3 * np.pi])
    return rng.uniform(-limits, limits, (count, 7))


def test_gen3_loads_with_its_continuous_joints_as_unlimited_revolute_joints():
    robot = load_urdf(GEN3_URDF)
    assert robot.joint_names == [f"joint_{i}" for i in range(1, 8)] and robot.model.nv == 7 and robot.model.nq == 11
    assert [name for name, c in zip(robot.joint_names, robot.continuous, strict=True) if c] == CONTINUOUS
    assert not robot.joint_is_prismatic.any()
    np.testing.assert_array_equal(robot.upper_limits, [np.inf, 2.24, np.inf, 2.57, np.inf, 2.09, np.inf])
    np.testing.assert_array_equal(robot.lower_limits, -robot.upper_limits)
    q = np.array([4.0, 0.5, -7.0, 1.0, 0.3, -0.4, 3.5])
    configuration = robot.configuration(q)  # (cos, sin) of each continuous joint, the others' angles
    np.testing.assert_array_equal(configuration, [np.cos(4.0), np.sin(4.0), 0.5, np.cos(-7.0), np.sin(-7.0), 1.0,
                                                  np.cos(0.3), np.sin(0.3), -0.4, np.cos(3.5), np.sin(3.5)])
    np.testing.assert_array_equal(robot.check_configuration(q), q)  # no limits on a continuous joint
    with pytest.raises(ConfigurationError, match="joint_2.*outside its limits"):
        robot.check_configuration(q + [0, 2, 0, 0, 0, 0, 0])
    drawn = np.array([robot.random_configuration(np.random.default_rng(s)) for s in range(200)])
    assert np.all(np.abs(drawn) <= np.pi) and np.all(np.abs(drawn[:, robot.continuous]).max(axis=0) > 3.0)


def test_placements_jacobians_and_loads_match_wide_revolute_joints(gen3_pair):
    continuous, revolute = gen3_pair
    assert revolute.model.nq == revolute.model.nv == 7 and not revolute.continuous.any()
    q = configurations(40)
    for qi in q:
        np.testing.assert_allclose(continuous.tool_placement(qi).homogeneous, revolute.tool_placement(qi).homogeneous,
                                   rtol=0, atol=1e-14)
        np.testing.assert_allclose(continuous.tool_jacobian(qi), revolute.tool_jacobian(qi), rtol=0, atol=1e-14)
    chain = serial_chain(continuous)
    assert chain is not None  # the batched path, not Pinocchio's one by one
    placements = chain.tool_in_joint(q)
    np.testing.assert_allclose(placements, serial_chain(revolute).tool_in_joint(q), rtol=0, atol=1e-14)
    spans = np.full(7, 0.1)
    batched, by_rnea = BearingLoads(continuous, 2.0, spans), BearingLoads(revolute, 2.0, spans)
    np.testing.assert_allclose(batched(q), by_rnea(q), rtol=1e-12)
    assert batched.chain is not None
    batched.chain = None  # RNEA at each configuration, through Pinocchio's (cos, sin)
    np.testing.assert_allclose(batched(q), by_rnea(q), rtol=1e-12)


@pytest.mark.parametrize("engine", ["fast", "exact"])
def test_deviations_across_pi_propagate_as_through_wide_revolute_joints(gen3_pair, engine):
    continuous, revolute = gen3_pair
    rng = np.random.default_rng(5)
    q = np.array([np.pi - 1e-4, 0.6, -np.pi + 2e-5, 1.2, np.pi, -0.7, -np.pi])  # deviations cross ±π
    dq = rng.normal(scale=2e-4, size=(500, 7))
    for reached, expected in zip(tool_deviations(continuous, q, dq, engine), tool_deviations(revolute, q, dq, engine),
                                 strict=True):
        np.testing.assert_allclose(reached, expected, rtol=0, atol=1e-15)
    positions, _ = tool_deviations_exact(continuous, q, dq)  # and as Pinocchio integrates its configuration
    model, data = continuous.model, continuous.data
    for position, step in zip(positions[:20], dq[:20], strict=True):
        pin.framesForwardKinematics(model, data, pin.integrate(model, continuous.configuration(q), step))
        np.testing.assert_allclose(position, data.oMf[continuous.tool_frame_id].translation, rtol=0, atol=1e-15)


def test_ik_crosses_pi_and_wraps_its_solution(gen3_pair, kernel_path):
    continuous, revolute = gen3_pair
    solution = np.array([3.05, 0.6, -3.0, 1.3, 3.1, -0.8, 2.9])
    target = continuous.tool_placement(solution)
    start = solution + np.array([0.15, 0.05, -0.2, 0.05, 0.12, 0.05, 0.3])  # continuous joints past ±π
    assert np.all(np.abs(start[continuous.continuous]) > np.pi)
    found = solve_ik(continuous, target, wrap_angles(start))  # starts at the other side of ±π
    unwrapped = solve_ik(revolute, target, start)
    assert found.success and unwrapped.success
    assert np.all(np.abs(found.q) <= np.pi)
    np.testing.assert_allclose(found.q, wrap_angles(unwrapped.q), rtol=0, atol=1e-9)
    assert np.abs(found.q - solution).max() < 0.2  # near the solution (a redundant arm's), not turns away
    np.testing.assert_allclose(continuous.tool_placement(found.q).homogeneous, target.homogeneous, atol=1e-9)
    targets = np.array([continuous.tool_placement(solution + [0.04 * k, 0, 0, 0, 0, 0, 0]).translation
                        for k in range(-3, 4)])  # joint_1 from 2.93 to 3.17 rad: across π
    rotation = target.rotation
    batch = solve_ik_batch(serial_chain(continuous), rotation, targets, np.tile(wrap_angles(start), (7, 1)))
    assert batch.success.all() and np.all(np.abs(batch.q) <= np.pi)
    assert (batch.q[:, 0] < 0).any() and (batch.q[:, 0] > 0).any()
    for position, q in zip(targets, batch.q, strict=True):
        alone = solve_ik(continuous, pin.SE3(rotation, position), wrap_angles(start))
        np.testing.assert_allclose(q, alone.q, rtol=0, atol=1e-9)
        np.testing.assert_allclose(continuous.tool_placement(q).translation, position, rtol=0, atol=1e-9)
