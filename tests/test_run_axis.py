"""The prismatic axis end to end: physics against closed forms (docs/concepts.md, "The joint model")."""

import copy
import dataclasses
import math

import numpy as np
import pytest
from matplotlib.figure import Figure
from matplotlib.text import Text

from conftest import AXIS_URDF, STUDIES, axis_study
from tribokin import InputError, load_study, run_study
from tribokin.output.writers import write_results
from tribokin.study.map_spec import CartesianMap

N, K = 150.0, 2.0e6


def rp_um(result):
    return result.poses[0].direction_figures("+")["RP_l_um"]


def test_frictionless_gives_zero_repeatability_and_offset_moves_accuracy():
    eps_t = 7.5e-6
    result = run_study(axis_study(offset=eps_t))
    row = result.poses[0].direction_figures("+")
    assert row["RP_l_um"] == 0.0
    assert row["AP_p_um"] == pytest.approx(eps_t * 1e6, abs=1e-6)
    assert row["RP_a_mdeg"] == 0.0


def test_uniform_friction_matches_closed_form():
    a, b = 0.09, 0.16
    study = axis_study(friction={"law": "uniform", "low": a, "high": b}, normal_force_N=N, stiffness=K)
    w = N * (b - a) / (2 * K)
    expected = w / 2 + 3 * w / math.sqrt(12)  # ~1.366 w
    result = run_study(study, cycles=100_000)
    assert rp_um(result) == pytest.approx(expected * 1e6, rel=0.02)


def test_gaussian_friction_matches_half_normal_closed_form():
    sigma = 0.0075
    study = axis_study(friction={"law": "gaussian", "mean": 0.1375, "std": sigma}, normal_force_N=N, stiffness=K)
    sigma_delta = N * sigma / K
    expected = (math.sqrt(2 / math.pi) + 3 * math.sqrt(1 - 2 / math.pi)) * sigma_delta  # ~2.607 sigma_delta
    result = run_study(study, cycles=100_000)
    assert rp_um(result) == pytest.approx(expected * 1e6, rel=0.02)


def test_bidirectional_constant_friction_gives_two_clusters():
    mu = 0.12
    study = axis_study(friction={"law": "constant", "mu": mu}, normal_force_N=N, stiffness=K)
    study["study"]["approach"] = "bidirectional"
    pose = run_study(study).poses[0]
    x = pose.positions_m[:, 0] - pose.commanded_position_m[0]
    assert set(np.round(x * 1e9).astype(int)) == {round(mu * N / K * 1e9), -round(mu * N / K * 1e9)}
    assert pose.report_row()["vAP_p_um"] == pytest.approx(2 * mu * N / K * 1e6, rel=1e-9)


def test_bidirectional_reports_each_direction_and_the_pooled_cloud():
    """Constant friction: each direction's 30 cycles land on one point (RP_l = 0, AP_p = mu N / K), in
    turn + and -; pooled, every cycle lies mu N / K from the common barycenter, so RP_l = mu N / K."""
    mu = 0.12
    study = axis_study(friction={"law": "constant", "mu": mu}, normal_force_N=N, stiffness=K)
    study["study"]["approach"] = "bidirectional"
    pose = run_study(study).poses[0]
    assert pose.directions == ("+", "-") and list(pose.approach[:4]) == [0, 1, 0, 1]
    row = pose.report_row()
    assert list(row["directions"]) == ["+", "-"] and row["cycles"] == 60
    for figures in row["directions"].values():
        assert figures["cycles"] == 30 and figures["RP_l_um"] == 0.0
        assert figures["AP_p_um"] == pytest.approx(mu * N / K * 1e6, rel=1e-9)
    assert row["RP_l_all_directions_um"] == pytest.approx(mu * N / K * 1e6, rel=1e-9)
    one_way = run_study(axis_study(friction={"law": "constant", "mu": mu}, normal_force_N=N, stiffness=K))
    assert one_way.poses[0].directions == ("+",) and one_way.poses[0].report_row()["vAP_p_um"] is None


