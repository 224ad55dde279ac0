"""Maximum-likelihood fit of the joint model to measured clouds, with honest uncertainty.

- **Start.** Moments: each series' S/ν is linear in 1/k² and σ_n² (non-negative least squares,
  ``scipy.optimize.nnls``), then the barycentre differences are linear in the backlash (least
  squares, within ``BACKLASH_FLOOR`` and ``BACKLASH_CAP`` times the largest lost motion τ̄/k). Parameters the
  moments leave at zero start at their nominal values, the others within ×/÷ 1000 of them (a joint that hardly
  moves the tool point would otherwise start anywhere). When the optimiser does not converge from
  there, it starts again from the nominal model and the better optimum is kept.
- **Optimum.** ``scipy.optimize.minimize`` with SLSQP and the analytic gradient in θ = log space,
  bounded to ``LOG_SPAN`` (natural log) around the moment start, then polished by Newton steps
  with the information below. (L-BFGS-B reaches the same optima but, with scipy 1.17's
  multi-threaded OpenBLAS on a busy machine, spent 15× longer per fit here.)
- **Uncertainty.** Observed Fisher information = Hessian of the negative log-likelihood at the
  optimum: the Jacobian of its analytic gradient by ``scipy.differentiate.jacobian`` (adaptive
  central differences with Richardson extrapolation), symmetrised. Standard errors, null space and
  identifiability: :mod:`.identifiability`.
  Intervals are Wald intervals in log space, ``exp(θ̂ ± 1.96·se)``: asymmetric in linear space;
  :func:`profile_interval` gives a parameter's profile-likelihood interval instead.
  A parameter that ends on a bound of the box is not at a maximum of the likelihood: it is named
  not identifiable whatever its standard error.
- AIC = 2p - 2·log L with p the number of free parameters.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
from scipy.differentiate import jacobian
from scipy.optimize import brentq, lsq_linear, minimize, nnls
from scipy.stats import chi2

from tribokin.calibration.data import PoseData, SeriesStack, stack
from tribokin.calibration.identifiability import MAX_RELATIVE_STD_ERROR, RANK_RTOL, analyse, hint
from tribokin.calibration.likelihood import log_likelihood_and_gradient
from tribokin.calibration.model import JointModel

#: Half width of the optimiser's box around the moment start, in natural log (×/÷ 1000).
LOG_SPAN = float(np.log(1e3))
#: A θ this close to the box's edge [natural log] is on a bound.
BOUND_ATOL = 1e-6
#: A relative standard error above this (a factor e either way at one standard error) is a flat likelihood.
FLAT_STD_ERROR = 1.0
#: The relative standard errors above which :func:`fit_determined` holds parameters, round by round.
FLAT_STEPS = (10.0, FLAT_STD_ERROR, FLAT_STD_ERROR)
#: Backlash starting value where the moments give none: this fraction of the largest τ̄/k.
BACKLASH_FLOOR = 1e-2
#: A relative standard error above this (a factor e either way at one standard error) is a flat likelihood.
FLAT_STD_ERROR = 1.0
#: The relative standard errors above which :func:`fit_determined` holds parameters, round by round.
FLAT_STEPS = (10.0, FLAT_STD_ERROR, FLAT_STD_ERROR)
#: Backlash starting value at most this multiple of the largest τ̄/k (or the study's value, if larger): a joint
#: that hardly moves the tool would otherwise take any value the least squares like.
BACKLASH_CAP = 100.0
#: A joint is invisible when its largest |s|·|J column| is below this fraction of the largest joint's.
INVISIBLE_RTOL = 1e-9
#: SLSQP stops when -log L falls by less than this between iterations.
FTOL = 1e-10
#: First step of the Hessian's finite differences in θ (natural log).
HESSIAN_STEP = 0.05
#: Newton steps polishing the optimiser's result, and how often each may be halved.
NEWTON_STEPS = 20
LINE_SEARCH_HALVINGS = 20
#: Relative rounding of -log L that a polishing step may raise it by.
ROUNDING = 1e-12
Z95 = 1.959963984540054


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
    first = np.array([np.flatnonzero(data.pose_index == p)[0] for p in data.pose_index])
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


def _polish(objective: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]], theta: np.ndarray,
            information: np.ndarray, bounds: np.ndarray) -> np.ndarray:
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


def _negative_log_likelihood(model: JointModel, data: SeriesStack
                             ) -> Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]:
    """θ (p, ...) -> (-log L (...), its gradient (p, ...))."""
    def objective(theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        value, gradient = log_likelihood_and_gradient(model, theta, data)
        return -value, -gradient
    return objective


def fit(model: JointModel, poses: list[PoseData] | tuple[PoseData, ...] | SeriesStack,
        max_relative_std_error: float = MAX_RELATIVE_STD_ERROR) -> Calibration:
    """Maximum-likelihood fit of ``model``'s free parameters to the measured series at ``poses``.

    Args:
        model: the joint model; its free parameters' values are the nominal second start.
        poses: measured poses (or their :func:`~tribokin.calibration.data.stack`).
        max_relative_std_error: largest standard error of log θ of an identifiable parameter.

    Raises:
        ValueError: no free parameter.
    """
    data = poses if isinstance(poses, SeriesStack) else stack(poses)
    names = model.names()
    if not names:
        raise ValueError("nothing to fit: free at least one parameter")

    objective = _negative_log_likelihood(model, data)

    def gradient(theta: np.ndarray) -> np.ndarray:
        return objective(theta)[1]

    start = starting_theta(model, data)
    bounds = np.stack([start - LOG_SPAN, start + LOG_SPAN], axis=1)
    nominal = np.clip(model.theta(), bounds[:, 0], bounds[:, 1])
    best = minimize(objective, start, method="SLSQP", jac=True, bounds=bounds, options={"ftol": FTOL})
    if not best.success:
        second = minimize(objective, nominal, method="SLSQP", jac=True, bounds=bounds, options={"ftol": FTOL})
        best = min((best, second), key=lambda r: r.fun)
    theta = _polish(objective, best.x, jacobian(gradient, best.x, initial_step=HESSIAN_STEP).df, bounds)
    information = jacobian(gradient, theta, initial_step=HESSIAN_STEP).df
    found = analyse(information, max_relative_std_error)
    invisible = _invisible_joints(data)
    identifiable = found.identifiable & ~_on_bound(theta, bounds)
    estimates = []
    for i, (name, unit, joints) in enumerate(zip(names, model.units(), _parameter_joints(model))):
        value, se = float(np.exp(theta[i])), float(found.std_error[i])
        known = np.isfinite(se)
        estimates.append(ParameterEstimate(
            name=name, unit=unit, value=value, std_error=value * se if known else None,
            ci95=(value * float(np.exp(-Z95 * se)), value * float(np.exp(Z95 * se))) if known else None,
            identifiable=bool(identifiable[i]),
            hint="" if identifiable[i] else hint(name, bool(len(joints)) and bool(invisible[joints].all()))))
    log_l = -float(objective(theta)[0])
    return Calibration(nominal=model, model=model.with_theta(theta), theta=theta, parameters=tuple(estimates),
                       log_likelihood=log_l, aic=2 * len(names) - 2 * log_l, information=information,
                       covariance=found.covariance, rank=found.rank, condition_number=found.condition_number,
                       converged=bool(best.success), bounds=bounds)


def held_where_flat(calibration: Calibration, flat_std_error: float = FLAT_STD_ERROR) -> JointModel | None:
    """The fit's nominal model with the parameters along which its likelihood is flat no longer free (held at the
    nominal values): on the information's null space, on the optimiser's box, or with a relative standard error
    above ``flat_std_error``. None when there are none, or nothing else is left free."""
    model = calibration.nominal
    on_bound = _on_bound(calibration.theta, calibration.bounds)
    unknown = {e.name for e, edge in zip(calibration.parameters, on_bound)
               if edge or e.std_error is None or e.std_error > flat_std_error * e.value}
    if not unknown or len(unknown) == len(calibration.parameters):
        return None
    stiffness = tuple(free and "joints.stiffness_factor" not in unknown if model.tied else
                      free and f"joints.{name}.stiffness" not in unknown
                      for name, free in zip(model.joint_names, model.fit_stiffness))
    backlash = tuple(free and f"joints.{name}.backlash" not in unknown
                     for name, free in zip(model.joint_names, model.fit_backlash))
    return replace(model, fit_stiffness=stiffness, fit_backlash=backlash,
                   fit_noise_floor=model.fit_noise_floor and "noise_floor_m" not in unknown)


def fit_determined(model: JointModel, poses: list[PoseData] | tuple[PoseData, ...] | SeriesStack
                   ) -> tuple[Calibration, Calibration]:
    """Fit all free parameters, then again with those along which the likelihood is flat held at ``model``'s values
    (:func:`held_where_flat`): first the flattest (``FLAT_STEPS[0]``), whose wandering along their flat directions
    also moves the others' standard errors, then the rest.

    Along a flat direction a fit's optimum is found only to the optimiser's tolerance, and the other parameters
    move with it; the refit has a unique optimum. Its values, standard errors and intervals are conditional on the
    held values, which change its predictions by little (the likelihood is flat along them).

    Returns:
        the first fit (which parameters are identifiable, and hints) and the last (the values to report).
    """
    data = poses if isinstance(poses, SeriesStack) else stack(poses)
    first = last = fit(model, data)
    for flat in FLAT_STEPS:
        held = held_where_flat(last, flat)
        if held is not None:
            last = fit(held, data)
    return first, last


def profile_interval(calibration: Calibration, poses: list[PoseData] | tuple[PoseData, ...] | SeriesStack,
                     name: str) -> tuple[float | None, float | None]:
    """95 % profile-likelihood interval of one free parameter [its unit].

    Each end is where 2·(log L̂ - max over the other parameters of log L) reaches χ²₁(0.95) = 3.84,
    found by ``scipy.optimize.brentq`` in θ between the optimum and the box's edge (the other
    parameters re-fitted by SLSQP at each trial). None for an end the profile does not reach inside
    the box: the data do not bound the parameter on that side.
    """
    data = poses if isinstance(poses, SeriesStack) else stack(poses)
    i = calibration.nominal.names().index(name)
    objective = _negative_log_likelihood(calibration.nominal, data)
    others = np.arange(len(calibration.theta)) != i
    threshold = chi2.ppf(0.95, 1) / 2

    def excess(value: float) -> float:
        if not others.any():
            return float(objective(np.array([value]))[0]) + calibration.log_likelihood - threshold

        def restricted(rest: np.ndarray) -> tuple[float, np.ndarray]:
            theta = np.insert(rest, i, value)
            negative, gradient = objective(theta)
            return negative, gradient[others]
        best = minimize(restricted, calibration.theta[others], method="SLSQP", jac=True,
                        bounds=calibration.bounds[others], options={"ftol": FTOL})
        return best.fun + calibration.log_likelihood - threshold

    ends = []
    for edge in calibration.bounds[i]:
        ends.append(float(np.exp(brentq(excess, calibration.theta[i], edge, xtol=1e-6))) if excess(edge) > 0
                    else None)
    return ends[0], ends[1]
