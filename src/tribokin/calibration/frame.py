"""An unregistered measuring frame: its rotation as a nuisance parameter of the likelihood.

**Convention.** Points measured in another frame (a laser tracker's) are ``x = R·x_base + t``: R
(3 × 3) is the rotation of the measuring frame relative to the world frame, the same for every
series (the instrument did not move), t any translation. In the world frame a series' scatter is
``RᵀSR`` and its barycentre ``Rᵀ(x̄ - c)``, c the mean barycentre of its pose: t never matters,
since only covariances and within-pose differences of barycentres enter the likelihood, and
centring each pose keeps the barycentres' rounding at the scale of their differences (the
rotation's gradient sums terms of the barycentres' size that cancel across a pose).

**Parametrisation.** ``R = R0·exp([δ]×)``, δ ∈ R³ a rotation vector about a reference R0 (the
optimiser's start, re-centred on the optimum). The log-likelihood depends on S' = RᵀSR through
``-tr(Σ⁻¹S')/2`` (log|S'| does not change with R) and on x̄' = Rᵀx̄ through the barycentre
differences, so a turn ``R·exp([ε]×)`` changes it by ``Σ_k ε_k g_k`` with
``g_k = Σ_series [tr(∂L/∂S'·(S'E_k - E_kS')) - ∂L/∂x̄'·E_k x̄']``, E_k = [e_k]×; at δ ≠ 0 the
gradient in δ is ``J_r(δ)ᵀ g`` with J_r the right Jacobian of SO(3)
(``exp([δ + ε]×) ≈ exp([δ]×)·exp([J_r(δ)ε]×)``).

**What determines R.** The spread at a pose, with every joint moving, is one ellipsoid whatever
the approach signs (Σ depends on s²); it fixes R only up to the half turns about its axes. The
barycentre differences (vAP) carry signs and, with two non-parallel differences or ellipsoids of
several poses with different axes, fix R. With one direction at one pose, R is known up to those
half turns: harmless, since they leave the likelihood, and so θ̂, unchanged.

**Starts.** The likelihood can have several maxima in R (the half turns above, or an optimiser
stalled far from the truth). Candidates: the rotation that best turns the nominal model's
predicted barycentre differences into the measured ones (``Rotation.align_vectors``; on the test
arm within 4° of the truth), and the data's principal axes (:func:`principal_axes`) composed with
the identity and seeded random rotations. Every candidate is built from the data in a way that
turns with them, so a rigid motion of the measurements turns every start alike and leaves the fit
unchanged to rounding (1e-11 relative on the test arm); a parameter along a nearly flat direction
of the likelihood (not identifiable) may move by more, as the optimiser's path differs by rounding.

**Uncertainty.** The observed information of (θ, δ) is that of the joint problem; θ's covariance
is the θ block of its inverse, i.e. the inverse of the profile information
``F_θθ - F_θδ F_δδ⁺ F_δθ`` (Schur complement, :func:`profile_information`).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy.spatial.transform import Rotation

from tribokin.calibration.data import SeriesStack
from tribokin.calibration.identifiability import RANK_RTOL
from tribokin.calibration.likelihood import log_likelihood_and_data_derivatives
from tribokin.calibration.model import JointModel

#: (3, 3, 3) E_k = [e_k]×, the generators of rotations about the axes: E_k·v = e_k × v.
GENERATORS = np.cross(np.eye(3)[:, None, :], np.eye(3)[None, :, :]).transpose(0, 2, 1)


def to_base(data: SeriesStack, rotation: np.ndarray) -> SeriesStack:
    """The series in the world frame, given the measuring frame's rotation (..., 3, 3) (module docstring).

    Scatter matrices and barycentres take the rotation's batch dimensions before their own.
    """
    return replace(data, mean_m=np.einsum("...ba,mb->...ma", rotation, data.pose_centred_mean_m),
                   scatter_m2=np.einsum("...ba,mbc,...cd->...mad", rotation, data.scatter_m2, rotation))


def right_jacobian(rotation_vector: np.ndarray) -> np.ndarray:
    """(..., 3, 3) right Jacobian of SO(3) at rotation vectors (..., 3):
    ``I - (1 - cos φ)/φ²·[δ]× + (φ - sin φ)/φ³·[δ]×²``, φ = |δ|."""
    angle = np.linalg.norm(rotation_vector, axis=-1)[..., None, None]
    skew = np.einsum("...k,kab->...ab", rotation_vector, GENERATORS)
    with np.errstate(divide="ignore", invalid="ignore"):
        cubic = np.where(angle < 1e-4, 1 / 6 - angle ** 2 / 120, (angle - np.sin(angle)) / angle ** 3)
    return np.eye(3) - 0.5 * np.sinc(angle / (2 * np.pi)) ** 2 * skew + cubic * skew @ skew


def unknown_frame_log_likelihood_and_gradient(model: JointModel, parameters: np.ndarray, data: SeriesStack,
                                              reference: Rotation) -> tuple[np.ndarray, np.ndarray]:
    """Log-likelihood (...) of measurements in an unknown frame and its gradient (p + 3, ...).

    Args:
        model: the joint model.
        parameters: (p + 3, ...) θ, then δ [rad]: the frame's rotation ``reference·exp([δ]×)``.
        data: the series as measured, in the measuring frame.
        reference: R0.
    """
    theta, delta = parameters[:-3], np.moveaxis(parameters[-3:], 0, -1)
    rotation = (reference * Rotation.from_rotvec(delta.reshape(-1, 3))).as_matrix().reshape(delta.shape + (3,))
    base = to_base(data, rotation)
    value, d_theta, d_scatter, d_mean = log_likelihood_and_data_derivatives(model, theta, base)
    turn = (np.einsum("...mab,...mbc,kca->...k", d_scatter, base.scatter_m2, GENERATORS)
            - np.einsum("...mab,kbc,...mca->...k", d_scatter, GENERATORS, base.scatter_m2)
            - np.einsum("...ma,kab,...mb->...k", d_mean, GENERATORS, base.mean_m))
    d_delta = np.einsum("...ka,...k->...a", right_jacobian(delta), turn)
    return value, np.concatenate([d_theta, np.moveaxis(d_delta, -1, 0)])


def principal_axes(data: SeriesStack) -> Rotation:
    """A frame that turns with the data: the eigenvectors of the summed scatter matrices, each
    signed so that the barycentres' third moment along it is not negative, the third axis the
    cross product of the first two."""
    axes = np.linalg.eigh(data.scatter_m2.sum(axis=0))[1]
    centred = data.mean_m - data.mean_m.mean(axis=0)
    axes = axes * np.where(((centred @ axes) ** 3).sum(axis=0) < 0, -1.0, 1.0)
    axes[:, 2] = np.cross(axes[:, 0], axes[:, 1])
    return Rotation.from_matrix(axes)


def aligned_rotation(model: JointModel, data: SeriesStack) -> Rotation | None:
    """The rotation that best turns the model's predicted barycentre differences (world frame) into
    the measured ones (``Rotation.align_vectors``); None without any difference."""
    rows = np.flatnonzero(data.first_of_pose != np.arange(len(data.pose_index)))
    if not len(rows):
        return None
    first = data.first_of_pose[rows]
    shift = model.predict(data.jacobian, data.signs, data.torque_mean, data.torque_std)[1]
    return Rotation.align_vectors(data.mean_m[rows] - data.mean_m[first], shift[rows] - shift[first])[0]


def candidate_rotations(model: JointModel, data: SeriesStack, count: int, seed: int) -> Rotation:
    """Starts of the frame's rotation (module docstring): the aligned rotation when there is one,
    then the principal axes composed with the identity and ``count`` random rotations
    (``Rotation.random`` with ``numpy.random.default_rng(seed)``)."""
    random = Rotation.concatenate([Rotation.identity(), Rotation.random(count, rng=np.random.default_rng(seed))])
    aligned = aligned_rotation(model, data)
    candidates = principal_axes(data) * random
    return candidates if aligned is None else Rotation.concatenate([aligned, candidates])


def profile_information(information: np.ndarray) -> np.ndarray:
    """(p, p) profile information of θ from the (p + 3, p + 3) information of (θ, δ): its Schur
    complement ``F_θθ - F_θδ F_δδ⁺ F_δθ`` (pseudo-inverse at ``RANK_RTOL``: a rotation the data do
    not determine takes no information from θ)."""
    information = (information + information.T) / 2
    theta, rotation = information[:-3, :-3], information[-3:, -3:]
    coupling = information[:-3, -3:]
    return theta - coupling @ np.linalg.pinv(rotation, hermitian=True, rtol=RANK_RTOL) @ coupling.T
