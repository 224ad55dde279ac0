"""Expected figures of a pose's ISO tests whose cycles are correlated: a joint's friction a time series
(:mod:`tribokin.tribology.friction_series`), each stated with its relative Monte Carlo standard error.

A test's n cycles are not independent draws, so neither the closed forms of independent Gaussian cycles
(:mod:`tribokin.iso9283.gaussian_tests`) nor a map's common random numbers of single cycles apply. Two paths:

- **analytic** (:func:`analytic_figures`), where every joint's law is Gaussian with negligible truncation (or
  constant) and its series stationary: ``ar1`` and ``steady_mean_std`` only (no ``run_in``, ``thermal``), the mean at
  least ``NEGLIGIBLE_TRUNCATION_SIGMAS`` standard deviations of a cycle's value (σ² + τ², τ the steady mean's spread);
  the engine ``fast``, the first-order model about the mean deviation (:func:`~tribokin.maps.expected_figures.
  linear_model`, its bound over every cycle's deviation, the steady offset's included) serving the pose by the map's
  rule (:func:`~tribokin.maps.expected_figures.serves`). Joint k's value in cycle j is μ_k + τ_k o_k + σ_k z_kj (o_k
  one standard normal per test, z_k a stationary Gaussian AR(1) of lag-one correlation ρ_k = ``ar1``), so the tool's
  cycles are jointly Gaussian with Cov(y_i, y_j) = Σ_k b_k b_kᵀ (σ_k² ρ_k^|i−j| + τ_k²) + δ_ij Σ_k c_k c_kᵀ
  (:func:`cycle_covariance`; b_k the tool's deviation per unit of joint k's value, its Jacobian column times the
  joint's sign and lost motion per unit, c_k its column times the joint's noise). What that determines in closed form
  is computed so (stated error 0): E[AP_p] = E|ȳ − commanded|, ȳ normal of covariance the blocks' mean (the offsets
  τ_k count here: they do not cancel in AP); E[RP_a/b/c] = 3 E[S], S² = xᵀ M x / (n − 1) of the angle component's
  cycles x (M the centring), so E[S] = E√(Σ λ_i z_i²) over the eigenvalues of M C M / (n − 1) (C that component's n ×
  n covariance), by :func:`~tribokin.iso9283.gaussian_tests.expected_root`'s quadrature (at ρ = 0: σ c₄(n)); E[l̄] of
  RP_l = l̄ + 3 S_l, the mean over cycles of E|y_j − ȳ| (y_j − ȳ normal of covariance D_j, the offsets τ cancelling:
  :func:`~tribokin.iso9283.gaussian_tests.expected_norm`). E[S_l] and the band of one test's RP_l have no closed
  form: Gaussian tests are sampled from the exact covariance (no forward kinematics, no series drawn: each joint's
  shocks through :func:`~tribokin.tribology.friction_series.ar1_filter`, the tool's offsets b_k σ_k z_k + c_k ε),
  their mean RP_l with l̄ and the mean of l_j² as control variates (both expectations known: E[l̄] above, E[l_j²] =
  tr D_j), the band their RP_l's percentiles.
- **sampled** (:func:`sampled_figures`) otherwise (another law, a running-in, a warm-up, ``study.engine = "exact"``,
  or a pose the first-order model does not serve): whole tests drawn as the pose's own test draws them (each joint's
  series from its start in every test, :meth:`~tribokin.simulation.pose_test.PoseRunner.deviations`), through the
  study's engine (fast within its bound, or exact FK); each figure the mean over the tests, the band their RP_l's
  percentiles. Its engine's bound is kept (``bound``).

Both draw :func:`series_tests` tests: ``tests_for(SAMPLED_CYCLES, n)`` (2 000 of 30 cycles) times a factor decided
before any pose is sampled (:func:`series_factor`), the same at every pose and direction, so that their numbers are
common (:func:`~tribokin.streams.expected_stream`). Cycles that move together spread less within a test and more
from test to test: at ``ar1`` = 0.9 on the agreement rule's UR5 pose, RP_l's band's ends at 2 000 tests would state
errors of about 1.5 % (a Gaussian law) and 3.5 % (a uniform one); the factor brings each stated error of a
one-dimensional cloud of each joint's series within ``MC_ERROR_AIM`` (up to ``MAX_SERIES_FACTOR``)."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from tribokin.iso9283.gaussian_tests import BAND_PERCENTILES, expected_norm, expected_root, mean_error, percentile_error
from tribokin.iso9283.metrics import orientation_repeatability, position_repeatability, position_spread
from tribokin.maps.expected_figures import (
    BLOCK_CYCLES,
    NEGLIGIBLE_TRUNCATION_SIGMAS,
    SAMPLED_CYCLES,
    SPLIT_FIGURES,
    JointMoments,
    linear_model,
    pilot_factor,
    relative,
    rp_l_errors,
    serves,
    tests_for,
)
from tribokin.propagation.exact import engine_orders, tool_deviations_at_poses, tool_frames
from tribokin.simulation.joint_errors import TAIL_STDS, JointErrorModel, friction_lever, friction_loads
from tribokin.simulation.pose_test import PoseRunner, PoseTask
from tribokin.streams import expected_stream
from tribokin.tribology.friction_series import FrictionSeries, ar1_filter, draw_series, lag_correlations
from tribokin.tribology.laws import Constant, Gaussian, Scaled
from tribokin.units import MDEG_PER_RAD, UM_PER_M

#: Most cycles of a test the analytic path takes: it holds the cycles' (n, n, 3, 3) covariance (18 MB at 500) and
#: takes each angle's figure from the eigenvalues of an n × n matrix (n³ work); longer tests are sampled.
ANALYTIC_MAX_CYCLES = 500
#: Where the figures came from.
ANALYTIC, SAMPLED = "analytic", "sampled"
#: The most times the default tests a pose's correlated figures take (:func:`series_factor`): 200 000 tests of 30
#: cycles, about 3 CPU s a direction through the first-order model on a UR5 (more through the fast engine). Few
#: series ask for more: a uniform law at ``ar1`` = 0.99 asks for about 390 (its lower band end states 0.90 % at this
#: cap on the agreement rule's UR5 pose, 1.13 % at 64, every other figure at most 0.19 %).
MAX_SERIES_FACTOR = 100


@dataclass(frozen=True)
class SeriesFigures:
    """A direction's expected figures with correlated cycles: ``values`` [µm, mdeg] and their relative Monte Carlo
    standard errors ``mc_errors`` by name (:data:`~tribokin.maps.expected_figures.SPLIT_FIGURES`), the ``method``
    (``"analytic"`` or ``"sampled"``) and the ``bound`` (2,) [m, rad] of the engine on |engine − exact FK| over every
    sample it computed (the first-order model's, the fast engine's, or 0: exact FK)."""

    values: dict[str, float]
    mc_errors: dict[str, float]
    method: str
    bound: np.ndarray


def series_of(model: JointErrorModel) -> FrictionSeries:
    """A joint's time keys (:class:`~tribokin.tribology.friction_series.FrictionSeries`; none: independent draws)."""
    return model.series or FrictionSeries()


