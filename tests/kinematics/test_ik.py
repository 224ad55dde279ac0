"""Damped-least-squares IK of many targets at once, on both kernel paths, against solve_ik target by target through
Pinocchio: the same iterates, to rounding, with the tool's orientation held or not, on the UR5 and the prismatic
gantry; reachable targets and unreachable ones (which run to the iteration cap, on the NumPy path alone after the
batch's first iterations, and fail alike: their iterates, steps of a nearly singular system clipped to the joint
limits, soon depend on every rounding)."""

import numpy as np
import pinocchio as pin
import pytest

from conftest import ROOT
from tribokin.kinematics.chain import serial_chain
from tribokin.kinematics.ik import BATCH_ITERATIONS, solve_ik, solve_ik_batch, solve_ik_with_restarts
from tribokin.kinematics.robot import load_example_robot, load_urdf

#: The tool pointing down, as on studies/ur5-map-horizontal.toml.
DOWN = pin.rpy.rpyToMatrix(*np.radians([180.0, 0.0, 90.0]))


def ur5_targets(position_only: bool):
    """The UR5, about 30 reachable targets on a plane 0.1 m above its base and 6 beyond its reach (1 m from its base
    axis), warm starts 0.02 rad from a solution (from a reachable target's solution for those beyond the reach)."""
    robot = load_example_robot("ur5")
    rng = np.random.default_rng(11)
    start = np.array([0.0, -1.2, 1.6, -2.0, -1.57, 0.0])
    reached, starts = [], []
    for position in np.column_stack([rng.uniform(-0.5, 0.5, 40), rng.uniform(-0.8, -0.25, 40), np.full(40, 0.1)]):
        result = solve_ik_with_restarts(robot, pin.SE3(DOWN, position), start, rng, position_only=position_only)
        if result.success:
            reached.append(position)
            starts.append(result.q + rng.normal(scale=0.02, size=6))
    assert len(reached) > 25
    beyond = np.array(reached[:6]) * [1.0, 1.0, 0.0] / np.linalg.norm(np.array(reached[:6])[:, :2], axis=1,
                                                                      keepdims=True) + [0.0, 0.0, 0.1]
    return robot, DOWN, np.vstack([reached, beyond]), np.vstack([starts, np.array(starts[:6])]), position_only, 6


def gantry_targets(position_only: bool):
    """The prismatic gantry (tool = (0.2 + x, y, 0.2 + z) m), 30 targets within its travel and 3 beyond it, warm
    starts anywhere within the limits."""
    robot = load_urdf(ROOT / "urdf" / "cartesian_xyz.urdf", "tool")
    rng = np.random.default_rng(12)
    positions = np.vstack([rng.uniform([0.2, 0.0, 0.2], [0.8, 0.6, 0.7], (30, 3)), [[1.0, 0.3, 0.4], [0.5, -0.2, 0.4],
                                                                                  [0.5, 0.3, 0.9]]])
    starts = rng.uniform(robot.lower_limits, robot.upper_limits, (len(positions), 3))
    return robot, np.eye(3), positions, starts, position_only, 3


CASES = {
    "ur5, tool pointing down": lambda: ur5_targets(False),
    "ur5, position only": lambda: ur5_targets(True),
    "gantry, orientation held": lambda: gantry_targets(False),
    "gantry, position only": lambda: gantry_targets(True),
}


@pytest.fixture(scope="module", params=CASES)
def case(request):
    return CASES[request.param]()


def one_by_one(robot, rotation, positions, starts, position_only, **options):
    return [solve_ik(robot, pin.SE3(rotation, p), q, position_only=position_only, **options)
            for p, q in zip(positions, starts, strict=True)]


@pytest.mark.parametrize("iterations", [200, BATCH_ITERATIONS - 2, BATCH_ITERATIONS + 1])
def test_the_batch_follows_solve_ik(case, iterations, kernel_path, monkeypatch):
    """The batch on each kernel path (the compiled kernel, or NumPy then Pinocchio) against Pinocchio's solve_ik."""
    robot, rotation, positions, starts, position_only, beyond = case
    batch = solve_ik_batch(serial_chain(robot), rotation, positions, starts, position_only=position_only,
                           iterations=iterations)
    monkeypatch.setenv("TRIBOKIN_KERNELS", "numpy")
    alone = one_by_one(robot, rotation, positions, starts, position_only, iterations=iterations)
    np.testing.assert_array_equal(batch.success, [r.success for r in alone])
    reachable = slice(0, len(positions) - beyond)
    np.testing.assert_allclose(batch.q[reachable], [r.q for r in alone[reachable]], rtol=0, atol=1e-12)
    for name in ("position_error_m", "angle_error_rad"):
        np.testing.assert_allclose(getattr(batch, name)[reachable], [getattr(r, name) for r in alone[reachable]],
                                   rtol=1e-6, atol=1e-12)
    if iterations == 200:
        assert batch.success[reachable].all() and not batch.success[reachable.stop:].any()


def test_each_target_is_solved_as_if_alone(case, kernel_path):
    robot, rotation, positions, starts, position_only, _ = case
    chain = serial_chain(robot)
    together = solve_ik_batch(chain, rotation, positions, starts, position_only=position_only)
    for k in (0, 5, len(positions) - 1):  # the last one: beyond the reach, finished alone
        alone = solve_ik_batch(chain, rotation, positions[k:k + 1], starts[k:k + 1], position_only=position_only)
        assert alone.q.tobytes() == together.q[k:k + 1].tobytes()
        assert alone.position_error_m[0] == together.position_error_m[k] and alone.success[0] == together.success[k]
    empty = solve_ik_batch(chain, rotation, positions[:0], starts[:0], position_only=position_only)
    assert empty.q.shape == (0, robot.model.nv) and empty.success.shape == (0,)
