"""The IK of a map's rows: target by target, as before issue 22's batch, against a chunk's rows solved together.

Run from the repository root: ``OPENBLAS_NUM_THREADS=1 PYTHONPATH=src python benchmarks/ik.py`` (``--side 60`` for a
quicker run). Writes ``benchmarks/results/ik.json`` and prints it.

The grid is the shipped ``studies/ur5-map-horizontal.toml``'s plane (tool pointing down: the orientation held) at
``--side`` × ``--side`` targets; where its rows start is solved once (:func:`tribokin.maps.mapping.prepare_map`) and not
timed. Then, in one run, every row is solved from its head (:func:`tribokin.maps.rows.solve_rows`):

* ``row_by_row``: a row at a time, each target by :func:`~tribokin.kinematics.ik.solve_ik`, by ``solve_row`` as it
  was before the batch (:func:`solve_row_before`, its code; ``solve_rows(..., batched=False)`` gives the same bytes,
  with more overhead per column);
* ``batched``: ``rows`` rows at a time, each column's warm starts together
  (:func:`~tribokin.kinematics.ik.solve_ik_batch`), for the map's own chunks (``rows_per_chunk`` rows, about 256
  targets) and for more rows per batch, up to the whole plane.

Figures per run: seconds, µs per target (all targets, those beyond the reach bounds included: they cost no IK), and
the part spent in the one-by-one fallbacks both runs share (a failed warm start solved again from the row's last
reached target, then from seeded restarts: mostly the few unreachable targets within the bounds), with µs per target
without it. Then the ratios of row-by-row to batched time (with and without the fallbacks), the targets the batch
(at the map's chunks) solves differently (configuration more than ``SAME_RAD`` away, or reachability different), the
largest difference between the others' configurations, and whether every batch size gave the same bytes (and the
per-target path of :func:`~tribokin.maps.rows.solve_rows` those of before). Each run's time is the best of
``--repeats``.

Timings are wall clock on whatever machine runs this, which may be shared: compare ratios measured in the same run.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import os
import platform
import time
from pathlib import Path

import numpy as np

from tribokin.maps import rows as map_rows
from tribokin.maps.mapping import chunk_rows, prepare_map
from tribokin.study.assembly import load_robot, map_robots
from tribokin.study.reading import load_study, read_study_file

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results" / "ik.json"
STUDY = ROOT / "studies" / "ur5-map-horizontal.toml"
#: The largest difference [rad] between the two paths' configurations of a target still counted as the same solution.
SAME_RAD = 1e-9


@contextlib.contextmanager
def fallbacks_timed():
    """While open, :func:`tribokin.maps.rows._solve` (the one-by-one fallback) adds its seconds to the list yielded."""
    seconds, solve = [0.0], map_rows._solve

    def run(*arguments, **options):
        start = time.perf_counter()
        try:
            return solve(*arguments, **options)
        finally:
            seconds[0] += time.perf_counter() - start

    map_rows._solve = run
    try:
        yield seconds
    finally:
        map_rows._solve = solve


def extrapolate_row_before(q: np.ndarray, reachable: np.ndarray) -> np.ndarray | None:
    """``maps.rows.extrapolate_row`` before the batch: the warm start of a row's next target, or ``None``."""
    count = 0
    while count < min(map_rows.EXTRAPOLATION_POINTS, len(q)) and reachable[len(q) - 1 - count]:
        count += 1
    if count < 2:
        return None
    return sum((-1) ** (j + 1) * math.comb(count, j) * q[len(q) - j] for j in range(1, count + 1))


