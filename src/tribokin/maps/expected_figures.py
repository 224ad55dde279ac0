"""Expected figures of a block of map targets (``map.statistic = "expected"``): each figure's mean over ISO tests of
``cycles`` cycles at the target, with the 2.5 / 97.5 % band of one test's RP_l.

The joint deviations of a cycle are dq = offset + s ⊙ (L ⊙ μ + backlash / 2) + noise (:mod:`~tribokin.simulation.
joint_errors`; L the lost motion per unit of the law's draw μ). About q″ = q + E[dq] the tool deviates by
J(q″) (dq - E[dq]) to first order (:func:`linear_model`); its error for every deviation within each law's support
(a Gaussian's mean ± ``TAIL_STDS`` standard deviations) is bounded by b [m], β [rad]
(:func:`~tribokin.propagation.poe.first_order_model_bounds`, or the fast engine's order-1 truncation bound if
smaller).
The mean deviation itself goes through exact forward kinematics.

Figure-level error (:func:`figure_errors`): if every sample's position moves by at most b, a test's barycentre moves by
at most b and each distance l_j to it by at most |e_j - ē| (e_j the samples' errors), whose mean is at most b and
whose root mean square about ē is at most b; so l̄ moves by at most b, S_l (n - 1 in its denominator) by at most
b √(n / (n - 1)), and RP_l = l̄ + 3 S_l by at most (1 + 3 √(n / (n - 1))) b; each percentile of RP_l (the band) as
much; AP_p by at most b; RP_a/b/c = 3 S of an angle's component by at most 3 √(n / (n - 1)) β; the largest semi-axis
(the largest standard deviation along a direction) by at most √(n / (n - 1)) b; vAP_p, the largest distance between
two barycentres, by at most 2 b; RP_l_multi as RP_l. A model serves a target only where these are within
``FIGURE_TOLERANCE`` of each figure it gives (or ``FIGURE_FLOOR``); else its tests go through the fast engine (a
fallback: orders 2-3, else exact FK), whose own bound then takes b's place. Per target: the least exact engine used
(``engine``), the largest bound (``engine_bound``) and each figure's error (``figure_errors``).

- Each approach direction is ISO's unidirectional test of ``cycles`` cycles (every joint +; approached from both,
  ``bidirectional`` or ``random``, every joint - too: :func:`direction_tests`, :func:`directions_figures`).
- **analytic** (every law Gaussian, truncation negligible, or constant): the figures of
  :mod:`tribokin.iso9283.gaussian_tests` from the covariance of J(q″) dq.
- **sampled** (other laws, or a target the first-order model does not serve): common random
  numbers: the same ``sampled_tests`` tests of drawn μ at every target (and scenario), through the linear model,
  or through the fast engine where it does not serve (a *fallback*).
- **``study.engine = "exact"``** (the runner's settings): no closed form and no first-order figure; every figure
  (each direction's test, vAP_p, RP_l_multi; Gaussian laws too) sampled from the same common random numbers through
  exact FK (:func:`engine_tests`), the model only a control variate of the same numbers; per target the engine
  exact, its bound 0, no fallback counted.
- **Monte Carlo errors**: every figure of the test states its relative standard error (``mc_errors``): a mean over
  sampled tests its standard error, a band's end the percentile's (:func:`~tribokin.iso9283.gaussian_tests.
  percentile_error`), what comes from the shape table the table's, from ``ASYMPTOTIC_CYCLES`` cycles on RP_l and
  its band by the delta method over the cycles' moments (:func:`moments_errors`, :func:`cycles_band`) and the
  semi-axis from its fourth moments' halves (:func:`cycles_semi_axis`), a closed form 0.
- ``vAP_p_um``: the largest distance between the barycentres reached along +x, +y, +z of the world frame (joint
  signs as the measured cube's, :func:`~tribokin.iso9283.cube.held_approach_signs`); each barycentre through
  RP_l_multi's first-order model (about q + offset: its bound covers every direction's deviations), or where that
  does not serve each direction's own, plus a Gaussian of covariance Σ_d / n (the mean of n cycles); its
  expectation in closed form when one pair of directions is clearly farthest apart, else linearised in the noise
  (jointly normal distances: closed form) and corrected over ``VAP_DRAWS`` draws (a control variate); its stated
  Monte Carlo error 0, the correction's over its draws, or where sampled (:func:`_vap_tests`) the tests' mean's.
- ``RP_l_multi_um``: cycles each approached from a random joint-space direction (every joint's sign drawn at
  random, with equal odds): the mean RP_l over ``multi_tests`` sampled tests of that mixture; from
  ``ASYMPTOTIC_CYCLES`` cycles on with every law Gaussian, from the mixture's moments, sums over the joints' sign
  patterns of Gaussian norm moments (:func:`_multi_moments`), else from sampled single cycles' moments about the
  mixture's mean (:func:`cycle_moments`); either with a test's barycentre one draw its cycles share, whose offset
  ε adds εᵀUε to S_l² (:func:`~tribokin.iso9283.gaussian_tests.barycentre_shares`; 0.5 % of RP_l where sign flips
  dominate the cloud).
- The dominant joint and its share are those of the population variance (what many cycles give).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cached_property, lru_cache
from typing import NamedTuple

import numpy as np

from tribokin.compiled import use_compiled
from tribokin.iso9283.cube import APPROACH_DIRECTIONS, approach_signs_from_jacobians
from tribokin.iso9283.gaussian_tests import (
    ANALYTIC_MIN_CYCLES,
    ASYMPTOTIC_CYCLES,
    BAND_PERCENTILES,
    MAXIMUM_RULE,
    NORM_RULE,
    ShapeTable,
    band_factors,
    barycentre_shares,
    c4,
    eigenvalues,
    expected_maximum,
    expected_norm,
    expected_rp_l,
    expected_semi_axis,
    gaussian_band_skewness,
    gaussian_products,
    influence_skewness,
    mean_error,
    percentile_error,
    rp_l_from_mixture,
    rp_l_from_moments,
    sign_mixture,
    skewed_band,
    standardised_shape,
)
from tribokin.iso9283.metrics import barycenter, orientation_repeatability, position_repeatability, position_spread
from tribokin.kinematics.se3_log import skew
from tribokin.maps.schema import DIRECTIONS, direction_figure, map_figures, per_direction
from tribokin.propagation.exact import engine_orders, tool_deviations_at_poses, tool_frames
from tribokin.propagation.poe import first_order_model_bounds, truncation_bound
from tribokin.simulation.joint_errors import TAIL_STDS, JointErrorModel, friction_lever, friction_loads
from tribokin.simulation.pose_test import PoseRunner
from tribokin.streams import expected_stream
from tribokin.tribology.laws import Constant, FrictionLaw, Gaussian, Scaled
from tribokin.units import MDEG_PER_RAD, UM_PER_M

#: Sampled tests: about this many cycles in all (2 000 tests of 30 cycles: the RP_l band's error about 1 %, and as
#: much at more cycles, whose RP_l spreads less), at least 100 and at most 2 000 tests.
SAMPLED_CYCLES, MIN_TESTS, MAX_TESTS = 60_000, 100, 2_000
#: Every sampled figure's relative Monte Carlo standard error is held within ``MC_ERROR_LIMIT`` at every target; the
#: RP_l band's tests are chosen for ``MC_ERROR_AIM`` in its heaviest case (:func:`band_factor`), leaving room for the
#: stated errors' own noise (about 10 %) and clouds between the cases.
MC_ERROR_LIMIT, MC_ERROR_AIM = 0.01, 0.008
#: The most times the default sampled tests (or single cycles) the RP_l band takes.
MAX_BAND_FACTOR = 16
#: Cycles and fewest tests of the random-direction mixture where it is sampled (only its mean is kept, its Monte Carlo
#: error stated: 0.6-0.8 % at 30 cycles on a UR5).
MULTI_CYCLES, MIN_MULTI_TESTS = 12_000, 20
#: Cycles whose offsets :func:`tests_rp_l`'s kernel holds at once (three coordinates' worth within a core's L1 cache).
TESTS_CHUNK = 1024
#: Most joints whose 2^(nv - 1) sign patterns RP_l_multi is summed over (:func:`_multi_moments`); more are sampled.
MIXTURE_MAX_JOINTS = 10
#: Sampled cycles of the targets computed together (their positions and angles in memory at once).
BLOCK_CYCLES = 400_000
#: The figures a test's model gives, sampled or not: each has a stated Monte Carlo error (``mc_errors``).
SAMPLED_FIGURES = ("RP_l_um", "RP_l_lo_um", "RP_l_hi_um", "AP_p_um", "RP_a_mdeg", "RP_b_mdeg", "RP_c_mdeg",
                   "largest_semi_axis_um")
#: Draws of the barycentres' noise correcting vAP_p's linearised expectation where two pairs of approach directions
#: are about as far apart (:func:`_vap_close`; on the UR5 plane the correction's standard deviation over draws is
#: 6e-5 of vAP_p at 30 cycles, 2e-6 at 1 000, against 1e-2 and 2e-3 for the distance itself: over 64 draws the
#: stated error is below 1e-5 of vAP_p, and the draws cost a quarter of what 256 did).
VAP_DRAWS = 64
#: Where ``VAP_DRAWS`` leave that correction's stated relative error above ``MC_ERROR_AIM`` (pairs close and their
#: noise as large as their distances, where the linearised distances stand for little: a Panda plane's smallest
#: vAP_p, up to 18 % over 64 draws), it is drawn again over ``VAP_MORE_DRAWS`` times as many draws (the first of them
#: the same), its error 16 times smaller, and so on up to ``VAP_MOST_DRAWS``.
VAP_MORE_DRAWS, VAP_MOST_DRAWS = 256, 4096 * VAP_DRAWS
#: The pairs of vAP_p's approach directions.
VAP_PAIRS = ((0, 1), (0, 2), (1, 2))
#: Truncation of a Gaussian law below this probability counts as none: its tests are computed analytically.
NEGLIGIBLE_TRUNCATION_SIGMAS = 6.0
#: The first-order model serves a target only where its bound guarantees each figure it gives (:func:`figure_errors`)
#: to within this fraction of the figure, or within ``FIGURE_FLOOR`` (µm or mdeg) for figures near zero; otherwise
#: the target falls back to the fast engine.
FIGURE_TOLERANCE, FIGURE_FLOOR = 1e-3, 1e-6
#: The engines a target's figures rest on, least exact first (its ``engine`` column: an index here): the first-order
#: model, the fast engine truncated at order 2 or 3 (a fallback, never order 1), exact forward kinematics.
TARGET_ENGINES = ("first-order", "fast-2", "fast-3", "exact")
FIRST_ORDER = 0
#: The approach directions of vAP_p: +x, +y, +z of the world frame.
VAP_DIRECTIONS = ("+x", "+y", "+z")

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
    def of_draws(cls, models: list[JointErrorModel], draws: np.ndarray) -> JointMoments:
        """Of joints whose friction is a time series: each joint's mean, standard deviation and largest departure
        from its mean over ``draws`` (..., nv), the very values its sampled tests draw (:func:`series_draws`), so the
        first-order model's bound covers every one; never Gaussian (its tests are sampled whole)."""
        draws = draws.reshape(-1, draws.shape[-1])
        mean = draws.mean(axis=0)
        return cls(mean, draws.std(axis=0), np.abs(draws - mean).max(axis=0), np.array([m.offset for m in models]),
                   np.array([m.backlash / 2 for m in models]), np.array([m.noise_std for m in models]), False)

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
        jacobian: (k, 6, nv) tool Jacobian at q″, its angle rows (I - c̃^ / 2) J_ω: the angle from the commanded
            orientation is log(e^x̂ e^ĉ) = c + x + x × c / 2 + ..., c that of q″'s orientation (c̃ = J_ω E[dq] to first
            order), x the deviation's.
        lever: (k, nv) lost motion per unit draw L.
        deviation_variance: (k, nv) var(dq) [m² or rad²].
        bound: (k, 2) its bound [m, rad] on |model - exact FK| over deviations within the laws' supports, the model's
            angles c + (I - c̃^ / 2) J_ω (dq - E[dq]): the smaller of the order-1 truncation bound and
            :func:`~tribokin.propagation.poe.first_order_model_bounds`; in angle that times |I - c̃^ / 2|, plus
            the composition's terms (the same function's third value).
    """

    mean_dq: np.ndarray
    position_m: np.ndarray
    jacobian: np.ndarray
    lever: np.ndarray
    deviation_variance: np.ndarray
    bound: np.ndarray

    @cached_property
    def position_covariance(self) -> np.ndarray:
        """(k, 3, 3) covariance of the tool's position deviation [m²]."""
        return jacobian_covariance(self.jacobian, self.deviation_variance, 0)

    @cached_property
    def angle_covariance(self) -> np.ndarray:
        """(k, 3, 3) covariance of the tool's angle deviation [rad²]."""
        return jacobian_covariance(self.jacobian, self.deviation_variance, 3)


