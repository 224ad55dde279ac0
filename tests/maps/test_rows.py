"""The IK of map targets: along rows, extrapolated warm starts, holes filled from neighbouring rows."""

import dataclasses

import numpy as np
import pytest

from maps.test_grid import ur5_plane
from tribokin.maps.grid import grid_neighbours, make_grid
from tribokin.maps.rows import extrapolate_row, fill_from_neighbours, holes_beside_reached, solve_row, \
    solve_row_heads
from tribokin.study.assembly import load_robot


@pytest.fixture(scope="module")
def solved():
    study = ur5_plane([5, 4])
    robot = load_robot(study)
    grid = make_grid(robot, study.map)
    heads = solve_row_heads(robot, grid)
    rows = [solve_row(robot, grid, row, heads[row]) for row in range(grid.row_count)]
    q = np.vstack([r[0] for r in rows])
    reachable = np.concatenate([r[1] for r in rows])
    assert reachable.all()
    return robot, grid, q, reachable


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
        monkeypatch.setattr("tribokin.maps.rows.SCAN_TARGETS", block)
        assert holes_beside_reached(Box, lambda name, index: reachable[index]) == expected
    assert 0 not in expected and 59 in expected  # 0's neighbours 1, 5, 20 are all unreachable


def test_targets_out_of_reach_stay_unreachable(solved):
    robot, grid, q_solved, _ = solved
    far = dataclasses.replace(grid, origin_m=grid.origin_m + [3.0, 0.0, 0.0])  # 3 m further: beyond the UR5's reach
    q, reachable = q_solved.copy(), np.ones(grid.size, dtype=bool)
    q[7], reachable[7] = np.nan, False
    assert fill_from_neighbours(robot, far, reader(q, reachable)) == {}


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
