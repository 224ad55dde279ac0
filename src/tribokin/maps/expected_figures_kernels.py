"""Compiled (numba) kernels of :mod:`~tribokin.maps.expected_figures`, target by target: the covariance J diag(var) Jᵀ
of the tool's position or angle deviation (:class:`~tribokin.maps.expected_figures.LinearModel`), and vAP_p's
correction over draws where pairs of approach directions are close, with its standard error. They agree with the
NumPy path to rounding, about 1e-15 relative (the covariance) and 1e-12 (the correction: the noise drawn through the
symmetric root, which both paths' eigenvalue routines give alike).

Imported only on the compiled path (:func:`tribokin.compiled.use_compiled`).
"""

from __future__ import annotations

import math

import numpy as np

from tribokin.compiled import kernel
from tribokin.iso9283.gaussian_tests_kernels import _jacobi


@kernel
def covariances(jacobian, variance, first):
    """(k, 3, 3) Σ_n J[i, n] var[n] J[j, n] over rows i, j = ``first`` to ``first + 2`` of the Jacobians (k, 6, nv)
    and the joint deviations' variances (k, nv), in einsum's order ((J_in var_n) J_jn, summed over n)."""
    out = np.empty((jacobian.shape[0], 3, 3))
    for k in range(jacobian.shape[0]):
        for i in range(3):
            for j in range(i, 3):
                total = 0.0
                for n in range(jacobian.shape[2]):
                    total += jacobian[k, first + i, n] * variance[k, n] * jacobian[k, first + j, n]
                out[k, i, j] = total
                out[k, j, i] = total
    return out


@kernel
def vap_corrections(gaps, means, units, noise, z):
    """(k, 2) the mean over draws of vAP_p's largest distance |g + e| less its largest linearised one, and that
    mean's standard error (the differences' standard deviation over √draws), as
    ``maps.expected_figures._vap_close``: the pairs' gaps g (k, 3 pairs, 3), linearised means (k, 3 pairs) and unit
    gaps (k, 3 pairs, 3), the barycentres' noise covariances (k, 3 directions, 3, 3) (each drawn through its
    symmetric root) and standard normal draws ``z`` (3 directions, 3, draws)."""
    count, draws = gaps.shape[0], z.shape[2]
    out = np.empty((count, 2))
    differences = np.empty(draws)
    lam = np.empty(3)
    vectors = np.empty((3, 3))
    roots = np.empty((3, 3, 3))
    shift = np.empty((3, 3))
    first, second = (0, 0, 1), (1, 2, 2)
    for k in range(count):
        for d in range(3):
            _jacobi(noise[k, d], lam, vectors)
            for i in range(3):
                for j in range(3):
                    total = 0.0
                    for m in range(3):
                        total += vectors[i, m] * math.sqrt(max(lam[m], 0.0)) * vectors[j, m]
                    roots[d, i, j] = total
        total = 0.0
        for n in range(draws):
            for d in range(3):
                for i in range(3):
                    shift[d, i] = (roots[d, i, 0] * z[d, 0, n] + roots[d, i, 1] * z[d, 1, n]
                                   + roots[d, i, 2] * z[d, 2, n])
            exact, linear = -np.inf, -np.inf
            for p in range(3):
                size2, along = 0.0, 0.0
                for i in range(3):
                    error = shift[first[p], i] - shift[second[p], i]
                    size2 += (gaps[k, p, i] + error) ** 2
                    along += units[k, p, i] * error
                exact = max(exact, math.sqrt(size2))
                linear = max(linear, means[k, p] + along)
            differences[n] = exact - linear
            total += differences[n]
        out[k, 0] = total / draws
        square = 0.0
        for n in range(draws):
            square += (differences[n] - out[k, 0]) ** 2
        out[k, 1] = math.sqrt(square / (draws - 1) / draws)
    return out
