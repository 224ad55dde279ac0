"""Workspace maps: the ISO 9283 figures at every target of a grid, computed in chunks of whole rows.

Each target is measured like a single pose from its own random stream (:mod:`tribokin.maps.measure`),
and only its scalar figures are kept, on disk (:class:`~tribokin.maps.store.ChunkStore`): memory
holds a chunk's targets and a block's cycles, whatever the grid's size. A chunk solves and measures whole grid rows from
their heads (:mod:`tribokin.maps.rows`), so the numbers depend on neither the chunk size,
nor the number of workers, nor where the chunks run, nor on a resume. Every scenario is
measured at the same configurations with the same streams.
"""

from __future__ import annotations

import math
import threading
import uuid
from collections.abc import Callable
from concurrent.futures import Executor
from dataclasses import dataclass

import numpy as np

from tribokin.errors import InputError
from tribokin.execution import run_chunks
from tribokin.kinematics.chain import serial_chain
from tribokin.kinematics.robot import Robot
from tribokin.maps.grid import GridError, TargetGrid, make_grid, target_positions_m
from tribokin.iso9283.expected import ASYMPTOTIC_CYCLES
from tribokin.maps.expected import ExpectedSetup, expected_targets, shape_table
from tribokin.maps.measure import measure_targets
from tribokin.maps.result import MapResult, ScenarioMap
from tribokin.maps.rows import fill_from_neighbours, first_tries, solve_row_heads, solve_rows, solve_tries
from tribokin.maps.schema import map_columns, scenario_column
from tribokin.maps.store import ChunkStore, fingerprint, temporary_store
from tribokin.propagation.exact import tool_frames
from tribokin.simulation.pose_run import PoseRunner
from tribokin.study.assembly import joint_models, load_robot
from tribokin.study.spec import Study


@dataclass(frozen=True)
class MapJob:
    """What a chunk needs besides its rows: the study (robot, ``[map]``) and each scenario's study.

    ``token`` names the job, so each process builds the robot, grid and runners once per job. ``setups``: each
    scenario's :class:`~tribokin.maps.expected.ExpectedSetup` (``None`` for a one-test map).
    """

    token: str
    study: Study
    scenarios: tuple[Study, ...]
    setups: tuple[ExpectedSetup | None, ...]


#: Per thread (Pinocchio data is mutable, and a dask worker may run chunks in several threads):
#: the last job's token and its (robot, grid, runners).
_local = threading.local()


def _job_context(job: MapJob):
    """(robot, grid, runners) of ``job``, built once per thread."""
    cache = getattr(_local, "cache", None)
    if cache is None or cache[0] != job.token:
        robot = load_robot(job.study, meshes=False)  # nothing drawn here
        runners = [PoseRunner(s, robot, joint_models(s, robot)) for s in job.scenarios]
        _local.cache = (job.token, robot, make_grid(robot, job.study.map), runners)
    return _local.cache[1:]


def compute_chunk(job: MapJob, rows: list[int], heads: np.ndarray) -> dict[str, np.ndarray]:
    """Solve grid rows ``rows`` from their ``heads`` (rows, nv), together (:func:`solve_rows`), then measure them row
    by row (a row's reached targets measured together, in blocks: :func:`measure_targets`).

    Returns:
        the chunk's targets' values of every column of :func:`~tribokin.maps.schema.map_columns`, in index order.
    """
    robot, grid, runners = _job_context(job)
    arrays = empty_arrays(len(rows) * grid.row_length, robot.model.nv, len(runners), job.study.map.figure_set)
    solved = solve_rows(robot, grid, rows, heads)
    for k, (row, q, reachable, closest) in enumerate(zip(rows, *solved)):
        span = slice(k * grid.row_length, (k + 1) * grid.row_length)
        indices = grid.row_indices(row)
        arrays["q"][span], arrays["reachable"][span], arrays["closest"][span] = q, reachable, closest
        arrays["position_m"][span] = target_positions_m(robot, grid, indices, q)
        measure_into(arrays, span.start + np.flatnonzero(reachable), robot, runners, job.setups, q[reachable],
                     indices[reachable])
    return arrays


def empty_arrays(n: int, nv: int, scenarios: int, figure_set: str) -> dict[str, np.ndarray]:
    """The columns of ``n`` targets, all unreachable, before any is solved or measured."""
    arrays = {name: np.full((n, *shape), np.nan if dtype == "f8" else 0, dtype=dtype)
              for name, (shape, dtype) in map_columns(nv, scenarios, figure_set).items()}
    for s in range(scenarios):
        arrays[scenario_column(s, "dominant_joint")][:] = -1
    return arrays


