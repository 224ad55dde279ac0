"""A map whose edge lies outside the robot's reach: ``tribokin run`` with and without the reach bounds.

Run from the repository root: ``OPENBLAS_NUM_THREADS=1 PYTHONPATH=src python benchmarks/reach.py``
(``--side 60 --cycles 30`` for a quicker run). Writes ``benchmarks/results/reach.json`` and prints it.

Each run is one child process running ``tribokin run <study> --report light --workers 1`` on a copy of the
shipped ``studies/ur5-map-horizontal.toml`` (tool pointing down: the orientation held) at ``--side`` × ``--side``
targets (``--cycles`` cycles): ``before`` with the bounds switched off (:func:`tribokin.maps.rows.beyond_reach_m`
finding no target beyond the reach, the IK tried everywhere as before them), ``sphere`` with the tool point's sphere
alone (:func:`tribokin.kinematics.reach.reach_sphere`), ``after`` as shipped (that sphere, then the last joint's,
:func:`tribokin.kinematics.reach.last_joint_sphere`). Figures per run:

* ``seconds``: the command's wall time in the child (``seconds_process``: the whole child, imports included);
* the IK's time [s] per target, by outcome: reached, unreachable within the bounds, beyond the tool point's sphere
  (``beyond``), within it but beyond the last joint's (``beyond_last_joint``) (the time of every IK solve of a
  target, warm start, restarts, row head and retries from neighbours, summed per target; the time of a column's
  warm starts solved together shared equally among its targets);
* that the runs wrote the same bytes to ``map.csv`` (a target's reason for being beyond the reach is made from its
  position, so it reads the same whether the IK was tried there or not).

Timings are wall clock on whatever machine runs this, which may be shared: compare ratios measured in the same run.
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path

START = time.perf_counter()

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results" / "reach.json"
STUDY = ROOT / "studies" / "ur5-map-horizontal.toml"
SHIPPED_RESOLUTION = "resolution = [49, 29]"


def child(mode: str, study: str, out: str, cycles: int) -> None:
    """In a child process: run the study as ``tribokin run`` does (the bounds off for ``mode == "before"``, the tool
    point's sphere alone for ``"sphere"``), the IK of each target timed; print the figures as one JSON line."""
    import numpy as np

    from tribokin.cli import main
    from tribokin.maps import rows

    if mode == "before":
        rows.beyond_reach_m = lambda grid, indices: np.full(len(indices), np.nan)
    elif mode == "sphere":
        rows.beyond_reach_m = lambda grid, indices, bound=rows.beyond_reach_m: bound(
            dataclasses.replace(grid, reach=grid.reach[:1]), indices)
    ik_seconds = defaultdict(float)

    def timed(solve, indices_of):
        def run(*arguments, **options):
            start = time.perf_counter()
            try:
                return solve(*arguments, **options)
            finally:
                indices = indices_of(*arguments)
                for index in indices:
                    ik_seconds[int(index)] += (time.perf_counter() - start) / len(indices)
        return run

    for name in ("_solve", "_solve_from"):
        setattr(rows, name, timed(getattr(rows, name), lambda robot, grid, index, q_start: [index]))
    rows._solve_from_warm_starts = timed(rows._solve_from_warm_starts,
                                         lambda robot, chain, grid, indices, *rest: indices)
    start = time.perf_counter()
    status = main(["run", study, "--out", out, "--cycles", cycles, "--report", "light", "--workers", 1, "--force"])
    seconds = time.perf_counter() - start
    assert status == 0, status
    with open(Path(out) / "map.csv", newline="") as table:
        outcome = [("reached" if row["reachable"] == "true"
                    else "beyond" if row["reason"].startswith("beyond the robot's reach: ")
                    else "beyond_last_joint" if row["reason"].startswith("beyond")
                    else "unreachable") for row in csv.DictReader(table)]
    ik = {}
    for kind in ("reached", "unreachable", "beyond", "beyond_last_joint"):
        indices = [i for i, k in enumerate(outcome) if k == kind]
        total = sum(ik_seconds.get(i, 0.0) for i in indices)
        ik[kind] = {"targets": len(indices), "ik_seconds": total,
                    "ik_ms_per_target": 1e3 * total / len(indices) if indices else None}
    print(json.dumps({"seconds": seconds, "seconds_process": time.perf_counter() - START,
                      "ik_seconds": sum(ik_seconds.values()), "ik": ik}))


def run(mode: str, study: Path, out: Path, cycles: int) -> dict:
    command = [sys.executable, __file__, "--child", mode, str(study), str(out), str(cycles)]
    done = subprocess.run(command, capture_output=True, text=True, check=True, env=os.environ)
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--side", type=int, default=150, help="targets per side of the plane (default 150)")
    parser.add_argument("--cycles", type=int, default=100, help="cycles per target (default 100)")
    parser.add_argument("--child", nargs=4, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        mode, study, out, cycles = args.child
        return child(mode, study, out, int(cycles))

    text = STUDY.read_text()
    assert SHIPPED_RESOLUTION in text
    folder = Path(tempfile.mkdtemp(prefix="tribokin-reach-"))
    study = folder / "ur5-map-horizontal.toml"
    study.write_text(text.replace(SHIPPED_RESOLUTION, f"resolution = [{args.side}, {args.side}]"))
    runs = {mode: run(mode, study, folder / mode, args.cycles) for mode in ("before", "sphere", "after")}
    before, sphere, after = runs["before"], runs["sphere"], runs["after"]
    results = {
        "machine": {"python": platform.python_version(), "cpus": os.cpu_count(), "platform": platform.platform(),
                    "OPENBLAS_NUM_THREADS": os.environ.get("OPENBLAS_NUM_THREADS")},
        "map": {"study": "studies/ur5-map-horizontal.toml", "resolution": [args.side, args.side],
                "cycles": args.cycles, "report": "light", "workers": 1},
        **runs,
        "speed_up": before["seconds"] / after["seconds"],
        "ik_speed_up": before["ik_seconds"] / after["ik_seconds"],
        "speed_up_over_sphere": sphere["seconds"] / after["seconds"],
        "ik_speed_up_over_sphere": sphere["ik_seconds"] / after["ik_seconds"],
        "same_map_csv": len({(folder / mode / "map.csv").read_bytes() for mode in runs}) == 1,
    }
    RESULTS.parent.mkdir(exist_ok=True)
    RESULTS.write_text(json.dumps(results, indent=2) + "\n")
    print(json.dumps(results, indent=2))


if __name__ == "__main__":
    main()
