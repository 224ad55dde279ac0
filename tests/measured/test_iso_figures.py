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
from tribokin.measurement.registration import RegistrationWarning, Transform

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


def test_three_poses_keep_the_tracker_frame_unless_a_best_fit_is_asked_for_which_warns(tmp_path):
    kept = measure(tracker_file(tmp_path)).summary()["settings"]["registration"]
    assert kept["choice"] == "auto" and not kept["made"] and "uses 6 of their 9 coordinates" in kept["why"]
    with pytest.warns(RegistrationWarning, match="a best fit on 3 poses uses 6 of their 9 coordinates"):
        result = measure(tracker_file(tmp_path), registration="best-fit")
    summary = result.summary()
    registration = summary["settings"]["registration"]
    assert registration["made"] and registration["rms_residual_um"] < 1e-6
    assert registration["coordinates_used"] == [6, 9] and "absorbs" in registration["warning"]
    assert registration["rotation_angle_mdeg"] == pytest.approx(np.degrees(TRACKER.magnitude()) * 1e3, rel=1e-9)
    assert result.registration.rms_residual_m < 1e-12
    assert np.array(registration["rotation"]) == pytest.approx(TRACKER.as_matrix(), abs=1e-9)
    assert summary["settings"]["commanded_correction"] == {
        "made": False, "why": "the commanded positions of each pose agree", "largest_spread_um": 0.0}
    # registered: AP_p is the distance of the barycentre from the commanded position in the world frame, 0 here
    assert summary["poses"][0]["directions"]["+"]["AP_p_um"] == pytest.approx(0.0, abs=1e-6)
    result.write(tmp_path / "out", report="none")
    assert json.loads((tmp_path / "out" / "summary.json").read_text()) == summary


@pytest.mark.filterwarnings("ignore::tribokin.measurement.registration.RegistrationWarning")
def test_retaught_points_are_corrected_under_a_registration(tmp_path):
    result = measure(tracker_file(tmp_path, retaught_um=50.0), registration="best-fit")
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


#: Five poses (the ISO cube's P1-P5 shape) in the world frame [m], and each one's barycentre offset [µm] (its accuracy).
CUBE_M = np.array([[0.5, 0.0, 0.4], [0.6, 0.1, 0.5], [0.4, 0.1, 0.5], [0.4, -0.1, 0.3], [0.6, -0.1, 0.3]])
OFFSETS_UM = np.array([[12, -5, 3], [-8, 20, 1], [4, 4, -15], [-10, -6, 9], [2, -13, -4]])


def cube_file(folder, shift_um=(0.0, 0.0, 0.0), to_tracker=lambda p: p, name="cube.csv"):
    """The five poses, 4 cycles each about commanded + OFFSETS_UM (world frame), their readings moved by ``shift_um``
    in the tracker frame, which ``to_tracker`` makes of the world frame's points."""
    lines = ["pose,cycle,x_m,y_m,z_m,cx_m,cy_m,cz_m"]
    for k, commanded in enumerate(CUBE_M):
        for cycle, offset in enumerate(CYCLES_UM, start=1):
            reading = to_tracker(commanded + (OFFSETS_UM[k] + offset) * 1e-6) + np.asarray(shift_um) * 1e-6
            lines.append(",".join([f"P{k + 1}", str(cycle), *(repr(float(v)) for v in (*reading, *commanded))]))
    path = folder / name
    path.write_text("\n".join(lines) + "\n")
    return path


def ap_um(result) -> np.ndarray:
    return np.array([pose["directions"]["+"]["AP_p_um"] for pose in result.summary()["poses"]])


def test_none_measures_ap_in_the_tracker_frame_and_a_best_fit_absorbs_a_shift(tmp_path):
    """Adding 50 µm to every x reading moves each AP_p to |offset + 50 µm x| with registration 'none' (the tracker
    frame taken as the world frame), and leaves it unchanged under a best fit (auto on these five poses)."""
    plain, shifted = cube_file(tmp_path), cube_file(tmp_path, shift_um=(50, 0, 0), name="shifted.csv")
    np.testing.assert_allclose(ap_um(measure(plain, registration="none")), np.linalg.norm(OFFSETS_UM, axis=1),
                               rtol=1e-9)
    np.testing.assert_allclose(ap_um(measure(shifted, registration="none")),
                               np.linalg.norm(OFFSETS_UM + [50, 0, 0], axis=1), rtol=1e-9)
    auto, moved = measure(plain), measure(shifted)
    assert auto.registration is not None and auto.frame.choice == "auto" and auto.frame.warning is None
    np.testing.assert_allclose(ap_um(moved), ap_um(auto), rtol=1e-6)
    np.testing.assert_allclose(moved.registration.rotation, auto.registration.rotation, atol=1e-12)
    np.testing.assert_allclose(auto.registration.translation_m - moved.registration.translation_m,
                               auto.registration.rotation @ [50e-6, 0, 0], atol=1e-12)  # t' = t - R s
    assert auto.summary()["settings"]["registration"]["coordinates_used"] == [6, 15]


