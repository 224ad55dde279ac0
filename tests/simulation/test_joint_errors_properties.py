"""Properties of the joint error model: without friction, backlash or noise every cycle lands on the
same pose (RP = 0 exactly, the paper's reference case); with a constant mu the lost motion is the
closed form offset + s (mu N r / k + backlash / 2)."""

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from conftest import ROOT
from tribokin.iso9283.metrics import position_repeatability
from tribokin.kinematics.robot import load_urdf
from tribokin.propagation.exact import tool_deviations
from tribokin.simulation.joint_errors import JointErrorModel, approach_signs, sample_joint_deviations
from tribokin.tribology.laws import Constant

GANTRY = load_urdf(ROOT / "urdf" / "cartesian_xyz.urdf", "tool")  # three prismatic joints

stiffness = st.floats(1e3, 1e9)
forces = st.floats(0.0, 1e4)
offsets = st.floats(-1e-3, 1e-3)
modes = st.sampled_from(["unidirectional", "bidirectional", "random"])


def _models(mu, stiffnesses, offsets_, backlash=0.0):
    return [JointErrorModel(Constant(mu), k, offset=o, backlash=backlash, friction_radius_m=0.05)
            for k, o in zip(stiffnesses, offsets_, strict=True)]


@given(st.lists(stiffness, min_size=3, max_size=3), st.lists(offsets, min_size=3, max_size=3),
       st.lists(forces, min_size=3, max_size=3), modes, st.integers(2, 60), st.integers(0, 2 ** 32 - 1),
       st.sampled_from(["fast", "exact"]))
def test_no_friction_no_backlash_no_noise_gives_zero_dispersion(ks, offsets_, forces_N, mode, cycles, seed, engine):
    rng = np.random.default_rng(seed)
    signs, _ = approach_signs(mode, cycles, np.vstack([np.ones(3), -np.ones(3)]), rng)
    dq, drawn = sample_joint_deviations(_models(0.0, ks, offsets_), GANTRY.joint_is_prismatic, forces_N, signs, rng)
    assert np.all(drawn.values == 0.0) and np.all(dq == np.array(offsets_))
    q = (GANTRY.lower_limits + GANTRY.upper_limits) / 2
    positions, _ = tool_deviations(GANTRY, q, dq, engine)
    assert position_repeatability(positions)[0] == 0.0


@given(st.floats(0.0, 0.5), st.lists(stiffness, min_size=3, max_size=3), st.lists(offsets, min_size=3, max_size=3),
       st.lists(forces, min_size=3, max_size=3), st.floats(0.0, 1e-4), modes, st.integers(0, 2 ** 32 - 1))
def test_constant_friction_loses_the_closed_form_motion(mu, ks, offsets_, forces_N, backlash, mode, seed):
    rng = np.random.default_rng(seed)
    signs, _ = approach_signs(mode, 20, np.vstack([np.ones(3), -np.ones(3)]), rng)
    prismatic = np.array([True, False, True])  # r = 1 for prismatic joints, r = 0.05 m for the revolute one
    dq, _ = sample_joint_deviations(_models(mu, ks, offsets_, backlash), prismatic, forces_N, signs, rng)
    lever = np.array([1.0, 0.05, 1.0]) / np.array(ks)
    expected = np.array(offsets_) + signs * (mu * np.array(forces_N) * lever + backlash / 2)
    np.testing.assert_allclose(dq, expected, rtol=1e-12, atol=1e-18)
