"""Joint error model: friction draws and lost motion against the closed form in docs/concepts.md, "The joint model"."""

import math

import numpy as np
import pytest

from conftest import axis_study
from tribokin.errors import InputError, JointRangeError
from tribokin.run import run_study
from tribokin.simulation.joint_errors import (
    JointErrorModel,
    approach_signs,
    check_travel,
    deviation_parts,
    draw_friction,
    joint_travel,
    largest_mu,
    sample_joint_deviations,
)
from tribokin.tribology import Constant, Gaussian, Lognormal, Uniform
from tribokin.tribology.laws import Scaled


def test_each_joint_draws_from_its_own_law():
    models = [JointErrorModel(Uniform(0.1, 0.2), 1e5), JointErrorModel(Uniform(0.5, 0.6), 1e5),
              JointErrorModel(Constant(0.3), 1e5)]
    mu = draw_friction(models, 2000, np.random.default_rng(1)).values
    assert mu.shape == (2000, 3)
    assert 0.1 <= mu[:, 0].min() and mu[:, 0].max() <= 0.2
    assert 0.5 <= mu[:, 1].min() and mu[:, 1].max() <= 0.6
    assert np.all(mu[:, 2] == 0.3)


def test_joints_sharing_a_law_draw_joint_by_joint_from_one_stream():
    models = [JointErrorModel(Uniform(0.1, 0.2), 1e5) for _ in range(4)]  # equal laws, distinct objects
    mu = draw_friction(models, 100, np.random.default_rng(2)).values
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
    dq, drawn = sample_joint_deviations(models, prismatic, forces, signs, np.random.default_rng(0))
    lost = np.array([0.12 * 300 * 0.03 / 2e4 + 1e-5, 0.12 * 40 / 2e6])
    np.testing.assert_allclose(dq, np.array([1e-4, -1e-5]) + directions[group] * lost, rtol=1e-14, atol=0)
    assert np.all(drawn.values == 0.12) and drawn.temperature_C is None


def test_largest_mu_is_the_upper_bound_else_six_standard_deviations_above_the_mean():
    assert largest_mu(Uniform(0.09, 0.16)) == 0.16
    assert largest_mu(Constant(0.12)) == 0.12
    law = Gaussian(0.1375, 0.0075)
    assert largest_mu(law) == pytest.approx(law.mean() + 6 * law.std())


def test_deviation_parts_take_each_joints_largest_load():
    models = [JointErrorModel(Uniform(0.1, 0.2), 2e4, friction_radius_m=0.03, backlash=2e-3, offset=-1e-3,
                              noise_std=1e-4),
              JointErrorModel(Constant(0.1), 1e3)]
    forces = np.array([[300.0, 10.0], [100.0, 50.0]])  # two configurations
    parts = deviation_parts(models, np.array([False, True]), forces)
    np.testing.assert_allclose(parts, [[0.2 * 300 * 0.03 / 2e4, 1e-3, 1e-3, 6e-4], [0.1 * 50 / 1e3, 0, 0, 0]])


def test_a_revolute_joint_travels_at_most_a_full_turn():
    travel = joint_travel(np.array([0.0, -10.0, -1.0]), np.array([0.4, 10.0, 1.0]), np.array([True, False, False]))
    np.testing.assert_allclose(travel, [0.4, 2 * np.pi, 2.0])


def test_travel_check_names_the_joint_the_figures_and_the_key_to_change():
    models = [JointErrorModel(Constant(0.1), 1e6), JointErrorModel(Constant(0.16), 1.0, backlash=0.01)]
    with pytest.raises(JointRangeError) as error:
        check_travel(models, np.array([True, True]), np.array([150.0, 105.0]), np.array([0.4, 0.4]), ["x", "slide"])
    assert (error.value.joint, error.value.part) == ("slide", "stiffness")
    assert ("joint 'slide': deviation (lost motion 16.8 m, backlash/2 0.005 m) up to 16.8 m exceeds the joint's "
            "range 0.4 m; raise stiffness") in error.value.message
    check_travel(models[:1], np.array([True]), np.array([150.0]), np.array([0.4]), ["x"])  # fits


def test_pose_loads_beyond_a_joints_range_are_refused_before_any_pose_is_sampled(monkeypatch):
    study = axis_study(friction={"law": "constant", "mu": 0.1})
    study["poses"] = [{"name": "light", "q": [0.2], "normal_force_N": 1.0},
                      {"name": "heavy", "q": [0.2], "normal_force_N": 1e7}]
    sampled = []
    monkeypatch.setattr("tribokin.simulation.pose_test.sample_joint_deviations", lambda *args: sampled.append(args))
    with pytest.raises(InputError, match="lost motion up to 1 m exceeds the joint's range 0.4 m") as error:
        run_study(study)
    assert error.value.key == "joints.stiffness" and sampled == []


def force_study(law: dict, **joints) -> dict:
    """The prismatic axis with its friction force [N] given as a law (no mu, no load)."""
    study = axis_study(stiffness=2.0e6, normal_force_N=1e4, **joints)  # the load must play no part
    del study["joints"]["friction"]
    study["joints"]["friction_force_N"] = law
    return study


