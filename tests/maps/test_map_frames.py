"""A map's to_pandas() and to_xarray() hold exactly the numbers of its tables (map.csv, map_<scenario>.csv), parsed
from the written files: a plane, a box and a joint map of the gantry (two scenarios: other friction), and a plane of
studies/what-if-robots.toml, whose scenarios change the robot (a UR5 and a UR10)."""

import copy
import csv
import sys

import numpy as np
import pytest

from conftest import ROOT, STUDIES
from tribokin import MapResult, TribokinError, run_study
from tribokin.errors import MissingExtraError
from tribokin.maps.table import map_table_name
from tribokin.output.writers import write_map_table
from tribokin.study.reading import read_study_file

GANTRY = {
    "study": {"cycles": 8, "seed": 3},
    "robot": {"urdf": str(ROOT / "urdf" / "cartesian_xyz.urdf"), "tool_frame": "tool", "payload_kg": 5.0},
    "joints": {"friction": {"preset": "42CD4-raw"}, "stiffness": 2.0e7, "bearing_span_m": 0.2},
    "scenarios": [{"name": "raw"}, {"name": "treated-z", "joints": {"z": {"friction": {"preset": "42CD4-treated"}}}}],
}
#: The plane's last column (x = 0.9 m) is beyond the gantry's travel (x <= 0.8 m): unreachable targets, empty cells.
MAPS = {
    "plane": {"kind": "plane", "origin_m": [0.2, 0.0, 0.3], "axis_u": [1, 0, 0], "axis_v": [0, 0.6, 0.8],
              "extent_u_m": [0.0, 0.7], "extent_v_m": [0.0, 0.3], "resolution": [4, 3]},
    "box": {"kind": "box", "min_m": [0.3, 0.1, 0.25], "max_m": [0.5, 0.5, 0.45], "resolution": [2, 3, 2]},
    "joint": {"kind": "joint", "joints": ["z", "y"], "ranges": [[0.0, 0.4], [0.1, 0.3]], "counts": [3, 2]},
}
DIMS = {"plane": ("v", "u"), "box": ("z", "y", "x"), "joint": ("y", "z"), "robots": ("v", "u")}


def gantry_map(kind: str) -> MapResult:
    return run_study({**copy.deepcopy(GANTRY), "map": MAPS[kind]}).map


def robots_map() -> MapResult:
    """studies/what-if-robots.toml at 3 x 3 targets: the far row (y = -1 m) beyond the UR5, within the UR10."""
    study = copy.deepcopy(read_study_file(STUDIES / "what-if-robots.toml").mapping)
    study["map"]["resolution"] = [3, 3]
    study["study"]["cycles"] = 5
    return run_study(study).map


@pytest.fixture(scope="module", params=["plane", "box", "joint", "robots"])
def written(request, tmp_path_factory):
    """A map and its tables as written (name -> header, columns of cells)."""
    workspace_map = robots_map() if request.param == "robots" else gantry_map(request.param)
    folder = tmp_path_factory.mktemp(request.param)
    tables = {}
    for scenario in workspace_map.scenarios.values():
        path = folder / map_table_name(workspace_map, scenario)
        write_map_table(workspace_map, scenario, path)
        with open(path, newline="", encoding="utf-8") as handle:
            header, *rows = list(csv.reader(handle))
        tables[scenario.name] = {name: [row[i] for row in rows] for i, name in enumerate(header)}
    return request.param, workspace_map, tables


def parsed(cells: list[str]) -> np.ndarray:
    """A column of cells as map.csv means it: floats (empty: NaN), booleans (true/false) or text (a column of empty
    cells only: text, the reasons of a map whose every target is reachable)."""
    if set(cells) == {""}:
        return np.array(cells, dtype=object)
    if set(cells) <= {"true", "false"}:
        return np.array([cell == "true" for cell in cells])
    try:
        return np.array([float(cell) if cell else np.nan for cell in cells])
    except ValueError:
        return np.array(cells, dtype=object)


def assert_same(values, cells: list[str], what: str) -> None:
    """``values`` hold exactly the cells: the same bits for floats (NaN where empty), booleans, text."""
    expected, values = parsed(cells), np.asarray(values)
    if expected.dtype.kind == "f":
        assert values.dtype == np.float64, what
        assert np.array_equal(np.isnan(values), np.isnan(expected)), what
        assert np.array_equal(values[~np.isnan(values)].view(np.int64),
                              expected[~np.isnan(expected)].view(np.int64)), what
    else:
        assert values.tolist() == expected.tolist(), what


def missing(values) -> bool:
    """Whether a column is empty throughout: NaN, None or ``""``."""
    return all(v is None or v == "" or (isinstance(v, float) and np.isnan(v)) for v in np.asarray(values).tolist())