def solve_row_before(robot, grid, row: int, head_q) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``maps.rows.solve_row`` before the batch: grid row ``row`` target by target from where it starts."""
    indices = grid.row_indices(row)
    closest = np.full((len(indices), 2), np.nan)
    q = np.full((len(indices), robot.model.nv), np.nan)
    reachable = np.zeros(len(indices), dtype=bool)
    q_start = np.asarray(head_q, dtype=float)
    beyond = map_rows.beyond_reach_m(grid, indices)
    for k, index in enumerate(indices):
        if not np.isnan(beyond[k]):
            closest[k, 0] = beyond[k]
            continue
        result = None
        predicted = extrapolate_row_before(q[:k], reachable[:k])
        if predicted is not None:
            result = map_rows._solve_from(robot, grid, index, predicted)
        if result is None or not result.success:
            result = map_rows._solve(robot, grid, index, q_start)
        reachable[k] = result.success
        if result.success:
            q[k] = q_start = result.q
        else:
            closest[k] = result.position_error_m, np.nan if grid.rotation is None else result.angle_error_rad
    return q, reachable, closest


def timed(solve_all, targets: int, repeats: int) -> tuple[dict, tuple]:
    """The figures of the fastest of ``repeats`` runs of ``solve_all()`` (the solutions of every row: q (rows,
    columns, nv), reachable (rows, columns), closest (rows, columns, 2)), and its solutions."""
    best = None
    for _ in range(repeats):
        with fallbacks_timed() as fallbacks:
            start = time.perf_counter()
            solutions = solve_all()
            seconds = time.perf_counter() - start
        if best is None or seconds < best[0]:
            best = seconds, fallbacks[0]
    seconds, fallback_seconds = best
    return {"seconds": seconds, "us_per_target": 1e6 * seconds / targets, "fallback_seconds": fallback_seconds,
            "us_per_target_without_fallbacks": 1e6 * (seconds - fallback_seconds) / targets}, solutions


def batched(robot, grid, starts, batches: list[list[int]]) -> tuple:
    """Every row solved ``batches`` of rows at a time: q, reachable, closest as :func:`timed` wants them."""
    parts = [map_rows.solve_rows(robot, grid, rows, starts[rows]) for rows in batches]
    return tuple(np.concatenate(arrays) for arrays in zip(*parts, strict=True))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--side", type=int, default=150, help="targets per side of the plane (default 150)")
    parser.add_argument("--repeats", type=int, default=2, help="runs of each, the fastest kept (default 2)")
    args = parser.parse_args()
    mapping = read_study_file(STUDY).mapping
    mapping["map"]["resolution"] = [args.side, args.side]
    study = load_study(mapping)
    robot = load_robot(study)
    prepared = prepare_map(study, map_robots(study, robot))
    grid, starts = prepared.grids[0], prepared.row_starts[0]
    rows = list(range(grid.row_count))
    before, (q_before, reachable_before, _) = timed(lambda: tuple(np.array(arrays) for arrays in zip(
        *(solve_row_before(robot, grid, row, starts[row]) for row in rows), strict=True)), grid.size, args.repeats)
    runs, solutions = {}, []
    for size in sorted({study.map.rows_per_chunk, 8, 32, grid.row_count}):
        if size <= grid.row_count:
            batches = chunk_rows(study, grid.row_count) if size == study.map.rows_per_chunk else [
                rows[start:start + size] for start in range(0, grid.row_count, size)]
            runs[f"{size}_rows"], solved = timed(lambda batches=batches: batched(robot, grid, starts, batches),
                                                 grid.size, args.repeats)
            solutions.append(solved)
    per_target = map_rows.solve_rows(robot, grid, rows, starts, batched=False)
    q, reachable, _, _ = solutions[0]  # the map's chunks
    both = reachable & reachable_before
    difference = np.abs(q - q_before)[both].max(axis=-1)
    chunk = runs[f"{study.map.rows_per_chunk}_rows"]
    results = {
        "machine": {"python": platform.python_version(), "numpy": np.__version__, "cpus": os.cpu_count(),
                    "platform": platform.platform(), "OPENBLAS_NUM_THREADS": os.environ.get("OPENBLAS_NUM_THREADS")},
        "map": {"study": "studies/ur5-map-horizontal.toml", "resolution": [args.side, args.side],
                "targets": grid.size, "reached": int(reachable_before.sum()),
                "rows_per_chunk": study.map.rows_per_chunk},
        "row_by_row": before,
        "batched": runs,
        "speed_up_at_the_maps_chunks": before["seconds"] / chunk["seconds"],
        "speed_up_by_rows_per_batch": {name: before["seconds"] / run["seconds"] for name, run in runs.items()},
        "speed_up_without_fallbacks_by_rows_per_batch": {
            name: (before["seconds"] - before["fallback_seconds"]) / (run["seconds"] - run["fallback_seconds"])
            for name, run in runs.items()},
        "targets_solved_differently": int((reachable != reachable_before).sum() + (difference > SAME_RAD).sum()),
        "largest_difference_rad": float(difference.max()),
        "largest_difference_of_the_same_solutions_rad": float(difference[difference <= SAME_RAD].max()),
        "per_target_path_same_bytes_as_before": per_target[0].tobytes() == q_before.tobytes(),
        "same_bytes_for_every_batch_size": all(
            all(a.tobytes() == b.tobytes() for a, b in zip(solved, solutions[0], strict=True)) for solved in solutions),
    }
    RESULTS.parent.mkdir(exist_ok=True)
    RESULTS.write_text(json.dumps(results, indent=2) + "\n")
    print(json.dumps(results, indent=2))


if __name__ == "__main__":
    main()
