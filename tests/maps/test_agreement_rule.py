"""The agreement rule (issue 37, "Must hold"): every expected figure of a map target against an independent Monte Carlo
through exact Pinocchio forward kinematics, at ``TARGETS`` random targets away from singularities per robot (UR5,
Panda) and friction law (Gaussian, uniform, lognormal), the directional figures (vAP_p, RP_l_multi) included.

Each figure must lie within 4.5 √(e₁² + e₂²) + δ of the Monte Carlo's, and at most 10 % of the comparisons beyond
2 √(e₁² + e₂²) + δ: e₁ the figure's stated Monte Carlo error (``mc_errors``, relative, times the figure), e₂ the Monte
Carlo's own (a mean's: the tests' standard deviation over √``TESTS``; a band's end: its percentile's,
:func:`~tribokin.iso9283.gaussian_tests.percentile_error`), δ the figure's error from the engine's bound
(``figure_errors``). Every figure but the dominant joint's share (a property of the model, not of a test) is compared.

The Monte Carlo simulates ``TESTS`` ISO tests of ``CYCLES`` cycles per target and figure with the study's own error
model (:func:`~tribokin.simulation.joint_errors.sample_joint_deviations`, the loads at the target) on a fresh stream,
each cycle's tool pose through Pinocchio's forward kinematics (:func:`reached_positions`, and
:func:`~tribokin.propagation.exact.tool_deviations_pinocchio` for the angles), the figures by
:mod:`tribokin.iso9283.metrics`: unidirectional tests (every joint +) for RP_l, its band, AP_p, the largest semi-axis
and RP_a/b/c, each from its own series; the three approaches along +x, +y, +z of vAP_p (each its own series of
``CYCLES`` cycles); tests of ``CYCLES`` cycles each approached from a random joint-space direction (every joint's sign
drawn per cycle) for RP_l_multi. Over the 48 targets its relative errors e₂ at ``TESTS`` = 500 are RP_l 0.30-0.84 %,
the band's ends 0.47-2.9 %, AP_p 0.03-0.22 %, vAP_p 0.02-0.24 %, RP_l_multi 0.23-0.74 %, RP_a/b/c 0.37-0.74 %, the
largest semi-axis 0.37-0.73 %; the stated e₁ RP_l 0-0.24 %, the band's ends 0.21-1.03 %, RP_l_multi 0.24-0.81 %,
RP_a/b/c 0-0.37 %, the semi-axis 0.19-0.37 %, AP_p and vAP_p below 0.07 %. Every √(e₁² + e₂²) is held within
``LARGEST_RELATIVE_SIGMA`` of its figure, so a figure 4.5 of them off (at most about 13 %, for a band's end; 1-4 %
for the others) fails.

Each target's expected figures come from their own seed (``SEED + k``). A map's targets share their common random
numbers, so a sampled figure's Monte Carlo error is one draw common to every target of a map (RP_l_multi's z-scores
on eight lognormal UR5 targets of one seed have a standard deviation of about 0.5 about a mean of +0.86, +0.28 and
-0.91 at seeds 11, 12 and 13, the Monte Carlo at 2 000 tests; with ``study.engine = "exact"`` the same numbers through
exact FK give every sampled figure to within 7e-7 of the first-order model's, vAP_p, sampled there and in closed form
here, to 7e-4): eight targets of one seed are about one comparison of
such a figure, not eight, and the rule's allowance of 10 % beyond 2 standard errors counts independent ones. For the
same reason the Monte Carlo draws each figure from its own series.

Every case at 30 cycles (every shipped study's), and from ``ASYMPTOTIC_CYCLES`` on ``ASYMPTOTIC_CASE``: lognormal
friction on the UR5, the skewed law, at 200 tests (a 500-cycle test's RP_l spreads about four times less than a
30-cycle one's: e₂ stays within ``LARGEST_RELATIVE_SIGMA``; about 20 CPU s, where 500 tests took 47). There the
band once missed the rule: normal and 2-7 % too wide (the barycentre's first-order share left out), its low end
0.2-1.2 % low (z to -3.2 against exact FK), and the semi-axis was √λ₁ with no error stated (-0.1 to +0.17 % off,
z to +4 against 8 000 first-order tests); with :func:`~tribokin.maps.expected_figures.cycles_band` and
:func:`~tribokin.iso9283.gaussian_tests.expected_semi_axis` 5 of its 80 comparisons lie beyond 2 standard errors,
the largest |z| 3.55 (E[RP_l], its error from the 60 000 single cycles' moments). From ``ASYMPTOTIC_CYCLES`` on,
RP_l_multi from the cycles' moments once missed the rule: it drew each cycle's barycentre apart, where a test's
barycentre is one draw shared by its cycles (along a joint whose sign flips dominate the cloud it moves every cycle's
distance by ± its offset, so S_l² varies from test to test about 75 times as much as over independent cycles, and
E[S_l] lay 0.17-0.52 % above the first-order model's own tests, 4-9 standard errors; UR5 at 500 cycles: 9 of 80
beyond 2 standard errors, RP_l_multi's z-scores mean +1.16). With the shared barycentre counted
(:func:`~tribokin.iso9283.gaussian_tests.barycentre_shares`) the UR5 Gaussian case at 500 cycles gives RP_l_multi's
z-scores -1.95 to +2.63 (mean -0.07), every figure's |z| at most 2.63, and 4-5 of 80 comparisons beyond 2 standard
errors (the rule allows 8).
"""