def stationary_gaussian(model: JointErrorModel) -> bool:
    """Whether a joint's values are a stationary Gaussian series with negligible truncation: its law Gaussian (or
    constant), no running-in nor warm-up, the mean at least ``NEGLIGIBLE_TRUNCATION_SIGMAS`` standard deviations of a
    cycle's value, the steady mean's spread included."""
    series, law = series_of(model), model.friction
    inner = law.inner if isinstance(law, Scaled) else law
    spread = math.hypot(law.std(), series.steady_mean_std)  # both in the law's quantity
    return (isinstance(inner, (Gaussian, Constant)) and series.run_in is None and series.thermal is None
            and law.mean() >= NEGLIGIBLE_TRUNCATION_SIGMAS * spread)


def series_tests(runner: PoseRunner, factor: int) -> int:
    """The tests sampled of every pose and direction: ``tests_for(SAMPLED_CYCLES, cycles)`` times ``factor``
    (:func:`series_factor`)."""
    return tests_for(SAMPLED_CYCLES, runner.settings.cycles) * factor


def series_factor(runner: PoseRunner) -> int:
    """How many times ``tests_for(SAMPLED_CYCLES, cycles)`` tests every pose's correlated figures take, the same at
    every pose (common random numbers): the largest stated error of RP_l's mean, its band's ends and an angle's mean S
    in those tests of a one-dimensional cloud of each joint's values (its law and time keys but ``thermal``, whose
    power depends on the pose), over ``MC_ERROR_AIM``, squared; at most ``MAX_SERIES_FACTOR``. One joint alone is the
    heaviest case; clouds of several joints mix towards the Gaussian."""
    cycles = runner.settings.cycles
    tests = tests_for(SAMPLED_CYCLES, cycles)
    rng = expected_stream(runner.settings.seed, "series pilot")
    worst = 0.0
    for model in runner.models:
        series = replace(series_of(model), thermal=None)
        if model.friction.std() == 0 and series.run_in is None:
            continue  # a constant, at most offset per test: no spread within a test
        cloud = draw_series(model.friction, series, tests, cycles, rng).values
        errors = (*rp_l_errors(cloud), mean_error(cloud.std(axis=1, ddof=1)))
        worst = max(worst, *(float(error) for error in errors))
    return pilot_factor(worst, MAX_SERIES_FACTOR)


