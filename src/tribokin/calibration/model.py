"""The joint model's parameters, which of them a fit frees, and what they predict at one pose.

Per joint i, cycle j and approach sign s_ij (docs/concepts.md, "The joint model"):
``dq_ij = offset_i + s_ij·(τ_ij/k_i + b_i/2) + noise_ij``, τ_ij the friction torque (force) with
mean τ̄_i and standard deviation σ_τ,i at the pose. To first order the tool point moves by J·dq, and
the instrument adds isotropic noise of standard deviation σ_n, so a unidirectional series has

- covariance ``Σ(s) = J·diag(s²·σ_τ²/k² + σ_q²)·Jᵀ + σ_n²·I`` (σ_q the optional joint noise; s² = 1
  for a joint that moves, 0 for one that does not),
- barycentre ``x0 + J·offset + m(s)`` with ``m(s) = J·diag(s)·(τ̄/k + b/2)``.

Free parameters are fitted on a log scale (they are positive): θ = log of each free stiffness (or of
one common factor of the fitted joints' stiffnesses under ``tie = "all"``), of each free backlash,
and of the noise floor, in that order. A fit holds each within the :class:`ParameterRanges` of the model (a study's
ranges), so that what it finds is a value the study accepts.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np

TIES = ("none", "all")


def predict_series(stiffness: np.ndarray, backlash: np.ndarray, noise_floor_m: np.ndarray | float,
                   jacobian: np.ndarray, signs: np.ndarray, torque_mean: np.ndarray, torque_std: np.ndarray,
                   joint_noise: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Predicted covariance and barycentre shift of unidirectional series (broadcasting).

    Args:
        stiffness: (..., nv) k [N·m/rad | N/m].
        backlash: (..., nv) b [rad | m].
        noise_floor_m: (...) σ_n [m].
        jacobian: (..., 3, nv) J [m/rad | m/m].
        signs: (..., nv) approach signs s.
        torque_mean: (..., nv) τ̄ [N·m | N].
        torque_std: (..., nv) σ_τ [N·m | N].
        joint_noise: (..., nv) σ_q [rad | m], or None.

    Returns:
        ``(Σ, m)``: (..., 3, 3) covariance [m²] and (..., 3) shift m(s) [m].
    """
    variance = (signs * torque_std / stiffness) ** 2
    if joint_noise is not None:
        variance = variance + joint_noise ** 2
    noise = np.asarray(noise_floor_m, dtype=float)[..., None, None]
    covariance = np.einsum("...ai,...i,...bi->...ab", jacobian, variance, jacobian) + noise ** 2 * np.eye(3)
    shift = np.einsum("...ai,...i->...a", jacobian, signs * (torque_mean / stiffness + backlash / 2))
    return covariance, shift


@dataclass(frozen=True)
class ParameterRanges:
    """The lowest and highest values a fit may give: a joint's stiffness [N·m/rad | N/m], its backlash [rad | m] and
    the noise floor [m] (a study's ranges; unbounded by default)."""

    stiffness: tuple[float, float] = (0.0, math.inf)
    backlash: tuple[float, float] = (0.0, math.inf)
    noise_floor_m: tuple[float, float] = (0.0, math.inf)


