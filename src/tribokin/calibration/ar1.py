"""The friction's lag-one autocorrelation (the ``ar1`` key) per joint group, from measured series in time order.

**Model.** In the linear model (:mod:`.model`) a series' cycles deviate from their barycentre by
x_j − x̄ = J·diag(s)·(τ_j − τ̄)/k + noise_j. Along a unit axis e their signed deviations u_j = e·(x_j − x̄) [m]
are a sum of independent parts: each joint's friction, whose group g (the joints whose friction one study key gives)
is an AR(1) of lag-one correlation ρ_g over the cycles (μ's own ``ar1``, which τ = μ·N·r keeps at a fixed pose), and
the joint and instrument noise, independent between cycles. So u is Gaussian (a quasi-likelihood for other laws)
with covariance v·C(ρ),

    C(ρ) = Σ_g w_g·T(ρ_g) + (1 − Σ_g w_g)·I,   T(ρ)_jk = ρ^|j−k|,

w_g the share of u's variance that group g's joints give in the fitted model ((e·J_i)²·(s_i·σ_τ,i/k_i)² summed over
its joints, over eᵀΣe), v the series' own variance. Cycles next to each other in time order are one cycle apart.

**Estimator.** Restricted maximum likelihood (REML: each series' mean, its barycentre, integrated out, which removes
most of the maximum likelihood's downward bias of ρ in short series; Cheang & Reinsel 2000), summed over the series,
each with its own v profiled out:

    ℓ(ρ) = −½·Σ_m [(n_m − 1)·log(r_mᵀ·P_m·r_m) + log|C_m| + log(1ᵀ·C_m⁻¹·1)],

r_mᵀP_m r_m = uᵀC⁻¹u − (1ᵀC⁻¹u)²/(1ᵀC⁻¹1), maximised over ρ in [−``RHO_BOUND``, ``RHO_BOUND``] per group.
**Interval:** 95 % profile likelihood, the other groups' ρ re-maximised: where 2·(ℓ̂ − ℓ_p(ρ_g)) reaches χ²₁(0.95).
For one group and no noise its curvature is n/(1 − ρ²), Bartlett's variance that ``fit_ar1`` uses: the interval
allows for the autocorrelation. An end the profile does not reach within the bound is given as ±1.

**Which groups.** A group is estimated where a series of at least ``MIN_CYCLES`` cycles is dominated by its joints
(w_g ≥ ``DOMINANT``): that series' deviations are mostly its friction's. The other groups with a share somewhere stay
free in ℓ (so that their correlation is not pinned on the estimated ones), but are not reported. No series long
enough, or no group dominating one, is a reason instead of an estimate.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq, minimize, minimize_scalar
from scipy.stats import chi2

from tribokin.calibration.data import PoseData
from tribokin.calibration.model import JointModel
from tribokin.measurement.independence import MIN_CYCLES, deviations, main_axis, time_order
from tribokin.tribology.series_fit import Estimate

#: A group dominates a series whose deviations' variance it gives at least this share of.
DOMINANT = 0.5
#: The search's bound on each group's ρ (C stays invertible without noise).
RHO_BOUND = 0.99
#: Half the χ²₁ 95 % quantile: the profile's drop at an interval's end.
DROP = float(chi2.ppf(0.95, 1)) / 2
#: ``calibration.json``'s ``ar1.method``.
METHOD = ("restricted maximum likelihood of each joint group's AR(1) correlation from the series' signed deviations "
          "along their main axis in time order (each series' mean and variance profiled out; its covariance the "
          "groups' AR(1)s weighted by their shares in the fitted linear model, the rest independent noise); 95 % "
          "profile-likelihood intervals; a group is estimated where it gives at least "
          f"{DOMINANT:g} of the deviations' variance of a series of {MIN_CYCLES} or more cycles")


@dataclass(frozen=True, eq=False)
class TimedSeries:
    """A series' signed deviations in time order and each group's share of their variance.

    Attributes:
        deviations_m: (n,) deviations u_j [m], in time order.
        shares: (G,) each group's share w_g of their variance in the fitted model (the rest: independent noise).
    """

    deviations_m: np.ndarray
    shares: np.ndarray


@dataclass(frozen=True)
class GroupAr1:
    """One joint group's ``ar1`` as the measurements give it.

    Attributes:
        group: its study key (``joints.friction_torque_Nm``, ``joints.elbow_joint.friction_torque_Nm``, ...).
        joints: its joints.
        estimate: ρ̂ with its 95 % interval, or ``None`` (``reason`` says why).
        series: the series of ``MIN_CYCLES`` or more cycles it dominates.
        largest_share: its largest share of such a series' deviations' variance.
        reason: why there is no estimate ("" when there is one).
    """

    group: str
    joints: tuple[str, ...]
    estimate: Estimate | None
    series: int
    largest_share: float
    reason: str = ""


@dataclass(frozen=True)
class Ar1Fit:
    """Every group's ``ar1``, or why the measurements' time order allows none.

    Attributes:
        groups: per group its estimate or reason.
        series: the series of ``MIN_CYCLES`` or more cycles used.
        longest: the longest series' cycles.
        reason: why no group is estimated ("" when one is).
    """

    groups: tuple[GroupAr1, ...]
    series: int
    longest: int
    reason: str = ""


class _Bucket:
    """The series of one length, stacked: their deviations (m, n), shares (m, G) and the lag matrix |j − k|."""

    def __init__(self, series: list[TimedSeries]):
        u = np.array([s.deviations_m for s in series], dtype=float)
        u -= u.mean(axis=1, keepdims=True)  # ℓ is the same for u + c·1 (P·1 = 0): rᵀPr is then no cancellation
        self.u = u / np.sqrt(np.mean(u ** 2, axis=1, keepdims=True))  # and for c·u (v profiled out)
        self.shares = np.array([s.shares for s in series], dtype=float)
        n = self.u.shape[1]
        self.lags = np.abs(np.subtract.outer(np.arange(n), np.arange(n)))
        self.identity = np.eye(n)

    def log_likelihood(self, rho: np.ndarray) -> tuple[float, np.ndarray]:
        """Σ over the bucket's series of their restricted log-likelihood at ρ (G,), constants dropped, and its
        gradient (G,): with P = C⁻¹ − C⁻¹11ᵀC⁻¹/(1ᵀC⁻¹1), a = C⁻¹1 and D_g = ∂C/∂ρ_g,
        ∂ℓ/∂ρ_g = ½[(n − 1)·(Pu)ᵀD_g(Pu)/(uᵀPu) − tr(C⁻¹D_g) + aᵀD_g a/(1ᵀa)]."""
        lags = self.lags
        correlation = np.power.outer(rho, lags)  # (G, n, n)
        slope = lags * np.power.outer(rho, np.maximum(lags - 1, 0))  # ∂T/∂ρ, 0 on the diagonal
        noise = 1.0 - self.shares.sum(axis=1)
        c = np.einsum("mg,gjk->mjk", self.shares, correlation) + noise[:, None, None] * self.identity
        factor = np.linalg.cholesky(c)
        log_det = 2.0 * np.log(np.diagonal(factor, axis1=1, axis2=2)).sum(axis=1)
        inverse = np.linalg.inv(c)
        a = inverse.sum(axis=2)  # C⁻¹1
        one_a = a.sum(axis=1)
        c_u = np.einsum("mjk,mk->mj", inverse, self.u)
        p_u = c_u - a * (np.einsum("mj,mj->m", a, self.u) / one_a)[:, None]
        quadratic = np.einsum("mj,mj->m", self.u, p_u)
        n = self.u.shape[1]
        value = float(-0.5 * np.sum((n - 1) * np.log(quadratic) + log_det + np.log(one_a)))
        pdp = np.einsum("mj,gjk,mk->mg", p_u, slope, p_u)
        trace = np.einsum("mjk,gkj->mg", inverse, slope)
        ada = np.einsum("mj,gjk,mk->mg", a, slope, a)
        gradient = 0.5 * self.shares * ((n - 1) * pdp / quadratic[:, None] - trace + ada / one_a[:, None])
        return value, gradient.sum(axis=0)


def restricted_log_likelihood(rho: np.ndarray, series: list[TimedSeries]) -> tuple[float, np.ndarray]:
    """ℓ(ρ) of the module docstring, the series' restricted log-likelihood at the groups' ρ (G,), and its gradient."""
    parts = [bucket.log_likelihood(np.asarray(rho, dtype=float)) for bucket in _buckets(series)]
    return sum(v for v, _ in parts), sum(g for _, g in parts)


def _buckets(series: list[TimedSeries]) -> list[_Bucket]:
    lengths = sorted({len(s.deviations_m) for s in series})
    return [_Bucket([s for s in series if len(s.deviations_m) == n]) for n in lengths]


class _Problem:
    """−ℓ over the free groups' ρ (the others' shares kept, their ρ 0), minimised and profiled."""

    def __init__(self, series: list[TimedSeries], free: np.ndarray):
        self.buckets = _buckets(series)
        self.free = free

    def negative(self, rho_free: np.ndarray) -> tuple[float, np.ndarray]:
        """−ℓ and its gradient at the free groups' ρ."""
        rho = np.zeros(len(self.free))
        rho[self.free] = rho_free
        parts = [bucket.log_likelihood(rho) for bucket in self.buckets]
        return -sum(v for v, _ in parts), -sum(g for _, g in parts)[self.free]

    def start(self) -> np.ndarray:
        """The free groups' start: least squares of the series' lag-one autocorrelations on their shares (r₁ ≈
        Σ_g w_g·ρ_g), within ±0.9 (a start near ρ = ±1 may stay on that bound's side mode)."""
        r1 = np.concatenate([np.sum(b.u[:, 1:] * b.u[:, :-1], axis=1) / np.sum(b.u ** 2, axis=1)
                             for b in self.buckets])
        shares = np.concatenate([b.shares for b in self.buckets])[:, self.free]
        return np.clip(np.linalg.lstsq(shares, r1, rcond=None)[0], -0.9, 0.9)

    def maximise(self, start: np.ndarray, held: int | None = None, at: float = 0.0) -> tuple[np.ndarray, float]:
        """ρ̂ of the free groups and ℓ there, ``held`` (its index among them, if given) fixed ``at``."""
        others = np.arange(len(start)) != (-1 if held is None else held)

        def full(x: np.ndarray) -> np.ndarray:
            rho = np.array(start, dtype=float)
            rho[others] = x
            if held is not None:
                rho[held] = at
            return rho

        def objective(x: np.ndarray) -> tuple[float, np.ndarray]:
            value, gradient = self.negative(full(x))
            return value, gradient[others]
        if not others.any():
            return full(np.array([])), -self.negative(full(np.array([])))[0]
        if others.sum() == 1:  # a bounded scalar search: no gradient needed
            best = minimize_scalar(lambda x: objective(np.array([x]))[0], bounds=(-RHO_BOUND, RHO_BOUND),
                                   method="bounded", options={"xatol": 1e-7})
            return full(np.array([best.x])), -float(best.fun)
        best = minimize(objective, np.clip(start[others], -RHO_BOUND, RHO_BOUND), jac=True, method="L-BFGS-B",
                        bounds=[(-RHO_BOUND, RHO_BOUND)] * int(others.sum()), options={"ftol": 1e-13, "gtol": 1e-9})
        return full(best.x), -float(best.fun)

    def interval(self, rho_hat: np.ndarray, best: float, i: int) -> tuple[float, float]:
        """The 95 % profile interval of the free group ``i`` (its index among the free): each end by
        ``scipy.optimize.brentq`` (to 1e-6), ±1 where the profile stays above its drop up to the bound."""
        def excess(value: float) -> float:
            return best - self.maximise(rho_hat, held=i, at=value)[1] - DROP

        ends = []
        for edge in (-RHO_BOUND, RHO_BOUND):
            if excess(edge) < 0:
                ends.append(math.copysign(1.0, edge))
            else:
                ends.append(float(brentq(excess, rho_hat[i], edge, xtol=1e-6)))
        return ends[0], ends[1]