def jacobian_covariance(jacobian: np.ndarray, variance: np.ndarray, first: int) -> np.ndarray:
    """(k, 3, 3) J diag(var) Jᵀ of the rows ``first`` to ``first + 2`` of Jacobians (k, 6, nv) and the joints'
    independent deviations' variances (k, nv) (their units' product, squared); compiled where
    :func:`~tribokin.compiled.use_compiled`."""
    if use_compiled():
        from tribokin.maps.expected_figures_kernels import covariances

        return covariances(np.ascontiguousarray(jacobian, dtype=float), np.ascontiguousarray(variance, dtype=float),
                           first)
    part = jacobian[:, first:first + 3]
    return np.einsum("kin,kn,kjn->kij", part, variance, part)


def linear_model(robot, moments: JointMoments, qs: np.ndarray, lever: np.ndarray, signs: np.ndarray,
                 mixed: bool, frames: tuple[np.ndarray, np.ndarray] | None = None) -> LinearModel:
    """:class:`LinearModel` at configurations ``qs`` (k, nv) with levers ``lever`` (k, nv): every cycle with joint
    signs ``signs`` (k, nv) (+1, -1, 0: still), or (``mixed``) each joint's sign drawn per cycle with mean ``signs``;
    ``frames``: the :func:`~tribokin.propagation.exact.tool_frames` at ``qs``, used where E[dq] is 0 at every joint
    (no offset, no sign: the mixed model of a scenario without offsets) instead of computing them again.

    A joint's lost motion m = L μ + backlash / 2 departs from its mean by at most L d (d: the law's
    :func:`largest_departure`) unidirectionally, by (1 + |s̄|)(L (μ̄ + d) + backlash / 2) when its sign flips; its
    variance is s² L² σ² + (s² - s̄²) E[m]², with s² = 1 when mixed; and noise_std is added, up to ``TAIL_STDS`` of it.
    """
    mean_dq = moments.offset + signs * (lever * moments.mean + moments.half_backlash)
    twists, positions = frames if frames is not None and not np.any(mean_dq) else tool_frames(robot, qs + mean_dq)
    square = np.ones_like(signs) if mixed else signs ** 2
    lost = lever * moments.mean + moments.half_backlash
    variance = square * (lever * moments.std) ** 2 + (square - signs ** 2) * lost ** 2 + moments.noise_std ** 2
    departure = ((1 + np.abs(signs)) * (lost + lever * moments.departure) if mixed
                 else np.abs(signs) * lever * moments.departure) + TAIL_STDS * moments.noise_std
    bound = truncation_bound(twists, departure[:, None, :], order=1)
    position, truncation, composition = first_order_model_bounds(twists, departure, mean_dq)
    turn = np.einsum("kin,kn->ki", twists[:, 3:], mean_dq)  # c̃: R(q″) R(q)ᵀ = Π exp(ω̂_i(q″) E[dq_i]) to first order
    jacobian = twists.copy()
    jacobian[:, 3:] = (np.eye(3) - skew(turn) / 2) @ twists[:, 3:]  # x + x × c̃ / 2 = (I - c̃^ / 2) x
    angle = np.sqrt(1 + np.sum(turn ** 2, axis=1) / 4) * np.minimum(bound.angle_rad, truncation) + composition
    position = np.minimum(bound.position_m, position)
    return LinearModel(mean_dq, positions, jacobian, lever, variance,
                       np.column_stack([position, angle]).reshape(len(qs), 2))


@lru_cache(maxsize=64)
def shape_table(cycles: int, seed: int) -> ShapeTable:
    """The shape table of tests of ``cycles`` cycles from study seed ``seed``'s common random numbers, simulated once
    per process (a placement search maps its task region once per candidate; a notebook runs study after study), up
    to 64 of them kept (5 kB each; simulating one takes up to about a second)."""
    return ShapeTable.simulate(cycles, expected_stream(seed, "table"))


class Drawn(dict):
    """Arrays an :class:`ExpectedSetup` has drawn in this process, by name; pickled empty (a worker draws its own,
    the same numbers)."""

    def __reduce__(self):
        return Drawn, ()


@dataclass(frozen=True)
class ExpectedSetup:
    """What every block of one scenario's expected map shares, built once per map: the tests' ``cycles`` (of each
    approach direction), the scenario's :class:`JointMoments`, the shape table of Gaussian tests
    (:class:`~tribokin.iso9283.gaussian_tests.ShapeTable`; ``None`` from ``ASYMPTOTIC_CYCLES`` cycles on), the map's
    ``figure_set`` (``"directional"``: vAP_p and RP_l_multi too) and ``band_factor`` (:func:`band_factor`);
    ``series``: a joint's friction is a time series, every test sampled whole from the runner's state
    (:func:`series_draws`), its moments those of the draws (:meth:`JointMoments.of_draws`); ``drawn``: the common
    random numbers its blocks have drawn (:meth:`once`)."""

    cycles: int
    moments: JointMoments
    table: ShapeTable | None
    figure_set: str
    band_factor: int = 1
    series: bool = False
    drawn: Drawn = field(default_factory=Drawn, repr=False, compare=False)

    def once(self, name: str, draw: Callable[[], np.ndarray]) -> np.ndarray:
        """``draw()`` the first time ``name`` is asked for in this process, the same array after: numbers that every
        block of the map shares (common random numbers, independent of chunking)."""
        if name not in self.drawn:
            self.drawn[name] = draw()
        return self.drawn[name]

    @classmethod
    def build(cls, runner: PoseRunner, table: ShapeTable | None, figure_set: str) -> ExpectedSetup:
        cycles = runner.settings.cycles
        factor = band_factor(runner, cycles)
        if not runner.correlated:
            return cls(cycles, JointMoments.of(runner.models), table, figure_set, factor)
        tests = sampled_shape(SAMPLED_CYCLES, cycles, whole_tests=True)[0]
        draws = [series_draws(runner, tests, cycles, "tests")]
        if factor > 1:
            draws.append(series_draws(runner, (factor - 1) * tests, cycles, "band tests"))
        if figure_set == "directional":  # RP_l_multi's, through the mixed first-order model (vAP_p's: the engine)
            draws.append(series_draws(runner, sampled_shape(MULTI_CYCLES, cycles, MIN_MULTI_TESTS, True)[0], cycles,
                                      "multi").reshape(-1, len(runner.models)))
        moments = JointMoments.of_draws(runner.models, np.concatenate([d.reshape(-1, d.shape[-1]) for d in draws]))
        return cls(cycles, moments, table, figure_set, factor, series=True)


def band_factor(runner: PoseRunner, cycles: int) -> int:
    """How many times the default sampled tests (from ``ASYMPTOTIC_CYCLES`` cycles on: single cycles) the RP_l band of a
    scenario takes, the same at every target: its stated error (that of E[RP_l] too) in tests of a one-dimensional
    cloud of each joint's law and of a Gaussian, over ``MC_ERROR_AIM``, squared. One joint's law alone is the
    heaviest case of its tails; clouds of several joints mix towards the Gaussian."""
    whole = runner.correlated
    shape = sampled_shape(SAMPLED_CYCLES, cycles, whole_tests=whole)
    rng = expected_stream(runner.settings.seed, "band pilot")
    clouds = [rng.standard_normal(shape)] + [m.friction.rvs(size=shape, random_state=rng) for m in runner.models
                                             if m.friction.std() > 0]
    worst = 0.0
    for cloud in clouds:
        if cycles >= ASYMPTOTIC_CYCLES and not whole:
            points = np.zeros((1, shape[1], 3))
            points[0, :, 0] = cloud[0]
            moments, distances = cycle_moments(points, cycles, barycentre_normals(shape[1]))
            errors = moments_errors(distances, moments, cycles, band=cycles_band(points, cycles))
        else:
            errors = rp_l_errors(cloud)
        worst = max(worst, *(float(np.max(error)) for error in errors))
    return pilot_factor(worst, MAX_BAND_FACTOR)


def rp_l_errors(cloud: np.ndarray) -> tuple[np.ndarray, ...]:
    """The relative Monte Carlo standard errors of RP_l's mean and of its band's ends over tests of a one-dimensional
    ``cloud`` (tests, cycles): a pilot's, which sets a factor of tests (:func:`band_factor`,
    :func:`~tribokin.maps.series_expected.series_factor`)."""
    distances = np.abs(cloud - cloud.mean(axis=1, keepdims=True))
    rp_l = distances.mean(axis=1) + 3 * distances.std(axis=1, ddof=1)
    return (mean_error(rp_l), *(percentile_error(rp_l, p) for p in BAND_PERCENTILES))


def pilot_factor(worst: float, most: int) -> int:
    """How many times its tests bring a pilot's largest relative error ``worst`` within ``MC_ERROR_AIM``
    (⌈(worst / aim)²⌉), from 1 to ``most``."""
    return int(np.clip(math.ceil((worst / MC_ERROR_AIM) ** 2), 1, most))


def tests_for(cycles_in_all: int, cycles: int, fewest: int = MIN_TESTS) -> int:
    """Sampled tests of ``cycles`` cycles: about ``cycles_in_all`` cycles, at least ``fewest``, at most
    ``MAX_TESTS``."""
    return min(max(fewest, math.ceil(cycles_in_all / cycles)), MAX_TESTS)


