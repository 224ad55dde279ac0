"""Workspace maps: the ISO 9283 figures at every target of a grid, computed in chunks of whole rows.

Each target's figures are expected values over ISO tests (:mod:`tribokin.maps.expected_figures`), or those of one
simulated test from the target's own random stream (a one-test map: :mod:`tribokin.maps.measure`). Only its scalar
figures are kept, on disk (:class:`~tribokin.maps.store.ChunkStore`, into which a local worker writes its chunk itself,
no values sent back through a pipe): memory holds a chunk's targets and a block's cycles, whatever the grid's size. A
chunk solves and measures whole grid rows from where they start (:mod:`tribokin.maps.rows`), so the numbers depend on
neither the chunk size, nor the number of workers, nor where the chunks run, nor on a resume. Each robot the scenarios
measure with (another robot, base or tool: :class:`~tribokin.study.assembly.MapRobots`) solves its own IK of the same
targets; the scenarios of one robot are measured at its configurations, every scenario with the same streams.
"""

from __future__ import annotations

import math
import threading
import uuid
from collections.abc import Callable
from concurrent.futures import Executor
from dataclasses import dataclass, fields

import numpy as np

from tribokin.compiled import kernels_used
from tribokin.errors import InputError, TribokinError
from tribokin.execution import local_pool, run_chunks
from tribokin.iso9283.gaussian_tests import ASYMPTOTIC_CYCLES
from tribokin.kinematics.chain import serial_chain
from tribokin.kinematics.robot import Robot
from tribokin.maps.expected_figures import ExpectedSetup, change_errors, expected_targets, shape_table
from tribokin.maps.grid import GridError, TargetGrid, make_grid, target_positions_m
from tribokin.maps.measure import measure_targets
from tribokin.maps.result import MapResult, ScenarioMap
from tribokin.maps.rows import (
    FROM_NEIGHBOUR,
    fill_from_neighbours,
    first_tries,
    solve_row_starts,
    solve_rows,
    solve_tries,
)
from tribokin.maps.schema import (
    CHANGED_FIGURES,
    MapLayout,
    figure_index,
    per_direction,
    robot_column,
    scenario_column,
)
from tribokin.maps.store import ChunkStore, fingerprint, temporary_store
from tribokin.propagation.exact import tool_frames
from tribokin.simulation.joint_errors import JointErrorModel, warming_joints
from tribokin.simulation.pose_test import PoseRunner, TestSettings
from tribokin.study.assembly import MapRobots, joint_models, study_runner
from tribokin.study.map_spec import MapSpec
from tribokin.study.spec import Study
from tribokin.tribology.friction_series import COLD, FrictionState


@dataclass(frozen=True)
class MapJob:
    """What a chunk needs besides its rows: each scenario's settings, joint models and how its errors are located,
    the map's robots and grids.

    ``token`` names the job, so each process builds the runners once per job. ``setups``: each scenario's
    :class:`~tribokin.maps.expected_figures.ExpectedSetup` (``None`` for a one-test map). ``robots``: each robot the
    scenarios measure with (pickled as its kinematics: :meth:`~tribokin.kinematics.robot.Robot.__reduce__`), ``grids``
    its grid of the map's targets, ``layout`` the store's (each scenario's robot). ``states`` and ``warm_up_loads``:
    each scenario's runner's (where its joints' friction series start, the loads their warm-up rests on); ``compare``
    the map's second state (``None``: none) and ``compare_setups`` each scenario's setup in it.
    """

    token: str
    settings: tuple[TestSettings, ...]
    models: tuple[tuple[JointErrorModel, ...], ...]
    locators: tuple[Callable | None, ...]
    states: tuple[FrictionState, ...]
    warm_up_loads: tuple[np.ndarray | None, ...]
    setups: tuple[ExpectedSetup | None, ...]
    robots: tuple[Robot, ...]
    grids: tuple[TargetGrid, ...]
    layout: MapLayout
    compare: FrictionState | None = None
    compare_setups: tuple[ExpectedSetup | None, ...] = ()


#: Per thread (Pinocchio data is mutable, and a dask worker may run chunks in several threads):
#: the last job's token and its (robots, runners, scenarios: :func:`scenarios_of`).
_local = threading.local()


