"""Registration of the measuring frame: a known transform recovered; figures unchanged by moving the data; the share
of the coordinates a best fit absorbs, the rule by which ``auto`` registers, the warning of a best fit that absorbs
accuracy, and a given transform."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tribokin.errors import SettingsError
from tribokin.measurement.contract import Rows, assemble
from tribokin.measurement.figures import measurement_figures
from tribokin.measurement.registration import (
    RegistrationWarning,
    Transform,
    checked_choice,
    choose_frame,
    register,
    register_measurements,
    shares,
)

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


def _poses(commanded_m: np.ndarray, measured_m: np.ndarray | None = None):
    """One pose per commanded point, its two cycles 1 µm either side of ``measured_m`` (default: the commanded)
    along z."""
    measured = commanded_m if measured_m is None else measured_m
    k = len(commanded_m)
    positions = np.repeat(measured, 2, axis=0) + np.tile([[0, 0, 1e-6], [0, 0, -1e-6]], (k, 1))
    return assemble("synthetic", Rows(np.arange(2 * k), tuple(f"P{i // 2 + 1}" for i in range(2 * k)), ("+",) * 2 * k,
                                      np.tile([1, 2], k), positions, commanded_m=np.repeat(commanded_m, 2, axis=0)))


def test_a_best_fit_absorbs_each_pose_s_share_of_its_coordinates():
    """The shares sum to 6 / 3 (a rigid motion's 6 of the 3n coordinates); the centre of the ISO cube's poses is
    moved by the translation alone (1 / n); and over random isotropic errors, the residual keeps 1 - share of each
    pose's mean square error (Monte Carlo through register(), 1000 draws: standard error about 0.025)."""
    share = shares(CUBE_M)
    assert share.sum() == pytest.approx(2.0, rel=1e-12)
    assert share[0] == pytest.approx(1 / 5, rel=1e-9)
    rng = np.random.default_rng(5)
    sigma = 1e-4
    kept = np.zeros(5)
    for _ in range(1000):
        measured = CUBE_M + rng.normal(0, sigma, CUBE_M.shape)
        fitted = register(measured, CUBE_M)
        kept += np.sum((fitted.to_base(measured) - CUBE_M) ** 2, axis=1) / (3 * sigma ** 2) / 1000
    np.testing.assert_allclose(kept, 1 - share, atol=0.07)
    assert register(CUBE_M + 1e-5, CUBE_M).shares == pytest.approx(tuple(share))


def test_auto_registers_only_on_enough_well_spread_poses():
    tracker = (CUBE_M - SHIFT_M) @ ROTATION  # the tracker frame is not the world frame: registering finds it
    frame = choose_frame(_poses(CUBE_M, tracker))
    assert frame.choice == "auto" and frame.registration is not None and frame.warning is None
    np.testing.assert_allclose(frame.registration.rotation, ROTATION, atol=1e-9)
    for k, used in ((3, 9), (4, 12)):
        frame = choose_frame(_poses(CUBE_M[:k], tracker[:k]))
        assert frame.registration is None and frame.warning is None
        assert f"a best fit on {k} poses uses 6 of their {used} coordinates" in frame.why
    # six poses, five bunched within 1 cm and one 0.5 m away: the far one's coordinates are fitted for the most part
    bunched = np.vstack([CUBE_M * 0.02 + [0.5, 0, 0.4], [[1.0, 0.3, 0.9]]])
    frame = choose_frame(_poses(bunched))
    assert frame.registration is None and "of pose P6's coordinates" in frame.why
    assert max(shares(bunched)) > 0.5
    # six poses on a line, within 0.1 mm of it, 50 µm off their commanded positions: the rotation about it is guessed
    line = np.linspace(0, 1, 6)[:, None] * [0.4, 0.3, 0.0] + [[0, 0, 0], [0, 0, 1e-4], [0, 1e-4, 0]] * 2
    off = line + np.random.default_rng(3).normal(0, 50e-6, line.shape)
    frame = choose_frame(_poses(line, off))
    assert frame.registration is None and "close to one line" in frame.why
    assert register_measurements(_poses(line, off)).rotation_error_rad > 1e-2


def test_best_fit_on_few_poses_registers_and_warns_what_it_absorbed():
    tracker = (CUBE_M[:3] - SHIFT_M) @ ROTATION
    with pytest.warns(RegistrationWarning, match="best fit on 3 poses uses 6 of their 9 coordinates"):
        frame = choose_frame(_poses(CUBE_M[:3], tracker), "best-fit")
    assert frame.choice == "best-fit" and "6 of their 9 coordinates" in frame.warning
    np.testing.assert_allclose(frame.registration.rotation, ROTATION, atol=1e-9)
    entry = frame.summary()
    assert entry["coordinates_used"] == [6, 9] and entry["warning"] == frame.warning
    assert entry["rotation_angle_mdeg"] == pytest.approx(np.degrees(Rotation.from_matrix(ROTATION).magnitude()) * 1e3,
                                                         rel=1e-9)
    assert entry["translation_um"] == pytest.approx(np.linalg.norm(SHIFT_M) * 1e6, rel=1e-9)


def test_none_keeps_the_frame_and_a_transform_is_applied_as_given():
    tracker = (CUBE_M - SHIFT_M) @ ROTATION + [20e-6, 0, 0]
    assert choose_frame(_poses(CUBE_M, tracker), "none").registration is None
    given = choose_frame(_poses(CUBE_M, tracker), Transform(ROTATION, SHIFT_M, "frame.toml").checked())
    assert given.choice == "given" and given.registration.method == "given" and "frame.toml" in given.why
    assert given.registration.rotation is not None and np.array_equal(given.registration.rotation, ROTATION)
    # the residual of the given transform: every barycentre 20 µm off along the tracker's x, turned into the world
    assert given.registration.rms_residual_m == pytest.approx(20e-6, rel=1e-9)


@pytest.mark.parametrize("value, match", [
    ("bestfit", "did you mean 'best-fit'"), (None, "must be one of auto, none, best-fit"),
    (Transform(np.diag([1.0, 1.0, -1.0]), np.zeros(3)), "determinant"),
    (Transform(np.eye(3) * 1.001, np.zeros(3)), "orthonormal"),
    (Transform(np.eye(3), [0.0, np.nan, 0.0]), "translation must be 3 finite numbers"),
    (Transform(np.eye(2), np.zeros(3)), "3 rows of 3")])
def test_a_bad_registration_names_the_argument(value, match):
    with pytest.raises(SettingsError, match=match) as error:
        checked_choice(value)
    assert error.value.argument == "registration"
