"""Greenwood-Williamson integrals and contact figures against quadrature and hand computation."""

import math

import numpy as np
import pytest
from scipy import integrate, special

from tribokin.tribology import gw
from tribokin.tribology.gw import gw_F


def quadrature_F(n, h):
    """F_n(h) by direct quadrature, substituting s = h + t."""
    value, _ = integrate.quad(lambda t: t ** n * math.exp(-(h + t) ** 2 / 2), 0, np.inf, epsabs=0, epsrel=1e-12)
    return value / math.sqrt(2 * math.pi)


@pytest.mark.parametrize("n", [0, 1, 1.5, 2, 3])
@pytest.mark.parametrize("h", [-2.0, -0.5, 0.0, 0.7, 2.0, 4.0])
def test_F_against_quadrature(n, h):
    assert gw_F(n, h) == pytest.approx(quadrature_F(n, h), rel=1e-8)


def test_F_closed_forms_and_vectorised():
    h = np.linspace(-3, 4, 15)
    phi = np.exp(-h * h / 2) / math.sqrt(2 * math.pi)
    F0 = 0.5 * special.erfc(h / math.sqrt(2))
    np.testing.assert_allclose(gw_F(0, h), F0, rtol=1e-10)
    np.testing.assert_allclose(gw_F(1, h), phi - h * F0, rtol=1e-8)
    np.testing.assert_allclose(gw_F(2, h), (1 + h * h) * F0 - h * phi, rtol=1e-8)
    assert gw_F(np.array([0, 1, 2]), 0.0).shape == (3,)


def test_gw_figures_by_hand_at_zero_separation():
    # At h = 0: F_0 = 1/2, F_1 = 1/sqrt(2 pi), F_3/2 = 2^(1/4) Gamma(5/4) / sqrt(2 pi).
    eta, area, radius, sigma, modulus = 1e9, 1e-6, 50e-6, 0.5e-6, 115e9
    assert gw.contact_count(eta, area, 0.0) == pytest.approx(500.0)
    assert gw.real_area(eta, area, radius, sigma, 0.0) == pytest.approx(
        math.pi * 1000 * 50e-6 * 0.5e-6 / math.sqrt(2 * math.pi))                 # 3.133e-8 m^2
    f32 = 2 ** 0.25 * math.gamma(1.25) / math.sqrt(2 * math.pi)
    assert gw.load(eta, area, radius, sigma, 0.0, modulus) == pytest.approx(
        4 / 3 * 1000 * 115e9 * math.sqrt(50e-6) * 0.5e-6 ** 1.5 * f32)           # 383.4 N * 0.4300 = 164.8 N
    assert gw.load(eta, area, radius, sigma, 0.0, modulus) == pytest.approx(164.8, rel=1e-3)


def test_hertz_and_plasticity_index():
    assert gw.hertz_load(1e-4, 1e-6, 115e9) == pytest.approx(4 / 3 * 115e9 * 1e-2 * 1e-9)   # 1.533 N
    assert gw.hertz_area(1e-4, 1e-6) == pytest.approx(math.pi * 1e-10)
    assert gw.hertz_load(1e-4, -1e-6, 115e9) == 0 and gw.hertz_area(1e-4, -1e-6) == 0
    assert gw.plasticity_index(115e9, 2.9e9, 0.5e-6, 50e-6) == pytest.approx(115 / 2.9 * 0.1)
