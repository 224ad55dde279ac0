"""The engine each expected-map target's figures rest on, its bound against exact Pinocchio FK, and the figure-level
errors derived from it (:func:`~tribokin.maps.expected_figures.figure_errors`), for fallbacks forced to the fast
engine (tolerance 0) and to exact FK (joints so soft that the fast engine's bound exceeds its tolerance), and for
the first-order model where it serves. Few sampled cycles: the comparisons are on the same samples, so no Monte
Carlo error enters them."""

import numpy as np
import pytest

import tribokin.maps.expected_figures as expected
from tribokin.iso9283.gaussian_tests import ShapeTable
from tribokin.maps.schema import map_figures
from tribokin.propagation.exact import tool_deviations_exact, tool_frames
from tribokin.simulation.pose_test import PoseRunner
from tribokin.streams import expected_stream
from tribokin.study.assembly import joint_models, load_robot
from tribokin.study.reading import load_study

CYCLES = 30
#: UR5 targets away from singularities (rad).
TARGETS = np.array([[0.3, -1.2, 1.4, -1.8, -1.5, 0.4], [-0.5, -1.6, 1.1, -1.2, -1.4, -0.3]])
NAMES = [figure.name for figure in map_figures("directional")]


def runner_with(stiffness: float, approach: str = "unidirectional") -> PoseRunner:
    study = load_study({"study": {"name": "bounds", "cycles": CYCLES, "seed": 4, "approach": approach},
                        "robot": {"name": "ur5", "payload_kg": 2.0},
                        "joints": {"friction": {"law": "uniform", "low": 0.09, "high": 0.16}, "stiffness": stiffness,
                                   "friction_radius_m": 0.02, "bearing_span_m": 0.08},
                        "poses": [{"name": "target", "q": TARGETS[0].tolist()}]})
    robot = load_robot(study)
    return PoseRunner(study, robot, joint_models(study, robot))


@pytest.fixture
def few_samples(monkeypatch):
    """Sampled tests of 1 500 cycles (50 tests; the RP_l band's 50 more), the random-direction mixture's of 600."""
    monkeypatch.setattr(expected, "SAMPLED_CYCLES", 1500)
    monkeypatch.setattr(expected, "MAX_BAND_FACTOR", 2)
    monkeypatch.setattr(expected, "MIN_TESTS", 20)
    monkeypatch.setattr(expected, "MULTI_CYCLES", 600)


def targets(runner: PoseRunner) -> dict:
    table = ShapeTable.simulate(CYCLES, expected_stream(runner.settings.seed, "table"))
    return expected.expected_targets(runner, expected.ExpectedSetup.build(runner, table, "directional"), TARGETS,
                                      runner.normal_forces_at(TARGETS), *tool_frames(runner.robot, TARGETS))


def recorded_engine(monkeypatch) -> list:
    """Every call of the fallbacks' engine: its configuration, deviations, outputs and the engine it chose."""
    calls, engine = [], expected.tool_deviations_at_poses

    def recording(robot, qs, dq, name, twists, translations, used):
        positions, angles = engine(robot, qs, dq, name, twists, translations, used)
        calls.append((qs[0], dq[0], positions[0], angles[0], used))
        return positions, angles

    monkeypatch.setattr(expected, "tool_deviations_at_poses", recording)
    return calls


def through_exact_fk(monkeypatch) -> None:
    """Every model falls back, and every fallback goes through exact FK: the figures of the same samples."""
    monkeypatch.setattr(expected, "serves", lambda bound, *args: np.zeros(len(bound), dtype=bool))
    monkeypatch.setattr(expected, "tool_deviations_at_poses",
                        lambda robot, qs, dq, name, twists, translations, used: tool_deviations_exact(robot, qs[0],
                                                                                                      dq[0]))


def worst_samples(dq: np.ndarray, count: int = 300) -> np.ndarray:
    """The ``count`` samples of largest deviation (where the truncation errs most) and as many others at random."""
    size = np.abs(dq).sum(axis=1)
    chosen = np.argsort(-size)[:count]
    return np.union1d(chosen, np.random.default_rng(0).choice(len(dq), count, replace=False))


def assert_figures_within_their_errors(out: dict, exact: dict, names, columns=NAMES) -> None:
    """Each figure within its derived error of exact FK's, and of rounding: 1e-9 µm (1e-15 m: positions of about a
    metre, summed in another order) or mdeg; ``columns``: the figures' names in order."""
    for name in names:
        column = columns.index(name)
        difference = np.abs(out["figures"][:, column] - exact["figures"][:, column])
        assert np.all(difference <= out["figure_errors"][:, column] * (1 + 1e-9) + 1e-9), name