def blocks_of_tests(tests: int, cycles: int) -> list[int]:
    """``tests`` tests of ``cycles`` cycles in blocks drawn one after another, each within ``BLOCK_CYCLES`` cycles."""
    size = max(1, BLOCK_CYCLES // cycles)
    return [min(size, tests - start) for start in range(0, tests, size)]


def correlated_figures(runner: PoseRunner, task: PoseTask, forces_N: np.ndarray, direction: np.ndarray,
                       factor: int) -> SeriesFigures:
    """The expected figures of tests of the runner's ``cycles`` cycles at ``task``'s pose under bearing loads
    ``forces_N`` (nv,) [N], every cycle approached with joint signs ``direction`` (nv,), ``factor``
    (:func:`series_factor`): :func:`analytic_figures` where the model allows and serves, else
    :func:`sampled_figures`."""
    models = runner.models_at(task)
    if (runner.settings.engine == "fast" and runner.settings.cycles <= ANALYTIC_MAX_CYCLES
            and all(stationary_gaussian(m) for m in models)):
        figures = analytic_figures(runner, task, forces_N, direction, factor)
        if figures is not None:
            return figures
    return sampled_figures(runner, task, forces_N, direction, factor)


def cycle_covariance(columns: np.ndarray, std: np.ndarray, ar1: np.ndarray, steady_mean_std: np.ndarray,
                     noise: np.ndarray, cycles: int) -> np.ndarray:
    """(cycles, cycles, d, d) Cov(y_i, y_j) of a test's cycles y_j = Σ_k b_k (τ_k o_k + σ_k z_kj) + Σ_k c_k ε_kj:
    ``columns`` b (nv, d) the tool's deviation per unit of each joint's value, ``std`` σ (nv,), ``ar1`` ρ (nv,) (z_k a
    stationary AR(1): corr(z_ki, z_kj) = ρ_k^|i−j|), ``steady_mean_std`` τ (nv,) (o_k one standard normal per test),
    ``noise`` c (nv, d) (ε independent standard normals): Σ_k b_k b_kᵀ (σ_k² ρ_k^|i−j| + τ_k²) + δ_ij Σ_k c_k c_kᵀ."""
    lags = np.stack([s * s * lag_correlations(r, cycles) + t * t for s, r, t in zip(std, ar1, steady_mean_std,
                                                                                  strict=True)])
    own = np.einsum("ka,kb->ab", noise, noise)
    return np.einsum("kij,ka,kb->ijab", lags, columns, columns) + np.eye(cycles)[:, :, None, None] * own


def _series_parameters(models: list[JointErrorModel]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(nv,) each joint's σ of one cycle's value about its test's steady mean, ``ar1`` and ``steady_mean_std``."""
    series = [series_of(m) for m in models]
    return (np.array([m.friction.std() for m in models]), np.array([s.ar1 for s in series]),
            np.array([s.steady_mean_std for s in series]))


def analytic_figures(runner: PoseRunner, task: PoseTask, forces_N: np.ndarray, direction: np.ndarray,
                     factor: int) -> SeriesFigures | None:
    """:func:`correlated_figures` of stationary Gaussian series in the first-order model (the module's docstring), or
    ``None`` where its bound does not serve the pose (:func:`~tribokin.maps.expected_figures.serves`)."""
    robot, n = runner.robot, runner.settings.cycles
    models = runner.models_at(task)
    std, ar1, steady = _series_parameters(models)
    total = np.hypot(std, steady)
    moments = JointMoments.of(models)  # a cycle's value spreads by σ and the steady offset: the model's support
    moments = replace(moments, std=total, departure=np.where(steady > 0, TAIL_STDS * total, moments.departure))
    lever = friction_loads(models, forces_N) * friction_lever(models, robot.joint_is_prismatic)
    model = linear_model(robot, moments, task.q[None], lever[None], direction[None], mixed=False)
    jacobian = model.jacobian[0]  # (6, nv)
    per_unit = (jacobian * (direction * lever)).T  # (nv, 6): b_k, positions then angles
    noise = (jacobian * moments.noise_std).T
    position = cycle_covariance(per_unit[:, :3], std, ar1, steady, noise[:, :3], n)
    mean_block = position.mean(axis=(0, 1))
    commanded = robot.tool_placement(task.q).translation
    values = {"AP_p_um": float(expected_norm(model.position_m[0] - commanded, mean_block)) * UM_PER_M}
    each = position.mean(axis=0)  # (n, 3, 3): mean over i of Cov(y_i, y_j)
    offsets = np.einsum("jjab->jab", position) - each - np.swapaxes(each, 1, 2) + mean_block  # D_j
    mean_distance = float(expected_norm(np.zeros(3), offsets).mean())
    centring = np.eye(n) - 1 / n
    for i, axis in enumerate("abc"):
        angle = cycle_covariance(per_unit[:, 3 + i:4 + i], std, ar1, steady, noise[:, 3 + i:4 + i], n)[:, :, 0, 0]
        lam = np.maximum(np.linalg.eigvalsh(centring @ angle @ centring), 0.0) / max(n - 1, 1)
        deviation = float(expected_root(np.zeros(1), lam[None])[0]) if lam.sum() > 0 else 0.0  # still: S = 0
        values[f"RP_{axis}_mdeg"] = 3 * deviation * MDEG_PER_RAD
    rng = expected_stream(runner.settings.seed, "series gaussian tests")
    rp_l, controls = [], []
    for count in blocks_of_tests(series_tests(runner, factor), n):
        shocks = rng.standard_normal((len(models), count, n))
        z = np.stack([ar1_filter(shocks[k], r) if r else shocks[k] for k, r in enumerate(ar1)], axis=-1)
        draws = z * std @ per_unit[:, :3] + rng.standard_normal((count, n, len(models))) @ noise[:, :3]
        repeatability, distances = position_repeatability(draws)
        rp_l.append(repeatability)
        controls.append(np.stack([distances.mean(axis=-1), np.square(distances).mean(axis=-1)], axis=-1))
    rp_l = np.concatenate(rp_l)
    known = np.array([mean_distance, float(np.trace(offsets, axis1=1, axis2=2).mean())])
    rp_l_mean, rp_l_error = controlled(rp_l, np.concatenate(controls), known)
    values["RP_l_um"] = rp_l_mean * UM_PER_M
    mc = {name: 0.0 for name in values}
    mc["RP_l_um"] = rp_l_error
    for name, percentile in zip(("RP_l_lo_um", "RP_l_hi_um"), BAND_PERCENTILES, strict=True):
        values[name] = float(np.percentile(rp_l, percentile)) * UM_PER_M
        mc[name] = float(percentile_error(rp_l, percentile))
    if not serves(model.bound, n, {name: np.array([value]) for name, value in values.items()}, "test")[0]:
        return None
    return SeriesFigures({name: values[name] for name in SPLIT_FIGURES}, {name: mc[name] for name in SPLIT_FIGURES},
                         ANALYTIC, model.bound[0].copy())


def controlled(values: np.ndarray, controls: np.ndarray, known: np.ndarray) -> tuple[float, float]:
    """The mean of ``values`` (N,) with control variates ``controls`` (N, c) of known expectations ``known`` (c,):
    the values' mean less the regression's slopes times the controls' mean departures, and its relative standard error
    (the residuals' standard deviation, c + 1 degrees of freedom taken, over √N)."""
    offsets = controls - controls.mean(axis=0)
    slopes = np.linalg.lstsq(offsets, values - values.mean(), rcond=None)[0]
    estimate = float(values.mean() - slopes @ (controls.mean(axis=0) - known))
    residuals = values - offsets @ slopes
    error = math.sqrt(float(np.sum(np.square(residuals - residuals.mean()))) / (len(values) - len(known) - 1))
    return estimate, float(relative(np.array(error / math.sqrt(len(values))), np.array(estimate)))


def sampled_figures(runner: PoseRunner, task: PoseTask, forces_N: np.ndarray, direction: np.ndarray,
                    factor: int) -> SeriesFigures:
    """:func:`correlated_figures` from whole tests drawn as the pose's own (each joint's series from its start in every
    test, :meth:`~tribokin.simulation.pose_test.PoseRunner.deviations`) through the study's engine: each figure the
    mean over :func:`series_tests` tests (drawn in :func:`blocks_of_tests`), the band their RP_l's percentiles; the
    numbers common to every pose and direction (``"series tests"``); the bound the largest of the blocks' engines'."""
    cycles, engine = runner.settings.cycles, runner.settings.engine
    rng = expected_stream(runner.settings.seed, "series tests")
    twists, translations = tool_frames(runner.robot, task.q[None])
    commanded = runner.robot.tool_placement(task.q).translation
    blocks, bounds = [], []
    for count in blocks_of_tests(series_tests(runner, factor), cycles):
        signs = np.broadcast_to(direction, (count * cycles, len(direction)))
        dq, _ = runner.deviations(task, forces_N, signs, rng, count)
        used = engine_orders(twists, dq[None], engine)
        positions, angles = tool_deviations_at_poses(runner.robot, task.q[None], dq[None], engine, twists,
                                                     translations, used)
        spread = position_spread(positions[0].reshape(count, cycles, 3))
        rp_abc = orientation_repeatability(angles[0].reshape(count, cycles, 3)) * MDEG_PER_RAD
        blocks.append({"RP_l_um": spread.RP_l_m * UM_PER_M,
                       "AP_p_um": np.linalg.norm(spread.barycenter_m - commanded, axis=-1) * UM_PER_M,
                       **{f"RP_{axis}_mdeg": rp_abc[:, i] for i, axis in enumerate("abc")}})
        bounds.append([float(used.position_m[0]), float(used.angle_rad[0])])
    per_test = {name: np.concatenate([block[name] for block in blocks]) for name in blocks[0]}
    values = {name: float(figure.mean()) for name, figure in per_test.items()}
    mc = {name: float(mean_error(figure)) for name, figure in per_test.items()}
    for name, percentile in zip(("RP_l_lo_um", "RP_l_hi_um"), BAND_PERCENTILES, strict=True):
        values[name] = float(np.percentile(per_test["RP_l_um"], percentile))
        mc[name] = float(percentile_error(per_test["RP_l_um"], percentile))
    return SeriesFigures({name: values[name] for name in SPLIT_FIGURES}, {name: mc[name] for name in SPLIT_FIGURES},
                         SAMPLED, np.max(bounds, axis=0))