def _job_context(job: MapJob) -> tuple[list[Robot], list[PoseRunner], list[list[tuple]]]:
    """(robots, runners, each robot's scenarios) of ``job``, built once per thread."""
    cache = getattr(_local, "cache", None)
    if cache is None or cache[0] != job.token:
        robots = list(job.robots)
        runners = [PoseRunner(settings, robots[r], models, locate, state, loads) for settings, models, locate, state,
                   loads, r in zip(job.settings, job.models, job.locators, job.states, job.warm_up_loads,
                                   job.layout.places, strict=True)]
        _local.cache = (job.token, robots, runners, scenarios_of(job, runners))
    return _local.cache[1:]


def scenarios_of(job: MapJob, runners: list[PoseRunner]) -> list[list[tuple]]:
    """Per robot of ``job``, its scenarios as :func:`measure_into` takes them: (number, runner, setup, compared),
    ``compared`` the runner and setup of the map's ``compare`` state (``None``: none)."""
    compared = [None] * len(runners)
    if job.compare is not None:
        compared = [(r.at(job.compare), setup) for r, setup in zip(runners, job.compare_setups, strict=True)]
    return [[(s, runners[s], job.setups[s], compared[s]) for s in job.layout.scenarios_of(r)]
            for r in range(len(job.robots))]


def compute_chunk(job: MapJob, chunk: int, rows: list[int], starts: tuple[np.ndarray, ...],
                  store: ChunkStore | None = None) -> dict[str, np.ndarray] | None:
    """Solve grid rows ``rows`` for each robot from its ``starts`` (rows, nv), together (:func:`solve_rows`), then
    measure their reached targets together, in blocks of rows that follow each other (:func:`measure_into`: a
    target's figures do not depend on the others in its block).

    Returns:
        the chunk's targets' values of every column of the map's layout (:class:`~tribokin.maps.schema.MapLayout`),
        in index order; with a ``store`` (one this process can write: a local worker's), ``None``, the values
        saved there instead as chunk ``chunk`` (:meth:`~tribokin.maps.store.ChunkStore.save`), not sent back through
        a pipe.
    """
    robots, _, scenarios_by_robot = _job_context(job)
    row_length = job.grids[0].row_length
    arrays = empty_arrays(len(rows) * row_length, job.layout)
    for r, (robot, grid, robot_starts) in enumerate(zip(robots, job.grids, starts, strict=True)):
        scenarios = scenarios_by_robot[r]
        solved = solve_rows(robot, grid, rows, robot_starts)
        reached = []  # each row's (slots, configurations, indices) of its reached targets
        for k, (row, q, reachable, closest, routes) in enumerate(zip(rows, *solved, strict=True)):
            span = slice(k * row_length, (k + 1) * row_length)
            indices = grid.row_indices(row)
            for name, value in (("q", q), ("reachable", reachable), ("closest", closest), ("ik_route", routes)):
                arrays[robot_column(r, name)][span] = value
            if r == 0:
                arrays["position_m"][span] = target_positions_m(robot, grid, indices, q)
            reached.append((span.start + np.flatnonzero(reachable), q[reachable], indices[reachable]))
        slots, qs, indices = (np.concatenate(parts) for parts in zip(*reached, strict=True))
        measure_into(arrays, slots, robot, scenarios, qs, indices)
    if store is None:
        return arrays
    store.save(chunk, rows[0] * row_length, arrays)
    return None


def empty_arrays(n: int, layout: MapLayout, robot: int | None = None) -> dict[str, np.ndarray]:
    """The columns (:meth:`~tribokin.maps.schema.MapLayout.columns`: all, or ``robot``'s) of ``n`` targets, all
    unreachable, before any is solved or measured."""
    arrays = {name: np.full((n, *shape), np.nan if dtype == "f8" else 0, dtype=dtype)
              for name, (shape, dtype) in layout.columns(robot).items()}
    for s in range(len(layout.places)) if robot is None else layout.scenarios_of(robot):
        arrays[scenario_column(s, "dominant_joint")][:] = -1
    return arrays


#: Targets measured at once (a chunk's reached targets in pieces of this many): what measuring holds in memory stays
#: bounded, and each piece pays NumPy's per-call costs once for many targets.
MEASURE_TARGETS = 1024


