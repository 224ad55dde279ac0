"""The profile deviance of a registered fit, re-fitted by an optimiser other than the one under test."""

from __future__ import annotations

import numpy as np
from scipy.optimize import minimize

from tribokin.calibration.data import SeriesStack
from tribokin.calibration.fit import Calibration
from tribokin.calibration.likelihood import log_likelihood_and_gradient


def profile_deviance(calibration: Calibration, data: SeriesStack, name: str, value: float) -> float:
    """2·(log L̂ - max log L with parameter ``name`` held at ``value`` [its unit]), the other parameters re-fitted by
    L-BFGS-B run to convergence from the optimum (the fit's own profile uses SLSQP)."""
    i = calibration.nominal.names().index(name)
    others = np.arange(len(calibration.theta)) != i

    def negative(rest):
        log_l, gradient = log_likelihood_and_gradient(calibration.nominal, np.insert(rest, i, np.log(value)), data)
        return -log_l, -gradient[others]

    best = minimize(negative, calibration.theta[others], jac=True, method="L-BFGS-B",
                    bounds=calibration.bounds[others], options={"maxiter": 10_000, "ftol": 1e-13})
    return 2 * (calibration.log_likelihood + best.fun)