def test_backlash_and_noise_enter_the_deviation():
    study = axis_study(backlash=4e-6)
    study["study"]["approach"] = "bidirectional"
    pose = run_study(study).poses[0]
    assert pose.report_row()["vAP_p_um"] == pytest.approx(4.0, rel=1e-9)
    noisy = run_study(axis_study(noise_std=1e-6), cycles=20_000).poses[0]
    assert noisy.dq[:, 0].std() == pytest.approx(1e-6, rel=0.03)


def test_random_approach_mixes_both_directions():
    study = axis_study(friction={"law": "constant", "mu": 0.1})
    study["study"]["approach"] = "random"
    pose = run_study(study, cycles=200).poses[0]
    assert pose.cycles == 400 and 140 < (pose.approach == 1).sum() < 260  # 200 cycles per direction on average
    assert pose.report_row()["vAP_p_um"] == pytest.approx(2 * 0.1 * 100 / 1e6 * 1e6)
    counts = [row["cycles"] for row in pose.direction_rows()]
    assert counts == [np.count_nonzero(pose.approach == k) for k in (0, 1)]


def test_repeatability_scales_with_load_over_stiffness():
    base = axis_study(friction={"law": "uniform", "low": 0.09, "high": 0.16})
    one = rp_um(run_study(base))
    doubled_load = copy.deepcopy(base)
    doubled_load["joints"]["normal_force_N"] = 200.0
    doubled_k = copy.deepcopy(base)
    doubled_k["joints"]["stiffness"] = 2e6
    assert rp_um(run_study(doubled_load)) == pytest.approx(2 * one, rel=1e-9)
    assert rp_um(run_study(doubled_k)) == pytest.approx(one / 2, rel=1e-9)


def test_same_seed_same_numbers_and_cli_overrides():
    study = axis_study(friction={"preset": "42CD4-treated"})
    a, b = run_study(study), run_study(study)
    assert np.array_equal(a.poses[0].positions_m, b.poses[0].positions_m)
    c = run_study(study, seed=99)
    assert not np.array_equal(a.poses[0].positions_m, c.poses[0].positions_m)
    assert run_study(study, cycles=7).poses[0].cycles == 7


def test_pose_load_overrides_joint_load():
    study = axis_study(friction={"law": "constant", "mu": 0.1})
    study["poses"] = [{"name": "light", "q": [0.1], "normal_force_N": 40.0},
                      {"name": "heavy", "q": [0.1], "normal_force_N": 150.0}]
    result = run_study(study)
    assert result.pose("light").direction_figures("+")["AP_p_um"] == pytest.approx(0.1 * 40 / 1e6 * 1e6)
    assert result.pose("heavy").direction_figures("+")["AP_p_um"] == pytest.approx(0.1 * 150 / 1e6 * 1e6)


def test_results_expose_numpy_arrays():
    result = run_study(axis_study(friction={"preset": "42CD4-raw"}))
    table = result.table()
    assert table["RP_l_um"].shape == (1,) and list(table["direction"]) == ["+"]
    assert result.poses[0].positions_m.shape == (30, 3)


@pytest.mark.parametrize("change, key", [
    (lambda s: s["joints"].update(stiffness=-1.0), "joints.stiffness"),
    (lambda s: s["joints"].update(friction={"law": "gaussian", "mean": 0.1, "std": -0.1}), "joints.friction.std"),
    (lambda s: s["joints"].update(friction={"law": "uniform", "low": 0.3, "high": 0.1}), "joints.friction.low"),
    (lambda s: s["joints"].update(friction={"preset": "nope"}), "joints.friction.preset"),
    (lambda s: s["joints"].update(stifness=1.0), "joints.stifness"),
    (lambda s: s["poses"][0].update(q=[0.1, 0.2]), "poses[0].q"),
    (lambda s: s["poses"][0].update(q=[0.9]), "poses[0].q"),
    (lambda s: s["study"].update(cycles=0), "study.cycles"),
    (lambda s: s["robot"].update(tool_frame="tol"), "robot.tool_frame"),
    (lambda s: s["joints"].update(y={"stiffness": 1.0}), "joints.y"),
    (lambda s: s["poses"][0].update(name="a/b"), "poses[0].name"),
    (lambda s: s["study"].update(name="m\nline"), "study.name"),
])
def test_bad_mappings_name_the_key(change, key):
    study = axis_study()
    change(study)
    with pytest.raises(InputError) as error:
        run_study(study)
    assert error.value.key == key