def measure_into(arrays: dict, slots: np.ndarray, robot: Robot, scenarios: list[tuple], qs: np.ndarray,
                 indices: np.ndarray) -> None:
    """Measure targets ``indices`` at ``robot``'s configurations ``qs`` for each of ``scenarios`` (number, runner,
    setup, compared: :func:`scenarios_of`), into ``slots`` of ``arrays``: their expected figures (a scenario with a
    setup), else one test each, and with ``compared`` the change to its state (:func:`change_figures`);
    ``MEASURE_TARGETS`` at a time."""
    for start in range(0, len(qs), MEASURE_TARGETS):
        part = slice(start, start + MEASURE_TARGETS)
        _measure_block(arrays, slots[part], robot, scenarios, qs[part], indices[part])


def _measure_block(arrays: dict, slots: np.ndarray, robot: Robot, scenarios: list[tuple], qs: np.ndarray,
                   indices: np.ndarray) -> None:
    chain = serial_chain(robot)
    placements = None if chain is None else chain.tool_in_joint(qs)  # for the tool frames and the loads

    def measured(runner: PoseRunner, setup: ExpectedSetup | None) -> tuple[dict, np.ndarray]:
        if setup is None:
            figures, forces, dominant = measure_targets(runner, qs, indices, twists, translations)
            return {"figures": figures, "dominant_joint": dominant}, forces
        forces = runner.normal_forces_at(qs, placements)
        return expected_targets(runner, setup, qs, forces, twists, translations), forces

    twists, translations = tool_frames(robot, qs, placements)
    for s, runner, setup, compared in scenarios:
        values, forces = measured(runner, setup)
        if compared is not None:
            values.update(change_figures(values, measured(*compared)[0], runner.settings.approach, setup))
            if setup is not None:  # the paired tests' standard errors
                values["change_mc_errors"] = change_errors((runner, setup), compared, qs, forces, translations)
        values["normal_forces_N"] = forces
        for name, value in values.items():
            arrays[scenario_column(s, name)][slots] = value


def change_figures(start: dict, end: dict, approach: str, setup: ExpectedSetup | None) -> dict[str, np.ndarray]:
    """The change (:data:`~tribokin.maps.schema.CHANGE_FIGURES`) from figures ``start`` to ``end`` (a block's
    :func:`measure_into` values in the two states), end minus start [µm] (k, 2); an expected map's (a ``setup``) also
    under ``change_engine_bounds`` (k, 2) [µm] how far each change may lie from the same change through exact FK: the
    two figures' errors from their engines' bounds summed (``figure_errors``; each state's tests through its own model
    or engine, whose errors need not cancel)."""
    figure_set = "one-test" if setup is None else setup.figure_set
    columns = [figure_index(name, figure_set, per_direction(approach)) for name in CHANGED_FIGURES]
    change = {"change": end["figures"][:, columns] - start["figures"][:, columns]}
    if setup is not None:
        change["change_engine_bounds"] = end["figure_errors"][:, columns] + start["figure_errors"][:, columns]
    return change


#: The first tries of the holes from their neighbours go to an executor's workers in parts of about this many.
TRIES_PER_PART = 16


def solve_tries_of(job: MapJob, robot: int, tries: list[tuple[int, np.ndarray]]) -> list:
    """:func:`~tribokin.maps.rows.solve_tries` of ``job``'s robot number ``robot`` (run where the executor runs it)."""
    robots = _job_context(job)[0]
    return solve_tries(robots[robot], job.grids[robot], tries)


def first_tries_solved(job: MapJob, robot: int, read, executor: Executor) -> dict:
    """The first tries of :func:`~tribokin.maps.rows.fill_from_neighbours` (:func:`~tribokin.maps.rows.first_tries`)
    of robot number ``robot`` solved on ``executor``'s workers, by ``(target, neighbour)``: the same solves it would
    make one after another."""
    tries = first_tries(job.grids[robot], read)
    parts = math.ceil(len(tries) / TRIES_PER_PART)
    starts = read("q", np.array([neighbour for _, neighbour in tries], dtype=np.intp))  # the neighbours' at once
    todo = {k: (job, robot, [(index, q) for (index, _), q in zip(tries[k::parts], starts[k::parts], strict=True)])
            for k in range(parts)}
    solved = {}
    with run_chunks(solve_tries_of, todo, executor) as results:
        for k, part in results:
            solved.update(zip(tries[k::parts], part, strict=True))
    return solved


