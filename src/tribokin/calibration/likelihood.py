"""Log-likelihood of measured clouds under the joint model, from within-pose information only.

Two independent parts, both Gaussian (the friction torque is taken as Gaussian with the friction
law's mean and standard deviation: a quasi-likelihood for other laws):

- **Spread.** The scatter matrix S of a series of n cycles about its own mean is Wishart with
  ν = n - 1 degrees of freedom and scale Σ(s). For ν < 3 S is singular and has no density; the
  term is then the density of ν orthonormal (Helmert) contrasts of the cycles,
  ``-(3ν/2)·log 2π - (ν/2)·log|Σ| - tr(Σ⁻¹S)/2``, which depends on Σ exactly as the Wishart does
  (0 for a one-cycle series: it enters through its barycentre only).
- **Barycentre differences.** At a pose with d directions, the barycentres are
  ``x̄_a ~ N(g + m(s_a), Σ_a/n_a)`` with g the pose's unknown absolute position (its geometric
  error, which friction does not explain). Only the d - 1 differences ``x̄_a - x̄_1`` are used;
  their joint Gaussian density (for d = 2: covariance Σ_a/n_a + Σ_b/n_b about m(s_a) - m(s_b)) is
  computed in the equivalent form (Harville 1974, REML)
  ``-(3(d-1)/2)·log 2π - ½Σ_a log|V_a| - ½ log|Σ_a V_a⁻¹| - ½Σ_a r_aᵀ V_a⁻¹ r_a``,
  V_a = Σ_a/n_a, r_a = x̄_a - m(s_a) - ĝ, ĝ the V⁻¹-weighted mean of x̄_a - m(s_a) (for these
  contrasts the usual constant ``log|KᵀK| - log|XᵀX|`` is 3·log d - 3·log d = 0).

Absolute barycentres never enter. Everything is vectorised over a batch of parameter vectors.
"""

from __future__ import annotations

import weakref
from functools import lru_cache

import numpy as np
from scipy.special import multigammaln

from tribokin.calibration.data import SeriesStack
from tribokin.calibration.model import JointModel, predict_series

LOG_2PI = np.log(2 * np.pi)
#: Per data set (series stack) its :func:`scatter_log_density`: a fit's objective is called thousands of times on the
#: same data.
_SCATTER_TERMS: weakref.WeakKeyDictionary[SeriesStack, np.ndarray] = weakref.WeakKeyDictionary()


def wishart_logpdf(scatter: np.ndarray, dof: np.ndarray, covariance: np.ndarray) -> np.ndarray:
    """Log density of (..., 3, 3) scatter matrices with ``dof`` degrees of freedom under Σ (broadcasting).

    The Wishart density for dof >= 3; the Helmert-contrast density (module docstring) below.
    """
    return _wishart_logpdf(scatter_log_density(scatter, dof), dof, np.linalg.inv(covariance), covariance, scatter)


def scatter_log_density(scatter: np.ndarray, dof: np.ndarray) -> np.ndarray:
    """The terms of :func:`wishart_logpdf` that do not depend on Σ (the data's alone: a fit computes them once)."""
    dof = np.asarray(dof, dtype=float)
    wishart = dof >= 3
    log_2, log_gamma, helmert = _dof_terms(dof.shape, dof.tobytes())
    with np.errstate(invalid="ignore", divide="ignore"):
        log_det_s = np.where(wishart, np.linalg.slogdet(scatter)[1], 0.0)
        return np.where(wishart, (dof - 4) / 2 * log_det_s - log_2 - log_gamma, helmert)


