"""Properties of the ISO 9283 figures for any cloud of cycles: RP_l and RP_abc >= 0; RP_l, vAP, the
pooled RP_l and (with the commanded point moved along) AP unchanged by a rigid motion of the points;
positions scaled by c scale them by |c|; identical cycles give RP_l = 0 exactly."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from scipy.spatial.transform import Rotation

from tribokin.iso9283.metrics import directional_metrics, position_repeatability

# n cycles (two or more per direction), deviations of up to a millimetre about a point up to 2 m from the base
clouds = st.integers(4, 40).flatmap(lambda n: arrays(float, (n, 3), elements=st.floats(-1e-3, 1e-3)))
points = arrays(float, 3, elements=st.floats(-2.0, 2.0))
rotations = arrays(float, 3, elements=st.floats(-np.pi, np.pi)).map(lambda v: Rotation.from_rotvec(v).as_matrix())
scales = st.floats(-10.0, 10.0).filter(lambda c: abs(c) > 1e-3)


def _metrics(positions, angles, commanded):
    """Figures of the cycles as two interleaved approach directions; the first direction's figures
    besides vAP_p."""
    n = len(positions)
    metrics = directional_metrics(positions, angles, commanded, np.arange(n) % 2, ("+", "-"))
    return metrics, metrics.directions["+"]


@given(clouds, points, points)
def test_figures_are_never_negative(deviations, centre, commanded):
    positions = centre + deviations
    across, metrics = _metrics(positions, deviations, commanded)
    assert metrics.RP_l_m >= 0.0 and metrics.AP_p_m >= 0.0 and np.all(metrics.RP_abc_rad >= 0.0)
    assert np.all(metrics.distances_m >= 0.0) and across.RP_l_all_directions_m >= 0.0
    assert across.vAP_p_m is None or across.vAP_p_m >= 0.0


@given(clouds, points, points, rotations, points)
def test_rigid_motion_changes_no_figure(deviations, centre, commanded, rotation, translation):
    positions = centre + deviations
    moved = positions @ rotation.T + translation
    angles = np.zeros_like(positions)
    before = _metrics(positions, angles, commanded)
    after = _metrics(moved, angles, rotation @ commanded + translation)
    # rounding: about 1e-16 of the 4 m the points and the commanded point may be moved by
    for figures, figure in ((1, "RP_l_m"), (1, "AP_p_m"), (0, "vAP_p_m"), (0, "RP_l_all_directions_m")):
        assert getattr(after[figures], figure) == pytest.approx(getattr(before[figures], figure), rel=1e-9,
                                                                abs=1e-14), figure


@given(clouds, points, points, scales)
def test_scaling_positions_scales_rp_ap_and_vap(deviations, centre, commanded, c):
    positions = centre + deviations
    angles = np.zeros_like(positions)
    before = _metrics(positions, angles, commanded)
    after = _metrics(c * positions, angles, c * commanded)
    for figures, figure in ((1, "RP_l_m"), (1, "AP_p_m"), (0, "vAP_p_m"), (0, "RP_l_all_directions_m")):
        expected = abs(c) * getattr(before[figures], figure)
        assert getattr(after[figures], figure) == pytest.approx(expected, rel=1e-9, abs=1e-14), figure


@given(points, st.integers(1, 40))
def test_identical_cycles_have_zero_repeatability_exactly(point, n):
    positions = np.tile(point, (n, 1))
    assert position_repeatability(positions)[0] == 0.0
    across = directional_metrics(positions, np.zeros_like(positions), point, np.arange(n) % 2, ("+", "-"))
    assert across.vAP_p_m in (None, 0.0) and across.RP_l_all_directions_m == 0.0
