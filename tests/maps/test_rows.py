"""The IK of map targets: along rows, extrapolated warm starts, holes filled from neighbouring rows."""

import dataclasses

import numpy as np
import pytest

from conftest import STUDIES
from helpers.map_studies import ur5_plane
from tribokin import run_study
from tribokin.kinematics import ik
from tribokin.kinematics.robot import wrap_angles
from tribokin.maps import rows as map_rows
from tribokin.maps.grid import grid_neighbours, make_grid
from tribokin.maps.mapping import prepare_map
from tribokin.maps.rows import (
    beyond_reach_m,
    extrapolate_rows,
    fill_from_neighbours,
    first_bound_beyond,
    holes_beside_reached,
    solve_row_starts,
    solve_rows,
    turned_into_limits,
)
from tribokin.maps.schema import MapLayout
from tribokin.study.assembly import load_robot, map_robots
from tribokin.study.reading import load_study, read_study_file


@pytest.fixture(scope="module")
def solved():
    study = ur5_plane([5, 4])
    robot = load_robot(study)
    grid = make_grid(robot, study.map)
    starts = solve_row_starts(robot, grid)
    q, reachable, _, _ = solve_rows(robot, grid, range(grid.row_count), starts)
    q, reachable = q.reshape(grid.size, -1), reachable.ravel()
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


def test_holes_filled_with_their_first_tries_solved_beforehand_are_filled_alike(solved, monkeypatch):
    robot, grid, q_solved, _ = solved
    q, reachable = q_solved.copy(), np.ones(grid.size, dtype=bool)
    q[[5, 6, 7, 8, 9, 13]], reachable[[5, 6, 7, 8, 9, 13]] = np.nan, False
    read = reader(q, reachable)
    tries = map_rows.first_tries(grid, read)
    before = dict(zip(tries, map_rows.solve_tries(robot, grid, [(i, q[n]) for i, n in tries]), strict=True))
    alone = fill_from_neighbours(robot, grid, read)
    solves = []
    monkeypatch.setattr(map_rows, "_solve_from", lambda robot, grid, index, q_start, solve=map_rows._solve_from:
                        solves.append((index, q_start.tobytes())) or solve(robot, grid, index, q_start))
    together = fill_from_neighbours(robot, grid, read, before)
    assert list(together) == list(alone) and all(np.array_equal(together[i], alone[i]) for i in alone)
    assert tries and not set(solves) & {(i, q[n].tobytes()) for i, n in tries}  # none solved again


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


def refusing_beyond_reach(grid, solve, positions_m):
    """``solve`` (an IK) that fails the test when asked for a target beyond a bound of ``grid.reach``;
    ``positions_m(*arguments)``: the positions [m] of the targets it is asked for."""

    def checked(*arguments, **options):
        assert np.all(first_bound_beyond(grid, positions_m(*arguments))[0] < 0), "IK tried beyond the reach"
        return solve(*arguments, **options)

    return checked


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
    one = refusing_beyond_reach(far, ik.solve_ik, lambda robot, target, *rest: target.translation)
    monkeypatch.setattr(map_rows, "solve_ik", one)
    monkeypatch.setattr(ik, "solve_ik", one)  # the restarts' solves
    monkeypatch.setattr(map_rows, "solve_ik_batch", refusing_beyond_reach(
        far, ik.solve_ik_batch, lambda chain, rotation, positions_m, *rest: positions_m))
    q, reachable = q_solved.copy(), np.ones(grid.size, dtype=bool)
    q[7], reachable[7] = np.nan, False
    assert fill_from_neighbours(robot, far, reader(q, reachable)) == {}
    (row_q,), (row_reachable,), (closest,), _ = solve_rows(robot, far, [1], q_solved[[5]])
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
    layout = MapLayout.shared(len(bounded.joint_names), len(bounded.scenarios), bounded.reference.figure_set)
    for column in layout.columns():
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
    for b in (0, 1):  # how far the bounded point is from the sphere's centre, each target its own
        assert [reason.split(" m from ")[0].split(" ")[-1] for reason in reasons[bounds == b]] == \
            [f"{bounded.grid.reach[b].radius_m + gap:.4g}" for gap in gaps[bounds == b]]