import dataclasses

import numpy as np
import pinocchio as pin
import pytest

from tribokin.iso9283.cube import APPROACH_DIRECTIONS, held_approach_signs
from tribokin.iso9283.gaussian_tests import ASYMPTOTIC_CYCLES, BAND_PERCENTILES, percentile_error
from tribokin.iso9283.metrics import orientation_repeatability, position_spread
from tribokin.maps.expected_figures import (
    ANALYTIC,
    SAMPLED,
    VAP_DIRECTIONS,
    VAP_PAIRS,
    ExpectedSetup,
    expected_targets,
    shape_table,
)
from tribokin.maps.schema import map_figures
from tribokin.propagation.exact import tool_deviations_pinocchio, tool_frames
from tribokin.simulation.joint_errors import sample_joint_deviations
from tribokin.simulation.pose_test import PoseRunner
from tribokin.study.assembly import joint_models, load_robot
from tribokin.study.reading import load_study
from tribokin.units import MDEG_PER_RAD, UM_PER_M

TESTS, CYCLES, TARGETS, SEED = 500, 30, 8, 11
#: The case from ``ASYMPTOTIC_CYCLES`` on: (robot, law, cycles, tests).
ASYMPTOTIC_CASE = ("ur5", "lognormal", ASYMPTOTIC_CYCLES, 200)
LAWS = {"gaussian": {"law": "gaussian", "mean": 0.1375, "std": 0.0075},
        "uniform": {"law": "uniform", "low": 0.09, "high": 0.16},
        "lognormal": {"law": "lognormal", "mean": 0.12, "std": 0.03}}
#: The smallest singular value of the position Jacobian a target keeps [m]: away from singularities.
LEAST_SINGULAR_VALUE_M = 0.1
#: The figures compared: every expected figure but the dominant joint's share.
FIGURES = [figure.name for figure in map_figures("directional")]
COMPARED = [name for name in FIGURES if name != "dominant_share"]
#: The largest √(e₁² + e₂²) relative to its figure the comparisons may have (the rule's power: at most 4.5 times this
#: apart).
LARGEST_RELATIVE_SIGMA = 0.03


def runner_for(robot_name: str, law: str, cycles: int = CYCLES) -> PoseRunner:
    study = load_study({"study": {"name": "agreement", "cycles": cycles, "seed": SEED},
                        "robot": {"name": robot_name, "payload_kg": 2.0},
                        "joints": {"friction": LAWS[law], "stiffness": 1.0e5, "friction_radius_m": 0.02,
                                   "bearing_span_m": 0.08},
                        "poses": [{"name": "p", "q": [0.0] * (6 if robot_name == "ur5" else 7)}]})
    robot = load_robot(study)
    return PoseRunner(study, robot, joint_models(study, robot))