def fill_holes(job: MapJob, robots: list[Robot], scenarios_by_robot: list[list[tuple]], store: ChunkStore,
               executor: Executor | None = None) -> None:
    """Reach and measure, in ``store``, the targets that each of ``robots`` (``job``'s, loaded) reaches by IK from a
    neighbour's configuration (:func:`~tribokin.maps.rows.fill_from_neighbours`) though not along their own row, for
    the scenarios measured with it (``scenarios_by_robot``: :func:`scenarios_of`); with an ``executor``, the first
    tries solved beforehand on its workers (:func:`first_tries_solved`).

    Each robot's outcome is kept as a record (``filled``, ``robot<k>_filled``) before the store is changed, so a run
    killed while changing it writes the same values again on resume instead of searching anew from a changed store.
    """
    for r, (robot, grid) in enumerate(zip(robots, job.grids, strict=True)):
        record = robot_column(r, "filled")
        filled = store.load_record(record)
        if filled is None:
            def read(name, index, r=r):
                return store.read(robot_column(r, name), index)

            solved = None if executor is None else first_tries_solved(job, r, read, executor)
            reached = fill_from_neighbours(robot, grid, read, solved)
            indices = np.fromiter(reached, dtype=int, count=len(reached))
            filled = {"index": indices, **empty_arrays(len(indices), job.layout, r)}
            if len(indices):
                q = np.array(list(reached.values()))
                filled[robot_column(r, "q")], filled[robot_column(r, "reachable")][:] = q, True
                filled[robot_column(r, "ik_route")][:] = FROM_NEIGHBOUR
                measure_into(filled, np.arange(len(indices)), robot, scenarios_by_robot[r], q, indices)
            store.save_record(record, filled)
        indices = filled.pop("index")
        if len(indices):
            store.write(indices, filled)


def expected_setups(spec: MapSpec, runners: list[PoseRunner]) -> tuple[ExpectedSetup | None, ...]:
    """Each scenario's :class:`~tribokin.maps.expected_figures.ExpectedSetup` (a shape table per cycles and seed), or
    ``None`` each for a one-test map."""
    if spec.statistic != "expected":
        return (None,) * len(runners)
    tables = {}
    for runner in runners:
        key = runner.settings.cycles, runner.settings.seed
        if key not in tables:
            tables[key] = None if key[0] >= ASYMPTOTIC_CYCLES else shape_table(*key)
    return tuple(ExpectedSetup.build(r, tables[r.settings.cycles, r.settings.seed], spec.figure_set) for r in runners)


def chunk_rows(spec: MapSpec, row_count: int) -> list[list[int]]:
    """The grid rows of each chunk (:attr:`~tribokin.study.map_spec.MapSpec.rows_per_chunk`)."""
    size = spec.rows_per_chunk
    return [list(range(start, min(start + size, row_count))) for start in range(0, row_count, size)]


def open_store(prepared: PreparedMap, job: MapJob, chunks: list[list[int]], checkpoint, resume: bool) -> ChunkStore:
    """The map's store: in ``checkpoint`` (kept, for ``--resume``, recognised by the map's ``identity``), else in a
    new temporary folder that is deleted with the store."""
    settings = {**prepared.identity, "chunks": chunks, "scenarios": [[s.cycles, s.seed] for s in job.settings],
                "kernels": kernels_used()}
    columns, size = job.layout.columns(), prepared.grids[0].size
    if checkpoint is not None:
        return ChunkStore(checkpoint, fingerprint(settings), columns, size, resume)
    return temporary_store(fingerprint(settings), columns, size)


def chunk_order(count: int) -> list[int]:
    """The order ``count`` chunks are computed in: by their index's bits reversed (0, 8, 4, 12, 2, ... of 16), so
    that the chunks done first are spread evenly over the grid and their rate holds for the rest (in grid order, a
    plane's far rows, mostly unreachable hence slow to search, all came first and the first ETA was many times too
    long)."""
    bits = max(1, (count - 1).bit_length())
    return sorted(range(count), key=lambda k: f"{k:0{bits}b}"[::-1])


