"""Compiled (numba) kernels of :mod:`tribokin.iso9283.gaussian_tests`, target by target: E[RP_l] and its spread
(Carlson's R_F and R_D by duplication, the delta method), E|c + w| (expansion or quadrature), the largest of three
jointly normal values' expectation, the eigenvalues of symmetric 3 × 3 matrices by cyclic Jacobi rotations, a sign
mixture's moments, a test's barycentre shares and E√(a + εᵀ U ε) on the mixture's grid. They agree with the NumPy
path (SciPy's Carlson integrals and normal law, LAPACK's eigenvalues) to rounding, about 1e-14 relative.

Imported only on the compiled path (:func:`tribokin.compiled.use_compiled`). The NumPy module's constants are passed
in as arguments: numba's cache would keep a module global's old value.
"""

from __future__ import annotations

import math

import numpy as np

from tribokin.compiled import kernel

#: Relative error the duplication stops at (Carlson 1995: the truncated series' error is below it).
_TOLERANCE = 1e-17
#: The duplication's stopping factors: (3 r)^(-1/6) for R_F, (r / 4)^(-1/6) for R_D.
_RF_FACTOR, _RD_FACTOR = (3 * _TOLERANCE) ** (-1 / 6), (_TOLERANCE / 4) ** (-1 / 6)
#: Duplications at most: 4^-60 of the arguments' spread is far below any float64 argument's rounding.
_DUPLICATIONS = 60
#: The smallest normal float64.
_TINY = float(np.finfo(np.float64).tiny)
#: Below this exponent e^x is below 1e-19, negligible beside 1 (the sign mixture's Laplace transform).
_NEGLIGIBLE_EXPONENT = -44.0
#: Cyclic Jacobi sweeps at most (a 3 × 3 matrix is diagonal to rounding after about five).
_SWEEPS = 50


@kernel
def _carlson(u, rd):
    """Carlson's R_F(u_0, u_1, u_2), and into ``rd`` (3,) R_D with u_i last, of positive ``u`` (3,), by duplication
    (Carlson 1995). The four share one sequence of duplicated arguments (R_F and R_D are means of the same
    integrand's powers), run until each one's criterion is met; each then takes its own series."""
    total = u[0] + u[1] + u[2]
    means = np.empty(4)  # R_F's (u_0 + u_1 + u_2) / 3, then each R_D's (u_0 + u_1 + u_2 + 2 u_i) / 5
    spreads = np.empty(4)
    means[0] = total / 3
    for i in range(3):
        means[i + 1] = (total + 2 * u[i]) / 5
    for f in range(4):
        spreads[f] = max(abs(means[f] - u[0]), abs(means[f] - u[1]), abs(means[f] - u[2])) * (
            _RF_FACTOR if f == 0 else _RD_FACTOR)
    am = means.copy()
    xm = u.copy()
    sums = np.zeros(3)  # Σ 4^-m / (√z_m (z_m + λ_m)) of each R_D, z = u_i
    power = 1.0
    for _ in range(_DUPLICATIONS):
        if (power * spreads[0] < abs(am[0]) and power * spreads[1] < abs(am[1]) and power * spreads[2] < abs(am[2])
                and power * spreads[3] < abs(am[3])):
            break
        sx, sy, sz = math.sqrt(xm[0]), math.sqrt(xm[1]), math.sqrt(xm[2])
        lam = sx * sy + sx * sz + sy * sz
        sums[0] += power / (sx * (xm[0] + lam))
        sums[1] += power / (sy * (xm[1] + lam))
        sums[2] += power / (sz * (xm[2] + lam))
        for i in range(3):
            xm[i] = (xm[i] + lam) / 4
        for f in range(4):
            am[f] = (am[f] + lam) / 4
        power /= 4
    dx, dy = (means[0] - u[0]) * power / am[0], (means[0] - u[1]) * power / am[0]
    dz = -(dx + dy)
    e2, e3 = dx * dy - dz * dz, dx * dy * dz
    for i in range(3):
        a = am[i + 1]
        dx, dy = (means[i + 1] - u[(i + 1) % 3]) * power / a, (means[i + 1] - u[(i + 2) % 3]) * power / a
        dz = -(dx + dy) / 3
        xy, z2 = dx * dy, dz * dz
        f2, f3, f4, f5 = xy - 6 * z2, (3 * xy - 8 * z2) * dz, 3 * (xy - z2) * z2, xy * z2 * dz
        series = 1 - 3 * f2 / 14 + f3 / 6 + 9 * f2 * f2 / 88 - 3 * f4 / 22 - 9 * f2 * f3 / 52 + 3 * f5 / 26
        rd[i] = power * series / (a * math.sqrt(a)) + 3 * sums[i]
    return (1 - e2 / 10 + e3 / 14 + e2 * e2 / 24 - 3 * e2 * e3 / 44) / math.sqrt(am[0])


