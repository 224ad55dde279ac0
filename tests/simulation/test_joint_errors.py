"""Joint error model: friction draws and lost motion against the closed form of DESIGN §2."""

import numpy as np
import pytest

from tribokin.simulation.joint_errors import JointErrorModel, approach_signs, draw_friction, sample_joint_deviations
from tribokin.tribology import Constant, Uniform


def test_each_joint_draws_from_its_own_law():
    models = [JointErrorModel(Uniform(0.1, 0.2), 1e5), JointErrorModel(Uniform(0.5, 0.6), 1e5),
              JointErrorModel(Constant(0.3), 1e5)]
    mu = draw_friction(models, 2000, np.random.default_rng(1))
    assert mu.shape == (2000, 3)
    assert 0.1 <= mu[:, 0].min() and mu[:, 0].max() <= 0.2
    assert 0.5 <= mu[:, 1].min() and mu[:, 1].max() <= 0.6
    assert np.all(mu[:, 2] == 0.3)


def test_joints_sharing_a_law_draw_joint_by_joint_from_one_stream():
    models = [JointErrorModel(Uniform(0.1, 0.2), 1e5) for _ in range(4)]  # equal laws, distinct objects
    mu = draw_friction(models, 100, np.random.default_rng(2))
    expected = np.random.default_rng(2).uniform(0.1, 0.2, (4, 100)).T
    np.testing.assert_array_equal(mu, expected)


@pytest.mark.parametrize("mode", ["unidirectional", "bidirectional"])
def test_lost_motion_is_the_closed_form(mode):
    """dq = offset + s (mu N r / k + backlash / 2) for a revolute and a prismatic joint."""
    models = [JointErrorModel(Constant(0.12), 2e4, friction_radius_m=0.03, backlash=2e-5, offset=1e-4),
              JointErrorModel(Constant(0.12), 2e6, friction_radius_m=0.5, backlash=0.0, offset=-1e-5)]
    prismatic, forces = np.array([False, True]), np.array([300.0, 40.0])
    directions = np.array([[1.0, 1.0], [-1.0, -1.0]])
    signs, group = approach_signs(mode, 6, directions, np.random.default_rng(0))
    dq, mu = sample_joint_deviations(models, prismatic, forces, signs, np.random.default_rng(0))
    lost = np.array([0.12 * 300 * 0.03 / 2e4 + 1e-5, 0.12 * 40 / 2e6])
    np.testing.assert_allclose(dq, np.array([1e-4, -1e-5]) + directions[group] * lost, rtol=1e-14, atol=0)
    assert np.all(mu == 0.12)
