"""Throughput and memory of workspace maps on a UR5 plane.

Run from the repository root: ``OPENBLAS_NUM_THREADS=1 PYTHONPATH=src python benchmarks/map.py``
(``--side 40 --cycles 300`` for a quicker run). Writes ``benchmarks/results/map.json`` and prints
a summary. Figures:

* target-cycles/s of a whole map (IK, bearing loads, sampling, FK, metrics), 1 worker and 2 workers;
* the same rate over per-sample Pinocchio FK loops: the exact engine's (position and orientation, what
  the map would run without the fast engine) and a bare position-only one; and over drawing the same
  random numbers alone (the map's own draws: a fresh generator per target, every joint's friction law);
* how far the resident memory of a child process rises while it computes and writes a 10^4, 10^5,
  10^6 and 2·10^6 target map (few cycles; the kernel's recorded peak, and samples every 10 ms, Linux):
  per-target results go to the map's store on disk, tables are written block by block, figures
  and the scene show at most a bounded number of targets, so it should not grow with targets;
* which of the issue's goals this run meets (``goals``).

Timings are wall clock on whatever machine runs this, which may be shared: read them as orders
of magnitude, and compare ratios measured in the same run. A small map runs first, so one-off costs
(imports, reading the robot's meshes) stay out of the timings.
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


SHIPPED_STUDY = Path(__file__).resolve().parents[1] / "studies" / "ur5-map-horizontal.toml"


def ur5_plane(side_u: int, side_v: int, cycles: int, engine: str = "fast") -> dict:
    """A UR5 map on a horizontal plane in front of the base, tool down, every target reachable;
    robot, payload and joint model those of the shipped ``studies/ur5-map-horizontal.toml``."""
    from tribokin.study.reading import read_study_file

    shipped = read_study_file(SHIPPED_STUDY).mapping
    return {
        "study": {"name": "bench", "cycles": cycles, "seed": 1, "engine": engine},
        "robot": shipped["robot"],
        "joints": shipped["joints"],
        "map": {"kind": "plane", "origin_m": [0.0, -0.55, 0.1], "axis_u": [1, 0, 0], "axis_v": [0, 1, 0],
                "extent_u_m": [-0.4, 0.4], "extent_v_m": [0.0, 0.3], "resolution": [side_u, side_v],
                "rpy_deg": [180, 0, 90]},
    }


def timed_map(study: dict, workers: int) -> tuple[float, object]:
    from tribokin import run_study
    from tribokin.execution import executor_for

    start = time.perf_counter()
    with executor_for(workers) as executor:
        result = run_study(study, executor=executor)
    return time.perf_counter() - start, result.map


def fk_loop_rates(samples: int) -> dict:
    """Samples/s of per-sample Pinocchio loops at one UR5 configuration:

    * ``exact_engine``: tribokin's reference engine (forward kinematics, tool frame, rotation vector),
      i.e. what the map would run without the fast engine;
    * ``position_only``: the bare minimum, forward kinematics and the tool frame's translation.
    """
    from tribokin.kinematics.robot import load_example_robot
    from tribokin.propagation.exact import tool_deviations_exact

    robot = load_example_robot("ur5")
    model, data, frame = robot.model, robot.data, robot.tool_frame_id
    dq = 1e-5 * np.random.default_rng(0).standard_normal((samples, model.nv))
    start = time.perf_counter()
    tool_deviations_exact(robot, robot.reference_q, dq)
    exact_rate = samples / (time.perf_counter() - start)
    out = np.empty((samples, 3))
    start = time.perf_counter()
    for j, q in enumerate(robot.reference_q + dq):
        pin.forwardKinematics(model, data, q)
        out[j] = pin.updateFramePlacement(model, data, frame).translation
    return {"exact_engine_samples_per_s": exact_rate, "position_only_samples_per_s": samples / (time.perf_counter() - start)}


def draw_rate(study: dict, targets: int) -> float:
    """Target-cycles/s of drawing a map's random numbers alone, as the map draws them: per target its
    own stream, the approach signs and every joint's friction coefficients, turned into deviations."""
    from tribokin.simulation.pose_run import PoseRunner, joint_space_task
    from tribokin.streams import map_target_stream
    from tribokin.study.assembly import joint_models, load_robot
    from tribokin.study.reading import load_study

    loaded = load_study(study)
    robot = load_robot(loaded)
    runner = PoseRunner(loaded, robot, joint_models(loaded, robot))
    task = joint_space_task("target", robot.reference_q)
    forces = np.full(robot.model.nv, 100.0)
    start = time.perf_counter()
    for index in range(targets):
        runner.draw(task, forces, loaded.cycles, loaded.approach, map_target_stream(loaded.seed, index))
    return targets * loaded.cycles / (time.perf_counter() - start)