@kernel
def _unit_moments(u, mean_norm, slopes):
    """E|w|^k, k = 1..4, of w ~ N(0, diag(u)) for positive ``u`` (3,), as ``iso9283.gaussian_tests._unit_moments``:
    R_G from R_F and the R_D whose last argument is the middle one (no cancellation), ∂R_G/∂u_i = R_F/4 - u_i
    R_D_i/12 (into ``slopes`` (3,))."""
    rd = np.empty(3)  # R_D with u_i last
    rf = _carlson(u, rd)
    middle = 0
    for i in range(3):
        if (u[i] - u[(i + 1) % 3]) * (u[i] - u[(i + 2) % 3]) <= 0:
            middle = i
            break
    x, y, z = u[(middle + 1) % 3], u[(middle + 2) % 3], u[middle]
    rg = (z * rf - (x - z) * (y - z) * rd[middle] / 3 + math.sqrt(x * y / z)) / 2
    m1 = mean_norm * rg
    m2 = u[0] + u[1] + u[2]
    weighted = 0.0
    for i in range(3):
        slopes[i] = rf / 4 - u[i] * rd[i] / 12
        weighted += u[i] ** 2 * slopes[i]
    m3 = m2 * m1 + 2 * mean_norm * weighted
    m4 = m2 ** 2 + 2 * (u[0] ** 2 + u[1] ** 2 + u[2] ** 2)
    return m1, m2, m3, m4


@kernel
def _delta_terms(m1, m2, m3, m4, n):
    """(σ², the third and fourth central moments, 1 - Var(S_l²) / (8 σ⁴)) of one cycle's distance from its four
    moments, as ``iso9283.gaussian_tests.rp_l_from_moments`` (the factor 1 where σ⁴ is 0, or underflows)."""
    variance = np.maximum(m2 - m1 ** 2, 0.0)
    central3 = m3 - 3 * m2 * m1 + 2 * m1 ** 3
    central4 = m4 - 4 * m3 * m1 + 6 * m2 * m1 ** 2 - 3 * m1 ** 4
    variance_of_s2 = central4 / n - variance ** 2 * (n - 3) / (n * (n - 1))
    factor = 1 - variance_of_s2 / (8 * variance ** 2) if variance ** 2 > 0 else 1.0
    return variance, central3, central4, factor


@kernel
def _rp_l_from_moments(m1, m2, m3, m4, n):
    """(E[RP_l], its standard deviation) from one cycle's four moments, as
    ``iso9283.gaussian_tests.rp_l_from_moments``."""
    variance, central3, central4, factor = _delta_terms(m1, m2, m3, m4, n)
    sigma = math.sqrt(variance)
    if variance > 0:
        mean = m1 + 3 * sigma * factor
        spread = (variance + 9 * (central4 - variance ** 2) / (4 * variance) + 3 * central3 / sigma) / n
    else:
        mean, spread = m1 + 3 * sigma, 0.0
    return mean, math.sqrt(np.maximum(spread, 0.0))


@kernel
def expected_rp_l(lam, cycles, floor, mean_norm):
    """(E[RP_l], one test's standard deviation) (k,) each [m] of tests of ``cycles`` cycles with Gaussian deviations of
    covariance eigenvalues ``lam`` (k, 3) [m²], those below ``floor`` of the largest raised to it, as
    ``iso9283.gaussian_tests.expected_rp_l``; ``mean_norm``: E|z| of a standard normal 3-vector."""
    n = cycles
    mean, spread = np.empty(lam.shape[0]), np.empty(lam.shape[0])
    unit, slopes = np.empty(3), np.empty(3)
    for k in range(lam.shape[0]):
        largest = _unit_eigenvalues(lam[k], floor, (n - 1) / n, unit)
        m1, m2, m3, m4 = _unit_moments(unit, mean_norm, slopes)
        mean[k], spread[k] = _rp_l_from_moments(m1, m2, m3, m4, n)
        mean[k] *= math.sqrt(largest)
        spread[k] *= math.sqrt(largest)
    return mean, spread


@kernel
def _unit_eigenvalues(lam, floor, factor, unit):
    """The largest of the eigenvalues ``lam`` (3,) [m²] (negative ones taken as 0), and into ``unit`` (3,) each over
    it, raised to ``floor``, times ``factor``."""
    a, b, c = np.maximum(lam[0], 0.0), np.maximum(lam[1], 0.0), np.maximum(lam[2], 0.0)
    largest = np.maximum(np.maximum(a, b), c)
    divisor = largest if largest > 0 else 1.0
    unit[0] = factor * np.maximum(a / divisor, floor)
    unit[1] = factor * np.maximum(b / divisor, floor)
    unit[2] = factor * np.maximum(c / divisor, floor)
    return largest


