"""E|c + w| at the extremes of size: closed forms (a point, the Maxwell distribution) from 1e-300 to 1e300 m; E[RP_l]
against the moments of an isotropic and a one-dimensional Gaussian; each on both kernel paths, and the compiled
kernels (:mod:`tribokin.iso9283.gaussian_tests_kernels`) against NumPy's (SciPy's Carlson integrals, LAPACK's
eigenvalues)."""

import math
import os
import subprocess
import sys
from statistics import NormalDist

import numpy as np
import pytest
from scipy.stats import wishart

from tribokin.iso9283.gaussian_tests import (
    barycentre_shares,
    eigenvalues,
    expected_norm,
    expected_rp_l,
    expected_semi_axis,
    gaussian_band_skewness,
    gaussian_products,
    largest_eigenvalue,
    rp_l_from_moments,
    skewed_band,
)
from tribokin.iso9283.metrics import position_repeatability

#: E|w| of w ~ N(0, σ² I₃) over σ: the mean of the Maxwell distribution, 2 √(2/π).
MAXWELL_MEAN = 2 * math.sqrt(2 / math.pi)


@pytest.mark.parametrize("size", [1e-300, 1e-150, 1e-9, 1.0, 1e150, 1e300])
def test_a_point_and_an_isotropic_cloud_keep_their_closed_forms_at_any_size(size, kernel_path):
    centre = np.array([[0.6, -0.8, 0.0]]) * size  # |c| = size
    assert expected_norm(centre, np.zeros((1, 3, 3)))[0] == pytest.approx(size, rel=1e-15, abs=0)
    sigma = min(max(size, 1e-150), 1e150)  # σ² must be a float
    variance = np.eye(3)[None] * sigma * sigma
    # the log-scale trapezoid rule's own error: 2e-8 here
    assert expected_norm(np.zeros((1, 3)), variance)[0] == pytest.approx(MAXWELL_MEAN * sigma, rel=5e-8, abs=0)


@pytest.mark.parametrize("scale", [1e-150, 1e-20, 1e20, 1e150])
def test_scaling_a_cloud_scales_its_expected_distance(scale, kernel_path):
    centre = np.array([[0.3, -0.2, 0.5], [2.0, 0.1, 0.0]])
    covariance = np.array([[[0.2, 0.05, 0], [0.05, 0.1, 0.02], [0, 0.02, 0.3]], np.diag([1e-4, 2e-4, 5e-5])])
    scaled = expected_norm(scale * centre, covariance * scale * scale)
    np.testing.assert_allclose(scaled / scale, expected_norm(centre, covariance), rtol=1e-14)


def test_no_deviation_is_no_distance(kernel_path):
    assert np.array_equal(expected_norm(np.zeros((2, 3)), np.zeros((2, 3, 3))), [0.0, 0.0])


#: E|z|^k, k = 1..4, of a standard normal: in 3-D (the chi distribution of 3 degrees) and in 1-D.
ISOTROPIC_MOMENTS = (MAXWELL_MEAN, 3.0, 4 * MAXWELL_MEAN, 15.0)
LINE_MOMENTS = (math.sqrt(2 / math.pi), 1.0, 2 * math.sqrt(2 / math.pi), 3.0)


@pytest.mark.parametrize("cycles", [10, 1000])
@pytest.mark.parametrize("sigma", [1e-150, 1e-6, 1e150])
def test_expected_rp_l_of_an_isotropic_and_a_one_dimensional_cloud_follows_their_moments(cycles, sigma, kernel_path):
    """E[RP_l] and its spread from the Carlson integrals (isotropic: R_F = R_D = R_G = 1; along one axis the
    integrals diverge where two eigenvalues vanish and their difference carries the moments) against the delta method
    on the exact moments of |w| ((n - 1)/n of the covariance about the barycentre)."""
    shrink = (cycles - 1) / cycles
    for lam, moments in (([1.0, 1.0, 1.0], ISOTROPIC_MOMENTS), ([0.0, 1.0, 0.0], LINE_MOMENTS)):
        mean, spread = rp_l_from_moments(tuple(m * shrink ** (k / 2) for k, m in enumerate(moments, start=1)), cycles)
        got_mean, got_spread = expected_rp_l(np.array([lam]) * sigma ** 2, cycles)  # both scale as σ
        assert got_mean[0] == pytest.approx(mean * sigma, rel=1e-10)  # along one axis: 1e-11, the eigenvalue floor
        assert got_spread[0] == pytest.approx(spread * sigma, rel=1e-10)


