"""Expected figures of a block of map targets (``map.statistic = "expected"``): each figure's mean over ISO tests of
``cycles`` cycles at the target, with the 2.5 / 97.5 % band of one test's RP_l.

The joint deviations of a cycle are dq = offset + s ⊙ (L ⊙ μ + backlash / 2) + noise (:mod:`~tribokin.simulation.
joint_errors`; L the lost motion per unit of the law's draw μ). About q″ = q + E[dq] the tool deviates by
J(q″) (dq - E[dq]) to first order (:func:`linear_model`); its error for every deviation within each law's support
(a Gaussian's mean ± ``TAIL_STDS`` standard deviations) is the fast engine's order-1 truncation bound, kept per
target as ``engine_bound``. The mean deviation itself goes through exact forward kinematics.

- **analytic** (every law Gaussian, truncation negligible, or constant; unidirectional approach): the figures of
  :mod:`tribokin.iso9283.expected` from the covariance of J(q″) dq.
- **sampled** (other laws, approach modes, or a target whose bound exceeds ``DEFAULT_TOLERANCE``): common random
  numbers: the same ``sampled_tests`` tests of drawn μ at every target (and scenario), through the linear model,
  or through the fast engine where the bound is not met (a *fallback*). The RP_l band's Monte Carlo error is kept.
- ``vAP_p_um``: the largest distance between the barycentres reached along +x, +y, +z of the base frame (joint
  signs as the measured cube's, :func:`~tribokin.iso9283.cube.held_approach_signs`); each barycentre by exact
  forward kinematics of its mean deviation plus a Gaussian of covariance Σ_d / n (the mean of n cycles); its
  expectation in closed form when one pair of directions is clearly farthest apart, else over ``VAP_DRAWS`` draws.
- ``RP_l_multi_um``: cycles each approached from a random joint-space direction (every joint's sign drawn at
  random, with equal odds): the mean RP_l over ``multi_tests`` sampled tests of that mixture.
- The dominant joint and its share are those of the population variance (what many cycles give).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tribokin.iso9283.cube import APPROACH_DIRECTIONS, approach_signs_from_jacobians
from tribokin.iso9283.expected import ANALYTIC_MIN_CYCLES, BAND_PERCENTILES, ShapeTable, c4, expected_norm, \
    expected_rp_l, percentile_error, standardised_shape
from tribokin.iso9283.metrics import orientation_repeatability, position_repeatability, position_spread
from tribokin.propagation.exact import tool_deviations_at_poses, tool_frames
from tribokin.propagation.poe import DEFAULT_TOLERANCE, truncation_bound
from tribokin.simulation.joint_errors import TAIL_STDS, JointErrorModel, approach_signs, friction_lever, friction_loads
from tribokin.simulation.pose_run import PoseRunner
from tribokin.streams import expected_stream
from tribokin.tribology.laws import Constant, FrictionLaw, Gaussian, Scaled
from tribokin.units import MDEG_PER_RAD, UM_PER_M

#: Sampled tests: about this many cycles in all (the RP_l band's error about 1 % at 30 cycles), at least 400 tests.
SAMPLED_CYCLES, MIN_TESTS = 60_000, 400
#: Tests of the random-direction mixture (only its mean is kept: about 0.5 % Monte Carlo error).
MULTI_CYCLES = 12_000
#: Sampled cycles of the targets computed together (their positions and angles in memory at once).
BLOCK_CYCLES = 400_000
#: The figures each sampled test gives.
TEST_FIGURES = ("RP_l_um", "AP_p_um", "RP_a_mdeg", "RP_b_mdeg", "RP_c_mdeg", "largest_semi_axis_um")
#: Draws of the barycentres' noise when two pairs of approach directions are about as far apart.
VAP_DRAWS = 4_000
#: Truncation of a Gaussian law below this probability counts as none: its tests are computed analytically.
NEGLIGIBLE_TRUNCATION_SIGMAS = 6.0
#: The first-order model serves where its bound is within this fraction of the deviation's size (or within
#: ``DEFAULT_TOLERANCE``): each figure then moves by at most about 8 bounds (RP_l), 0.3 % of it in the worst case.
LINEAR_TOLERANCE = 1e-3
#: The approach directions of vAP_p: +x, +y, +z of the base frame.
VAP_DIRECTIONS = ("+x", "+y", "+z")

#: The figures of an expected map, in the store's order (µm, mdeg; ``dominant_share`` in [0, 1]).
EXPECTED_FIGURES = ("RP_l_um", "RP_l_lo_um", "RP_l_hi_um", "AP_p_um", "vAP_p_um", "RP_l_multi_um", "RP_a_mdeg",
                    "RP_b_mdeg", "RP_c_mdeg", "largest_semi_axis_um", "dominant_share")
#: How a target's figures were computed (its ``method`` column).
ANALYTIC, SAMPLED = 0, 1


def gaussian_law(law: FrictionLaw) -> bool:
    """Whether draws of ``law`` are Gaussian (a constant: of zero spread) to within a negligible truncation."""
    inner = law.inner if isinstance(law, Scaled) else law
    if isinstance(inner, Constant):
        return True
    return isinstance(inner, Gaussian) and inner.params["mean"] >= NEGLIGIBLE_TRUNCATION_SIGMAS * inner.params["std"]


def largest_departure(law: FrictionLaw) -> float:
    """The largest |draw - mean| of ``law``: from its support, else ``TAIL_STDS`` standard deviations."""
    low, high = law.support()
    reach = max(law.mean() - low, high - law.mean())
    return reach if math.isfinite(reach) else TAIL_STDS * law.std()


@dataclass(frozen=True)
class JointMoments:
    """What the expected figures need of a scenario's joint models (nv,) each: the laws' ``mean``, ``std`` and
    ``departure`` (:func:`largest_departure`), ``offset``, ``half_backlash`` [m or rad], ``noise_std`` [m or rad];
    ``gaussian``: every law is (:func:`gaussian_law`)."""

    mean: np.ndarray
    std: np.ndarray
    departure: np.ndarray
    offset: np.ndarray
    half_backlash: np.ndarray
    noise_std: np.ndarray
    gaussian: bool

    @classmethod
    def of(cls, models: list[JointErrorModel]) -> JointMoments:
        laws = [m.friction for m in models]
        return cls(np.array([law.mean() for law in laws]), np.array([law.std() for law in laws]),
                   np.array([largest_departure(law) for law in laws]), np.array([m.offset for m in models]),
                   np.array([m.backlash / 2 for m in models]), np.array([m.noise_std for m in models]),
                   all(gaussian_law(law) for law in laws))


@dataclass(frozen=True)
class LinearModel:
    """The first-order model of a block of k targets approached with joint signs ``signs`` (k, nv).

    Attributes:
        mean_dq: (k, nv) E[dq] [m or rad]. position_m: (k, 3) tool position at q″ = q + E[dq] [m].
        jacobian: (k, 6, nv) tool Jacobian at q″. lever: (k, nv) lost motion per unit draw L.
        deviation_variance: (k, nv) var(dq) [m² or rad²].
        bound: (k, 2) the order-1 truncation bound [m, rad] over deviations within the laws' supports.
    """

    mean_dq: np.ndarray
    position_m: np.ndarray
    jacobian: np.ndarray
    lever: np.ndarray
    deviation_variance: np.ndarray
    bound: np.ndarray

    def covariance(self, rows: slice) -> np.ndarray:
        """(k, 3, 3) covariance of the tool's position (``rows = slice(0, 3)``) or angle (``slice(3, 6)``) deviation."""
        part = self.jacobian[:, rows]
        return np.einsum("kin,kn,kjn->kij", part, self.deviation_variance, part)

    @property
    def met(self) -> np.ndarray:
        """(k,) the bound is within ``DEFAULT_TOLERANCE``, or ``LINEAR_TOLERANCE`` of the deviation's own size (the
        root of its covariance's trace), in position [m] and in angle [rad]."""
        sizes = np.sqrt(np.stack([np.trace(self.covariance(rows), axis1=1, axis2=2)
                                  for rows in (slice(0, 3), slice(3, 6))], axis=1))
        return (self.bound <= np.maximum(DEFAULT_TOLERANCE, LINEAR_TOLERANCE * sizes)).all(axis=1)