@kernel
def band_skewness(lam, cycles, floor, mean_norm):
    """The skewness (k,) of one test's RP_l over tests of ``cycles`` Gaussian cycles of covariance eigenvalues ``lam``
    (k, 3) [m²], as ``iso9283.gaussian_tests.gaussian_band_skewness`` (and its ``influence_skewness``)."""
    n = cycles
    skewness = np.zeros(lam.shape[0])
    unit, slopes = np.empty(3), np.empty(3)
    factor = math.sqrt(n / (n - 1))
    for k in range(lam.shape[0]):
        _unit_eigenvalues(lam[k], floor, 1.0, unit)
        m1, m2, m3, m4 = _unit_moments(unit, mean_norm, slopes)
        m5, squares, cubes = m2 * m3, 0.0, 0.0
        for i in range(3):
            m5 += 3 * unit[i] * (unit[i] * m1 + 2 * mean_norm * unit[i] ** 2 * slopes[i])
            squares += unit[i] ** 2
            cubes += unit[i] ** 3
        m6 = m2 ** 3 + 6 * m2 * squares + 8 * cubes
        sigma2 = m2 - m1 ** 2
        if not sigma2 > 0:
            continue
        sigma = math.sqrt(sigma2)
        slope, slope2 = 1 - 3 * factor * m1 / sigma, 1.5 * factor / sigma
        covariance, variance_l2 = m3 - m1 * m2, m4 - m2 ** 2
        third = (slope ** 3 * (m3 - 3 * m1 * m2 + 2 * m1 ** 3)
                 + 3 * slope ** 2 * slope2 * (m4 - m2 ** 2 - 2 * m1 * m3 + 2 * m1 ** 2 * m2)
                 + 3 * slope * slope2 ** 2 * (m5 - 2 * m2 * m3 - m1 * m4 + 2 * m1 * m2 ** 2)
                 + slope2 ** 3 * (m6 - 3 * m2 * m4 + 2 * m2 ** 3))
        variance = slope ** 2 * sigma2 + 2 * slope * slope2 * covariance + slope2 ** 2 * variance_l2
        share, share2 = slope * sigma2 + slope2 * covariance, slope * covariance + slope2 * variance_l2
        curvature = 3 * factor / (sigma2 * sigma) * (-m2 * share ** 2 + m1 * share * share2 - share2 ** 2 / 4)
        if variance > 0:
            skewness[k] = (third + 3 * curvature) / math.sqrt(n) / variance ** 1.5
    return skewness


@kernel
def _jacobi(matrix, values, vectors):
    """Eigenvalues into ``values`` (3,) ascending, and unit eigenvectors into the columns of ``vectors`` (3, 3), of the
    symmetric ``matrix`` (3, 3; its upper triangle read, left unchanged) by cyclic Jacobi rotations (Numerical Recipes'
    ``jacobi``: each rotation zeroes an off-diagonal element; small ones are dropped once they no longer change the
    diagonal). NaN throughout if an element is."""
    a = matrix.copy()
    for i in range(3):
        values[i] = a[i, i]
        for j in range(3):
            vectors[i, j] = 1.0 if i == j else 0.0
    for sweep in range(_SWEEPS):
        off = abs(a[0, 1]) + abs(a[0, 2]) + abs(a[1, 2])
        if off != off or values[0] != values[0] or values[1] != values[1] or values[2] != values[2]:
            values[:] = math.nan
            vectors[:] = math.nan
            return
        if off == 0:
            break
        threshold = 0.2 * off / 9 if sweep < 3 else 0.0
        for p, q in ((0, 1), (0, 2), (1, 2)):
            r = 3 - p - q
            element = a[p, q]
            g = 100 * abs(element)
            if sweep > 3 and abs(values[p]) + g == abs(values[p]) and abs(values[q]) + g == abs(values[q]):
                a[p, q] = 0.0
            elif abs(element) > threshold:
                h = values[q] - values[p]
                if abs(h) + g == abs(h):
                    t = element / h
                else:
                    theta = 0.5 * h / element
                    t = 1 / (abs(theta) + math.sqrt(1 + theta * theta))
                    if theta < 0:
                        t = -t
                c = 1 / math.sqrt(1 + t * t)
                s = t * c
                tau = s / (1 + c)
                values[p] -= t * element
                values[q] += t * element
                a[p, q] = 0.0
                rp, rq = (min(r, p), max(r, p)), (min(r, q), max(r, q))
                g, h = a[rp], a[rq]
                a[rp] = g - s * (h + g * tau)
                a[rq] = h + s * (g - h * tau)
                for i in range(3):
                    g, h = vectors[i, p], vectors[i, q]
                    vectors[i, p] = g - s * (h + g * tau)
                    vectors[i, q] = h + s * (g - h * tau)
    for i in range(2):  # ascending, the vectors with them
        for j in range(2 - i):
            if values[j] > values[j + 1]:
                values[j], values[j + 1] = values[j + 1], values[j]
                for row in range(3):
                    vectors[row, j], vectors[row, j + 1] = vectors[row, j + 1], vectors[row, j]


@kernel
def eigenvalues(matrices):
    """(k, 3) ascending eigenvalues of symmetric (k, 3, 3) ``matrices`` (:func:`_jacobi`)."""
    out = np.empty((matrices.shape[0], 3))
    vectors = np.empty((3, 3))
    for k in range(matrices.shape[0]):
        _jacobi(matrices[k], out[k], vectors)
    return out