@dataclass(frozen=True)
class MapScenario:
    """A what-if variant of a workspace map: what it changes of the map's own robot, joint models and settings
    (``None``: the map's). Scenarios with the same robot object share its IK.

    Attributes:
        name: its name (the figures' and files' names).
        robot: another robot, or the same one with another base or tool (:class:`~tribokin.kinematics.robot.Robot`).
        joints: one error model per joint of its robot (:func:`~tribokin.simulation.joint_errors.joint_models`).
        settings: its cycles, seed, approach, engine, payload (:class:`~tribokin.simulation.pose_test.TestSettings`).
    """

    name: str
    robot: Robot | None = None
    joints: tuple[JointErrorModel, ...] | None = None
    settings: TestSettings | None = None


@dataclass(frozen=True)
class PreparedMap:
    """A map checked and ready to run (:func:`plan_map`): its ``spec``, each scenario's ``names``, ``robots`` (the
    reference scenario's first), ``grids`` each robot's grid of the map's targets, ``row_starts`` where each robot's
    grid rows start (rows, nv; :func:`~tribokin.maps.rows.solve_row_starts`), ``runners`` one per scenario, ``layout``
    the store's (each scenario's robot), ``identity`` what a checkpoint of it is recognised by (``--resume``)."""

    spec: MapSpec
    names: tuple[str, ...]
    robots: tuple[Robot, ...]
    grids: tuple[TargetGrid, ...]
    row_starts: tuple[np.ndarray, ...]
    runners: list[PoseRunner]
    layout: MapLayout
    identity: dict


def plan_map(spec: MapSpec, robots: tuple[Robot, ...], runners: list[PoseRunner], names: tuple[str, ...],
             identity: dict) -> PreparedMap:
    """The grids of ``spec``, one per robot of ``robots`` (the first's held orientation the others hold), and where
    each robot's grid rows start, checked before any work: the map's joints, ranges, start posture and orientation for
    each robot, and each scenario's loads at each row's start (``runners``: one per scenario, of one of ``robots``).

    Where a joint's friction is a time series, every test at every target starts from ``spec.state`` (``None``:
    each joint's own age, cold), and a warming joint's power rests on its bearing load averaged over the
    configurations the grid's rows start from (solved here, before any work: the same whatever the chunks), not on
    the target's: the robot warms up running its cycle, wherever the map's test is.

    Raises:
        GridError: a spec that does not fit a robot; its ``robot`` is that robot's number.
        JointRangeError: (or what a runner's ``locate`` makes of it) a deviation beyond a joint's range at a row's
            start; its ``scenario`` is the scenario's number.
    """
    places = tuple(next(r for r, robot in enumerate(robots) if robot is runner.robot) for runner in runners)
    grids = []
    for r, robot in enumerate(robots):
        try:
            grids.append(make_grid(robot, spec, grids[0] if grids else None))
        except GridError as error:
            error.robot = r
            raise
    starts = tuple(solve_row_starts(robot, grid) for robot, grid in zip(robots, grids, strict=True))
    started = []
    for i, (runner, r) in enumerate(zip(runners, places, strict=True)):
        try:
            forces = runner.normal_forces_at(starts[r])  # the loads at each row's start, checked before any chunk runs
        except TribokinError as error:
            error.scenario = i
            raise
        started.append(series_runner(runner, spec.state, forces))
    return PreparedMap(spec, tuple(names), tuple(robots), tuple(grids), starts, started,
                       MapLayout(tuple(robot.model.nv for robot in robots), places, spec.figure_set,
                                 tuple(per_direction(runner.settings.approach) for runner in runners),
                                 spec.compare is not None), identity)


def series_runner(runner: PoseRunner, state: FrictionState | None, forces_N: np.ndarray) -> PoseRunner:
    """``runner`` as a map runs it: its joints' friction series from ``state`` (``None``: cold at their own age), a
    warming joint's power on its mean load over ``forces_N`` (rows, nv) [N]; ``runner`` itself without a series."""
    if not runner.correlated:
        return runner
    return PoseRunner(runner.settings, runner.robot, runner.models, runner.locate, state or COLD,
                      forces_N.mean(axis=0) if warming_joints(runner.models) else None)


