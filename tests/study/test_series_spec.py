"""The time keys of a joint's friction in a study file (study.series_spec): parsed into the joint's FrictionSeries,
each checked in the law's quantity, thermal's motion required per joint."""

from __future__ import annotations

import pytest

from tribokin.errors import InputError
from tribokin.study.spec import parse_study
from tribokin.tribology.friction_series import FrictionSeries, RunIn
from tribokin.tribology.thermal import Thermal


def study(joints: dict, **sections) -> dict:
    return {"robot": {"name": "ur5"}, "joints": {"stiffness": 1e4, **joints}, "iso_cube": {}, **sections}


def refused(mapping: dict) -> str:
    with pytest.raises(InputError) as error:
        parse_study(mapping, "s.toml")
    return error.value.one_line()


def test_time_keys_become_the_joint_s_series():
    parsed = parse_study(study({"friction": {"preset": "42CD4-treated"},
                                "elbow_joint": {"travel_per_cycle": 1.5, "friction_torque_Nm": {
                                    "law": "gaussian", "mean": 5.0, "std": 0.3, "ar1": 0.9,
                                    "run_in": {"start": 7.5, "tau_cycles": 60},
                                    "thermal": {"mu_table": [[20, 1.0], [60, 0.8]]}}}},
                               study={"cycle_time_s": 4.0}), "s.toml")
    assert parsed.joints.series is None and parsed.cycle_time_s == 4.0
    elbow = parsed.joint("elbow_joint")
    assert elbow.travel_per_cycle == 1.5
    assert elbow.series == FrictionSeries(0.9, RunIn(7.5, 60.0), thermal=Thermal(
        1800.0, 1.0, 20.0, mu_table=((20.0, 1.0), (60.0, 0.8))))


def test_each_key_is_checked_in_the_law_s_quantity():
    """A torque law's run_in starts in N·m (up to 10⁴), a law of mu's within mu's range (up to 10)."""
    torque = {"law": "gaussian", "mean": 5.0, "std": 0.3, "run_in": {"start": 50.0, "tau_cycles": 60}}
    assert parse_study(study({"friction_torque_Nm": torque}), "s.toml").joints.series.run_in.start == 50.0
    assert "joints.friction.run_in.start: must be between 0 and 10" in refused(
        study({"friction": {"preset": "42CD4-raw", "run_in": {"start": 50.0, "tau_cycles": 60}}}))
    assert "joints.friction_torque_Nm.ar1: must be between -1 and 1" in refused(
        study({"friction_torque_Nm": {**torque, "ar1": 2}}))


def test_thermal_needs_each_joint_s_travel_and_scenarios_are_checked_alike():
    thermal = {"preset": "42CD4-raw", "thermal": {"mu_per_K": -0.005}}
    assert "joints.shoulder_pan_joint.travel_per_cycle: joints.shoulder_pan_joint.friction.thermal" in refused(
        study({"shoulder_pan_joint": {"friction": thermal}}, study={"cycle_time_s": 4.0}))
    assert "scenarios[0].study.cycle_time_s" in refused(
        study({"friction": {"preset": "42CD4-raw"}, "travel_per_cycle": 1.0}, map={
            "kind": "joint", "joints": ["shoulder_pan_joint"], "ranges": [[0, 1]], "counts": [2]},
            scenarios=[{"name": "warm", "joints": {"friction": thermal}}]))


def test_where_time_keys_are_not_simulated_the_first_is_named():
    """study.assembly.refuse_series (a map's run, a calibration): the first joint friction's time key, its own
    table's first; none given, nothing refused."""
    from tribokin.study.assembly import refuse_series

    given = parse_study(study({"friction": {"preset": "42CD4-raw"}, "wrist_1_joint": {"friction_torque_Nm": {
        "law": "gaussian", "mean": 1.0, "std": 0.1, "steady_mean_std": 0.05}}}), "s.toml")
    with pytest.raises(InputError) as error:
        refuse_series(given, "a calibration", "remove the key")
    assert error.value.one_line() == ("s.toml: joints.wrist_1_joint.friction_torque_Nm.steady_mean_std: a calibration "
                                      "does not simulate friction time keys yet (it would draw every cycle "
                                      "independently; only the study's poses and ISO cube draw them): remove the key")
    refuse_series(parse_study(study({"friction": {"preset": "42CD4-raw"}}), "s.toml"), "a calibration", "")


def test_friction_groups_are_the_joints_each_friction_key_gives():
    """calibrate --fit-ar1's groups: the [joints] friction's joints (those without their own), then each joint
    whose own table gives a friction; a joint's other keys do not make it a group."""
    from tribokin.study.assembly import friction_groups

    names = ("shoulder_pan_joint", "elbow_joint", "wrist_1_joint")
    given = parse_study(study({"friction": {"preset": "42CD4-raw"}, "wrist_1_joint": {"backlash": 1e-5},
                               "elbow_joint": {"friction_torque_Nm": {"law": "gaussian", "mean": 1.0, "std": 0.1}}}),
                        "s.toml")
    assert friction_groups(given, names) == [("joints.friction", ("shoulder_pan_joint", "wrist_1_joint")),
                                             ("joints.elbow_joint.friction_torque_Nm", ("elbow_joint",))]
    assert friction_groups(given, ("elbow_joint",)) == [("joints.elbow_joint.friction_torque_Nm", ("elbow_joint",))]
