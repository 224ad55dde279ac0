"""`tribokin calibrate`: a study's joint model fitted to a measurement file, its outputs, and its bad input."""

from __future__ import annotations

import csv
import json
import os
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from scipy.stats import chi2

from conftest import ROOT
from helpers.command import in_process, tribokin
from helpers.folders import assert_frame_matches_csv, assert_frozen, assert_same_files
from helpers.profile_deviance import profile_deviance
from tribokin.calibration.data import stack

STUDY = ROOT / "studies" / "ur5-calibrate.toml"
DATA = ROOT / "studies" / "data" / "ur5-tracker.csv"
OUTPUTS = ("calibration.json", "comparison.csv", "calibrated.toml", "parity.png", "report.html")


def read_rows(path) -> tuple[list[str], list[str], list[dict]]:
    """Comment lines, header and rows of a CSV file."""
    lines = path.read_text(encoding="utf-8").splitlines()
    comments = [line for line in lines if line.startswith("#")]
    rows = list(csv.DictReader(line for line in lines if not line.startswith("#")))
    return comments, list(rows[0]), rows


def write_rows(path, header: list[str], rows: list[dict]) -> None:
    with open(path, "w", newline="", encoding="utf-8") as handle:
        writer = csv.DictWriter(handle, fieldnames=header)
        writer.writeheader()
        writer.writerows(rows)


def study_without_map(folder, **calibration) -> str:
    """ur5-calibrate.toml without its [map] (faster), its [calibration] keys replaced by ``calibration``."""
    text = STUDY.read_text(encoding="utf-8").split("\n# The calibrated model")[0]
    if calibration:
        head, _ = text.split("[calibration]")
        text = head + "[calibration]\n" + "".join(f"{k} = {json.dumps(v)}\n" for k, v in calibration.items())
    path = folder / "study.toml"
    path.write_text(text, encoding="utf-8")
    return path


def parameters(folder) -> dict[str, dict]:
    summary = json.loads((folder / "calibration.json").read_text(encoding="utf-8"))
    return {p["name"]: p for p in summary["parameters"]}