def prepare_map(study: Study, robots: MapRobots) -> PreparedMap:
    """:func:`plan_map` of the study's ``[map]`` and its scenarios' robots (``robots``: the study's first), a runner per
    scenario (the study itself without scenarios), its errors naming the study's file and key."""
    scenarios = tuple(s.study for s in study.scenarios) or (study,)
    runners = []
    for i, (scenario, r) in enumerate(zip(scenarios, robots.places, strict=True)):
        robot = robots.robots[r]
        try:
            runners.append(study_runner(scenario, robot, joint_models(scenario, robot)))
        except InputError as error:
            key = error.key if not study.scenarios else f"scenarios[{i}].{error.key}"
            raise InputError(error.message, error.source, key) from None
    identity = {"study": study.mapping, "source": study.source, "robots": [spec.as_settings() for spec in robots.specs]}
    try:
        return plan_map(study.map, robots.robots, runners, tuple(s.name for s in study.scenarios) or (study.name,),
                        identity)
    except GridError as error:
        prefix = f"scenarios[{robots.places.index(error.robot)}]." if error.robot else ""  # the first measured with it
        raise InputError(str(error), study.source, f"{prefix}map.{error.key}") from None
    except InputError as error:
        key = error.key if not study.scenarios else f"scenarios[{error.scenario}].{error.key}"
        raise InputError(error.message, error.source, key) from None


def measure_map(prepared: PreparedMap, executor: Executor | None = None, checkpoint=None, resume: bool = False,
                progress: Callable[[int, int], None] | None = None,
                meanwhile: Callable[[], None] | None = None) -> MapResult:
    """Measure a prepared map (:func:`plan_map`) for each of its scenarios.

    Args:
        prepared: its robots, grids, where its rows start and runners.
        executor: where chunks run (:func:`~tribokin.execution.executor_for`; ``None``: here).
        checkpoint: folder where the results are kept as chunks finish (``None``: a temporary folder,
            deleted with the result).
        resume: reuse the chunks an interrupted run saved in ``checkpoint``.
        progress: called ``progress(done_targets, total_targets)`` before the chunks run (the targets of
            resumed chunks done) and as each finishes, if the map has more than one chunk.
        meanwhile: called once, here, after the chunks are handed to ``executor`` and before their results are
            read: while its workers compute, this process has the time (with no executor, before the chunks run).
    """
    runners = prepared.runners
    grid = prepared.grids[0]
    chunks = chunk_rows(prepared.spec, grid.row_count)
    compare = prepared.spec.compare
    compared = [] if compare is None else [r.at(compare) for r in runners]
    job = MapJob(uuid.uuid4().hex, tuple(TestSettings.of(r.settings) for r in runners),
                 tuple(tuple(r.models) for r in runners), tuple(r.locate for r in runners),
                 tuple(r.state for r in runners), tuple(r.warm_up_loads_N for r in runners),
                 expected_setups(prepared.spec, runners), prepared.robots, prepared.grids, prepared.layout, compare,
                 expected_setups(prepared.spec, compared))
    store = open_store(prepared, job, chunks, checkpoint, resume)
    finished = set(store.finished())
    robots = list(prepared.robots)
    scenarios_by_robot = scenarios_of(job, runners)
    _local.cache = (job.token, robots, runners, scenarios_by_robot)  # chunks run in this thread need not rebuild them
    writer = store if local_pool(executor) is not None else None  # a local worker saves its chunk in the store
    todo = {k: (job, k, chunks[k], tuple(starts[chunks[k]] for starts in prepared.row_starts), writer)
            for k in chunk_order(len(chunks)) if k not in finished}
    done_targets = sum(len(chunks[k]) for k in finished) * grid.row_length
    report = progress if progress is not None and len(chunks) > 1 else lambda done, total: None
    try:
        with run_chunks(compute_chunk, todo, executor) as results:
            report(done_targets, grid.size)
            if meanwhile is not None:
                meanwhile()
            for chunk, arrays in results:
                if arrays is not None:  # else saved by the worker
                    store.save(chunk, chunks[chunk][0] * grid.row_length, arrays)
                done_targets += len(chunks[chunk]) * grid.row_length
                report(done_targets, grid.size)
    finally:
        _local.cache = None
    fill_holes(job, robots, scenarios_by_robot, store, executor)
    maps = {name: ScenarioMap(name, settings.cycles, i, robots[r].joint_names, store, prepared.spec.figure_set, r,
                              prepared.layout.both_directions(i), settings.engine, prepared.layout.change)
            for i, (name, settings, r)
            in enumerate(zip(prepared.names, job.settings, prepared.layout.places, strict=True))}
    states = {}
    if any(runner.correlated for runner in runners):  # where the tests' friction series start (summary.json)
        states = {"state": (prepared.spec.state or COLD).describe(),
                  **({} if compare is None else {"compare": compare.describe()})}
    return MapResult(prepared.grids, robots[0].joint_names, store, maps, prepared.robots[0], states)


