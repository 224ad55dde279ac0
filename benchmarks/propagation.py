"""Samples per second of the fast engine and of the exact engine's batched FK (both kernel paths) against the
per-sample Pinocchio FK loop; and the whole ``tribokin run`` of a small expected map with ``study.engine = "exact"``,
its exact FK batched (as shipped) and through the Pinocchio loop (as before the batched FK), in one run.

Run from the repository root: ``OPENBLAS_NUM_THREADS=1 PYTHONPATH=src python benchmarks/propagation.py``
(multithreaded BLAS on this skinny product was up to 5x slower on a busy 2-core machine).
Writes ``benchmarks/results/propagation.json`` and prints a table. Every figure is the best of
``REPEATS`` runs (the machine may be shared; the command's of ``COMMAND_REPEATS``, the two variants in turn); ratios
are against the Pinocchio loop on the same robot.
"""

from __future__ import annotations

import json
import os
import platform
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pinocchio as pin
import tomlkit

from tribokin.compiled import VARIABLE
from tribokin.kinematics.robot import load_example_robot
from tribokin.propagation.exact import tool_deviations_exact, tool_deviations_pinocchio
from tribokin.propagation.poe import MAX_ORDER, tool_deviations_fast

ROBOTS = ("ur5", "panda")
FAST_SAMPLES = 200_000
LOOP_SAMPLES = 20_000
CYCLES_PER_POSE = 30  # ISO 9283 default: what one pose of a study costs
DEVIATION_STD = 1e-4  # joint deviation spread [m or rad] for the automatic order choice
REPEATS = 5
EXACT_SAMPLES = 200_000
COMMAND_REPEATS = 2
ROOT = Path(__file__).resolve().parent.parent
#: The command's study: ur5-map-horizontal on a 4 x 3 plane (8 targets reachable), every figure through exact FK.
EXACT_MAP = ROOT / "studies" / "ur5-map-horizontal.toml"
EXACT_MAP_RESOLUTION = [4, 3]
#: The command in a child process; with "loop" first, the exact engine's FK through the Pinocchio loop.
COMMAND = """import sys
from tribokin.propagation import exact
if sys.argv.pop(1) == "loop":
    exact.tool_deviations_exact = exact.tool_deviations_pinocchio
from tribokin.cli import entry
sys.exit(entry())
"""
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
    loop_rate = LOOP_SAMPLES / best_seconds(lambda: tool_deviations_pinocchio(robot, q, dq[:LOOP_SAMPLES]))
    rows = {"Pinocchio loop": {"order": None, "samples": LOOP_SAMPLES, "samples_per_s": loop_rate}}
    chosen = os.environ.get(VARIABLE)
    for path in ("numpy", "compiled"):
        os.environ[VARIABLE] = path
        tool_deviations_exact(robot, q, dq[:10])  # the compiled kernel loaded (or compiled) first
        rows[f"exact batched ({path})"] = {"order": None, "samples": EXACT_SAMPLES, "samples_per_s": EXACT_SAMPLES
                                           / best_seconds(lambda: tool_deviations_exact(robot, q, dq[:EXACT_SAMPLES]))}
    if chosen is None:
        del os.environ[VARIABLE]
    else:
        os.environ[VARIABLE] = chosen
    auto_order = tool_deviations_fast(robot, q, dq).bound.order
    for order in range(1, MAX_ORDER + 1):
        rate = FAST_SAMPLES / best_seconds(lambda order=order: tool_deviations_fast(robot, q, dq, order=order))
        label = f"fast K={order}" + (" (auto)" if order == auto_order else "")
        rows[label] = {"order": order, "samples": FAST_SAMPLES, "samples_per_s": rate}
    rows["rng.standard_normal alone"] = {
        "order": None, "samples": FAST_SAMPLES,
        "samples_per_s": FAST_SAMPLES / best_seconds(lambda: rng.standard_normal((FAST_SAMPLES, nv)))}
    for row in rows.values():
        row["vs_pinocchio_loop"] = row["samples_per_s"] / loop_rate
    pose = dq[:CYCLES_PER_POSE]
    per_pose_us = {"Pinocchio loop": 1e6 * best_seconds(lambda: tool_deviations_pinocchio(robot, q, pose)),
                   "exact batched": 1e6 * best_seconds(lambda: tool_deviations_exact(robot, q, pose))}
    for order in range(1, MAX_ORDER + 1):
        per_pose_us[f"fast K={order}"] = 1e6 * best_seconds(
            lambda order=order: tool_deviations_fast(robot, q, pose, order=order))
    return {"nv": nv, "q": q.tolist(), "deviation_std": DEVIATION_STD, "auto_order": auto_order,
            "throughput": rows, f"pose_of_{CYCLES_PER_POSE}_cycles_us": per_pose_us}


