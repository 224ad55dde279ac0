"""Workspace maps: the ISO 9283 figures at every target of a grid, computed in chunks of whole rows.

Each target is measured like a single pose (:meth:`~tribokin.study.PoseRunner.measure`,
joint-space approach) from its own random stream ``pose_rng(seed, index, MAP_STREAM)``,
and only its scalar figures are kept. A chunk solves and measures whole grid rows from
their heads (:mod:`tribokin.targets`), so the numbers depend on neither the chunk size,
nor the number of workers, nor where the chunks run, nor on a resume. Every scenario is
measured at the same configurations with the same streams.
"""

from __future__ import annotations

import math
import threading
import uuid
from dataclasses import dataclass

import numpy as np
from tqdm import tqdm

from tribokin.checkpoint import ChunkStore, fingerprint
from tribokin.config import Study
from tribokin.errors import InputError
from tribokin.executors import run_chunks
from tribokin.iso9283 import orientation_repeatability, position_spread, variance_contributions
from tribokin.memory import TARGET_BLOCK_SAMPLES
from tribokin.propagate import tool_deviations_at_poses, tool_frames
from tribokin.results import MAP_FIGURES, MDEG_PER_RAD, UM_PER_M, MapResult, ScenarioMap
from tribokin.robot import Robot
from tribokin.study import PoseRunner, joint_models, joint_space_task, load_robot, pose_rng
from tribokin.targets import fill_from_neighbours, make_grid, solve_row, solve_row_heads

#: Random stream of map targets: target i draws from ``pose_rng(seed, i, MAP_STREAM)``
#: (poses use streams 0 and 1).
MAP_STREAM = 2
#: Default chunk size: this many targets, rounded up to whole grid rows.
CHUNK_TARGETS = 256


class ProgressBar(tqdm):
    """tqdm without its monitor thread, which would outlive the bar and keep later runs from forking workers."""

    monitor_interval = 0


@dataclass(frozen=True)
class MapJob:
    """What a chunk needs besides its rows: the study (robot, ``[map]``) and each scenario's study.

    ``token`` names the job, so each process builds the robot, grid and runners once per job.
    """

    token: str
    study: Study
    scenarios: tuple[Study, ...]


#: Per thread (Pinocchio data is mutable, and a dask worker may run chunks in several threads):
#: the last job's token and its (robot, grid, runners).
_local = threading.local()


def _job_context(job: MapJob):
    """(robot, grid, runners) of ``job``, built once per thread."""
    cache = getattr(_local, "cache", None)
    if cache is None or cache[0] != job.token:
        robot = load_robot(job.study)
        runners = [PoseRunner(s, robot, joint_models(s, robot)) for s in job.scenarios]
        _local.cache = (job.token, robot, make_grid(robot, job.study.map, job.study.source), runners)
    return _local.cache[1:]


