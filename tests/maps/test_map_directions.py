"""Maps approached from both directions (issue 37, deliverable 1): ISO's figures per approach direction in their own
columns, the unsuffixed ones the larger of the two; a pose's expected figures are a map target's (deliverable 5)."""

import copy
import math

import numpy as np
import pytest
from scipy.stats import norm

from helpers.map_studies import GANTRY, PAYLOAD, UR5_PLANE, K, gantry_loads_by_hand
from tribokin import run_study
from tribokin.maps.expected_figures import SPLIT_FIGURES
from tribokin.maps.schema import MapLayout, direction_figure, map_figures, table_figures

MEAN, STD, CYCLES = 0.12, 0.02, 10


def x_only_study(friction: dict, approach: str = "bidirectional", statistic: str = "expected",
                 cycles: int = CYCLES) -> dict:
    """The gantry with friction on its x axis only (y, z frictionless): each direction's cycles spread along x alone,
    dq_x = ±μ N_x / k."""
    return {
        "study": {"cycles": cycles, "seed": 5, "approach": approach},
        "robot": {"urdf": GANTRY, "tool_frame": "tool", "payload_kg": PAYLOAD},
        "joints": {"friction": {"law": "constant", "mu": 0.0}, "stiffness": K, "bearing_span_m": 0.2,
                   "x": {"friction": friction}},
        "map": {"kind": "plane", "origin_m": [0.2, 0.0, 0.3], "axis_u": [1, 0, 0], "axis_v": [0, 1, 0],
                "extent_u_m": [0.0, 0.4], "extent_v_m": [0.0, 0.6], "resolution": [2, 3], "statistic": statistic},
    }


def one_axis_tests(draws: np.ndarray, lever: np.ndarray) -> dict:
    """RP_l's mean and 2.5 / 97.5 % band [µm] at targets of levers ``lever`` [m] of tests of ``draws`` (tests, cycles)
    of μ on one axis, dq = μ L: by ISO's formulas, independently of tribokin (each direction's cloud is the other's
    mirrored; a target's figures are L times those of L = 1)."""
    distances = np.abs(draws - draws.mean(axis=1, keepdims=True))
    rp = (distances.mean(axis=1) + 3 * distances.std(axis=1, ddof=1)) * 1e6
    return {name: value * lever for name, value in (("RP_l_um", rp.mean()), ("RP_l_lo_um", np.percentile(rp, 2.5)),
                                                    ("RP_l_hi_um", np.percentile(rp, 97.5)))}


def test_the_names_of_each_direction_s_columns_follow_figure_direction_unit():
    assert direction_figure("RP_l_lo_um", "plus") == "RP_l_lo_plus_um"
    assert direction_figure("RP_c_mdeg", "minus") == "RP_c_minus_mdeg"
    assert [f.name for f in map_figures("expected", True)][9:] == [
        "RP_l_plus_um", "RP_l_lo_plus_um", "RP_l_hi_plus_um", "AP_p_plus_um", "RP_a_plus_mdeg", "RP_b_plus_mdeg",
        "RP_c_plus_mdeg", "RP_l_minus_um", "RP_l_lo_minus_um", "RP_l_hi_minus_um", "AP_p_minus_um", "RP_a_minus_mdeg",
        "RP_b_minus_mdeg", "RP_c_minus_mdeg"]
    assert [f.name for f in map_figures("expected", True)][:9] == [f.name for f in map_figures("expected")]
    one_test = table_figures("one-test", True)
    assert one_test[:6] == table_figures("one-test")[:6] and one_test[-3:] == [
        "RP_l_all_directions_um", "dominant_joint", "dominant_share"]
    layout = MapLayout.shared(3, 2, "directional", ("unidirectional", "random"))
    assert layout.columns()["scenario0_figures"] == ((11,), "f8")  # unidirectional: as before
    assert layout.columns()["scenario1_figures"] == layout.columns()["scenario1_figure_errors"] == ((25,), "f8")


@pytest.fixture(scope="module")
def gaussian_x():
    return run_study(x_only_study({"law": "gaussian", "mean": MEAN, "std": STD})).map