def linear_model(robot, moments: JointMoments, qs: np.ndarray, lever: np.ndarray, signs: np.ndarray,
                 mixed: bool) -> LinearModel:
    """:class:`LinearModel` at configurations ``qs`` (k, nv) with levers ``lever`` (k, nv): every cycle with joint
    signs ``signs`` (k, nv) (+1, -1, 0: still), or (``mixed``) each joint's sign drawn per cycle with mean ``signs``.

    A joint's lost motion m = L μ + backlash / 2 departs from its mean by at most L d (d: the law's
    :func:`largest_departure`) unidirectionally, by (1 + |s̄|)(L (μ̄ + d) + backlash / 2) when its sign flips; its
    variance is s² L² σ² + (s² - s̄²) E[m]², with s² = 1 when mixed; and noise_std is added, up to ``TAIL_STDS`` of it.
    """
    mean_dq = moments.offset + signs * (lever * moments.mean + moments.half_backlash)
    twists, positions = tool_frames(robot, qs + mean_dq)
    square = np.ones_like(signs) if mixed else signs ** 2
    lost = lever * moments.mean + moments.half_backlash
    variance = square * (lever * moments.std) ** 2 + (square - signs ** 2) * lost ** 2 + moments.noise_std ** 2
    departure = ((1 + np.abs(signs)) * (lost + lever * moments.departure) if mixed
                 else np.abs(signs) * lever * moments.departure) + TAIL_STDS * moments.noise_std
    bound = truncation_bound(twists, departure[:, None, :], order=1)
    return LinearModel(mean_dq, positions, twists, lever, variance,
                       np.column_stack([bound.position_m, bound.angle_rad]).reshape(len(qs), 2))