def fit_group_ar1(series: list[TimedSeries], groups: list[tuple[str, tuple[str, ...]]]) -> Ar1Fit:
    """Each group's ``ar1`` from ``series`` (module docstring); ``groups``: (study key, joints) in the shares' order.

    Series of fewer than :data:`MIN_CYCLES` cycles are not used; without one, or without a group dominating one, the
    fit's ``reason`` says so."""
    longest = max((len(s.deviations_m) for s in series), default=0)
    used = [s for s in series if len(s.deviations_m) >= MIN_CYCLES]
    if not used:
        return Ar1Fit(tuple(GroupAr1(g, joints, None, 0, 0.0, "no series long enough") for g, joints in groups),
                      0, longest, f"no series has {MIN_CYCLES} or more cycles in time order (the longest has "
                      f"{longest}): too short to tell one cycle's friction from the next's")
    shares = np.array([s.shares for s in used]).reshape(len(used), len(groups))
    largest = shares.max(axis=0, initial=0.0)
    dominated = (shares >= DOMINANT).sum(axis=0)
    if not dominated.any():
        reason = (f"no joint group gives {DOMINANT:g} or more of the deviations of a series of {MIN_CYCLES} or more "
                  f"cycles (largest share {largest.max(initial=0.0):.2f})")
        return Ar1Fit(tuple(_not_dominated(name, joints, share) for (name, joints), share in
                            zip(groups, largest, strict=True)), len(used), longest, reason)
    free = largest > 0
    problem = _Problem(used, free)
    rho_hat, best = problem.maximise(problem.start())
    index = np.cumsum(free) - 1
    fitted = []
    for g, (name, joints) in enumerate(groups):
        if not dominated[g]:
            fitted.append(_not_dominated(name, joints, largest[g]))
            continue
        low, high = problem.interval(rho_hat, best, int(index[g]))
        fitted.append(GroupAr1(name, joints, Estimate(float(rho_hat[index[g]]), low, high), int(dominated[g]),
                               float(largest[g])))
    return Ar1Fit(tuple(fitted), len(used), longest)


