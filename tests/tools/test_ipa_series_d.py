"""tools/ipa_series_d.py: Series D of the IPA UR10 data as a measurement file, checked against facts read by hand
from the raw file (the copy in studies/data/ipa-ur10, checked against its upstream git blob hashes), the committed
conversion, and its one-line errors."""

from __future__ import annotations

import csv
import hashlib
import io
import re
from collections import Counter

import numpy as np
import pytest

from conftest import ROOT, load_tool
from tribokin.study.reading import read_study_file

ipa_series_d = load_tool("ipa_series_d")

DATA = ROOT / "studies" / "data" / "ipa-ur10"
COMMITTED = ROOT / "studies" / "data" / "ipa-ur10-series-d.csv"
RAW = DATA / "raw" / "Series_D" / "measurements_iso_cubes.csv"
TRAFO = DATA / "raw" / "Series_D" / "Trafo_TM_F_init.txt"
JOINTS = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint",
          "wrist_3_joint"]


def _rx(t):
    c, s = np.cos(t), np.sin(t)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def _ry(t):
    c, s = np.cos(t), np.sin(t)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def _rz(t):
    c, s = np.cos(t), np.sin(t)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def _raw_rows():
    """The raw file parsed by hand: header and rows of floats (';' separators, decimal commas)."""
    lines = RAW.read_text(encoding="utf-8").splitlines()
    header = lines[0].split(";")
    return header, [dict(zip(header, (float(v.replace(",", ".")) for v in line.split(";")), strict=True))
                    for line in lines[1:]]


def _read(text):
    """Comment lines and data rows (dicts of strings) of a measurement file."""
    lines = text.splitlines()
    comments = [line[2:] for line in lines if line.startswith("#")]
    return comments, list(csv.DictReader(io.StringIO("\n".join(line for line in lines if not line.startswith("#")))))


@pytest.fixture(scope="module")
def converted(tmp_path_factory):
    out = tmp_path_factory.mktemp("ipa") / "ipa-ur10-series-d.csv"
    assert ipa_series_d.main([str(DATA), "--out", str(out)]) == 0
    return out


def _git_blob(data: bytes) -> str:
    """Git's object hash of a file's bytes (``git hash-object``)."""
    return hashlib.sha1(b"blob %d\0" % len(data) + data).hexdigest()


def test_the_vendored_files_are_the_upstream_bytes_listed_in_the_provenance_note():
    # The note's table: | `path` | bytes | `git blob` | upstream path | ..., the hashes read from the upstream
    # commit's tree (git ls-tree -r 507fba69...).
    listed = {m[1]: (int(m[2]), m[3]) for m in re.finditer(r"^\| `([^`]+)` \| (\d+) \| `([0-9a-f]{40})` \|",
                                                           (DATA / "README.md").read_text(encoding="utf-8"), re.M)}
    assert {"raw/Series_D/measurements_iso_cubes.csv", "raw/Series_D/Trafo_TM_F_init.txt", "LICENSE"} <= set(listed)
    present = {p.relative_to(DATA).as_posix() for p in DATA.rglob("*") if p.is_file()} - {"README.md"}
    assert present == set(listed)
    for name, (size, blob) in listed.items():
        data = (DATA / name).read_bytes()
        assert (len(data), _git_blob(data)) == (size, blob), name
    assert b"\r\n" in (DATA / "raw/Series_D/measurements_iso_cubes.csv").read_bytes()  # CRLF kept, as upstream


def test_the_committed_conversion_is_what_the_tool_writes(converted):
    assert COMMITTED.read_bytes() == converted.read_bytes()
    comments, _ = _read(converted.read_text())
    named = [line for line in comments if line.startswith("Converted by")]
    assert named == ["Converted by tools/ipa_series_d.py (tribokin); see studies/data/ipa-ur10/README.md in "
                     "tribokin for the data."] and (DATA / "README.md").is_file()


