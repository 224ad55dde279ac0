"""Maximum-likelihood fit of the joint model to measured clouds, with honest uncertainty.

- **Start.** Moments: each series' S/ν is linear in 1/k² and σ_n² (non-negative least squares,
  ``scipy.optimize.nnls``), then the barycentre differences are linear in the backlash (least
  squares, within ``BACKLASH_FLOOR`` and ``BACKLASH_CAP`` times the largest lost motion τ̄/k). Parameters the
  moments leave at zero start at their nominal values, the others within ×/÷ 1000 of them (a joint that hardly
  moves the tool point would otherwise start anywhere). When the optimiser does not converge from
  there, it starts again from the nominal model and the better optimum is kept.
- **Optimum.** ``scipy.optimize.minimize`` with SLSQP and the analytic gradient in θ = log space, bounded to
  ``LOG_SPAN`` (natural log) around the moment start, then polished by Newton steps (each halved until it lowers the
  objective; their matrix from one central difference of the gradient). The objective carries a weak prior: a Gaussian
  in θ about the moment start with standard deviation ``PRIOR_LOG_STD`` (a factor 1000). It moves a parameter the data
  determine with standard error se (in log) by about (se/``PRIOR_LOG_STD``)²·|θ̂ - start|: at most 0.15 % of its value
  for se = 0.1 within the box; along directions the data leave flat it makes the optimum unique, so the fit converges
  there too (without it the optimiser stops anywhere along them, and the determined parameters move with it, by up to
  1e-5 relative under a rotation of the data). Standard errors and log L are the data's alone. (L-BFGS-B reaches the
  same optima, more slowly: docs/benchmarks.md.)
- **Uncertainty.** Observed Fisher information = Hessian of the negative log-likelihood at the
  optimum: the Jacobian of its analytic gradient by ``scipy.differentiate.jacobian`` (adaptive
  central differences with Richardson extrapolation), symmetrised. Standard errors, null space and
  identifiability: :mod:`.identifiability`.
  Intervals are Wald intervals in log space, ``exp(θ̂ ± 1.96·se)``: asymmetric in linear space;
  :func:`profile_interval` gives a parameter's profile-likelihood interval instead.
  A parameter that ends on a bound of the box is not at a maximum of the likelihood: it is named
  not identifiable whatever its standard error. An optimum beyond the model's ranges (a study's: a backlash of
  at most 0.1 rad, ...) is searched again with the start and the box within them (a fit within them is not
  searched twice, and its numbers are those of a fit without ranges); a parameter held at an end of them is
  named so (``RANGE_HINT``), so that a fit never gives a value its study would refuse, and never calls one it
  had to hold there determined.
- **Unknown frame** (``frame="unknown"``: the points are in a measuring frame whose rotation R
  relative to the Jacobians' world frame is unknown). R is a nuisance parameter maximised jointly
  with θ (:mod:`.frame`): the candidate rotations (:func:`~.frame.candidate_rotations`) are ranked
  by log L at their moment start of θ (:func:`starting_theta` of the data turned to the base by
  them), the ``REFINED_STARTS`` likeliest are optimised in (θ, δ) by SLSQP with δ in
  ``ROTATION_BOX``, the best re-centred (δ = 0) and polished. The information is then that of
  (θ, δ); θ's standard errors, identifiability and Wald intervals come from its profile (Schur
  complement) information, so they include the rotation's uncertainty. :func:`profile_interval`
  re-fits the rotation with the other parameters.
- AIC = 2p - 2·log L with p the number of free parameters (the rotation not counted: it is no
  parameter of the joint model).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cache, partial

import numpy as np
from scipy.differentiate import jacobian
from scipy.optimize import OptimizeResult, brentq, lsq_linear, minimize, nnls
from scipy.spatial.transform import Rotation
from scipy.stats import chi2

from tribokin.calibration.data import PoseData, SeriesStack, stack
from tribokin.calibration.frame import (
    candidate_rotations,
    profile_information,
    to_base,
    unknown_frame_log_likelihood_and_gradient,
)
from tribokin.calibration.identifiability import MAX_RELATIVE_STD_ERROR, RANK_RTOL, analyse, hint
from tribokin.calibration.likelihood import log_likelihood, log_likelihood_and_gradient
from tribokin.calibration.model import JointModel, predict_series

#: Half width of the optimiser's box around the moment start, in natural log (×/÷ 1000).
LOG_SPAN = float(np.log(1e3))
#: A θ this close to the box's edge [natural log] is on a bound.
BOUND_ATOL = 1e-6
#: Backlash starting value where the moments give none: this fraction of the largest τ̄/k.
BACKLASH_FLOOR = 1e-2
#: Why a joint's stiffness or backlash is not known when the barycentres alone would have to tell them apart.
LOST_MOTION_HINT = ("the barycentres see only the sum of the joint's mean lost motion τ̄/k and half its backlash, "
                    "and the spreads do not determine its stiffness: fix the backlash or the stiffness, or measure "
                    "more poses")
#: Why a parameter held at an end of its range (:class:`~.model.ParameterRanges`) is not known.
RANGE_HINT = ("held at the end of the range a study allows: the measurements ask for a value beyond it, which a study "
              "would refuse; check the data, their units and the model, or fix its value")
#: Standard deviation [natural log] of the weak prior about the moment start (module docstring).
PRIOR_LOG_STD = LOG_SPAN
#: Backlash starting value at most this multiple of the largest τ̄/k (or the study's value, if larger): a joint
#: that hardly moves the tool would otherwise take any value the least squares like.
BACKLASH_CAP = 100.0
#: A joint is invisible when its largest |s|·|J column| is below this fraction of the largest joint's.
INVISIBLE_RTOL = 1e-9
#: SLSQP stops when -log L falls by less than this between iterations.
FTOL = 1e-10
#: SLSQP's iteration limit: a profile's re-fits with a weakly determined parameter held took 120-170 here, past
#: scipy's default of 100 (their log-likelihood then short of its maximum by up to 0.02).
MAX_ITERATIONS = 1000
#: First step of the Hessian's finite differences in θ (natural log).
HESSIAN_STEP = 0.05
#: Order of the one central difference that gives the polish's step matrix (the information's differences are
#: adaptive, to ``scipy.differentiate.jacobian``'s default tolerances): on the test arm the polished optimum moved by
#: at most 1e-9 relative against the adaptive step matrix, at two thirds of the fit's time.
POLISH_STEP_ORDER = 2
#: Newton steps polishing the optimiser's result, and how often each may be halved.
NEWTON_STEPS = 20
LINE_SEARCH_HALVINGS = 20
#: Relative rounding of -log L that a polishing step may raise it by.
ROUNDING = 1e-12
Z95 = 1.959963984540054
#: x (q, ...) -> (-log L (...), its gradient (q, ...)).
Objective = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]
FRAMES = ("registered", "unknown")
#: Unknown frame: random rotations among the starts (:func:`~.frame.candidate_rotations`) and their seed.
FRAME_STARTS = 32
FRAME_SEED = 9283
#: Unknown frame: starts (the most likely at their moment θ) the optimiser refines.
REFINED_STARTS = 2
#: Unknown frame: optima whose log L differ by less than this are one; the likelier start's is
#: kept (not the one rounding favours, which a rotation of the data could change).
SAME_OPTIMUM = 1e-3
#: (3, 2) the optimiser's box for the frame's rotation vector δ about its reference [rad].
ROTATION_BOX = np.tile([-np.pi, np.pi], (3, 1))


@dataclass(frozen=True)
class ParameterEstimate:
    """One free parameter as fitted.

    Attributes:
        name: e.g. ``joints.elbow_joint.stiffness``, ``joints.stiffness_factor``, ``noise_floor_m``.
        unit: SI unit.
        value: maximum-likelihood value.
        std_error: delta-method standard error (value × se of log), None on the null space.
        ci95: (low, high) Wald 95 % interval in log space, None on the null space.
        identifiable: the data determine it (:mod:`.identifiability`); False: do not report it as known.
        hint: what to do when it is not identifiable, else "".
    """

    name: str
    unit: str
    value: float
    std_error: float | None
    ci95: tuple[float, float] | None
    identifiable: bool
    hint: str


@dataclass(frozen=True, eq=False)
class Calibration:
    """A fitted joint model.

    Attributes:
        nominal: the joint model as given to the fit (θ unpacks with it).
        model: the joint model with the fitted values written in.
        theta: (p,) fitted log parameters.
        parameters: one estimate per free parameter, in θ's order.
        log_likelihood: at the optimum.
        aic: 2p - 2·log L.
        information: (p, p) observed Fisher information in θ space.
        covariance: (p, p) its inverse off the null space (NaN on it).
        rank: rank of the information.
        condition_number: of the information (inf when singular).
        converged: the optimiser reported success.
        bounds: (p, 2) the box in θ the optimiser searched.
        rotation: (3, 3) fitted rotation R of the measuring frame relative to the world frame
            (measured points ``x = R·x_base + t``) when the frame was unknown; then
            ``information`` is θ's profile information (the rotation profiled out). None when
            the frame was registered.
    """

    nominal: JointModel
    model: JointModel
    theta: np.ndarray
    parameters: tuple[ParameterEstimate, ...]
    log_likelihood: float
    aic: float
    information: np.ndarray
    covariance: np.ndarray
    rank: int
    condition_number: float
    converged: bool
    bounds: np.ndarray
    rotation: np.ndarray | None = None


def starting_theta(model: JointModel, data: SeriesStack) -> np.ndarray:
    """θ from the moments of the data (module docstring); nominal values where they say nothing."""
    free_k, free_b = np.array(model.fit_stiffness), np.array(model.fit_backlash)
    # Per series and joint (s·σ_τ)²·J_i J_iᵀ (m, nv, 3, 3): Σ's coefficient of 1/k_i².
    outer = np.einsum("mai,mbi,mi->miab", data.jacobian, data.jacobian, (data.signs * data.torque_std) ** 2)
    identity = np.eye(3)
    dof = (data.cycles - 1).astype(float)
    weights = np.sqrt(dof)[:, None, None]
    fixed = np.einsum("miab,i->mab", outer[:, ~free_k], model.stiffness[~free_k] ** -2.0)
    if model.joint_noise is not None:
        fixed = fixed + np.einsum("mai,i,mbi->mab", data.jacobian, model.joint_noise ** 2, data.jacobian)
    if not model.fit_noise_floor:
        fixed = fixed + model.noise_floor_m ** 2 * identity
    sample = np.divide(data.scatter_m2, dof[:, None, None], out=np.zeros_like(data.scatter_m2),
                       where=dof[:, None, None] > 0)
    target = weights * (sample - fixed)
    if model.tied:
        columns = [np.einsum("miab,i->mab", outer[:, free_k], model.stiffness[free_k] ** -2.0)]
    else:
        columns = list(np.moveaxis(outer[:, free_k], 1, 0))
    if model.fit_noise_floor:
        columns.append(np.broadcast_to(identity, target.shape))
    theta = model.theta()
    n_k = 1 if model.tied else int(free_k.sum())
    if columns:
        design = np.stack([(weights * c).ravel() for c in columns], axis=1)
        scale = np.linalg.norm(design, axis=0)
        scale[scale == 0] = 1.0
        solution = nnls(design / scale, target.ravel())[0] / scale
        positive = solution > 0
        with np.errstate(divide="ignore"):
            moment = np.log(solution)
        moment[:n_k] *= -0.5
        moment[n_k:] *= 0.5
        indices = [*range(n_k)] + ([len(theta) - 1] if model.fit_noise_floor else [])
        nominal = theta[indices]
        theta[indices] = np.where(positive, np.clip(moment, nominal - LOG_SPAN, nominal + LOG_SPAN), nominal)
    if free_b.any():
        theta[n_k:n_k + int(free_b.sum())] = _backlash_start(model, model.unpack(theta)[0], data)
    return theta


def _backlash_start(model: JointModel, stiffness: np.ndarray, data: SeriesStack) -> np.ndarray:
    """Log backlash of the free joints from the barycentre differences, given the stiffness."""
    free_b = np.array(model.fit_backlash)
    first = data.first_of_pose
    rows = np.flatnonzero(first != np.arange(len(first)))
    lost = data.torque_mean / stiffness
    fallback = np.full(int(free_b.sum()), BACKLASH_FLOOR * np.abs(lost).max())
    if not len(rows):
        return np.log(np.where(model.backlash[free_b] > 0, model.backlash[free_b], fallback))
    sign_change = data.signs[rows] - data.signs[first[rows]]
    observed = data.mean_m[rows] - data.mean_m[first[rows]]
    fixed_backlash = np.where(free_b, 0.0, model.backlash)
    known = np.einsum("rai,ri->ra", data.jacobian[rows], sign_change * (lost[rows] + fixed_backlash / 2))
    design = np.einsum("rai,ri->rai", data.jacobian[rows][..., free_b], sign_change[:, free_b] / 2)
    cap = np.maximum(BACKLASH_CAP * np.abs(lost).max(), model.backlash[free_b])
    solution = lsq_linear(design.reshape(-1, free_b.sum()), (observed - known).ravel(), bounds=(0.0, cap)).x
    return np.log(np.maximum(solution, fallback))


def _invisible_joints(data: SeriesStack) -> np.ndarray:
    """(nv,) True for a joint that never moves the tool point on an approach at the measured poses."""
    reach = (np.abs(data.signs) * np.linalg.norm(data.jacobian, axis=1)).max(axis=0)
    return reach <= INVISIBLE_RTOL * reach.max()


def _parameter_joints(model: JointModel) -> list[np.ndarray]:
    """For each free parameter, the joints it acts on (empty for the noise floor)."""
    free_k, free_b = np.flatnonzero(model.fit_stiffness), np.flatnonzero(model.fit_backlash)
    stiff = [free_k] if model.tied else [np.array([i]) for i in free_k]
    noise = [np.array([], dtype=int)] if model.fit_noise_floor else []
    return stiff + [np.array([i]) for i in free_b] + noise


def _on_bound(theta: np.ndarray, bounds: np.ndarray) -> np.ndarray:
    """(p,) True where θ sits on the optimiser's box (within ``BOUND_ATOL``)."""
    return (np.isclose(theta, bounds[:, 0], rtol=0, atol=BOUND_ATOL)
            | np.isclose(theta, bounds[:, 1], rtol=0, atol=BOUND_ATOL))


