"""map.csv written by orjson a few thousand lines at a time: the bytes of ``repr`` and ``csv.writer`` cell by cell."""

import copy
import csv
import io

import numpy as np
import pytest

from conftest import STUDIES
from tribokin import run_study
from tribokin.execution import executor_for
from tribokin.output import writers
from tribokin.output.writers import column_cells, float_lines, map_table_name, table_lines, write_map_table
from tribokin.study.reading import read_study_file

SPECIAL = [0.0, -0.0, 3.0, -3.0, 0.1, 1e-4, 9.999999999999999e-05, 1e-5, 1.5e-5, -2e-7, 1e-9, 9.99e-10, 1e-10,
           5e-324, -5e-324, 2.2250738585072014e-308, 2.225073858507201e-308, 1e308, 1.7976931348623157e308,
           1e15, 1e16, 123456789012345678.0, np.inf, -np.inf, np.nan]
TEXTS = ["", "elbow_joint", "a, b", 'say "hi"', '"', ",", "line\nbreak", "cr\rhere", " spaced ", "tab\tx", "µm"]


def repr_lines(columns: dict) -> str:
    """The lines as the writer before issue 22 wrote them: ``repr`` of each float (NaN empty), true/false,
    ``csv.writer`` for the rest."""
    def cell(value):
        if isinstance(value, bool):
            return "true" if value else "false"
        return ("" if np.isnan(value) else repr(value)) if isinstance(value, float) else value

    text = io.StringIO()
    csv.writer(text).writerows([cell(v) for v in row]
                               for row in zip(*(c.tolist() for c in columns.values()), strict=True))
    return text.getvalue()


def test_every_float_is_written_as_repr_and_round_trips_bit_for_bit():
    """Random bit patterns (subnormals, huge, NaN payloads), every order of magnitude, and the edges of orjson's
    and repr's styles: the cell is repr's (so -0.0 is ``-0.0``, 3.0 is ``3.0``, inf ``inf``), NaN empty."""
    rng = np.random.default_rng(22)
    values = np.concatenate([rng.integers(0, 2**64, 200_003, dtype=np.uint64).view(np.float64),
                             rng.normal(size=50_000) * 10.0 ** rng.integers(-320, 300, 50_000), SPECIAL])
    cells = [cell.decode() for cell in float_lines(values[:, None])]
    assert cells == ["" if np.isnan(v) else repr(v) for v in values.tolist()]
    finite = ~np.isnan(values)
    parsed = np.array([float(cell) for cell, keep in zip(cells, finite, strict=True) if keep])
    assert np.array_equal(parsed.view(np.int64), values[finite].view(np.int64))
    assert float_lines(values.reshape(-1, 4)) == [",".join(cells[i:i + 4]).encode() for i in range(0, len(cells), 4)]
    assert float_lines(values[::-7, None]) == [cell.encode() for cell in cells[::-7]]
    assert float_lines(np.empty((0, 3))) == []



def test_columns_of_small_floats_formatted_whole_are_written_as_repr():
    """Columns where many cells are small (1e-12 to 1e-2: orjson's one-digit exponents and positional values below
    1e-4, which ``repr`` writes otherwise), with NaN, ±inf and zeros among them, beside an ordinary column: formatted
    a column at a time, every cell is repr's."""
    rng = np.random.default_rng(23)
    small = rng.choice([-1.0, 1.0], 60_000) * 10.0 ** rng.uniform(-12, -2, 60_000)
    small = np.array([float(f"{v:.{digits}g}") for v, digits in  # short digit strings too: 1e-05, 1.5e-06
                      zip(small.tolist(), rng.integers(1, 18, 60_000).tolist(), strict=True)])
    small[rng.random(60_000) < 0.05] = np.nan
    small[:6] = [np.inf, -np.inf, 0.0, -0.0, 1e-5, 1.5e-5]
    values = np.column_stack([small, rng.normal(size=60_000), small[::-1]])
    expected = [",".join("" if np.isnan(v) else repr(v) for v in row).encode() for row in values.tolist()]
    assert float_lines(values) == expected
    assert float_lines(values[:, :1]) == [line.split(b",")[0] for line in expected]

def test_rows_of_nan_only_and_rows_with_some_nan_have_empty_cells():
    values = np.array([[np.nan, np.nan, np.nan], [1.0, np.nan, -2.5], [np.nan, 3e-5, np.nan], [0.5, 1.0, 2.0]])
    assert float_lines(values) == [b",,", b"1.0,,-2.5", b",3e-05,", b"0.5,1.0,2.0"]
    assert float_lines(np.full((2, 1), np.nan)) == [b"", b""]


