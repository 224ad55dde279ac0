"""Throughput and memory of workspace maps on a UR5 plane.

Run from the repository root: ``OPENBLAS_NUM_THREADS=1 PYTHONPATH=src python benchmarks/map.py``
(``--side 40 --cycles 300`` for a quicker run). Writes ``benchmarks/results/map.json`` and prints
a summary. Figures:

* target-cycles/s of a whole map (IK, bearing loads, sampling, FK, metrics), 1 worker and 2 workers;
* the same rate over a bare per-sample Pinocchio FK loop (the floor of the exact engine), and over
  drawing the same random numbers alone (a fresh generator per target, every joint's friction law);
* how far the resident memory of a child process rises while it computes a 10^4 and a 10^5 target
  map (few cycles; sampled every 10 ms, Linux): only per-target scalars are kept, so it grows
  with targets (tens of bytes each), not with cycles.

Timings are wall clock on whatever machine runs this, which may be shared: read them as orders
of magnitude, and compare ratios measured in the same run.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pinocchio as pin

RESULTS = Path(__file__).resolve().parent / "results" / "map.json"
MEMORY_CYCLES = 10


def ur5_plane(side_u: int, side_v: int, cycles: int, engine: str = "fast") -> dict:
    """A UR5 map on a horizontal plane in front of the base, tool down, every target reachable."""
    return {
        "study": {"name": "bench", "cycles": cycles, "seed": 1, "engine": engine},
        "robot": {"name": "ur5", "payload_kg": 3.0},
        "joints": {"friction": {"preset": "42CD4-raw"}, "stiffness": 1.0e5, "bearing_span_m": 0.08},
        "map": {"kind": "plane", "origin_m": [0.0, -0.55, 0.1], "axis_u": [1, 0, 0], "axis_v": [0, 1, 0],
                "extent_u_m": [-0.4, 0.4], "extent_v_m": [0.0, 0.3], "resolution": [side_u, side_v],
                "rpy_deg": [180, 0, 90]},
    }


def timed_map(study: dict, workers: int) -> tuple[float, object]:
    from tribokin import run_study

    start = time.perf_counter()
    result = run_study(study, workers=workers)
    return time.perf_counter() - start, result.map


def fk_loop_rate(samples: int) -> float:
    """Samples/s of the bare per-sample loop: configuration, forward kinematics, tool frame, copy."""
    from tribokin.robot import load_example_robot

    robot = load_example_robot("ur5")
    model, data, frame = robot.model, robot.data, robot.tool_frame_id
    q = robot.reference_q + 1e-5 * np.random.default_rng(0).standard_normal((samples, model.nv))
    out = np.empty((samples, 3))
    start = time.perf_counter()
    for j in range(samples):
        pin.forwardKinematics(model, data, q[j])
        out[j] = pin.updateFramePlacement(model, data, frame).translation
    return samples / (time.perf_counter() - start)


def draw_rate(targets: int, cycles: int) -> float:
    """Target-cycles/s of drawing a map's random numbers alone: per target a fresh stream and one
    friction draw of ``cycles`` values per joint, as the map does."""
    from tribokin.study import pose_rng
    from tribokin.tribology.spec import law_from_spec

    law, joints = law_from_spec({"preset": "42CD4-raw"}), 6
    start = time.perf_counter()
    for index in range(targets):
        rng = pose_rng(1, index, 2)
        for _ in range(joints):
            law.rvs(size=cycles, random_state=rng)
    return targets * cycles / (time.perf_counter() - start)


def resident_mib() -> float:
    """Current resident memory of this process [MiB] (Linux /proc)."""
    return int(Path("/proc/self/statm").read_text().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20


def memory_child(targets_v: int) -> None:
    """In a child process: print how far the resident memory rose above its level before a
    1000 x ``targets_v`` map [MiB], sampled every 10 ms."""
    from tribokin import run_study
    from tribokin.study import load_robot, load_study

    study = ur5_plane(1000, targets_v, MEMORY_CYCLES)
    load_robot(load_study(study))  # imports done and meshes read before the baseline
    baseline, peak, running = resident_mib(), [0.0], [True]

    def sample():
        while running[0]:
            peak[0] = max(peak[0], resident_mib())
            time.sleep(0.01)

    sampler = threading.Thread(target=sample)
    sampler.start()
    start = time.perf_counter()
    result = run_study(study)
    seconds = time.perf_counter() - start
    running[0] = False
    sampler.join()
    print(json.dumps({"targets": result.map.grid.size, "reachable": int(result.map.reachable.sum()),
                      "cycles": MEMORY_CYCLES, "seconds": seconds, "rss_before_MiB": baseline,
                      "peak_rss_growth_MiB": peak[0] - baseline}))


def memory_run(targets_v: int) -> dict:
    command = [sys.executable, __file__, "--memory-child", str(targets_v)]
    done = subprocess.run(command, capture_output=True, text=True, check=True, env=os.environ)
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--side", type=int, default=100, help="targets per side of the plane (default 100)")
    parser.add_argument("--cycles", type=int, default=1000, help="cycles per target (default 1000)")
    parser.add_argument("--engine", choices=("fast", "exact"), default="fast", help="propagation engine (default fast)")
    parser.add_argument("--memory-child", type=int, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.memory_child:
        return memory_child(args.memory_child)

    study = ur5_plane(args.side, args.side, args.cycles, args.engine)
    serial_s, serial = timed_map(study, workers=1)
    targets = serial.grid.size
    target_cycles = int(serial.reachable.sum()) * args.cycles
    two_s, two = timed_map(study, workers=2)
    assert np.array_equal(serial.reference.figures, two.reference.figures, equal_nan=True)
    map_rate = target_cycles / serial_s
    fk_rate = fk_loop_rate(50_000)
    random_rate = draw_rate(min(targets, 2000), args.cycles)
    results = {
        "machine": {"python": platform.python_version(), "cpus": os.cpu_count(), "platform": platform.platform(),
                    "OPENBLAS_NUM_THREADS": os.environ.get("OPENBLAS_NUM_THREADS")},
        "map": {"robot": "ur5", "kind": "plane", "targets": targets, "reachable": int(serial.reachable.sum()),
                "cycles": args.cycles, "engine": args.engine},
        "serial": {"seconds": serial_s, "target_cycles_per_s": map_rate, "targets_per_s": targets / serial_s},
        "two_workers": {"seconds": two_s, "target_cycles_per_s": target_cycles / two_s, "speed_up": serial_s / two_s,
                        "identical_to_serial": True},
        "fk_loop": {"samples_per_s": fk_rate, "map_rate_over_fk_loop": map_rate / fk_rate},
        "random_draws_alone": {"target_cycles_per_s": random_rate, "map_rate_over_draws": map_rate / random_rate},
        "memory": [memory_run(10), memory_run(100)],
    }
    RESULTS.parent.mkdir(exist_ok=True)
    RESULTS.write_text(json.dumps(results, indent=2) + "\n")
    print(json.dumps(results, indent=2))


if __name__ == "__main__":
    main()
