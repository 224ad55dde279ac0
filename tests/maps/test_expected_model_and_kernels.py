"""The first-order model's bound against exact Pinocchio forward kinematics at every target of a map, and expected
figures' kernels: compiled against NumPy, and a target's figures independent of the others in its block. (The figures
against an independent Monte Carlo through exact FK: ``test_agreement_rule.py``.)
"""

import dataclasses

import numpy as np
import pytest

from tribokin.maps.expected_figures import ANALYTIC, SAMPLED, ExpectedSetup, expected_targets
from tribokin.maps.schema import map_figures
from tribokin.propagation.exact import tool_deviations_exact, tool_frames
from tribokin.simulation.pose_test import PoseRunner
from tribokin.study.assembly import joint_models, load_robot
from tribokin.study.reading import load_study

CYCLES = 30
LAWS = {"gaussian": {"law": "gaussian", "mean": 0.1375, "std": 0.0075},
        "uniform": {"law": "uniform", "low": 0.09, "high": 0.16},
        "lognormal": {"law": "lognormal", "mean": 0.12, "std": 0.03}}
#: A target of each robot away from singularities (rad).
TARGETS = {"ur5": [0.3, -1.2, 1.4, -1.8, -1.5, 0.4], "panda": [0.2, -0.4, 0.1, -2.0, 0.1, 1.8, 0.6]}


def runner_for(robot_name: str, law: str) -> PoseRunner:
    study = load_study({"study": {"name": "check", "cycles": CYCLES, "seed": 5},
                        "robot": {"name": robot_name, "payload_kg": 2.0},
                        "joints": {"friction": LAWS[law], "stiffness": 1.0e5, "friction_radius_m": 0.02,
                                   "bearing_span_m": 0.08},
                        "poses": [{"name": "target", "q": TARGETS[robot_name]}]})
    robot = load_robot(study)
    return PoseRunner(study, robot, joint_models(study, robot))


def test_the_first_order_models_bound_holds_against_exact_kinematics_at_every_target_of_a_map():
    """At every reachable target of a UR5 map, deviations anywhere within the laws' supports (corners of the box
    and random points) reach positions and angles within the reported bound of the first-order model from exact FK
    (angles from the commanded orientation: c + (I - ĉ / 2) J_ω δ)."""
    from tribokin import run_study
    from tribokin.maps.expected_figures import FIRST_ORDER, JointMoments, linear_model
    from tribokin.simulation.joint_errors import friction_lever, friction_loads

    study = {"study": {"name": "bound", "cycles": 30, "seed": 2}, "robot": {"name": "ur5", "payload_kg": 3.0},
             "joints": {"friction": LAWS["uniform"], "stiffness": 1.0e5, "friction_radius_m": 0.02,
                        "bearing_span_m": 0.08},
             "map": {"kind": "plane", "origin_m": [0.0, -0.55, 0.1], "axis_u": [1, 0, 0], "axis_v": [0, 1, 0],
                     "extent_u_m": [-0.6, 0.6], "extent_v_m": [-0.35, 0.35], "resolution": [9, 6],
                     "rpy_deg": [180, 0, 90], "directional": False}}  # the test's model's bound alone
    result = run_study(study).map
    computed = result.summary()["computed"]["bound"]
    assert computed["fallback_targets"] == 0 and computed["sampled_targets"] == result.summary()["reachable"]
    mapped = load_study(study)
    robot = load_robot(mapped)
    runner = PoseRunner(mapped, robot, joint_models(mapped, robot))
    moments = JointMoments.of(runner.models)
    qs = result.q[result.reachable]
    lever = friction_loads(runner.models, runner.normal_forces_at(qs)) * friction_lever(runner.models,
                                                                                     robot.joint_is_prismatic)
    model = linear_model(robot, moments, qs, lever, np.ones_like(lever), mixed=False)
    assert np.all(result.reference.read("engine")[result.reachable] == FIRST_ORDER)
    np.testing.assert_allclose(model.bound, result.reference.read("engine_bound")[result.reachable], rtol=1e-12)
    rng = np.random.default_rng(8)
    corners = np.array(np.meshgrid(*[[-1.0, 1.0]] * 6)).reshape(6, -1).T
    for k, q in enumerate(qs):
        reach = lever[k] * moments.departure
        deltas = np.vstack([corners, rng.uniform(-1, 1, (32, 6))]) * reach
        positions, angles = tool_deviations_exact(robot, q, model.mean_dq[k] + deltas)  # angles from q's
        turn = tool_deviations_exact(robot, q, model.mean_dq[k][None])[1][0]  # c: q″'s orientation from q's
        linear = model.position_m[k] + deltas @ model.jacobian[k, :3].T
        assert np.linalg.norm(positions - linear, axis=1).max() <= model.bound[k, 0]
        model_angles = turn + deltas @ model.jacobian[k, 3:].T
        assert np.linalg.norm(angles - model_angles, axis=1).max() <= model.bound[k, 1] + 1e-15