def test_a_constant_friction_force_loses_force_over_stiffness_and_repeats_exactly():
    result = run_study(force_study({"law": "constant", "value": 30.0}))
    pose = result.poses[0]
    np.testing.assert_allclose(pose.dq, 30.0 / 2.0e6, rtol=1e-14, atol=0)
    assert pose.direction_figures("+")["RP_l_um"] == 0.0
    assert "friction_is_torque" not in result.settings["joint_models"]["x"]  # the law says what it draws
    described = result.settings["friction"]["x"]
    assert described["quantity"] == "friction_force_N" and described["value"] == 30.0 and described["mean"] == 30.0


def test_a_constant_friction_torque_loses_torque_over_stiffness_on_a_revolute_joint():
    """tau / k, whatever the load and friction radius."""
    law = Scaled(Constant(0.4 / 1024), 1024, "friction_torque_Nm")
    models = [JointErrorModel(law, 50.0, friction_radius_m=0.03),
              JointErrorModel(Constant(0.1), 50.0, friction_radius_m=0.03)]
    dq, drawn = sample_joint_deviations(models, np.array([False, False]), np.array([300.0, 300.0]),
                                        np.ones((4, 2)), np.random.default_rng(0))
    np.testing.assert_allclose(dq, [[0.4 / 50.0, 0.1 * 300 * 0.03 / 50.0]] * 4, rtol=1e-14, atol=0)
    assert np.all(drawn.values[:, 0] == 0.4)


def test_torque_laws_of_the_same_numbers_but_different_kinds_are_drawn_each_from_its_own():
    gaussian, lognormal = (Scaled(law(0.4 / 1024, 0.2 / 1024), 1024, "friction_torque_Nm")
                           for law in (Gaussian, Lognormal))
    assert gaussian.params == lognormal.params and gaussian != lognormal
    mu = draw_friction([JointErrorModel(gaussian, 1.0), JointErrorModel(lognormal, 1.0)], 10_000,
                       np.random.default_rng(0)).values
    assert mu[:, 1].min() > 0 and mu[:, 0].min() < mu[:, 1].min()  # the lognormal's tail is thinner near 0


def test_a_gaussian_friction_force_gives_the_closed_form_repeatability():
    """RP_l = (sqrt(2/pi) + 3 sqrt(1 - 2/pi)) sigma / k = 2.607 sigma / k (docs/concepts.md, "The joint model");
    over n = 100000 cycles the estimate's standard deviation is about 2.1 sigma / k / sqrt(n) = 0.26 %, so 1 % is
    four of them."""
    sigma = 1.5
    study = force_study({"law": "gaussian", "mean": 20.0, "std": sigma})  # truncation at 13 std: negligible
    study["study"]["cycles"] = 100_000
    expected = (math.sqrt(2 / math.pi) + 3 * math.sqrt(1 - 2 / math.pi)) * sigma / 2.0e6 * 1e6
    assert run_study(study).poses[0].direction_figures("+")["RP_l_um"] == pytest.approx(expected, rel=0.01)


def test_friction_given_twice_in_one_table_is_one_line_naming_the_second_key():
    study = force_study({"law": "constant", "value": 30.0})
    study["joints"]["friction"] = {"law": "constant", "mu": 0.1}
    with pytest.raises(InputError) as error:
        run_study(study)
    assert error.value.key == "joints.friction_force_N" and "\n" not in str(error.value)
    assert "give one of friction, friction_torque_Nm, friction_force_N, not friction and friction_force_N" \
        in error.value.message


def test_a_joints_own_friction_replaces_the_defaults_kind():
    study = axis_study(friction={"law": "constant", "mu": 0.1}, stiffness=2.0e6, normal_force_N=1e4)
    study["joints"]["x"] = {"friction_force_N": {"law": "constant", "value": 30.0}}
    np.testing.assert_allclose(run_study(study).poses[0].dq, 30.0 / 2.0e6, rtol=1e-14, atol=0)


def test_a_poses_friction_sets_a_law_of_mu_there_over_a_joints_friction_force():
    study = force_study({"law": "constant", "value": 30.0})
    study["poses"][0]["friction"] = {"law": "constant", "mu": 0.1}
    np.testing.assert_allclose(run_study(study).poses[0].dq, 0.1 * 1e4 / 2.0e6, rtol=1e-14, atol=0)


@pytest.mark.parametrize("joints, key, message", [
    ({"friction_torque_Nm": {"law": "constant", "value": 1.0}}, "joints.friction_torque_Nm",
     "joint 'x' is prismatic: give its friction as joints.x.friction_force_N [N]"),
    ({"friction_force_N": {"law": "gaussian", "mean": 2e5, "std": 1.0}}, "joints.friction_force_N.mean",
     "must be between 0 and 100000 N (got 200000)"),
    ({"friction_force_N": {"law": "empirical", "values": [1.0, -2.0]}}, "joints.friction_force_N.values[1]",
     "must be >= 0"),
    ({"friction_force_N": {"law": "constant", "mu": 1.0}}, "joints.friction_force_N.mu",
     'a constant torque or force is written { law = "constant", value = ... }'),
    ({"friction_force_N": {"law": "constant", "value": 1e5}, "stiffness": 1e3}, "joints.stiffness",
     "lost motion up to 100 m exceeds the joint's range 0.4 m"),
])
def test_friction_force_laws_are_checked_before_any_run(joints, key, message):
    study = axis_study(**joints)
    del study["joints"]["friction"]
    with pytest.raises(InputError) as error:
        run_study(study)
    assert error.value.key == key and message in error.value.message
