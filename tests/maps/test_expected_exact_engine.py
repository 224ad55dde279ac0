"""``study.engine = "exact"`` in expected maps (:mod:`tribokin.maps.expected_figures`): every figure sampled through
exact Pinocchio FK (no closed form, no first-order figure), each target's engine exact with bound 0, the summary's
``computed.<scenario>.engine`` exact; the figures within their stated Monte Carlo errors of the default engine's, a
Gaussian law's too (sampled, not analytic), at 30 cycles and from single cycles at 600; the same numbers at every
target (chunking changes no byte). Few sampled cycles, so that exact FK (about 8 µs a sample) stays within seconds."""

import numpy as np
import pytest

import tribokin.maps.expected_figures as expected
from tribokin import run_study
from tribokin.maps.expected_figures import SAMPLED, stated_figures
from tribokin.maps.schema import map_figures, mc_error_name
from tribokin.propagation.exact import tool_frames
from tribokin.simulation.pose_test import PoseRunner
from tribokin.study.assembly import joint_models, load_robot
from tribokin.study.reading import load_study

RAW, TREATED = {"preset": "42CD4-raw"}, {"preset": "42CD4-treated"}  # a uniform law, a Gaussian one


@pytest.fixture
def few_samples(monkeypatch):
    """Sampled tests of 6 000 cycles (200 tests of 30; the RP_l band's 200 more), the random-direction mixture's of
    1 200."""
    monkeypatch.setattr(expected, "SAMPLED_CYCLES", 6_000)
    monkeypatch.setattr(expected, "MAX_BAND_FACTOR", 2)
    monkeypatch.setattr(expected, "MULTI_CYCLES", 1_200)


def plane_study(engine: str, friction: dict, approach: str = "unidirectional", cycles: int = 30) -> dict:
    """A UR5 on a 3 × 2 plane (ur5-map-horizontal's loads), its directional figures on."""
    return {"study": {"name": "plane", "cycles": cycles, "seed": 3, "approach": approach, "engine": engine},
            "robot": {"name": "ur5", "payload_kg": 3.0},
            "joints": {"friction": friction, "stiffness": 1.0e5, "friction_radius_m": 0.02, "bearing_span_m": 0.08},
            "map": {"kind": "plane", "origin_m": [0.0, -0.55, 0.1], "axis_u": [1, 0, 0], "axis_v": [0, 1, 0],
                    "extent_u_m": [-0.3, 0.3], "extent_v_m": [-0.2, 0.2], "resolution": [3, 2],
                    "rpy_deg": [180, 0, 90]}}


def only_exact_fk(monkeypatch, refused_names=("_analytic", "_vap_expected", "_multi_moments", "sampled_tests")
                  ) -> list:
    """Every closed form and first-order figure (``refused_names``) refused, and every engine call recorded (its
    orders: 0, exact FK)."""
    def refused(*args, **kwargs):
        raise AssertionError("a closed-form or first-order figure under engine exact")

    for name in refused_names:
        monkeypatch.setattr(expected, name, refused)
    calls, engine = [], expected.tool_deviations_at_poses

    def recording(robot, qs, dq, name, twists, translations, used):
        calls.append((name, dq.shape[1], used.order.tolist(), used.position_m.tolist(), used.angle_rad.tolist()))
        return engine(robot, qs, dq, name, twists, translations, used)

    monkeypatch.setattr(expected, "tool_deviations_at_poses", recording)
    return calls