def measure_into(arrays: dict, slots: np.ndarray, robot: Robot, runners: list[PoseRunner],
                 setups: tuple[ExpectedSetup | None, ...], qs: np.ndarray, indices: np.ndarray) -> None:
    """Measure targets ``indices`` at configurations ``qs`` for every scenario, into ``slots`` of ``arrays``: their
    expected figures (a scenario with a ``setups`` entry), else one test each."""
    chain = serial_chain(robot)
    placements = None if chain is None else chain.tool_in_joint(qs)  # for the tool frames and the loads
    twists, translations = tool_frames(robot, qs, placements)
    for s, (runner, setup) in enumerate(zip(runners, setups)):
        if setup is None:
            figures, forces, dominant = measure_targets(runner, qs, indices, twists, translations)
            values = {"figures": figures, "dominant_joint": dominant}
        else:
            forces = runner.normal_forces_at(qs, placements)
            values = expected_targets(runner, setup, qs, forces, twists, translations)
        values["normal_forces_N"] = forces
        for name, value in values.items():
            arrays[scenario_column(s, name)][slots] = value


#: The first tries of the holes from their neighbours go to an executor's workers in parts of about this many.
TRIES_PER_PART = 16


def solve_tries_of(job: MapJob, tries: list[tuple[int, np.ndarray]]) -> list:
    """:func:`~tribokin.maps.rows.solve_tries` of ``job``'s map (run where the executor runs it)."""
    robot, grid, _ = _job_context(job)
    return solve_tries(robot, grid, tries)


def first_tries_solved(job: MapJob, grid: TargetGrid, read, executor: Executor) -> dict:
    """The first tries of :func:`~tribokin.maps.rows.fill_from_neighbours` (:func:`~tribokin.maps.rows.first_tries`)
    solved on ``executor``'s workers, by ``(target, neighbour)``: the same solves it would make one after another."""
    tries = first_tries(grid, read)
    parts = math.ceil(len(tries) / TRIES_PER_PART)
    todo = {k: (job, [(index, read("q", neighbour)) for index, neighbour in tries[k::parts]]) for k in range(parts)}
    solved = {}
    with run_chunks(solve_tries_of, todo, executor) as results:
        for k, part in results:
            solved.update(zip(tries[k::parts], part))
    return solved


def fill_holes(robot: Robot, grid, runners: list[PoseRunner], setups: tuple[ExpectedSetup | None, ...],
               store: ChunkStore, figure_set: str, job: MapJob | None = None, executor: Executor | None = None) -> None:
    """Reach and measure, in ``store``, the targets that IK reaches from a neighbour's configuration
    (:func:`~tribokin.maps.rows.fill_from_neighbours`) though not along their own row; with an ``executor``, its
    first tries solved beforehand on the executor's workers (:func:`first_tries_solved`, ``job`` the map's).

    The outcome is kept as the record ``filled`` before the store is changed, so a run killed while
    changing it writes the same values again on resume instead of searching anew from a changed store.
    """
    filled = store.load_record("filled")
    if filled is None:
        solved = None if executor is None else first_tries_solved(job, grid, store.read, executor)
        reached = fill_from_neighbours(robot, grid, store.read, solved)
        indices = np.fromiter(reached, dtype=int, count=len(reached))
        filled = {"index": indices, **empty_arrays(len(indices), robot.model.nv, len(runners), figure_set)}
        if len(indices):
            q = np.array(list(reached.values()))
            filled["q"], filled["reachable"][:] = q, True
            filled["position_m"] = target_positions_m(robot, grid, indices, q)
            measure_into(filled, np.arange(len(indices)), robot, runners, setups, q, indices)
        store.save_record("filled", filled)
    indices = filled.pop("index")
    if len(indices):
        store.write(indices, filled)


def expected_setups(study: Study, runners: list[PoseRunner]) -> tuple[ExpectedSetup | None, ...]:
    """Each scenario's :class:`~tribokin.maps.expected.ExpectedSetup` (a shape table per cycles and seed), or
    ``None`` each for a one-test map."""
    if study.map.statistic != "expected":
        return (None,) * len(runners)
    tables = {}
    for runner in runners:
        key = runner.study.cycles, runner.study.seed
        if key not in tables:
            tables[key] = None if key[0] >= ASYMPTOTIC_CYCLES else shape_table(*key)
    return tuple(ExpectedSetup.build(r, tables[r.study.cycles, r.study.seed], study.map.figure_set) for r in runners)