@kernel
def expected_norm(centre, covariance, ratio, times, weights, step):
    """E|c + w| (k,) [m] for w ~ N(0, S), centres c (k, 3) [m] and covariances S (k, 3, 3) [m²], as
    ``iso9283.gaussian_tests.expected_norm`` (:func:`_expected_norm`)."""
    out = np.empty(centre.shape[0])
    c = np.empty(3)
    s = np.empty((3, 3))
    lam = np.empty(3)
    vectors = np.empty((3, 3))
    for k in range(centre.shape[0]):
        out[k] = _expected_norm(centre[k], covariance[k], ratio, times, weights, step, c, s, lam, vectors)
    return out


@kernel
def _expected_norm(centre, covariance, ratio, times, weights, step, c, s, lam, vectors):
    """E|c + w| [m] for w ~ N(0, S), c ``centre`` (3,) [m] and S ``covariance`` (3, 3) [m²]: on c and S scaled by a
    power of two to order one (into ``c`` (3,) and ``s`` (3, 3); ``lam`` (3,) and ``vectors`` (3, 3) for their
    eigenvalues); where tr S < ``ratio`` |c|² the expansion |c| + (tr S - ĉᵀ S ĉ) / (2 |c|), else the trapezoid rule
    of step ``step`` at the quadrature's ``times`` e^u with ``weights`` e^(-u/2)."""
    magnitude, diagonal = 0.0, 0.0  # NaN if any is
    for i in range(3):
        magnitude = np.maximum(magnitude, abs(centre[i]))
        diagonal = np.maximum(diagonal, abs(covariance[i, i]))
    magnitude = np.maximum(magnitude, math.sqrt(diagonal))
    if not magnitude > 0:
        return 0.0
    scale = 2.0 ** np.round(math.log2(magnitude))
    for i in range(3):
        c[i] = centre[i] / scale
        for j in range(3):
            s[i, j] = covariance[i, j] / scale / scale
    size2 = c[0] * c[0] + c[1] * c[1] + c[2] * c[2]
    trace = s[0, 0] + s[1, 1] + s[2, 2]
    if trace < ratio * size2:
        size = math.sqrt(size2)
        along = 0.0
        for i in range(3):
            along += c[i] * (s[i, 0] * c[0] + s[i, 1] * c[1] + s[i, 2] * c[2])
        return (size + (trace - along / size2) / (2 * size)) * scale
    _jacobi(s, lam, vectors)
    beta2 = np.empty(3)
    total = 0.0
    for j in range(3):
        lam[j] = np.maximum(lam[j], 0.0)
        beta2[j] = (vectors[0, j] * c[0] + vectors[1, j] * c[1] + vectors[2, j] * c[2]) ** 2
    scale2 = np.maximum(beta2[0] + beta2[1] + beta2[2] + (lam[0] + lam[1] + lam[2]), _TINY)
    for m in range(times.shape[0]):
        t = times[m] / scale2
        transform = 0.0
        for j in range(3):
            transform += -0.5 * math.log1p(2 * t * lam[j]) - t * beta2[j] / (1 + 2 * t * lam[j])
        total += -math.expm1(transform) * weights[m]
    return total * step * math.sqrt(scale2) / (2 * math.sqrt(math.pi)) * scale


@kernel
def expected_maximum(mean, covariance, nodes, weights, span):
    """E[max(Y_1, Y_2, Y_3)] of jointly normal Y of ``mean`` (3,) and ``covariance`` (3, 3), as
    ``iso9283.gaussian_tests.expected_maximum``: over D = Y_2 - Y_1 by Gauss-Legendre (``nodes`` and ``weights`` on
    [-1, 1]) on either side of the kink D = 0 within ``span`` standard deviations, E[max(max(0, D), W) | D] in closed
    form (Φ by ``math.erfc``); where one of them lies ``span`` standard deviations of its differences below both
    others, the others' largest in closed form (Clark's)."""
    for low in range(3):
        a, b = (1, 2) if low == 0 else (0, 2) if low == 1 else (0, 1)
        if _far_below(mean, covariance, low, a, span) and _far_below(mean, covariance, low, b, span):
            spread = math.sqrt(max(covariance[a, a] + covariance[b, b] - 2 * covariance[a, b], 0.0))
            if not spread > 0:
                return max(mean[a], mean[b])
            alpha = (mean[a] - mean[b]) / spread
            return (mean[a] * 0.5 * math.erfc(-alpha / math.sqrt(2)) + mean[b] * 0.5 * math.erfc(alpha / math.sqrt(2))
                    + spread * math.exp(-alpha ** 2 / 2) / math.sqrt(2 * math.pi))
    mean_d, mean_w = mean[1] - mean[0], mean[2] - mean[0]
    var_d = max(covariance[1, 1] + covariance[0, 0] - 2 * covariance[0, 1], 0.0)
    var_w = max(covariance[2, 2] + covariance[0, 0] - 2 * covariance[0, 2], 0.0)
    shared = covariance[1, 2] - covariance[0, 1] - covariance[0, 2] + covariance[0, 0]
    sd_d = math.sqrt(var_d)
    slope = shared / var_d if var_d > 0 else 0.0
    sd_w = math.sqrt(max(var_w - slope * shared, 0.0))
    kink = -mean_d / sd_d if sd_d > 0 else (span if mean_d < 0 else -span)
    kink = min(max(kink, -span), span)
    total, mass = 0.0, 0.0
    for low, high in ((-span, kink), (kink, span)):
        half, middle = (high - low) / 2, (high + low) / 2
        for i in range(nodes.shape[0]):
            x = half * nodes[i] + middle
            weight = half * weights[i] * math.exp(-x ** 2 / 2)
            floor = max(mean_d + sd_d * x, 0.0)
            excess = mean_w + slope * sd_d * x - floor
            if sd_w > 0:
                z = excess / sd_w
                inner = floor + excess * 0.5 * math.erfc(-z / math.sqrt(2)) + sd_w * math.exp(-z ** 2 / 2) / math.sqrt(
                    2 * math.pi)
            else:
                inner = floor + max(excess, 0.0)
            total += weight * inner
            mass += weight
    return mean[0] + total / mass


