"""Where to put the robot: the study's ``[map]`` (the task region, world frame) mapped with the robot's base at each
candidate placement of its ``[placement]``, each candidate's RP_l summarised.

A candidate is one unit of work: on the executor's worker it loads the robot at its base, maps the task region there
with the map machinery itself (:func:`~tribokin.maps.mapping.run_map`, in that process, its store a temporary folder),
and returns the targets it reached and RP_l's mean, 95th percentile and maximum over them. Finished candidates are kept
in a :class:`~tribokin.maps.store.ChunkStore` (one row a candidate), so ``--resume`` computes only the missing ones; the
numbers depend on nothing but the candidate, so neither on the workers nor on a resume.
"""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import Executor
from dataclasses import replace

import numpy as np

from tribokin.compiled import kernels_used
from tribokin.execution import run_chunks
from tribokin.maps.mapping import chunk_order, prepare_map, run_map
from tribokin.maps.result import ScenarioMap
from tribokin.maps.store import ChunkStore, fingerprint, temporary_store
from tribokin.maps.streaming import blocks, order_statistic
from tribokin.placement.result import STATISTICS, PlacementResult
from tribokin.study.assembly import load_robot, map_robots
from tribokin.study.placement_spec import Candidate, turned_rpy_deg
from tribokin.study.spec import Study

#: The store's columns: per candidate, the targets reached and RP_l's statistics [µm].
COLUMNS = {"reachable": ((), "i8"), "RP_l_um": ((len(STATISTICS),), "f8")}
#: The percentile of ``objective = "p95"``.
PERCENTILE = 95.0


def placed_study(study: Study, candidate: Candidate) -> Study:
    """The study with its robot's base at ``candidate`` (its yaw added to ``robot.base_rpy_deg``'s), without
    ``[placement]`` and without directional figures (a search ranks candidates by RP_l only)."""
    robot = replace(study.robot, base_xyz_m=candidate.base_xyz_m,
                    base_rpy_deg=turned_rpy_deg(study.robot.base_rpy_deg, candidate.yaw_deg))
    return replace(study, robot=robot, placement=None, map=replace(study.map, directional=False))


def rp_l_statistics(scenario: ScenarioMap, size: int) -> np.ndarray:
    """Mean, :data:`PERCENTILE` th percentile (linear between order statistics, as :func:`numpy.percentile`) and
    maximum of the RP_l [µm] of a map's reached targets (its finite values), read block by block; NaN each if none."""
    read = lambda part: scenario.figure("RP_l_um", part)  # noqa: E731
    count, total, high = 0, 0.0, -np.inf
    for part in blocks(size):
        values = read(part)
        values = values[np.isfinite(values)]
        count, total = count + values.size, total + float(values.sum())
        high = max(high, float(values.max(initial=-np.inf)))
    if not count:
        return np.full(len(STATISTICS), np.nan)
    position = PERCENTILE / 100 * (count - 1)
    low_rank = int(np.floor(position))
    low = order_statistic(read, size, low_rank)
    upper = order_statistic(read, size, min(low_rank + 1, count - 1))
    return np.array([total / count, low + (position - low_rank) * (upper - low), high])


def evaluate_candidate(study: Study, candidate: Candidate) -> dict[str, np.ndarray]:
    """Map the task region with the base at ``candidate`` (here, a temporary store) and return the store's row of it
    (:data:`COLUMNS`)."""
    placed = placed_study(study, candidate)
    robot = load_robot(placed, meshes=False)
    workspace = run_map(placed, prepare_map(placed, map_robots(placed, robot)))
    reachable = sum(int(workspace.read("reachable", part).sum()) for part in workspace.blocks())
    return {"reachable": np.array([reachable]),
            "RP_l_um": rp_l_statistics(workspace.reference, workspace.grid.size)[None, :]}


def open_store(study: Study, count: int, checkpoint, resume: bool) -> ChunkStore:
    """The search's store of finished candidates: in ``checkpoint`` (kept, for ``--resume``), else a temporary one."""
    key = fingerprint({"placement": study.mapping, "source": study.source, "cycles": study.cycles,
                       "seed": study.seed, "kernels": kernels_used()})
    if checkpoint is not None:
        return ChunkStore(checkpoint, key, COLUMNS, count, resume)
    return temporary_store(key, COLUMNS, count)


def run_placement(study: Study, executor: Executor | None = None, checkpoint=None, resume: bool = False,
                  progress: Callable[[int, int], None] | None = None) -> PlacementResult:
    """Search the study's ``[placement]`` for its ``[map]`` (module docstring).

    Args:
        study: a checked study with ``placement`` and ``map``.
        executor: where candidates run (:func:`~tribokin.execution.executor_for`; ``None``: here).
        checkpoint: the folder of finished candidates.
        resume: whether to reuse an interrupted run's.
        progress: called ``progress(done_targets, total_targets)``, the task's targets times the candidates done and
            in all, before the candidates run and as each finishes.
    """
    candidates = study.placement.search()
    store = open_store(study, len(candidates), checkpoint, resume)
    finished = set(store.finished())
    todo = {k: (study, candidates[k]) for k in chunk_order(len(candidates)) if k not in finished}
    targets = study.map.target_count
    report = progress or (lambda done, total: None)
    done = len(finished)
    with run_chunks(evaluate_candidate, todo, executor) as results:
        report(done * targets, len(candidates) * targets)
        for index, row in results:
            store.save(index, index, row)
            done += 1
            report(done * targets, len(candidates) * targets)
    return PlacementResult(study, candidates, targets, store.read("reachable"), store.read("RP_l_um"))