def test_the_shipped_study_uses_the_probe_offset_the_conversion_prints():
    comments, _ = _read(COMMITTED.read_text(encoding="utf-8"))
    printed = {key: tuple(float(v) for v in line.split("[")[1].split("]")[0].split(","))
               for line in comments for key in ("tool_offset_m", "tool_offset_rpy_deg")
               if line.startswith(f"  robot.{key} = [")}
    robot = read_study_file(ROOT / "studies" / "ur10-ipa-calibrate.toml").robot
    assert printed == {"tool_offset_m": robot.tool_offset_m, "tool_offset_rpy_deg": robot.tool_offset_rpy_deg}


def test_counts_read_by_hand_from_the_raw_file(converted, capsys):
    # 633 lines = header + 632 rows; 31 poses measured more than once, of which the six two-visit centres
    # (first rows 486, 504, 522, 549, 576, 594) come once from the previous location and once along the cube
    # diagonal: 25 kept (L01 centre 5 rows, eight L01 corners 3 rows each, 16 centres 3 rows each).
    result = ipa_series_d.convert(DATA)
    assert result.rows_read == 632
    assert len(result.kept) == 25 and sum(map(len, result.kept.values())) == 5 + 8 * 3 + 16 * 3
    assert len(result.dropped) == 574 - 25
    repeated = sorted(name for name, rows in result.dropped.items() if len(rows) > 1)
    assert repeated == ["row486", "row504", "row522", "row549", "row576", "row594"]
    comments, rows = _read(converted.read_text())
    assert len(rows) == 77 and {r["pose"] for r in rows} == set(result.kept)
    assert any(line.startswith("  row594: rows 594, 603;") for line in comments)
    assert any(line.startswith("  and 543 measured once") for line in comments)
    assert "MIT, Copyright (c) 2021 Christian Landgraf" in "\n".join(comments)


def test_every_kept_pose_has_a_series_of_two_cycles_numbered_in_order(converted):
    _, rows = _read(converted.read_text())
    series = Counter()
    for row in rows:
        series[row["pose"], row["direction"]] += 1
        assert int(row["cycle"]) == series[row["pose"], row["direction"]]
    longest = Counter()
    for (pose, _), count in series.items():
        longest[pose] = max(longest[pose], count)
    assert min(longest.values()) >= 2
    # The L01 corners are always reached from the same preceding pose: one series of 3 each.
    assert all(len([k for k in series if k[0] == f"row00{i}"]) == 1 for i in range(1, 9))
    assert series["row000", "start"] == 1 and series["row000", "+0.58+0.58+0.58"] == 4
    assert series["row045", "+0.58+0.58+0.58"] == 2 and series["row045", "+0.33+0.33-0.89"] == 1


def test_grouping_tolerances_hold_within_every_pose(converted):
    header, raw = _raw_rows()
    by_joints = {tuple(r[j] for j in JOINTS): r for r in raw}
    _, rows = _read(converted.read_text())
    poses = {}
    for row in rows:
        source = by_joints[tuple(float(row[f"q_{j}"]) for j in JOINTS)]
        assert float(row["cx_m"]) == source["Goal x"]  # each row keeps its own commanded position
        poses.setdefault(row["pose"], []).append(source)
    for members in poses.values():
        c = np.array([[r["Goal x"], r["Goal y"], r["Goal z"]] for r in members])
        spread_m = np.linalg.norm(c[:, None] - c[None], axis=2).max()
        rotations = [_rz(r["Goal yaw"]) @ _ry(r["Goal pitch"]) @ _rx(r["Goal roll"]) for r in members]
        spread_deg = max(np.degrees(np.arccos(np.clip((np.trace(a.T @ b) - 1) / 2, -1, 1)))
                         for a in rotations for b in rotations)
        assert spread_m < 0.5e-3 and spread_deg < 0.1
    assert np.ptp([r["Goal x"] for r in poses["row000"]]) > 0  # the re-taught centre drifts


