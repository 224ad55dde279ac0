"""What the data determine: rank and condition of the Fisher information, standard errors, hints.

The observed Fisher information F (the Hessian of the negative log-likelihood at the optimum, in
θ = log-parameter space) is split by its eigenvalues: those at or below ``RANK_RTOL``·λ_max span
its null space, where the likelihood is flat to the Hessian's precision. A parameter loading on that
null space (squared projection above ``NULL_LOADING``) has no standard error; the others' covariance
is the inverse of F restricted to them. A parameter is identifiable when it has a standard error in
log space of at most ``max_relative_std_error`` (default ln 2 / 1.96: its 95 % Wald interval lies
within a factor 2 of the value on each side).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Eigenvalues of F at or below this fraction of the largest span its null space.
RANK_RTOL = 1e-8
#: Squared projection of a parameter's axis on F's null space above which it has no standard error.
NULL_LOADING = 1e-2
#: Default largest standard error of log θ of an identifiable parameter: 95 % interval within ×/÷ 2.
MAX_RELATIVE_STD_ERROR = float(np.log(2) / 1.96)


@dataclass(frozen=True, eq=False)
class Identifiability:
    """Standard errors and identifiability of the free parameters (θ = log space).

    Attributes:
        rank: rank of F.
        condition_number: λ_max / λ_min of F (inf when singular or indefinite).
        covariance: (p, p) inverse of F over the parameters off its null space; NaN rows and
            columns for those on it.
        std_error: (p,) standard error of log θ (≈ relative standard error); inf on the null space.
        in_null_space: (p,) True where the likelihood is flat along the parameter.
        identifiable: (p,) finite standard error within ``max_relative_std_error``.
    """

    rank: int
    condition_number: float
    covariance: np.ndarray
    std_error: np.ndarray
    in_null_space: np.ndarray
    identifiable: np.ndarray


def analyse(information: np.ndarray, max_relative_std_error: float = MAX_RELATIVE_STD_ERROR) -> Identifiability:
    """Identifiability of the parameters from the (p, p) observed Fisher information in log space."""
    information = (information + information.T) / 2
    eigenvalues, vectors = np.linalg.eigh(information)
    tolerance = RANK_RTOL * max(eigenvalues[-1], 0.0)
    null = eigenvalues <= tolerance
    in_null = (vectors[:, null] ** 2).sum(axis=1) > NULL_LOADING
    keep = ~in_null
    covariance = np.full_like(information, np.nan)
    covariance[np.ix_(keep, keep)] = np.linalg.pinv(information[np.ix_(keep, keep)], hermitian=True,
                                                    rtol=RANK_RTOL)
    variance = np.diag(covariance)
    std_error = np.where(keep & (variance > 0), np.sqrt(np.where(variance > 0, variance, 1.0)), np.inf)
    condition = eigenvalues[-1] / eigenvalues[0] if eigenvalues[0] > tolerance else np.inf
    return Identifiability(rank=int((~null).sum()), condition_number=float(condition), covariance=covariance,
                           std_error=std_error, in_null_space=in_null,
                           identifiable=np.isfinite(std_error) & (std_error <= max_relative_std_error))


def hint(name: str, invisible: bool) -> str:
    """What to do about a parameter the data do not determine (``name`` as in JointModel.names)."""
    if invisible:
        return ("the tool point does not move with this joint at the measured poses (it lies on the joint's axis, "
                "or the joint does not move on the approaches): fix its value")
    if name == "noise_floor_m":
        return "fix it from a measurement of the robot standing still"
    if name == "joints.stiffness_factor":
        return "measure more poses, or fix its value"
    if name.endswith(".backlash"):
        return ("fix its value (backlash separates from stiffness only through the spread), "
                "or measure more poses and approach directions")
    return 'measure more poses, tie the joints (tie = "all"), or fix its value'
