"""Compiled (numba) kernel of :mod:`tribokin.iso9283.cube`, target by target: the joints' approach signs where the
tool Jacobian is surely of full rank (:func:`~tribokin.iso9283.cube.surely_full_rank`'s bound), the tool's
orientation held. The signs are NumPy's (LAPACK's determinant and solve): the velocities agree to rounding, and a
sign could differ only for a joint whose speed lies within rounding of ``STILL_RTOL`` times the fastest's.

Imported only on the compiled path (:func:`tribokin.compiled.use_compiled`). The NumPy module's constants are passed
in as arguments: numba's cache would keep a module global's old value.
"""

from __future__ import annotations

import numpy as np

from tribokin.compiled import kernel


@kernel
def held_signs(jacobians, directions, bound, still):
    """(k, nv, m) approach signs (+1, -1, 0) of tool Jacobians (k, 6, nv) along unit directions (m, 3), and (k,)
    where they were computed: where det(J Jᵀ) > ``bound`` tr(J Jᵀ)⁵ (surely full rank), the velocities
    v = Jᵀ (J Jᵀ)⁻¹ [d, 0] (Gaussian elimination with partial pivoting, as LAPACK's), 0 where |v_n| <= ``still``
    max |v|; elsewhere zeros, left to the NumPy path."""
    count, nv, m = jacobians.shape[0], jacobians.shape[2], directions.shape[0]
    signs = np.zeros((count, nv, m))
    sure = np.zeros(count, dtype=np.bool_)
    square = np.empty((6, 6))
    solution = np.empty((6, m))
    velocity = np.empty(nv)
    for k in range(count):
        jacobian = jacobians[k]
        trace = 0.0
        for i in range(6):
            for j in range(i, 6):
                total = 0.0
                for n in range(nv):
                    total += jacobian[i, n] * jacobian[j, n]
                square[i, j] = total
                square[j, i] = total
            trace += square[i, i]
            for d in range(m):
                solution[i, d] = directions[d, i] if i < 3 else 0.0
        determinant = 1.0
        for c in range(6):  # eliminate below the pivot, the right-hand sides with the rows
            pivot = c
            for r in range(c + 1, 6):
                if abs(square[r, c]) > abs(square[pivot, c]):
                    pivot = r
            if pivot != c:
                determinant = -determinant
                for col in range(c, 6):
                    square[c, col], square[pivot, col] = square[pivot, col], square[c, col]
                for d in range(m):
                    solution[c, d], solution[pivot, d] = solution[pivot, d], solution[c, d]
            determinant *= square[c, c]
            if square[c, c] == 0.0:
                break
            for r in range(c + 1, 6):
                factor = square[r, c] / square[c, c]
                for col in range(c + 1, 6):
                    square[r, col] -= factor * square[c, col]
                for d in range(m):
                    solution[r, d] -= factor * solution[c, d]
        if not determinant > bound * trace ** 5:
            continue
        sure[k] = True
        for d in range(m):
            for r in range(5, -1, -1):  # back substitution
                total = solution[r, d]
                for col in range(r + 1, 6):
                    total -= square[r, col] * solution[col, d]
                solution[r, d] = total / square[r, r]
            fastest = 0.0
            for n in range(nv):
                total = 0.0
                for i in range(6):
                    total += jacobian[i, n] * solution[i, d]
                velocity[n] = total
                fastest = max(fastest, abs(total))
            for n in range(nv):
                if abs(velocity[n]) > still * fastest:
                    signs[k, n, d] = 1.0 if velocity[n] > 0 else -1.0
    return signs, sure
