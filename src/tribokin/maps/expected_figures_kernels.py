"""Compiled (numba) kernels of :mod:`~tribokin.maps.expected_figures`, target by target: the covariance J diag(var) Jᵀ
of the tool's position or angle deviation (:class:`~tribokin.maps.expected_figures.LinearModel`), RP_l of each
sampled test through the first-order model, and E[vAP_p] with its Monte Carlo standard error: the farthest pair's
expected distance, or where pairs of approach directions are close, their linearised largest and its correction over
draws. They agree with the NumPy path to rounding, about 1e-15 relative (the covariance, and the farthest pair's
distance: the compiled E|c + w|'s to the bit), 1e-12 (where pairs are close: the noise drawn through the symmetric
root, which both paths' eigenvalue routines give alike, and Φ by ``math.erfc`` for SciPy's ``ndtr``) and about 1e-11
(the tests' RP_l: their NumPy path adds the tool's position before it takes the barycentre away).

Imported only on the compiled path (:func:`tribokin.compiled.use_compiled`). Constants are passed in as arguments:
numba's cache would keep a module global's old value.
"""

from __future__ import annotations

import math

import numpy as np

from tribokin.compiled import kernel
from tribokin.iso9283.gaussian_tests_kernels import _expected_norm, _jacobi, expected_maximum, symmetric_root


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
def vap_expected(centres, noise, z, tail_stds, norm_rule, maximum_rule):
    """(k, 2) E[vAP_p] [m] and its Monte Carlo standard error [m], as ``maps.expected_figures._vap_expected``, of
    barycentres ``centres`` (k, 3 directions, 3) [m] with Gaussian noise of covariances ``noise``
    (k, 3 directions, 3, 3) [m²]: the farthest pair's E|g + e| (``norm_rule``: ratio, times, weights and step of
    :func:`~tribokin.iso9283.gaussian_tests_kernels.expected_norm`), or where the two farthest pairs are within
    ``tail_stds`` of their noises' largest standard deviations (summed) of each other, :func:`_vap_close` (standard
    normal draws ``z`` (3 directions, 3, draws), ``maximum_rule``: nodes, weights and span of
    :func:`~tribokin.iso9283.gaussian_tests_kernels.expected_maximum`)."""
    ratio, times, weights, step = norm_rule
    out = np.zeros((centres.shape[0], 2))
    gaps, spreads, sizes = np.empty((3, 3)), np.empty((3, 3, 3)), np.empty(3)
    c, s, lam, vectors = np.empty(3), np.empty((3, 3)), np.empty(3), np.empty((3, 3))
    differences, roots, shift = np.empty(z.shape[2]), np.empty((3, 3, 3)), np.empty((3, 3))
    for k in range(centres.shape[0]):
        _pairs(centres[k], noise[k], gaps, spreads, sizes)
        farthest, next_ = 0, 1  # the pairs by decreasing size, the first of equal ones first (a stable sort)
        if sizes[1] > sizes[0]:
            farthest, next_ = 1, 0
        if sizes[2] > sizes[farthest]:
            farthest, next_ = 2, farthest
        elif sizes[2] > sizes[next_]:
            next_ = 2
        gap = sizes[farthest] - sizes[next_]
        close = gap <= tail_stds * (_trace_root(spreads[farthest]) + _trace_root(spreads[next_]))
        if close:  # √tr S >= the largest standard deviation: only then can the widths themselves say close
            _jacobi(spreads[farthest], lam, vectors)
            width = math.sqrt(lam[2])
            _jacobi(spreads[next_], lam, vectors)
            width += math.sqrt(lam[2])
            close = gap <= tail_stds * width
        if close:
            _vap_close(gaps, spreads, sizes, noise[k], z, maximum_rule, out[k], lam, vectors, differences, roots,
                       shift)
        else:
            out[k, 0] = _expected_norm(gaps[farthest], spreads[farthest], ratio, times, weights, step, c, s, lam,
                                       vectors)
    return out


@kernel
def _trace_root(matrix):
    """√tr of a (3, 3) covariance: at least the square root of its largest eigenvalue."""
    return math.sqrt(max(matrix[0, 0] + matrix[1, 1] + matrix[2, 2], 0.0))


@kernel
def _pairs(centres, noise, gaps, spreads, sizes):
    """Into ``gaps`` (3 pairs, 3) [m], ``spreads`` (3 pairs, 3, 3) [m²] and ``sizes`` (3,) [m] the differences of the
    pairs' barycentres ``centres`` (3 directions, 3), the sums of their noise covariances ``noise``
    (3 directions, 3, 3) and the gaps' lengths."""
    first, second = (0, 0, 1), (1, 2, 2)
    for p in range(3):
        for i in range(3):
            gaps[p, i] = centres[first[p], i] - centres[second[p], i]
            for j in range(3):
                spreads[p, i, j] = noise[first[p], i, j] + noise[second[p], i, j]
        sizes[p] = math.sqrt(gaps[p, 0] * gaps[p, 0] + gaps[p, 1] * gaps[p, 1] + gaps[p, 2] * gaps[p, 2])