def common_numbers(runner: PoseRunner, signs: np.ndarray, tests: int, purpose: str) -> np.ndarray:
    """(tests × cycles, 3 nv) the common random numbers of one scenario's sampled tests, the same at every target:
    per cycle [s ⊙ μ, s, z], the joints' signs ``signs`` (1 or tests, cycles, nv), the laws' draws μ and standard normal
    noise z (:func:`~tribokin.streams.expected_stream` of ``purpose``). A target's deviations from E[dq] are these
    times its :func:`responses`' rows, less E[dq] - offset."""
    rng = expected_stream(runner.settings.seed, purpose)
    cycles, nv = signs.shape[1], len(runner.models)
    if runner.correlated:
        mu = series_draws(runner, tests, cycles, rng)
    else:
        mu = np.stack([m.friction.rvs(size=(tests, cycles), random_state=rng) for m in runner.models], axis=-1)
    noise = rng.standard_normal((tests, cycles, nv))
    return np.concatenate([signs * mu, np.broadcast_to(signs, mu.shape), noise], axis=-1).reshape(-1, 3 * nv)


def series_draws(runner: PoseRunner, tests: int, cycles: int, purpose) -> np.ndarray:
    """(tests, cycles, nv) the joints' friction draws of one scenario's sampled tests where a joint's friction is a
    time series: each test from the runner's state, the series running through its cycles
    (:meth:`~tribokin.simulation.pose_test.PoseRunner.friction_tests`), from ``purpose``'s stream (its name, or the
    stream itself) first: the same at every target."""
    rng = expected_stream(runner.settings.seed, purpose) if isinstance(purpose, str) else purpose
    return runner.friction_tests(tests, cycles, rng)


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
    (``slice(3, 6)``) of targets ``chosen`` through the first-order model, for :func:`common_numbers` ``numbers``.
    Each target's coordinates lie in memory cycle after cycle ((k, 3, tests, cycles) under the view), so that the
    figures' sums over the cycles read memory in order."""
    moved = (responses(model, moments, chosen, rows).T @ numbers.T).reshape(len(chosen), 3, *shape)
    return np.moveaxis(moved, 1, -1) + shift_of(model, moments, chosen, rows)[:, None, None, :]


def centred_numbers(numbers: np.ndarray, shape: tuple) -> np.ndarray:
    """(3 nv, tests × cycles) :func:`common_numbers` ``numbers`` of tests of ``shape`` (tests, cycles) less their test's
    mean (:func:`~tribokin.iso9283.metrics.barycenter`, as a test's positions are taken from theirs), a column after
    another: what :func:`tests_rp_l`'s kernel reads."""
    per_test = numbers.reshape(*shape, -1)
    centred = per_test - barycenter(per_test)[:, None, :]
    return np.ascontiguousarray(centred.reshape(numbers.shape).T)


def tests_rp_l(model: LinearModel, moments: JointMoments, chosen: np.ndarray, numbers: np.ndarray, shape: tuple,
               centred: np.ndarray) -> np.ndarray:
    """(k, tests) RP_l [m] of each sampled test (``shape``: tests, cycles) of targets ``chosen`` through the
    first-order model, for :func:`common_numbers` ``numbers``: of :func:`sampled_tests`' positions, or where
    :func:`~tribokin.compiled.use_compiled`, from each cycle's offset from its test's barycentre W (n - n̄) (W the
    target's :func:`responses`, n - n̄ the numbers' ``centred``, :func:`centred_numbers`: the tool's position and
    E[dq] cancel)."""
    if not use_compiled():
        return position_repeatability(sampled_tests(model, moments, chosen, numbers, shape, slice(0, 3)))[0]
    from tribokin.maps.expected_figures_kernels import tests_repeatability

    weights = responses(model, moments, chosen, slice(0, 3)).reshape(numbers.shape[1], len(chosen), 3)
    return tests_repeatability(np.ascontiguousarray(weights.transpose(1, 2, 0)), centred, *shape, TESTS_CHUNK)


def shift_of(model: LinearModel, moments: JointMoments, chosen: np.ndarray, rows: slice) -> np.ndarray:
    """(k, 3) what :func:`sampled_tests` adds to the common random numbers' responses of targets ``chosen``: the tool
    position at q″ [m] (``rows = slice(0, 3)``) less the responses' part of E[dq] - offset."""
    shift = np.einsum("kn,kin->ki", moments.offset - model.mean_dq[chosen], model.jacobian[chosen, rows])
    return shift + model.position_m[chosen] if rows.start == 0 else shift


def position_control(model: LinearModel, moments: JointMoments, chosen: np.ndarray, means: np.ndarray,
                     direction: np.ndarray, commanded: np.ndarray, cycles: int) -> tuple[np.ndarray, np.ndarray]:
    """A control variate of AP_p of targets ``chosen``: (k, tests) each sampled test's |ȳ - commanded|² [m²] through
    the first-order model less its expectation (|E ȳ - commanded|² + tr Cov ȳ, both from the numbers' known
    moments), from the tests' mean :func:`common_numbers` ``means`` (tests, 3 nv), every cycle approached with joint
    signs ``direction`` (nv,); and before it (k, tests) the model's AP_p of each test [µm]."""
    nv = len(direction)
    weights = responses(model, moments, chosen, slice(0, 3)).reshape(3 * nv, len(chosen), 3)
    shift = shift_of(model, moments, chosen, slice(0, 3)) - commanded
    reached = np.einsum("tc,cki->kti", means, weights) + shift[:, None]
    expected = np.concatenate([direction * moments.mean, direction, np.zeros(nv)])
    centre = np.einsum("c,cki->ki", expected, weights) + shift
    variance = np.concatenate([direction ** 2 * moments.std ** 2, np.zeros(nv), np.ones(nv)]) / cycles
    spread = np.einsum("c,ck->k", variance, np.square(weights).sum(axis=2))
    square = np.square(reached).sum(axis=2)
    return np.sqrt(square) * UM_PER_M, square - (np.square(centre).sum(axis=1) + spread)[:, None]


def controlled_mean(values: np.ndarray, model_values: np.ndarray, control: np.ndarray) -> tuple[np.ndarray,
                                                                                              np.ndarray]:
    """The mean of ``values`` (k, tests) with a control variate ``control`` (k, tests) of expectation 0: the values'
    mean less β times the control's, β the regression slope of the first-order model's ``model_values`` on the
    control (so a fallback's figure differs from the model's by the values' mean difference alone); and its relative
    standard error (the residuals' standard deviation over √tests)."""
    centred = model_values - model_values.mean(axis=1, keepdims=True)
    offsets = control - control.mean(axis=1, keepdims=True)
    square = np.square(offsets).sum(axis=1)
    beta = np.divide((centred * offsets).sum(axis=1), square, out=np.zeros(len(values)), where=square > 0)
    estimate = values.mean(axis=1) - beta * control.mean(axis=1)
    error = (values - beta[:, None] * control).std(axis=1, ddof=2) / math.sqrt(values.shape[1])
    return estimate, relative(error, estimate)


def figure_errors(bound: np.ndarray, cycles: int) -> dict[str, np.ndarray]:
    """Each figure's largest change [µm, mdeg] (k,) when every sample's position and angle move by at most ``bound``
    (k, 2) [m, rad] (the engine's bound against exact FK), for tests of ``cycles`` cycles (the module's docstring
    derives them)."""
    spread = math.sqrt(cycles / (cycles - 1)) if cycles > 1 else 1.0
    position, angle = bound[:, 0] * UM_PER_M, bound[:, 1] * MDEG_PER_RAD
    repeatability = (1 + 3 * spread) * position
    return {"RP_l_um": repeatability, "RP_l_lo_um": repeatability, "RP_l_hi_um": repeatability, "AP_p_um": position,
            "vAP_p_um": 2 * position, "RP_l_multi_um": repeatability,
            **{f"RP_{axis}_mdeg": 3 * spread * angle for axis in "abc"}, "largest_semi_axis_um": spread * position}


#: The figures each model gives, which its bound must guarantee (:data:`FIGURE_TOLERANCE`): the test's, vAP_p's and
#: RP_l_multi's.
SERVED_FIGURES = {"test": ("RP_l_um", "AP_p_um", "RP_a_mdeg", "RP_b_mdeg", "RP_c_mdeg"), "vap": ("vAP_p_um",),
                  "multi": ("RP_l_multi_um",)}


def serves(bound: np.ndarray, cycles: int, figures: dict[str, np.ndarray], served: str) -> np.ndarray:
    """(k,) where a model of bound ``bound`` (k, 2) [m, rad] guarantees each of the ``figures`` [µm, mdeg] of its
    kind ``served`` (:data:`SERVED_FIGURES`) to within ``FIGURE_TOLERANCE`` of it, or ``FIGURE_FLOOR``."""
    errors = figure_errors(bound, cycles)
    ok = np.ones(len(bound), dtype=bool)
    for name in SERVED_FIGURES[served]:
        ok &= errors[name] <= np.maximum(FIGURE_TOLERANCE * np.abs(figures[name]), FIGURE_FLOOR)  # NaN: not served
    return ok


@dataclass(frozen=True)
class EngineUsed:
    """The engine that computed a model's figures at k targets: ``engine`` (k,) an index in ``TARGET_ENGINES``,
    ``bound`` (k, 2) its bound [m, rad] on |engine - exact FK| over every sample it computed (exact FK: 0)."""

    engine: np.ndarray
    bound: np.ndarray

    @classmethod
    def first_order(cls, model: LinearModel) -> EngineUsed:
        return cls(np.full(len(model.bound), FIRST_ORDER), model.bound.copy())

    @classmethod
    def of(cls, used) -> EngineUsed:
        """One target's engine chosen by :func:`engine_tests` (a :class:`~tribokin.propagation.poe.TruncationBound`
        of one pose, order 0: exact FK)."""
        order, position, angle = (np.atleast_1d(value)[0] for value in used)
        return cls(np.array([TARGET_ENGINES.index(f"fast-{order}" if order else "exact")]),
                   np.array([[position, angle]]))

    def fall_back(self, k: int, other: EngineUsed) -> None:
        """Target ``k``'s figures computed again by ``other``'s (one target's) engine."""
        self.engine[k], self.bound[k] = other.engine[0], other.bound[0]

    @classmethod
    def combined(cls, used: list[EngineUsed]) -> EngineUsed:
        """Of several models at the same targets: the least exact engine, the largest bound."""
        return cls(np.min([u.engine for u in used], axis=0), np.max([u.bound for u in used], axis=0))


