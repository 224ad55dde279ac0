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

- **analytic** (every law Gaussian, truncation negligible, or constant; unidirectional approach): the figures of
  :mod:`tribokin.iso9283.gaussian_tests` from the covariance of J(q″) dq.
- **sampled** (other laws, approach modes, or a target the first-order model does not serve): common random
  numbers: the same ``sampled_tests`` tests of drawn μ at every target (and scenario), through the linear model,
  or through the fast engine where it does not serve (a *fallback*). The RP_l band's Monte Carlo error is kept.
- ``vAP_p_um``: the largest distance between the barycentres reached along +x, +y, +z of the world frame (joint
  signs as the measured cube's, :func:`~tribokin.iso9283.cube.held_approach_signs`); each barycentre through
  RP_l_multi's first-order model (about q + offset: its bound covers every direction's deviations), or where that
  does not serve each direction's own, plus a Gaussian of covariance Σ_d / n (the mean of n cycles); its
  expectation in closed form when one pair of directions is clearly farthest apart, else linearised in the noise
  (jointly normal distances: closed form) and corrected over ``VAP_DRAWS`` draws (a control variate).
- ``RP_l_multi_um``: cycles each approached from a random joint-space direction (every joint's sign drawn at
  random, with equal odds): the mean RP_l over ``multi_tests`` sampled tests of that mixture; from
  ``ASYMPTOTIC_CYCLES`` cycles on with every law Gaussian, from the mixture's moments, sums over the joints' sign
  patterns of Gaussian norm moments (:func:`_multi_moments`).
- The dominant joint and its share are those of the population variance (what many cycles give).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property, lru_cache, partial

import numpy as np

from tribokin.compiled import use_compiled
from tribokin.iso9283.cube import APPROACH_DIRECTIONS, approach_signs_from_jacobians
from tribokin.iso9283.gaussian_tests import (
    ANALYTIC_MIN_CYCLES,
    ASYMPTOTIC_CYCLES,
    BAND_PERCENTILES,
    ShapeTable,
    c4,
    eigenvalues,
    expected_maximum,
    expected_norm,
    expected_rp_l,
    normal_band,
    percentile_error,
    rp_l_from_moments,
    sign_mixture_moments,
    standardised_shape,
)
from tribokin.iso9283.metrics import orientation_repeatability, position_repeatability, position_spread
from tribokin.kinematics.se3_log import skew
from tribokin.maps.schema import map_figures
from tribokin.propagation.exact import engine_orders, tool_deviations_at_poses, tool_frames
from tribokin.propagation.poe import first_order_model_bounds, truncation_bound
from tribokin.simulation.joint_errors import TAIL_STDS, JointErrorModel, approach_signs, friction_lever, friction_loads
from tribokin.simulation.pose_test import PoseRunner
from tribokin.streams import expected_stream
from tribokin.tribology.laws import Constant, FrictionLaw, Gaussian, Scaled
from tribokin.units import MDEG_PER_RAD, UM_PER_M

