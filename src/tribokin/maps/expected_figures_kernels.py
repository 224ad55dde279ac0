"""Compiled (numba) kernel of :class:`~tribokin.maps.expected_figures.LinearModel`: the covariance J diag(var) Jᵀ of the
tool's position or angle deviation, target by target. It agrees with the NumPy path (``np.einsum``) to rounding,
about 1e-15 relative.

Imported only on the compiled path (:func:`tribokin.compiled.use_compiled`).
"""

from __future__ import annotations

import numpy as np

from tribokin.compiled import kernel


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