def status_mib(field: str) -> float:
    """``field`` of /proc/self/status (``VmRSS``: resident memory now, ``VmHWM``: its peak) [MiB] (Linux)."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith(field + ":"):
            return int(line.split()[1]) / 1024
    raise KeyError(field)


def memory_child(targets_v: int) -> None:
    """In a child process: run and write a 1000 x ``targets_v`` map as ``tribokin run`` does (results,
    tables, heat maps and the light report) and print how far the resident memory rose above its level
    before [MiB]: the peak the kernel recorded (VmHWM), and sampled every 10 ms."""
    import tempfile

    from tribokin import run_study
    from tribokin.maps.store import chunk_folder
    from tribokin.output.writers import write_results
    from tribokin.study.assembly import load_robot
    from tribokin.study.reading import load_study

    study = ur5_plane(1000, targets_v, MEMORY_CYCLES)
    load_robot(load_study(study))  # imports done and meshes read before the baseline
    import tribokin.viz.report  # noqa: F401  (the writers' imports: matplotlib, meshcat)
    out = Path(tempfile.mkdtemp(prefix="tribokin-bench-")) / "out"
    baseline, peak, running = status_mib("VmRSS"), [0.0], [True]

    def sample():
        while running[0]:
            peak[0] = max(peak[0], status_mib("VmRSS"))
            time.sleep(0.01)

    sampler = threading.Thread(target=sample)
    sampler.start()
    start = time.perf_counter()
    try:
        write_results(run_study(study, checkpoint=chunk_folder(out)), out, report="light")
    finally:
        running[0] = False
        sampler.join()
    seconds = time.perf_counter() - start
    summary = json.loads((out / "summary.json").read_text())["map"]
    with open(out / "map.csv") as table:
        csv_rows = sum(1 for _ in table) - 1
    print(json.dumps({"targets": summary["count"], "reachable": summary["reachable"], "csv_rows": csv_rows,
                      "cycles": MEMORY_CYCLES, "seconds": seconds, "rss_before_MiB": baseline,
                      "peak_rss_growth_MiB": max(peak[0], status_mib("VmHWM")) - baseline,
                      "sampled_peak_growth_MiB": peak[0] - baseline}))


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
    timed_map(ur5_plane(3, 3, 10, args.engine), workers=1)  # warm-up: imports, the robot read once per process
    serial_s, serial = timed_map(study, workers=1)
    targets = serial.grid.size
    target_cycles = int(serial.reachable.sum()) * args.cycles
    two_s, two = timed_map(study, workers=2)
    assert np.array_equal(serial.reference.figures, two.reference.figures, equal_nan=True)
    map_rate = target_cycles / serial_s
    fk_rates = fk_loop_rates(50_000)
    random_rate = draw_rate(study, min(targets, 2000))
    results = {
        "machine": {"python": platform.python_version(), "cpus": os.cpu_count(), "platform": platform.platform(),
                    "OPENBLAS_NUM_THREADS": os.environ.get("OPENBLAS_NUM_THREADS")},
        "map": {"robot": "ur5", "kind": "plane", "targets": targets, "reachable": int(serial.reachable.sum()),
                "cycles": args.cycles, "engine": args.engine},
        "serial": {"seconds": serial_s, "target_cycles_per_s": map_rate, "targets_per_s": targets / serial_s},
        "two_workers": {"seconds": two_s, "target_cycles_per_s": target_cycles / two_s, "speed_up": serial_s / two_s,
                        "identical_to_serial": True},
        "fk_loop": {**fk_rates, "map_rate_over_exact_engine_loop": map_rate / fk_rates["exact_engine_samples_per_s"],
                    "map_rate_over_position_only_loop": map_rate / fk_rates["position_only_samples_per_s"]},
        "random_draws_alone": {"target_cycles_per_s": random_rate, "map_rate_over_draws": map_rate / random_rate},
        "memory": [memory_run(targets_v) for targets_v in (10, 100, 1000, 2000)],
    }
    memory = results["memory"]
    # blocks (65 536 targets), heat maps (400 x 400 per panel) and the scene (50 000 points) reach their
    # caps by 10^6 targets: the growth from there on is what grows with the map
    results["memory_growth_per_target_B"] = ((memory[-1]["peak_rss_growth_MiB"] - memory[-2]["peak_rss_growth_MiB"])
                                             * 2**20 / (memory[-1]["targets"] - memory[-2]["targets"]))
    results["goals"] = {
        "30x_exact_engine_loop": results["fk_loop"]["map_rate_over_exact_engine_loop"] >= 30,
        "half_of_random_draws": results["random_draws_alone"]["map_rate_over_draws"] >= 0.5,
        "1.6x_with_two_workers": results["two_workers"]["speed_up"] >= 1.6,
        "memory_independent_of_targets": results["memory_growth_per_target_B"] < 1,
    }
    RESULTS.parent.mkdir(exist_ok=True)
    RESULTS.write_text(json.dumps(results, indent=2) + "\n")
    print(json.dumps(results, indent=2))


if __name__ == "__main__":
    main()
