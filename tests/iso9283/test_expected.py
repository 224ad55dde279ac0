"""E|c + w| at the extremes of size: closed forms (a point, the Maxwell distribution) from 1e-300 to 1e300 m."""

import math

import numpy as np
import pytest

from tribokin.iso9283.expected import expected_norm

#: E|w| of w ~ N(0, σ² I₃) over σ: the mean of the Maxwell distribution, 2 √(2/π).
MAXWELL_MEAN = 2 * math.sqrt(2 / math.pi)


@pytest.mark.parametrize("size", [1e-300, 1e-150, 1e-9, 1.0, 1e150, 1e300])
def test_a_point_and_an_isotropic_cloud_keep_their_closed_forms_at_any_size(size):
    centre = np.array([[0.6, -0.8, 0.0]]) * size  # |c| = size
    assert expected_norm(centre, np.zeros((1, 3, 3)))[0] == pytest.approx(size, rel=1e-15, abs=0)
    sigma = min(max(size, 1e-150), 1e150)  # σ² must be a float
    variance = np.eye(3)[None] * sigma * sigma
    # the log-scale trapezoid rule's own error: 2e-8 here
    assert expected_norm(np.zeros((1, 3)), variance)[0] == pytest.approx(MAXWELL_MEAN * sigma, rel=5e-8, abs=0)


@pytest.mark.parametrize("scale", [1e-150, 1e-20, 1e20, 1e150])
def test_scaling_a_cloud_scales_its_expected_distance(scale):
    centre = np.array([[0.3, -0.2, 0.5], [2.0, 0.1, 0.0]])
    covariance = np.array([[[0.2, 0.05, 0], [0.05, 0.1, 0.02], [0, 0.02, 0.3]], np.diag([1e-4, 2e-4, 5e-5])])
    scaled = expected_norm(scale * centre, covariance * scale * scale)
    np.testing.assert_allclose(scaled / scale, expected_norm(centre, covariance), rtol=1e-14)


def test_no_deviation_is_no_distance():
    assert np.array_equal(expected_norm(np.zeros((2, 3)), np.zeros((2, 3, 3))), [0.0, 0.0])
