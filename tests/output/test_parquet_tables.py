"""Map tables as Parquet (``--table-format parquet``): the CSV's values in typed columns, the same bytes for the same
map however it was computed (workers, chunks) and however often it is written."""

import copy
import csv
import sys

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from conftest import GANTRY_MAP_TOML, ROOT
from tribokin import run_study
from tribokin.cli import main
from tribokin.execution import executor_for
from tribokin.maps.table import map_table_name
from tribokin.output.writers import write_map_table

#: The gantry over a plane whose last column is beyond its travel, in three scenarios: the reference, other friction
#: on z (the same robot), and the base moved 0.15 m along x (another robot: a reached_by column, other reasons).
STUDY = {
    "study": {"name": "gantry-parquet", "cycles": 6, "seed": 4},
    "robot": {"urdf": str(ROOT / "urdf" / "cartesian_xyz.urdf"), "tool_frame": "tool", "payload_kg": 5.0},
    "joints": {"friction": {"preset": "42CD4-raw"}, "stiffness": 2.0e7, "bearing_span_m": 0.2},
    "map": {"kind": "plane", "origin_m": [0.2, 0.0, 0.3], "axis_u": [1, 0, 0], "axis_v": [0, 1, 0],
            "extent_u_m": [0.0, 0.9], "extent_v_m": [0.0, 0.6], "resolution": [7, 4]},
    "scenarios": [{"name": "raw"}, {"name": "treated-z", "joints": {"z": {"friction": {"preset": "42CD4-treated"}}}},
                  {"name": "moved", "robot": {"base_xyz_m": [0.15, 0.0, 0.0]}}],
}


#: The gantry's plane map (conftest's) made small: 7 x 4 targets of 6 cycles, in one-row chunks.
PARQUET_STUDY_TOML = GANTRY_MAP_TOML
for _old, _new in (('name = "gantry-resume"', 'name = "gantry-parquet"'), ("cycles = 400", "cycles = 6"),
                   ("seed = 8", "seed = 4"), ("origin_m = [0.2, 0.0, 0.4]", "origin_m = [0.2, 0.0, 0.3]"),
                   ("extent_u_m = [0.0, 0.6]", "extent_u_m = [0.0, 0.9]"),
                   ("resolution = [25, 40]", "resolution = [7, 4]")):
    assert _old in PARQUET_STUDY_TOML, _old  # an edit that does not apply would test another study
    PARQUET_STUDY_TOML = PARQUET_STUDY_TOML.replace(_old, _new)

def study(**map_keys) -> dict:
    mapping = copy.deepcopy(STUDY)
    mapping["map"].update(map_keys)
    return mapping


def tables(workspace_map, folder, table_format: str) -> dict[str, bytes]:
    """Each scenario's table written in ``table_format`` into ``folder``: file name -> bytes."""
    folder.mkdir(exist_ok=True)
    written = {}
    for scenario in workspace_map.scenarios.values():
        path = folder / map_table_name(workspace_map, scenario, table_format)
        write_map_table(workspace_map, scenario, path, table_format)
        written[path.name] = path.read_bytes()
    return written


@pytest.fixture(scope="module")
def gantry():
    return run_study(study()).map


def csv_columns(path) -> dict[str, list[str]]:
    with open(path, newline="", encoding="utf-8") as handle:
        header, *rows = list(csv.reader(handle))
    return {name: [row[i] for row in rows] for i, name in enumerate(header)}


def test_parquet_holds_the_csvs_values_in_the_types_the_csv_implies(gantry, tmp_path):
    tables(gantry, tmp_path, "csv")
    names = tables(gantry, tmp_path, "parquet")
    assert sorted(names) == ["map.parquet", "map_moved.parquet", "map_treated-z.parquet"]
    seen = set()
    for name in names:
        table = pq.read_table(tmp_path / name)
        cells = csv_columns(tmp_path / name.replace(".parquet", ".csv"))
        assert table.column_names == list(cells)
        for column, values in cells.items():
            typed = table.column(column)
            if set(values) <= {"true", "false"}:
                assert typed.type == pa.bool_() and typed.to_pylist() == [v == "true" for v in values]
                seen.add("bool")
            elif all(v == "" or v.lstrip("-")[:1].isdigit() or v in ("inf", "-inf") for v in values):
                expected = np.array([float(v) if v else np.nan for v in values])
                got = typed.to_numpy()
                assert typed.type == pa.float64() and typed.null_count == 0  # empty cells: NaN, not null
                assert np.array_equal(np.isnan(got), np.isnan(expected))
                assert np.array_equal(got[~np.isnan(got)].view(np.int64), expected[~np.isnan(expected)].view(np.int64))
                seen.add("float")
            else:
                assert typed.type == pa.string() and typed.to_pylist() == values, column
                seen.add("text")
        assert table.num_rows == gantry.grid.size
    assert seen == {"bool", "float", "text"}
    assert "reached_by" in pq.read_table(tmp_path / "map_moved.parquet").column_names


def test_parquet_bytes_are_the_same_written_twice_and_however_the_map_was_computed(gantry, tmp_path):
    """Written twice; a map computed again in chunks of one grid row on two workers: the same bytes; no time, host
    or path in the file's metadata."""
    once = tables(gantry, tmp_path / "once", "parquet")
    assert tables(gantry, tmp_path / "twice", "parquet") == once
    with executor_for(2) as pool:
        again = run_study(study(chunk_rows=1), executor=pool).map
    assert tables(again, tmp_path / "chunked", "parquet") == once
    metadata = pq.read_metadata(tmp_path / "once" / "map.parquet")
    assert metadata.created_by.startswith("parquet-cpp-arrow version") and metadata.num_row_groups == 1
    assert str(tmp_path).encode() not in once["map.parquet"]


def test_the_command_writes_parquet_tables_instead_of_csv(tmp_path):
    path = tmp_path / "study.toml"
    path.write_text(PARQUET_STUDY_TOML)
    assert main(["run", str(path), "--out", str(tmp_path / "csv"), "--report", "none"]) == 0
    assert main(["run", str(path), "--out", str(tmp_path / "parquet"), "--report", "none", "--table-format",
                 "parquet", "--workers", "2"]) == 0
    files = {folder: sorted(p.name for p in (tmp_path / folder).iterdir()) for folder in ("csv", "parquet")}
    assert files["parquet"] == [name.replace("map.csv", "map.parquet") for name in files["csv"]]
    frame = pq.read_table(tmp_path / "parquet" / "map.parquet")
    assert frame.column_names == list(csv_columns(tmp_path / "csv" / "map.csv"))
    here = tables(run_study(path).map, tmp_path / "here", "parquet")  # one process, written by write_map_table
    assert (tmp_path / "parquet" / "map.parquet").read_bytes() == here["map.parquet"]


def test_parquet_without_pyarrow_is_refused_before_any_work(tmp_path, monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "pyarrow", None)
    monkeypatch.setitem(sys.modules, "pyarrow.parquet", None)
    path = tmp_path / "missing.toml"
    path.write_text("this study file is not even read")
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--table-format", "parquet"]) == 2
    err = capsys.readouterr().err.splitlines()
    assert err == ["tribokin: error: command line: --table-format: --table-format parquet needs pyarrow, which is "
                   "not installed; install it with pip install 'tribokin[data]'"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["missing.toml"]