@kernel
def _far_below(mean, covariance, low, other, span):
    """Whether normal ``low`` of jointly normal Y (``mean`` (3,), ``covariance`` (3, 3)) lies ``span`` standard
    deviations of Y_other - Y_low below Y_other's mean."""
    spread = math.sqrt(max(covariance[other, other] + covariance[low, low] - 2 * covariance[other, low], 0.0))
    return mean[other] - mean[low] >= span * spread


@kernel
def _exp_less_one(x):
    """e^x - 1: ``expm1`` above x = -1, ``exp`` less 1 below (within 1.5 ulp there, and cheaper)."""
    return math.expm1(x) if x > -1.0 else math.exp(x) - 1.0


@kernel
def sign_mixture(columns, covariance, times, step, half, three_halves, lower):
    """E|x|^k, k = 1..4, (k,) each [m^k] and E[x xᵀ / |x|²] (k, 3, 3) of x = Σ_i s_i b_i + w over independent signs
    s_i = ±1, w ~ N(0, S), of (k, m, 3) ``columns`` and (k, 3, 3) ``covariance``, as ``iso9283.gaussian_tests.
    sign_mixture``: the patterns in Gray-code order (one column's sign flipped from one to the next; columns of zeros
    left out), the quadrature's ``times`` e^u of ``step`` and the sums ``half``, ``three_halves`` of its grid's tails;
    the directions from the same nodes' L(t) of each pattern. Each node's exponents over the patterns first, then
    their sums, with the patterns' products β_i β_j and their sums over patterns kept by pattern (the sums over
    patterns of L(t) - 1 and of (L(t) - 1) β_i β_j, those of L(t) added back from the products' own)."""
    count, width = columns.shape[0], columns.shape[1]
    out = (np.empty(count), np.empty(count), np.empty(count), np.empty(count), np.zeros((count, 3, 3)))
    lam = np.empty(3)
    vectors = np.empty((3, 3))
    s = np.empty((3, 3))
    rotated = np.empty((width, 3))
    beta = np.empty(3)
    patterns = 2 ** max(width - 1, 0)
    beta2 = np.empty((3, patterns))
    products = np.empty((patterns, 6))
    exponents = np.empty(patterns)
    less_one = np.empty(patterns)
    base = np.empty(6)
    weighted = np.empty(6)
    weighted_fourth = np.empty(6)
    pairs = np.empty(6)
    slope = np.empty(3)
    tilt = np.empty(3)
    elementary = np.empty(4)
    inner = np.empty((3, 3))
    for k in range(count):
        for i in range(3):
            for j in range(3):
                s[i, j] = covariance[k, i, j]
        _jacobi(s, lam, vectors)
        scale2 = 0.0
        for i in range(3):
            lam[i] = np.maximum(lam[i], 0.0)
            scale2 += lam[i]
        used = 0
        for c in range(width):
            size2 = 0.0
            for j in range(3):
                rotated[used, j] = (vectors[0, j] * columns[k, c, 0] + vectors[1, j] * columns[k, c, 1]
                                    + vectors[2, j] * columns[k, c, 2])
                size2 += rotated[used, j] ** 2
            if size2 > 0:
                scale2 += size2
                used += 1
        if not scale2 > 0:
            out[0][k], out[1][k], out[2][k], out[3][k] = 0.0, 0.0, 0.0, 0.0
            continue
        scale = math.sqrt(scale2)
        for i in range(3):
            lam[i] /= scale2
        elementary[1] = lam[0] + lam[1] + lam[2]
        elementary[2] = lam[0] * lam[1] + lam[0] * lam[2] + lam[1] * lam[2]
        elementary[3] = lam[0] * lam[1] * lam[2]
        for c in range(used):
            for j in range(3):
                rotated[c, j] /= scale
        for j in range(3):
            beta[j] = 0.0
            for c in range(used):
                beta[j] += rotated[c, j]
        count_p = 2 ** max(used - 1, 0)
        mean_fourth, mean_sixth, mean_eighth, mean_tenth, second_sum = 0.0, 0.0, 0.0, 0.0, 0.0
        for m in range(6):
            base[m] = 0.0
            weighted[m] = 0.0
            weighted_fourth[m] = 0.0
        for p in range(count_p):
            if p > 0:  # Gray code: flip the column of p's lowest set bit (the first column keeps its +1)
                bit, rest = 0, p
                while rest % 2 == 0:
                    rest //= 2
                    bit += 1
                sign = -2.0 if ((p ^ (p >> 1)) >> bit) & 1 else 2.0
                for j in range(3):
                    beta[j] += sign * rotated[bit + 1, j]
            k1, k2, k3, k4, k5 = 0.0, 0.0, 0.0, 0.0, 0.0  # the cumulants of |x|², as _quadratic_form_moments
            for j in range(3):
                beta2[j, p] = beta[j] * beta[j]
                power = 1.0
                k1 += lam[j] + beta2[j, p]
                power *= lam[j]
                k2 += 2 * power * (lam[j] + 2 * beta2[j, p])
                power *= lam[j]
                k3 += 8 * power * (lam[j] + 3 * beta2[j, p])
                power *= lam[j]
                k4 += 48 * power * (lam[j] + 4 * beta2[j, p])
                power *= lam[j]
                k5 += 384 * power * (lam[j] + 5 * beta2[j, p])
            second_sum += k1
            fourth = k2 + k1 ** 2
            mean_fourth += fourth
            mean_sixth += k3 + 3 * k2 * k1 + k1 ** 3
            mean_eighth += k4 + 4 * k3 * k1 + 3 * k2 ** 2 + 6 * k2 * k1 ** 2 + k1 ** 4
            mean_tenth += (k5 + 5 * k4 * k1 + 10 * k3 * k2 + 10 * k3 * k1 ** 2 + 15 * k2 ** 2 * k1
                           + 10 * k2 * k1 ** 3 + k1 ** 5)
            m = 0
            for i in range(3):
                for j in range(i + 1):
                    products[p, m] = beta[i] * beta[j]
                    base[m] += products[p, m]
                    weighted[m] += k1 * products[p, m]
                    weighted_fourth[m] += fourth * products[p, m]
                    m += 1
        fourth_sum = mean_fourth
        mean_fourth, mean_sixth = mean_fourth / count_p, mean_sixth / count_p
        mean_eighth, mean_tenth = mean_eighth / count_p, mean_tenth / count_p
        first, third = 0.0, 0.0
        q = 0
        for i in range(3):  # below the grid: t L(t) (S_t + m_t m_tᵀ) to second order in t, summed over the nodes
            for j in range(i + 1):
                spread, squared, cubed = (lam[i], lam[i] ** 2, lam[i] ** 3) if i == j else (0.0, 0.0, 0.0)
                inner[i, j] = (lower[4] * (count_p * spread + base[q])
                               - lower[5] * (second_sum * spread + weighted[q] + 2 * count_p * squared
                                             + 2 * (lam[i] + lam[j]) * base[q])
                               + lower[6] * (fourth_sum / 2 * spread + weighted_fourth[q] / 2
                                             + 2 * (second_sum * squared + (lam[i] + lam[j]) * weighted[q])
                                             + 4 * (count_p * cubed + (lam[i] ** 2 + lam[i] * lam[j] + lam[j] ** 2)
                                                    * base[q])))
                q += 1
        dead = False  # every pattern's L(t) below e^-44 at a node: at every later one too (the exponent falls with t)
        for m in range(times.shape[0]):
            t = times[m]
            if dead:  # L(t) = 0 to rounding: what the loop below adds, without its exponentials
                first += count_p / math.sqrt(t)
                third += (t * second_sum - count_p) / (t * math.sqrt(t))
                continue
            for j in range(3):
                tilt[j] = 1 / (1 + 2 * t * lam[j])
                slope[j] = t * tilt[j]
            # ln det(I + 2tΛ)^{-1/2}, det(I + 2tΛ) - 1 = 2t (e_1 + 2t (e_2 + 2t e_3)) of the eigenvalues' elementary
            # symmetric polynomials (every term >= 0: no cancellation)
            log_det = -0.5 * math.log1p(2 * t * (elementary[1] + 2 * t * (elementary[2] + 2 * t * elementary[3])))
            top = -np.inf
            for p in range(count_p):
                exponents[p] = log_det - beta2[0, p] * slope[0] - beta2[1, p] * slope[1] - beta2[2, p] * slope[2]
                top = max(top, exponents[p])
            dead = not top > _NEGLIGIBLE_EXPONENT
            less = 0.0
            for p in range(count_p):
                e = exponents[p]
                less_one[p] = _exp_less_one(e) if e > _NEGLIGIBLE_EXPONENT else -1.0
                less += less_one[p]
            p0, p1, p2, p3, p4, p5 = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
            for p in range(count_p):
                weight = less_one[p]
                p0 += weight * products[p, 0]
                p1 += weight * products[p, 1]
                p2 += weight * products[p, 2]
                p3 += weight * products[p, 3]
                p4 += weight * products[p, 4]
                p5 += weight * products[p, 5]
            pairs[0], pairs[1], pairs[2] = p0 + base[0], p1 + base[1], p2 + base[2]
            pairs[3], pairs[4], pairs[5] = p3 + base[3], p4 + base[4], p5 + base[5]
            first -= less / math.sqrt(t)
            third += (less + t * second_sum) / (t * math.sqrt(t))
            weights = less + count_p  # Σ L(t)
            q = 0
            for i in range(3):  # t L(t) (S_t + m_t m_tᵀ) summed over patterns (dt = t du), in S's eigenvectors
                for j in range(i + 1):
                    if i == j:
                        inner[i, i] += t * (weights * lam[i] * tilt[i] + pairs[q] * tilt[i] * tilt[i])
                    else:
                        inner[i, j] += t * pairs[q] * tilt[i] * tilt[j]
                    q += 1
        for i in range(3):
            for j in range(3):
                total = 0.0
                for a in range(3):
                    for b in range(3):
                        entry = inner[a, b] if b <= a else inner[b, a]
                        total += vectors[i, a] * entry * vectors[j, b]
                out[4][k, i, j] = step * total / count_p
        first = step * (first / count_p + half + lower[0] - mean_fourth / 2 * lower[1] + mean_sixth / 6 * lower[2]
                        - mean_eighth / 24 * lower[3])
        third = step * (third / count_p + half - three_halves + mean_fourth / 2 * lower[0]
                        - mean_sixth / 6 * lower[1] + mean_eighth / 24 * lower[2] - mean_tenth / 120 * lower[3])
        out[0][k] = first / (2 * math.sqrt(math.pi)) * scale
        out[1][k] = scale2
        out[2][k] = 3 * third / (4 * math.sqrt(math.pi)) * scale2 * scale
        out[3][k] = mean_fourth * scale2 * scale2
    return out