def test_decimal_commas_are_parsed(converted):
    # Raw data row 0: measurement_x 2336,7643 mm; Goal z 0,762898 m; shoulder_pan_joint 0,934319; measurement_std_x
    # 0,00095905 mm.
    _, rows = _read(converted.read_text())
    first = rows[0]
    assert (first["pose"], first["cycle"], first["direction"]) == ("row000", "1", "start")
    assert (first["x_m"], first["cz_m"], first["q_shoulder_pan_joint"], first["sx_mm"]) == (
        "2.3367643", "0.762898", "0.934319", "0.00095905")


def test_orientation_deviations_are_rotations_about_the_tracker_axes(converted):
    # Raw data rows 1 and 10 (pose row001, cycles 1 and 2): measurement_rx, _ry, _rz (intrinsic X-Y-Z, deg)
    # -89,122719; -78,89186; 0,70338482 and -89,124746; -78,897373; 0,70491163.
    first = _rx(np.radians(-89.122719)) @ _ry(np.radians(-78.89186)) @ _rz(np.radians(0.70338482))
    second = _rx(np.radians(-89.124746)) @ _ry(np.radians(-78.897373)) @ _rz(np.radians(0.70491163))
    turn = first @ second.T
    expected_deg = np.degrees([turn[2, 1] - turn[1, 2], turn[0, 2] - turn[2, 0], turn[1, 0] - turn[0, 1]]) / 2
    _, rows = _read(converted.read_text())
    pose = [r for r in rows if r["pose"] == "row001"]
    abc = np.array([[float(r[k]) for k in ("a_deg", "b_deg", "c_deg")] for r in pose])
    assert np.linalg.norm(expected_deg) > 1e-3
    np.testing.assert_allclose(abc[0] - abc[1], expected_deg, atol=1e-6)
    np.testing.assert_allclose(abc.mean(axis=0), 0, atol=1e-9)


def test_the_tool_offset_reproduces_the_commanded_pose_with_the_ur10_model(converted):
    # Maker's UR10 DH parameters; the ROS base is the maker's turned 180 deg about z. Raw data row 0: Goal 0,115748;
    # 0,63364; 0,762898 m, roll-pitch-yaw 1,5699; -0,000777623; -3,14154 rad.
    comments, rows = _read(converted.read_text())
    offset_m, rpy = ([line for line in comments if line.startswith(f"  robot.{key} = [")][0].split("[")[1].split("]")[0]
                     for key in ("tool_offset_m", "tool_offset_rpy_deg"))
    tool = np.eye(4)
    tool[:3, 3] = [float(v) for v in offset_m.split(",")]
    roll, pitch, yaw = np.radians([float(v) for v in rpy.split(",")])
    tool[:3, :3] = _rz(yaw) @ _ry(pitch) @ _rx(roll)
    pose = np.eye(4)
    pose[:3, :3] = _rz(np.pi)
    for a, d, alpha, q in zip([0, -0.612, -0.5723, 0, 0, 0], [0.1273, 0, 0, 0.163941, 0.1157, 0.0922],
                              [np.pi / 2, 0, 0, np.pi / 2, -np.pi / 2, 0],
                              [float(rows[0][f"q_{j}"]) for j in JOINTS], strict=True):
        link = np.eye(4)
        link[:3, :3] = _rz(q) @ _rx(alpha)
        link[:3, 3] = [a * np.cos(q), a * np.sin(q), d]
        pose = pose @ link
    pose = pose @ tool
    goal = _rz(-3.14154) @ _ry(-0.000777623) @ _rx(1.5699)
    assert np.linalg.norm(pose[:3, 3] - [0.115748, 0.63364, 0.762898]) < 0.1e-3
    assert np.degrees(np.arccos((np.trace(goal.T @ pose[:3, :3]) - 1) / 2)) < 0.05