def test_pose_friction_overrides_joint_friction():
    study = axis_study(friction={"law": "constant", "mu": 0.1})
    study["poses"] = [{"name": "base", "q": [0.1]},
                      {"name": "grippy", "q": [0.1], "friction": {"law": "constant", "mu": 0.3}},
                      {"name": "bad", "q": [0.1], "friction": {"law": "uniform", "low": 0.3, "high": 0.1}}]
    with pytest.raises(InputError) as error:
        run_study(study)
    assert error.value.key == "poses[2].friction.low"
    study["poses"].pop()
    result = run_study(study)
    assert result.pose("base").direction_figures("+")["AP_p_um"] == pytest.approx(0.1 * 100 / 1e6 * 1e6)
    assert result.pose("grippy").direction_figures("+")["AP_p_um"] == pytest.approx(0.3 * 100 / 1e6 * 1e6)
    assert result.pose("grippy").report_row()["friction"]["mu"] == 0.3


def small_map(study):
    """``study`` with its map (a placement's task region) at most 4 targets along each axis: every shipped study's
    whole map runs in `make demo`; here, its settings."""
    if study.map is None:
        return study
    key = "resolution" if isinstance(study.map, CartesianMap) else "counts"
    counts = tuple(min(count, 4) for count in getattr(study.map, key))
    return dataclasses.replace(study, map=dataclasses.replace(study.map, **{key: counts}))


@pytest.mark.parametrize("path", sorted(STUDIES.glob("*.toml")), ids=lambda p: p.stem)
def test_every_shipped_study_runs(path):
    """Every shipped study runs; one with nothing but [calibration] is refused by `run` and runs in
    tests/integration/test_calibrate.py."""
    if not load_study(path).has_tests:
        with pytest.raises(InputError, match="tribokin calibrate"):
            run_study(path, cycles=5)
        return
    result = run_study(small_map(load_study(path, cycles=5)))
    assert result.poses or result.map is not None or result.placement is not None
    if result.placement is not None:  # a best placement reaches the whole task
        assert result.placement.meets_min_reachable[result.placement.best.index]
    assert not result.poses or np.all(np.isfinite(result.table()["RP_l_um"]))
    if result.map is not None:
        reachable = result.map.reachable
        assert reachable.any()
        for scenario in result.map.scenarios.values():  # each where the robot it is measured with reaches
            reached = scenario.read_robot("reachable")
            assert np.all(np.isfinite(scenario.figure("RP_l_um")[reached]))
            assert np.all(np.isnan(scenario.figure("RP_l_um")[~reached]))


def test_names_are_shown_as_written_in_figures(tmp_path, monkeypatch):
    """'$' is no math text in a figure: a study name 'm$^^$' (or a joint named so in the URDF) broke matplotlib's
    parser after the whole run, and '$x$' would show an italic x."""
    texts = []
    save = Figure.savefig

    def record(fig, *args, **kwargs):
        result = save(fig, *args, **kwargs)
        texts.extend(text for text in fig.findobj(Text) if text.get_text())
        return result

    monkeypatch.setattr(Figure, "savefig", record)
    urdf = tmp_path / "axis.urdf"
    urdf.write_text(AXIS_URDF.read_text().replace('joint name="x"', 'joint name="x$^^$"'))
    study = axis_study()
    study["robot"]["urdf"] = str(urdf)
    study["study"]["name"] = "m$^^$"
    study["poses"][0]["name"] = "$x$"
    study["map"] = {"kind": "joint", "joints": ["x$^^$"], "ranges": [[0.0, 0.3]], "counts": [3]}
    write_results(run_study(study), tmp_path / "out", report="none")
    assert sorted(text.get_text().split(":")[0] for text in texts if text.get_text().startswith("m$")) == [
        "m$^^$", "m$^^$", "m$^^$", "m$^^$", "m$^^$", "m$^^$ — $x$"]  # the map's RP_l, its band's upper edge, its
    # dominant joint, vAP_p and RP_l_multi (directional figures by default)
    assert {"x$^^$ [m]", "x$^^$"} <= {text.get_text() for text in texts}  # the map's axis, the dominant joint
    assert not any(text.get_parse_math() for text in texts)
