"""ISO 9283 formulas against a hand-computed example."""

import numpy as np
import pinocchio as pin
import pytest
from scipy.spatial.distance import pdist

from tribokin.iso9283.metrics import (
    directional_metrics,
    largest_distance,
    multidirectional_variation,
    pose_metrics,
    position_repeatability,
)


def test_hand_computed_example():
    # Four points on a square of side 2 µm around (1, 1, 0) µm; commanded at the origin.
    pts = np.array([[0, 0, 0], [2, 0, 0], [2, 2, 0], [0, 2, 0]], dtype=float) * 1e-6
    m = pose_metrics(pts, np.zeros((4, 3)), np.zeros(3))
    # barycenter (1,1,0) µm -> AP_p = sqrt(2) µm; every l_j = sqrt(2) µm, S_l = 0 -> RP_l = sqrt(2) µm
    assert m.barycenter_m == pytest.approx([1e-6, 1e-6, 0])
    assert m.AP_p_m == pytest.approx(np.sqrt(2) * 1e-6)
    assert m.RP_l_m == pytest.approx(np.sqrt(2) * 1e-6)


def test_sample_std_uses_n_minus_1():
    pts = np.array([[0, 0, 0], [1, 0, 0], [3, 0, 0]], dtype=float)  # barycenter 4/3
    distances = np.abs(pts[:, 0] - 4 / 3)  # l_j: 4/3, 1/3, 5/3
    expected = distances.mean() + 3 * np.sqrt(((distances - distances.mean()) ** 2).sum() / 2)
    assert position_repeatability(pts)[0] == pytest.approx(expected)


def test_orientation_accuracy_and_repeatability():
    angles_x = np.array([1.0, 2.0, 3.0, 6.0]) * 1e-5  # rad about x
    m = pose_metrics(np.zeros((4, 3)), np.column_stack([angles_x, 0 * angles_x, 0 * angles_x]), np.zeros(3))
    assert m.AP_abc_rad == pytest.approx([3e-5, 0, 0], abs=1e-12)
    assert m.RP_abc_rad[0] == pytest.approx(3 * np.std(angles_x, ddof=1), rel=1e-9)
    assert m.RP_abc_rad[1:] == pytest.approx([0, 0], abs=1e-15)


def test_vap_is_largest_distance_between_direction_barycenters():
    barycenters = np.array([[0, 0, 0], [3, 0, 0], [0, 4, 0]], dtype=float)
    assert multidirectional_variation(barycenters) == pytest.approx(5.0)
    assert multidirectional_variation(barycenters[:1]) is None