#: Sampled tests: about this many cycles in all (2 000 tests of 30 cycles: the RP_l band's error about 1 %, and as
#: much at more cycles, whose RP_l spreads less), at least 100 and at most 2 000 tests.
SAMPLED_CYCLES, MIN_TESTS, MAX_TESTS = 60_000, 100, 2_000
#: Cycles and fewest tests of the random-direction mixture (only its mean is kept: about 0.5 % Monte Carlo error).
MULTI_CYCLES, MIN_MULTI_TESTS = 12_000, 20
#: Most joints whose 2^(nv - 1) sign patterns RP_l_multi is summed over (:func:`_multi_moments`); more are sampled.
MIXTURE_MAX_JOINTS = 10
#: Sampled cycles of the targets computed together (their positions and angles in memory at once).
BLOCK_CYCLES = 400_000
#: The figures each sampled test gives.
TEST_FIGURES = ("RP_l_um", "AP_p_um", "RP_a_mdeg", "RP_b_mdeg", "RP_c_mdeg", "largest_semi_axis_um")
#: Draws of the barycentres' noise correcting vAP_p's linearised expectation where two pairs of approach directions
#: are about as far apart (:func:`_vap_close`; on the UR5 plane the correction's standard deviation over draws is
#: 6e-5 of vAP_p at 30 cycles, 2e-6 at 1 000, against 1e-2 and 2e-3 for the distance itself).
VAP_DRAWS = 256
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
        return self._covariance(0)

    @cached_property
    def angle_covariance(self) -> np.ndarray:
        """(k, 3, 3) covariance of the tool's angle deviation [rad²]."""
        return self._covariance(3)

    def _covariance(self, first: int) -> np.ndarray:
        """J diag(var) Jᵀ of the Jacobian's rows ``first`` to ``first + 2``; compiled where
        :func:`~tribokin.compiled.use_compiled`."""
        if use_compiled():
            from tribokin.maps.expected_figures_kernels import covariances

            return covariances(np.ascontiguousarray(self.jacobian, dtype=float),
                               np.ascontiguousarray(self.deviation_variance, dtype=float), first)
        part = self.jacobian[:, first:first + 3]
        return np.einsum("kin,kn,kjn->kij", part, self.deviation_variance, part)


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
    position, truncation, composition = first_order_model_bounds(twists, departure, mean_dq)
    turn = np.einsum("kin,kn->ki", twists[:, 3:], mean_dq)  # c̃: R(q″) R(q)ᵀ = Π exp(ω̂_i(q″) E[dq_i]) to first order
    jacobian = twists.copy()
    jacobian[:, 3:] = (np.eye(3) - skew(turn) / 2) @ twists[:, 3:]  # x + x × c̃ / 2 = (I - c̃^ / 2) x
    angle = np.sqrt(1 + np.sum(turn ** 2, axis=1) / 4) * np.minimum(bound.angle_rad, truncation) + composition
    position = np.minimum(bound.position_m, position)
    return LinearModel(mean_dq, positions, jacobian, lever, variance,
                       np.column_stack([position, angle]).reshape(len(qs), 2))


@lru_cache(maxsize=4)
def shape_table(cycles: int, seed: int) -> ShapeTable:
    """The shape table of tests of ``cycles`` cycles from study seed ``seed``'s common random numbers, simulated once
    per process (a placement search maps its task region once per candidate)."""
    return ShapeTable.simulate(cycles, expected_stream(seed, "table"))