@kernel
def root_with_tails(constant, lam, times, step, half, lower):
    """E√(a + Σ_i λ_i z_i²) (k,) of constants a (k,) >= 0 and λ (k, m) >= 0, as ``iso9283.gaussian_tests.
    _root_with_tails`` (:func:`_root`)."""
    out = np.empty(lam.shape[0])
    elementary = np.empty(lam.shape[1] + 1)
    for k in range(lam.shape[0]):
        total = 0.0
        for i in range(lam.shape[1]):
            total += lam[k, i]
        scale2 = max(constant[k] + total, _TINY)
        elementary[0] = 1.0
        elementary[1:] = 0.0
        for i in range(lam.shape[1]):  # e_j of λ / (a + Σ λ)
            unit = lam[k, i] / scale2
            for j in range(i + 1, 0, -1):
                elementary[j] += unit * elementary[j - 1]
        out[k] = _root(constant[k] / scale2, elementary, times, step, half, lower) * math.sqrt(scale2)
    return out


@kernel
def _root(ratio, elementary, times, step, half, lower):
    """E√Y of Y = a + Σ_i λ_i z_i² in units of E Y = a + Σ λ (``ratio`` a / E Y, ``elementary`` (m + 1,) the
    elementary symmetric polynomials e_0 = 1, e_1, ..., e_m of λ / E Y): the trapezoid rule of step ``step`` at the
    mixture grid's ``times`` e^u of the Laplace transform e^{-ta} det(I + 2tΛ)^{-1/2}, det(I + 2tΛ) = Σ_j (2t)^j e_j;
    above the grid (``half``) its tail t^{-1/2}, below it (``lower``: the sums of t^{1/2}, t^{3/2}, t^{5/2}, t^{7/2}
    over the nodes below) the series of 1 - e^{-tY} in E Y^k, from the power sums of λ (Newton's identities); e^x - 1
    by :func:`_exp_less_one`."""
    m = elementary.shape[0] - 1
    e1 = elementary[1] if m >= 1 else 0.0
    e2 = elementary[2] if m >= 2 else 0.0
    e3 = elementary[3] if m >= 3 else 0.0
    e4 = elementary[4] if m >= 4 else 0.0
    p2 = e1 * e1 - 2 * e2
    p3 = e1 * p2 - e2 * e1 + 3 * e3
    p4 = e1 * p3 - e2 * p2 + e3 * e1 - 4 * e4
    second = 1 + 2 * p2  # E Y^k from the cumulants κ_1 = 1, κ_r = 2^(r-1) (r-1)! p_r
    third = 1 + 6 * p2 + 8 * p3
    fourth = 1 + 12 * p2 + 12 * p2 * p2 + 32 * p3 + 48 * p4
    inner, dead = 0.0, False  # the exponent falls with t: once below e^-44, e^x - 1 is -1 exactly from there on
    for node in range(times.shape[0]):
        t = times[node]
        if dead:
            inner -= -1.0 / math.sqrt(t)
            continue
        grown = 0.0
        for j in range(m, 0, -1):
            grown = 2 * t * (elementary[j] + grown)
        exponent = -ratio * t - 0.5 * math.log1p(grown)
        dead = exponent < _NEGLIGIBLE_EXPONENT
        inner -= _exp_less_one(exponent) / math.sqrt(t)
    rule = step * (inner + half + lower[0] - second / 2 * lower[1] + third / 6 * lower[2] - fourth / 24 * lower[3])
    return rule / (2 * math.sqrt(math.pi))