@pytest.mark.parametrize("friction, approach", [(RAW, "unidirectional"), (TREATED, "bidirectional")])
def test_an_exact_map_samples_every_figure_through_exact_fk_and_agrees_with_the_default(friction, approach,
                                                                                      few_samples, monkeypatch):
    """The default engine's map, then the exact one's with every closed form and first-order figure refused: each
    reached target's engine exact, its bound 0 nm / 0 nrad, every figure sampled (a Gaussian law's too, which the
    default computes in closed form), no fallback counted, the summary's engine exact (the default's fast); every
    engine call exact FK; each figure with a stated error within 4.5 √(e₁² + e₂²) of the default's (e the stated
    errors times the figures, plus the default's error from its bound), vAP_p and RP_l_multi included, each
    direction's too."""
    default = run_study(plane_study("fast", friction, approach)).map
    calls = only_exact_fk(monkeypatch)
    exact = run_study(plane_study("exact", friction, approach)).map
    reached = exact.reachable
    assert reached.sum() >= 4
    table = exact.to_pandas()[reached]
    assert (table["engine"] == "exact").all()
    assert (table[["engine_bound_nm", "engine_bound_nrad"]] == 0).all().all()
    computed, fast = exact.summary()["computed"]["plane"], default.summary()["computed"]["plane"]
    assert computed["engine"] == "exact" and fast["engine"] == "fast"
    assert computed["engine_targets"] == {"first-order": 0, "fast-2": 0, "fast-3": 0, "exact": int(reached.sum())}
    assert computed["sampled_targets"] == reached.sum() and computed["analytic_targets"] == 0
    assert computed["fallback_targets"] == 0 and computed["engine_max_deviation_nm"] == 0.0
    assert (exact.reference.read("method")[reached] == SAMPLED).all()
    if friction is TREATED:
        assert fast["analytic_targets"] == reached.sum()
    assert calls and {(name, tuple(order)) for name, _, order, _, _ in calls} == {("exact", (0,))}
    assert all(position == [0.0] and angle == [0.0] for *_, position, angle in calls)
    compared = 0
    for name in stated_figures("directional", approach != "unidirectional"):
        ours, theirs = exact.reference.figure(name)[reached], default.reference.figure(name)[reached]
        error = np.hypot(exact.reference.mc_error(name)[reached] * ours, default.reference.mc_error(name)[reached]
                         * theirs)
        assert (table[mc_error_name(name)] > 0).all(), name
        within = 4.5 * error + default.reference.figure_error(name)[reached] + 1e-9
        assert np.all(np.abs(ours - theirs) <= within), (name, ours, theirs, error)
        compared += 1
    assert compared >= 10


def test_exact_figures_are_each_targets_own_whatever_targets_it_is_computed_with(few_samples):
    """The same common random numbers at every target: a target's exact figures, errors and engine the same bytes
    computed with another target or alone (so independent of the map's chunks)."""
    study = load_study({**plane_study("exact", RAW), "poses": [{"name": "target", "q": [0.3, -1.2, 1.4, -1.8, -1.5,
                                                                                           0.4]}]})
    robot = load_robot(study)
    runner = PoseRunner(study, robot, joint_models(study, robot))
    targets = np.array([[0.3, -1.2, 1.4, -1.8, -1.5, 0.4], [-0.5, -1.6, 1.1, -1.2, -1.4, -0.3]])

    def at(chosen):
        setup = expected.ExpectedSetup.build(runner, None, "directional")
        return expected.expected_targets(runner, setup, chosen, runner.normal_forces_at(chosen),
                                         *tool_frames(robot, chosen))

    both, alone = at(targets), at(targets[1:])
    for name in ("figures", "mc_errors", "engine", "engine_bound", "method"):
        np.testing.assert_array_equal(both[name][1:], alone[name], err_msg=name)


def test_from_500_cycles_exact_figures_come_from_single_cycles_through_exact_fk(few_samples, monkeypatch):
    """At 600 cycles (one series of single cycles; the first-order model's samples of the same numbers only a
    control variate, so ``sampled_tests`` stays) with a Gaussian law, which the default engine computes in closed
    form (RP_l_multi from the sign mixture's moments): every engine call exact FK, the engine exact, bound 0, sampled,
    and each stated figure within 4.5 √(e₁² + e₂²) of the default's plus its error from the bound."""
    q = [0.3, -1.2, 1.4, -1.8, -1.5, 0.4]
    runs = {}
    for engine in ("fast", "exact"):
        study = load_study({**plane_study(engine, TREATED, cycles=600), "poses": [{"name": "target", "q": q}]})
        robot = load_robot(study)
        runner = PoseRunner(study, robot, joint_models(study, robot))
        if engine == "exact":
            calls = only_exact_fk(monkeypatch, ("_analytic", "_vap_expected", "_multi_moments"))
        targets = np.array([q])
        runs[engine] = expected.expected_targets(runner, expected.ExpectedSetup.build(runner, None, "directional"),
                                                 targets, runner.normal_forces_at(targets),
                                                 *tool_frames(robot, targets))
    default, exact = runs["fast"], runs["exact"]
    assert default["method"][0] == expected.ANALYTIC and exact["method"][0] == SAMPLED
    assert exact["engine"][0] == expected.TARGET_ENGINES.index("exact") and not exact["engine_bound"].any()
    assert exact["fallbacks"][0] == 0 and {tuple(order) for _, _, order, _, _ in calls} == {(0,)}
    names = [figure.name for figure in map_figures("directional")]
    for name in stated_figures("directional", False):
        column = names.index(name)
        ours, theirs = exact["figures"][0, column], default["figures"][0, column]
        error = np.hypot(exact["mc_errors"][0, column] * ours, default["mc_errors"][0, column] * theirs)
        assert abs(ours - theirs) <= 4.5 * error + default["figure_errors"][0, column] + 1e-9, (name, ours, theirs)
