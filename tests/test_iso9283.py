"""ISO 9283 formulas against a hand-computed example."""

import numpy as np
import pytest

from tribokin.iso9283 import multidirectional_variation, pose_metrics, position_repeatability


def test_hand_computed_example():
    # Four points on a square of side 2 µm around (1, 1, 0) µm; commanded at the origin.
    pts = np.array([[0, 0, 0], [2, 0, 0], [2, 2, 0], [0, 2, 0]], dtype=float) * 1e-6
    m = pose_metrics(pts, np.zeros((4, 3)), np.zeros(3))
    # barycenter (1,1,0) µm -> AP_p = sqrt(2) µm; every l_j = sqrt(2) µm, S_l = 0 -> RP_l = sqrt(2) µm
    assert m.barycenter_m == pytest.approx([1e-6, 1e-6, 0])
    assert m.AP_p_m == pytest.approx(np.sqrt(2) * 1e-6)
    assert m.RP_l_m == pytest.approx(np.sqrt(2) * 1e-6)
    assert m.vAP_p_m is None


def test_sample_std_uses_n_minus_1():
    pts = np.array([[0, 0, 0], [1, 0, 0], [3, 0, 0]], dtype=float)  # barycenter 4/3
    l = np.abs(pts[:, 0] - 4 / 3)  # 4/3, 1/3, 5/3
    expected = l.mean() + 3 * np.sqrt(((l - l.mean()) ** 2).sum() / 2)
    assert position_repeatability(pts)[0] == pytest.approx(expected)


def test_orientation_accuracy_and_repeatability():
    angles_x = np.array([1.0, 2.0, 3.0, 6.0]) * 1e-5  # rad about x
    m = pose_metrics(np.zeros((4, 3)), np.column_stack([angles_x, 0 * angles_x, 0 * angles_x]), np.zeros(3))
    assert m.AP_abc_rad == pytest.approx([3e-5, 0, 0], abs=1e-12)
    assert m.RP_abc_rad[0] == pytest.approx(3 * np.std(angles_x, ddof=1), rel=1e-9)
    assert m.RP_abc_rad[1:] == pytest.approx([0, 0], abs=1e-15)


def test_vap_is_largest_distance_between_direction_barycenters():
    pts = np.array([[0, 0, 0], [0, 0, 0], [3, 0, 0], [3, 0, 0], [0, 4, 0], [0, 4, 0]], dtype=float)
    assert multidirectional_variation(pts, np.array([0, 0, 1, 1, 2, 2])) == pytest.approx(5.0)


def test_position_spread_of_a_batch_matches_each_cloud_alone():
    """Barycenter, RP_l and largest semi-axis of several clouds at once against NumPy's mean, the
    per-cloud RP_l and the square root of the largest eigenvalue of ``np.cov``."""
    from tribokin.iso9283 import position_spread

    rng = np.random.default_rng(3)
    shapes = np.diag([3.0, 1.0, 0.1]) @ np.linalg.qr(rng.standard_normal((3, 3)))[0]
    clouds = 0.5 + 1e-6 * rng.standard_normal((4, 200, 3)) @ shapes
    spread = position_spread(clouds)
    for k, cloud in enumerate(clouds):
        assert spread.barycenter_m[k] == pytest.approx(cloud.mean(axis=0), rel=1e-15)
        assert spread.RP_l_m[k] == pytest.approx(position_repeatability(cloud)[0], rel=1e-12)
        largest = np.sqrt(np.linalg.eigvalsh(np.cov(cloud.T)).max())
        assert spread.largest_semi_axis_m[k] == pytest.approx(largest, rel=1e-9)