@kernel
def symmetric_root(matrix, lam, vectors, root):
    """Into ``root`` (3, 3) the symmetric root V √max(Λ, 0) Vᵀ of the symmetric ``matrix`` (3, 3) (:func:`_jacobi`,
    its eigenvalues and vectors into ``lam`` (3,) and ``vectors`` (3, 3))."""
    _jacobi(matrix, lam, vectors)
    for i in range(3):
        for j in range(3):
            total = 0.0
            for m in range(3):
                total += vectors[i, m] * math.sqrt(max(lam[m], 0.0)) * vectors[j, m]
            root[i, j] = total


@kernel
def barycentre_shares(directions, pooled, cycles):
    """(k, 3) ascending eigenvalues of R U R / n, R the symmetric root of ``pooled`` Σ̄ (k, 3, 3), U ``directions``
    (k, 3, 3), n ``cycles``, as ``iso9283.gaussian_tests.barycentre_shares`` (:func:`_jacobi` for LAPACK)."""
    out = np.empty((pooled.shape[0], 3))
    lam = np.empty(3)
    vectors = np.empty((3, 3))
    root = np.empty((3, 3))
    half = np.empty((3, 3))
    product = np.empty((3, 3))
    for k in range(pooled.shape[0]):
        symmetric_root(pooled[k], lam, vectors, root)
        for i in range(3):
            for j in range(3):
                total = 0.0
                for m in range(3):
                    total += root[i, m] * directions[k, m, j]
                half[i, j] = total
        for i in range(3):
            for j in range(3):
                total = 0.0
                for m in range(3):
                    total += half[i, m] * root[m, j]
                product[i, j] = total
        _jacobi(product, out[k], vectors)
        for i in range(3):
            out[k, i] /= cycles
    return out


