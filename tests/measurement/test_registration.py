"""Registration of the measuring frame: a known transform recovered; figures unchanged by moving the data."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tribokin.measurement.contract import Rows, assemble
from tribokin.measurement.figures import measurement_figures
from tribokin.measurement.registration import register, register_measurements

ROTATION = Rotation.from_euler("zyx", [40, -15, 70], degrees=True).as_matrix()
SHIFT_M = np.array([1.2, -0.4, 0.7])
CUBE_M = np.array([[0.5, 0.0, 0.4], [0.6, 0.1, 0.5], [0.4, 0.1, 0.5], [0.4, -0.1, 0.3], [0.6, -0.1, 0.3]])


def _measurements(positions_m: np.ndarray, commanded_m: np.ndarray) -> object:
    """Five poses, directions "+x" (6 cycles) and "-x" (5 cycles) of rows in the given order."""
    poses = tuple(f"P{k // 11 + 1}" for k in range(len(positions_m)))
    directions = tuple("+x" if k % 11 < 6 else "-x" for k in range(len(positions_m)))
    cycles = np.array([k % 11 + 1 if k % 11 < 6 else k % 11 - 5 for k in range(len(positions_m))])
    return assemble("synthetic", Rows(np.arange(len(positions_m)), poses, directions, cycles, positions_m,
                                      commanded_m=commanded_m))


@pytest.fixture
def data():
    """Base-frame clouds: 20 µm noise, a 30 µm gap between directions, 50 µm geometric error per pose."""
    rng = np.random.default_rng(21)
    commanded = np.repeat(CUBE_M, 11, axis=0)
    direction_gap = np.tile(np.r_[np.zeros(6), np.ones(5)], 5)[:, None] * [30e-6, 0, 0]
    geometric = np.repeat(rng.normal(0, 50e-6, (5, 3)), 11, axis=0)
    return commanded + geometric + direction_gap + rng.normal(0, 20e-6, commanded.shape), commanded


def test_registration_recovers_a_known_transform():
    commanded = CUBE_M
    measured = (commanded - SHIFT_M) @ ROTATION  # tracker coordinates: p_base = R p + t
    registration = register(measured, commanded)
    np.testing.assert_allclose(registration.rotation, ROTATION, atol=1e-12)
    np.testing.assert_allclose(registration.translation_m, SHIFT_M, atol=1e-12)
    assert registration.rms_residual_m < 1e-12
    np.testing.assert_allclose(registration.to_base(measured), commanded, atol=1e-12)


def test_registration_reports_its_residual():
    offsets = np.array([[1e-4, 0, 0], [-1e-4, 0, 0], [0, 0, 0], [0, 0, 0], [0, 0, 0]])
    registration = register(CUBE_M + offsets, CUBE_M)
    assert 0 < registration.rms_residual_m < np.sqrt(2 / 5) * 1e-4


def test_registration_is_unavailable_with_too_few_or_collinear_poses():
    assert register(CUBE_M[:2], CUBE_M[:2]) is None
    line = np.array([[0.1, 0.2, 0.3], [0.2, 0.4, 0.6], [0.4, 0.8, 1.2], [0.5, 1.0, 1.5]])
    assert register(line + 1e-3, line) is None


def test_rotating_and_shifting_the_measurements_changes_no_figure(data):
    positions, commanded = data
    before = _measurements(positions, commanded)
    after = _measurements((positions - SHIFT_M) @ ROTATION, commanded)
    registered = register_measurements(after)
    assert registered.rms_residual_m > 10e-6  # the geometric error is left as residual
    for a, b in zip(measurement_figures(before, register_measurements(before)),
                    measurement_figures(after, registered), strict=True):
        assert b.vAP_p_m == pytest.approx(a.vAP_p_m, rel=1e-9)
        assert b.RP_l_all_directions_m == pytest.approx(a.RP_l_all_directions_m, rel=1e-9)
        for x, y in zip(a.directions, b.directions, strict=True):
            assert y.RP_l_m == pytest.approx(x.RP_l_m, rel=1e-9)
            assert y.AP_p_m == pytest.approx(x.AP_p_m, rel=1e-9)
            np.testing.assert_allclose(y.RP_l_ci95_m, x.RP_l_ci95_m, rtol=1e-9)
            np.testing.assert_allclose(y.semi_axes_m, x.semi_axes_m, rtol=1e-9)