def test_booleans_and_text_are_written_as_csv_writer_writes_them():
    texts = np.array(TEXTS, dtype=object)
    columns = {"ok": np.arange(len(TEXTS)) % 2 == 0, "name": texts, "x": np.linspace(0, 1, len(TEXTS))}
    assert column_cells(columns["ok"])[:2] == [b"true", b"false"]
    lines = b"".join(table_lines(columns)).decode()
    assert lines == repr_lines(columns)
    assert [row[1] for row in csv.reader(io.StringIO(lines))] == TEXTS


@pytest.mark.parametrize("rows", [1, 3, 4096])
def test_lines_are_the_same_however_many_are_formatted_at_a_time(rows):
    rng = np.random.default_rng(rows)
    columns = {"a": rng.normal(size=10), "b": np.where(rng.random(10) < 0.5, np.nan, rng.random(10) * 1e-6),
               "c": rng.random(10) < 0.5, "d": rng.choice(np.array(TEXTS, dtype=object), 10)}
    assert b"".join(table_lines(columns, rows)).decode() == repr_lines(columns)


def test_map_tables_of_a_real_map_are_the_repr_writers_bytes_written_block_by_block(tmp_path, monkeypatch):
    """A UR5 map with unreachable targets and two scenarios: each table is the old writer's bytes, the same with
    blocks of 4 targets, the columns read 4 targets at a time."""
    result = run_study({
        "study": {"name": "ur5-map", "cycles": 20, "seed": 5},
        "robot": {"name": "ur5", "payload_kg": 2.0},
        "joints": {"friction": {"preset": "42CD4-raw"}, "stiffness": 1.0e5, "bearing_span_m": 0.08},
        "map": {"kind": "plane", "origin_m": [0.0, -0.5, 0.1], "axis_u": [0, -1, 0], "axis_v": [0, 0, 1],
                "extent_u_m": [-0.2, 0.45], "extent_v_m": [0.0, 0.3], "resolution": [5, 3]},
        "scenarios": [{"name": "raw"}, {"name": "treated-shoulder",
                                        "joints": {"shoulder_lift_joint": {"friction": {"preset": "42CD4-treated"}}}}],
    })
    workspace_map, columns, tables = result.map, writers.map_table_columns, {}
    assert 0 < int(workspace_map.reachable.sum()) < workspace_map.grid.size
    for scenario in workspace_map.scenarios.values():
        path = tmp_path / map_table_name(workspace_map, scenario)
        write_map_table(workspace_map, scenario, path)
        whole = columns(workspace_map, scenario, slice(0, workspace_map.grid.size))
        assert path.read_bytes() == (",".join(whole) + "\r\n" + repr_lines(whole)).encode()
        tables[scenario.name] = path.read_bytes()
    read = []
    monkeypatch.setattr(writers, "TABLE_TARGETS", 4)
    monkeypatch.setattr(writers, "map_table_columns", lambda m, s, part: read.append(part) or columns(m, s, part))
    for scenario in workspace_map.scenarios.values():
        write_map_table(workspace_map, scenario, tmp_path / "blocks.csv")
        assert (tmp_path / "blocks.csv").read_bytes() == tables[scenario.name]
    assert [part.stop - part.start for part in read] == [0, 4, 4, 4, 3] * 2  # the header's names, then blocks


def test_map_tables_formatted_by_two_workers_while_the_figures_are_drawn_are_the_same_bytes(tmp_path, monkeypatch):
    """Blocks of 7 targets formatted by a pool of 2 processes (reading the map's store) into part files, while
    ``meanwhile`` runs here: the same bytes as written here, block after block, and no part file left."""
    monkeypatch.setattr(writers, "TABLE_TARGETS", 7)
    study = copy.deepcopy(read_study_file(STUDIES / "ur5-map-horizontal.toml").mapping)
    study["map"]["resolution"] = [6, 5]
    result = run_study(study)
    workspace_map = result.map
    scenario = workspace_map.reference
    write_map_table(workspace_map, scenario, tmp_path / "here.csv")
    events = []
    with executor_for(2) as pool:
        writers.write_map_tables(workspace_map, [(scenario, tmp_path / "pool.csv")], pool,
                                 lambda: events.append((tmp_path / "pool.csv").exists()))
    assert events == [False]  # meanwhile ran before the table was opened
    assert (tmp_path / "pool.csv").read_bytes() == (tmp_path / "here.csv").read_bytes()
    assert (tmp_path / "here.csv").read_bytes().count(b"\r\n") == workspace_map.grid.size + 1
    assert sorted(path.name for path in tmp_path.iterdir()) == ["here.csv", "pool.csv"]