def with_path(monkeypatch, path, function, *args):
    monkeypatch.setenv("TRIBOKIN_KERNELS", path)
    return function(*args)


def covariances(rng, count):
    """Covariances J diag(v) Jᵀ of six joints, of rank 3, 2 (a zero row and column) and 1, and diagonal ones."""
    jacobians = rng.normal(size=(count, 3, 6))
    jacobians[count // 4:count // 2, 2] = 0.0
    jacobians[count // 2:3 * count // 4, 1:] = 0.0
    out = np.einsum("kin,kn,kjn->kij", jacobians, rng.uniform(0, 1, (count, 6)), jacobians)
    out[-5:] = [np.eye(3), np.zeros((3, 3)), np.diag([1.0, 1e-12, 3.0]), np.diag([2.0, 2.0, 1e-300]), np.eye(3) * 7]
    return out


def test_the_compiled_closed_forms_agree_with_numpy(monkeypatch):
    """Eigenvalues (Jacobi against LAPACK, to 1e-14 of the largest), E[RP_l] and its spread from the eigenvalues
    (rank 3 to 0, n = 10 to 1000), the band's skewness (n = 500 and 1000) and E|c + w| (its expansion and its
    quadrature, at sizes from 1e-300 to 1e300 m) compiled against NumPy: to 1e-12."""
    rng = np.random.default_rng(21)
    matrices = covariances(rng, 400)
    lapack, jacobi = (with_path(monkeypatch, path, eigenvalues, matrices) for path in ("numpy", "compiled"))
    assert np.all(np.abs(jacobi - lapack) <= 1e-14 * np.abs(lapack).max(axis=1, keepdims=True))
    for cycles in (10, 30, 1000):
        for got, expected in zip(*(with_path(monkeypatch, path, expected_rp_l, lapack * 1e-12, cycles)
                                   for path in ("compiled", "numpy")), strict=True):
            np.testing.assert_allclose(got, expected, rtol=1e-12, atol=0)
    for cycles in (500, 1000):
        got, expected = (with_path(monkeypatch, path, gaussian_band_skewness, lapack * 1e-12, cycles)
                         for path in ("compiled", "numpy"))
        np.testing.assert_allclose(got, expected, rtol=1e-12, atol=0)
    centres = rng.normal(size=(400, 3)) * np.exp(rng.uniform(-8, 3, (400, 1)))  # about and beyond the expansion
    for size in (1e-300, 1e-150, 1e-6, 1.0, 1e150, 1e300):
        spread = matrices * size * size if 1e-150 <= size <= 1e150 else np.zeros_like(matrices)
        got, expected = (with_path(monkeypatch, path, expected_norm, centres * size, spread)
                         for path in ("compiled", "numpy"))
        np.testing.assert_allclose(got, expected, rtol=1e-12, atol=0)
    pairs = (centres[:12].reshape(6, 2, 3), matrices[:6, None])  # a batch of (6, 2) broadcast from both
    got, expected = (with_path(monkeypatch, path, expected_norm, *pairs) for path in ("compiled", "numpy"))
    assert got.shape == (6, 2)
    np.testing.assert_allclose(got, expected, rtol=1e-12, atol=0)


def test_the_shape_table_alone_imports_scipy_interpolate():
    """The import takes about 0.1 s; runs of ASYMPTOTIC_CYCLES cycles or more use no table."""
    code = ("import sys, numpy as np; from tribokin.iso9283.gaussian_tests import ShapeTable; "
            "assert 'scipy.interpolate' not in sys.modules, 'imported'; "
            "ShapeTable.simulate(30, np.random.default_rng(0)).at(np.array([0.5, 0.5])); "
            "assert 'scipy.interpolate' in sys.modules, 'never imported'")
    subprocess.run([sys.executable, "-c", code], check=True, env=os.environ | {"PYTHONPATH": os.pathsep.join(sys.path)})


def mixture_points(columns: np.ndarray, covariance: np.ndarray, count: int, rng) -> np.ndarray:
    """``count`` points Σ s_i b_i + w of one target's mixture, drawn (signs ±1 with equal odds, w ~ N(0, S))."""
    signs = rng.choice([-1.0, 1.0], size=(count, len(columns)))
    return signs @ columns + rng.multivariate_normal(np.zeros(3), covariance, size=count)


def test_a_sign_mixtures_moments_and_directions_agree_with_a_monte_carlo_of_the_mixture(kernel_path):
    """E|x|^k, k = 1..4, and each entry of U = E[x xᵀ / |x|²] of x = Σ s_i b_i + w over the 2^(m - 1) sign patterns
    against 400 000 draws of the mixture, each within 4.5 of its standard errors: four columns with noise small, and
    large, against them; U's trace 1 to 1e-6."""
    from tribokin.iso9283.gaussian_tests import sign_mixture

    rng = np.random.default_rng(5)
    columns = rng.standard_normal((2, 4, 3)) * 1e-5
    roots = rng.standard_normal((2, 3, 3)) * np.array([2e-7, 1e-5])[:, None, None]
    covariance = roots @ np.swapaxes(roots, 1, 2)
    moments, directions = sign_mixture(columns, covariance)
    np.testing.assert_allclose(np.trace(directions, axis1=1, axis2=2), 1.0, atol=1e-6)
    for k in range(2):
        points = mixture_points(columns[k], covariance[k], 400_000, rng)
        norms = np.linalg.norm(points, axis=1)
        for power, moment in enumerate(moments, start=1):
            values = norms ** power
            assert abs(moment[k] - values.mean()) <= 4.5 * values.std() / math.sqrt(len(values)), (k, power)
        units = points / norms[:, None]
        products = units[:, :, None] * units[:, None, :]
        tolerance = 4.5 * products.std(axis=0) / math.sqrt(len(points))
        assert np.all(np.abs(directions[k] - products.mean(axis=0)) <= tolerance), k


def test_a_sign_mixture_without_columns_has_a_gaussians_moments_and_compiled_agrees_with_numpy(monkeypatch):
    """No columns (or columns of zeros): the moments of w alone (:func:`norm_moments`, Carlson's integrals) to 1e-10;
    the two kernel paths agree to 1e-12 on a 6-column mixture (32 patterns, the compiled path's Gray-code order), its
    directions U to 1e-12 of their largest entry."""
    from tribokin.iso9283.gaussian_tests import norm_moments, sign_mixture

    covariance = np.array([[[2.0, 0.3, 0.1], [0.3, 1.0, -0.2], [0.1, -0.2, 0.5]]]) * 1e-12
    rng = np.random.default_rng(6)
    columns = rng.standard_normal((3, 6, 3)) * 1e-6
    columns[1, 2] = 0.0  # a joint that adds no lost motion
    spread = np.repeat(covariance, 3, axis=0) * np.array([1.0, 1e-4, 1e4])[:, None, None]
    results = {}
    for path in ("numpy", "compiled"):
        monkeypatch.setenv("TRIBOKIN_KERNELS", path)
        alone = sign_mixture(np.zeros((1, 2, 3)), covariance)[0]
        for moment, expected in zip(alone, norm_moments(np.linalg.eigvalsh(covariance)), strict=True):
            assert moment == pytest.approx(expected, rel=1e-10)
        results[path] = sign_mixture(columns, spread)
    for numpy_moment, compiled_moment in zip(results["numpy"][0], results["compiled"][0], strict=True):
        np.testing.assert_allclose(compiled_moment, numpy_moment, rtol=1e-12)
    np.testing.assert_allclose(results["compiled"][1], results["numpy"][1], rtol=0, atol=1e-12)


def test_a_sign_mixtures_series_below_its_grid_agrees_with_the_same_rule_carried_further_down():
    """The series in t that stands for :func:`sign_mixture`'s nodes below ``SIGN_LOG_START`` (u = -4.5) against the
    same trapezoid rule carried down to u = -20 (the series below it less than 1e-25 of the integral's): E|x| and
    E|x|³ to 2e-10 (1.4e-10 here: the first terms the series leave out), U to 1e-8 (second order in t below the grid;
    5e-7 off without its third term), on mixtures with offsets far beyond the noise (a map's), about as large, and
    none with anisotropic noise."""
    from tribokin.iso9283 import gaussian_tests as gt

    rng = np.random.default_rng(7)
    columns = rng.standard_normal((3, 6, 3)) * np.array([16.0, 1.0, 0.0])[:, None, None]
    roots = rng.standard_normal((3, 3, 3)) * np.array([[1.0, 0.3, 0.01]])
    covariance = roots @ np.swapaxes(roots, 1, 2)
    columns, covariance = columns / 40, covariance / 1600  # to order one, as sign_mixture scales them
    deeper = np.exp(np.arange(-20.0, gt.MIXTURE_LOG_RANGE + 1e-9, gt.MIXTURE_LOG_STEP))
    series = gt._mixture_block(columns, covariance, np.exp(gt._SIGN_LOGS), gt._mixture_tails(),
                               gt._lower_tails(gt.SIGN_LOG_START))
    carried = gt._mixture_block(columns, covariance, deeper, gt._mixture_tails(), gt._lower_tails(-20.0))
    assert gt.SIGN_LOG_START == -4.5
    np.testing.assert_allclose(series[0], carried[0], rtol=2e-10)
    np.testing.assert_allclose(series[2], carried[2], rtol=2e-10)
    np.testing.assert_allclose(series[4], carried[4], rtol=0, atol=1e-8)


def test_the_expected_maximum_of_three_normals_agrees_with_a_monte_carlo_and_ignores_their_order():
    """E[max(Y_1, Y_2, Y_3)] against 10^6 draws (within 4.5 standard errors) for correlated, degenerate (one Y
    constant) and noiseless normals, and the same to 1e-12 whichever Y comes first."""
    from tribokin.iso9283.gaussian_tests import expected_maximum

    rng = np.random.default_rng(7)
    roots = rng.standard_normal((3, 3, 3))
    covariance = roots @ np.swapaxes(roots, 1, 2)
    covariance[1, 2, :] = covariance[1, :, 2] = 0.0  # Y_3 constant
    covariance[2] = 0.0  # no noise: the largest mean
    means = np.array([[0.1, -0.3, 0.2], [1.0, 1.2, 1.1], [1.0, 3.0, 2.0]])
    expected = expected_maximum(means, covariance)
    assert expected[2] == 3.0
    for k in range(2):
        largest = rng.multivariate_normal(means[k], covariance[k], size=1_000_000).max(axis=1)
        assert abs(expected[k] - largest.mean()) <= 4.5 * largest.std() / 1000
    for order in ([1, 0, 2], [2, 1, 0], [0, 2, 1]):
        np.testing.assert_allclose(expected_maximum(means[:, order], covariance[:, order][:, :, order]), expected,
                                   rtol=1e-12)



def test_the_expected_maximum_leaves_a_normal_far_below_the_others_out(monkeypatch):
    """Where one Y lies ``MAXIMUM_SPAN`` standard deviations below both others (two approach directions with the same
    joint signs: their distance about 0), E[max Y] is the other two's in closed form: against a direct integral of
    the largest of those two to 1e-12 (where the quadrature over D is 5e-5 off: W given D spreads far less than D),
    on both kernel paths, the same whichever Y is low, and about the same (1e-12) just within the span, by
    quadrature."""
    from scipy import integrate

    from tribokin.iso9283.gaussian_tests import MAXIMUM_SPAN, expected_maximum

    covariance = np.array([[0.0025, 0.0, 0.0], [0.0, 0.1527, 0.058], [0.0, 0.058, 0.0226]])
    means = np.array([5.49, 10.0, 10.0389])
    spread = math.sqrt(covariance[1, 1] + covariance[2, 2] - 2 * covariance[1, 2])
    gap = means[1] - means[2]
    direct = means[2] + integrate.quad(lambda x: max(x, 0.0) * math.exp(-(x - gap) ** 2 / (2 * spread ** 2)),
                                       gap - 12 * spread, gap + 12 * spread, points=[0.0], epsabs=0,
                                       epsrel=1e-13)[0] / (spread * math.sqrt(2 * math.pi))
    for path in ("numpy", "compiled"):
        monkeypatch.setenv("TRIBOKIN_KERNELS", path)
        for order in ([0, 1, 2], [1, 0, 2], [2, 1, 0]):
            found = expected_maximum(means[None, order], covariance[None][:, order][:, :, order])[0]
            assert found == pytest.approx(direct, rel=1e-12, abs=0), (path, order)
        below = means[1] - MAXIMUM_SPAN * math.sqrt(2 * 0.0025)  # at the span's edge
        edges = [expected_maximum(np.array([[low, means[1], means[1] + 0.5]]), np.diag([0.0025, 0.0025, 0.0025])[None]
                                  )[0] for low in (below - 1e-9, below + 1e-9)]
        assert edges[0] == pytest.approx(edges[1], rel=1e-12, abs=0)

def test_the_largest_eigenvalue_in_closed_form_is_lapacks():
    """Sample covariances of 5 Gaussian cycles (the shape table's) scaled to every shape, and the cases where the
    cubic's angle is ill-conditioned: two eigenvalues equal (largest or not), three equal, a zero and a rank-one
    matrix, axis-aligned and turned, and extremes of scale."""
    rng = np.random.default_rng(3)
    draws = rng.standard_normal((4000, 5, 3))
    draws -= draws.mean(axis=1, keepdims=True)
    covariances = np.einsum("tni,tnj->tij", draws, draws) / 4
    turn = np.linalg.qr(rng.standard_normal((3, 3)))[0]
    special = [np.diag(d) for d in ([2.0, 2.0, 1.0], [2.0, 1.0, 1.0], [3.0, 3.0, 3.0], [0.0, 0.0, 0.0],
                                    [5.0, 0.0, 0.0], [1e-300, 1e-300, 2e-300], [1e150, 1.0, 0.0])]
    special += [turn @ m @ turn.T for m in special[:3]] + [np.outer([1.0, 2.0, 3.0], [1.0, 2.0, 3.0])]
    for a in np.linspace(0.0, 1.0, 5):
        for b in np.linspace(0.0, 1.0, 5):
            scale = np.array([1.0, a, a * b])
            matrices = np.concatenate([covariances * np.outer(scale, scale), np.array(special)])
            lapack = np.linalg.eigvalsh(matrices)[:, -1]
            np.testing.assert_allclose(largest_eigenvalue(matrices), lapack, rtol=2e-14, atol=0.0)


def test_the_expected_root_on_both_grids_keeps_its_closed_forms_and_a_direct_integral(kernel_path):
    """E√(a + Σ λ_i z_i²): √a where every λ is 0 (the coarse grid with its tails, to 1e-9) and √(2λ/π) where a is
    (the fine grid without its tail beyond t = e^36: to 5e-8), and E√(a + λ z²) against scipy's quad over z on the
    coarse grid (a ample) to 1e-9."""
    from scipy.integrate import quad

    from tribokin.iso9283.gaussian_tests import expected_root

    roots = expected_root(np.array([2.0, 0.0, 3e-12]), np.array([[0.0, 0.0, 0.0], [0.7, 0.0, 0.0], [1e-12, 0.0, 0.0]]))
    direct = quad(lambda z: math.sqrt(3e-12 + 1e-12 * z * z) * math.exp(-z * z / 2), -40, 40, epsabs=0,
                  epsrel=1e-13)[0] / math.sqrt(2 * math.pi)
    np.testing.assert_allclose(roots[[0, 2]], [math.sqrt(2.0), direct], rtol=1e-9)
    assert roots[1] == pytest.approx(math.sqrt(1.4 / math.pi), rel=5e-8)


@pytest.mark.parametrize("lam", [(1.0, 0.05, 0.01), (1.0, 1.0, 0.1), (1.0, 0.99, 1e-6)])
def test_the_expected_largest_semi_axis_of_500_gaussian_cycles_agrees_with_wishart_draws(lam):
    """E√λ̂₁ of one test's sample covariance (n - 1) over tests of 500 Gaussian cycles against 200 000 draws of it
    (scipy's Wishart, n - 1 degrees of freedom): within 4 standard errors (about 6e-5 of √λ₁), where the two largest
    eigenvalues are far apart (the bias -1/(4n) of a square root) and where they meet (+2.7 %: the perturbation
    series' bias diverges there)."""
    cycles, lam = 500, np.array(lam)
    draws = wishart(df=cycles - 1, scale=np.diag(lam) / (cycles - 1)).rvs(size=200_000,
                                                                           random_state=np.random.default_rng(5))
    largest = np.sqrt(np.linalg.eigvalsh(draws)[:, -1])
    expected = expected_semi_axis(lam[None], gaussian_products(lam[None]), cycles)[0]
    assert abs(expected - largest.mean()) <= 4 * largest.std() / math.sqrt(len(largest))
    assert abs(largest.mean() - math.sqrt(lam[0])) > 4 * largest.std() / math.sqrt(len(largest))  # a bias to find


def test_a_band_without_skewness_is_the_normal_band_and_skewness_moves_both_ends_up():
    mean, spread = np.array([10.0, 2.0]), np.array([0.5, 0.1])
    z = NormalDist().inv_cdf(0.975)
    np.testing.assert_allclose(skewed_band(mean, spread, np.zeros(2)), (mean - z * spread, mean + z * spread),
                               rtol=1e-15)
    low, high = skewed_band(mean, spread, np.full(2, 0.2))
    np.testing.assert_allclose(low, mean + spread * (-z + (z * z - 1) * 0.2 / 6), rtol=1e-14)
    np.testing.assert_allclose(high, mean + spread * (z + (z * z - 1) * 0.2 / 6), rtol=1e-14)


def test_the_compiled_barycentre_shares_and_expected_root_agree_with_numpy(monkeypatch):
    """The shares U Σ̄ / n (Jacobi against LAPACK: to 1e-13 of the largest, U of rank 3 to 1, Σ̄ of rank 3 to 0) and
    E√(a + εᵀ U ε) on the coarse grid (a ample; λ from 0 to a's size, a from 1e-300 to 1e300 m²) compiled against
    NumPy: to 1e-14."""
    from tribokin.iso9283.gaussian_tests import barycentre_shares, expected_root

    rng = np.random.default_rng(37)
    pooled = covariances(rng, 400) * 1e-12
    units = rng.normal(size=(400, 3, 3)) * (np.arange(3) < rng.integers(1, 4, (400, 1)))[:, None, :]
    directions = units @ np.swapaxes(units, 1, 2)
    directions /= np.trace(directions, axis1=1, axis2=2)[:, None, None]
    got, expected = (with_path(monkeypatch, path, barycentre_shares, directions, pooled, 1000)
                     for path in ("compiled", "numpy"))
    assert np.all(np.abs(got - expected) <= 1e-13 * np.abs(expected).max(axis=1, keepdims=True))
    for size in (1e-300, 1e-12, 1.0, 1e300):
        constant = rng.uniform(0.5, 2.0, 400) * size
        lam = np.sort(rng.uniform(0, 1, (400, 3)) * 10.0 ** rng.uniform(-8, 0, (400, 3)), axis=1) * size
        lam[:20] = 0.0
        got, expected = (with_path(monkeypatch, path, expected_root, constant, lam) for path in ("compiled", "numpy"))
        np.testing.assert_allclose(got, expected, rtol=1e-14, atol=0)



def test_rp_l_from_a_mixture_in_one_kernel_agrees_with_its_shares_and_root_on_numpy(monkeypatch):
    """E[RP_l] from a cycle's four moments and the barycentre its cycles share (U, Σ̄), compiled in one kernel per
    target (U Σ̄ / n's trace, principal minors and determinant for R U R's eigenvalues) against the NumPy path's
    :func:`barycentre_shares` and :func:`rp_l_from_moments`: to 1e-12, at sizes from 1e-60 to 1e60 m, where the
    constant a is ample (the grid's root) and where it is not (the NumPy quadrature, which the kernel leaves to it)."""
    from tribokin.iso9283.gaussian_tests import rp_l_from_mixture

    rng = np.random.default_rng(41)
    pooled = covariances(rng, 400)
    units = rng.normal(size=(400, 3, 3)) * (np.arange(3) < rng.integers(1, 4, (400, 1)))[:, None, :]
    directions = units @ np.swapaxes(units, 1, 2)
    directions /= np.trace(directions, axis1=1, axis2=2)[:, None, None]
    m1 = rng.uniform(1.0, 2.0, 400)
    m2 = m1 ** 2 * (1 + rng.uniform(0.01, 0.3, 400))
    m2[:40] = m1[:40] ** 2 + np.trace(pooled[:40] @ directions[:40], axis1=1, axis2=2) / 1000 * 1.000001  # a ≈ 0
    m3, m4 = m1 * m2 * 1.1, m2 ** 2 * 1.3
    for size in (1e-60, 1e-6, 1.0, 1e60):
        moments = (m1 * size, m2 * size ** 2, m3 * size ** 3, m4 * size ** 4)
        got, expected = (with_path(monkeypatch, path, rp_l_from_mixture, moments, directions, pooled * size ** 2,
                                   1000) for path in ("compiled", "numpy"))
        np.testing.assert_allclose(got, expected, rtol=1e-12, atol=0)
    monkeypatch.setenv("TRIBOKIN_KERNELS", "numpy")
    shares = barycentre_shares(directions, pooled, 1000)
    variance = m2 - m1 ** 2
    assert np.sum(variance - shares.sum(axis=1) < 1e-5 * variance) >= 20  # the quadrature's targets are there

def test_the_sixth_order_norm_moments_keep_the_half_normal_and_maxwell_closed_forms():
    """E|w|⁵ and E|w|⁶ (Stein's lemma; a polynomial) of a one-dimensional and an isotropic cloud: 8 √(2/π) and 15,
    and the chi law of three degrees' 2^(5/2) Γ(4) / Γ(3/2) and 105."""
    from tribokin.iso9283.gaussian_tests import _unit_moments

    line = _unit_moments(np.array([1.0, 1e-12, 1e-12]), order=6)
    assert line[4] == pytest.approx(8 * math.sqrt(2 / math.pi), rel=1e-9) and line[5] == pytest.approx(15, rel=1e-9)
    ball = _unit_moments(np.ones(3), order=6)
    assert ball[4] == pytest.approx(2 ** 2.5 * math.gamma(4) / math.gamma(1.5), rel=1e-13)
    assert ball[5] == pytest.approx(105, rel=1e-13)


@pytest.mark.parametrize("lam", [(1.0, 0.3, 0.05), (1.0, 1e-6, 1e-6)])
def test_the_band_skewness_of_gaussian_tests_agrees_with_simulated_tests(lam):
    """The skewness of one test's RP_l over 12 000 simulated tests of 500 Gaussian cycles (its standard error about
    0.022) against the closed form's (0.04-0.06): within 0.07, and the normal band's 0 more than 1.5 standard errors
    off."""
    cycles, lam = 500, np.array(lam)
    rng = np.random.default_rng(8)
    rp_l = np.concatenate([position_repeatability(rng.standard_normal((2_000, cycles, 3)) * np.sqrt(lam))[0]
                           for _ in range(6)])
    skewness = float(np.mean((rp_l - rp_l.mean()) ** 3) / rp_l.std() ** 3)
    closed = gaussian_band_skewness(lam[None], cycles)[0]
    assert closed == pytest.approx(skewness, abs=0.07) and skewness > 1.5 * math.sqrt(6 / len(rp_l))