@kernel
def _vap_close(gaps, spreads, sizes, noise, z, maximum_rule, out, lam, vectors, differences, roots, shift):
    """Into ``out`` (2,) E[vAP_p] [m] and its Monte Carlo standard error [m] of one target whose pairs are close, as
    ``maps.expected_figures._vap_close``: the pairs' gaps g (3 pairs, 3) [m], covariances (3 pairs, 3, 3) [m²] and
    sizes |g| (3,) [m], the directions' noise covariances (3, 3, 3) [m²] (each drawn through its symmetric root from
    ``z`` (3 directions, 3, draws)); the rest scratch. The linearised distances' largest in closed form
    (:func:`~tribokin.iso9283.gaussian_tests_kernels.expected_maximum`), plus the mean over draws of the exact
    largest less the linearised one."""
    nodes, weights, span = maximum_rule
    units, means, covariance = np.zeros((3, 3)), np.empty(3), np.empty((3, 3))
    first, second = (0, 0, 1), (1, 2, 2)
    for p in range(3):
        trace, along = 0.0, 0.0
        if sizes[p] > 0:
            for i in range(3):
                units[p, i] = gaps[p, i] / sizes[p]
        for i in range(3):
            trace += spreads[p, i, i]
            for j in range(3):
                along += units[p, i] * spreads[p, i, j] * units[p, j]
        means[p] = sizes[p] + ((trace - along) / (2 * sizes[p]) if trace < sizes[p] ** 2 else 0.0)
    for p in range(3):  # Σ_d (±ĝ_p)ᵀ N_d (±ĝ_q) over the directions d the pairs p and q share
        for q in range(p, 3):
            total = 0.0
            for d in range(3):
                sign_p = 1.0 if d == first[p] else -1.0 if d == second[p] else 0.0
                sign_q = 1.0 if d == first[q] else -1.0 if d == second[q] else 0.0
                if sign_p * sign_q != 0.0:
                    for i in range(3):
                        for j in range(3):
                            total += sign_p * sign_q * units[p, i] * noise[d, i, j] * units[q, j]
            covariance[p, q] = total
            covariance[q, p] = total
    out[0] = expected_maximum(means, covariance, nodes, weights, span)
    for d in range(3):
        symmetric_root(noise[d], lam, vectors, roots[d])
    draws = z.shape[2]
    total = 0.0
    for n in range(draws):
        for d in range(3):
            for i in range(3):
                shift[d, i] = roots[d, i, 0] * z[d, 0, n] + roots[d, i, 1] * z[d, 1, n] + roots[d, i, 2] * z[d, 2, n]
        exact2, linear = -np.inf, -np.inf  # the largest square distance: its root is the largest distance
        for p in range(3):
            size2, along = 0.0, 0.0
            for i in range(3):
                error = shift[first[p], i] - shift[second[p], i]
                size2 += (gaps[p, i] + error) ** 2
                along += units[p, i] * error
            exact2 = max(exact2, size2)
            linear = max(linear, means[p] + along)
        differences[n] = math.sqrt(exact2) - linear
        total += differences[n]
    correction = total / draws
    square = 0.0
    for n in range(draws):
        square += (differences[n] - correction) ** 2
    out[0] += correction
    out[1] = math.sqrt(square / (draws - 1) / draws)


@kernel
def tests_repeatability(weights, centred, tests, cycles, chunk):
    """(k, tests) RP_l = l̄ + 3 S_l (S_l with n - 1) of each test of ``cycles`` cycles of k targets, as
    ``maps.expected_figures.tests_rp_l``: a cycle's offset from its test's barycentre is W (n - n̄), W the target's
    position responses (k, 3, m) and n - n̄ its common random numbers less their test's mean, ``centred``
    (m, tests × cycles); ``chunk`` cycles' offsets at a time, one number's column after another."""
    count, width, total = weights.shape[0], weights.shape[2], centred.shape[1]
    out = np.empty((count, tests))
    distances = np.empty(total)
    x, y, z = np.empty(chunk), np.empty(chunk), np.empty(chunk)
    for k in range(count):
        for start in range(0, total, chunk):
            length = min(chunk, total - start)
            x[:length], y[:length], z[:length] = 0.0, 0.0, 0.0
            for j in range(width):
                w0, w1, w2 = weights[k, 0, j], weights[k, 1, j], weights[k, 2, j]
                for c in range(length):
                    number = centred[j, start + c]
                    x[c] += w0 * number
                    y[c] += w1 * number
                    z[c] += w2 * number
            for c in range(length):
                distances[start + c] = math.sqrt(x[c] * x[c] + y[c] * y[c] + z[c] * z[c])
        for t in range(tests):
            first = t * cycles
            mean = 0.0
            for c in range(first, first + cycles):
                mean += distances[c]
            mean /= cycles
            square = 0.0
            for c in range(first, first + cycles):
                square += (distances[c] - mean) ** 2
            out[k, t] = mean + 3 * math.sqrt(square / (cycles - 1)) if cycles > 1 else mean
    return out