def test_each_direction_of_a_gaussian_axis_is_iso_s_unidirectional_figure_in_closed_form():
    """One prismatic axis, Gaussian μ: each direction's cycles x_j = ±L μ_j, a normal of mean ±L μ̄ and spread L σ. AP_p
    = E|x̄ - x_c| of x̄ ~ N(L μ̄, (L σ)² / n) in closed form; RP_l by ISO's formulas over 200 000 drawn tests of 30
    cycles (the closed form's delta method: 0.05 %), its band within 3 of the map's stated Monte Carlo errors. The
    pooled cloud would hold both means, 2 L μ̄ apart: its l̄ alone is about L μ̄, more than twice RP_l here."""
    cycles = 30
    workspace_map = run_study(x_only_study({"law": "gaussian", "mean": MEAN, "std": STD}, cycles=cycles)).map
    scenario, ok = workspace_map.reference, workspace_map.reachable
    lever = gantry_loads_by_hand(workspace_map.positions_m[ok, 1])[0] / K
    mean, spread = MEAN * lever, STD * lever / math.sqrt(cycles)
    ap = spread * math.sqrt(2 / math.pi) * np.exp(-(mean / spread) ** 2 / 2) + mean * (1 - 2 * norm.cdf(-mean / spread))
    drawn = one_axis_tests(np.random.default_rng(1).normal(MEAN, STD, (200_000, cycles)), lever)
    for label in ("plus", "minus"):
        np.testing.assert_allclose(scenario.figure(f"AP_p_{label}_um")[ok], ap * 1e6, rtol=1e-7)  # hand statics
        np.testing.assert_allclose(scenario.figure(f"RP_l_{label}_um")[ok], drawn["RP_l_um"], rtol=2e-3)
        for name in ("RP_l_lo_um", "RP_l_hi_um"):
            stated = scenario.mc_error(direction_figure(name, label))[ok]  # the shape table's
            assert np.all((0 < stated) & (stated < 0.01))
            relative = scenario.figure(direction_figure(name, label))[ok] / drawn[name] - 1
            assert np.all(np.abs(relative) < 3 * stated), (name, relative, stated)
        for axis in "abc":
            assert np.all(scenario.figure(f"RP_{axis}_{label}_mdeg")[ok] == 0.0)  # a gantry does not turn
    assert np.all(scenario.figure("RP_l_um")[ok] < 0.5 * mean * 1e6)
    assert np.all(scenario.read("method")[ok] == 0)  # analytic, each direction a unidirectional test


def test_a_bidirectional_map_s_plus_direction_is_the_unidirectional_map_and_each_figure_the_larger(gaussian_x):
    study = x_only_study({"law": "gaussian", "mean": MEAN, "std": STD}, approach="unidirectional")
    unidirectional = run_study(study).map.reference
    both, ok = gaussian_x.reference, gaussian_x.reachable
    for name in SPLIT_FIGURES:
        np.testing.assert_array_equal(both.figure(direction_figure(name, "plus")), unidirectional.figure(name))
        larger = np.maximum(both.figure(direction_figure(name, "plus")), both.figure(direction_figure(name, "minus")))
        np.testing.assert_array_equal(both.figure(name)[ok], larger[ok])
        np.testing.assert_array_equal(both.figure_error(name)[ok], np.maximum(
            both.figure_error(direction_figure(name, "plus")), both.figure_error(direction_figure(name, "minus")))[ok])
    summary = gaussian_x.summary()
    assert "larger of the + and - approach directions'" in summary["unsuffixed_figures"]
    assert {"RP_l_plus_um", "RP_l_minus_um", "AP_p_plus_um", "AP_p_minus_um"} <= set(summary)
    assert "unsuffixed_figures" not in run_study(study).map.summary()
    study["scenarios"] = [{"name": "one"}, {"name": "both", "study": {"approach": "random"}}]
    one, both = run_study(study).map.summary()["scenarios"]
    assert "unsuffixed_figures" not in one and "larger of the + and - approach" in both["unsuffixed_figures"]


def test_a_sampled_law_per_direction_agrees_with_iso_s_formulas():
    """Uniform μ on the x axis: each direction's figures over the map's sampled tests against 200 000 drawn tests,
    within three of their stated Monte Carlo errors."""
    low, high = 0.09, 0.16
    result = run_study(x_only_study({"law": "uniform", "low": low, "high": high}, approach="random")).map
    scenario, ok = result.reference, result.reachable
    lever = gantry_loads_by_hand(result.positions_m[ok, 1])[0] / K
    drawn = one_axis_tests(np.random.default_rng(2).uniform(low, high, (200_000, CYCLES)), lever)
    for label in ("plus", "minus"):
        for name, value in drawn.items():  # with the drawn tests' own error: under 0.05 % (200 000 tests)
            stated = scenario.mc_error(direction_figure(name, label))[ok]
            assert np.all((0 < stated) & (stated < 0.01))
            relative = scenario.figure(direction_figure(name, label))[ok] / value - 1
            assert np.all(np.abs(relative) < 3 * np.hypot(stated, 5e-4)), (name, relative, stated)
    assert np.all(scenario.read("method")[ok] == 1)


