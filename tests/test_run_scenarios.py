"""What-if scenarios: the same targets and streams, overrides merged into the study, comparisons."""

import numpy as np
import pytest

from helpers.map_studies import MU, G, gantry_loads_by_hand, gantry_map_study
from tribokin import InputError, run_study
from tribokin.output.writers import write_results
from tribokin.simulation.pose_test import PoseRunner
from tribokin.study.names import pose_figure_file, scenario_files


def with_scenarios(*scenarios, **joints):
    study = gantry_map_study(**joints)
    study["study"]["approach"] = "unidirectional"
    study["joints"]["friction"] = {"preset": "42CD4-raw"}
    study["scenarios"] = list(scenarios)
    return study


def test_scenarios_share_targets_and_streams():
    study = with_scenarios({"name": "raw"}, {"name": "same"}, {"name": "none", "joints": {"friction": {
        "preset": "frictionless"}}})
    workspace_map = run_study(study).map
    raw, same, none = workspace_map.scenarios.values()
    np.testing.assert_array_equal(raw.figures, same.figures)  # no override: the very same numbers
    assert np.all(none.figure("RP_l_um")[workspace_map.reachable] == 0.0)
    np.testing.assert_array_equal(workspace_map.ratio_RP_l(none)[workspace_map.reachable], 0.0)
    np.testing.assert_array_equal(workspace_map.diff_RP_l_um(none), -raw.figure("RP_l_um"))
    summary = workspace_map.summary()
    assert summary["wins"] == {"raw": 0, "same": 0, "none": summary["reachable"]} and summary["ties"] == 0
    assert [s["name"] for s in summary["scenarios"]] == ["raw", "same", "none"]


def test_payload_and_joint_overrides_change_only_what_they_name():
    heavy_payload = 25.0
    study = with_scenarios({"name": "base"}, {"name": "heavy", "robot": {"payload_kg": heavy_payload}},
                           {"name": "constant-x", "joints": {"x": {"friction": {"law": "constant", "mu": MU}}}},
                           {"name": "short", "study": {"cycles": 4}})
    workspace_map = run_study(study, cycles=6).map
    base, heavy, constant_x, _ = workspace_map.scenarios.values()
    ok = workspace_map.reachable
    y = workspace_map.positions_m[:, 1]
    extra_x = heavy_payload - 5.0  # the base payload of gantry_map_study
    # hand statics with 20 kg more at the tool (see gantry_loads_by_hand): weight, pitch arm 0.2 m, roll arm y
    weight = (40 + 15 + 8 + heavy_payload) * G
    pitch, roll = G * (15 * 0.1 + (13 + extra_x) * 0.2), G * np.abs(40 * 0.35 + (28 + extra_x) * y)
    np.testing.assert_allclose(heavy.normal_forces_N[ok, 0], (max(weight, 2 * pitch / 0.2) + 2 * roll / 0.2)[ok],
                               rtol=1e-9)
    np.testing.assert_allclose(base.normal_forces_N[ok, 0], gantry_loads_by_hand(y)[0][ok], rtol=1e-9)
    assert np.all(heavy.figure("RP_l_um")[ok] > base.figure("RP_l_um")[ok])
    # constant mu on x: its lost motion no longer varies; only y's uniform friction spreads the cycles
    assert np.all(constant_x.figure("RP_l_um")[ok] < 0.5 * base.figure("RP_l_um")[ok])
    assert np.all(constant_x.dominant_joint[ok] == 1) and constant_x.joint_names[1] == "y"
    names = constant_x.dominant_joint_names()
    assert set(names[ok]) == {"y"} and set(names[~ok]) <= {""}
    assert [s.cycles for s in workspace_map.scenarios.values()] == [6, 6, 6, 4]  # --cycles applies unless overridden


@pytest.mark.parametrize("scenario, key", [
    ({"name": "a", "robot": {"name": "ur55"}}, "scenarios[1].robot.name"),
    ({"name": "a", "map": {}}, "scenarios[1].map"),
    ({"name": "a", "joints": {"stiffness": -1.0}}, "scenarios[1].joints.stiffness"),
    ({"name": "a", "joints": {"w": {"stiffness": 1.0}}}, "scenarios[1].joints.w"),
    ({"name": "a", "joints": {"friction": {"preset": "42CD4-rw"}}}, "scenarios[1].joints.friction.preset"),
    ({"name": "base"}, "scenarios[1].name"),
    ({"name": "a/b"}, "scenarios[1].name"),
    ({"joints": {}}, "scenarios[1].name"),
])
def test_bad_scenarios_name_the_key(scenario, key):
    with pytest.raises(InputError) as error:
        run_study(with_scenarios({"name": "base"}, scenario))
    assert error.value.key == key


@pytest.mark.parametrize("first, second, file", [
    ("b", "ratio_b", "map_RP_l_ratio_b.png"),
    ("b", "diff_b", "map_RP_l_diff_b.png"),
    ("treated", "Treated", "map_Treated.csv"),
])
def test_scenarios_writing_the_same_file_are_refused_before_any_work(monkeypatch, first, second, file):
    def measured(*args):
        raise AssertionError("a target was measured before the refusal")

    monkeypatch.setattr(PoseRunner, "draw", measured)
    with pytest.raises(InputError) as error:
        run_study(with_scenarios({"name": "raw"}, {"name": first}, {"name": second}))
    assert error.value.key == "scenarios[2].name"
    assert f"writes {file}, as scenarios[1].name does" in error.value.message


def test_files_named_by_poses_and_scenarios_are_the_files_written(tmp_path):
    names = ["Raw", "Lighter", "Heavier"]
    study = with_scenarios(*({"name": name} for name in names))
    study["poses"] = [{"name": "Near", "q": [0.1, 0.1, 0.1]}]
    write_results(run_study(study, cycles=4), tmp_path / "out", report="none")
    named = {pose_figure_file("Near")} | {file for name in names[1:] for file in scenario_files(name)}
    written = {path.name for path in (tmp_path / "out").iterdir()}
    assert {file for file in written if any(name in file for name in ["Near", *names])} == named


def test_scenarios_need_a_map():
    study = with_scenarios({"name": "base"})
    del study["map"]
    study["poses"] = [{"q": [0.1, 0.1, 0.1]}]
    with pytest.raises(InputError) as error:
        run_study(study)
    assert error.value.key == "scenarios"


def test_friction_twice_as_large_doubles_the_gantry_s_rp_l():
    """Two uniform-mu scenarios, the second's law the first's doubled: the ratio map is 2 everywhere (each direction's
    RP_l is linear in mu on the same random numbers; constant mu would put each direction's cycles on one point)."""
    study = with_scenarios({"name": "mu", "joints": {"friction": {"law": "uniform", "low": MU, "high": 1.5 * MU}}},
                           {"name": "double", "joints": {"friction": {"law": "uniform", "low": 2 * MU,
                                                                      "high": 3 * MU}}})
    study["study"]["approach"] = "bidirectional"
    workspace_map = run_study(study).map
    ratio = workspace_map.ratio_RP_l(workspace_map.scenarios["double"])[workspace_map.reachable]
    np.testing.assert_allclose(ratio, 2.0, rtol=1e-6)
    assert workspace_map.summary()["wins"]["mu"] == workspace_map.summary()["reachable"]