@dataclass(frozen=True)
class ExpectedSetup:
    """What every block of one scenario's expected map shares, built once per map: the tests' ``cycles``, the
    scenario's :class:`JointMoments` and the shape table of Gaussian tests
    (:class:`~tribokin.iso9283.expected.ShapeTable`)."""

    cycles: int
    moments: JointMoments
    table: ShapeTable

    @classmethod
    def build(cls, runner: PoseRunner, table: ShapeTable) -> ExpectedSetup:
        return cls(runner.study.cycles, JointMoments.of(runner.models), table)


def tests_for(cycles_in_all: int, cycles: int) -> int:
    """Sampled tests of ``cycles`` cycles: about ``cycles_in_all`` cycles, at least ``MIN_TESTS`` tests."""
    return max(MIN_TESTS, math.ceil(cycles_in_all / cycles))


def common_numbers(runner: PoseRunner, signs: np.ndarray, tests: int, purpose: str) -> np.ndarray:
    """(tests × cycles, 3 nv) the common random numbers of one scenario's sampled tests, the same at every target:
    per cycle [s ⊙ μ, s, z], the joints' signs ``signs`` (1 or tests, cycles, nv), the laws' draws μ and standard normal
    noise z (:func:`~tribokin.streams.expected_stream` of ``purpose``). A target's deviations from E[dq] are these
    times its :func:`responses`' rows, less E[dq] - offset."""
    rng = expected_stream(runner.study.seed, purpose)
    cycles, nv = signs.shape[1], len(runner.models)
    mu = np.stack([m.friction.rvs(size=(tests, cycles), random_state=rng) for m in runner.models], axis=-1)
    noise = rng.standard_normal((tests, cycles, nv))
    return np.concatenate([signs * mu, np.broadcast_to(signs, mu.shape), noise], axis=-1).reshape(-1, 3 * nv)