def measure_targets(runner: PoseRunner, qs: np.ndarray, indices: np.ndarray, twists: np.ndarray,
                    translations: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Figures (targets, ``MAP_FIGURES``), bearing loads [N] (targets, nv) and dominant joint (-1: none)
    of the targets ``indices`` at configurations ``qs`` (targets, nv), each drawn from its own stream
    and measured like a single pose (joint-space approach); ``twists``, ``translations``: their
    :func:`~tribokin.propagate.tool_frames`. Targets go through in blocks of even sizes, of at most about
    ``TARGET_BLOCK_SAMPLES`` cycles: few enough for the arrays to stay small, enough to share the
    per-call costs."""
    study = runner.study
    task = joint_space_task("map target", np.zeros(qs.shape[1]))  # the draws use its approach directions only
    forces = runner.normal_forces_at(qs)
    figures = np.empty((len(qs), len(MAP_FIGURES)))
    dominant = np.empty(len(qs), dtype=int)
    blocks = math.ceil(len(qs) / max(1, TARGET_BLOCK_SAMPLES // study.cycles))
    for b in range(blocks):  # blocks of even sizes: no small last one paying the per-call costs alone
        members = slice(len(qs) * b // blocks, len(qs) * (b + 1) // blocks)
        per_joint = np.empty((len(indices[members]), qs.shape[1], study.cycles))  # cycles contiguous
        for k, (load, index) in enumerate(zip(forces[members], indices[members])):
            per_joint[k] = runner.draw(task, load, study.cycles, study.approach,
                                       pose_rng(study.seed, int(index), MAP_STREAM))[0].T
        figures[members], dominant[members] = block_figures(runner, qs[members], np.swapaxes(per_joint, 1, 2),
                                                            twists[members], translations[members])
    return figures, forces, dominant


def block_figures(runner: PoseRunner, qs: np.ndarray, dq: np.ndarray, twists: np.ndarray, translations: np.ndarray):
    """``MAP_FIGURES`` (targets, 7) and dominant joint (targets,) of deviations ``dq`` (targets, n, nv)."""
    positions, angles = tool_deviations_at_poses(runner.robot, qs, dq, runner.study.engine, twists, translations)
    shares = variance_contributions(twists[:, :3], dq)
    dominant = np.where(np.isnan(shares).all(axis=1), -1, np.argmax(np.nan_to_num(shares, nan=-1.0), axis=1))
    spread = position_spread(positions)
    figures = np.column_stack([
        spread.RP_l_m * UM_PER_M,
        np.linalg.norm(spread.barycenter_m - translations, axis=1) * UM_PER_M,
        orientation_repeatability(angles) * MDEG_PER_RAD,
        spread.largest_semi_axis_m * UM_PER_M,
        np.where(dominant < 0, np.nan, np.take_along_axis(shares, np.maximum(dominant, 0)[:, None], axis=1)[:, 0]),
    ])
    return figures, dominant


def compute_chunk(job: MapJob, rows: list[int], heads: np.ndarray) -> dict[str, np.ndarray]:
    """Solve and measure grid rows ``rows`` from their ``heads`` (rows, nv), row by row (a row's reached targets
    measured together, in blocks: :func:`measure_targets`).

    Returns:
        arrays over the chunk's targets, in index order: ``q`` (n, nv), ``reachable``, ``reason``,
        and for scenario s ``<s>/figures`` (n, len(MAP_FIGURES)), ``<s>/normal_forces_N`` (n, nv),
        ``<s>/dominant_joint`` (n,).
    """
    robot, grid, runners = _job_context(job)
    arrays = empty_arrays(len(rows) * grid.row_length, robot.model.nv, len(runners))
    reasons = []
    for k, (row, head) in enumerate(zip(rows, heads)):
        q, reachable, why = solve_row(robot, grid, row, head)
        span = slice(k * grid.row_length, (k + 1) * grid.row_length)
        arrays["q"][span], arrays["reachable"][span] = q, reachable
        reasons += why
        measure_into(arrays, span.start + np.flatnonzero(reachable), robot, runners, q[reachable],
                     grid.row_indices(row)[reachable])
    arrays["reason"] = np.array(reasons, dtype=str)
    return arrays


def empty_arrays(n: int, nv: int, scenarios: int) -> dict[str, np.ndarray]:
    """The arrays of ``n`` targets (:func:`compute_chunk`), all unreachable, before any is measured."""
    arrays = {"q": np.full((n, nv), np.nan), "reachable": np.zeros(n, dtype=bool)}
    for s in range(scenarios):
        arrays[f"{s}/figures"] = np.full((n, len(MAP_FIGURES)), np.nan)
        arrays[f"{s}/normal_forces_N"] = np.full((n, nv), np.nan)
        arrays[f"{s}/dominant_joint"] = np.full(n, -1)
    return arrays


def measure_into(arrays: dict, slots: np.ndarray, robot: Robot, runners: list[PoseRunner], qs: np.ndarray,
                 indices: np.ndarray) -> None:
    """Measure targets ``indices`` at configurations ``qs`` for every scenario, into ``slots`` of ``arrays``."""
    twists, translations = tool_frames(robot, qs)
    for s, runner in enumerate(runners):
        figures, forces, dominant = measure_targets(runner, qs, indices, twists, translations)
        arrays[f"{s}/figures"][slots] = figures
        arrays[f"{s}/normal_forces_N"][slots] = forces
        arrays[f"{s}/dominant_joint"][slots] = dominant


def fill_holes(robot: Robot, grid, runners: list[PoseRunner], totals: dict) -> None:
    """Reach and measure, in ``totals``, the targets that IK reaches from a neighbour's configuration
    (:func:`~tribokin.targets.fill_from_neighbours`) though not along their own row."""
    filled = np.array(fill_from_neighbours(robot, grid, totals["q"], totals["reachable"]), dtype=int)
    if filled.size:
        measure_into(totals, filled, robot, runners, totals["q"][filled], filled)
        totals["reason"][filled] = ""


def chunk_rows(study: Study, row_length: int, row_count: int) -> list[list[int]]:
    """The grid rows of each chunk: ``map.chunk_rows`` rows (default: about ``CHUNK_TARGETS`` targets)."""
    size = study.map["chunk_rows"] or math.ceil(CHUNK_TARGETS / row_length)
    return [list(range(start, min(start + size, row_count))) for start in range(0, row_count, size)]


def run_map(study: Study, robot: Robot, workers: int = 1, scheduler: str | None = None, checkpoint=None,
            resume: bool = False, progress: bool = False) -> MapResult:
    """Measure the study's ``[map]`` for each scenario.

    Args:
        study: a study with a ``map`` (its ``scenarios``, if any, are measured instead of it).
        robot: the study's robot.
        workers, scheduler: where chunks run (see :func:`~tribokin.executors.run_chunks`).
        checkpoint: folder where finished chunks are saved as they complete (``None``: kept in memory only).
        resume: reuse the chunks an interrupted run saved in ``checkpoint``.
        progress: show a progress bar (when there is more than one chunk).
    """
    scenarios = study.scenarios
    studies = tuple(s.study for s in scenarios) or (study,)
    names = [s.name for s in scenarios] or [study.name]
    runners = []
    for i, scenario in enumerate(studies):
        try:
            runners.append(PoseRunner(scenario, robot, joint_models(scenario, robot)))
        except InputError as error:
            key = error.key if not scenarios else f"scenarios[{i}].{error.key}"
            raise InputError(error.message, error.source, key) from None
    grid = make_grid(robot, study.map, study.source)
    chunks = chunk_rows(study, grid.row_length, grid.row_count)
    store = None
    if checkpoint is not None:
        settings = {"study": study.mapping, "source": study.source, "chunks": chunks,
                    "scenarios": [[s.cycles, s.seed] for s in studies]}
        store = ChunkStore(checkpoint, fingerprint(settings), resume)
    heads = solve_row_heads(robot, grid)
    n = grid.size
    totals = {**empty_arrays(n, robot.model.nv, len(studies)), "reason": np.full(n, "", object)}

    def keep(chunk: int, arrays: dict) -> None:
        first = chunks[chunk][0] * grid.row_length
        for name, values in arrays.items():
            totals[name][first:first + len(values)] = values

    finished = store.finished() if store else []
    for chunk in finished:
        keep(chunk, store.load(chunk))
    job = MapJob(uuid.uuid4().hex, study, studies)
    _local.cache = (job.token, robot, grid, runners)  # chunks run in this thread need not rebuild them
    todo = {k: (job, rows, heads[rows]) for k, rows in enumerate(chunks) if k not in finished}
    done_targets = sum(len(chunks[k]) for k in finished) * grid.row_length
    try:
        results = run_chunks(compute_chunk, todo, workers, scheduler)
        with ProgressBar(total=n, initial=done_targets, unit="target", desc=f"map {study.name}",
                  disable=not progress or len(chunks) <= 1) as bar:
            for chunk, arrays in results:
                if store:
                    store.save(chunk, arrays)
                keep(chunk, arrays)
                bar.update(len(chunks[chunk]) * grid.row_length)
    finally:
        _local.cache = None
    fill_holes(robot, grid, runners, totals)
    maps = [ScenarioMap(name, s.cycles, totals[f"{i}/figures"], totals[f"{i}/normal_forces_N"],
                        totals[f"{i}/dominant_joint"]) for i, (name, s) in enumerate(zip(names, studies))]
    return MapResult(grid, robot.joint_names, totals["q"], totals["reachable"], totals["reason"], maps)