def targets_near(robot_name: str, count: int) -> np.ndarray:
    """``count`` configurations about the robot's target (rad), the first the target itself."""
    offsets = np.random.default_rng(31).normal(0.0, 0.3, (count, len(TARGETS[robot_name])))
    offsets[0] = 0.0
    return np.array(TARGETS[robot_name]) + offsets


def expected_block(runner: PoseRunner, qs: np.ndarray, figure_set: str = "directional") -> dict:
    """:func:`expected_targets` of configurations ``qs`` on the current kernel path, with their loads and frames."""
    from tribokin.iso9283.gaussian_tests import ASYMPTOTIC_CYCLES
    from tribokin.maps.expected_figures import shape_table

    study = runner.settings
    table = None if study.cycles >= ASYMPTOTIC_CYCLES else shape_table(study.cycles, study.seed)
    forces = runner.normal_forces_at(qs)
    out = expected_targets(runner, ExpectedSetup.build(runner, table, figure_set), qs, forces,
                           *tool_frames(runner.robot, qs))
    return {**out, "normal_forces_N": forces}


@pytest.mark.parametrize("robot_name, law, cycles", [("ur5", "gaussian", 1000), ("panda", "gaussian", 30),
                                                     ("ur5", "uniform", 30)])
def test_the_compiled_expected_figures_agree_with_numpy(robot_name, law, cycles, monkeypatch):
    """Every output of 40 targets' expected figures (closed form at 1000 cycles and with the shape table at 30,
    sampled tests for a uniform law; vAP_p and RP_l_multi), compiled against NumPy: to 1e-12, lengths also to
    1e-14 m (AP_p, vAP_p and sampled distances are differences of positions of about a metre, good to a few of their
    roundings whichever the path), the band's Monte Carlo error also to 1e-11 (a difference of two sampled distances
    over a third: 1e-14 m of a few micrometres), the engines' bounds and figure errors to 1e-8, the same methods,
    fallbacks, engines and dominant joints."""
    runner = runner_for(robot_name, law)
    runner.settings = dataclasses.replace(runner.settings, cycles=cycles)
    qs = targets_near(robot_name, 40)
    monkeypatch.setenv("TRIBOKIN_KERNELS", "numpy")
    reference = expected_block(runner, qs)
    monkeypatch.setenv("TRIBOKIN_KERNELS", "compiled")
    compiled = expected_block(runner, qs)
    assert (reference["method"] == (ANALYTIC if law == "gaussian" else SAMPLED)).all()
    lengths = np.array([figure.name.endswith("_um") for figure in map_figures("directional")])
    for name, expected in reference.items():
        if name == "figures":
            for columns, atol in ((lengths, 1e-14 * 1e6), (~lengths, 0.0)):
                np.testing.assert_allclose(compiled[name][:, columns], expected[:, columns], rtol=1e-12, atol=atol)
        elif name in ("engine_bound", "figure_errors"):  # bounds: the composition's, a difference of series tails,
            # takes the Jacobians' roundings to about 1e-9 of itself
            np.testing.assert_allclose(compiled[name], expected, rtol=1e-8, err_msg=name)
        elif expected.dtype.kind == "f":
            atol = 1e-11 if name == "mc_errors" else 0.0
            np.testing.assert_allclose(compiled[name], expected, rtol=1e-12, atol=atol, err_msg=name)
        else:
            np.testing.assert_array_equal(compiled[name], expected, err_msg=name)


@pytest.mark.parametrize("cycles", [1000, 30])
def test_a_targets_expected_figures_do_not_depend_on_the_others_in_its_block(kernel_path, cycles):
    """The same 24 UR5 targets measured in one block and in two blocks, the second half first: the same figures
    (the same bytes on the compiled path, whose kernels take one target at a time), at 1000 cycles (closed forms)
    and 30 (RP_l_multi's sampled tests)."""
    runner = runner_for("ur5", "gaussian")
    runner.settings = dataclasses.replace(runner.settings, cycles=cycles)
    qs = targets_near("ur5", 24)
    whole = expected_block(runner, qs)
    halves = [expected_block(runner, qs[12:]), expected_block(runner, qs[:12])]
    for name, values in whole.items():
        split = np.concatenate([halves[1][name], halves[0][name]])
        if kernel_path == "compiled":
            assert np.array_equal(split, values, equal_nan=True), name
        else:
            np.testing.assert_allclose(split, values, rtol=1e-14, atol=0, err_msg=name)