def _not_dominated(name: str, joints: tuple[str, ...], largest: float) -> GroupAr1:
    """A group that dominates no series long enough, and why it has no estimate."""
    return GroupAr1(name, joints, None, 0, float(largest),
                    f"its joints give at most {largest:.2f} of a series' deviations (at least {DOMINANT:g} needed in a "
                    f"series of {MIN_CYCLES} or more cycles): measure poses and directions where they move the tool "
                    "most")


def timed_series(model: JointModel, poses: list[PoseData] | tuple[PoseData, ...], group_of_joint: np.ndarray,
                 groups: int) -> list[TimedSeries]:
    """Every series of ``poses`` (points in the world frame of their Jacobians) as a :class:`TimedSeries`: its
    deviations along its cloud's main axis e in time order
    (:func:`~tribokin.measurement.independence.deviations`, as ``measure`` tests them), and each of the ``groups``
    groups' share of their variance by ``model`` (module docstring); ``group_of_joint``: (nv,) each joint's group,
    −1 for none."""
    timed = []
    grouped = group_of_joint >= 0
    for pose in poses:
        for series in pose.series:
            points = np.asarray(series.points_m)[time_order(len(series.points_m), series.times_s)]
            axis = main_axis(points)
            covariance, _ = model.predict(pose.jacobian, series.signs, pose.torque_mean, pose.torque_std)
            friction = (axis @ pose.jacobian * series.signs * pose.torque_std / model.stiffness) ** 2
            per_group = np.bincount(group_of_joint[grouped], weights=friction[grouped], minlength=groups)
            timed.append(TimedSeries(deviations(points), per_group / float(axis @ covariance @ axis)))
    return timed