def test_largest_distance_is_scipys_largest_pairwise_distance_repeated_points_included():
    rng = np.random.default_rng(3)
    for count in (2, 3, 7, 90):
        points = rng.normal(scale=[1e-6, 0.3, 20.0], size=(count, 3))
        points[count // 2:] = points[0]  # repeated points (a pose's commanded position on every row)
        assert largest_distance(points) == pytest.approx(pdist(points).max(), rel=1e-15)
    assert largest_distance(np.ones((5, 3))) == 0.0 == largest_distance(np.zeros((1, 3)))


def test_figures_per_direction_and_across_directions_by_hand():
    """Three approach directions, commanded at the origin, cycles interleaved as a bidirectional test:
    '+x' a square of side 2 around (10, 0, 0), '+y' two points 2 apart around (0, 20, 0), '+z' three
    points on a line around (0, 0, 0)."""
    square = np.array([[9, -1, 0], [11, -1, 0], [11, 1, 0], [9, 1, 0]], dtype=float)
    pair = np.array([[0, 19, 0], [0, 21, 0]], dtype=float)
    line = np.array([[0, 0, -1], [0, 0, 0], [0, 0, 2]], dtype=float)  # barycenter (0, 0, 1/3)
    approach = np.array([0, 1, 2, 0, 1, 2, 0, 2, 0])
    positions = np.empty((9, 3))
    for k, points in enumerate((square, pair, line)):
        positions[approach == k] = points
    m = directional_metrics(positions * 1e-6, np.zeros((9, 3)), np.zeros(3), approach, ("+x", "+y", "+z"))
    assert list(m.directions) == ["+x", "+y", "+z"]
    plus_x, plus_y, plus_z = m.directions.values()
    # '+x': every l_j = sqrt(2), S_l = 0; AP_p = 10
    assert plus_x.RP_l_m == pytest.approx(np.sqrt(2) * 1e-6) and plus_x.AP_p_m == pytest.approx(10e-6)
    # '+y': l_j = 1, 1; AP_p = 20
    assert plus_y.RP_l_m == pytest.approx(1e-6) and plus_y.AP_p_m == pytest.approx(20e-6)
    # '+z': l_j = 4/3, 1/3, 5/3 -> mean 10/9, S_l = sqrt(((2/9)^2 + (7/9)^2 + (5/9)^2) / 2) = sqrt(39)/9; AP_p = 1/3
    assert plus_z.RP_l_m == pytest.approx((10 + 3 * np.sqrt(39)) / 9 * 1e-6)
    assert plus_z.AP_p_m == pytest.approx(1e-6 / 3)
    # vAP_p: barycenters (10, 0, 0), (0, 20, 0), (0, 0, 1/3); farthest apart: '+x' and '+y', sqrt(500)
    assert m.vAP_p_m == pytest.approx(np.sqrt(500) * 1e-6)
    # pooled: barycenter (40, 40, 1) / 9, l_j about it, l_bar + 3 S_l (n - 1)
    distances = np.linalg.norm(positions - np.array([40, 40, 1]) / 9, axis=1)
    pooled = distances.mean() + 3 * np.sqrt(((distances - distances.mean()) ** 2).sum() / 8)
    assert m.RP_l_all_directions_m == pytest.approx(pooled * 1e-6)
    assert pooled > 5 * max(plus_x.RP_l_m, plus_y.RP_l_m, plus_z.RP_l_m) * 1e6  # mixing directions is no RP


def test_a_direction_with_fewer_than_two_cycles_has_no_figures():
    positions = np.array([[0, 0, 0], [1, 0, 0], [5, 0, 0]], dtype=float)
    m = directional_metrics(positions, np.zeros((3, 3)), np.zeros(3), np.array([0, 0, 1]), ("+", "-"))
    assert list(m.directions) == ["+"] and m.vAP_p_m is None
    assert m.RP_l_all_directions_m == pytest.approx(position_repeatability(positions)[0])


def test_position_spread_of_a_batch_matches_each_cloud_alone():
    """Barycenter, RP_l and largest semi-axis of several clouds at once against NumPy's mean, the
    per-cloud RP_l and the square root of the largest eigenvalue of ``np.cov``."""
    from tribokin.iso9283.metrics import position_spread

    rng = np.random.default_rng(3)
    shapes = np.diag([3.0, 1.0, 0.1]) @ np.linalg.qr(rng.standard_normal((3, 3)))[0]
    clouds = 0.5 + 1e-6 * rng.standard_normal((4, 200, 3)) @ shapes
    spread = position_spread(clouds)
    for k, cloud in enumerate(clouds):
        assert spread.barycenter_m[k] == pytest.approx(cloud.mean(axis=0), rel=1e-15)
        assert spread.RP_l_m[k] == pytest.approx(position_repeatability(cloud)[0], rel=1e-12)
        largest = np.sqrt(np.linalg.eigvalsh(np.cov(cloud.T)).max())
        assert spread.largest_semi_axis_m[k] == pytest.approx(largest, rel=1e-9)


def _rotation_vector_and_rpy(commanded, theta, axis):
    """(log3(R_j R_c^T), rpy(R_j R_c^T), rpy(R_j) - rpy(R_c)) for a rotation of theta [rad] about ``axis``."""
    deviation = pin.exp3(theta * axis)
    reached = deviation @ commanded
    return (pin.log3(reached @ commanded.T), pin.rpy.matrixToRpy(deviation),
            pin.rpy.matrixToRpy(reached) - pin.rpy.matrixToRpy(commanded))


def test_rotation_vector_and_roll_pitch_yaw_agree_to_second_order():
    """The module docstring's claim: |log3 - rpy| of the deviation is O(theta²) (at most theta²/4) at any
    commanded orientation; the difference of the absolute angles agrees as well only at R_c = I."""
    axis = np.array([0.6, -0.48, 0.64])
    general = pin.rpy.rpyToMatrix(0.3, -0.5, 1.2)
    for commanded in (np.eye(3), general):
        ratios = []
        for theta in (1e-2, 1e-3, 1e-4):
            vector, rpy, _ = _rotation_vector_and_rpy(commanded, theta, axis)
            ratios.append(np.abs(vector - rpy).max() / theta ** 2)
        assert max(ratios) <= 0.25 and min(ratios) > 0.05  # second order: the ratio to theta² stays put
    for theta in (1e-2, 1e-3):
        vector, _, differences = _rotation_vector_and_rpy(np.eye(3), theta, axis)
        assert np.abs(vector - differences).max() <= 0.25 * theta ** 2
        vector, _, differences = _rotation_vector_and_rpy(general, theta, axis)
        assert np.abs(vector - differences).max() > 0.1 * theta  # first order away from the base's axes