@kernel
def mixture_rp_l(m1, m2, m3, m4, directions, pooled, cycles, times, step, half, lower, share):
    """E[RP_l] (k,) [m] of tests of ``cycles`` cycles from one cycle's distance moments ``m1`` .. ``m4`` (k,) each
    [m^k] and the barycentre its cycles share (U ``directions``, Σ̄ ``pooled`` (k, 3, 3) [m²]), as
    ``iso9283.gaussian_tests.rp_l_from_moments(moments, cycles, barycentre_shares(directions, pooled, cycles))``'s
    mean: E√(a + εᵀ U ε) by :func:`_root` from the elementary symmetric polynomials of U Σ̄ / n (trace, principal
    minors, determinant: R U R's eigenvalues' without them), NaN where a is below ``share`` of a + tr(U Σ̄) / n (the
    NumPy path's quadrature then)."""
    n = cycles
    out = np.empty(m1.shape[0])
    product = np.empty((3, 3))
    elementary = np.empty(4)
    for k in range(m1.shape[0]):
        for i in range(3):
            for j in range(3):
                total = 0.0
                for m in range(3):
                    total += directions[k, i, m] * pooled[k, m, j]
                product[i, j] = total / n
        trace = product[0, 0] + product[1, 1] + product[2, 2]
        variance, _, _, factor = _delta_terms(m1[k], m2[k], m3[k], m4[k], n)
        trace = max(trace, 0.0)
        constant = max(variance - trace, 0.0)
        if not constant >= share * (constant + trace):
            out[k] = np.nan
            continue
        scale2 = max(constant + trace, _TINY)
        for i in range(3):
            for j in range(3):
                product[i, j] /= scale2
        a = product
        elementary[0], elementary[1] = 1.0, trace / scale2
        elementary[2] = max(a[0, 0] * a[1, 1] - a[0, 1] * a[1, 0] + a[0, 0] * a[2, 2] - a[0, 2] * a[2, 0]
                            + a[1, 1] * a[2, 2] - a[1, 2] * a[2, 1], 0.0)
        elementary[3] = max(a[0, 0] * (a[1, 1] * a[2, 2] - a[1, 2] * a[2, 1]) - a[0, 1] * (a[1, 0] * a[2, 2]
                            - a[1, 2] * a[2, 0]) + a[0, 2] * (a[1, 0] * a[2, 1] - a[1, 1] * a[2, 0]), 0.0)
        deviation = _root(constant / scale2, elementary, times, step, half, lower) * math.sqrt(scale2)
        out[k] = m1[k] + 3 * deviation * factor
    return out