def test_same_bytes_and_no_overwrite_without_force(converted, tmp_path, capsys):
    before = converted.read_bytes()
    assert ipa_series_d.main([str(DATA), "--out", str(converted)]) == 2
    assert capsys.readouterr().err.strip().endswith("exists; give another --out or add --force")
    assert ipa_series_d.main([str(DATA), "--out", str(converted), "--force"]) == 0
    printed = capsys.readouterr().out
    assert "read 632 rows; kept 25 poses (77 rows), dropped 549" in printed and "row594: rows 594, 603" in printed
    assert converted.read_bytes() == before


# Small synthetic inputs built from the real header and rows.


def _series(folder, edit=lambda header, rows: None, trafo=None):
    """A data folder holding raw rows 0-26 (the L01 400 mm cube, three times), changed by ``edit``."""
    lines = RAW.read_text(encoding="utf-8").splitlines()
    header, rows = lines[0].split(";"), [line.split(";") for line in lines[1:28]]
    edit(header, rows)
    series = folder / "raw" / "Series_D"
    series.mkdir(parents=True)
    (series / RAW.name).write_text("\r\n".join(";".join(r) for r in [header, *rows]) + "\r\n", encoding="utf-8")
    (series / TRAFO.name).write_text(TRAFO.read_text() if trafo is None else trafo)
    return folder


def _fails(folder, tmp_path, capsys, *words):
    out = tmp_path / "out.csv"
    assert ipa_series_d.main([str(folder), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and err.startswith("ipa_series_d: error: ")
    assert all(word in err for word in words), err
    assert not out.exists() and not list(tmp_path.glob(".out.csv.*"))


def test_a_small_valid_folder_keeps_the_cube_run_three_times(tmp_path):
    result = ipa_series_d.convert(_series(tmp_path / "d"))
    assert result.rows_read == 27 and len(result.kept) == 9 and result.dropped == {}


def test_a_missing_folder_is_one_line(tmp_path, capsys):
    _fails(tmp_path / "nowhere", tmp_path, capsys, "measurements_iso_cubes.csv", "cannot read it")


def test_a_missing_column_is_named(tmp_path, capsys):
    def rename(header, rows):
        header[header.index("measurement_rx")] = "measurement_roll"
    _fails(_series(tmp_path / "d", rename), tmp_path, capsys, "missing column(s) measurement_rx")


def test_a_non_number_names_line_and_column(tmp_path, capsys):
    def spoil(header, rows):
        rows[4][header.index("measurement_x")] = "2336,76x"
    _fails(_series(tmp_path / "d", spoil), tmp_path, capsys, "line 6: measurement_x", "'2336,76x' is not a finite")


def test_a_short_row_is_named(tmp_path, capsys):
    _fails(_series(tmp_path / "d", lambda header, rows: rows[2].pop()), tmp_path, capsys, "line 4", "25 fields")


def test_poses_chained_beyond_the_tolerance_are_refused(tmp_path, capsys):
    def chain(header, rows):  # rows 0, 9, 18 (the centre) 0.4 mm apart in a row: 0.8 mm end to end
        x = header.index("Goal x")
        for step, row in enumerate((0, 9, 18)):
            rows[row][x] = f"{0.115748 + 0.0004 * step:.6f}".replace(".", ",")
    _fails(_series(tmp_path / "d", chain), tmp_path, capsys, "data rows 0, 9, 18 chain into one pose")


def test_a_row_that_does_not_move_has_no_direction(tmp_path, capsys):
    def repeat(header, rows):
        rows[1] = list(rows[0])
    _fails(_series(tmp_path / "d", repeat), tmp_path, capsys, "data rows 0 and 1 are commanded within 0.5 mm")


def test_no_series_of_two_cycles_is_refused(tmp_path, capsys):
    def once(header, rows):
        del rows[9:]
    _fails(_series(tmp_path / "d", once), tmp_path, capsys, "no pose was measured twice from one direction")


def test_a_bad_tool_matrix_is_refused(tmp_path, capsys):
    _fails(_series(tmp_path / "d", trafo="1 0 0\n0 1 0\n"), tmp_path, capsys, "Trafo_TM_F_init.txt",
           "4x4")