@pytest.mark.parametrize("statistic, approach", [("expected", "bidirectional"), ("one-test", "random")])
def test_each_direction_s_columns_do_not_depend_on_the_chunking(statistic, approach):
    study = x_only_study({"law": "uniform", "low": 0.09, "high": 0.16}, approach, statistic)
    study["joints"]["y"] = {"friction": {"law": "gaussian", "mean": MEAN, "std": STD}}
    whole = run_study(study).map.reference
    study["map"]["chunk_rows"] = 1
    chunked = run_study(study).map.reference
    # an expected map's figures include the directional ones (on by default)
    assert whole.both_directions and len(whole.figure_list) == (25 if statistic == "expected" else 18)
    np.testing.assert_array_equal(chunked.figures, whole.figures)


@pytest.mark.parametrize("approach", ["bidirectional", "random"])
def test_a_one_test_map_measures_each_direction_s_cycles_as_a_pose_does(approach):
    """Constant μ: each direction's cycles land on one point (RP_l 0), x_c ± d, d = μ (N_x, N_y, 0) / k; every cycle
    pooled lies |d| from their barycentre (RP_l_all_directions_um: what the map gave as RP_l before; random: as many
    from each direction in all, their barycentre off the middle, hence not asserted)."""
    study = x_only_study({"law": "constant", "mu": MEAN}, approach, "one-test")
    study["joints"]["y"] = {"friction": {"law": "constant", "mu": MEAN}}
    workspace_map = run_study(study).map
    scenario, ok = workspace_map.reference, workspace_map.reachable
    n_x, n_y, _ = gantry_loads_by_hand(workspace_map.positions_m[ok, 1])
    d = np.hypot(MEAN * n_x / K, MEAN * n_y / K) * 1e6
    for name in ("RP_l_um", "RP_l_plus_um", "RP_l_minus_um"):
        np.testing.assert_allclose(scenario.figure(name)[ok], 0.0, atol=1e-9)
    pooled = ("RP_l_all_directions_um",) if approach == "bidirectional" else ()
    for name in ("AP_p_um", "AP_p_plus_um", "AP_p_minus_um", *pooled):
        np.testing.assert_allclose(scenario.figure(name)[ok], d, rtol=1e-9)


@pytest.mark.parametrize("friction", [{"law": "uniform", "low": 0.09, "high": 0.16},
                                      {"law": "gaussian", "mean": MEAN, "std": STD}])
def test_a_pose_s_expected_figures_are_a_map_target_s_at_its_configuration(friction):
    """A UR5 pose at a map target's configuration, with the same seed and approach: the same expected figures per
    direction to 1e-9 (sampled tests of a uniform law, and the closed form of a Gaussian one)."""
    study = copy.deepcopy(UR5_PLANE)
    study["study"].update(approach="bidirectional", cycles=CYCLES)
    study["joints"]["friction"] = friction
    study["map"]["resolution"] = [2, 2]
    workspace_map = run_study(study).map
    k = int(np.flatnonzero(workspace_map.reachable)[0])
    assert workspace_map.reference.read("method")[k] == (1 if friction["law"] == "uniform" else 0)
    del study["map"]
    study["poses"] = [{"name": "at-target", "q": workspace_map.q[k].tolist()}]
    pose = run_study(study).poses[0]
    for label, sign in (("plus", "+"), ("minus", "-")):
        figures = pose.direction_figures(sign)
        for name in SPLIT_FIGURES:
            map_value = workspace_map.reference.figure(direction_figure(name, label))[k]
            np.testing.assert_allclose(figures[f"expected_{name}"], map_value, rtol=1e-9, atol=1e-12)
        assert figures["RP_l_um"] != figures["expected_RP_l_um"]  # the one simulated test's, beside them
    assert figures["expected_RP_l_lo_um"] < figures["expected_RP_l_um"] < figures["expected_RP_l_hi_um"]
    columns = list(pose.to_pandas().columns)  # poses.csv's: the expected figures under their own names
    assert columns.count("RP_l_um") == 1 and {f"expected_{name}" for name in SPLIT_FIGURES} <= set(columns)


def test_the_console_says_which_figure_it_shows(gaussian_x, capsys):
    from tribokin.cli.run import _print_map

    _print_map(gaussian_x)
    assert "approached from both directions: RP_l, its band, AP_p and RP_a/b/c: the larger of the + and - approach " \
           "directions'" in capsys.readouterr().out
