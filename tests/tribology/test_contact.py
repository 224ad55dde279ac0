"""Mixed-lubrication friction: Monte Carlo asperity loads against GW, and the regime limits."""

import math

import numpy as np
import pytest
from scipy import integrate

from tribokin.tribology import gw
from tribokin.tribology.contact import Lubrication, asperity_loads, friction_per_cycle
from tribokin.tribology.surfaces import SurfaceStatistics

SURFACE = SurfaceStatistics("test", 4e-3, 0.8e-6, 150, 25e-6, 1.2 / 25e-6 ** 2, 0.5e-6, 0.7e-6, 0.6, math.log(40))


def test_mean_asperity_load_is_the_gw_load():
    separation = 1.2e-6
    loads = asperity_loads(SURFACE, 1e-6, separation, 4000, np.random.default_rng(0))
    # E[sqrt(R)] of the lognormal radius law by quadrature, R = 1 µm * R*
    law = SURFACE.radius_law()
    mean_sqrt_r, _ = integrate.quad(lambda r: math.sqrt(r) * law.pdf(r), 0, 5e-3, points=[40e-6], limit=200)
    h = (separation - SURFACE.Alt_m) / SURFACE.SAlt_m
    expected = gw.load(SURFACE.summit_density_m2, 1e-6, mean_sqrt_r ** 2, SURFACE.SAlt_m, h, 115e9)
    assert loads.mean() == pytest.approx(expected, rel=4 * loads.std() / math.sqrt(4000) / expected)
    assert loads.std() > 0


def test_regime_limits():
    rng = np.random.default_rng(1)
    mu, share = friction_per_cycle(SURFACE, 150.0, 1e-6, Lubrication(20e-6), 200, rng)   # film far above summits
    np.testing.assert_array_equal(share, 0)
    np.testing.assert_allclose(mu, 0.09)
    mu, share = friction_per_cycle(SURFACE, 1e-3, 1e-6, Lubrication(0.5e-6), 200, rng)   # tiny load: boundary
    np.testing.assert_array_equal(share, 1)
    np.testing.assert_allclose(mu, 0.16)
    mu, share = friction_per_cycle(SURFACE, 150.0, 1e-6, Lubrication(1.2e-6, 0.2, 0.05), 200, rng)
    np.testing.assert_allclose(mu, share * 0.2 + (1 - share) * 0.05)
    assert 0 < share.mean() < 1 and mu.std() > 0