def _polish(objective: Objective, theta: np.ndarray, information: np.ndarray, bounds: np.ndarray) -> np.ndarray:
    """Newton steps with the fixed information off its null space, the parameters on the box's edge held there,
    each halved (up to ``LINE_SEARCH_HALVINGS`` times) until it stays in bounds and does not raise -log L beyond
    its rounding: the optimum to the gradient's precision, not the line search's."""
    inside = ~_on_bound(theta, bounds)
    block = information[np.ix_(inside, inside)]
    step_matrix = np.linalg.pinv((block + block.T) / 2, hermitian=True, rtol=RANK_RTOL)
    value, gradient = objective(theta)
    for _ in range(NEWTON_STEPS):
        step = np.zeros_like(theta)
        step[inside] = -step_matrix @ gradient[inside]
        for halving in range(LINE_SEARCH_HALVINGS + 1):
            trial = theta + step / 2 ** halving
            if np.all(trial >= bounds[:, 0]) and np.all(trial <= bounds[:, 1]):
                trial_value, trial_gradient = objective(trial)
                if trial_value <= value + ROUNDING * abs(value):
                    break
        else:
            break
        theta, value, gradient = trial, trial_value, trial_gradient
    return theta


def _negative(log_likelihood_and_gradient_at: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]) -> Objective:
    """The objective of a function x -> (log L, its gradient)."""
    def objective(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        value, gradient = log_likelihood_and_gradient_at(x)
        return -value, -gradient
    return objective


def _registered_objective(model: JointModel, data: SeriesStack) -> Objective:
    """θ (p, ...) -> (-log L (...), its gradient (p, ...)) with the data in the world frame."""
    return _negative(partial(log_likelihood_and_gradient, model, data=data))


def _unknown_frame_objective(model: JointModel, data: SeriesStack, reference: Rotation) -> Objective:
    """(θ, δ) (p + 3, ...) -> (-log L (...), its gradient (p + 3, ...)), the frame ``reference·exp([δ]×)``."""
    return _negative(partial(unknown_frame_log_likelihood_and_gradient, model, data=data, reference=reference))


def _log_box(model: JointModel, start: np.ndarray, ranged: bool) -> np.ndarray:
    """(p, 2) the optimiser's box in θ around ``start``; if ``ranged``, within the model's ranges
    (:meth:`JointModel.theta_range`)."""
    box = np.stack([start - LOG_SPAN, start + LOG_SPAN], axis=1)
    return np.clip(box, *model.theta_range().T[:, :, None]) if ranged else box


def _start(model: JointModel, theta: np.ndarray, ranged: bool) -> np.ndarray:
    """A start ``theta``, within the model's ranges if ``ranged``."""
    return np.clip(theta, *model.theta_range().T) if ranged else theta


def _optimise(objective: Objective, start: np.ndarray, bounds: np.ndarray) -> OptimizeResult:
    """SLSQP with the analytic gradient in ``bounds`` from ``start``, to ``FTOL`` within ``MAX_ITERATIONS``."""
    return minimize(objective, start, method="SLSQP", jac=True, bounds=bounds,
                    options={"ftol": FTOL, "maxiter": MAX_ITERATIONS})


def _penalised(objective: Objective, centre: np.ndarray) -> Objective:
    """``objective`` (of x of shape (p, ...)) plus the weak prior ½·Σ((θ - centre)/``PRIOR_LOG_STD``)² on its first
    ``len(centre)`` entries (θ; a frame's rotation δ after them is not penalised)."""
    p = len(centre)

    def penalised(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        value, gradient = objective(x)
        offset = (x[:p] - centre.reshape((p,) + (1,) * (np.ndim(x) - 1))) / PRIOR_LOG_STD
        gradient = np.array(gradient, dtype=float)
        gradient[:p] += offset / PRIOR_LOG_STD
        return value + 0.5 * (offset ** 2).sum(axis=0), gradient
    return penalised


def _polished(objective: Objective, penalised: Objective, x: np.ndarray, bounds: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray]:
    """The optimiser's result polished by :func:`_polish` on the ``penalised`` objective, its step matrix from one
    central difference of the gradient (``POLISH_STEP_ORDER``: a Newton step needs the Hessian to a few per cent, and
    each step is kept only where it lowers -log L), and the observed information of the data (``objective``) there,
    to the adaptive differences' precision."""
    def gradient(of: Objective) -> Callable[[np.ndarray], np.ndarray]:
        return lambda at: of(at)[1]

    step_matrix = jacobian(gradient(penalised), x, initial_step=HESSIAN_STEP, order=POLISH_STEP_ORDER, maxiter=1).df
    x = _polish(penalised, x, step_matrix, bounds)
    return x, jacobian(gradient(objective), x, initial_step=HESSIAN_STEP).df


@dataclass(frozen=True, eq=False)
class _Optimum:
    """θ̂, θ's observed (profile) information, log L̂, convergence, the box in θ and the frame's rotation (or None)."""

    theta: np.ndarray
    information: np.ndarray
    log_likelihood: float
    converged: bool
    bounds: np.ndarray
    rotation: np.ndarray | None


def _fit_registered(model: JointModel, data: SeriesStack, ranged: bool) -> _Optimum:
    """Moment start, then the nominal model's when the optimiser does not converge (module docstring); within the
    model's ranges if ``ranged``."""
    objective = _registered_objective(model, data)
    start = _start(model, starting_theta(model, data), ranged)
    bounds = _log_box(model, start, ranged)
    penalised = _penalised(objective, start)
    nominal = np.clip(model.theta(), bounds[:, 0], bounds[:, 1])
    best = _optimise(penalised, start, bounds)
    if not best.success:
        best = min((best, _optimise(penalised, nominal, bounds)), key=lambda r: r.fun)
    theta, information = _polished(objective, penalised, best.x, bounds)
    return _Optimum(theta, information, -float(objective(theta)[0]), bool(best.success), bounds, None)


def _frame_starts(model: JointModel, data: SeriesStack) -> list[tuple[Rotation, np.ndarray]]:
    """The ``REFINED_STARTS`` most likely of the frame's candidate rotations, each with its moment θ
    (:func:`starting_theta` of the data turned to the world frame by it)."""
    rotations = candidate_rotations(model, data, FRAME_STARTS, FRAME_SEED)
    starts = []
    for i in range(len(rotations)):
        base = to_base(data, rotations[i].as_matrix())
        theta = starting_theta(model, base)
        starts.append((float(log_likelihood(model, theta, base)), rotations[i], theta))
    order = np.argsort([-value for value, _, _ in starts], kind="stable")[:REFINED_STARTS]
    return [starts[i][1:] for i in order]


def _fit_unknown_frame(model: JointModel, data: SeriesStack, ranged: bool) -> _Optimum:
    """θ and the frame's rotation jointly from the most likely starts (``SAME_OPTIMUM``); the optimum
    re-centred (δ = 0) before polishing; θ's profile information (:mod:`.frame`); within the model's ranges if
    ``ranged``."""
    runs = []
    for reference, theta in _frame_starts(model, data):
        theta = _start(model, theta, ranged)
        bounds = np.vstack([_log_box(model, theta, ranged), ROTATION_BOX])
        penalised = _penalised(_unknown_frame_objective(model, data, reference), theta)
        best = _optimise(penalised, np.append(theta, np.zeros(3)), bounds)
        runs.append((best, reference, bounds, theta))
    lowest = min(run[0].fun for run in runs)
    best, reference, bounds, centre = next(run for run in runs if run[0].fun <= lowest + SAME_OPTIMUM)
    reference = reference * Rotation.from_rotvec(best.x[-3:])
    objective = _unknown_frame_objective(model, data, reference)
    parameters, information = _polished(objective, _penalised(objective, centre),
                                        np.append(best.x[:-3], np.zeros(3)), bounds)
    rotation = (reference * Rotation.from_rotvec(parameters[-3:])).as_matrix()
    return _Optimum(parameters[:-3], profile_information(information), -float(objective(parameters)[0]),
                    bool(best.success), bounds[:-3], rotation)


def _spread_std_errors(model: JointModel, theta: np.ndarray, data: SeriesStack) -> np.ndarray:
    """(p,) standard error of log θ of each stiffness parameter and the noise floor from the series' spreads
    alone, inf for the backlashes: the expected Wishart information ``ν/2·tr(Σ⁻¹ ∂_aΣ Σ⁻¹ ∂_bΣ)`` summed over the
    series at θ (frame-free: it needs no measured point), analysed as the full information is."""
    stiffness, backlash, noise = model.unpack(theta)
    covariance, _ = predict_series(stiffness, backlash, noise, data.jacobian, data.signs, data.torque_mean,
                                   data.torque_std, model.joint_noise)
    variance = (data.signs * data.torque_std / stiffness) ** 2                       # (m, nv)
    per_joint = -2 * np.einsum("mai,mbi,mi->imab", data.jacobian, data.jacobian, variance)
    free_k = np.flatnonzero(model.fit_stiffness)
    derivatives = [per_joint[free_k].sum(axis=0)] if model.tied else list(per_joint[free_k])
    n_stiffness = len(derivatives)
    if model.fit_noise_floor:
        derivatives.append(np.broadcast_to(2 * noise ** 2 * np.eye(3), covariance.shape))
    if not derivatives:  # backlashes alone: the spreads say nothing of them
        return np.full(len(theta), np.inf)
    inverse = np.linalg.inv(covariance)
    scaled = [inverse @ d for d in derivatives]
    dof = (data.cycles - 1).astype(float)
    information = np.array([[np.sum(dof / 2 * np.einsum("mab,mba->m", a, b)) for b in scaled] for a in scaled])
    std_error = np.full(len(theta), np.inf)
    spread = analyse(information).std_error
    std_error[:n_stiffness] = spread[:n_stiffness]
    if model.fit_noise_floor:
        std_error[-1] = spread[-1]
    return std_error


def _lost_motion_confounded(model: JointModel, theta: np.ndarray, data: SeriesStack, identifiable: np.ndarray,
                            max_relative_std_error: float) -> np.ndarray:
    """(p,) True for parameters a barycentre cannot tell apart: the barycentres see a joint's τ̄/k + b/2 only, so
    where a joint's backlash is free its stiffness is known only if the spreads alone determine it
    (:func:`_spread_std_errors`), and its backlash only if its stiffness is known (or fixed)."""
    names = model.names()
    free_b = np.array(model.fit_backlash)
    spread_known = _spread_std_errors(model, theta, data) <= max_relative_std_error
    confounded = np.zeros(len(names), dtype=bool)
    stiffness_known = {}
    for i, joints in enumerate(_parameter_joints(model)):
        if names[i].endswith(("stiffness", "stiffness_factor")):
            confounded[i] = bool(free_b[joints].any()) and not spread_known[i]
            stiffness_known.update({j: identifiable[i] and not confounded[i] for j in joints})
    for i, joints in enumerate(_parameter_joints(model)):
        if names[i].endswith(".backlash") and model.fit_stiffness[joints[0]]:
            confounded[i] = not stiffness_known[joints[0]]
    return confounded


def _calibration(model: JointModel, data: SeriesStack, optimum: _Optimum, max_relative_std_error: float
                 ) -> Calibration:
    """The fit's report: estimates, standard errors and identifiability of an optimum."""
    theta, bounds = optimum.theta, optimum.bounds
    found = analyse(optimum.information, max_relative_std_error)
    invisible = _invisible_joints(data)
    at_range = _on_bound(theta, model.theta_range())
    identifiable = found.identifiable & ~_on_bound(theta, bounds)
    confounded = _lost_motion_confounded(model, theta, data, identifiable, max_relative_std_error)
    identifiable &= ~confounded
    estimates, values = [], model.value_range()
    for i, (name, unit, joints) in enumerate(zip(model.names(), model.units(), _parameter_joints(model), strict=True)):
        value, se = float(np.clip(np.exp(theta[i]), *values[i])), float(found.std_error[i])
        known = np.isfinite(se)
        unseen = bool(len(joints)) and bool(invisible[joints].all())
        why = "" if identifiable[i] else RANGE_HINT if at_range[i] else LOST_MOTION_HINT if confounded[i] and \
            not unseen else hint(name, unseen)
        estimates.append(ParameterEstimate(
            name=name, unit=unit, value=value, std_error=value * se if known else None,
            ci95=(value * float(np.exp(-Z95 * se)), value * float(np.exp(Z95 * se))) if known else None,
            identifiable=bool(identifiable[i]), hint=why))
    log_l = optimum.log_likelihood
    return Calibration(nominal=model, model=model.with_theta(theta), theta=theta, parameters=tuple(estimates),
                       log_likelihood=log_l, aic=2 * len(estimates) - 2 * log_l, information=optimum.information,
                       covariance=found.covariance, rank=found.rank, condition_number=found.condition_number,
                       converged=optimum.converged, bounds=bounds, rotation=optimum.rotation)


def fit(model: JointModel, poses: list[PoseData] | tuple[PoseData, ...] | SeriesStack,
        max_relative_std_error: float = MAX_RELATIVE_STD_ERROR, frame: str = "registered") -> Calibration:
    """Maximum-likelihood fit of ``model``'s free parameters to the measured series at ``poses``.

    Args:
        model: the joint model; its free parameters' values are the nominal second start.
        poses: measured poses (or their :func:`~tribokin.calibration.data.stack`).
        max_relative_std_error: largest standard error of log θ of an identifiable parameter.
        frame: ``"registered"``: points and Jacobians are in the same frame. ``"unknown"``: the
            points are in a measuring frame whose rotation relative to the Jacobians' (the base)
            is unknown; it is fitted with θ and profiled out of θ's uncertainty (:mod:`.frame`).

    Raises:
        ValueError: no free parameter, or an unknown ``frame``.
    """
    data = poses if isinstance(poses, SeriesStack) else stack(poses)
    if not model.names():
        raise ValueError("nothing to fit: free at least one parameter")
    if frame not in FRAMES:
        raise ValueError(f"frame must be one of {FRAMES}, not {frame!r}")
    search = _fit_registered if frame == "registered" else _fit_unknown_frame
    optimum = search(model, data, ranged=False)
    low, high = model.theta_range().T
    if np.any(optimum.theta < low) or np.any(optimum.theta > high):  # fitted again, within the ranges
        optimum = search(model, data, ranged=True)
    return _calibration(model, data, optimum, max_relative_std_error)


def _profile_problem(calibration: Calibration, data: SeriesStack) -> tuple[Objective, np.ndarray, np.ndarray]:
    """The objective a profile maximises over, its optimum and its box: θ's, or (θ, δ)'s with δ
    about the fitted rotation when the frame was unknown."""
    if calibration.rotation is None:
        return _registered_objective(calibration.nominal, data), calibration.theta, calibration.bounds
    objective = _unknown_frame_objective(calibration.nominal, data, Rotation.from_matrix(calibration.rotation))
    return objective, np.append(calibration.theta, np.zeros(3)), np.vstack([calibration.bounds, ROTATION_BOX])


def profile_interval(calibration: Calibration, poses: list[PoseData] | tuple[PoseData, ...] | SeriesStack,
                     name: str) -> tuple[float | None, float | None]:
    """95 % profile-likelihood interval of one free parameter [its unit].

    Each end is where 2·(log L̂ - max over the other parameters of log L) reaches χ²₁(0.95) = 3.84: the first
    crossing met stepping out from the optimum in θ to the Wald end, then twice as far each step, up to the box's edge
    (the whole way at once where θ has no standard error), then found by ``scipy.optimize.brentq`` (to 1e-6 in θ)
    on the signed root of that deviance, which is close to linear in θ. The other parameters, and the frame's rotation
    when it was unknown, are re-fitted by SLSQP from the optimum at each trial. None for an end the profile does not
    reach inside the box: the data do not bound the parameter on that side.
    """
    data = poses if isinstance(poses, SeriesStack) else stack(poses)
    i = calibration.nominal.names().index(name)
    objective, optimum, bounds = _profile_problem(calibration, data)
    others = np.arange(len(optimum)) != i
    threshold = chi2.ppf(0.95, 1) / 2

    @cache
    def excess(value: float) -> float:
        if not others.any():
            return float(objective(np.array([value]))[0]) + calibration.log_likelihood - threshold

        def restricted(rest: np.ndarray) -> tuple[float, np.ndarray]:
            negative, gradient = objective(np.insert(rest, i, value))
            return negative, gradient[others]
        best = _optimise(restricted, optimum[others], bounds[others])
        return best.fun + calibration.log_likelihood - threshold

    def signed_root(value: float) -> float:  # the same zero as excess; about linear in θ near the optimum
        return float(np.sqrt(2.0 * max(excess(value) + threshold, 0.0)) - np.sqrt(2.0 * threshold))

    variance = calibration.covariance[i, i]
    wald = Z95 * float(np.sqrt(variance)) if np.isfinite(variance) and variance > 0 else np.inf
    def end_towards(edge: float) -> float | None:
        theta = calibration.theta[i]
        inner, step, reach = theta, wald, abs(edge - theta)
        while True:
            outer = edge if step >= reach else theta + np.sign(edge - theta) * step
            if excess(outer) > 0:
                return float(np.exp(brentq(signed_root, inner, outer, xtol=1e-6)))
            if outer == edge:
                return None
            inner, step = outer, 2.0 * step

    low, high = calibration.bounds[i]
    return end_towards(low), end_towards(high)