@dataclass(frozen=True)
class ExpectedSetup:
    """What every block of one scenario's expected map shares, built once per map: the tests' ``cycles``, the scenario's
    :class:`JointMoments`, the shape table of Gaussian tests (:class:`~tribokin.iso9283.gaussian_tests.ShapeTable`;
    ``None`` from ``ASYMPTOTIC_CYCLES`` cycles on), the map's ``figure_set`` (``"directional"``: vAP_p and RP_l_multi
    too) and ``mean_signs`` (nv,), each joint's mean sign of travel over the sampled tests' cycles (:func:`test_signs`),
    about which the test's first-order model is taken."""

    cycles: int
    moments: JointMoments
    table: ShapeTable | None
    figure_set: str
    mean_signs: np.ndarray

    @classmethod
    def build(cls, runner: PoseRunner, table: ShapeTable | None, figure_set: str) -> ExpectedSetup:
        signs = test_signs(runner, sampled_shape(SAMPLED_CYCLES, runner.settings.cycles))
        return cls(runner.settings.cycles, JointMoments.of(runner.models), table, figure_set, signs.mean(axis=(0, 1)))


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
    fast engine (orders 2-3, else exact FK): where the first-order model does not serve; and the engine used, the
    :class:`~tribokin.propagation.poe.TruncationBound` of :func:`~tribokin.propagation.exact.engine_orders`."""
    nv = len(q)
    signed_mu, signs, noise = numbers[:, :nv], numbers[:, nv:2 * nv], numbers[:, 2 * nv:]
    dq = moments.offset + signed_mu * model.lever[k] + signs * moments.half_backlash + noise * moments.noise_std
    twists, translations = tool_frames(runner.robot, q[None])
    used = engine_orders(twists, dq[None], lowest_order=2)
    positions, angles = tool_deviations_at_poses(runner.robot, q[None], dq[None], "fast", twists, translations, used)
    return positions.reshape(*shape, 3), angles.reshape(*shape, 3), used


def blocks_of(indices: np.ndarray, cycles_each: int) -> list[np.ndarray]:
    """``indices`` in groups whose sampled cycles stay within ``BLOCK_CYCLES``."""
    size = max(1, BLOCK_CYCLES // cycles_each)
    return [indices[start:start + size] for start in range(0, len(indices), size)]


def expected_targets(runner: PoseRunner, setup: ExpectedSetup, qs: np.ndarray, forces: np.ndarray,
                     twists: np.ndarray, translations: np.ndarray) -> dict[str, np.ndarray]:
    """Expected figures of k targets at configurations ``qs`` (k, nv) under bearing loads ``forces`` (k, nv) [N];
    ``twists``, ``translations``: their :func:`~tribokin.propagation.exact.tool_frames`.

    Returns:
        ``figures`` (k, figures) in the order of :func:`~tribokin.maps.schema.map_figures` of ``setup.figure_set``,
        ``figure_errors`` (k, figures) each figure's largest change [µm, mdeg] from the engine's bound
        (:func:`figure_errors`; NaN for ``dominant_share``), ``dominant_joint`` (k,) (-1: none), ``method`` (k,)
        (``ANALYTIC`` or ``SAMPLED``), ``fallbacks`` (k,) how many of the models (the test's; vAP_p's, RP_l_multi's)
        the first-order model did not serve and went through the fast engine, ``engine`` (k,) the least exact engine
        of the models (an index in ``TARGET_ENGINES``), ``engine_bound`` (k, 2) [m, rad] their largest bound on
        |engine - exact FK| (exact FK: 0), ``band_error`` (k,) the RP_l band's relative Monte Carlo error.
    """
    models, robot, moments, n = runner.models, runner.robot, setup.moments, setup.cycles
    lever = friction_loads(models, forces) * friction_lever(models, robot.joint_is_prismatic)
    columns = {figure.name: k for k, figure in enumerate(map_figures(setup.figure_set))}
    figures = np.full((len(qs), len(columns)), np.nan)
    errors = np.full((len(qs), len(columns)), np.nan)
    unidirectional = runner.settings.approach == "unidirectional"
    model = linear_model(robot, moments, qs, lever, np.broadcast_to(setup.mean_signs, lever.shape),
                         mixed=not unidirectional)
    everywhere, closed_form = np.ones(len(qs), dtype=bool), moments.gaussian and unidirectional
    values = (_analytic(model, everywhere, setup, translations) if closed_form
              else _sampled(runner, setup, model, everywhere, qs, translations))
    band_error = values.pop("band_error", np.full(len(qs), 0.0 if setup.table is None else setup.table.band_error))
    served = serves(model.bound, n, values, "test")
    used = EngineUsed.first_order(model)
    if not served.all():
        for name, again in _sampled(runner, setup, model, ~served, qs, translations, used).items():
            (band_error if name == "band_error" else values[name])[~served] = again
    for name, value in values.items():
        figures[:, columns[name]] = value
    out = {"figures": figures, "figure_errors": errors, "method": np.where(served & closed_form, ANALYTIC, SAMPLED),
           "fallbacks": (~served).astype(int), "band_error": band_error}
    engines = {"test": used}  # the engine of each model: the test's, and vAP_p's and RP_l_multi's by their figure
    if setup.figure_set == "directional":
        mixed = linear_model(robot, moments, qs, lever, np.zeros_like(lever), mixed=True)  # random directions
        for name, (value, engine, fallbacks) in {"vAP_p_um": _vap(runner, moments, qs, lever, twists, n, mixed),
                                                 "RP_l_multi_um": _multi(runner, setup, qs, mixed)}.items():
            figures[:, columns[name]] = value
            out["fallbacks"] += fallbacks
            engines[name] = engine
    bounded = {model_name: figure_errors(engine.bound, n) for model_name, engine in engines.items()}
    for name, column in columns.items():
        if name != "dominant_share":
            errors[:, column] = bounded.get(name, bounded["test"])[name]
    combined = EngineUsed.combined(list(engines.values()))
    out["engine"], out["engine_bound"] = combined.engine, combined.bound
    parts = model.deviation_variance * np.sum(model.jacobian[:, :3] ** 2, axis=1)
    total = parts.sum(axis=1)
    out["dominant_joint"] = np.where(total > 0, np.argmax(parts, axis=1), -1)
    figures[:, columns["dominant_share"]] = np.where(total > 0, parts.max(axis=1) / np.where(total > 0, total, 1),
                                                     np.nan)
    return out


def sampled_shape(cycles_in_all: int, cycles: int, fewest: int = MIN_TESTS) -> tuple[int, int]:
    """(tests, cycles per test) sampled for tests of ``cycles`` cycles: :func:`tests_for` tests (at least ``fewest``),
    or from ``ASYMPTOTIC_CYCLES`` on one series of ``cycles_in_all`` single cycles (:func:`cycle_moments`)."""
    if cycles >= ASYMPTOTIC_CYCLES:
        return 1, cycles_in_all
    return tests_for(cycles_in_all, cycles, fewest), cycles


def test_signs(runner: PoseRunner, shape: tuple[int, int]) -> np.ndarray:
    """Joint signs (1 or tests, cycles, nv) of sampled tests of ``shape`` (tests, cycles) under the study's ``approach``
    mode (:func:`~tribokin.simulation.joint_errors.approach_signs` with every joint forwards, then backwards): the
    same for every test unless the directions are drawn at random."""
    nv, mode = len(runner.models), runner.settings.approach
    rng = expected_stream(runner.settings.seed, "signs")
    directions = np.vstack([np.ones(nv), -np.ones(nv)])
    if mode != "random":
        return approach_signs(mode, shape[1], directions, rng)[0][None]
    return approach_signs(mode, math.prod(shape), directions, rng)[0].reshape(*shape, nv)


def _sampled(runner: PoseRunner, setup: ExpectedSetup, model: LinearModel, chosen: np.ndarray, qs: np.ndarray,
             commanded: np.ndarray, used: EngineUsed | None = None) -> dict[str, np.ndarray]:
    """The figures of targets ``chosen`` (mask) over the sampled tests, and their RP_l band's ``band_error``: through
    the first-order ``model``, or with ``used``, through the fast engine (each target's engine recorded there)."""
    n, moments = setup.cycles, setup.moments
    shape = sampled_shape(SAMPLED_CYCLES, n)
    signs = test_signs(runner, shape)
    numbers = common_numbers(runner, np.broadcast_to(signs, (*shape, signs.shape[2])) if len(signs) == 1 else signs,
                             shape[0], "tests")
    summarise = partial(_summarise_cycles, cycles=n) if n >= ASYMPTOTIC_CYCLES else _summarise_tests
    indices = np.flatnonzero(chosen)
    values = {name: np.empty(len(indices)) for name in (*TEST_FIGURES, "RP_l_lo_um", "RP_l_hi_um", "band_error")}
    if used is None:
        for block in blocks_of(np.arange(len(indices)), math.prod(shape)):
            targets = indices[block]
            positions = sampled_tests(model, moments, targets, numbers, shape, slice(0, 3))
            angles = sampled_tests(model, moments, targets, numbers, shape, slice(3, 6))
            summarise(values, list(block), positions, angles, commanded[targets])
        return values
    for slot, k in enumerate(indices):
        positions, angles, engine = engine_tests(runner, model, moments, k, qs[k], numbers, shape)
        used.fall_back(k, EngineUsed.of(engine))
        summarise(values, [slot], positions[None], angles[None], commanded[[k]])
    return values


def cycle_moments(positions: np.ndarray, cycles: int, normals: np.ndarray) -> tuple[tuple[np.ndarray, ...],
                                                                                     np.ndarray]:
    """E[l^k], k = 1..4 (k,) each, of the distance l [m] of one of ``cycles`` cycles to their barycentre, from (k, M, 3)
    single cycles, and the distances (k, M).

    The cycle x_j and the barycentre x̄ = x_j / n + (the other n - 1 cycles' sum) / n: the latter is drawn for each
    single cycle as a normal of the cycles' covariance times (n - 1) / n² (the other cycles' mean, by the central
    limit theorem), from standard ``normals`` (M, 3). The l_j of one test share x̄: E[S_l²] is Var(l) less their
    covariance ē (Σ / n) ē, ē = E[(x_j - x̄) / l_j] (to first order), taken off the second moment.
    """
    n = cycles
    coordinates = np.moveaxis(positions, 2, 1).copy()  # (k, 3, M): each coordinate's cycles together in memory
    centred = coordinates - coordinates.mean(axis=2, keepdims=True)
    covariance = centred @ np.swapaxes(centred, 1, 2) / (positions.shape[1] - 1)
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


def barycentre_normals(count: int) -> np.ndarray:
    """(count, 3) standard normals drawing the barycentre of each single cycle (:func:`cycle_moments`), the same at
    every target and scenario."""
    return expected_stream(0, "barycentre").standard_normal((count, 3))


def _summarise_cycles(values: dict, slots: list[int], positions: np.ndarray, angles: np.ndarray,
                      commanded: np.ndarray, cycles: int) -> None:
    """As :func:`_summarise_tests`, for tests of ``cycles`` >= ``ASYMPTOTIC_CYCLES`` cycles from (k, 1, M, 3) single
    cycles: RP_l from their distances' moments (:func:`~tribokin.iso9283.gaussian_tests.rp_l_from_moments`), its band
    normal; AP_p, RP_a/b/c and the semi-axis from the cycles' mean and covariance as in the closed form. The band's
    Monte Carlo error: that of the distances' mean and standard deviation over M cycles."""
    positions, angles = positions[:, 0], angles[:, 0]
    n, count = cycles, positions.shape[1]
    moments, distances = cycle_moments(positions, n, barycentre_normals(positions.shape[1]))
    mean, spread = rp_l_from_moments(moments, n)
    low, high = normal_band(mean, spread)
    offsets = positions - positions.mean(axis=1, keepdims=True)
    covariance = np.einsum("kmi,kmj->kij", offsets, offsets) / (count - 1)
    angle_std = angles.std(axis=1, ddof=1)
    lengths = {"RP_l_um": mean, "RP_l_lo_um": low, "RP_l_hi_um": high,
               "AP_p_um": expected_norm(positions.mean(axis=1) - commanded, covariance / n),
               "largest_semi_axis_um": np.sqrt(np.maximum(np.linalg.eigvalsh(covariance)[:, -1], 0.0))}
    for name, length in lengths.items():
        values[name][slots] = length * UM_PER_M
    for i, axis in enumerate("abc"):
        values[f"RP_{axis}_mdeg"][slots] = 3 * c4(n) * angle_std[:, i] * MDEG_PER_RAD
    sigma = distances.std(axis=1)
    kurtosis = ((distances - moments[0][:, None]) ** 4).mean(axis=1) / np.where(sigma > 0, sigma ** 4, 1.0)
    error = (sigma + 3 * sigma * np.sqrt(np.maximum(kurtosis - 1, 0.0) / 4)) / math.sqrt(count)
    values["band_error"][slots] = np.where(low > 0, error / np.where(low > 0, low, 1.0), 0.0)


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
    """The figures of targets ``chosen`` in closed form (:mod:`tribokin.iso9283.gaussian_tests`)."""
    n = setup.cycles
    position = model.position_covariance[chosen]
    lam = eigenvalues(position)
    scale, shape = standardised_shape(lam)
    rp_l, spread = expected_rp_l(lam, n)
    if setup.table is None:  # from ASYMPTOTIC_CYCLES on
        band, semi_axis = normal_band(rp_l, spread), scale
    else:
        mean, low, high, semi_axis = setup.table.at(shape)
        rp_l = rp_l if n >= ANALYTIC_MIN_CYCLES else mean * scale
        with np.errstate(divide="ignore", invalid="ignore"):
            band = [np.where(mean > 0, rp_l * ratio / mean, 0.0) for ratio in (low, high)]
        semi_axis = semi_axis * scale
    angle_std = np.sqrt(np.diagonal(model.angle_covariance[chosen], axis1=1, axis2=2))
    return {"RP_l_um": rp_l * UM_PER_M, "RP_l_lo_um": band[0] * UM_PER_M, "RP_l_hi_um": band[1] * UM_PER_M,
            "AP_p_um": expected_norm(model.position_m[chosen] - commanded, position / n) * UM_PER_M,
            **{f"RP_{axis}_mdeg": 3 * c4(n) * angle_std[:, i] * MDEG_PER_RAD for i, axis in enumerate("abc")},
            "largest_semi_axis_um": semi_axis * UM_PER_M}


def _vap(runner: PoseRunner, moments: JointMoments, qs: np.ndarray, lever: np.ndarray, twists: np.ndarray,
         cycles: int, mixed: LinearModel) -> tuple[np.ndarray, EngineUsed, np.ndarray]:
    """vAP_p [µm] (k,), the engine that computed it (:class:`EngineUsed`) and its fallbacks (k,).

    The three directions' barycentres through the ``mixed`` first-order model (about q + offset, RP_l_multi's: its
    bound holds for every sign pattern's deviations, so for each direction's); where it does not serve, through each
    direction's own model about its mean deviation (the three's least exact engine, their largest bound), and where
    those do not serve either, :func:`_vap_tests`."""
    directions = np.array([APPROACH_DIRECTIONS[label] for label in VAP_DIRECTIONS])
    signs = approach_signs_from_jacobians(twists, directions)  # (k, 3, nv)
    position = mixed.jacobian[:, :3]
    lost = lever * moments.mean + moments.half_backlash
    centres = mixed.position_m[:, None] + np.einsum("kin,kdn->kdi", position, signs * lost[:, None])
    variance = signs ** 2 * ((lever * moments.std) ** 2)[:, None] + moments.noise_std ** 2  # (k, 3 directions, nv)
    vap = _vap_expected(centres, np.einsum("kin,kdn,kjn->kdij", position, variance, position) / cycles,
                        runner.settings.seed) * UM_PER_M
    used = EngineUsed.first_order(mixed)
    own = np.flatnonzero(~serves(used.bound, cycles, {"vAP_p_um": vap}, "vap"))
    fallen = np.zeros(len(qs), dtype=int)
    if len(own):
        models = [linear_model(runner.robot, moments, qs[own], lever[own], signs[own, d], mixed=False)
                  for d in range(len(directions))]
        vap[own] = _vap_expected(np.stack([m.position_m for m in models], axis=1),
                                 np.stack([m.position_covariance for m in models], axis=1) / cycles,
                                 runner.settings.seed) * UM_PER_M
        theirs = EngineUsed.combined([EngineUsed.first_order(m) for m in models])
        for j in np.flatnonzero(~serves(theirs.bound, cycles, {"vAP_p_um": vap[own]}, "vap")):
            vap[own[j]] = _vap_tests(runner, models, moments, j, qs[own[j]], signs[own[j]], cycles, theirs) * UM_PER_M
            fallen[own[j]] = 1
        used.engine[own], used.bound[own] = theirs.engine, theirs.bound
    return vap, used, fallen


def _vap_expected(centres: np.ndarray, noise: np.ndarray, seed: int) -> np.ndarray:
    """E[vAP_p] [m] (k,) of barycentres ``centres`` (k, 3 directions, 3) [m] with Gaussian noise of covariances
    ``noise`` (k, 3 directions, 3, 3) [m²]: the farthest pair's E|g + e| in closed form, or :func:`_vap_close` where
    two pairs are about as far apart."""
    gaps = np.stack([centres[:, a] - centres[:, b] for a, b in VAP_PAIRS], axis=1)
    spreads = np.stack([noise[:, a] + noise[:, b] for a, b in VAP_PAIRS], axis=1)
    sizes = np.linalg.norm(gaps, axis=-1)
    order = np.argsort(-sizes, axis=1)
    first, second = (np.take_along_axis(sizes, order[:, [i]], axis=1)[:, 0] for i in (0, 1))
    farthest = (np.arange(len(gaps)), order[:, 0])
    widths = np.sqrt(eigenvalues(spreads[farthest])[:, -1]) + np.sqrt(eigenvalues(
        spreads[np.arange(len(gaps)), order[:, 1]])[:, -1])
    vap = expected_norm(gaps[farthest], spreads[farthest])
    close = np.flatnonzero(first - second <= TAIL_STDS * widths)
    if len(close):
        vap[close] = _vap_close(centres[close], noise[close], seed)
    return vap


def _vap_close(centres: np.ndarray, noise: np.ndarray, seed: int) -> np.ndarray:
    """E[vAP_p] [m] (k,) where two or three pairs of approach directions are about as far apart: the largest of the
    pairs' distances |g + e| between barycentres of ``centres`` (k, 3 directions, 3) [m] and Gaussian noise of
    covariances ``noise`` (k, 3 directions, 3, 3) [m²] (e: the difference of a pair's two).

    Linearised, each distance is |g| + (tr S - ĝᵀ S ĝ) / (2 |g|) + ĝᵀ e (S the pair's covariance; the middle term
    only where tr S < |g|²): jointly normal, their largest's expectation in closed form
    (:func:`~tribokin.iso9283.gaussian_tests.expected_maximum`), is a control variate: the mean over ``VAP_DRAWS``
    draws (common random numbers) of the exact largest distance less the linearised one is added, whose Monte Carlo
    error is that of the difference (second order in the noise), not of the distance."""
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
    z = expected_stream(seed, "vap").standard_normal((VAP_DRAWS, 3, 3))
    z = np.ascontiguousarray(z.transpose(1, 2, 0))  # (3 directions, 3, draws): each direction's draws by coordinate
    if use_compiled():
        from tribokin.maps.expected_figures_kernels import vap_corrections

        return vap + vap_corrections(gaps, means, units, np.ascontiguousarray(noise), z)
    for k in np.array_split(np.arange(len(gaps)), max(1, len(gaps) * VAP_DRAWS // BLOCK_CYCLES)):
        lam, vectors = np.linalg.eigh(noise[k])  # the symmetric root of each (block, 3 directions, 3, 3)
        roots = (vectors * np.sqrt(np.maximum(lam, 0.0))[..., None, :]) @ np.swapaxes(vectors, -1, -2)
        shifts = roots @ z  # (block, 3 directions, 3, draws)
        exact, linearised = [], []
        for p, (a, b) in enumerate(VAP_PAIRS):
            error = shifts[:, a] - shifts[:, b]  # (block, 3, draws)
            exact.append(np.sqrt(np.sum((gaps[k, p, :, None] + error) ** 2, axis=1)))
            linearised.append(means[k, p, None] + np.sum(units[k, p, :, None] * error, axis=1))
        vap[k] += (np.max(exact, axis=0) - np.max(linearised, axis=0)).mean(axis=1)
    return vap


def _vap_tests(runner: PoseRunner, models: list[LinearModel], moments: JointMoments, k: int, q: np.ndarray,
               signs: np.ndarray, cycles: int, used: EngineUsed) -> float:
    """vAP_p [m] of target ``k`` through the fast engine (:func:`engine_tests`): the mean over ``tests_for``
    sampled tests (common random numbers) of the largest distance between the barycentres of ``cycles`` cycles
    approached with each direction's joint signs ``signs`` (3, nv); the directions' engines recorded in ``used``."""
    tests = tests_for(SAMPLED_CYCLES, cycles)
    nv = len(q)
    unsigned = common_numbers(runner, np.ones((1, cycles, nv)), len(signs) * tests, "vap tests")
    barycentres, engines = [], []
    for d, part in enumerate(np.split(unsigned, len(signs))):
        numbers = np.concatenate([part[:, :nv] * signs[d], np.broadcast_to(signs[d], (len(part), nv)),
                                  part[:, 2 * nv:]], axis=1)
        positions, _, engine = engine_tests(runner, models[d], moments, k, q, numbers, (tests, cycles))
        barycentres.append(positions.mean(axis=1))
        engines.append(EngineUsed.of(engine))
    used.fall_back(k, EngineUsed.combined(engines))
    return float(np.max([np.linalg.norm(barycentres[a] - barycentres[b], axis=1) for a, b in VAP_PAIRS], axis=0).mean())


def _multi(runner: PoseRunner, setup: ExpectedSetup, qs: np.ndarray, model: LinearModel
           ) -> tuple[np.ndarray, EngineUsed, np.ndarray]:
    """RP_l_multi [µm] (k,), the engine that computed it (:class:`EngineUsed`) and its fallbacks (k,), from the
    mixed first-order ``model`` (every joint's sign drawn per cycle, about q + offset)."""
    n, moments = setup.cycles, setup.moments
    shape = sampled_shape(MULTI_CYCLES, n, MIN_MULTI_TESTS)

    @lru_cache(maxsize=1)
    def numbers() -> np.ndarray:  # the sampled cycles' common random numbers, drawn only where cycles are sampled
        rng = expected_stream(runner.settings.seed, "multi signs")
        signs = rng.integers(0, 2, size=(*shape, len(runner.models))) * 2.0 - 1.0
        return common_numbers(runner, signs, shape[0], "multi")

    def repeatability(positions: np.ndarray) -> np.ndarray:  # (k, tests, cycles, 3) -> E[RP_l] (k,)
        if n >= ASYMPTOTIC_CYCLES:
            return rp_l_from_moments(cycle_moments(positions[:, 0], n, barycentre_normals(shape[1]))[0], n)[0]
        return position_repeatability(positions)[0].mean(axis=1)

    if n >= ASYMPTOTIC_CYCLES and moments.gaussian and len(runner.models) <= MIXTURE_MAX_JOINTS:
        rp = _multi_moments(model, moments, n)
    else:
        rp = np.empty(len(qs))
        for block in blocks_of(np.arange(len(qs)), math.prod(shape)):
            rp[block] = repeatability(sampled_tests(model, moments, block, numbers(), shape, slice(0, 3)))
    rp *= UM_PER_M
    used = EngineUsed.first_order(model)
    fallen = ~serves(model.bound, n, {"RP_l_multi_um": rp}, "multi")
    for k in np.flatnonzero(fallen):
        positions, _, engine = engine_tests(runner, model, moments, k, qs[k], numbers(), shape)
        used.fall_back(k, EngineUsed.of(engine))
        rp[k] = repeatability(positions[None])[0] * UM_PER_M
    return rp, used, fallen.astype(int)


def _multi_moments(model: LinearModel, moments: JointMoments, cycles: int) -> np.ndarray:
    """E[RP_l_multi] [m] (k,) of tests of ``cycles`` >= ``ASYMPTOTIC_CYCLES`` cycles, every law Gaussian, from the
    mixed first-order ``model`` (its mean deviation the offset): the cloud of one sign pattern s is Gaussian, of mean
    J (s ⊙ m) (m the lost motion L μ̄ + backlash / 2, J the position rows) and covariance Σ = J diag(L² σ² + noise²) Jᵀ,
    the pooled cycles' mean the model's position and their covariance Σ̄ = Σ + J diag(m²) Jᵀ. As
    :func:`cycle_moments` (the cycle less a barycentre drawn as a normal of covariance Σ̄ (n - 1) / n²), the distance
    to the barycentre is the norm of (1 - 1/n) J (s ⊙ m) plus a normal of covariance (1 - 1/n)² Σ + (n - 1) / n² Σ̄:
    its moments over the patterns (:func:`~tribokin.iso9283.gaussian_tests.sign_mixture_moments`; the shared term of
    :func:`cycle_moments` is 0, the mixture being symmetric about its mean) give RP_l
    (:func:`~tribokin.iso9283.gaussian_tests.rp_l_from_moments`)."""
    n = cycles
    position = model.jacobian[:, :3]
    lost = model.lever * moments.mean + moments.half_backlash
    columns = np.swapaxes(position * lost[:, None, :], 1, 2)  # (k, nv, 3): J_i m_i
    spread = (model.lever * moments.std) ** 2 + moments.noise_std ** 2
    pattern = np.einsum("kin,kn,kjn->kij", position, spread, position)
    pooled = pattern + np.einsum("kni,knj->kij", columns, columns)
    covariance = (1 - 1 / n) ** 2 * pattern + (n - 1) / n ** 2 * pooled
    return rp_l_from_moments(sign_mixture_moments((1 - 1 / n) * columns, covariance), n)[0]
