"""Profile statistics against spectral theory, exact geometry and closed forms."""

import dataclasses
import math
import warnings

import numpy as np
import pytest
from scipy import stats

from tribokin.errors import InputError
from tribokin.tribology.surfaces import RADIUS_UNIT_M, analyse_profile, peak_curvatures
from tribokin.tribology.synthetic import REFERENCE_PROFILES, synthetic_profile

ELL = 10e-6


def test_peak_density_of_gaussian_profile_matches_rice_nayak():
    # Gaussian ACF exp(-tau^2/l^2): m2 = 2/l^2, m4 = 12/l^4, D_1 = sqrt(m4/m2)/(2 pi)
    m2, m4 = 2 / ELL ** 2, 12 / ELL ** 4
    D1 = math.sqrt(m4 / m2) / (2 * math.pi)
    recipe = dataclasses.replace(REFERENCE_PROFILES["ground"], points=100_000, seed=11, spacing_m=0.5e-6)
    surface = analyse_profile(*synthetic_profile(recipe))
    assert 1 / surface.AR_m == pytest.approx(D1, rel=0.03)
    assert surface.summit_density_m2 == pytest.approx(1.2 * D1 ** 2, rel=0.06)
    assert surface.summit_density_m2 == pytest.approx(m4 / (6 * math.pi * math.sqrt(3) * m2), rel=0.06)


def test_sinusoid_peaks_spacing_altitude_and_radius():
    amplitude, wavelength = 1e-6, 100e-6
    x = np.arange(0, 2e-3, 0.5e-6)
    z = amplitude * np.cos(2 * np.pi * x / wavelength) + 3e-7 + 1e-4 * x     # offset and tilt are levelled out
    surface = analyse_profile(x, z)
    assert surface.AR_m == pytest.approx(wavelength, rel=1e-9)
    assert surface.Alt_m == pytest.approx(amplitude, rel=1e-3)
    radius = 1 / (amplitude * (2 * np.pi / wavelength) ** 2)                # 253.3 µm
    assert math.exp(surface.radius_b) * RADIUS_UNIT_M == pytest.approx(radius, rel=1e-3)
    assert surface.radius_a < 1e-3


def test_parabola_curvature_exact_on_non_uniform_grid():
    x = np.cumsum(np.random.default_rng(0).uniform(0.5, 1.5, 9))
    z = -3.0 * (x - x[4]) ** 2 + 2.0
    assert peak_curvatures(x, z, np.array([4]))[0] == pytest.approx(-6.0)


def test_asperity_count_equation_6_against_closed_form():
    surface = analyse_profile(*synthetic_profile(REFERENCE_PROFILES["ground"]))
    z1, z2 = surface.Alt_m, surface.Alt_m + 2 * surface.SAlt_m
    r1, r2 = 20e-6, 60e-6
    expected = (1.2 * 1e-6 / surface.AR_m ** 2
                * (stats.norm.cdf(2) - stats.norm.cdf(0))
                * (stats.norm.cdf((math.log(60) - surface.radius_b) / surface.radius_a)
                   - stats.norm.cdf((math.log(20) - surface.radius_b) / surface.radius_a)))
    assert surface.asperity_count(1e-6, (z1, z2), (r1, r2)) == pytest.approx(expected, rel=1e-12)
    assert surface.asperity_count(1e-6) == pytest.approx(surface.summit_density_m2 * 1e-6, rel=1e-12)
    far = surface.asperity_count(1e-6, (surface.Alt_m + 9 * surface.SAlt_m, np.inf))  # 1 - cdf would give 0 here
    assert far == pytest.approx(1.2 * 1e-6 / surface.AR_m ** 2 * stats.norm.sf(9), rel=1e-9)
    low = surface.asperity_count(1e-6, radius_range_m=(0.0, 1e-9))  # radii below 1 nm: the lognormal's lower tail
    assert low == pytest.approx(1.2 * 1e-6 / surface.AR_m ** 2
                                * stats.norm.cdf((math.log(1e-3) - surface.radius_b) / surface.radius_a), rel=1e-9)


def test_too_few_peaks_is_an_input_error():
    x = np.linspace(0, 1e-3, 100)
    with pytest.raises(InputError, match="peaks"):
        analyse_profile(x, 1e-6 * np.sin(2 * np.pi * x / 5e-4))


def test_subnormal_heights_are_one_input_error_without_warnings():
    x = np.arange(200) * 1e-6
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a warning would be a second line on stderr
        with pytest.raises(InputError, match="summit statistics are not finite numbers of some spread") as error:
            analyse_profile(x, 1e-310 * np.sin(x / 3e-6), "p.csv")
    assert error.value.source == "p.csv" and error.value.key == "z_m"
