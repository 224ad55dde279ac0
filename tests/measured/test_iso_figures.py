"""measure(): registration and the re-taught correction as summary.json states them; the result, frozen, writes the
command's folder byte for byte, and its table is poses.csv's."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from helpers.folders import assert_frame_matches_csv, assert_frozen, assert_same_files
from tribokin import MeasurementResult, measure
from tribokin.cli import main
from tribokin.errors import InputError, SettingsError
from tribokin.measured.iso_figures import Segmenting

#: Three poses' commanded positions in the world frame [m]; the tracker frame is rotated and shifted.
COMMANDED_M = np.array([[0.5, 0.0, 0.3], [0.3, 0.4, 0.3], [0.4, 0.1, 0.6]])
TRACKER = Rotation.from_euler("xyz", [10, -20, 35], degrees=True)
SHIFT_M = np.array([1.0, -2.0, 0.5])
CYCLES_UM = np.array([[3, 0, 0], [-3, 0, 0], [0, 4, 0], [0, -4, 0]])


def tracker_file(folder, retaught_um: float = 0.0, times: bool = False):
    """Each pose measured 4 times exactly at its commanded position plus CYCLES_UM (world frame), written in the
    tracker frame; with ``retaught_um`` the last cycle of each pose is commanded (and reached) that much
    further along x; with ``times``, a ``t_s`` column."""
    lines = ["pose,cycle,x_m,y_m,z_m,cx_m,cy_m,cz_m" + (",t_s" if times else "")]
    for k, commanded in enumerate(COMMANDED_M):
        for cycle, offset in enumerate(CYCLES_UM * 1e-6, start=1):
            moved = commanded + ([retaught_um * 1e-6, 0, 0] if cycle == 4 else 0)
            measured = TRACKER.inv().apply(moved + offset - SHIFT_M)
            cells = [f"P{k + 1}", str(cycle), *(repr(float(v)) for v in (*measured, *moved))]
            lines.append(",".join(cells + ([repr(10.0 * (4 * k + cycle))] if times else [])))
    path = folder / "tracker.csv"
    path.write_text("\n".join(lines) + "\n")
    return path


def test_three_poses_register_the_tracker_frame(tmp_path):
    result = measure(tracker_file(tmp_path))
    summary = result.summary()
    registration = summary["settings"]["registration"]
    assert registration["made"] and registration["rms_residual_um"] < 1e-6
    assert result.registration.rms_residual_m < 1e-12
    assert np.array(registration["rotation"]) == pytest.approx(TRACKER.as_matrix(), abs=1e-9)
    assert summary["settings"]["commanded_correction"] == {
        "made": False, "why": "the commanded positions of each pose agree", "largest_spread_um": 0.0}
    # registered: AP_p is the distance of the barycentre from the commanded position in the world frame, 0 here
    assert summary["poses"][0]["directions"]["+"]["AP_p_um"] == pytest.approx(0.0, abs=1e-6)
    result.write(tmp_path / "out", report="none")
    assert json.loads((tmp_path / "out" / "summary.json").read_text()) == summary


def test_retaught_points_are_corrected_under_a_registration(tmp_path):
    result = measure(tracker_file(tmp_path, retaught_um=50.0))
    correction = result.summary()["settings"]["commanded_correction"]
    assert correction["made"] and correction["largest_spread_um"] == pytest.approx(50.0, rel=1e-6)
    assert result.correction.made and result.correction.largest_spread_um == correction["largest_spread_um"]
    # each cycle about its own commanded position: l = 3, 3, 4, 4 µm, RP_l = 3.5 + sqrt(3) (hand), not 50 µm wide
    assert result.summary()["poses"][0]["directions"]["+"]["RP_l_um"] == pytest.approx(3.5 + np.sqrt(3), rel=1e-3)
    assert result.figures[0].directions[0].RP_l_m == pytest.approx((3.5 + np.sqrt(3)) * 1e-6, rel=1e-3)


@pytest.mark.parametrize("report", ["full", "none"])
def test_the_result_is_frozen_and_writes_the_command_s_folder_and_its_table_is_poses_csv(tmp_path, report):
    path = tracker_file(tmp_path, retaught_um=20.0, times=True)
    assert main(["measure", path, "--out", tmp_path / "command", "--seed", "7", "--report", report]) == 0
    result = measure(path, seed=7)
    assert isinstance(result, MeasurementResult)
    assert_frozen(result)
    assert result.write(tmp_path / "library", report=report) == tmp_path / "library"
    assert (tmp_path / "library" / "drift.png").is_file()
    assert_same_files(tmp_path / "library", tmp_path / "command")
    assert_frame_matches_csv(result.to_pandas(), tmp_path / "command" / "poses.csv")
    with pytest.raises(InputError, match="output folder exists"):
        result.write(tmp_path / "library")
    result.write(tmp_path / "library", force=True, report=report)
    assert_same_files(tmp_path / "library", tmp_path / "command")


def test_a_bad_seed_or_segmenting_names_the_argument_not_a_file(tmp_path):
    path = tracker_file(tmp_path)
    with pytest.raises(SettingsError) as error:
        measure(path, seed=-1)
    assert error.value.argument == "seed" and "must be a whole number >= 0" in error.value.message
    with pytest.raises(SettingsError) as error:
        measure(path, segmenting=Segmenting(min_duration_s=0.0))
    assert error.value.argument == "min_duration_s"