def chunk_rows(study: Study, row_count: int) -> list[list[int]]:
    """The grid rows of each chunk (:attr:`~tribokin.study.map_spec.MapSpec.rows_per_chunk`)."""
    size = study.map.rows_per_chunk
    return [list(range(start, min(start + size, row_count))) for start in range(0, row_count, size)]


def open_store(study: Study, studies: tuple[Study, ...], chunks: list[list[int]], size: int, nv: int, checkpoint,
               resume: bool) -> ChunkStore:
    """The map's store: in ``checkpoint`` (kept, for ``--resume``), else in a new temporary folder that
    is deleted with the store."""
    settings = {"study": study.mapping, "source": study.source, "chunks": chunks,
                "scenarios": [[s.cycles, s.seed] for s in studies]}
    columns = map_columns(nv, len(studies), study.map.figure_set)
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


def prepare_map(study: Study, robot: Robot) -> tuple[TargetGrid, list[PoseRunner], np.ndarray]:
    """The grid of the study's ``[map]``, a runner per scenario (the study itself without scenarios) and each
    grid row's starting posture (rows, nv), checked against ``robot`` before any work: the map's joints, ranges,
    start posture and orientation, each scenario's joints and friction laws, and its loads at each row's start."""
    try:
        grid = make_grid(robot, study.map)
    except GridError as error:
        raise InputError(str(error), study.source, f"map.{error.key}") from None
    heads = solve_row_heads(robot, grid)
    runners = []
    for i, scenario in enumerate(tuple(s.study for s in study.scenarios) or (study,)):
        try:
            runners.append(PoseRunner(scenario, robot, joint_models(scenario, robot)))
            runners[-1].normal_forces_at(heads)  # the loads at each row's start, checked before any chunk runs
        except InputError as error:
            key = error.key if not study.scenarios else f"scenarios[{i}].{error.key}"
            raise InputError(error.message, error.source, key) from None
    return grid, runners, heads


def run_map(study: Study, robot: Robot, grid: TargetGrid, runners: list[PoseRunner], heads: np.ndarray,
            executor: Executor | None = None, checkpoint=None, resume: bool = False,
            progress: Callable[[int, int], None] | None = None) -> MapResult:
    """Measure the study's ``[map]`` for each scenario.

    Args:
        study: a study with a ``map`` (its ``scenarios``, if any, are measured instead of it).
        robot: the study's robot.
        grid, runners, heads: the map's grid, its scenarios' runners and its rows' starting postures
            (:func:`prepare_map`).
        executor: where chunks run (:func:`~tribokin.execution.executor_for`; ``None``: here).
        checkpoint: folder where the results are kept as chunks finish (``None``: a temporary folder,
            deleted with the result).
        resume: reuse the chunks an interrupted run saved in ``checkpoint``.
        progress: called ``progress(done_targets, total_targets)`` before the chunks run (the targets of
            resumed chunks done) and as each finishes, if the map has more than one chunk.
    """
    studies = tuple(runner.study for runner in runners)
    names = [s.name for s in study.scenarios] or [study.name]
    chunks = chunk_rows(study, grid.row_count)
    store = open_store(study, studies, chunks, grid.size, robot.model.nv, checkpoint, resume)
    finished = set(store.finished())
    setups = expected_setups(study, runners)
    job = MapJob(uuid.uuid4().hex, study, studies, setups)
    _local.cache = (job.token, robot, grid, runners)  # chunks run in this thread need not rebuild them
    todo = {k: (job, chunks[k], heads[chunks[k]]) for k in chunk_order(len(chunks)) if k not in finished}
    done_targets = sum(len(chunks[k]) for k in finished) * grid.row_length
    report = progress if progress is not None and len(chunks) > 1 else lambda done, total: None
    try:
        with run_chunks(compute_chunk, todo, executor) as results:
            report(done_targets, grid.size)
            for chunk, arrays in results:
                store.save(chunk, chunks[chunk][0] * grid.row_length, arrays)
                done_targets += len(chunks[chunk]) * grid.row_length
                report(done_targets, grid.size)
    finally:
        _local.cache = None
    fill_holes(robot, grid, runners, setups, store, study.map.figure_set, job, executor)
    maps = {name: ScenarioMap(name, s.cycles, i, robot.joint_names, store, study.map.figure_set)
            for i, (name, s) in enumerate(zip(names, studies))}
    return MapResult(grid, robot.joint_names, store, maps)