@pytest.mark.parametrize("stiffness, engines, approach", [(1.0e5, ("fast-2", "fast-3"), "unidirectional"),
                                                          (25.0, ("exact",), "unidirectional"),
                                                          (1.0e5, ("fast-2", "fast-3"), "bidirectional")])
def test_a_forced_fallback_reports_the_bound_of_the_engine_it_used(stiffness, engines, approach, few_samples,
                                                                   monkeypatch):
    """Tolerance 0 (every model falls back) at ordinary joints: the fast engine, its bound > 0 and at least |fast -
    exact FK| over the samples it computed (the largest deviations among them), and every figure within its derived
    error of the same samples' figures through exact FK; joints 4 000 times softer: exact FK, bound 0, the figures
    those of exact FK. Approached from both directions: each direction's test falls back, each direction's figures
    (and the larger of the two) within their errors."""
    monkeypatch.setattr(expected, "FIGURE_TOLERANCE", 0.0)
    monkeypatch.setattr(expected, "FIGURE_FLOOR", 0.0)
    runner = runner_with(stiffness, approach)
    both = approach != "unidirectional"
    names = [figure.name for figure in map_figures("directional", both)]
    calls = recorded_engine(monkeypatch)
    out = targets(runner)
    assert [expected.TARGET_ENGINES[e] for e in out["engine"]] and all(
        expected.TARGET_ENGINES[e] in engines for e in out["engine"])
    assert np.all(out["fallbacks"] == 3 + both)
    # per target: each direction's test's and its band's further tests', three vAP_p directions', RP_l_multi's
    assert len(calls) == len(TARGETS) * (6 + 2 * both)
    for k, q in enumerate(TARGETS):
        own = [call for call in calls if np.array_equal(call[0], q)]
        for _, dq, positions, angles, used in own:
            order, position_m, angle_rad = (np.atleast_1d(value)[0] for value in used)
            assert (order > 0) == (engines != ("exact",))
            assert (position_m > 0 and angle_rad > 0) if order else (position_m == angle_rad == 0)
            assert out["engine_bound"][k, 0] >= position_m and out["engine_bound"][k, 1] >= angle_rad
            chosen = worst_samples(dq)
            exact_positions, exact_angles = tool_deviations_exact(runner.robot, q, dq[chosen])
            assert np.linalg.norm(positions[chosen] - exact_positions, axis=1).max() <= position_m + 1e-15
            assert np.linalg.norm(angles[chosen] - exact_angles, axis=1).max() <= angle_rad + 1e-15
    exact = pytest.MonkeyPatch.context()
    with exact as patch:
        through_exact_fk(patch)
        reference = targets(runner)
    assert_figures_within_their_errors(out, reference, [name for name in names if name != "dominant_share"], names)
    errors = np.delete(out["figure_errors"], names.index("dominant_share"), axis=1)
    if engines == ("exact",):
        assert np.all(out["engine_bound"] == 0) and np.all(errors == 0)
    else:
        assert np.all(errors > 0)


def test_where_the_first_order_model_serves_each_figure_is_within_its_derived_error_of_exact_fk(few_samples,
                                                                                               monkeypatch):
    """Stiff joints: the first-order model serves every model at both targets (engine first-order, no fallback), its
    bound is within 0.1 % of each figure it serves, and each figure of the sampled tests (RP_l and its band, AP_p,
    RP_a/b/c, the semi-axis, RP_l_multi) is within its derived error of the same samples through exact FK."""
    runner = runner_with(1.0e6)
    out = targets(runner)
    assert np.all(out["engine"] == expected.FIRST_ORDER) and np.all(out["fallbacks"] == 0)
    served = ("RP_l_um", "AP_p_um", "RP_a_mdeg", "RP_b_mdeg", "RP_c_mdeg", "vAP_p_um", "RP_l_multi_um")
    for name in served:
        column = NAMES.index(name)
        assert np.all(out["figure_errors"][:, column] <= 1e-3 * out["figures"][:, column])
    with pytest.MonkeyPatch.context() as patch:
        through_exact_fk(patch)
        reference = targets(runner)
    assert_figures_within_their_errors(out, reference, [name for name in NAMES if name not in (
        "vAP_p_um", "dominant_share")])  # vAP_p's first-order form is not sampled: no same samples to compare