def test_a_given_transform_is_applied_exactly(tmp_path):
    """Readings in a tracker frame turned and shifted from the world; the transform given back: barycentres, AP_p and
    the residual as computed here from the readings."""
    rotation, shift = TRACKER.as_matrix(), SHIFT_M
    path = cube_file(tmp_path, to_tracker=lambda p: (p - shift) @ rotation)
    result = measure(path, registration=Transform(rotation, shift, "frame.toml"))
    readings = np.loadtxt(path, delimiter=",", skiprows=1, usecols=(2, 3, 4)).reshape(5, 4, 3)
    barycentres = readings.mean(axis=1) @ rotation.T + shift  # p_world = R p + t, by hand
    for pose, expected, commanded in zip(result.summary()["poses"], barycentres, CUBE_M, strict=True):
        direction = pose["directions"]["+"]
        np.testing.assert_allclose(direction["barycenter_m"], expected, rtol=0, atol=1e-15)
        assert direction["AP_p_um"] == pytest.approx(np.linalg.norm(expected - commanded) * 1e6, rel=1e-9)
    registration = result.summary()["settings"]["registration"]
    assert registration["choice"] == "given" and registration["method"] == "given" and registration["warning"] is None
    assert registration["rotation"] == rotation.tolist() and registration["translation_m"] == shift.tolist()
    assert registration["rms_residual_um"] == pytest.approx(
        np.sqrt(np.mean(np.sum((barycentres - CUBE_M) ** 2, axis=1))) * 1e6, rel=1e-9)


def test_the_command_prints_what_the_registration_absorbed_and_warns_once(tmp_path, capsys):
    path = tracker_file(tmp_path)
    assert main(["measure", path, "--out", tmp_path / "fit", "--registration", "best-fit", "--report", "none"]) == 0
    out, err = capsys.readouterr()
    assert err.splitlines() == [err.strip()] and err.startswith(
        "tribokin: warning: registration by best fit: a best fit on 3 poses uses 6 of their 9 coordinates")
    angle = np.degrees(TRACKER.magnitude()) * 1e3
    assert (f"registration (best-fit): best fit on 3 poses (6 of their 9 coordinates), rms residual 0.000 µm; rigid "
            f"motion: rotation {angle:.6g} mdeg, translation {np.linalg.norm(SHIFT_M) * 1e6:.6g} µm") in out
    (tmp_path / "frame.toml").write_text(f"rpy_deg = {TRACKER.as_euler('xyz', degrees=True).tolist()}\n"
                                         f"translation_m = {SHIFT_M.tolist()}\n")
    assert main(["measure", path, "--out", tmp_path / "given", "--transform", tmp_path / "frame.toml",
                 "--report", "none"]) == 0
    out, err = capsys.readouterr()
    assert err == "" and f"registration (given): the transform given in {tmp_path / 'frame.toml'}" in out
    summary = json.loads((tmp_path / "given" / "summary.json").read_text())
    np.testing.assert_allclose(summary["settings"]["registration"]["rotation"], TRACKER.as_matrix(), atol=1e-12)
    assert summary["poses"][0]["directions"]["+"]["AP_p_um"] == pytest.approx(0.0, abs=1e-6)


@pytest.mark.filterwarnings("ignore::tribokin.measurement.registration.RegistrationWarning")
def test_each_series_has_its_test_of_independence_in_time_order_and_a_short_one_none(tmp_path):
    # P1: 12 cycles on one world-frame line, the tracker turned and shifted, measured in an order its t_s undoes;
    # P2, P3: 4 cycles each (below the 10 the test needs). Registered, the deviations are the line's offsets.
    along_um = np.array([3, -1, 4, 1, -5, 9, -2, 6, -5, 3, 5, -8], dtype=float)
    order = np.random.default_rng(0).permutation(12)
    lines = ["pose,cycle,x_m,y_m,z_m,cx_m,cy_m,cz_m,t_s"]
    for k, commanded in enumerate(COMMANDED_M):
        offsets = along_um[:, None] * [0.6e-6, 0.0, 0.8e-6] if k == 0 else CYCLES_UM * 1e-6
        times = order if k == 0 else np.arange(4)
        for cycle, (offset, t) in enumerate(zip(offsets[times], times, strict=True), start=1):
            measured = TRACKER.inv().apply(commanded + offset - SHIFT_M)
            lines.append(",".join([f"P{k + 1}", str(cycle), *(repr(float(v)) for v in (*measured, *commanded)),
                                   repr(float(100 * k + t))]))
    (path := tmp_path / "tracker.csv").write_text("\n".join(lines) + "\n")
    summary = measure(path, registration="best-fit").summary()
    d = along_um - along_um.mean()
    r1 = float(d[:-1] @ d[1:] / (d @ d))
    q = 12 * 14 * sum((d[:-k] @ d[k:] / (d @ d)) ** 2 / (12 - k) for k in (1, 2))
    first = summary["poses"][0]["directions"]["+"]
    assert first["lag1_autocorrelation"] == pytest.approx(r1, rel=1e-6)
    assert first["ljung_box_p"] == pytest.approx(np.exp(-q / 2), rel=1e-6) and first["ljung_box_lags"] == 2
    assert first["independent"] == (np.exp(-q / 2) >= 0.05)
    for pose in summary["poses"][1:]:
        assert pose["directions"]["+"]["lag1_autocorrelation"] is None
        assert pose["directions"]["+"]["independent"] is None
    assert summary["settings"]["independence"]["min_cycles"] == 10