def test_to_pandas_holds_every_table_column_by_column(written):
    kind, workspace_map, tables = written
    frame = workspace_map.to_pandas()
    assert frame.index.name == "target" and frame.columns[0] == "scenario"
    assert list(frame["scenario"]) == [name for name in tables for _ in range(workspace_map.grid.size)]
    assert frame["reachable"].dtype == bool and frame["RP_l_um"].dtype == np.float64
    for name, table in tables.items():
        rows = frame[frame["scenario"] == name]
        assert list(rows.index) == list(range(workspace_map.grid.size))
        assert [c for c in rows.columns if c in table] == list(table)  # map.csv's columns, in its order
        for column, cells in table.items():
            assert_same(rows[column].to_numpy(), cells, f"{kind} {name} {column}")
        others = [c for c in rows.columns if c not in table and c != "scenario"]
        assert all(missing(rows[c].to_numpy()) for c in others), others
    assert np.isnan(frame["RP_l_um"]).any() == (kind in ("plane", "robots"))  # unreachable targets: empty cells


def dataset_column(dataset, kind: str, scenario: int, name: str, robots: dict[int, str]):
    """Table column ``name`` of scenario number ``scenario`` from the Dataset, flattened in target order."""
    suffix = "" if len(set(robots.values())) == 1 else f"_{robots[scenario]}"
    if name in ("x_m", "y_m", "z_m"):
        return dataset[name].values.ravel()
    if name in ("u_m", "v_m"):
        return dataset[name[0]].broadcast_like(dataset["x_m"]).transpose(*DIMS[kind]).values.ravel()
    if name.startswith("q_"):
        return dataset[f"q{suffix}"].sel({f"joint{suffix}": name[2:]}).values.ravel()
    if name.startswith("normal_force_"):
        return dataset[f"normal_force_N{suffix}"].isel(scenario=scenario).sel(
            {f"joint{suffix}": name[len("normal_force_"):-2]}).values.ravel()
    return dataset[name].isel(scenario=scenario).values.ravel()


def test_to_xarray_holds_every_table_on_the_grids_axes(written):
    kind, workspace_map, tables = written
    dataset = workspace_map.to_xarray()
    dims = DIMS[kind]
    assert dataset["RP_l_um"].dims == ("scenario", *dims) and list(dataset["scenario"].values) == list(tables)
    assert dataset["RP_l_um"].attrs["units"] == "µm" and dataset["RP_a_mdeg"].attrs["units"] == "mdeg"
    robots = {s: robot for s, robot in enumerate(["ur5", "ur10"] if kind == "robots" else ["raw", "raw"])}
    for s, (name, table) in enumerate(tables.items()):
        for column, cells in table.items():
            assert_same(dataset_column(dataset, kind, s, column, robots), cells, f"{kind} {name} {column}")
        per_scenario = [v for v in dataset.data_vars if "scenario" in dataset[v].dims and "joint" not in
                        "".join(dataset[v].dims) and v not in table]
        assert all(missing(dataset[v].isel(scenario=s).values.ravel()) for v in per_scenario), per_scenario
    if kind == "robots":  # each robot's joints on its own dimension; a scenario's loads on its own robot's only
        assert dataset["q_ur10"].dims == ("v", "u", "joint_ur10") and "q" not in dataset
        assert np.isnan(dataset["normal_force_N_ur5"].sel(scenario="ur10")).all()
        assert set(dataset["reached_by"].sel(scenario="ur10").values.ravel()) == {"both", "ur10 only"}
    else:
        assert dataset["q"].dims == (*dims, "joint") and list(dataset["joint"].values) == ["x", "y", "z"]


def close(a, b) -> bool:
    """Whether DataArrays ``a`` and ``b`` agree within 1e-12 (broadcast by their dimensions' names)."""
    return float(abs(a - b).max()) < 1e-12


def test_the_datasets_axes_place_each_target_where_the_grid_has_it(written):
    """Independently of the tables: the positions (or configurations) on the axes follow from the axes' values."""
    kind, workspace_map, _ = written
    dataset = workspace_map.to_xarray()
    x, y, z = (dataset[name] for name in ("x_m", "y_m", "z_m"))
    if kind == "plane":  # origin (0.2, 0, 0.3) + u (1, 0, 0) + v (0, 0.6, 0.8)
        assert close(x, 0.2 + dataset["u"]) and close(y, 0.6 * dataset["v"]) and close(z, 0.3 + 0.8 * dataset["v"])
    elif kind == "robots":  # origin (0, -0.6, 0.1) + u (1, 0, 0) + v (0, 1, 0)
        assert close(x, dataset["u"]) and close(y, -0.6 + dataset["v"]) and close(z, 0.1 + 0 * dataset["u"])
    elif kind == "box":
        assert all((dataset[f"{axis}_m"] == dataset[axis]).all() for axis in "xyz")
    else:  # tool = (0.2 + q_x, q_y, 0.2 + q_z)
        assert (dataset["q"].sel(joint="z") == dataset["z"]).all()
        assert (dataset["q"].sel(joint="y") == dataset["y"]).all()
        assert close(z, 0.2 + dataset["z"]) and close(y, dataset["y"])


def test_a_missing_extra_is_one_error_naming_the_install_command(written, monkeypatch):
    monkeypatch.setitem(sys.modules, "pandas", None)
    monkeypatch.setitem(sys.modules, "xarray", None)
    for convert in (written[1].to_pandas, written[1].to_xarray):
        with pytest.raises(MissingExtraError) as error:
            convert()
        assert isinstance(error.value, ImportError) and isinstance(error.value, TribokinError)
        assert "pip install 'tribokin[data]'" in str(error.value) and error.value.library in ("pandas", "xarray")