def test_row_extrapolation_continues_a_polynomial_through_the_last_reached_targets():
    steps = np.arange(6.0)[:, None]
    cubic = 0.3 - 0.2 * steps + 0.05 * steps**2 + 0.01 * steps**3 + np.zeros((1, 2))
    line = 0.3 - 0.2 * steps + np.zeros((1, 2))
    rows = np.stack([cubic[:5], line[:5], line[:5], cubic[:5], cubic[:5]])
    predicted = extrapolate_rows(rows, np.array([5, 2, 3, 1, 0]))  # how many reached right before the next target
    assert predicted[0] == pytest.approx(cubic[5], abs=1e-12)  # four points: exact to degree 3
    assert predicted[1] == pytest.approx(line[5], abs=1e-12) and predicted[2] == pytest.approx(line[5], abs=1e-12)
    assert np.isnan(predicted[3:]).all()  # fewer than two
    assert np.isnan(extrapolate_rows(rows[:, :1], np.ones(5, dtype=int))).all()


def test_rows_with_as_many_points_give_each_row_the_same_bytes_as_rows_with_others():
    """Every row alike (most columns) takes no masks: the same bytes as each row among rows of other counts."""
    q = np.random.default_rng(5).normal(size=(4, 6, 3))
    for count in (2, 3, 4):
        alike = extrapolate_rows(q, np.full(4, count))
        mixed = extrapolate_rows(q, np.array([count, 5 - count, count, 1]))
        np.testing.assert_array_equal(alike[[0, 2]], mixed[[0, 2]])
        assert np.isnan(mixed[3]).all() and not np.isnan(alike).any()


def test_a_warm_start_beyond_a_multi_turn_joints_limit_is_turned_back_within_it(horizontal):
    robot, _, _ = horizontal  # UR5: every joint within ±2π
    q = np.array([[6.3, -6.4, 0.1, 2 * np.pi, -7.0, 13.0], [np.nan, 0.0, 0.0, 0.0, 0.0, 0.0]])
    turned = turned_into_limits(robot, q)
    np.testing.assert_allclose(turned[0], [6.3 - 2 * np.pi, -6.4 + 2 * np.pi, 0.1, 2 * np.pi, -7.0 + 2 * np.pi,
                                           13.0 - 4 * np.pi], rtol=0, atol=1e-15)  # at a limit: as it is
    np.testing.assert_array_equal(turned[1], q[1])  # no warm start: none made up
    panda = load_robot(load_study(STUDIES / "panda-map-vertical.toml"))  # every joint's limits less than a turn apart
    beyond = np.array([[6.8, 0.0, 0.0, -2.0, 0.0, 2.0, 0.0]])
    np.testing.assert_array_equal(turned_into_limits(panda, beyond), beyond)  # clipped by the IK as before


def test_a_row_running_into_a_joint_limit_goes_on_along_its_branch_on_either_kernel_path(tmp_path, monkeypatch):
    """studies/ur5-map-horizontal.toml's plane turned to the robot's -x side: along every row, the pan (or the last
    wrist joint) passes its limit ±2π. A warm start beyond it used to be clipped there, and the solve went to another
    branch, one that rounding chose (pan turned by 3.4 rad in a 2 mm step, differently on the two kernel paths);
    turned by a whole turn, each 25 mm step moves every joint less than 0.3 rad modulo 2π (seen: 0.25), and the two
    paths agree to 1e-12 rad."""
    study_file = tmp_path / "plane.toml"
    text = (STUDIES / "ur5-map-horizontal.toml").read_text()
    for before, after in (("origin_m = [0.0, -0.55, 0.1]", "origin_m = [-0.55, 0.0, 0.1]"),
                          ("axis_u = [1, 0, 0]", "axis_u = [0, 1, 0]"), ("axis_v = [0, 1, 0]", "axis_v = [1, 0, 0]")):
        assert before in text
        text = text.replace(before, after)
    study_file.write_text(text)
    study = load_study(study_file)
    robot = load_robot(study)
    solved = rows_on_both_paths(robot, make_grid(robot, study.map), monkeypatch)
    for path, (_, q, reachable, _, _) in solved.items():
        for row, reached in zip(q, reachable, strict=True):
            steps = np.diff(row[reached], axis=0)
            assert np.abs(wrap_angles(steps)).max() < 0.3, path
            assert np.abs(steps).max() > 6.0, path  # turned once on the way
    reached_once, apart = differences(solved)
    assert reached_once == 0 and apart.max() < 1e-12


@pytest.fixture(scope="module")
def horizontal():
    """The UR5 plane of studies/ur5-map-horizontal.toml (tool pointing down, 49 × 29 targets, some beyond the reach
    and some within it unreachable): robot, grid and where its rows start."""
    study = load_study(STUDIES / "ur5-map-horizontal.toml")
    robot = load_robot(study)
    prepared = prepare_map(study, map_robots(study, robot))
    return robot, prepared.grids[0], prepared.row_starts[0]