def exact_map_command(folder: Path) -> dict:
    """``tribokin run`` of :data:`EXACT_MAP` (``study.engine = "exact"``), each variant ``COMMAND_REPEATS`` times in
    turn: its exact FK batched and through the Pinocchio loop. Wall and processor time [s] (user and system of the
    child, ``resource``), each the best of its runs, and the loop's over the batched's."""
    study = tomlkit.parse(EXACT_MAP.read_text())
    study["study"]["engine"] = "exact"
    study["map"]["resolution"] = EXACT_MAP_RESOLUTION
    path = folder / "exact-map.toml"
    path.write_text(tomlkit.dumps(study))
    runs = {"batched": [], "loop": []}
    for _ in range(COMMAND_REPEATS):
        for variant in runs:
            used = resource.getrusage(resource.RUSAGE_CHILDREN)
            start = time.perf_counter()
            subprocess.run([sys.executable, "-c", COMMAND, variant, "run", str(path), "--out", str(folder / variant),
                            "--force"], check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            wall = time.perf_counter() - start
            after = resource.getrusage(resource.RUSAGE_CHILDREN)
            runs[variant].append((wall, after.ru_utime + after.ru_stime - used.ru_utime - used.ru_stime))
    summary = json.loads((folder / "batched" / "summary.json").read_text())
    best = {variant: {"wall_s": min(wall for wall, _ in times), "cpu_s": min(cpu for _, cpu in times),
                      "runs": [{"wall_s": wall, "cpu_s": cpu} for wall, cpu in times]}
            for variant, times in runs.items()}
    return {"study": f"{EXACT_MAP.name}, study.engine = \"exact\", map.resolution = {EXACT_MAP_RESOLUTION}",
            "targets": summary["map"]["count"], "reachable": summary["map"]["reachable"], **best,
            "loop_over_batched_wall": best["loop"]["wall_s"] / best["batched"]["wall_s"],
            "loop_over_batched_cpu": best["loop"]["cpu_s"] / best["batched"]["cpu_s"]}


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
    with tempfile.TemporaryDirectory() as folder:
        results["exact_map_command"] = exact_map_command(Path(folder))
    RESULTS.parent.mkdir(parents=True, exist_ok=True)
    RESULTS.write_text(json.dumps(results, indent=2) + "\n")
    print(f"{'robot':<7}{'engine':<28}{'samples':>9}{'samples/s':>13}{'ns/sample':>11}{'x loop':>9}")
    for name, robot in results["robots"].items():
        for label, row in robot["throughput"].items():
            print(f"{name:<7}{label:<28}{row['samples']:>9}{row['samples_per_s']:>13.3g}"
                  f"{1e9 / row['samples_per_s']:>11.1f}{row['vs_pinocchio_loop']:>9.1f}")
        costs = ", ".join(f"{label} {us:.0f}" for label, us in robot[f"pose_of_{CYCLES_PER_POSE}_cycles_us"].items())
        print(f"{name:<7}one pose of {CYCLES_PER_POSE} cycles [µs]: {costs}")
    command = results["exact_map_command"]
    print(f"tribokin run, {command['study']} ({command['reachable']} of {command['targets']} targets reachable): "
          f"batched {command['batched']['wall_s']:.1f} s ({command['batched']['cpu_s']:.1f} s CPU), Pinocchio loop "
          f"{command['loop']['wall_s']:.1f} s ({command['loop']['cpu_s']:.1f} s CPU): "
          f"{command['loop_over_batched_wall']:.2f}x ({command['loop_over_batched_cpu']:.2f}x CPU)")
    print(f"wrote {RESULTS}")


if __name__ == "__main__":
    main()
