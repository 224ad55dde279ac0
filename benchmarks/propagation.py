"""Samples per second of the fast engine against the per-sample Pinocchio FK loop.

Run from the repository root: ``OPENBLAS_NUM_THREADS=1 PYTHONPATH=src python benchmarks/propagation.py``
(multithreaded BLAS on this skinny product was up to 5x slower on a busy 2-core machine).
Writes ``benchmarks/results/propagation.json`` and prints a table. Every figure is the best of
``REPEATS`` runs (the machine may be shared); ratios are against the exact loop on the same robot.
"""

from __future__ import annotations

import json
import os
import platform
import time
from pathlib import Path

import numpy as np
import pinocchio as pin

from tribokin.kinematics.robot import load_example_robot
from tribokin.propagation.exact import tool_deviations_exact
from tribokin.propagation.poe import MAX_ORDER, tool_deviations_fast

ROBOTS = ("ur5", "panda")
FAST_SAMPLES = 200_000
LOOP_SAMPLES = 20_000
CYCLES_PER_POSE = 30  # ISO 9283 default: what one pose of a study costs
DEVIATION_STD = 1e-4  # joint deviation spread [m or rad] for the automatic order choice
REPEATS = 5
RESULTS = Path(__file__).resolve().parent / "results" / "propagation.json"


def best_seconds(run) -> float:
    """Shortest wall time of ``REPEATS`` calls of ``run`` [s]."""
    best = np.inf
    for _ in range(REPEATS):
        start = time.perf_counter()
        run()
        best = min(best, time.perf_counter() - start)
    return best


def benchmark_robot(name: str, rng: np.random.Generator) -> dict:
    """Throughputs [samples/s] of each engine on one robot, at one random configuration."""
    robot = load_example_robot(name)
    nv = robot.model.nv
    q = rng.uniform(np.maximum(robot.lower_limits, -np.pi), np.minimum(robot.upper_limits, np.pi))
    dq = DEVIATION_STD * rng.standard_normal((FAST_SAMPLES, nv))
    loop_rate = LOOP_SAMPLES / best_seconds(lambda: tool_deviations_exact(robot, q, dq[:LOOP_SAMPLES]))
    rows = {"exact loop": {"order": None, "samples": LOOP_SAMPLES, "samples_per_s": loop_rate}}
    auto_order = tool_deviations_fast(robot, q, dq).bound.order
    for order in range(1, MAX_ORDER + 1):
        rate = FAST_SAMPLES / best_seconds(lambda order=order: tool_deviations_fast(robot, q, dq, order=order))
        label = f"fast K={order}" + (" (auto)" if order == auto_order else "")
        rows[label] = {"order": order, "samples": FAST_SAMPLES, "samples_per_s": rate}
    rows["rng.standard_normal alone"] = {
        "order": None, "samples": FAST_SAMPLES,
        "samples_per_s": FAST_SAMPLES / best_seconds(lambda: rng.standard_normal((FAST_SAMPLES, nv)))}
    for row in rows.values():
        row["vs_exact_loop"] = row["samples_per_s"] / loop_rate
    pose = dq[:CYCLES_PER_POSE]
    per_pose_us = {"exact loop": 1e6 * best_seconds(lambda: tool_deviations_exact(robot, q, pose))}
    for order in range(1, MAX_ORDER + 1):
        per_pose_us[f"fast K={order}"] = 1e6 * best_seconds(
            lambda order=order: tool_deviations_fast(robot, q, pose, order=order))
    return {"nv": nv, "q": q.tolist(), "deviation_std": DEVIATION_STD, "auto_order": auto_order,
            "throughput": rows, f"pose_of_{CYCLES_PER_POSE}_cycles_us": per_pose_us}


def main() -> None:
    rng = np.random.default_rng(20240611)
    results = {
        "machine": {"python": platform.python_version(), "numpy": np.__version__, "pinocchio": pin.__version__,
                    "processor": platform.processor() or platform.machine(), "cpus": os.cpu_count(),
                    "load_average_1min": os.getloadavg()[0],
                    "OPENBLAS_NUM_THREADS": os.environ.get("OPENBLAS_NUM_THREADS")},
        "settings": {"fast_samples": FAST_SAMPLES, "loop_samples": LOOP_SAMPLES, "repeats": REPEATS},
        "robots": {name: benchmark_robot(name, rng) for name in ROBOTS},
    }
    RESULTS.parent.mkdir(parents=True, exist_ok=True)
    RESULTS.write_text(json.dumps(results, indent=2) + "\n")
    print(f"{'robot':<7}{'engine':<28}{'samples':>9}{'samples/s':>13}{'ns/sample':>11}{'x loop':>9}")
    for name, robot in results["robots"].items():
        for label, row in robot["throughput"].items():
            print(f"{name:<7}{label:<28}{row['samples']:>9}{row['samples_per_s']:>13.3g}"
                  f"{1e9 / row['samples_per_s']:>11.1f}{row['vs_exact_loop']:>9.1f}")
        costs = ", ".join(f"{label} {us:.0f}" for label, us in robot[f"pose_of_{CYCLES_PER_POSE}_cycles_us"].items())
        print(f"{name:<7}one pose of {CYCLES_PER_POSE} cycles [µs]: {costs}")
    print(f"wrote {RESULTS}")


if __name__ == "__main__":
    main()
