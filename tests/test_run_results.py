"""A study's results as the library hands them over: StudyResult.to_pandas() and PoseResult.to_pandas() hold
poses.csv's columns and numbers, and StudyResult.write(folder) writes the command's files."""

import csv
import json

import numpy as np
import pytest

from conftest import ROOT
from helpers.map_studies import gantry_map_study
from tribokin import InputError, run_study
from tribokin.cli import main
from tribokin.output.writers import write_pose_table

#: The gantry: a pose with its own friction law, the ISO cube's five poses from two approach directions, and a small
#: plane map in two scenarios (its last column beyond the travel): every kind of poses.csv cell, and map tables.
STUDY = f"""[study]
name = "gantry-results"
cycles = 8
seed = 21
approach = "bidirectional"

[robot]
urdf = "{ROOT / 'urdf' / 'cartesian_xyz.urdf'}"
tool_frame = "tool"
payload_kg = 5.0

[joints]
friction = {{ preset = "42CD4-raw" }}
stiffness = 2.0e7
bearing_span_m = 0.2

[[poses]]
name = "own-law"
q = [0.3, 0.2, 0.1]
friction = {{ law = "uniform", low = 0.05, high = 0.15 }}

[iso_cube]
center_m = [0.5, 0.3, 0.45]
side_m = 0.2

[map]
kind = "plane"
origin_m = [0.2, 0.0, 0.3]
axis_u = [1, 0, 0]
axis_v = [0, 1, 0]
extent_u_m = [0.0, 0.9]
extent_v_m = [0.0, 0.6]
resolution = [4, 3]

[[scenarios]]
name = "raw"

[[scenarios]]
name = "treated-z"
joints.z.friction = {{ preset = "42CD4-treated" }}
"""


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    path = tmp_path_factory.mktemp("study") / "gantry-results.toml"
    path.write_text(STUDY)
    return path


@pytest.fixture(scope="module")
def result(study):
    return run_study(study)


def read_csv(path) -> dict[str, list[str]]:
    with open(path, newline="", encoding="utf-8") as handle:
        header, *rows = list(csv.reader(handle))
    return {name: [row[i] for row in rows] for i, name in enumerate(header)}


def assert_column(values: np.ndarray, cells: list[str], what: str) -> None:
    """A DataFrame column holds the file's cells: the same float bits (NaN where empty), else the same text (a pose's
    own friction law: the dict whose text the file holds; NaN where the file's cell is empty)."""
    try:
        expected = np.array([float(cell) if cell else np.nan for cell in cells])
    except ValueError:
        assert ["" if isinstance(v, float) and np.isnan(v) else str(v) for v in values] == cells, what
        return
    values = values.astype(np.float64)
    assert np.array_equal(np.isnan(values), np.isnan(expected)), what
    assert np.array_equal(values[~np.isnan(values)].view(np.int64), expected[~np.isnan(expected)].view(np.int64)), what


def test_study_and_pose_frames_hold_poses_csv(result, tmp_path):
    write_pose_table(result, tmp_path)  # as write() and the command write it (test_write_gives_the_commands_files...)
    table = read_csv(tmp_path / "poses.csv")
    frame = result.to_pandas()
    assert list(frame.columns) == list(table) and len(frame) == len(table["name"]) > 6  # poses x directions
    for column, cells in table.items():
        assert_column(frame[column].to_numpy(), cells, column)
    assert frame["RP_l_um"].dtype == np.float64 and "q_x" in frame and "normal_force_z_N" in frame
    assert frame["vAP_p_um"].notna().all() and frame["ellipsoid_semi_axis_1_um"].notna().all()
    pose = result.pose("own-law").to_pandas()
    assert list(pose.columns) == [c for c in frame.columns if c in pose.columns] and len(pose) == 2  # + and -
    rows = frame[frame["name"] == "own-law"].reset_index(drop=True)
    assert pose.equals(rows[pose.columns]) and "friction" in pose


def folder_files(folder) -> dict[str, bytes]:
    return {path.name: path.read_bytes() for path in sorted(folder.iterdir())}


def test_write_gives_the_commands_files_but_the_command_line_summary_json_records(study, result, tmp_path):
    """The same study through `tribokin run` (its views drawn in the views' process) and through write() (drawn
    here): every file the same bytes, report and scene included; summary.json differs only in
    reproduce.command, the command line, which a library call has none of (None)."""
    assert main(["run", str(study), "--out", str(tmp_path / "command")]) == 0
    written = result.write(tmp_path / "library")
    command, library = folder_files(tmp_path / "command"), folder_files(written)
    assert sorted(command) == sorted(library)
    assert {"report.html", "scene.npz", "poses.csv", "samples.npz", "map.csv", "map_treated-z.csv"} <= set(library)
    assert [name for name in command if command[name] != library[name]] == ["summary.json"]
    by_command, by_library = json.loads(command["summary.json"]), json.loads(library["summary.json"])
    assert by_command["reproduce"].pop("command") == ["tribokin", "run", str(study), "--out", str(tmp_path / "command")]
    assert by_library["reproduce"].pop("command") is None
    assert by_command == by_library
    assert not (tmp_path / "library.lock").exists()


def test_write_refuses_an_existing_folder_unless_forced(tmp_path):
    """On a map of four targets: what write() refuses and replaces does not depend on what the results hold (the
    module's study would draw its six poses' and two scenarios' figures for nothing)."""
    study = gantry_map_study()
    study["map"]["resolution"] = [2, 2]
    result = run_study(study)
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "notes.txt").write_text("a user's")
    with pytest.raises(InputError, match="output folder exists; choose another --out or pass --force"):
        result.write(tmp_path / "mine", report="none")
    assert folder_files(tmp_path / "mine") == {"notes.txt": b"a user's"}
    result.write(tmp_path / "mine", force=True, report="none", table_format="parquet")
    assert "notes.txt" not in folder_files(tmp_path / "mine") and (tmp_path / "mine" / "map.parquet").exists()