@dataclass(frozen=True, eq=False)
class JointModel:
    """Joint stiffness, backlash and instrument noise, and which of them are free.

    Values of parameters that are not free are used as they are; values of free ones are the
    nominal values (the study's), replaced by :meth:`with_theta`.

    Attributes:
        joint_names: (nv,) names.
        stiffness: (nv,) k > 0 [N·m/rad, or N/m for a prismatic joint].
        backlash: (nv,) b >= 0 [rad | m].
        noise_floor_m: σ_n > 0 [m].
        fit_stiffness: (nv,) True where k is free.
        fit_backlash: (nv,) True where b is free.
        fit_noise_floor: True when σ_n is free.
        tie: ``"none"`` (one k per free joint) or ``"all"`` (k_i = c·k_i,nominal, one factor c for
            the joints whose stiffness is free).
        prismatic: (nv,) True for a prismatic joint (units only).
        joint_noise: (nv,) known joint noise σ_q [rad | m], or None.
        ranges: the values the free parameters may take (:meth:`value_range`).
    """

    joint_names: tuple[str, ...]
    stiffness: np.ndarray
    backlash: np.ndarray
    noise_floor_m: float
    fit_stiffness: tuple[bool, ...]
    fit_backlash: tuple[bool, ...]
    fit_noise_floor: bool
    tie: str = "none"
    prismatic: tuple[bool, ...] | None = None
    joint_noise: np.ndarray | None = None
    ranges: ParameterRanges = field(default_factory=ParameterRanges)

    def __post_init__(self) -> None:
        nv = len(self.joint_names)
        object.__setattr__(self, "stiffness", np.asarray(self.stiffness, dtype=float))
        object.__setattr__(self, "backlash", np.asarray(self.backlash, dtype=float))
        object.__setattr__(self, "prismatic", tuple(self.prismatic or (False,) * nv))
        if self.tie not in TIES:
            raise ValueError(f"tie must be one of {TIES}, not {self.tie!r}")
        shapes = (self.stiffness.shape, self.backlash.shape, (len(self.fit_stiffness),),
                  (len(self.fit_backlash),), (len(self.prismatic),))
        if any(shape != (nv,) for shape in shapes):
            raise ValueError(f"stiffness, backlash and the fit flags must have one entry per joint ({nv})")
        if np.any(self.stiffness <= 0) or np.any(self.backlash < 0) or not self.noise_floor_m > 0:
            raise ValueError("stiffness and the noise floor must be positive, backlash not negative")

    @cached_property
    def _free(self) -> tuple[np.ndarray, np.ndarray]:
        """(nv,) masks of the free stiffnesses and backlashes (a fit's objective unpacks θ thousands of times)."""
        return np.array(self.fit_stiffness, dtype=bool), np.array(self.fit_backlash, dtype=bool)

    @property
    def tied(self) -> bool:
        """One common stiffness factor for the free joints."""
        return self.tie == "all" and any(self.fit_stiffness)

    def names(self) -> tuple[str, ...]:
        """Names of the free parameters, in θ's order (``joints.<joint>.stiffness``, ...)."""
        stiff = ["joints.stiffness_factor"] if self.tied else [
            f"joints.{n}.stiffness" for n, f in zip(self.joint_names, self.fit_stiffness, strict=True) if f]
        back = [f"joints.{n}.backlash" for n, f in zip(self.joint_names, self.fit_backlash, strict=True) if f]
        return tuple(stiff + back + (["noise_floor_m"] if self.fit_noise_floor else []))

    def units(self) -> tuple[str, ...]:
        """Units of the free parameters, in θ's order."""
        stiff = ["1"] if self.tied else [
            "N/m" if p else "N·m/rad" for p, f in zip(self.prismatic, self.fit_stiffness, strict=True) if f]
        back = ["m" if p else "rad" for p, f in zip(self.prismatic, self.fit_backlash, strict=True) if f]
        return tuple(stiff + back + (["m"] if self.fit_noise_floor else []))

    def theta(self) -> np.ndarray:
        """θ of the model's own values (a tied factor is 1); -inf for a free backlash of 0."""
        stiff = [0.0] if self.tied else np.log(self.stiffness[list(self.fit_stiffness)])
        with np.errstate(divide="ignore"):
            back = np.log(self.backlash[list(self.fit_backlash)])
        noise = [np.log(self.noise_floor_m)] if self.fit_noise_floor else []
        return np.concatenate([stiff, back, noise])

    def value_range(self) -> np.ndarray:
        """(p, 2) the lowest and highest value of each free parameter, in θ's order, that :attr:`ranges` allow (a tied
        factor's: the factor that keeps every free joint's stiffness within them)."""
        free_k = np.array(self.fit_stiffness)
        if self.tied:
            low, high = self.ranges.stiffness
            stiff = [(float(np.max(low / self.stiffness[free_k])), float(np.min(high / self.stiffness[free_k])))]
        else:
            stiff = [self.ranges.stiffness] * int(free_k.sum())
        back = [self.ranges.backlash] * int(np.sum(self.fit_backlash))
        noise = [self.ranges.noise_floor_m] if self.fit_noise_floor else []
        return np.array(stiff + back + noise, dtype=float).reshape(-1, 2)

    def theta_range(self) -> np.ndarray:
        """(p, 2) :meth:`value_range` in θ (natural log; -inf for a range from 0)."""
        with np.errstate(divide="ignore"):
            return np.log(self.value_range())

    def unpack(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Stiffness (..., nv), backlash (..., nv) and noise floor (...) of θ of shape (p, ...)."""
        theta = np.asarray(theta, dtype=float)
        batch = theta.shape[1:]
        free_k, free_b = self._free
        n_k = 1 if self.tied else int(free_k.sum())
        n_b = int(free_b.sum())
        values = np.exp(np.moveaxis(theta, 0, -1))
        stiffness = np.broadcast_to(self.stiffness, batch + self.stiffness.shape).copy()
        if self.tied:
            stiffness[..., free_k] = self.stiffness[free_k] * values[..., :1]
        else:
            stiffness[..., free_k] = values[..., :n_k]
        backlash = np.broadcast_to(self.backlash, batch + self.backlash.shape).copy()
        backlash[..., free_b] = values[..., n_k:n_k + n_b]
        noise = values[..., -1] if self.fit_noise_floor else np.full(batch, self.noise_floor_m)
        return stiffness, backlash, noise

    def predict(self, jacobian: np.ndarray, signs: np.ndarray, torque_mean: np.ndarray, torque_std: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray]:
        """``(Σ, m(s))`` of a series at one pose with the model's own values (:func:`predict_series`)."""
        return predict_series(self.stiffness, self.backlash, self.noise_floor_m, jacobian, signs, torque_mean,
                              torque_std, self.joint_noise)

    def gradient(self, d_log_stiffness: np.ndarray, d_log_backlash: np.ndarray, d_log_noise: np.ndarray
                 ) -> np.ndarray:
        """(p, ...) derivative with respect to θ of derivatives with respect to every joint's log k
        (..., nv), log b (..., nv) and log σ_n (...)."""
        free_k, free_b = self._free
        stiff = d_log_stiffness[..., free_k]
        if self.tied:
            stiff = stiff.sum(axis=-1, keepdims=True)
        noise = [d_log_noise[..., None]] if self.fit_noise_floor else []
        return np.moveaxis(np.concatenate([stiff, d_log_backlash[..., free_b], *noise], axis=-1), -1, 0)

    def with_theta(self, theta: np.ndarray) -> JointModel:
        """The model with the values of θ written in (a tied factor applied to the nominal stiffness), within its
        ranges."""
        stiffness, backlash, noise = self.unpack(np.asarray(theta, dtype=float))
        # exp(log(x)) may lie an ulp beyond a range's end x
        return replace(self, stiffness=np.clip(stiffness, *self.ranges.stiffness),
                       backlash=np.clip(backlash, *self.ranges.backlash),
                       noise_floor_m=float(np.clip(noise, *self.ranges.noise_floor_m)))
