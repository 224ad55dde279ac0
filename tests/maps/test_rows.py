"""The IK of map targets: along rows, extrapolated warm starts, holes filled from neighbouring rows."""

import dataclasses

import numpy as np
import pytest

from conftest import STUDIES
from maps.test_grid import ur5_plane
from tribokin import run_study
from tribokin.kinematics import ik
from tribokin.maps import rows as map_rows
from tribokin.maps.grid import grid_neighbours, make_grid
from tribokin.maps.schema import map_columns
from tribokin.maps.rows import beyond_reach_m, extrapolate_row, fill_from_neighbours, first_bound_beyond, \
    holes_beside_reached, solve_row, solve_row_heads
from tribokin.study.assembly import load_robot
from tribokin.study.reading import read_study_file


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


def ik_refusing_beyond_reach(grid):
    """``solve_ik`` that fails the test when asked for a target beyond a bound of ``grid.reach``."""
    real = ik.solve_ik

    def solve(robot, target, q_start, **options):
        assert first_bound_beyond(grid, target.translation)[0][0] < 0, "IK tried beyond the reach"
        return real(robot, target, q_start, **options)

    return solve


@pytest.mark.parametrize("shift_m, bound", [
    ([1.0, 0.0, 0.0], 0),  # 1 m further: the tool point beyond the UR5's reach
    ([0.0, 0.0, 0.7], 1),  # 0.7 m higher: within it, but the last joint's origin, 82 mm above, beyond its sphere
])
def test_targets_out_of_reach_stay_unreachable_without_ik(solved, monkeypatch, shift_m, bound):
    robot, grid, q_solved, _ = solved
    far = dataclasses.replace(grid, origin_m=grid.origin_m + shift_m)
    gaps = beyond_reach_m(far, np.arange(far.size))
    assert np.all(gaps > 0.02)
    assert np.all(first_bound_beyond(far, far.positions_m(np.arange(far.size)))[0] == bound)
    monkeypatch.setattr(map_rows, "solve_ik", ik_refusing_beyond_reach(far))
    monkeypatch.setattr(ik, "solve_ik", ik_refusing_beyond_reach(far))  # the restarts' solves
    q, reachable = q_solved.copy(), np.ones(grid.size, dtype=bool)
    q[7], reachable[7] = np.nan, False
    assert fill_from_neighbours(robot, far, reader(q, reachable)) == {}
    row_q, row_reachable, closest = solve_row(robot, far, 1, q_solved[5])
    assert np.isnan(row_q).all() and not row_reachable.any()
    np.testing.assert_array_equal(closest[:, 0], gaps[far.row_indices(1)])
    assert np.isnan(closest[:, 1]).all()


def test_the_reach_bounds_change_only_the_reasons_of_targets_beyond_them(monkeypatch):
    study = read_study_file(STUDIES / "ur5-map-horizontal.toml").mapping
    study["map"]["resolution"], study["study"]["cycles"] = [25, 15], 20
    bounded = run_study(study).map
    monkeypatch.setattr(map_rows, "beyond_reach_m", lambda grid, indices: np.full(len(indices), np.nan))
    unbounded = run_study(study).map
    bounds, gaps = first_bound_beyond(bounded.grid, bounded.grid.positions_m(np.arange(bounded.grid.size)))
    beyond = bounds >= 0
    np.testing.assert_array_equal(gaps, beyond_reach_m(bounded.grid, np.arange(bounded.grid.size)))
    # the far corners beyond the tool point's sphere; nearer, targets the wrist cannot reach pointing down: here
    # every unreachable target
    assert (bounds == 0).sum() > 10 and (bounds == 1).sum() > 10
    np.testing.assert_array_equal(beyond, ~unbounded.reachable)
    for column in map_columns(len(bounded.joint_names), len(bounded.scenarios), bounded.reference.figure_set):
        if column != "closest":
            np.testing.assert_array_equal(bounded.read(column), unbounded.read(column), err_msg=column)
    np.testing.assert_array_equal(bounded.read("closest")[~beyond], unbounded.read("closest")[~beyond])
    np.testing.assert_array_equal(bounded.read("closest")[beyond, 0], gaps[beyond])
    reasons = bounded.reasons()
    assert all(reason.startswith("beyond the robot's reach: ") for reason in reasons[bounds == 0])
    assert reasons[bounds == 0][0].endswith("m from (0, 0, 0.08916) m, where the tool point never goes farther "
                                            "than 0.9619 m (no IK tried)")
    assert all(reason.startswith("beyond the robot's reach with the tool's orientation held: the origin of joint "
                                 "'wrist_3_joint' would be ") for reason in reasons[bounds == 1])
    assert reasons[bounds == 1][0].endswith("m from (0, 0, 0.08916) m, where it never goes farther than 0.9184 m "
                                            "(no IK tried)")


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