def test_the_rows_solved_together_are_each_solved_as_alone(horizontal):
    robot, grid, starts = horizontal
    rows = range(grid.row_count)
    together = solve_rows(robot, grid, rows, starts)
    assert together[1].any() and not together[1].all()
    for row in (0, 7, 12, grid.row_count - 1):
        alone = solve_rows(robot, grid, [row], starts[[row]])
        for array, whole in zip(alone, together, strict=True):
            assert array[0].tobytes() == whole[row].tobytes()


def test_a_row_whose_head_is_not_reached_starts_from_the_last_head_reached(horizontal, monkeypatch):
    """Checked against the heads' targets: a row starts at its own head's target, or, its head not reached, exactly
    where the row before it in the heads' order starts; no head beyond the reach is solved."""
    robot, grid, starts = horizontal
    heads = np.arange(grid.row_count) * grid.row_length
    beyond = ~np.isnan(beyond_reach_m(grid, heads))
    solved = []
    solve = map_rows._solve
    monkeypatch.setattr(map_rows, "_solve", lambda robot, grid, index, *rest, **options: solved.append(index) or
                        solve(robot, grid, index, *rest, **options))
    assert map_rows.solve_row_starts(robot, grid).tobytes() == starts.tobytes()
    assert sorted(solved) == heads[~beyond].tolist()
    order = map_rows.head_order(grid)
    at_head = 0
    for before, row in zip([None, *order], order, strict=False):
        placement = robot.tool_placement(starts[row])
        if np.allclose(placement.translation, grid.positions_m([heads[row]])[0], atol=1e-9):
            at_head += 1
        else:
            assert starts[row].tobytes() == (grid.start_q if before is None else starts[before]).tobytes()
    assert 0 < beyond.sum() and at_head <= grid.row_count - beyond.sum()


def test_the_far_rows_keep_the_branch_of_the_rows_before_them(horizontal):
    """studies/ur5-map-horizontal.toml: every reached target with the elbow bent the same way and the second wrist
    joint on the same side, from the near rows to the far ones whose heads lie beyond the reach (when such a row
    started where its head's failed IK ended, 175 of the 1 266 targets the rows reached took other branches)."""
    robot, grid, starts = horizontal
    q, reachable, _, _ = solve_rows(robot, grid, range(grid.row_count), starts)
    reached = q[reachable]
    branches = {(elbow > 0, np.sin(wrist) > 0) for elbow, wrist in reached[:, [2, 4]]}
    assert reachable.sum() > 1250 and len(branches) == 1


def test_solving_rows_together_changes_only_rounding(horizontal):
    """Against the targets solved one by one (today's path before the batch): 0 of the 1 421 targets differ by more
    than 1e-9 rad or in reachability (seen: 7e-15 rad at most)."""
    robot, grid, starts = horizontal
    rows = range(grid.row_count)
    q, reachable, closest, _ = solve_rows(robot, grid, rows, starts)
    q_alone, reachable_alone, closest_alone, _ = solve_rows(robot, grid, rows, starts, batched=False)
    both = reachable & reachable_alone
    assert both.sum() > 1000
    differing = (reachable != reachable_alone).sum() + (np.abs(q - q_alone)[both].max(axis=-1) > 1e-9).sum()
    assert differing <= 2
    beyond = ~np.isnan(beyond_reach_m(grid, np.arange(grid.size))).reshape(reachable.shape)
    np.testing.assert_array_equal(closest[beyond], closest_alone[beyond])


def rows_on_both_paths(robot, grid, monkeypatch, rows=None) -> dict:
    """Where the rows start and rows ``rows`` (:func:`solve_rows`; default the whole grid) on each kernel path."""
    rows = range(grid.row_count) if rows is None else rows
    solved = {}
    for path in ("numpy", "compiled"):
        monkeypatch.setenv("TRIBOKIN_KERNELS", path)
        starts = solve_row_starts(robot, grid)
        solved[path] = starts, *solve_rows(robot, grid, rows, starts[rows])
    return solved


def differences(solved) -> tuple[int, np.ndarray]:
    """Targets reached on one path only, and the largest difference [rad] of each target reached on both."""
    (_, q, reachable, _, _), (_, q_compiled, reachable_compiled, _, _) = solved["numpy"], solved["compiled"]
    both = reachable & reachable_compiled
    return (reachable != reachable_compiled).sum(), np.abs(q - q_compiled)[both].max(axis=-1)