def responses(model: LinearModel, moments: JointMoments, chosen: np.ndarray, rows: slice) -> np.ndarray:
    """(3 nv, 3 k) how the tool's position (``rows = slice(0, 3)``) or angle (``slice(3, 6)``) of targets ``chosen``
    (k,) moves with each of :func:`common_numbers`' columns: L_i J_i, backlash_i / 2 J_i, noise_std_i J_i."""
    part = np.swapaxes(model.jacobian[chosen, rows], 1, 2)  # (k, nv, 3)
    weights = np.concatenate([model.lever[chosen], np.broadcast_to(moments.half_backlash, model.lever[chosen].shape),
                              np.broadcast_to(moments.noise_std, model.lever[chosen].shape)], axis=1)
    stacked = weights[:, :, None] * np.concatenate([part] * 3, axis=1)  # (k, 3 nv, 3)
    return np.moveaxis(stacked, 0, 1).reshape(stacked.shape[1], -1)


def sampled_tests(model: LinearModel, moments: JointMoments, chosen: np.ndarray, numbers: np.ndarray, shape: tuple,
                  rows: slice) -> np.ndarray:
    """(k, tests, cycles, 3) tool positions [m] (``rows = slice(0, 3)``) or angle deviations from q″'s [rad]
    (``slice(3, 6)``) of targets ``chosen`` through the first-order model, for :func:`common_numbers` ``numbers``."""
    shift = np.einsum("kn,kin->ki", moments.offset - model.mean_dq[chosen], model.jacobian[chosen, rows])
    if rows.start == 0:
        shift = shift + model.position_m[chosen]
    moved = (numbers @ responses(model, moments, chosen, rows)).reshape(*shape, len(chosen), 3)
    return np.moveaxis(moved, 2, 0) + shift[:, None, None, :]


def engine_tests(runner: PoseRunner, model: LinearModel, moments: JointMoments, k: int, q: np.ndarray,
                 numbers: np.ndarray, shape: tuple) -> tuple[np.ndarray, np.ndarray]:
    """Positions [m] and angle deviations [rad] (tests, cycles, 3) of target ``k`` at configuration ``q`` through the
    fast engine (orders 2-3, else exact FK): where the first-order model's bound is not met."""
    nv = len(q)
    signed_mu, signs, noise = numbers[:, :nv], numbers[:, nv:2 * nv], numbers[:, 2 * nv:]
    dq = moments.offset + signed_mu * model.lever[k] + signs * moments.half_backlash + noise * moments.noise_std
    positions, angles = tool_deviations_at_poses(runner.robot, q[None], dq[None], "fast",
                                                 *tool_frames(runner.robot, q[None]))
    return positions.reshape(*shape, 3), angles.reshape(*shape, 3)


