"""Map targets: grid neighbours and IK holes filled from neighbouring rows."""

import dataclasses

import numpy as np
import pytest

from conftest import STUDIES
from tribokin.run import load_robot, load_study
from tribokin.maps.targets import (extrapolate_row, fill_from_neighbours, grid_neighbours, holes_beside_reached, make_grid,
                              solve_row, solve_row_heads)


def ur5_plane(resolution):
    return load_study({
        "study": {"cycles": 10},
        "robot": {"name": "ur5"},
        "joints": {"friction": {"preset": "42CD4-raw"}, "stiffness": 1.0e5},
        "map": {"kind": "plane", "origin_m": [0.0, -0.5, 0.2], "axis_u": [1, 0, 0], "axis_v": [0, 1, 0],
                "extent_u_m": [-0.1, 0.1], "extent_v_m": [0.0, 0.1], "resolution": resolution, "rpy_deg": [180, 0, 90]},
    })


@pytest.fixture(scope="module")
def solved():
    study = ur5_plane([5, 4])
    robot = load_robot(study)
    grid = make_grid(robot, study.map, study.source)
    heads = solve_row_heads(robot, grid)
    rows = [solve_row(robot, grid, row, heads[row]) for row in range(grid.row_count)]
    q = np.vstack([r[0] for r in rows])
    reachable = np.concatenate([r[1] for r in rows])
    assert reachable.all()
    return robot, grid, q, reachable


def test_neighbours_along_each_axis():
    class Box:  # only the shape matters: 2 layers x 3 rows x 4 columns
        shape = (2, 3, 4)

    assert grid_neighbours(Box, 0) == [1, 4, 12]
    assert grid_neighbours(Box, 17) == [5, 13, 16, 18, 21]
    assert grid_neighbours(Box, 23) == [11, 19, 22]


def reader(q, reachable):
    """``read(column, index)`` over in-memory columns, as fill_from_neighbours reads a map's store."""
    return lambda name, index: {"q": q, "reachable": reachable}[name][index]


def test_a_missed_row_and_a_hole_are_reached_from_their_neighbours(solved):
    robot, grid, q_solved, _ = solved
    q, reachable = q_solved.copy(), np.ones(grid.size, dtype=bool)
    missed = [5, 6, 7, 8, 9, 13]  # all of row 1, and one target of row 2
    q[missed], reachable[missed] = np.nan, False
    filled = fill_from_neighbours(robot, grid, reader(q, reachable))
    assert list(filled) == missed
    for index, q_index in filled.items():
        reached = robot.tool_placement(q_index)
        np.testing.assert_allclose(reached.translation, grid.positions_m([index])[0], atol=1e-9)
        np.testing.assert_allclose(reached.rotation, grid.rotation, atol=1e-8)


def test_holes_beside_reached_targets_are_found_block_by_block(monkeypatch):
    class Box:  # 3 layers x 4 rows x 5 columns
        shape, size = (3, 4, 5), 60

    reachable = np.ones(60, dtype=bool)
    reachable[[0, 1, 5, 20, 21, 22, 23, 24, 25, 59]] = False
    expected = [i for i in np.flatnonzero(~reachable) if reachable[grid_neighbours(Box, i)].any()]
    for block in (7, 60):  # the scan's blocks do not change what it finds
        monkeypatch.setattr("tribokin.maps.targets.SCAN_TARGETS", block)
        assert holes_beside_reached(Box, lambda name, index: reachable[index]) == expected
    assert 0 not in expected and 59 in expected  # 0's neighbours 1, 5, 20 are all unreachable


def test_targets_out_of_reach_stay_unreachable(solved):
    robot, grid, q_solved, _ = solved
    far = dataclasses.replace(grid, origin_m=grid.origin_m + [3.0, 0.0, 0.0])  # 3 m further: beyond the UR5's reach
    q, reachable = q_solved.copy(), np.ones(grid.size, dtype=bool)
    q[7], reachable[7] = np.nan, False
    assert fill_from_neighbours(robot, far, reader(q, reachable)) == {}