def random_targets(runner: PoseRunner, rng: np.random.Generator) -> np.ndarray:
    """(``TARGETS``, nv) configurations drawn uniformly within the joint limits (and ±π), each kept where its position
    Jacobian's smallest singular value is at least ``LEAST_SINGULAR_VALUE_M``."""
    robot = runner.robot
    low = np.maximum(robot.model.lowerPositionLimit, -np.pi)
    high = np.minimum(robot.model.upperPositionLimit, np.pi)
    found = []
    while len(found) < TARGETS:
        q = rng.uniform(low, high)
        if np.linalg.svd(robot.tool_jacobian(q)[:3], compute_uv=False)[-1] >= LEAST_SINGULAR_VALUE_M:
            found.append(q)
    return np.array(found)


def expected_at(runner: PoseRunner, q: np.ndarray, seed: int) -> dict:
    """The expected figures of one target at configuration ``q`` from study seed ``seed``'s common random numbers:
    :func:`expected_targets`' outputs of its one row (as a map's: no shape table from ``ASYMPTOTIC_CYCLES`` on)."""
    runner.settings = dataclasses.replace(runner.settings, seed=seed)
    cycles = runner.settings.cycles
    table = None if cycles >= ASYMPTOTIC_CYCLES else shape_table(cycles, seed)  # kept per process
    setup = ExpectedSetup.build(runner, table, "directional")
    at = q[None]
    out = expected_targets(runner, setup, at, runner.normal_forces_at(at), *tool_frames(runner.robot, at))
    return {name: value[0] for name, value in out.items()}


def reached_positions(robot, q: np.ndarray, dq: np.ndarray) -> np.ndarray:
    """(n, 3) tool positions [m] at configurations ``q`` + ``dq`` (n, nv), one Pinocchio forward-kinematics call each
    (:func:`~tribokin.propagation.exact.tool_deviations_pinocchio` without the angles, which cost as much again)."""
    positions = np.empty((len(dq), 3))
    for j, reached in enumerate(robot.configuration(q + dq)):
        pin.forwardKinematics(robot.model, robot.data, reached)
        positions[j] = pin.updateFramePlacement(robot.model, robot.data, robot.tool_frame_id).translation
    return positions


def monte_carlo(runner: PoseRunner, q: np.ndarray, rng: np.random.Generator, tests: int) -> tuple[dict, dict]:
    """Each figure's mean over ``tests`` simulated tests through exact FK (the band: its percentiles
    over the tests, at the order statistics' expected positions p (n + 1), numpy's ``weibull``: linear interpolation's
    (n - 1) p + 1 would pull each end inwards by about 0.27 of its standard error at 500 tests), and its Monte Carlo
    standard error, in the figures' units. Each figure from its own series of tests, so that the Monte Carlo's errors
    of different figures are independent (a test's RP_l, RP_c and largest semi-axis correlate up to 0.96-1.0 where one
    joint dominates its cloud: one fluctuation would count as three comparisons)."""
    robot, nv, cycles = runner.robot, len(q), runner.settings.cycles
    forces = runner.normal_forces_at(q)

    def deviations(signs: np.ndarray) -> np.ndarray:  # (tests, cycles, nv) joint signs -> (tests × cycles, nv) dq
        return sample_joint_deviations(runner.models, robot.joint_is_prismatic, forces, signs.reshape(-1, nv), rng)[0]

    def positions(signs: np.ndarray) -> np.ndarray:  # (tests, cycles, 3)
        return reached_positions(robot, q, deviations(signs)).reshape(*signs.shape[:2], 3)

    plus = np.ones((tests, cycles, nv))  # ISO's unidirectional test: every joint +
    commanded = robot.tool_placement(q).translation
    directions = held_approach_signs(robot, q, np.array([APPROACH_DIRECTIONS[d] for d in VAP_DIRECTIONS]))
    barycentres = [positions(np.broadcast_to(signs, plus.shape)).mean(axis=1) for signs in directions]
    angles = tool_deviations_pinocchio(robot, q, deviations(plus))[1].reshape(tests, cycles, 3)
    random_directions = rng.integers(0, 2, plus.shape) * 2.0 - 1.0  # every joint's sign drawn per cycle
    per_test = {"RP_l_um": position_spread(positions(plus)).RP_l_m * UM_PER_M,
                "AP_p_um": np.linalg.norm(positions(plus).mean(axis=1) - commanded, axis=-1) * UM_PER_M,
                "vAP_p_um": np.max([np.linalg.norm(barycentres[a] - barycentres[b], axis=-1) for a, b in VAP_PAIRS],
                                   axis=0) * UM_PER_M,
                "RP_l_multi_um": position_spread(positions(random_directions)).RP_l_m * UM_PER_M,
                **{f"RP_{axis}_mdeg": orientation_repeatability(angles)[:, i] * MDEG_PER_RAD
                   for i, axis in enumerate("abc")},
                "largest_semi_axis_um": position_spread(positions(plus)).largest_semi_axis_m * UM_PER_M}
    means = {name: values.mean() for name, values in per_test.items()}
    errors = {name: values.std(ddof=1) / np.sqrt(tests) for name, values in per_test.items()}
    band = position_spread(positions(plus)).RP_l_m * UM_PER_M
    for name, percentile in zip(("RP_l_lo_um", "RP_l_hi_um"), BAND_PERCENTILES, strict=True):
        means[name] = np.percentile(band, percentile, method="weibull")
        errors[name] = percentile_error(band, percentile) * np.percentile(band, percentile)
    return means, errors


