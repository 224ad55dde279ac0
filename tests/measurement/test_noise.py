"""The instrument's noise floor from still readings, and the figures within twice of it."""

from __future__ import annotations

import numpy as np
import pytest

from helpers.measurement_files import write_csv
from tribokin.errors import InputError
from tribokin.measurement.contract import read_stream
from tribokin.measurement.figures import DirectionFigures, PoseFigures
from tribokin.measurement.noise import flag_figures, noise_floor

UM = 1e-6


@pytest.fixture
def floor(tmp_path):
    """Still readings 3, 3, 4, 4 µm from their barycentre: RP_l = 3.5 + 3 sqrt(1/3) µm."""
    rows = ["0,0.503,0.2,0.3", "1,0.497,0.2,0.3", "2,0.5,0.204,0.3", "3,0.5,0.196,0.3"]
    return noise_floor(read_stream(write_csv(tmp_path, "t_s,x_mm,y_mm,z_mm", rows)))


def test_noise_floor_equals_the_hand_computation(floor):
    assert floor.readings == 4
    assert floor.RP_l_m == pytest.approx((3.5 + 3 * np.sqrt(1 / 3)) * UM, rel=1e-6)
    np.testing.assert_allclose(floor.std_m, np.array([np.sqrt(6), np.sqrt(32 / 3), 0]) * UM, rtol=1e-6, atol=1e-12)


def test_figures_within_twice_the_floor_are_flagged(floor):
    # twice the floor: RP_l 10.46 µm, semi-axis 6.53 µm
    def direction(label, rp_l_um, axes_um):
        return DirectionFigures(label, 5, np.zeros(3), rp_l_um * UM, None, np.array(axes_um) * UM, None, None)

    pose = PoseFigures("P1", (direction("+x", 10.4, [20.0, 6.5, 1.0]), direction("-x", 10.5, [20.0, 7.0, 6.6])),
                       vAP_p_m=30 * UM, RP_l_all_directions_m=10.0 * UM, commanded_spread_m=None,
                       commanded_corrected=False, registered=False)
    flags = flag_figures((pose,), floor)
    assert [(f.direction, f.figure) for f in flags] == [
        ("+x", "RP_l_um"), ("+x", "ellipsoid_semi_axis_2_um"), ("+x", "ellipsoid_semi_axis_3_um"),
        (None, "RP_l_all_directions_um")]
    assert flags[0].floor_m == floor.RP_l_m and flags[1].floor_m == pytest.approx(np.sqrt(32 / 3) * UM)


def test_noise_floor_needs_two_readings(tmp_path):
    with pytest.raises(InputError, match="two readings"):
        noise_floor(read_stream(write_csv(tmp_path, "x_m,y_m,z_m", ["1,2,3"]), require_time=False))
