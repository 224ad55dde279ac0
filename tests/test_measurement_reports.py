"""measure(): registration and the re-taught correction as summary.json states them."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tribokin.measurement_reports import measure

#: Three poses' commanded positions in the base frame [m]; the tracker frame is rotated and shifted.
COMMANDED_M = np.array([[0.5, 0.0, 0.3], [0.3, 0.4, 0.3], [0.4, 0.1, 0.6]])
TRACKER = Rotation.from_euler("xyz", [10, -20, 35], degrees=True)
SHIFT_M = np.array([1.0, -2.0, 0.5])
CYCLES_UM = np.array([[3, 0, 0], [-3, 0, 0], [0, 4, 0], [0, -4, 0]])


def tracker_file(folder, retaught_um: float = 0.0):
    """Each pose measured 4 times exactly at its commanded position plus CYCLES_UM (base frame), written in the
    tracker frame; with ``retaught_um`` the last cycle of each pose is commanded (and reached) that much
    further along x."""
    lines = ["pose,cycle,x_m,y_m,z_m,cx_m,cy_m,cz_m"]
    for k, commanded in enumerate(COMMANDED_M):
        for cycle, offset in enumerate(CYCLES_UM * 1e-6, start=1):
            moved = commanded + ([retaught_um * 1e-6, 0, 0] if cycle == 4 else 0)
            measured = TRACKER.inv().apply(moved + offset - SHIFT_M)
            lines.append(",".join([f"P{k + 1}", str(cycle), *(repr(float(v)) for v in (*measured, *moved))]))
    path = folder / "tracker.csv"
    path.write_text("\n".join(lines) + "\n")
    return path


def test_three_poses_register_the_tracker_frame(tmp_path):
    summary = measure(tracker_file(tmp_path), tmp_path / "out", report="none")
    registration = summary["settings"]["registration"]
    assert registration["made"] and registration["rms_residual_um"] < 1e-6
    assert np.array(registration["rotation"]) == pytest.approx(TRACKER.as_matrix(), abs=1e-9)
    assert summary["settings"]["commanded_correction"] == {
        "made": False, "why": "the commanded positions of each pose agree", "largest_spread_um": 0.0}
    # registered: AP_p is the distance of the barycentre from the commanded position in the base frame, 0 here
    assert summary["poses"][0]["directions"]["+"]["AP_p_um"] == pytest.approx(0.0, abs=1e-6)
    assert json.loads((tmp_path / "out" / "summary.json").read_text()) == summary


def test_retaught_points_are_corrected_under_a_registration(tmp_path):
    summary = measure(tracker_file(tmp_path, retaught_um=50.0), tmp_path / "out", report="none")
    correction = summary["settings"]["commanded_correction"]
    assert correction["made"] and correction["largest_spread_um"] == pytest.approx(50.0, rel=1e-6)
    # each cycle about its own commanded position: l = 3, 3, 4, 4 µm, RP_l = 3.5 + sqrt(3) (hand), not 50 µm wide
    assert summary["poses"][0]["directions"]["+"]["RP_l_um"] == pytest.approx(3.5 + np.sqrt(3), rel=1e-3)