def z_scores(robot_name: str, law: str, cycles: int = CYCLES, tests: int = TESTS) -> tuple[dict, dict, dict, list]:
    """Per compared figure (``TARGETS``,) each: the expected figure less the Monte Carlo's over √(e₁² + e₂²) (its
    z-score), √(e₁² + e₂²) relative to the figure, and δ over √(e₁² + e₂²); and each target's (method, fallbacks)."""
    runner = runner_for(robot_name, law, cycles)
    rng = np.random.default_rng(9283)
    qs = random_targets(runner, rng)
    z, relative, delta = ({name: np.empty(TARGETS) for name in COMPARED} for _ in range(3))
    computed = []
    for k, q in enumerate(qs):
        expected = expected_at(runner, q, SEED + k)
        computed.append((int(expected["method"]), int(expected["fallbacks"])))
        simulated, simulation_errors = monte_carlo(runner, q, rng, tests)
        for name in COMPARED:
            column = FIGURES.index(name)
            figure = expected["figures"][column]
            sigma = np.hypot(expected["mc_errors"][column] * abs(figure), simulation_errors[name])
            z[name][k] = (figure - simulated[name]) / sigma
            relative[name][k] = sigma / abs(figure)
            delta[name][k] = expected["figure_errors"][column] / sigma
    return z, relative, delta, computed


@pytest.mark.parametrize("robot_name, law, cycles, tests", [(robot_name, law, CYCLES, TESTS) for robot_name in
                                                             ("ur5", "panda") for law in LAWS] + [ASYMPTOTIC_CASE])
def test_each_expected_figure_agrees_with_exact_kinematics_within_the_agreement_rule(robot_name, law, cycles, tests):
    z, relative, delta, computed = z_scores(robot_name, law, cycles, tests)
    served = [method for method, fallbacks in computed if fallbacks == 0]  # the first-order model's (others: the fast
    assert len(served) >= TARGETS // 2 and set(served) == {ANALYTIC if law == "gaussian" else SAMPLED}  # engine's)
    summary = {name: f"z mean {z[name].mean():+.2f}, sd {z[name].std(ddof=1):.2f}, max |z| {np.abs(z[name]).max():.2f}"
               for name in COMPARED}
    for name in COMPARED:
        assert np.all(relative[name] <= LARGEST_RELATIVE_SIGMA), (name, relative[name])
        assert np.all(np.abs(z[name]) <= 4.5 + delta[name]), (name, summary)
    beyond = sum(int(np.sum(np.abs(z[name]) > 2 + delta[name])) for name in COMPARED)
    assert beyond <= 0.1 * TARGETS * len(COMPARED), (beyond, summary)