@lru_cache(maxsize=64)
def _dof_terms(shape: tuple[int, ...], dof: bytes) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The terms of :func:`scatter_log_density` that depend on the degrees of freedom alone (float64 ``dof`` as
    bytes): ``1.5·ν·log 2``, the multivariate gamma function's log, and the Helmert density's constant (a frame's
    turned scatter matrices are new data on every call; their series' ν are not)."""
    dof_array = np.frombuffer(dof).reshape(shape)
    return 1.5 * dof_array * np.log(2), multigammaln(np.maximum(dof_array, 3) / 2, 3), -1.5 * dof_array * LOG_2PI


def _wishart_logpdf(data: np.ndarray, dof: np.ndarray, inverse: np.ndarray, covariance: np.ndarray,
                    scatter: np.ndarray) -> np.ndarray:
    """:func:`wishart_logpdf` from its data terms (:func:`scatter_log_density`) and Σ⁻¹."""
    log_det = np.linalg.slogdet(covariance)[1]
    quadratic = np.einsum("...ab,...ba->...", inverse, scatter)
    return data - np.asarray(dof, dtype=float) / 2 * log_det - quadratic / 2


def difference_loglik(means: np.ndarray, shifts: np.ndarray, variances: np.ndarray, pose_matrix: np.ndarray
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Log density of the within-pose differences of barycentres (module docstring), and its derivatives.

    Args:
        means: (m, 3) measured barycentres [m].
        shifts: (..., m, 3) predicted shifts m(s) [m].
        variances: (..., m, 3, 3) covariances of the barycentres V = Σ/n [m²].
        pose_matrix: (n_poses, m) series-to-pose indicator.

    Returns:
        (..., n_poses) log density per pose (0 for a pose with one series); (..., m, 3) its
        derivative with respect to the shifts, ``V⁻¹·r``; (..., m, 3, 3) its derivative with respect
        to V, ``½(V⁻¹ r rᵀ V⁻¹ - V⁻¹ + V⁻¹ A⁻¹ V⁻¹)`` with A = Σ_a V_a⁻¹ of the series' pose.
    """
    weights = np.linalg.inv(variances)
    residual = means - shifts
    information = np.einsum("pm,...mab->...pab", pose_matrix, weights)
    inverse_information = np.linalg.inv(information)
    weighted = np.einsum("pm,...mab,...mb->...pa", pose_matrix, weights, residual)
    offset = np.einsum("...pab,...pb->...pa", inverse_information, weighted)
    centred = residual - np.einsum("pm,...pa->...ma", pose_matrix, offset)
    d_shift = np.einsum("...mab,...mb->...ma", weights, centred)
    quadratic = np.einsum("...ma,...ma->...m", centred, d_shift)
    log_det = np.linalg.slogdet(variances)[1]
    directions = pose_matrix.sum(axis=1)
    value = (-0.5 * (quadratic + log_det) @ pose_matrix.T - 0.5 * np.linalg.slogdet(information)[1]
             - 1.5 * (directions - 1) * LOG_2PI)
    spread_back = weights @ np.einsum("pm,...pab->...mab", pose_matrix, inverse_information) @ weights
    d_variance = 0.5 * (d_shift[..., :, None] * d_shift[..., None, :] - weights + spread_back)
    return value, d_shift, d_variance


def _scatter_terms(data: SeriesStack) -> np.ndarray:
    """(..., m) :func:`scatter_log_density` of the data's series, computed once per data set."""
    terms = _SCATTER_TERMS.get(data)
    if terms is None:
        terms = _SCATTER_TERMS[data] = scatter_log_density(data.scatter_m2, data.cycles - 1)
    return terms


def log_likelihood(model: JointModel, theta: np.ndarray, data: SeriesStack) -> np.ndarray:
    """Log-likelihood of the stacked series at θ of shape (p, ...) → (...)."""
    return log_likelihood_and_gradient(model, theta, data)[0]


def log_likelihood_and_gradient(model: JointModel, theta: np.ndarray, data: SeriesStack
                                ) -> tuple[np.ndarray, np.ndarray]:
    """Log-likelihood (...) and its gradient with respect to θ (p, ...) at θ of shape (p, ...).

    The gradient is analytic: ∂/∂Σ of the spread term is ``½(Σ⁻¹SΣ⁻¹ - νΣ⁻¹)``; the difference
    term's derivatives come from :func:`difference_loglik`; then the chain rule through
    :func:`~tribokin.calibration.model.predict_series` and the log parametrisation.
    """
    return log_likelihood_and_data_derivatives(model, theta, data)[:2]


def log_likelihood_and_data_derivatives(model: JointModel, theta: np.ndarray, data: SeriesStack
                                        ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """:func:`log_likelihood_and_gradient` and the derivatives with respect to the data.

    ``data.scatter_m2`` and ``data.mean_m`` may carry the batch dimensions of θ before their own
    ((..., m, 3, 3), (..., m, 3)): one data set per parameter vector.

    Returns:
        ``(log L (...), ∂/∂θ (p, ...), ∂/∂S (..., m, 3, 3), ∂/∂x̄ (..., m, 3))``. ∂/∂S is that of
        the terms ``-tr(Σ⁻¹S)/2``, i.e. ``-Σ⁻¹/2``: the Wishart's ``(ν-4)/2·log|S|`` is left out
        (it depends on S only through its eigenvalues, which a rotation of the frame keeps);
        ∂/∂x̄ is minus the derivative with respect to the shifts (:func:`difference_loglik`).
    """
    stiffness, backlash, noise = model.unpack(theta)
    k, b = stiffness[..., None, :], backlash[..., None, :]
    covariance, shift = predict_series(k, b, noise[..., None], data.jacobian, data.signs, data.torque_mean,
                                       data.torque_std, model.joint_noise)
    dof = data.cycles - 1
    inverse = np.linalg.inv(covariance)
    spread = _wishart_logpdf(_scatter_terms(data), dof, inverse, covariance, data.scatter_m2).sum(axis=-1)
    n = data.cycles[:, None, None]
    differences, d_shift, d_variance = difference_loglik(data.mean_m, shift, covariance / n, data.pose_matrix)
    d_covariance = 0.5 * (inverse @ data.scatter_m2 @ inverse - dof[:, None, None] * inverse) + d_variance / n
    # Σ = Σ_i v_i J_i J_iᵀ + σ_n² I, v_i = (s σ_τ / k_i)² (+ σ_q²); m = Σ_i J_i s_i (τ̄_i / k_i + b_i / 2).
    d_v = np.einsum("mai,...mab,mbi->...mi", data.jacobian, d_covariance, data.jacobian)
    d_m = np.einsum("mai,...ma->...mi", data.jacobian, d_shift) * data.signs
    d_log_k = (-2 * d_v * (data.signs * data.torque_std / k) ** 2 - d_m * data.torque_mean / k).sum(axis=-2)
    d_log_b = (d_m * b / 2).sum(axis=-2)
    d_log_noise = 2 * noise ** 2 * np.trace(d_covariance, axis1=-2, axis2=-1).sum(axis=-1)
    return (spread + differences.sum(axis=-1), model.gradient(d_log_k, d_log_b, d_log_noise), -0.5 * inverse,
            -d_shift)
