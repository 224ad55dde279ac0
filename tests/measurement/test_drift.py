"""Drift of AP and RP over a timed series, against hand computations."""

from __future__ import annotations

import numpy as np
import pytest

from tribokin.measurement.contract import Rows, assemble
from tribokin.measurement.drift import pose_drift

UM = 1e-6
SET_UM = np.array([[3, 0, 0], [-3, 0, 0], [0, 4, 0], [0, -4, 0]], dtype=float)


def _pose(times_s, angles=True):
    """Eight cycles at a commanded (0.5, 0, 0.3) m: the first four as SET_UM about the commanded position,
    the last four twice as wide about a barycentre 10 µm off along x."""
    commanded = np.tile([0.5, 0.0, 0.3], (8, 1))
    positions = commanded + np.vstack([SET_UM, 2 * SET_UM + [10, 0, 0]]) * UM
    c_deg = np.r_[[0, 1, -1, 0], [0, 2, -2, 0]] * 1e-3
    rows = Rows(np.arange(8), ("P1",) * 8, ("+",) * 8, np.arange(1, 9), positions, commanded_m=commanded,
                times_s=np.asarray(times_s, dtype=float),
                angles_rad=np.column_stack([np.zeros(8), np.zeros(8), np.radians(c_deg)]) if angles else None)
    return assemble("synthetic", rows).poses[0]


def test_drift_between_the_first_and_last_sets_equals_the_hand_computation():
    (drift,) = pose_drift(_pose(np.arange(8) * 600.0))
    assert drift.cycles_per_set == 4  # at most half the series each
    rp_first = (3.5 + 3 * np.sqrt(1 / 3)) * UM  # l_j = 3, 3, 4, 4
    assert drift.dRP_l_m == pytest.approx(rp_first, rel=1e-6)  # the last set's RP_l is twice it
    assert drift.dAP_p_m == pytest.approx(10 * UM, rel=1e-6)  # AP_p 0 then 10 µm
    assert drift.barycenter_shift_m == pytest.approx(10 * UM, rel=1e-6)
    # c: 3 S_c = 3 sqrt(2/3) mdeg first, twice it last
    assert np.degrees(drift.dRP_abc_rad[2]) * 1e3 == pytest.approx(3 * np.sqrt(2 / 3), rel=1e-6)
    assert drift.dRP_abc_rad[0] == 0
    assert drift.start_s.tolist() == [0, 1800] and drift.end_s.tolist() == [2400, 4200]
    row = drift.report_row()
    assert row["dAP_p_um"] == pytest.approx(10) and row["dRP_c_mdeg"] == pytest.approx(3 * np.sqrt(2 / 3))
    assert row["dRP_l_um"] == pytest.approx(3.5 + 3 * np.sqrt(1 / 3)) and row["last_set_s"] == [2400, 4200]


def test_sets_follow_the_times_not_the_cycle_numbers():
    (drift,) = pose_drift(_pose([4, 5, 6, 7, 0, 1, 2, 3]), cycles_per_set=2)
    assert drift.cycles_per_set == 2
    # first set in time: cycles 5, 6 (2·(±3, 0, 0) µm about +10 µm); last: cycles 3, 4 (0, ±4, 0) µm
    assert drift.dRP_l_m == pytest.approx(2 * UM, rel=1e-6)  # RP_l 6 µm against 4 µm
    assert drift.dAP_p_m == pytest.approx(10 * UM, rel=1e-6)


def test_no_drift_without_times_or_cycles():
    rows = Rows(np.arange(3), ("P",) * 3, ("+",) * 3, np.arange(1, 4), np.zeros((3, 3)), times_s=np.arange(3.0))
    assert pose_drift(assemble("s", rows).poses[0]) == ()
    assert pose_drift(_pose(np.zeros(8), angles=False))[0].dRP_abc_rad is None