def test_the_compiled_ik_solves_the_ur5_rows_as_numpy_and_pinocchio(horizontal, monkeypatch):
    """studies/ur5-map-horizontal.toml (tool pointing down; 9 of its 29 row heads beyond the reach, whose rows start
    where another row's head was reached): the same row starts to the bit (Pinocchio's path on both), the same
    reached targets and routes, configurations within 1e-12 rad, and the same ``closest`` beyond the reach bounds
    (where IK failed, how close it came depends on every rounding)."""
    robot, grid, _ = horizontal
    solved = rows_on_both_paths(robot, grid, monkeypatch)
    assert solved["numpy"][0].tobytes() == solved["compiled"][0].tobytes()
    reached_once, apart = differences(solved)
    assert reached_once == 0 and apart.size > 1200 and apart.max() < 1e-12
    np.testing.assert_array_equal(solved["numpy"][4], solved["compiled"][4])
    beyond = ~np.isnan(beyond_reach_m(grid, np.arange(grid.size))).reshape(grid.shape[1:])
    np.testing.assert_array_equal(solved["numpy"][3][beyond], solved["compiled"][3][beyond])


def test_the_compiled_ik_solves_the_panda_rows_as_numpy_but_for_a_redundant_arms_drift(monkeypatch):
    """studies/panda-map-vertical.toml: 7 joints for the tool's 6 degrees of freedom. Damped least squares leaves the
    self-motion's direction to the path, so rounding is not corrected along it but carried from target to target
    along a row (to about 1e-11 rad), and near the reach's edge a warm start may then end at another solution. Seen:
    of 767 targets, 1 reached on one path only, 33 apart by more than 1e-12 rad, 4 by more than 1e-9 (the NumPy
    batch against Pinocchio one target at a time: 0, 15 and 1)."""
    study = load_study(STUDIES / "panda-map-vertical.toml")
    robot = load_robot(study)
    grid = make_grid(robot, study.map)
    reached_once, apart = differences(rows_on_both_paths(robot, grid, monkeypatch))
    assert apart.size > 750 and reached_once <= 2
    assert (apart > 1e-12).sum() <= 50 and (apart > 1e-9).sum() <= 6


def test_a_robot_numpy_cannot_compute_is_solved_target_by_target(solved, monkeypatch):
    robot, grid, _, _ = solved
    starts = solve_row_starts(robot, grid)
    alone = solve_rows(robot, grid, range(grid.row_count), starts, batched=False)
    monkeypatch.setattr(map_rows, "serial_chain", lambda robot: None)
    monkeypatch.setattr(map_rows, "solve_ik_batch", None)
    for array, expected in zip(solve_rows(robot, grid, range(grid.row_count), starts), alone, strict=True):
        assert array.tobytes() == expected.tobytes()


def test_each_target_says_how_the_ik_reached_it(horizontal):
    """Checked by solving again: a target reached after restarts is not reached from its row's last reached
    configuration, one reached from there is, and the map counts every reached target once in summary.json."""
    robot, grid, starts = horizontal
    rows = range(grid.row_count)
    q, reachable, _, routes = solve_rows(robot, grid, rows, starts)
    assert np.array_equal(routes != map_rows.UNREACHED, reachable)
    counts = np.bincount(routes.ravel(), minlength=5)
    assert counts[map_rows.ALONG_ROW] > 0.9 * reachable.sum() and counts[map_rows.FROM_LAST_REACHED] > 0
    restarted = np.isin(routes, [map_rows.FROM_LAST_REACHED, map_rows.AFTER_RESTARTS])
    for row, column in zip(*np.nonzero(restarted), strict=True):
        before = np.flatnonzero(reachable[row, :column])
        start = q[row, before[-1]] if len(before) else starts[row]
        index = grid.row_indices(row)[column]
        again = ik.solve_ik(robot, map_rows._target(grid, index), start, position_only=grid.rotation is None)
        assert again.success == (routes[row, column] == map_rows.FROM_LAST_REACHED)
    study = load_study(STUDIES / "ur5-map-horizontal.toml")
    summary = run_study(study).map.summary()
    ik_counts = summary["ik"]
    assert sum(ik_counts.values()) == summary["reachable"]
    assert ik_counts["after_restarts"] == counts[map_rows.AFTER_RESTARTS]
    assert ik_counts["from_neighbours"] == summary["reachable"] - reachable.sum()