def blocks_of(indices: np.ndarray, cycles_each: int) -> list[np.ndarray]:
    """``indices`` in groups whose sampled cycles stay within ``BLOCK_CYCLES``."""
    size = max(1, BLOCK_CYCLES // cycles_each)
    return [indices[start:start + size] for start in range(0, len(indices), size)]


def expected_targets(runner: PoseRunner, setup: ExpectedSetup, qs: np.ndarray, forces: np.ndarray,
                     twists: np.ndarray, translations: np.ndarray) -> dict[str, np.ndarray]:
    """Expected figures of k targets at configurations ``qs`` (k, nv) under bearing loads ``forces`` (k, nv) [N];
    ``twists``, ``translations``: their :func:`~tribokin.propagation.exact.tool_frames`.

    Returns:
        ``figures`` (k, len(EXPECTED_FIGURES)), ``dominant_joint`` (k,) (-1: none), ``method`` (k,) (``ANALYTIC``
        or ``SAMPLED``), ``fallbacks`` (k,) how many of the three models (the test's, vAP_p's, RP_l_multi's) did not
        meet the bound and went through the fast engine, ``engine_bound`` (k, 2) [m, rad] the largest bound of the
        first-order models used, ``band_error`` (k,) the RP_l band's relative Monte Carlo error.
    """
    models, robot, moments = runner.models, runner.robot, setup.moments
    lever = friction_loads(models, forces) * friction_lever(models, robot.joint_is_prismatic)
    columns = {name: k for k, name in enumerate(EXPECTED_FIGURES)}
    figures = np.full((len(qs), len(EXPECTED_FIGURES)), np.nan)
    unidirectional = runner.study.approach == "unidirectional"
    signs = test_signs(runner, setup.cycles)
    model = linear_model(robot, moments, qs, lever, np.broadcast_to(signs.mean(axis=(0, 1)), lever.shape),
                         mixed=not unidirectional)
    analytic = model.met & moments.gaussian & unidirectional
    out = {"figures": figures, "method": np.where(analytic, ANALYTIC, SAMPLED),
           "fallbacks": (~model.met).astype(int), "engine_bound": np.where(model.met[:, None], model.bound, 0.0),
           "band_error": np.full(len(qs), setup.table.band_error)}
    if analytic.any():
        for name, values in _analytic(model, analytic, setup, translations[analytic]).items():
            figures[analytic, columns[name]] = values
    if not analytic.all():
        sampled = _sampled(runner, setup, model, ~analytic, signs, qs, translations)
        out["band_error"][~analytic] = sampled.pop("band_error")
        for name, values in sampled.items():
            figures[~analytic, columns[name]] = values
    vap, vap_bounds, vap_fallbacks = _vap(runner, moments, qs, lever, twists, setup.cycles)
    multi, multi_bounds, multi_fallbacks = _multi(runner, setup, qs, lever)
    figures[:, columns["vAP_p_um"]], figures[:, columns["RP_l_multi_um"]] = vap, multi
    out["fallbacks"] += vap_fallbacks + multi_fallbacks
    out["engine_bound"] = np.maximum(out["engine_bound"], np.maximum(vap_bounds, multi_bounds))
    parts = model.deviation_variance * np.sum(model.jacobian[:, :3] ** 2, axis=1)
    total = parts.sum(axis=1)
    out["dominant_joint"] = np.where(total > 0, np.argmax(parts, axis=1), -1)
    figures[:, columns["dominant_share"]] = np.where(total > 0, parts.max(axis=1) / np.where(total > 0, total, 1),
                                                     np.nan)
    return out


def test_signs(runner: PoseRunner, cycles: int) -> np.ndarray:
    """Joint signs (1 or tests, cycles, nv) of the sampled tests of a map target under the study's ``approach`` mode
    (:func:`~tribokin.simulation.joint_errors.approach_signs` with every joint forwards, then backwards): the same for
    every test unless the directions are drawn at random."""
    nv, mode = len(runner.models), runner.study.approach
    rng = expected_stream(runner.study.seed, "signs")
    directions = np.vstack([np.ones(nv), -np.ones(nv)])
    if mode != "random":
        return approach_signs(mode, cycles, directions, rng)[0][None]
    tests = tests_for(SAMPLED_CYCLES, cycles)
    return approach_signs(mode, tests * cycles, directions, rng)[0].reshape(tests, cycles, nv)


def _sampled(runner: PoseRunner, setup: ExpectedSetup, model: LinearModel, chosen: np.ndarray, signs: np.ndarray,
             qs: np.ndarray, commanded: np.ndarray) -> dict[str, np.ndarray]:
    """The figures of targets ``chosen`` (mask) over the sampled tests, and their RP_l band's ``band_error``."""
    n, moments = setup.cycles, setup.moments
    tests = tests_for(SAMPLED_CYCLES, n)
    numbers = common_numbers(runner, np.broadcast_to(signs, (tests, n, signs.shape[2])) if signs.shape[0] == 1
                             else signs, tests, "tests")
    indices = np.flatnonzero(chosen)
    values = {name: np.empty(len(indices)) for name in (*TEST_FIGURES, "RP_l_lo_um", "RP_l_hi_um", "band_error")}
    place = {k: i for i, k in enumerate(indices)}
    linear = indices[model.met[indices]]
    for block in blocks_of(linear, tests * n):
        positions = sampled_tests(model, moments, block, numbers, (tests, n), slice(0, 3))
        angles = sampled_tests(model, moments, block, numbers, (tests, n), slice(3, 6))
        _summarise_tests(values, [place[k] for k in block], positions, angles, commanded[block])
    for k in indices[~model.met[indices]]:
        positions, angles = engine_tests(runner, model, moments, k, qs[k], numbers, (tests, n))
        _summarise_tests(values, [place[k]], positions[None], angles[None], commanded[[k]])
    return values


def _summarise_tests(values: dict, slots: list[int], positions: np.ndarray, angles: np.ndarray,
                     commanded: np.ndarray) -> None:
    """Into ``values[...][slots]``: the mean of each figure over the tests of (k, tests, cycles, 3) ``positions``
    [m] and ``angles`` [rad], the RP_l band and its Monte Carlo error."""
    spread = position_spread(positions)
    rp_abc = orientation_repeatability(angles) * MDEG_PER_RAD
    per_test = {"RP_l_um": spread.RP_l_m * UM_PER_M,
                "AP_p_um": np.linalg.norm(spread.barycenter_m - commanded[:, None], axis=-1) * UM_PER_M,
                "RP_a_mdeg": rp_abc[..., 0], "RP_b_mdeg": rp_abc[..., 1], "RP_c_mdeg": rp_abc[..., 2],
                "largest_semi_axis_um": spread.largest_semi_axis_m * UM_PER_M}
    for name, figure in per_test.items():
        values[name][slots] = figure.mean(axis=1)
    ordered = np.sort(per_test["RP_l_um"], axis=1)
    values["RP_l_lo_um"][slots], values["RP_l_hi_um"][slots] = np.percentile(ordered, BAND_PERCENTILES, axis=1)
    values["band_error"][slots] = [max(percentile_error(row, p) for p in BAND_PERCENTILES) for row in ordered]


def _analytic(model: LinearModel, chosen: np.ndarray, setup: ExpectedSetup, commanded: np.ndarray
              ) -> dict[str, np.ndarray]:
    """The figures of targets ``chosen`` in closed form (:mod:`tribokin.iso9283.expected`)."""
    n = setup.cycles
    position = model.covariance(slice(0, 3))[chosen]
    lam = np.linalg.eigvalsh(position)
    scale, shape = standardised_shape(lam)
    mean, low, high, semi_axis = setup.table.at(shape)
    rp_l = expected_rp_l(lam, n) if n >= ANALYTIC_MIN_CYCLES else mean * scale
    with np.errstate(divide="ignore", invalid="ignore"):
        band = [np.where(mean > 0, rp_l * ratio / mean, 0.0) for ratio in (low, high)]
    angle_std = np.sqrt(np.diagonal(model.covariance(slice(3, 6))[chosen], axis1=1, axis2=2))
    return {"RP_l_um": rp_l * UM_PER_M, "RP_l_lo_um": band[0] * UM_PER_M, "RP_l_hi_um": band[1] * UM_PER_M,
            "AP_p_um": expected_norm(model.position_m[chosen] - commanded, position / n) * UM_PER_M,
            **{f"RP_{axis}_mdeg": 3 * c4(n) * angle_std[:, i] * MDEG_PER_RAD for i, axis in enumerate("abc")},
            "largest_semi_axis_um": semi_axis * scale * UM_PER_M}


def _vap(runner: PoseRunner, moments: JointMoments, qs: np.ndarray, lever: np.ndarray, twists: np.ndarray,
         cycles: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """vAP_p [µm] (k,), the bound [m, rad] (k, 2) of its first-order models and their fallbacks (k,)."""
    directions = np.array([APPROACH_DIRECTIONS[label] for label in VAP_DIRECTIONS])
    signs = approach_signs_from_jacobians(twists, directions)  # (k, 3, nv)
    models = [linear_model(runner.robot, moments, qs, lever, signs[:, d], mixed=False) for d in range(len(directions))]
    centres = np.stack([m.position_m for m in models], axis=1)  # (k, 3 directions, 3)
    noise = np.stack([m.covariance(slice(0, 3)) for m in models], axis=1) / cycles
    pairs = [(0, 1), (0, 2), (1, 2)]
    gaps = np.stack([centres[:, a] - centres[:, b] for a, b in pairs], axis=1)
    spreads = np.stack([noise[:, a] + noise[:, b] for a, b in pairs], axis=1)
    expected = expected_norm(gaps, spreads)
    sizes = np.linalg.norm(gaps, axis=-1)
    order = np.argsort(-sizes, axis=1)
    first, second = (np.take_along_axis(sizes, order[:, [i]], axis=1)[:, 0] for i in (0, 1))
    widths = np.sqrt(np.linalg.eigvalsh(spreads)[..., -1])
    width = np.take_along_axis(widths, order[:, [0]], axis=1)[:, 0] + np.take_along_axis(widths, order[:, [1]],
                                                                                         axis=1)[:, 0]
    vap = np.take_along_axis(expected, order[:, [0]], axis=1)[:, 0]
    close = np.flatnonzero(first - second <= TAIL_STDS * width)
    if len(close):
        rng = expected_stream(runner.study.seed, "vap")
        z = rng.standard_normal((VAP_DRAWS, len(directions), 3))
        for k in close:
            lam, vectors = np.linalg.eigh(noise[k])  # a root of each (3 directions, 3, 3), singular ones too
            roots = vectors * np.sqrt(np.maximum(lam, 0.0))[:, None, :]
            barycentres = centres[k] + np.einsum("dij,tdj->tdi", roots, z)
            vap[k] = np.max([np.linalg.norm(barycentres[:, a] - barycentres[:, b], axis=-1) for a, b in pairs],
                            axis=0).mean()
    bounds = np.max([np.where(m.met[:, None], m.bound, 0.0) for m in models], axis=0)
    return vap * UM_PER_M, bounds, np.sum([~m.met for m in models], axis=0).clip(max=1)


def _multi(runner: PoseRunner, setup: ExpectedSetup, qs: np.ndarray, lever: np.ndarray
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """RP_l_multi [µm] (k,), the bound [m, rad] (k, 2) of its first-order model and its fallbacks (k,)."""
    n, moments = setup.cycles, setup.moments
    tests = tests_for(MULTI_CYCLES, n)
    rng = expected_stream(runner.study.seed, "multi signs")
    signs = rng.integers(0, 2, size=(tests, n, len(runner.models))) * 2.0 - 1.0
    numbers = common_numbers(runner, signs, tests, "multi")
    model = linear_model(runner.robot, moments, qs, lever, np.zeros_like(lever), mixed=True)
    rp = np.empty(len(qs))
    linear = np.flatnonzero(model.met)
    for block in blocks_of(linear, tests * n):
        rp[block] = position_repeatability(sampled_tests(model, moments, block, numbers, (tests, n),
                                                         slice(0, 3)))[0].mean(axis=1)
    for k in np.flatnonzero(~model.met):
        rp[k] = position_repeatability(engine_tests(runner, model, moments, k, qs[k], numbers, (tests, n))[0]
                                       )[0].mean()
    return rp * UM_PER_M, np.where(model.met[:, None], model.bound, 0.0), (~model.met).astype(int)