def test_a_map_with_soft_joints_reports_its_fallbacks_engines_and_bounds_in_its_table_and_summary(few_samples):
    """ur5-map-horizontal's robot and loads with stiffness 2 000 N·m/rad on a 3 × 2 plane: the first-order model
    does not serve, the targets fall back to the fast engine (or exact FK where its bound exceeds 0.1 nm); map.csv's
    engine, engine_bound_nm and _nrad (through to_pandas) and summary.json's computed block say so, the fast ones'
    bounds above 0 (they were 0 before), each figure's error (figure_error) its RP_l error from the bound."""
    from tribokin import run_study

    study = {"study": {"name": "soft", "cycles": CYCLES, "seed": 3}, "robot": {"name": "ur5", "payload_kg": 3.0},
             "joints": {"friction": {"law": "uniform", "low": 0.09, "high": 0.16}, "stiffness": 2000.0,
                        "friction_radius_m": 0.02, "bearing_span_m": 0.08},
             "map": {"kind": "plane", "origin_m": [0.0, -0.55, 0.1], "axis_u": [1, 0, 0], "axis_v": [0, 1, 0],
                     "extent_u_m": [-0.3, 0.3], "extent_v_m": [-0.2, 0.2], "resolution": [3, 2],
                     "rpy_deg": [180, 0, 90], "directional": False}}  # the test's engine alone (vAP_p's go exact)
    workspace_map = run_study(study).map
    computed = workspace_map.summary()["computed"]["soft"]
    table = workspace_map.to_pandas()
    reached = table[table["reachable"]]
    fast = reached["engine"].isin(["fast-2", "fast-3"])
    assert fast.any() and set(reached["engine"]) <= {"fast-2", "fast-3", "exact"}
    assert computed["fallback_targets"] == len(reached)
    assert {name: int((reached["engine"] == name).sum()) for name in ("fast-2", "fast-3", "exact")} == {
        name: computed["engine_targets"][name] for name in ("fast-2", "fast-3", "exact")}
    assert (reached.loc[fast, "engine_bound_nm"] > 0).all() and (reached.loc[fast, "engine_bound_nrad"] > 0).all()
    assert (reached.loc[~fast, ["engine_bound_nm", "engine_bound_nrad"]] == 0).all().all()
    assert computed["engine_max_deviation_nm"] == reached["engine_bound_nm"].max()
    assert computed["engine_max_angle_deviation_nrad"] == reached["engine_bound_nrad"].max()
    assert (table.loc[~table["reachable"], "engine"] == "").all()
    errors = workspace_map.reference.figure_error("RP_l_um")[workspace_map.reachable]
    np.testing.assert_allclose(errors, (1 + 3 * np.sqrt(CYCLES / (CYCLES - 1))) * reached["engine_bound_nm"] * 1e-3,
                               rtol=1e-12)


def test_an_analytic_rp_l_multi_the_first_order_model_does_not_serve_falls_back_to_sampled_fast_engine_cycles(
        few_samples):
    """From 500 cycles with Gaussian laws RP_l_multi comes from the sign mixture's moments; with soft joints
    (2 000 N·m/rad) the mixed first-order model's bound does not guarantee it to 0.1 %, so each target's cycles are
    sampled through the fast engine instead: fallbacks counted, the engine (a fast order or exact FK) and its bound
    recorded (above 0 for a fast order), the figure within 5 % of the first-order closed form (what the model's
    curvature moves), not equal to it."""
    study = load_study({"study": {"name": "soft", "cycles": 500, "seed": 4},
                        "robot": {"name": "ur5", "payload_kg": 2.0},
                        "joints": {"friction": {"preset": "42CD4-treated"}, "stiffness": 2000.0,
                                   "friction_radius_m": 0.02, "bearing_span_m": 0.08},
                        "poses": [{"name": "target", "q": TARGETS[0].tolist()}]})
    robot = load_robot(study)
    runner = PoseRunner(study, robot, joint_models(study, robot))
    setup = expected.ExpectedSetup.build(runner, None, "directional")
    lever = expected.friction_loads(runner.models, runner.normal_forces_at(TARGETS)) * expected.friction_lever(
        runner.models, robot.joint_is_prismatic)
    mixed = expected.linear_model(robot, setup.moments, TARGETS, lever, np.zeros_like(lever), mixed=True)
    analytic = expected._multi_moments(mixed, setup.moments, 500) * 1e6
    rp, _, used, fallen = expected._multi(runner, setup, TARGETS, mixed)
    assert fallen.tolist() == [1, 1] and (used.engine > expected.FIRST_ORDER).all()
    fast = used.engine < expected.TARGET_ENGINES.index("exact")
    assert (used.bound[fast] > 0).all() and (used.bound[~fast] == 0).all()
    assert np.all(np.abs(rp / analytic - 1) < 0.05) and not np.allclose(rp, analytic, rtol=1e-6, atol=0)