def test_grid_positions_coordinates_and_thinning(solved):
    _, grid, _, _ = solved  # 4 rows (v) x 5 columns (u), origin (0, -0.5, 0.2), u along x, v along y
    np.testing.assert_allclose(grid.positions_m([0, 7]), [[-0.1, -0.5, 0.2], [0.0, -0.5 + 0.1 / 3, 0.2]])
    coordinates = grid.coordinates([7])
    np.testing.assert_allclose([coordinates["u_m"][0], coordinates["v_m"][0]], [0.0, 0.1 / 3])
    np.testing.assert_array_equal(grid.every((1, 2, 3)), [[[0, 3], [10, 13]]])
    shown, stride = grid.thinned(6)
    assert stride == 2 and shown.size <= 6
    np.testing.assert_array_equal(shown, grid.every((2, 2, 2)))
    assert grid.thinned(20) == (pytest.approx(np.arange(20).reshape(1, 4, 5)), 1)


def test_row_extrapolation_continues_a_polynomial_through_the_last_reached_targets():
    steps = np.arange(6.0)[:, None]
    cubic = 0.3 - 0.2 * steps + 0.05 * steps**2 + 0.01 * steps**3 + np.zeros((1, 2))
    line = 0.3 - 0.2 * steps + np.zeros((1, 2))
    reached = np.ones(5, dtype=bool)
    assert extrapolate_row(cubic[:5], reached) == pytest.approx(cubic[5], abs=1e-12)  # four points: exact to degree 3
    partly = reached.copy()
    partly[2] = False  # only the last two before the next target count: a straight line
    assert extrapolate_row(line[:5], partly) == pytest.approx(line[5], abs=1e-12)
    assert extrapolate_row(cubic[:5], np.array([True, True, True, False, True])) is None
    assert extrapolate_row(cubic[:1], reached[:1]) is None


def _short(values) -> bool:
    return all(v == float(f"{v:.9g}") for v in np.ravel(values))


@pytest.mark.parametrize("name", sorted(p.stem for p in STUDIES.glob("*.toml") if "[map]" in p.read_text()))
def test_shipped_map_grids_are_the_decimals_written(name):
    study = load_study(STUDIES / f"{name}.toml")
    grid = make_grid(load_robot(study), study.map, study.source)
    positions = grid.positions_m(np.arange(grid.size))
    values = grid.axis_values(np.arange(grid.size))
    assert _short(positions) and _short(values)
    assert not np.signbit(positions[positions == 0]).any() and not np.signbit(values[values == 0]).any()
    spec = study.map
    if spec["kind"] == "plane":
        lows, highs = [spec["extent_u_m"][0], spec["extent_v_m"][0]], [spec["extent_u_m"][1], spec["extent_v_m"][1]]
        assert values[0, :2].tolist() == lows and values[-1, :2].tolist() == highs
        directions = np.array([spec["axis_u"], spec["axis_v"]])
        corners = [np.asarray(spec["origin_m"]) + np.array(b) @ directions for b in (lows, highs)]
        assert positions[[0, -1]].tolist() == np.round(corners, 12).tolist()
    else:
        assert positions[0].tolist() == spec["min_m"] and positions[-1].tolist() == spec["max_m"]


def test_joint_and_line_grids_are_the_decimals_written():
    study = load_study({
        "study": {"cycles": 10},
        "robot": {"name": "ur5"},
        "joints": {"friction": {"preset": "42CD4-raw"}, "stiffness": 1.0e5},
        "map": {"kind": "joint", "joints": ["shoulder_pan_joint", "elbow_joint"],
                "ranges": [[-0.55, 0.45], [-2.0, 0.4]], "counts": [21, 7]},
    })
    grid = make_grid(load_robot(study), study.map, study.source)
    values = grid.axis_values(np.arange(grid.size))[:, :2]
    assert _short(values) and values[0].tolist() == [-0.55, -2.0] and values[-1].tolist() == [0.45, 0.4]
    assert 0.0 in values[:, 1] and not np.signbit(values[values == 0]).any()  # -2 + 5 · 0.4 rounds to -0.0
    line = make_grid(load_robot(study), ur5_plane([21, 1]).map)
    assert _short(line.positions_m(np.arange(line.size))) and line.axes[1].values.tolist() == [0.0]