def run_map(study: Study, prepared: PreparedMap, executor: Executor | None = None, checkpoint=None,
            resume: bool = False, progress: Callable[[int, int], None] | None = None,
            meanwhile: Callable[[], None] | None = None) -> MapResult:
    """Measure the study's ``[map]`` for each scenario (:func:`measure_map`; ``study``: a study with a ``map``, its
    ``scenarios``, if any, measured instead of it)."""
    return measure_map(prepared, executor, checkpoint, resume, progress, meanwhile)


def workspace_map(robot: Robot, joints: list[JointErrorModel], map_spec: MapSpec, *,
                  scenarios: tuple[MapScenario, ...] = (), name: str = "map", cycles: int = 30, seed: int = 0,
                  approach: str = "unidirectional", engine: str = "fast", payload_kg: float = 0.0,
                  cycle_time_s: float | None = None, executor: Executor | None = None, checkpoint=None,
                  resume: bool = False, progress: Callable[[int, int], None] | None = None) -> MapResult:
    """The ISO 9283 figures at every target of a workspace map, for the robot or each of its ``scenarios``.

    Args:
        robot: the robot (:class:`~tribokin.kinematics.robot.Robot`).
        joints: one error model per joint (:func:`~tribokin.simulation.joint_errors.joint_models`).
        map_spec: the map: :class:`~tribokin.study.map_spec.PlaneMap`, ``BoxMap`` or ``JointMap``; its ``state``
            and ``compare`` (:class:`~tribokin.tribology.friction_series.FrictionState`) where a joint's friction is a
            time series.
        scenarios: what-if variants measured instead of the robot itself (:class:`MapScenario`), the first the
            reference; ``()``: the robot alone, a scenario called ``name``.
        name: the map's one scenario's name, without ``scenarios``.
        cycles: cycles of each test (:class:`~tribokin.simulation.pose_test.TestSettings`), each scenario's unless
            it sets its own settings.
        seed: the random streams' seed.
        approach: ``"unidirectional"``, ``"bidirectional"`` or ``"random"``.
        engine: ``"fast"`` or ``"exact"``.
        payload_kg: the payload at the tool point [kg].
        cycle_time_s: one cycle's duration [s], what a joint's friction warm-up (its ``series``' ``thermal``) reads;
            the map's tests start from ``map_spec.state``.
        executor: where chunks run (:func:`~tribokin.execution.executor_for`; ``None``: here).
        checkpoint: folder where finished chunks are kept (``None``: a temporary one).
        resume: reuse the chunks an interrupted run saved in ``checkpoint``.
        progress: called ``progress(done_targets, total_targets)`` as chunks finish.

    Returns:
        every target's figures per scenario, read from its store (a temporary one without ``checkpoint``).

    Raises:
        GridError: a map that does not fit a robot (its ``key``: the spec's field).
        SettingsError: a bad setting.
        JointRangeError: a joint whose deviation could exceed its range.
    """
    settings = TestSettings(cycles, seed, approach, engine, payload_kg, cycle_time_s)
    scenarios = tuple(scenarios) or (MapScenario(name),)
    robots = [robot]
    for scenario in scenarios:
        if scenario.robot is not None and all(scenario.robot is not known for known in robots):
            robots.append(scenario.robot)
    runners = [PoseRunner(s.settings or settings, s.robot or robot, joints if s.joints is None else s.joints)
               for s in scenarios]
    identity = {"map": repr(map_spec), "robots": [r.origin for r in robots],
                "joints": [[{f.name: m.friction.describe() if f.name == "friction" else getattr(m, f.name)
                             for f in fields(m)} for m in runner.models] for runner in runners],
                "settings": [repr(runner.settings) for runner in runners]}
    return measure_map(plan_map(map_spec, tuple(robots), runners, tuple(s.name for s in scenarios), identity),
                       executor, checkpoint, resume, progress)