def study_with_small_map(folder) -> Path:
    """ur5-calibrate.toml with its map at 5 x 4 targets rather than 37 x 29 (the same outputs, faster)."""
    text = STUDY.read_text(encoding="utf-8")
    assert "resolution = [37, 29]" in text
    path = folder / "ur5-calibrate.toml"
    path.write_text(text.replace("resolution = [37, 29]", "resolution = [5, 4]"), encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def command_run(tmp_path_factory):
    """The command run on the study with its small map, in this process (no new interpreter's imports: 2-3 s of
    CPU; a fresh interpreter's run is compared with this process's by
    test_the_fit_writes_the_same_bytes_on_one_blas_thread_or_two): its folder, what it printed, the study, and the
    CalibrationResult it wrote (recorded from tribokin.measured.calibrated.calibrate, which the command calls)."""
    from tribokin.measured import calibrated as library

    folder = tmp_path_factory.mktemp("calibrate")
    study = study_with_small_map(folder)
    results, real = [], library.calibrate
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(library, "calibrate", lambda *args, **options: results.append(real(*args, **options)) or
                      results[-1])
        done = in_process("calibrate", study, "--measurements", DATA, "--out", folder / "fit")
    assert done.returncode == 0, done.stderr
    assert len(results) == 1
    return folder / "fit", done.stdout, study, results[0]


@pytest.fixture(scope="module")
def calibrated(command_run):
    """The command's folder, what it printed, and the study (:func:`command_run`)."""
    return command_run[:3]


@pytest.fixture(scope="module")
def registered(tmp_path_factory) -> tuple[Path, Path, str]:
    """The study without its map, its fit to the tracker file with Wald intervals (no report; the tests that use it
    check values, frames and the Wald intervals, the calibrated fixture's run the profile ones), and what it printed."""
    folder = tmp_path_factory.mktemp("registered")
    study = study_without_map(folder)
    done = in_process("calibrate", study, "--measurements", DATA, "--out", folder / "fit", "--report", "none",
                      "--intervals", "wald")
    assert done.returncode == 0, done.stderr
    return study, folder / "fit", done.stdout


@pytest.fixture(scope="module")
def library(command_run):
    """The command's CalibrationResult (one for every library check) and the folder its write() wrote beside the
    command's (``calibrated.toml`` names the study's files relative to its folder)."""
    *_, study, result = command_run
    out = study.parent / "library"
    assert result.write(out) == out
    return result, out


def test_calibrate_writes_its_folder_and_names_what_it_fitted(calibrated):
    out, stdout, _ = calibrated
    for name in OUTPUTS:
        assert (out / name).is_file(), name
    assert sorted(p.name for p in out.glob("clouds_*.png")) == [f"clouds_P{i}.png" for i in range(1, 6)]
    assert list(out.glob("map_*.png")), "the calibrated study's map"
    found = parameters(out)
    for name in ("joints.shoulder_pan_joint.stiffness", "joints.shoulder_lift_joint.stiffness",
                 "joints.elbow_joint.stiffness", "noise_floor_m"):
        assert found[name]["identifiable"], name
        low, high = found[name]["ci95"]
        assert low < found[name]["value"] < high
    wrist_3 = found["joints.wrist_3_joint.stiffness"]
    assert not wrist_3["identifiable"] and wrist_3["value"] is None and "axis" in wrist_3["hint"]
    assert "not identifiable" in stdout
    assert "frame: registered (auto): best fit on 5 poses (6 of their 15 coordinates), rms residual" in stdout
    registration = json.loads((out / "calibration.json").read_text(encoding="utf-8"))["registration"]
    assert registration["choice"] == "auto" and registration["made"] and registration["warning"] is None
    assert registration["coordinates_used"] == [6, 15] and registration["largest_share"] == pytest.approx(0.45)
    assert registration["rotation_angle_mdeg"] == pytest.approx(
        np.degrees(Rotation.from_matrix(registration["rotation"]).magnitude()) * 1e3, rel=1e-9)
    assert registration["translation_um"] == pytest.approx(np.linalg.norm(registration["translation_m"]) * 1e6,
                                                           rel=1e-12)


def test_comparison_holds_measured_and_predicted_figures_of_every_pose(calibrated):
    out, *_ = calibrated
    _, header, rows = read_rows(out / "comparison.csv")
    assert header[:5] == ["pose", "direction", "figure", "cycles", "measured_um"]
    assert {(r["pose"], r["figure"]) for r in rows} == {(f"P{i}", f) for i in range(1, 6) for f in ("RP_l", "vAP_p")}
    for row in rows:
        low, high = float(row["held_out_low_um"]), float(row["held_out_high_um"])
        assert low <= float(row["held_out_predicted_um"]) <= high


def test_the_command_s_result_written_again_gives_its_bytes_and_is_frozen(calibrated, library):
    """The CalibrationResult the command computed, written by its write() to another folder, gives the command's
    files byte for byte (a second, fresh interpreter's fit writes the same bytes as this process's:
    test_the_fit_writes_the_same_bytes_on_one_blas_thread_or_two)."""
    from tribokin import CalibrationResult

    result, out = library
    assert isinstance(result, CalibrationResult)
    assert_frozen(result)
    assert_same_files(out, calibrated[0])
    assert result.map is not None and result.calibrated.map is not None


def test_the_library_s_result_holds_what_the_command_printed(calibrated, library):
    result, _ = library
    _, stdout, _ = calibrated
    parameters = {p.name: p for p in result.calibration.parameters}
    for line in stdout.splitlines():
        name = line.split(" ")[0]
        if name in parameters and parameters[name].identifiable:
            low, high = result.intervals[name]
            assert line.split()[1:3] == [f"{parameters[name].value:.4g}", f"{parameters[name].std_error:.4g}"]
            assert low < parameters[name].value < high
    assert result.inputs.registration is not None and result.registration_why is None
    assert [c.row() for c in result.compared] == result.rows()


def test_the_profile_interval_ends_are_where_the_deviance_reaches_the_chi2_quantile(library):
    """The UR5's weakly determined parameters too (SLSQP's default 100 iterations, which a held elbow stiffness
    needed 120-170 of, left its upper end 0.4 % short): at each end the other parameters re-fitted by another
    optimiser give 2·(log L̂ - log L) = χ²₁(0.95), for the elbow's stiffness and backlash (the least determined)."""
    result, _ = library
    assert result.calibration.rotation is None  # registered: the deviance of θ alone
    for name in ("joints.elbow_joint.stiffness", "joints.elbow_joint.backlash"):
        for end in (end for end in result.intervals[name] if end is not None):
            deviance = profile_deviance(result.calibration, stack(result.inputs.poses), name, end)
            assert deviance == pytest.approx(chi2.ppf(0.95, 1), abs=2e-3), (name, end)


def test_the_library_s_table_is_comparison_csv(calibrated, library):
    result, _ = library
    assert_frame_matches_csv(result.to_pandas(), calibrated[0] / "comparison.csv")


def test_the_calibrated_study_runs_with_the_fitted_values(calibrated, tmp_path):
    out, *_ = calibrated
    text = (out / "calibrated.toml").read_text(encoding="utf-8")
    found = parameters(out)
    pan = found["joints.shoulder_pan_joint.stiffness"]["value"]
    assert f"stiffness = {pan!r}" in text and "profile likelihood" in text
    assert "not identifiable from the measurements" in text  # wrist_3 keeps the fit's value, and says so
    done = in_process("run", out / "calibrated.toml", "--out", tmp_path / "predicted", "--report", "none")
    assert done.returncode == 0, done.stderr
    summary = json.loads((tmp_path / "predicted" / "summary.json").read_text(encoding="utf-8"))
    assert [p["name"] for p in summary["poses"]] == [f"P{i}" for i in range(1, 6)]
    assert all(list(p["directions"]) == ["+x", "+y", "+z"] for p in summary["poses"])  # approached as measured
    assert summary["study"]["joint_models"]["shoulder_pan_joint"]["stiffness"] == pan


def test_the_fit_writes_the_same_bytes_on_one_blas_thread_or_two(registered):
    """OpenBLAS sums some products in an order set by its thread count: the fit run on one thread and on two gave
    standard errors 4e-5 apart (one thread: what dask's workers set in the process that starts them, and so in every
    command a test starts after a dask test in the same process). calibrate() fits on one
    (tribokin.calibration.blas_threads)."""
    study, fitted, _ = registered
    threads = "2" if os.environ.get("OPENBLAS_NUM_THREADS") == "1" else "1"  # not what the fixture's command had
    out = fitted.parent / f"fit-on-{threads}"  # beside the fixture's: calibrated.toml names the study alike
    done = tribokin("calibrate", study, "--measurements", DATA, "--out", out, "--report", "none", "--intervals",
                    "wald", env={"OPENBLAS_NUM_THREADS": threads, "OMP_NUM_THREADS": threads})
    assert done.returncode == 0, done.stderr
    for name in ("calibration.json", "calibrated.toml", "comparison.csv"):
        assert (out / name).read_bytes() == (fitted / name).read_bytes(), name


def test_rotating_and_shifting_the_measurements_changes_no_fitted_value(registered, tmp_path):
    study, fitted, _ = registered
    comments, header, rows = read_rows(DATA)
    rotation = Rotation.from_euler("zyx", [71.0, -12.0, 33.0], degrees=True).as_matrix()
    for row in rows:
        point = rotation @ [float(row[k]) for k in ("x_m", "y_m", "z_m")] + np.array([-3.2, 1.7, 0.9])
        row.update({k: repr(float(v)) for k, v in zip(("x_m", "y_m", "z_m"), point, strict=True)})
    write_rows(tmp_path / "moved.csv", header, rows)
    done = in_process("calibrate", study, "--measurements", tmp_path / "moved.csv", "--out", tmp_path / "moved",
                      "--report", "none", "--intervals", "wald")
    assert done.returncode == 0, done.stderr
    first, moved = parameters(fitted), parameters(tmp_path / "moved")
    for name, entry in first.items():
        assert entry["identifiable"] == moved[name]["identifiable"]
        if entry["identifiable"]:
            assert moved[name]["value"] == pytest.approx(entry["value"], rel=1e-9), name


def test_wald_intervals_are_the_standard_errors_in_log_space_and_the_output_says_so(registered, calibrated):
    """--intervals wald: each identifiable parameter's interval is value·exp(±1.96·se/value) (se its standard error,
    the same as the profile run's), the Wald interval calibration.json gives beside it; the settings, the printed
    table and calibrated.toml's comments name them; the values are the profile run's (its study has a map too)."""
    _, fitted, stdout = registered
    wald, profile = parameters(fitted), parameters(calibrated[0])
    summary = json.loads((fitted / "calibration.json").read_text(encoding="utf-8"))
    assert summary["settings"]["intervals"].startswith("Wald in log space")
    assert "95 % interval (Wald, log scale)" in stdout and "profile likelihood" not in stdout
    text = (fitted / "calibrated.toml").read_text(encoding="utf-8")
    assert "(Wald, log scale)" in text and "profile likelihood" not in text
    known = [name for name, entry in wald.items() if entry["identifiable"]]
    assert len(known) == 6
    for name in known:
        entry, se = wald[name], wald[name]["std_error"] / wald[name]["value"]
        assert entry == {**profile[name], "ci95": entry["ci95"]}, name
        assert entry["ci95"] == entry["ci95_wald"] != profile[name]["ci95"], name
        np.testing.assert_allclose(entry["ci95"], entry["value"] * np.exp([-1.959963984540054 * se,
                                                                           1.959963984540054 * se]), rtol=1e-12)


def test_intervals_other_than_profile_or_wald_are_refused_before_anything_is_read(tmp_path):
    from tribokin import calibrate
    from tribokin.errors import SettingsError

    with pytest.raises(SettingsError, match="must be one of profile, wald") as refused:
        calibrate(tmp_path / "absent.toml", DATA, intervals="bootstrap")
    assert refused.value.argument == "intervals"
    done = in_process("calibrate", tmp_path / "absent.toml", "--measurements", DATA, "--intervals", "bootstrap")
    assert done.returncode == 2 and "argument --intervals: invalid choice: 'bootstrap'" in done.stderr


def test_too_few_poses_name_the_parameters_they_cannot_determine_and_tying_the_joints_helps(tmp_path):
    comments, header, rows = read_rows(DATA)
    write_rows(tmp_path / "two.csv", header, [r for r in rows if r["pose"] in ("P1", "P2")])
    per_joint = study_without_map(tmp_path, fit=["stiffness", "noise_floor"])
    done = in_process("calibrate", per_joint, "--measurements", tmp_path / "two.csv", "--out", tmp_path / "per-joint",
                      "--report", "none", "--intervals", "wald")
    assert done.returncode == 0, done.stderr
    found = parameters(tmp_path / "per-joint")
    blind = [n for n, p in found.items() if n.endswith("stiffness") and not p["identifiable"]]
    assert blind and all(n in done.stdout for n in blind)
    tied = study_without_map(tmp_path, fit=["stiffness", "noise_floor"], tie="all")
    done = in_process("calibrate", tied, "--measurements", tmp_path / "two.csv", "--out", tmp_path / "tied",
                      "--report", "none", "--intervals", "wald")
    assert done.returncode == 0, done.stderr
    assert parameters(tmp_path / "tied")["joints.stiffness_factor"]["identifiable"]


BAD_STUDIES = {
    "no-calibration-section": ("[calibration]", "[iso_cube]\nside_m = 0.2\n",
                               "calibration: no [calibration] section"),
    "unknown-parameter": ("fit = [\"stiffness\", \"backlash\", \"noise_floor\"]", "fit = [\"stifness\"]",
                          "calibration.fit[0]: must be one of"),
    "unknown-joint": ("joints = \"all\"", "joints = [\"elbow\"]", "calibration.joints: unknown joint 'elbow'"),
    "noise-neither-fitted-nor-given": ("fit = [\"stiffness\", \"backlash\", \"noise_floor\"]", "fit = [\"stiffness\"]",
                                       "calibration.noise_floor_m: the instrument's noise floor is neither"),
}


@pytest.mark.parametrize("case", BAD_STUDIES)
def test_bad_study_is_one_line_and_writes_nothing(case, tmp_path):
    old, new, message = BAD_STUDIES[case]
    text = study_without_map(tmp_path).read_text(encoding="utf-8")
    assert old in text
    if case == "no-calibration-section":
        text = text.split(old)[0] + old
    (tmp_path / "study.toml").write_text(text.replace(old, new), encoding="utf-8")
    done = in_process("calibrate", tmp_path / "study.toml", "--measurements", DATA, "--out", tmp_path / "fit")
    assert done.returncode == 2 and len(done.stderr.strip().splitlines()) == 1, done.stderr
    assert message in done.stderr
    assert not (tmp_path / "fit").exists()


def test_measurements_without_configurations_or_commanded_positions_are_refused(tmp_path):
    _, header, rows = read_rows(DATA)
    kept = [h for h in header if not h.startswith(("q_", "cx_", "cy_", "cz_"))]
    write_rows(tmp_path / "bare.csv", kept, [{k: r[k] for k in kept} for r in rows])
    done = in_process("calibrate", study_without_map(tmp_path), "--measurements", tmp_path / "bare.csv",
                      "--out", tmp_path / "fit")
    assert done.returncode == 2 and "q_<joint> columns, or commanded positions" in done.stderr
    assert not (tmp_path / "fit").exists()


def test_a_joint_column_the_robot_does_not_have_is_refused(tmp_path):
    _, header, rows = read_rows(DATA)
    renamed = ["q_elbow" if h == "q_elbow_joint" else h for h in header]
    write_rows(tmp_path / "renamed.csv", renamed,
               [{("q_elbow" if k == "q_elbow_joint" else k): v for k, v in r.items()} for r in rows])
    done = in_process("calibrate", study_without_map(tmp_path), "--measurements", tmp_path / "renamed.csv",
                      "--out", tmp_path / "fit")
    assert done.returncode == 2 and "q_elbow: not a joint of ur5" in done.stderr


def test_configurations_from_commanded_positions_by_ik(tmp_path):
    """Without q_ columns each pose's configuration is solved by IK from its commanded position with the tool held
    at calibration.tool_rpy_deg: it puts the tool point there with that orientation (IK may pick another of the
    arm's branches than the file's q, so the fit is not compared)."""
    from tribokin.kinematics.robot import load_example_robot

    _, header, rows = read_rows(DATA)
    kept = [h for h in header if not h.startswith("q_")]
    write_rows(tmp_path / "commanded.csv", kept, [{k: r[k] for k in kept} for r in rows])
    cube_rpy = next(line for line in read_rows(DATA)[0] if "rpy_deg" in line).split("rpy_deg=[")[1].split("]")[0]
    rpy = [float(v) for v in cube_rpy.split(",")]
    study = study_without_map(tmp_path, fit=["stiffness", "backlash", "noise_floor"], tool_rpy_deg=rpy)
    done = in_process("calibrate", study, "--measurements", tmp_path / "commanded.csv", "--out", tmp_path / "ik",
                      "--report", "none", "--intervals", "wald")
    assert done.returncode == 0, done.stderr
    summary = json.loads((tmp_path / "ik" / "calibration.json").read_text(encoding="utf-8"))
    assert summary["settings"]["configurations"]["source"].startswith("inverse kinematics")
    robot = load_example_robot("ur5")
    held = Rotation.from_euler("xyz", rpy, degrees=True).as_matrix()  # roll-pitch-yaw: Rz Ry Rx
    for pose, q in summary["settings"]["configurations"]["q"].items():
        commanded = np.mean([[float(r[k]) for k in ("cx_m", "cy_m", "cz_m")] for r in rows if r["pose"] == pose],
                            axis=0)
        placement = robot.tool_placement(q)
        assert np.linalg.norm(placement.translation - commanded) < 1e-6
        assert np.allclose(placement.rotation, held, atol=1e-6)


def test_run_refuses_a_study_with_nothing_but_calibration(tmp_path):
    done = in_process("run", study_without_map(tmp_path), "--out", tmp_path / "out")
    assert done.returncode == 2 and "tribokin calibrate" in done.stderr


def test_without_a_registration_the_frame_is_fitted_and_the_output_says_so(registered, tmp_path):
    """--registration none (the same fit as a file without commanded positions, whose series' points are the same):
    the tracker frame's rotation is profiled out; the determined stiffnesses agree with the registered fit's within
    their standard errors."""
    study, fitted, _ = registered
    done = in_process("calibrate", study, "--measurements", DATA, "--out", tmp_path / "unknown", "--report", "none",
                      "--registration", "none", "--intervals", "wald")
    assert done.returncode == 0, done.stderr
    assert "frame: not registered (none)" in done.stdout
    summary = json.loads((tmp_path / "unknown" / "calibration.json").read_text(encoding="utf-8"))
    assert not summary["registration"]["made"] and "profiled out" in summary["registration"]["why"]
    assert summary["registration"]["choice"] == "none"
    rotation = np.array(summary["registration"]["fitted_rotation"])
    truth = Rotation.from_euler("xyz", [3.0, -2.0, 130.0], degrees=True).as_matrix()  # the file's tracker frame
    assert np.degrees(Rotation.from_matrix(rotation @ truth.T).magnitude()) < 5.0  # 2.4° here: shapes fix it loosely
    known, unknown = parameters(fitted), parameters(tmp_path / "unknown")
    for name in ("joints.shoulder_pan_joint.stiffness", "joints.shoulder_lift_joint.stiffness", "noise_floor_m"):
        assert unknown[name]["identifiable"]
        assert abs(unknown[name]["value"] - known[name]["value"]) < 2 * known[name]["std_error"]


GANTRY = ROOT / "urdf" / "cartesian_xyz.urdf"
#: The gantry's [joints] in each layout a study may give them (the same values): the calibrated study must parse,
#: run and carry each fitted value's interval in a comment.
JOINTS_LAYOUTS = {
    "root-dotted-keys": ('joints.stiffness = 2.0e6   # N/m, a guess\n'
                         'joints.friction_force_N = { law = "gaussian", mean = 20.0, std = 5.0 }\n'
                         'joints.z.backlash = 1.0e-6\n', ""),
    "root-inline-table": ('joints = { stiffness = 2.0e6, friction_force_N = { law = "gaussian", mean = 20.0, '
                          'std = 5.0 }, z = { backlash = 1.0e-6 } }\n', ""),
    "joint-tables-inline-and-dotted": ("", '[joints]\nstiffness = 2.0e6\nfriction_force_N = { law = "gaussian", '
                                           'mean = 20.0, std = 5.0 }\nx = { stiffness = 1.5e6 }\ny.stiffness = 2.5e6'
                                           '\n\n[joints.z]\nbacklash = 1.0e-6   # m\n'),
    "joint-tables-out-of-order": ("", '[joints]\nstiffness = 2.0e6\nfriction_force_N = { law = "gaussian", '
                                      'mean = 20.0, std = 5.0 }\n', '\n[joints.z]\nbacklash = 1.0e-6\n'),
}
#: The layouts tomlkit can edit in place (the others are written anew as tables, and the header says so).
KEPT_LAYOUTS = ("joint-tables-out-of-order",)


def gantry_study(folder, layout: str, calibration: str = 'fit = ["stiffness", "noise_floor"]') -> Path:
    """The gantry with ``calibration`` (default: of its stiffness and the noise floor), its [joints] in ``layout``."""
    root, tables, *after = JOINTS_LAYOUTS[layout]
    path = folder / "study.toml"
    path.write_text(f'{root}\n[study]\nname = "gantry"\ncycles = 8\n\n[robot]\nurdf = "{GANTRY}"\n'
                    f'tool_frame = "tool"\n\n{tables}\n[calibration]\n{calibration}\n' + "".join(after),
                    encoding="utf-8")
    return path


def gantry_measurements(path, backlash_m: float = 0.0, noise_m: float = 1e-6, rho: float | None = None,
                        cycles: int = 8) -> None:
    """Three poses of the gantry, each approached from + and - ``cycles`` times: every joint's lost motion from a
    friction force of 20 ± 5 N (independent between cycles, or with ``rho`` an AR(1) of that lag-one correlation) on
    stiffnesses 2e6, 1e6, 3e6 N/m and half its ``backlash_m``, ``noise_m`` of instrument noise (with commanded
    positions: registered by ``--registration best-fit``; three poses are too few for ``auto``)."""
    from tribokin.kinematics.robot import load_urdf

    robot, rng = load_urdf(GANTRY, tool_frame="tool"), np.random.default_rng(35)
    stiffness = np.array([2e6, 1e6, 3e6])
    rows = []
    for name, q in {"P1": [0.1, 0.2, 0.3], "P2": [0.3, 0.1, 0.2], "P3": [0.2, 0.3, 0.1]}.items():
        commanded = robot.tool_placement(np.array(q)).translation
        for direction, sign in (("+", 1.0), ("-", -1.0)):
            force = None  # the AR(1)'s standard normal state
            for cycle in range(1, cycles + 1):
                if rho is None:
                    lost = rng.normal(20.0, 5.0, 3) / stiffness + backlash_m / 2
                else:
                    shock = rng.normal(0.0, 1.0, 3)
                    force = shock if force is None else rho * force + np.sqrt(1 - rho * rho) * shock
                    lost = (20.0 + 5.0 * force) / stiffness + backlash_m / 2
                point = commanded + sign * lost + rng.normal(0.0, noise_m, 3)
                rows.append({"pose": name, "cycle": cycle, "direction": direction,
                             **{f"{a}_m": repr(float(v)) for a, v in zip("xyz", point, strict=True)},
                             **{f"c{a}_m": repr(float(v)) for a, v in zip("xyz", commanded, strict=True)},
                             **{f"q_{a}": v for a, v in zip("xyz", q, strict=True)}})
    write_rows(path, list(rows[0]), rows)


@pytest.mark.parametrize("layout", JOINTS_LAYOUTS)
def test_every_layout_of_joints_calibrates_and_the_calibrated_study_runs(layout, tmp_path):
    gantry_measurements(tmp_path / "data.csv")
    done = in_process("calibrate", gantry_study(tmp_path, layout), "--measurements", tmp_path / "data.csv", "--out",
                      tmp_path / "fit", "--report", "none", "--registration", "best-fit",  # registered, as before auto
                      "--intervals", "wald")
    assert done.returncode == 0, done.stderr
    text = (tmp_path / "fit" / "calibrated.toml").read_text(encoding="utf-8")
    found = parameters(tmp_path / "fit")
    lines = {line.split(" = ")[1].split(" # ")[0]: line for line in text.splitlines() if "stiffness = " in line}
    for joint in "xyz":
        entry = found[f"joints.{joint}.stiffness"]
        value = entry["value"] if entry["identifiable"] else entry["kept_value"]
        comment = "fitted: 95 % interval [" if entry["identifiable"] else "not identifiable from the measurements"
        assert comment in lines[repr(value)], (joint, text)  # the value's line carries its comment
    assert found["joints.x.stiffness"]["identifiable"]
    assert ("[joints] is written as tables below" in text) == (layout not in KEPT_LAYOUTS)
    if layout in KEPT_LAYOUTS:
        assert text.count("[joints.z]\nbacklash = 1.0e-6\n") == 1  # the user's own text, edited in place
    done = in_process("run", tmp_path / "fit" / "calibrated.toml", "--out", tmp_path / "predicted", "--report", "none")
    assert done.returncode == 0, done.stderr
    summary = json.loads((tmp_path / "predicted" / "summary.json").read_text(encoding="utf-8"))
    models = summary["study"]["joint_models"]
    for joint in "xyz":
        entry = found[f"joints.{joint}.stiffness"]
        assert models[joint]["stiffness"] == (entry["value"] if entry["identifiable"] else entry["kept_value"])
    assert models["z"]["backlash"] == 1e-6  # the study's other values kept
    assert {law["quantity"] for law in summary["study"]["friction"].values()} == {"friction_force_N"}
    assert [p["name"] for p in summary["poses"]] == ["P1", "P2", "P3"]


def test_fitted_values_run_would_refuse_are_one_line_naming_the_fit_and_nothing_is_written(tmp_path, monkeypatch,
                                                                                           capsys):
    """Should a fit (within the ranges) still give values `run` refuses (here a stiffness of 1 N/m forced in: the
    gantry's x axis would then lose more than its travel), calibrate says so in one line naming the measurements
    and what run would refuse, never the calibrated.toml it did not write."""
    from tribokin.cli import main
    from tribokin.measured import calibrated as calibrated_module
    from tribokin.study.calibrated_study import WrittenValue

    monkeypatch.setattr(calibrated_module, "_written_values",
                        lambda *args: [WrittenValue("x", "stiffness", 1.0, "forced by the test")])
    gantry_measurements(tmp_path / "data.csv")
    status = main(["calibrate", str(gantry_study(tmp_path, "joint-tables-out-of-order")), "--measurements",
                   str(tmp_path / "data.csv"), "--out", str(tmp_path / "fit"), "--report", "none", "--registration",
                   "best-fit", "--intervals", "wald"])
    error = capsys.readouterr().err
    assert status == 2 and len(error.strip().splitlines()) == 1, error
    assert error.startswith(f"tribokin: error: {tmp_path / 'data.csv'}: calibration: the fitted values make a study "
                            "that `tribokin run` refuses (joints.x.stiffness: ")
    assert "lost motion up to" in error and "calibrated.toml" not in error
    assert sorted(p.name for p in tmp_path.iterdir()) == ["data.csv", "study.toml"]


def test_a_fit_beyond_the_study_s_range_is_held_at_its_end_said_so_and_the_calibrated_study_runs(tmp_path):
    """Barycentres 0.12 m apart between + and -: the backlash the data ask for (0.12 m) is beyond the 0.1 m a study
    allows (main wrote 0.12, which run refuses). The fit holds it at 0.1, names it not identifiable there (never
    determined), says so in calibration.json, on the console and in calibrated.toml, which runs."""
    gantry_measurements(tmp_path / "data.csv", backlash_m=0.12, noise_m=1e-3)
    study = gantry_study(tmp_path, "joint-tables-out-of-order", 'fit = ["backlash"]\nnoise_floor_m = 1e-3')
    text = study.read_text(encoding="utf-8")
    study.write_text(text.replace("stiffness = 2.0e6", "stiffness = 2.0e6\nbacklash = 0.09"), encoding="utf-8")
    done = in_process("calibrate", study, "--measurements", tmp_path / "data.csv", "--out", tmp_path / "fit",
                      "--report", "none", "--registration", "best-fit",  # three poses: auto keeps the tracker's frame
                      "--intervals", "wald")
    assert done.returncode == 0, done.stderr
    text = (tmp_path / "fit" / "calibrated.toml").read_text(encoding="utf-8")
    for joint in "xyz":
        entry = parameters(tmp_path / "fit")[f"joints.{joint}.backlash"]
        assert not entry["identifiable"] and entry["value"] is None and "held at the end of the range" in entry["hint"]
        assert entry["kept_value"] == pytest.approx(0.1, rel=1e-12) and entry["kept_value"] <= 0.1
        assert f"backlash = {entry['kept_value']!r} # the fit's value" in text
    assert done.stdout.count("held at the end of the range a study allows") == 3
    done = in_process("run", tmp_path / "fit" / "calibrated.toml", "--out", tmp_path / "predicted", "--report", "none")
    assert done.returncode == 0, done.stderr


def test_a_measurement_file_beyond_the_memory_is_refused_before_it_is_read(tmp_path, capsys, monkeypatch):
    from tribokin.cli import main
    from tribokin.maps import budget
    from tribokin.measured import calibrated as calibrated_module

    monkeypatch.setattr(budget, "available_bytes", lambda: 2 ** 20)  # a machine of little memory
    monkeypatch.setattr(calibrated_module, "read_robot_measurements", None)  # never reached
    assert main(["calibrate", study_without_map(tmp_path), "--measurements", DATA, "--out", tmp_path / "fit"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"tribokin: error: {DATA}: rows: calibrating with this file needs")
    assert "1 MiB is available" in err and not (tmp_path / "fit").exists()


def test_a_map_beyond_the_memory_is_refused_before_the_fit(tmp_path, capsys, monkeypatch):
    from tribokin.cli import main
    from tribokin.maps import budget
    from tribokin.measured import calibrated as calibrated_module

    study = tmp_path / "study.toml"
    study.write_text(STUDY.read_text(encoding="utf-8").replace("cycles = 30", "cycles = 100000000"), encoding="utf-8")
    monkeypatch.setattr(budget, "available_bytes", lambda: 2 ** 30)
    monkeypatch.setattr(calibrated_module, "fit", None)  # the fit is never reached
    assert main(["calibrate", study, "--measurements", DATA, "--out", tmp_path / "fit"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"tribokin: error: {study}: study.cycles: this run needs about")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["study.toml"]


def test_fit_ar1_on_series_too_short_says_so_in_one_line_and_writes_no_ar1(tmp_path):
    """The gantry's 8-cycle series (the IPA UR10 file has 2-5): calibrate --fit-ar1 fits the rest and says in one
    line, and in calibration.json's ar1.reason, why it fits no ar1; calibrated.toml carries none."""
    study = gantry_study(tmp_path, "joint-tables-out-of-order")
    gantry_measurements(tmp_path / "data.csv")
    done = in_process("calibrate", study, "--measurements", tmp_path / "data.csv", "--out", tmp_path / "fit",
                      "--report", "none", "--intervals", "wald", "--fit-ar1")
    assert done.returncode == 0, done.stderr
    reason = ("no series has 10 or more cycles in time order (the longest has 8): too short to tell one cycle's "
              "friction from the next's")
    assert [line for line in done.stdout.splitlines() if line.startswith("ar1")] == [f"ar1: not fitted: {reason}"]
    summary = json.loads((tmp_path / "fit" / "calibration.json").read_text(encoding="utf-8"))
    assert summary["ar1"]["reason"] == reason and summary["ar1"]["longest_series"] == 8
    assert [g["value"] for g in summary["ar1"]["groups"]] == [None]
    assert "ar1 =" not in (tmp_path / "fit" / "calibrated.toml").read_text(encoding="utf-8")


def test_fit_ar1_recovers_the_friction_s_correlation_and_writes_it_into_its_table(tmp_path):
    """Gantry series of 40 cycles whose friction forces are AR(1)s of 0.7: the [joints] friction's group (every
    joint) dominates all six series, its ar1's 95 % interval covers 0.7, and calibrated.toml gives it in the
    friction's table with its interval, and the console and the report the same."""
    study = gantry_study(tmp_path, "joint-tables-out-of-order")
    gantry_measurements(tmp_path / "data.csv", rho=0.7, cycles=40)
    done = in_process("calibrate", study, "--measurements", tmp_path / "data.csv", "--out", tmp_path / "fit",
                      "--intervals", "wald", "--fit-ar1")
    assert done.returncode == 0, done.stderr
    (group,) = json.loads((tmp_path / "fit" / "calibration.json").read_text(encoding="utf-8"))["ar1"]["groups"]
    assert group["key"] == "joints.friction_force_N" and group["joints"] == ["x", "y", "z"]
    low, high = group["ci95"]
    assert low < 0.7 < high and high - low < 0.25 and group["series"] == 6, group
    line = next(line for line in (tmp_path / "fit" / "calibrated.toml").read_text(encoding="utf-8").splitlines()
                if line.startswith("friction_force_N"))
    assert f"ar1 = {group['value']!r}" in line and f"95 % interval [{low:.3g}, {high:.3g}]" in line
    assert f"ar1 joints.friction_force_N (x, y, z): {group['value']:.3f}" in done.stdout
    report = (tmp_path / "fit" / "report.html").read_text(encoding="utf-8")
    assert f"joints.friction_force_N: {group['value']:.3f} [{low:.3f}, {high:.3f}] (6 series)" in report


def test_fit_ar1_other_than_true_or_false_is_refused_before_anything_is_read(tmp_path):
    from tribokin import calibrate
    from tribokin.errors import SettingsError

    with pytest.raises(SettingsError, match="must be True or False") as refused:
        calibrate(tmp_path / "absent.toml", DATA, fit_ar1="yes")
    assert refused.value.argument == "fit_ar1"


#: A 3 x 3 plane of the gantry's workspace: the map a calibrated study runs with the fitted ar1.
GANTRY_SERIES_MAP = ('\n[map]\nkind = "plane"\norigin_m = [0.2, 0.0, 0.4]\naxis_u = [1, 0, 0]\naxis_v = [0, 1, 0]\n'
                     'extent_u_m = [0.0, 0.6]\nextent_v_m = [0.0, 0.6]\nresolution = [3, 3]\n')


def test_fit_ar1_with_a_map_writes_a_calibrated_study_whose_map_draws_it_and_run_runs_it(tmp_path):
    """A study with a [map] calibrated with fit_ar1 (refused before maps drew friction time keys): calibrated.toml
    carries the fitted ar1 and the map; run_study of it runs, its joints' series and its map's tests drawn with that
    ar1 (the summary's map.state: a map whose friction is correlated), and the calibration's map is that map (the
    same summary, to the last bit). The library throughout: the command's folder is test_calibrate_writes_its_folder's
    and test_the_command_s_result_written_again_gives_its_bytes_and_is_frozen'."""
    from tribokin import calibrate, run_study

    study = gantry_study(tmp_path, "joint-tables-out-of-order")
    study.write_text(study.read_text(encoding="utf-8") + GANTRY_SERIES_MAP, encoding="utf-8")
    gantry_measurements(tmp_path / "data.csv", rho=0.7, cycles=40)
    fit = tmp_path / "fit"
    result = calibrate(study, tmp_path / "data.csv", out=fit, intervals="wald", fit_ar1=True)
    (group,) = json.loads(json.dumps(result.summary()))["ar1"]["groups"]
    assert group["value"] is not None and group["series"] == 6, group
    text = result.calibrated_text(fit)
    assert f"ar1 = {group['value']!r}" in text and GANTRY_SERIES_MAP in text
    fit.mkdir()
    (fit / "calibrated.toml").write_text(text, encoding="utf-8")
    summary = json.loads(json.dumps(run_study(fit / "calibrated.toml", meshes=False).summary()))
    assert {joint: model["series"]["ar1"] for joint, model in summary["study"]["joint_models"].items()} == \
        dict.fromkeys("xyz", group["value"])
    assert summary["map"]["state"] == {"after_s": 0.0} and summary["map"]["reachable"] == 9
    assert json.loads(json.dumps(result.map.summary())) == summary["map"]