def engine_tests(runner: PoseRunner, model: LinearModel, moments: JointMoments, k: int, q: np.ndarray,
                 numbers: np.ndarray, shape: tuple) -> tuple[np.ndarray, np.ndarray, tuple]:
    """Positions [m] and angle deviations [rad] (tests, cycles, 3) of target ``k`` at configuration ``q`` through the
    engine of the runner's ``study.engine``: ``"fast"`` (orders 2-3, else exact FK), where the first-order model does
    not serve; ``"exact"``: exact FK, at every target; and the engine used, the
    :class:`~tribokin.propagation.poe.TruncationBound` of :func:`~tribokin.propagation.exact.engine_orders`."""
    nv = len(q)
    signed_mu, signs, noise = numbers[:, :nv], numbers[:, nv:2 * nv], numbers[:, 2 * nv:]
    dq = moments.offset + signed_mu * model.lever[k] + signs * moments.half_backlash + noise * moments.noise_std
    twists, translations = tool_frames(runner.robot, q[None])
    engine = runner.settings.engine
    used = engine_orders(twists, dq[None], engine, lowest_order=2)
    positions, angles = tool_deviations_at_poses(runner.robot, q[None], dq[None], engine, twists, translations, used)
    return positions.reshape(*shape, 3), angles.reshape(*shape, 3), used


def blocks_of(indices: np.ndarray, cycles_each: int) -> list[np.ndarray]:
    """``indices`` in groups whose sampled cycles stay within ``BLOCK_CYCLES``."""
    size = max(1, BLOCK_CYCLES // cycles_each)
    return [indices[start:start + size] for start in range(0, len(indices), size)]


class DirectionTests(NamedTuple):
    """The test's figures at k targets approached from one direction (:func:`direction_tests`): ``values`` by name
    [µm, mdeg] (k,) each (:data:`SAMPLED_FIGURES`), their relative Monte Carlo standard errors ``mc_errors`` by name
    (k,) each, where the first-order ``model`` (:class:`LinearModel`) ``served`` (k,), and the engine ``used``
    (:class:`EngineUsed`)."""

    values: dict[str, np.ndarray]
    mc_errors: dict[str, np.ndarray]
    served: np.ndarray
    used: EngineUsed
    model: LinearModel


def direction_tests(runner: PoseRunner, setup: ExpectedSetup, qs: np.ndarray, lever: np.ndarray, direction: np.ndarray,
                    commanded: np.ndarray) -> DirectionTests:
    """The expected figures of tests of ``setup.cycles`` cycles at configurations ``qs`` (k, nv), levers ``lever``
    (k, nv), every cycle approached with joint signs ``direction`` (nv,) (ISO's unidirectional series), commanded
    positions ``commanded`` (k, 3) [m]: in closed form where every law is Gaussian, else sampled; through the fast
    engine where the first-order model does not serve. With ``study.engine = "exact"`` sampled through exact FK at
    every target, whatever the laws (the model serving none; its samples of the same numbers only a control
    variate)."""
    moments, n = setup.moments, setup.cycles
    model = linear_model(runner.robot, moments, qs, lever, np.broadcast_to(direction, lever.shape), mixed=False)
    everywhere = np.ones(len(qs), dtype=bool)
    if runner.settings.engine == "exact":
        used = EngineUsed.first_order(model)  # each target's replaced by exact FK's
        values = _sampled(runner, setup, model, everywhere, qs, commanded, direction, used)
        mc = values.pop("mc_errors")
        return DirectionTests(values, mc, ~everywhere, used, model)
    values = (_analytic(model, everywhere, setup, commanded) if moments.gaussian
              else _sampled(runner, setup, model, everywhere, qs, commanded, direction))
    mc = values.pop("mc_errors")
    served = serves(model.bound, n, values, "test")
    used = EngineUsed.first_order(model)
    if not served.all():
        again = _sampled(runner, setup, model, ~served, qs, commanded, direction, used)
        for name, value in again.pop("mc_errors").items():
            mc[name][~served] = value
        for name, value in again.items():
            values[name][~served] = value
    return DirectionTests(values, mc, served, used, model)


#: The test's figures a map approached from both directions gives per direction
#: (:attr:`~tribokin.maps.schema.MapFigure.per_direction`).
SPLIT_FIGURES = tuple(figure.name for figure in map_figures("expected") if figure.per_direction)


def stated_figures(figure_set: str, both_directions: bool) -> tuple[str, ...]:
    """The figures whose relative Monte Carlo standard error an expected map of ``figure_set`` states
    (``mc_errors``): :data:`SAMPLED_FIGURES`, vAP_p and RP_l_multi where the set is ``"directional"``, and approached
    from both directions each direction's :data:`SPLIT_FIGURES` too."""
    stated = SAMPLED_FIGURES + (("vAP_p_um", "RP_l_multi_um") if figure_set == "directional" else ())
    if not both_directions:
        return stated
    return stated + tuple(direction_figure(name, label) for label in DIRECTIONS for name in SPLIT_FIGURES)


def directions_figures(tests: list[DirectionTests], cycles: int) -> tuple[dict, dict, dict]:
    """The figures [µm, mdeg], their errors from the engines' bounds [µm, mdeg] and their relative Monte Carlo errors
    of the approach directions' ``tests`` (one: as they are; + and -: each direction's :data:`SPLIT_FIGURES` by their
    own names, :func:`~tribokin.maps.schema.direction_figure`, and each figure the larger of the two's, whose errors
    are at most the larger of theirs)."""
    if len(tests) == 1:
        return tests[0].values, figure_errors(tests[0].used.bound, cycles), tests[0].mc_errors
    values = {name: np.maximum(*(t.values[name] for t in tests)) for name in tests[0].values}
    errors = figure_errors(np.maximum(*(t.used.bound for t in tests)), cycles)
    mc = {name: np.maximum(*(t.mc_errors[name] for t in tests)) for name in tests[0].mc_errors}
    for label, test in zip(DIRECTIONS, tests, strict=True):
        own = figure_errors(test.used.bound, cycles)
        for name in SPLIT_FIGURES:
            values[direction_figure(name, label)] = test.values[name]
            errors[direction_figure(name, label)] = own[name]
            mc[direction_figure(name, label)] = test.mc_errors[name]
    return values, errors, mc


def expected_targets(runner: PoseRunner, setup: ExpectedSetup, qs: np.ndarray, forces: np.ndarray,
                     twists: np.ndarray, translations: np.ndarray) -> dict[str, np.ndarray]:
    """Expected figures of k targets at configurations ``qs`` (k, nv) under bearing loads ``forces`` (k, nv) [N];
    ``twists``, ``translations``: their :func:`~tribokin.propagation.exact.tool_frames`. A study approaching from
    both directions (``bidirectional``, ``random``: :func:`~tribokin.maps.schema.per_direction`) has ISO's tests of
    ``cycles`` cycles from each, every joint travelling + (every joint -): :func:`directions_figures`.

    Returns:
        ``figures`` (k, figures) in the order of :func:`~tribokin.maps.schema.map_figures` of ``setup.figure_set``,
        ``figure_errors`` (k, figures) each figure's largest change [µm, mdeg] from the engine's bound
        (:func:`figure_errors`; NaN for ``dominant_share``), ``dominant_joint`` (k,) (-1: none), ``method`` (k,)
        (``ANALYTIC`` or ``SAMPLED``), ``fallbacks`` (k,) how many of the models (each direction's test's; vAP_p's,
        RP_l_multi's) the first-order model did not serve and went through the fast engine, ``engine`` (k,) the least
        exact engine of the models (an index in ``TARGET_ENGINES``), ``engine_bound`` (k, 2) [m, rad] their largest
        bound on |engine - exact FK| (exact FK: 0), ``mc_errors`` (k, figures) each figure's relative Monte Carlo
        standard error (0: in closed form; NaN for ``dominant_share``, which states none). With
        ``study.engine = "exact"`` (the runner's settings) every figure sampled through exact FK: ``method``
        ``SAMPLED``, ``engine`` exact, its bound 0, no fallbacks.
    """
    models, robot, moments, n = runner.models, runner.robot, setup.moments, setup.cycles
    lever = friction_loads(models, forces) * friction_lever(models, robot.joint_is_prismatic)
    both = per_direction(runner.settings.approach)
    columns = {figure.name: k for k, figure in enumerate(map_figures(setup.figure_set, both))}
    figures = np.full((len(qs), len(columns)), np.nan)
    errors = np.full((len(qs), len(columns)), np.nan)
    tests = [direction_tests(runner, setup, qs, lever, np.full(len(models), sign), translations)
             for sign in ((1.0, -1.0) if both else (1.0,))]
    values, test_errors, mc = directions_figures(tests, n)
    served = np.all([t.served for t in tests], axis=0)
    mc_errors = np.full((len(qs), len(columns)), np.nan)
    for name, value in values.items():
        figures[:, columns[name]] = value
        mc_errors[:, columns[name]] = mc[name]
    exact = runner.settings.engine == "exact"  # no model served: none fell back, every one went through exact FK
    out = {"figures": figures, "figure_errors": errors,
           "method": np.where(served & moments.gaussian, ANALYTIC, SAMPLED),
           "fallbacks": np.sum([~t.served & (not exact) for t in tests], axis=0), "mc_errors": mc_errors}
    # the engine of each model: the tests', and vAP_p's and RP_l_multi's by their figure
    engines = {"test": EngineUsed.combined([t.used for t in tests])}
    if setup.figure_set == "directional":
        mixed = linear_model(robot, moments, qs, lever, np.zeros_like(lever), mixed=True,  # random directions
                             frames=(twists, translations))
        vap, mc_errors[:, columns["vAP_p_um"]], engines["vAP_p_um"], fallbacks = _vap(runner, moments, qs, lever,
                                                                                      twists, n, mixed)
        figures[:, columns["vAP_p_um"]] = vap
        out["fallbacks"] += fallbacks
        multi, mc_errors[:, columns["RP_l_multi_um"]], engines["RP_l_multi_um"], fallbacks = _multi(runner, setup, qs,
                                                                                                    mixed)
        figures[:, columns["RP_l_multi_um"]] = multi
        out["fallbacks"] += fallbacks
    bounded = {model_name: figure_errors(engine.bound, n) for model_name, engine in engines.items()}
    bounded["test"] = test_errors
    for name, column in columns.items():
        if name != "dominant_share":
            errors[:, column] = bounded.get(name, bounded["test"])[name]
    combined = EngineUsed.combined(list(engines.values()))
    out["engine"], out["engine_bound"] = combined.engine, combined.bound
    parts = sum(t.model.deviation_variance * np.sum(t.model.jacobian[:, :3] ** 2, axis=1) for t in tests)
    total = parts.sum(axis=1)
    out["dominant_joint"] = np.where(total > 0, np.argmax(parts, axis=1), -1)
    figures[:, columns["dominant_share"]] = np.where(total > 0, parts.max(axis=1) / np.where(total > 0, total, 1),
                                                     np.nan)
    return out


def change_errors(start: tuple[PoseRunner, ExpectedSetup], end: tuple[PoseRunner, ExpectedSetup], qs: np.ndarray,
                  forces: np.ndarray, commanded: np.ndarray) -> np.ndarray:
    """(k, 2) Monte Carlo standard errors [µm] of the changes of E[RP_l] and E[AP_p] (:data:`~tribokin.maps.schema.
    CHANGE_FIGURES`) from state ``start`` to state ``end`` (each a runner and its setup, the same joints in two
    states of their friction series) at configurations ``qs`` (k, nv) under bearing loads ``forces`` (k, nv) [N],
    commanded positions ``commanded`` (k, 3) [m]: both states' sampled tests share their random numbers (the same
    streams), so a test's change is paired; each test's RP_l and AP_p in both states through the states' first-order
    models, the differences' standard deviation over √tests (the band's further tests left out: a larger error than
    the figures' own over every test). Approached from both directions: the larger of the two directions' errors."""
    runner = start[0]
    lever = friction_loads(runner.models, forces) * friction_lever(runner.models, runner.robot.joint_is_prismatic)
    both = per_direction(runner.settings.approach)
    errors = np.zeros((len(qs), 2))
    for sign in (1.0, -1.0) if both else (1.0,):
        direction = np.full(len(runner.models), sign)
        shape = sampled_shape(SAMPLED_CYCLES, start[1].cycles, whole_tests=True)
        signs = np.broadcast_to(direction, (*shape, len(direction)))
        states = [(linear_model(r.robot, setup.moments, qs, lever, np.broadcast_to(direction, lever.shape), False),
                   setup.moments, common_numbers(r, signs, shape[0], "tests")) for r, setup in (start, end)]
        for block in blocks_of(np.arange(len(qs)), 2 * shape[0] * shape[1]):
            figures = []
            for model, moments, numbers in states:
                spread = position_spread(sampled_tests(model, moments, block, numbers, shape, slice(0, 3)))
                figures.append(np.stack([spread.RP_l_m, np.linalg.norm(
                    spread.barycenter_m - commanded[block, None], axis=-1)], axis=-1))  # (block, tests, 2)
            change = (figures[1] - figures[0]) * UM_PER_M
            errors[block] = np.fmax(errors[block], change.std(axis=1, ddof=1) / math.sqrt(shape[0]))
    return errors


def sampled_shape(cycles_in_all: int, cycles: int, fewest: int = MIN_TESTS,
                  whole_tests: bool = False) -> tuple[int, int]:
    """(tests, cycles per test) sampled for tests of ``cycles`` cycles: :func:`tests_for` tests (at least ``fewest``),
    or from ``ASYMPTOTIC_CYCLES`` on one series of ``cycles_in_all`` single cycles (:func:`cycle_moments`), unless
    ``whole_tests`` (cycles that are not independent: a friction time series)."""
    if cycles >= ASYMPTOTIC_CYCLES and not whole_tests:
        return 1, cycles_in_all
    return tests_for(cycles_in_all, cycles, fewest), cycles


def _sampled(runner: PoseRunner, setup: ExpectedSetup, model: LinearModel, chosen: np.ndarray, qs: np.ndarray,
             commanded: np.ndarray, direction: np.ndarray, used: EngineUsed | None = None) -> dict[str, np.ndarray]:
    """The figures of targets ``chosen`` (mask) approached with joint signs ``direction`` (nv,) over the sampled tests,
    and under ``"mc_errors"`` each one's relative Monte Carlo standard error: through the first-order ``model``, or
    with ``used``, through the fast engine (each target's engine recorded there). Every direction's tests draw the
    same numbers."""
    n, moments = setup.cycles, setup.moments
    asymptotic = n >= ASYMPTOTIC_CYCLES and not setup.series
    shape = sampled_shape(SAMPLED_CYCLES * (setup.band_factor if asymptotic else 1), n, whole_tests=setup.series)
    signs = np.broadcast_to(direction, (1, shape[1], len(direction)))
    numbers = common_numbers(runner, np.broadcast_to(signs, (*shape, signs.shape[2])), shape[0], "tests")
    extra = (0 if asymptotic else (setup.band_factor - 1) * shape[0], n)  # the band's further tests
    extra_numbers = None
    if extra[0]:
        extra_numbers = common_numbers(runner, np.broadcast_to(signs, (*extra, signs.shape[2])), extra[0],
                                       "band tests")
    means = None if asymptotic else numbers.reshape(*shape, -1).mean(axis=1)
    indices = np.flatnonzero(chosen)
    values = {name: np.empty(len(indices)) for name in SAMPLED_FIGURES}
    errors = {name: np.empty(len(indices)) for name in SAMPLED_FIGURES}

    def summarise(slots, targets, positions, angles, more, linear=None):
        if asymptotic:
            _summarise_cycles(values, errors, slots, positions, angles, commanded[targets], n,
                              (model, targets, linear))
        else:
            control = position_control(model, moments, targets, means, direction, commanded[targets], n)
            if setup.series:  # a series' test means have no known expectation: no control variate
                control = (control[0], np.zeros_like(control[1]))
            _summarise_tests(values, errors, slots, positions, angles, commanded[targets], more, control)

    if used is None:
        for block in blocks_of(np.arange(len(indices)), (shape[0] + extra[0]) * shape[1]):
            targets = indices[block]
            positions = sampled_tests(model, moments, targets, numbers, shape, slice(0, 3))
            angles = sampled_tests(model, moments, targets, numbers, shape, slice(3, 6))
            more = None if extra_numbers is None else sampled_tests(model, moments, targets, extra_numbers, extra,
                                                                    slice(0, 3))
            summarise(list(block), targets, positions, angles, more)
        return {**values, "mc_errors": errors}
    for slot, k in enumerate(indices):
        positions, angles, engine = engine_tests(runner, model, moments, k, qs[k], numbers, shape)
        engines, more = [EngineUsed.of(engine)], None
        if extra_numbers is not None:
            more, _, extra_engine = engine_tests(runner, model, moments, k, qs[k], extra_numbers, extra)
            engines.append(EngineUsed.of(extra_engine))
        used.fall_back(k, EngineUsed.combined(engines))
        linear = None
        if asymptotic:  # the first-order model's own samples: a control variate of their moments
            linear = tuple(sampled_tests(model, moments, np.array([k]), numbers, shape, rows)
                           for rows in (slice(0, 3), slice(3, 6)))
        summarise([slot], np.array([k]), positions[None], angles[None], None if more is None else more[None], linear)
    return {**values, "mc_errors": errors}


def cycle_moments(positions: np.ndarray, cycles: int, normals: np.ndarray, centre: np.ndarray | None = None
                  ) -> tuple[tuple[np.ndarray, ...], np.ndarray]:
    """E[l^k], k = 1..4 (k,) each, of the distance l [m] of one of ``cycles`` cycles to their barycentre, from (k, M, 3)
    single cycles, and the distances (k, M); the cycles' mean their ``centre`` (k, 3) [m] where known, else their
    sample mean (whose own error δ ~ N(0, Σ / M), shared by the M cycles, adds δᵀ U δ to their distances' variance
    as a test's barycentre does to its S_l²: where sign flips dominate, twice the variance the delta method states).

    The cycle x_j and the barycentre x̄ = x_j / n + (the other n - 1 cycles' sum) / n: the latter is drawn for each
    single cycle as a normal of the cycles' covariance times (n - 1) / n² (the other cycles' mean, by the central
    limit theorem), from standard ``normals`` (M, 3). The l_j of one test share x̄: E[S_l²] is Var(l) less their
    covariance ē (Σ / n) ē, ē = E[(x_j - x̄) / l_j] (to first order), taken off the second moment.
    """
    n = cycles
    coordinates = np.moveaxis(positions, 2, 1).copy()  # (k, 3, M): each coordinate's cycles together in memory
    if centre is None:
        centred = coordinates - coordinates.mean(axis=2, keepdims=True)
        covariance = centred @ np.swapaxes(centred, 1, 2) / (positions.shape[1] - 1)
    else:
        centred = coordinates - centre[:, :, None]
        covariance = centred @ np.swapaxes(centred, 1, 2) / positions.shape[1]
    lam, vectors = np.linalg.eigh(covariance)
    roots = vectors * np.sqrt(np.maximum(lam, 0.0) * (n - 1))[:, None, :] / n
    offsets = (1 - 1 / n) * centred
    offsets -= roots @ normals.T
    squares = np.square(offsets).sum(axis=1)
    distances = np.sqrt(squares)
    inverse = np.divide(1.0, distances, out=np.zeros_like(distances), where=distances > 0)
    direction = (offsets * inverse[:, None, :]).mean(axis=2)
    shared = np.einsum("ki,kij,kj->k", direction, covariance, direction) / n
    moments = [distances.mean(axis=1), squares.mean(axis=1) - shared, (squares * distances).mean(axis=1),
               np.square(squares).mean(axis=1)]
    return tuple(moments), distances


def cycles_shares(positions: np.ndarray, cycles: int) -> np.ndarray:
    """The eigenvalues (k, 3) [m²] of U Σ̄ / n (:func:`~tribokin.iso9283.gaussian_tests.barycentre_shares`) of tests of
    ``cycles`` cycles from (k, M, 3) single cycles: U = E[û ûᵀ] over their unit offsets from their mean, Σ̄ their
    covariance."""
    centred = positions - positions.mean(axis=1, keepdims=True)
    norms = np.linalg.norm(centred, axis=-1, keepdims=True)
    units = np.divide(centred, norms, out=np.zeros_like(centred), where=norms > 0)
    directions = np.einsum("kmi,kmj->kij", units, units) / positions.shape[1]
    return barycentre_shares(directions, sample_covariance(positions), cycles)


def barycentre_normals(count: int) -> np.ndarray:
    """(count, 3) standard normals drawing the barycentre of each single cycle (:func:`cycle_moments`), the same at
    every target and scenario."""
    return expected_stream(0, "barycentre").standard_normal((count, 3))


def _summarise_cycles(values: dict, errors: dict, slots: list[int], positions: np.ndarray, angles: np.ndarray,
                      commanded: np.ndarray, cycles: int, control: tuple) -> None:
    """As :func:`_summarise_tests`, for tests of ``cycles`` >= ``ASYMPTOTIC_CYCLES`` cycles from (k, 1, M, 3) single
    cycles: RP_l from their distances' moments (:func:`~tribokin.iso9283.gaussian_tests.rp_l_from_moments`), its band
    from their spread and skewness (:func:`cycles_band`), their Monte Carlo errors by the delta method over the
    cycles' moments (:func:`moments_errors`); the semi-axis E√λ̂₁ from the covariance and the cycles' fourth moments
    (:func:`cycles_semi_axis`); AP_p and RP_a/b/c as in the closed form from the cycles' mean and covariance, which
    are the first-order
    model's (``control``: the model, the targets, and after a fallback the model's samples of the same numbers, a
    control variate: the engine's sample moments less the model's plus the model's exact ones; their errors then
    bounded by the model's bound b, β over √M)."""
    positions, angles = positions[:, 0], angles[:, 0]
    n, count = cycles, positions.shape[1]
    moments, distances = cycle_moments(positions, n, barycentre_normals(positions.shape[1]))
    mean = rp_l_from_moments(moments, n)[0]
    band = cycles_band(positions, n)
    low, high = skewed_band(mean, band.spread, band.skewness)
    model, targets, linear = control
    centre, covariance = model.position_m[targets], model.position_covariance[targets]
    angle_variance = np.diagonal(model.angle_covariance[targets], axis1=1, axis2=2)
    bound = np.zeros((len(targets), 2))
    if linear is not None:
        own, own_angles = linear[0][:, 0], linear[1][:, 0]
        centre = centre + positions.mean(axis=1) - own.mean(axis=1)
        covariance = covariance + sample_covariance(positions) - sample_covariance(own)
        angle_variance = angle_variance + angles.var(axis=1, ddof=1) - own_angles.var(axis=1, ddof=1)
        bound = model.bound[targets] / math.sqrt(count)
    ap_p = expected_norm(centre - commanded, covariance / n)
    semi_axis, semi_axis_error = cycles_semi_axis(positions, covariance, n)
    angle_std = np.sqrt(np.maximum(angle_variance, 0.0))
    lengths = {"RP_l_um": mean, "RP_l_lo_um": low, "RP_l_hi_um": high, "AP_p_um": ap_p,
               "largest_semi_axis_um": semi_axis}
    for name, length in lengths.items():
        values[name][slots] = length * UM_PER_M
    stated = dict(zip(("RP_l_um", "RP_l_lo_um", "RP_l_hi_um"), moments_errors(distances, moments, n, band=band),
                      strict=True))
    stated.update({"AP_p_um": relative(bound[:, 0], ap_p),
                   "largest_semi_axis_um": relative(np.hypot(bound[:, 0], semi_axis_error), semi_axis)})
    for i, axis in enumerate("abc"):
        values[f"RP_{axis}_mdeg"][slots] = 3 * c4(n) * angle_std[:, i] * MDEG_PER_RAD
        stated[f"RP_{axis}_mdeg"] = relative(bound[:, 1], angle_std[:, i])
    for name, error in stated.items():
        errors[name][slots] = error


def sample_covariance(points: np.ndarray) -> np.ndarray:
    """(k, d, d) covariance (n - 1) of (k, M, d) ``points``."""
    offsets = points - points.mean(axis=1, keepdims=True)
    return np.einsum("kmi,kmj->kij", offsets, offsets) / (points.shape[1] - 1)


def relative(error: np.ndarray, value: np.ndarray) -> np.ndarray:
    """``error`` over ``|value|``, 0 where the value is."""
    return np.divide(error, np.abs(value), out=np.zeros(np.shape(error)), where=value != 0)


def moments_errors(distances: np.ndarray, moments: tuple[np.ndarray, ...], cycles: int,
                   shared: np.ndarray | None = None, band: CyclesBand | None = None) -> tuple[np.ndarray, ...]:
    """Relative standard errors of E[RP_l] (:func:`~tribokin.iso9283.gaussian_tests.rp_l_from_moments`, with the
    barycentre's ``shared`` form if given) taken from ``moments`` of (k, M) single cycles' ``distances``, and with
    ``band`` (:func:`cycles_band`, of the same cycles) of its band's two ends: the delta method, E[RP_l]'s gradient
    in the four moments by central differences times each cycle's (l, l², l³, l⁴) less their means, an end's that plus
    its quantile factor times the cycle's influence on the band's spread, their mean squares over M (the shared form
    held: its own error, of a term 0.1-0.5 % of RP_l estimated to about 1/√M, is some 1e-5; the skewness's, which
    moves an end by about 0.5 % of an error of it times the spread, too)."""
    powers = distances[..., None] ** np.arange(1, 5)  # (k, M, 4)
    centred = powers - powers.mean(axis=1, keepdims=True)
    count = distances.shape[1]
    covariance = np.einsum("kmi,kmj->kij", centred, centred) / (count - 1) / count

    def mean_of(point):
        return rp_l_from_moments(tuple(point), cycles, shared)[0]

    point = np.stack(moments)  # (4, k)
    gradient = np.empty((point.shape[1], 4))
    for i in range(4):
        step = np.zeros_like(point)
        step[i] = 1e-4 * np.abs(point[i]) + np.finfo(float).tiny
        gradient[:, i] = (mean_of(point + step) - mean_of(point - step)) / (2 * step[i])
    mean = mean_of(point)
    errors = [relative(np.sqrt(np.maximum(np.einsum("ki,kij,kj->k", gradient, covariance, gradient), 0.0)), mean)]
    if band is not None:
        influence = np.einsum("kmi,ki->km", centred, gradient)
        for factor, end in zip(band_factors(band.skewness), skewed_band(mean, band.spread, band.skewness), strict=True):
            variance = np.square(influence + factor[:, None] * band.influence).sum(axis=1) / (count - 1) / count
            errors.append(relative(np.sqrt(variance), end))
    return tuple(errors)


class CyclesBand(NamedTuple):
    """One test's RP_l spread over tests of n cycles from (k, M) single cycles (:func:`cycles_band`): its standard
    deviation ``spread`` [m] and ``skewness`` (k,), and each cycle's ``influence`` (k, M) on the spread [m] (its
    error's share)."""

    spread: np.ndarray
    skewness: np.ndarray
    influence: np.ndarray


def cycles_band(positions: np.ndarray, cycles: int) -> CyclesBand:
    """The spread and skewness of one test's RP_l = l̄ + 3 S_l over tests of ``cycles`` cycles, from (k, M, 3) single
    cycles [m]: the delta method over one cycle's (l, l²) about the cycles' mean (the l_j measured from a test's own
    barycentre ȳ: l̄ moves by -ēᵀ(ȳ - μ) to first order, ē = E[(y - μ) / |y - μ|], which a skewed cloud makes
    non-zero, and mean l² by |ȳ - μ|² only; the normal band leaving this out was 2-7 % too wide on lognormal
    friction), the influence h = g_l (l - ēᵀ(y - μ) - E l) + g_l² (l² - E l²) of each cycle, Var(RP_l) = E[h²] / n and
    the third cumulant (E[h³] + 3 hᵀ H h) / n² (H the Hessian of l̄ + 3 S_l in the two means; its skewness, about 0.2
    at 500 cycles on lognormal friction, moves the band's ends by about 0.5 % of RP_l; left out: the barycentre's
    second-order share, which the lognormal clouds put at about 0.05 of the skewness)."""
    n = cycles
    offsets = positions - positions.mean(axis=1, keepdims=True)
    squares = np.einsum("kmi,kmi->km", offsets, offsets)
    distances = np.sqrt(squares)
    inverse_distances = np.divide(1.0, distances, out=np.zeros_like(distances), where=distances > 0)
    mean_unit = (inverse_distances[:, None, :] @ offsets)[:, 0] / offsets.shape[1]
    along = distances - (offsets @ mean_unit[:, :, None])[..., 0]
    first, second = distances.mean(axis=1), squares.mean(axis=1)
    factor = math.sqrt(n / (n - 1))
    sigma = np.sqrt(np.maximum(second - first ** 2, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        inverse = np.where(sigma > 0, 1 / sigma, 0.0)
    slope_first, slope_second = 1 - 3 * factor * first * inverse, 1.5 * factor * inverse
    deviations = (along - first[:, None], squares - second[:, None])
    h = slope_first[:, None] * deviations[0] + slope_second[:, None] * deviations[1]
    h2 = h * h
    variance = h2.mean(axis=1)
    spread = np.sqrt(variance / n)
    shares = tuple((h * d).mean(axis=1) for d in deviations)
    skewness = influence_skewness((h2 * h).mean(axis=1), variance, shares, (first, second), n)
    with np.errstate(divide="ignore", invalid="ignore"):
        influence = np.where(spread[:, None] > 0, (h2 - variance[:, None]) / (2 * n * spread[:, None]), 0.0)
    return CyclesBand(spread, skewness, influence)


def cycles_semi_axis(positions: np.ndarray, covariance: np.ndarray, cycles: int) -> tuple[np.ndarray, np.ndarray]:
    """E√λ̂₁ [m] (k,) over tests of ``cycles`` cycles (:func:`~tribokin.iso9283.gaussian_tests.expected_semi_axis`) of
    cycles of ``covariance`` (k, 3, 3) [m²], the fourth moments in its eigenvectors' axes from the (k, M, 3) single
    cycles ``positions`` [m], and its standard error [m] from those moments: half the difference of the figure from
    the even and from the odd cycles (one draw of it, right in mean square; some 1e-6 of the figure)."""
    lam, vectors = np.linalg.eigh(covariance)
    lam, vectors = lam[:, ::-1], vectors[:, :, ::-1]
    axes = (positions - positions.mean(axis=1, keepdims=True)) @ vectors
    terms = np.stack([axes[..., 0] ** 2, axes[..., 1] ** 2, axes[..., 0] * axes[..., 1], axes[..., 0] * axes[..., 2]],
                     axis=-1)
    halves = [(half.sum(axis=1), np.swapaxes(half, 1, 2) @ half, half.shape[1]) for half in (terms[:, ::2],
                                                                                          terms[:, 1::2])]
    whole = (halves[0][0] + halves[1][0], halves[0][1] + halves[1][1], terms.shape[1])

    def products(sums, squares, count):  # the (k, 4, 4) covariance (count - 1) of the terms from their sums
        return (squares - sums[:, :, None] * sums[:, None, :] / count) / (count - 1)

    even, odd = (expected_semi_axis(lam, products(*half), cycles) for half in halves)
    return expected_semi_axis(lam, products(*whole), cycles), np.abs(even - odd) / 2


def _summarise_tests(values: dict, errors: dict, slots: list[int], positions: np.ndarray, angles: np.ndarray,
                     commanded: np.ndarray, more: np.ndarray | None, control: tuple) -> None:
    """Into ``values[...][slots]``: the mean of each figure over the tests of (k, tests, cycles, 3) ``positions``
    [m] and ``angles`` [rad], RP_l's and its band's over these and the ``more`` (k, further tests, cycles, 3)
    positions of :func:`band_factor`, AP_p's with its ``control`` variate (:func:`position_control`'s pair); into
    ``errors[...][slots]`` their relative Monte Carlo standard errors (:func:`~tribokin.iso9283.gaussian_tests.
    mean_error`, :func:`~tribokin.iso9283.gaussian_tests.percentile_error`, :func:`controlled_mean`)."""
    spread = position_spread(positions)
    rp_abc = orientation_repeatability(angles) * MDEG_PER_RAD
    rp_l = spread.RP_l_m if more is None else np.concatenate([spread.RP_l_m, position_repeatability(more)[0]], axis=1)
    per_test = {"RP_l_um": rp_l * UM_PER_M,
                "RP_a_mdeg": rp_abc[..., 0], "RP_b_mdeg": rp_abc[..., 1], "RP_c_mdeg": rp_abc[..., 2],
                "largest_semi_axis_um": spread.largest_semi_axis_m * UM_PER_M}
    for name, figure in per_test.items():
        values[name][slots] = figure.mean(axis=1)
        errors[name][slots] = mean_error(figure)
    ap_p = np.linalg.norm(spread.barycenter_m - commanded[:, None], axis=-1) * UM_PER_M
    values["AP_p_um"][slots], errors["AP_p_um"][slots] = controlled_mean(ap_p, *control)
    ordered = np.sort(per_test["RP_l_um"], axis=1)
    values["RP_l_lo_um"][slots], values["RP_l_hi_um"][slots] = np.percentile(ordered, BAND_PERCENTILES, axis=1)
    for name, percentile in zip(("RP_l_lo_um", "RP_l_hi_um"), BAND_PERCENTILES, strict=True):
        errors[name][slots] = percentile_error(ordered, percentile)


def _analytic(model: LinearModel, chosen: np.ndarray, setup: ExpectedSetup, commanded: np.ndarray
              ) -> dict[str, np.ndarray]:
    """The figures of targets ``chosen`` in closed form (:mod:`tribokin.iso9283.gaussian_tests`), and under
    ``"mc_errors"`` their relative Monte Carlo standard errors: the shape table's for what comes from it, else 0."""
    n = setup.cycles
    position = model.position_covariance[chosen]
    lam = eigenvalues(position)
    scale, shape = standardised_shape(lam)
    rp_l, spread = expected_rp_l(lam, n)
    errors = {name: np.zeros(len(scale)) for name in SAMPLED_FIGURES}
    if setup.table is None:  # from ASYMPTOTIC_CYCLES on
        largest_first = lam[:, ::-1]
        band = skewed_band(rp_l, spread, gaussian_band_skewness(lam, n))
        semi_axis = expected_semi_axis(largest_first, gaussian_products(largest_first), n)
    else:
        mean, low, high, semi_axis = setup.table.at(shape)
        table_errors = dict(zip(("RP_l_um", "RP_l_lo_um", "RP_l_hi_um", "largest_semi_axis_um"),
                                setup.table.errors_at(shape), strict=True))
        rp_l = rp_l if n >= ANALYTIC_MIN_CYCLES else mean * scale
        with np.errstate(divide="ignore", invalid="ignore"):
            band = [np.where(mean > 0, rp_l * ratio / mean, 0.0) for ratio in (low, high)]
        semi_axis = semi_axis * scale
        if n >= ANALYTIC_MIN_CYCLES:
            del table_errors["RP_l_um"]
        errors.update(table_errors)
    angle_std = np.sqrt(np.diagonal(model.angle_covariance[chosen], axis1=1, axis2=2))
    return {"RP_l_um": rp_l * UM_PER_M, "RP_l_lo_um": band[0] * UM_PER_M, "RP_l_hi_um": band[1] * UM_PER_M,
            "AP_p_um": expected_norm(model.position_m[chosen] - commanded, position / n) * UM_PER_M,
            **{f"RP_{axis}_mdeg": 3 * c4(n) * angle_std[:, i] * MDEG_PER_RAD for i, axis in enumerate("abc")},
            "largest_semi_axis_um": semi_axis * UM_PER_M, "mc_errors": errors}


def _vap(runner: PoseRunner, moments: JointMoments, qs: np.ndarray, lever: np.ndarray, twists: np.ndarray,
         cycles: int, mixed: LinearModel) -> tuple[np.ndarray, np.ndarray, EngineUsed, np.ndarray]:
    """vAP_p [µm] (k,), its relative Monte Carlo standard error (k,) (0 in closed form), the engine that computed it
    (:class:`EngineUsed`) and its fallbacks (k,).

    The three directions' barycentres through the ``mixed`` first-order model (about q + offset, RP_l_multi's: its
    bound holds for every sign pattern's deviations, so for each direction's); where it does not serve, through each
    direction's own model about its mean deviation (the three's least exact engine, their largest bound), and where
    those do not serve either, :func:`_vap_tests`. With ``study.engine = "exact"``, :func:`_vap_tests` through exact
    FK at every target (none counted as a fallback); where a joint's friction is a time series (its barycentres not
    the Gaussians of independent cycles), :func:`_vap_tests` through the fast engine at every target, each test's
    series drawn from the runner's state (none counted as a fallback either)."""
    directions = np.array([APPROACH_DIRECTIONS[label] for label in VAP_DIRECTIONS])
    signs = approach_signs_from_jacobians(twists, directions)  # (k, 3, nv)
    if runner.settings.engine == "exact" or runner.correlated:
        models = [linear_model(runner.robot, moments, qs, lever, signs[:, d], mixed=False)
                  for d in range(len(directions))]
        used = EngineUsed.first_order(models[0])
        unsigned = common_numbers(runner, np.ones((1, cycles, qs.shape[1])),
                                  len(directions) * tests_for(SAMPLED_CYCLES, cycles), "vap tests")
        sampled = np.array([_vap_tests(runner, models, moments, k, qs[k], signs[k], cycles, used, unsigned)
                            for k in range(len(qs))]).reshape(len(qs), 2)
        return sampled[:, 0] * UM_PER_M, sampled[:, 1], used, np.zeros(len(qs), dtype=int)
    position = mixed.jacobian[:, :3]
    lost = lever * moments.mean + moments.half_backlash
    centres = mixed.position_m[:, None] + (signs * lost[:, None]) @ np.swapaxes(position, 1, 2)
    variance = signs ** 2 * ((lever * moments.std) ** 2)[:, None] + moments.noise_std ** 2  # (k, 3 directions, nv)
    noise = np.stack([jacobian_covariance(mixed.jacobian, variance[:, d], 0) for d in range(len(directions))], axis=1)
    vap, error = _vap_expected(centres, noise / cycles,
                               runner.settings.seed)
    vap *= UM_PER_M
    used = EngineUsed.first_order(mixed)
    own = np.flatnonzero(~serves(used.bound, cycles, {"vAP_p_um": vap}, "vap"))
    fallen = np.zeros(len(qs), dtype=int)
    if len(own):
        models = [linear_model(runner.robot, moments, qs[own], lever[own], signs[own, d], mixed=False)
                  for d in range(len(directions))]
        vap[own], error[own] = _vap_expected(np.stack([m.position_m for m in models], axis=1),
                                             np.stack([m.position_covariance for m in models], axis=1) / cycles,
                                             runner.settings.seed)
        vap[own] *= UM_PER_M
        theirs = EngineUsed.combined([EngineUsed.first_order(m) for m in models])
        for j in np.flatnonzero(~serves(theirs.bound, cycles, {"vAP_p_um": vap[own]}, "vap")):
            vap[own[j]], error[own[j]] = _vap_tests(runner, models, moments, j, qs[own[j]], signs[own[j]], cycles,
                                                    theirs)
            vap[own[j]] *= UM_PER_M
            fallen[own[j]] = 1
        used.engine[own], used.bound[own] = theirs.engine, theirs.bound
    return vap, error, used, fallen


def _vap_expected(centres: np.ndarray, noise: np.ndarray, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """E[vAP_p] [m] (k,) of barycentres ``centres`` (k, 3 directions, 3) [m] with Gaussian noise of covariances
    ``noise`` (k, 3 directions, 3, 3) [m²], and its relative Monte Carlo standard error (k,): the farthest pair's
    E|g + e| in closed form (0), or :func:`_vap_close` where two pairs are about as far apart, over ``VAP_DRAWS``
    draws, and where that leaves the error above ``MC_ERROR_AIM``, over ``VAP_MORE_DRAWS`` times as many, up to
    ``VAP_MOST_DRAWS``. In one compiled kernel where :func:`~tribokin.compiled.use_compiled`
    (:func:`~tribokin.maps.expected_figures_kernels.vap_expected`)."""
    draws = VAP_DRAWS
    vap, error = _vap_expected_over(centres, noise, seed, draws)
    again = np.flatnonzero(error > MC_ERROR_AIM)
    while len(again) and draws < VAP_MOST_DRAWS:
        draws = min(draws * VAP_MORE_DRAWS, VAP_MOST_DRAWS)
        vap[again], error[again] = _vap_expected_over(centres[again], noise[again], seed, draws)
        again = again[error[again] > MC_ERROR_AIM]
    return vap, error


def _vap_expected_over(centres: np.ndarray, noise: np.ndarray, seed: int, draws: int
                       ) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_vap_expected`, close pairs corrected over ``draws`` draws."""
    if use_compiled():
        from tribokin.maps.expected_figures_kernels import vap_expected

        out = vap_expected(np.ascontiguousarray(centres, dtype=float), np.ascontiguousarray(noise, dtype=float),
                           _vap_draws(seed, draws), TAIL_STDS, NORM_RULE, MAXIMUM_RULE)
        return out[:, 0], relative(out[:, 1], out[:, 0])
    gaps = np.stack([centres[:, a] - centres[:, b] for a, b in VAP_PAIRS], axis=1)
    spreads = np.stack([noise[:, a] + noise[:, b] for a, b in VAP_PAIRS], axis=1)
    sizes = np.linalg.norm(gaps, axis=-1)
    order = np.argsort(-sizes, axis=1)
    first, second = (np.take_along_axis(sizes, order[:, [i]], axis=1)[:, 0] for i in (0, 1))
    farthest = (np.arange(len(gaps)), order[:, 0])
    widths = np.sqrt(eigenvalues(spreads[farthest])[:, -1]) + np.sqrt(eigenvalues(
        spreads[np.arange(len(gaps)), order[:, 1]])[:, -1])
    vap, error = expected_norm(gaps[farthest], spreads[farthest]), np.zeros(len(gaps))
    close = np.flatnonzero(first - second <= TAIL_STDS * widths)
    if len(close):
        vap[close], error[close] = _vap_close(centres[close], noise[close], seed, draws)
    return vap, relative(error, vap)


def _vap_close(centres: np.ndarray, noise: np.ndarray, seed: int, draws: int = VAP_DRAWS
               ) -> tuple[np.ndarray, np.ndarray]:
    """E[vAP_p] [m] (k,) and its Monte Carlo standard error [m] (k,) where two or three pairs of approach directions
    are about as far apart: the largest of the pairs' distances |g + e| between barycentres of ``centres``
    (k, 3 directions, 3) [m] and Gaussian noise of covariances ``noise`` (k, 3 directions, 3, 3) [m²] (e: the
    difference of a pair's two).

    Linearised, each distance is |g| + (tr S - ĝᵀ S ĝ) / (2 |g|) + ĝᵀ e (S the pair's covariance; the middle term
    only where tr S < |g|²): jointly normal, their largest's expectation in closed form
    (:func:`~tribokin.iso9283.gaussian_tests.expected_maximum`), is a control variate: the mean over ``draws``
    draws (common random numbers) of the exact largest distance less the linearised one is added, whose Monte Carlo
    error is that of the difference (second order in the noise), not of the distance: the differences' standard
    deviation over √``draws``, the error stated. The NumPy path's; the compiled one is within
    :func:`~tribokin.maps.expected_figures_kernels.vap_expected`."""
    gaps = np.stack([centres[:, a] - centres[:, b] for a, b in VAP_PAIRS], axis=1)  # (k, pairs, 3)
    spreads = np.stack([noise[:, a] + noise[:, b] for a, b in VAP_PAIRS], axis=1)
    sizes = np.linalg.norm(gaps, axis=-1)
    units = np.divide(gaps, sizes[..., None], out=np.zeros_like(gaps), where=sizes[..., None] > 0)
    trace = np.trace(spreads, axis1=-2, axis2=-1)
    along = np.einsum("kpi,kpij,kpj->kp", units, spreads, units)
    linear = trace < sizes ** 2
    means = sizes + np.divide(trace - along, 2 * sizes, out=np.zeros_like(sizes), where=linear)
    loads = np.zeros((len(gaps), len(VAP_PAIRS), 3, 3))  # (k, pairs, directions, 3): how e moves each distance
    for p, (a, b) in enumerate(VAP_PAIRS):
        loads[:, p, a], loads[:, p, b] = units[:, p], -units[:, p]
    covariance = np.einsum("kpdi,kdij,kqdj->kpq", loads, noise, loads)
    vap = expected_maximum(means, covariance)
    z = _vap_draws(seed, draws)
    standard_error = np.empty(len(gaps))
    for k in np.array_split(np.arange(len(gaps)), max(1, len(gaps) * draws // BLOCK_CYCLES)):
        lam, vectors = np.linalg.eigh(noise[k])  # the symmetric root of each (block, 3 directions, 3, 3)
        roots = (vectors * np.sqrt(np.maximum(lam, 0.0))[..., None, :]) @ np.swapaxes(vectors, -1, -2)
        shifts = roots @ z  # (block, 3 directions, 3, draws)
        exact, linearised = [], []
        for p, (a, b) in enumerate(VAP_PAIRS):
            error = shifts[:, a] - shifts[:, b]  # (block, 3, draws)
            exact.append(np.sqrt(np.sum((gaps[k, p, :, None] + error) ** 2, axis=1)))
            linearised.append(means[k, p, None] + np.sum(units[k, p, :, None] * error, axis=1))
        differences = np.max(exact, axis=0) - np.max(linearised, axis=0)
        vap[k] += differences.mean(axis=1)
        standard_error[k] = differences.std(axis=1, ddof=1) / math.sqrt(draws)
    return vap, standard_error


@lru_cache(maxsize=4)
def _vap_draws(seed: int, draws: int = VAP_DRAWS) -> np.ndarray:
    """(3 directions, 3, ``draws``) the standard normal draws of :func:`_vap_close`'s correction (read-only): each
    direction's draws by coordinate; the first ``VAP_DRAWS`` of any count the same."""
    z = expected_stream(seed, "vap").standard_normal((draws, 3, 3))
    z = np.ascontiguousarray(z.transpose(1, 2, 0))
    z.flags.writeable = False
    return z


def _vap_tests(runner: PoseRunner, models: list[LinearModel], moments: JointMoments, k: int, q: np.ndarray,
               signs: np.ndarray, cycles: int, used: EngineUsed, unsigned: np.ndarray | None = None
               ) -> tuple[float, float]:
    """vAP_p [m] of target ``k`` through the engine of :func:`engine_tests`: the mean over ``tests_for``
    sampled tests (common random numbers, ``unsigned``: :func:`common_numbers` of ``"vap tests"`` with every sign +1,
    drawn here when not given) of the largest distance between the barycentres of ``cycles`` cycles approached with
    each direction's joint signs ``signs`` (3, nv), and its relative standard error; where that error is above
    ``MC_ERROR_AIM`` (a vAP_p small beside its barycentres' spread), with as many more tests (``"vap more tests"``)
    as bring it within (:func:`pilot_factor`, at most ``MAX_BAND_FACTOR`` times as many in all); the directions'
    engines recorded in ``used``."""
    tests, nv = tests_for(SAMPLED_CYCLES, cycles), len(q)
    if unsigned is None:
        unsigned = common_numbers(runner, np.ones((1, cycles, nv)), len(signs) * tests, "vap tests")
    largest = _vap_largest(runner, models, moments, k, q, signs, cycles, used, unsigned)
    factor = pilot_factor(float(mean_error(largest)), MAX_BAND_FACTOR)
    if factor > 1:
        more = common_numbers(runner, np.ones((1, cycles, nv)), len(signs) * (factor - 1) * tests, "vap more tests")
        largest = np.concatenate([largest, _vap_largest(runner, models, moments, k, q, signs, cycles, used, more)])
    return float(largest.mean()), float(mean_error(largest))


def _vap_largest(runner: PoseRunner, models: list[LinearModel], moments: JointMoments, k: int, q: np.ndarray,
                 signs: np.ndarray, cycles: int, used: EngineUsed, unsigned: np.ndarray) -> np.ndarray:
    """(tests,) the largest distance between the three directions' barycentres of each test of ``cycles`` cycles
    drawn from ``unsigned`` (3 tests × cycles, 3 nv) (:func:`_vap_tests`)."""
    nv, tests = len(q), len(unsigned) // (len(signs) * cycles)
    barycentres, engines = [], []
    for d, part in enumerate(np.split(unsigned, len(signs))):
        numbers = np.concatenate([part[:, :nv] * signs[d], np.broadcast_to(signs[d], (len(part), nv)),
                                  part[:, 2 * nv:]], axis=1)
        positions, _, engine = engine_tests(runner, models[d], moments, k, q, numbers, (tests, cycles))
        barycentres.append(positions.mean(axis=1))
        engines.append(EngineUsed.of(engine))
    used.fall_back(k, EngineUsed.combined(engines))
    return np.max([np.linalg.norm(barycentres[a] - barycentres[b], axis=1) for a, b in VAP_PAIRS], axis=0)


def _multi(runner: PoseRunner, setup: ExpectedSetup, qs: np.ndarray, model: LinearModel
           ) -> tuple[np.ndarray, np.ndarray, EngineUsed, np.ndarray]:
    """RP_l_multi [µm] (k,), its relative Monte Carlo standard error (k,) (0: from the mixture's moments; sampled:
    the tests' mean's, or from ``ASYMPTOTIC_CYCLES`` cycles on the delta method's over the cycles' moments), the engine
    that computed it (:class:`EngineUsed`) and its fallbacks (k,), from the mixed first-order ``model`` (every joint's
    sign drawn per cycle, about q + offset); with ``study.engine = "exact"`` sampled through exact FK at every target
    (none counted as a fallback)."""
    n, moments = setup.cycles, setup.moments
    single = n >= ASYMPTOTIC_CYCLES and not setup.series  # single cycles, not whole tests
    shape = sampled_shape(MULTI_CYCLES, n, MIN_MULTI_TESTS, whole_tests=setup.series)

    def draw() -> np.ndarray:
        rng = expected_stream(runner.settings.seed, "multi signs")
        signs = rng.integers(0, 2, size=(*shape, len(runner.models))) * 2.0 - 1.0
        return common_numbers(runner, signs, shape[0], "multi")

    def numbers() -> np.ndarray:  # the sampled cycles' common random numbers, drawn only where cycles are sampled
        return setup.once("multi", draw)

    def repeatability(positions: np.ndarray, centre: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(k,) each of (k, tests, cycles, 3) ``positions``, from ``ASYMPTOTIC_CYCLES`` cycles on about the mixture's
        mean ``centre`` (k, 3) (:func:`cycle_moments`)."""
        if single:
            distance_moments, distances = cycle_moments(positions[:, 0], n, barycentre_normals(shape[1]), centre)
            shared = cycles_shares(positions[:, 0], n)
            return (rp_l_from_moments(distance_moments, n, shared)[0],
                    moments_errors(distances, distance_moments, n, shared)[0])
        per_test = position_repeatability(positions)[0]
        return per_test.mean(axis=1), mean_error(per_test)

    exact = runner.settings.engine == "exact"
    if exact:
        rp, error = np.full(len(qs), np.nan), np.full(len(qs), np.nan)  # every target's from exact FK below
    elif n >= ASYMPTOTIC_CYCLES and moments.gaussian and len(runner.models) <= MIXTURE_MAX_JOINTS:
        rp, error = _multi_moments(model, moments, n), np.zeros(len(qs))
    else:
        rp, error = np.empty(len(qs)), np.empty(len(qs))
        for block in blocks_of(np.arange(len(qs)), math.prod(shape)):
            if single:
                rp[block], error[block] = repeatability(sampled_tests(model, moments, block, numbers(), shape,
                                                                      slice(0, 3)), model.position_m[block])
            else:
                centred = setup.once("multi centred", lambda: centred_numbers(numbers(), shape))
                per_test = tests_rp_l(model, moments, block, numbers(), shape, centred)
                rp[block], error[block] = per_test.mean(axis=1), mean_error(per_test)
    rp *= UM_PER_M
    used = EngineUsed.first_order(model)
    fallen = ~serves(model.bound, n, {"RP_l_multi_um": rp}, "multi")  # exact: NaN, served nowhere
    for k in np.flatnonzero(fallen):
        positions, _, engine = engine_tests(runner, model, moments, k, qs[k], numbers(), shape)
        used.fall_back(k, EngineUsed.of(engine))
        centre = model.position_m[k]
        if single:  # the mixture's mean: the model's, less its own samples' error (a control variate)
            own = sampled_tests(model, moments, np.array([k]), numbers(), shape, slice(0, 3))[0]
            centre = centre + positions.mean(axis=(0, 1)) - own.mean(axis=(0, 1))
        again, again_error = repeatability(positions[None], centre[None])
        rp[k], error[k] = again[0] * UM_PER_M, again_error[0]
    return rp, error, used, (fallen & (not exact)).astype(int)


def _multi_moments(model: LinearModel, moments: JointMoments, cycles: int) -> np.ndarray:
    """E[RP_l_multi] [m] (k,) of tests of ``cycles`` >= ``ASYMPTOTIC_CYCLES`` cycles, every law Gaussian, from the
    mixed first-order ``model`` (its mean deviation the offset): the cloud of one sign pattern s is Gaussian, of mean
    J (s ⊙ m) (m the lost motion L μ̄ + backlash / 2, J the position rows) and covariance Σ = J diag(L² σ² + noise²) Jᵀ,
    the pooled cycles' mean the model's position and their covariance Σ̄ = Σ + J diag(m²) Jᵀ. As
    :func:`cycle_moments` (the cycle less a barycentre drawn as a normal of covariance Σ̄ (n - 1) / n²), the distance
    to the barycentre is the norm of (1 - 1/n) J (s ⊙ m) plus a normal of covariance (1 - 1/n)² Σ + (n - 1) / n² Σ̄:
    its moments over the patterns (:func:`~tribokin.iso9283.gaussian_tests.sign_mixture`; the shared term of
    :func:`cycle_moments` is 0, the mixture being symmetric about its mean) give RP_l
    (:func:`~tribokin.iso9283.gaussian_tests.rp_l_from_moments`), with the barycentre a test's cycles share through
    U = E[û ûᵀ] of that same distance's direction (from the same quadrature nodes; the direction of a cycle's offset
    from the mean, which the shared term's derivation names, differs from it by O(1/n) in its covariance, moving
    RP_l_multi by about 1e-6 of itself at 500 cycles) and Σ̄."""
    n = cycles
    position = model.jacobian[:, :3]
    lost = model.lever * moments.mean + moments.half_backlash
    columns = np.swapaxes(position * lost[:, None, :], 1, 2)  # (k, nv, 3): J_i m_i
    spread = (model.lever * moments.std) ** 2 + moments.noise_std ** 2
    pattern = jacobian_covariance(model.jacobian, spread, 0)
    pooled = pattern + jacobian_covariance(model.jacobian, lost ** 2, 0)  # + Σ_i (J_i m_i)(J_i m_i)ᵀ
    covariance = (1 - 1 / n) ** 2 * pattern + (n - 1) / n ** 2 * pooled
    moments, directions = sign_mixture((1 - 1 / n) * columns, covariance)
    return rp_l_from_mixture(moments, directions, pooled, n)
