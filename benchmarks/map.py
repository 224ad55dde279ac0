"""Speed and memory of workspace maps: the whole ``tribokin run`` command on a UR5 plane, in one run.

Run from the repository root: ``OPENBLAS_NUM_THREADS=1 PYTHONPATH=src python benchmarks/map.py`` (about 3 minutes on
2 cores; ``--quick`` for a small run of about a minute, printed and not written unless ``--results`` is given).
Writes ``benchmarks/results/map.json`` and prints it.

Every map is the shipped ``studies/ur5-map-horizontal.toml`` (its robot, payload, friction law and loads; the
default ``map.statistic = "expected"``) with only ``map.resolution`` and ``study.cycles`` changed (and
``map.statistic`` for the one-test runs). Figures:

* ``command``: the wall time of ``python -m tribokin run <study> --out <tmp> --report light`` in a child process
  (imports, IK, figures, map.csv, heat maps, report: what a user waits for) on a ``--side`` × ``--side`` plane
  (600 × 600) × ``--cycles`` (1000), on 1 worker and on 2 (``--workers 2``), each the best of 3 runs (as the FK loop;
  ``runs_s``: every run's), and the target-cycles/s it makes (reachable targets × cycles / wall time); that the two
  wrote the same ``map.csv``; the 2-worker speed-up;
* ``kernels``: the compiled kernels (numba) against the NumPy path (``TRIBOKIN_KERNELS=numpy``): the cold compile
  (numba's cache empty) and the warm load of a tiny map's command, and the whole command on 2 workers on both paths,
  on the big plane (best of 3 each) and on the 10^6-target map (one run each), with their ratios (``goals``:
  whether they double each); how the big plane's two map.csv differ (``map_csv_against_numpy``: targets whose IK
  found another configuration, and elsewhere the largest differences);
* ``fk_loop``: a single-core loop of Pinocchio frame forward kinematics per sample (``pin.forwardKinematics`` and
  ``pin.updateFramePlacement`` at UR5 configurations), its time per sample, and the command's rate over it: the
  loop's time for reachable targets × cycles × the test's approach series (1, or 2 for ``bidirectional`` and
  ``random``: ``series``) samples over the command's wall time: the best run over the best loop, and (``paired``)
  each 2-worker run over the loop timed right after it, whose median the goal (100× on 2 workers) is judged on, since
  a shared machine's speed drifts in the minutes between the loop and the runs;
* ``directional``: the plane (``--directional-side``, the big plane's by default) on 2 workers with
  ``map.directional = false``, then ``true``, in turn (``--directional-repeats``), the FK loop timed after each run:
  the map's ratio to the loop with the directional figures on (``on_over_loop``, the goal of 100×) and off (each
  the median of the runs over their own loops; vAP_p's and RP_l_multi's series are not counted in the loop's
  equivalent), and what the directional figures cost (``cost_ratio``: each run with them over the run without them
  just before it, in wall time; ``cpu_cost_ratio``: in processor time, which a shared machine's load moves less);
  ``profile``: where a directional map's time goes, from cProfile of one in-process run on 1 worker
  of a ``--profile-side`` plane: the expected figures, RP_l_multi's sampled cycles over random sign patterns (their
  random numbers, the cycles through the first-order model, RP_l from the cycles' moments, the sampled tests' RP_l,
  fast-engine fallbacks), vAP_p (its expected distances, close pairs within the compiled kernel, its approach signs
  and the rest), the rest of the expected figures and of the command;
* ``one_test``: the same command with ``map.statistic = "one-test"`` (one simulated test per target: the engine
  before expected maps) on a ``--one-test-side`` plane (a 600 × 600 one would take minutes), beside the expected
  map on the same plane; its time per reachable target scaled to the big plane's reachable targets (``scaled``) for
  the ratio of one-test to expected time there, and the ratio measured on the same plane;
* ``stages``: µs per target (all targets of the plane) of each stage of one in-process run of the command on the
  big plane (1 worker, every stage in one process: the views too, not by the views' process), from timing hooks
  wrapped around the functions that do each stage, each stage's time its own
  (a stage inside another counts for itself only): imports, the robot (URDF and meshes), IK (rows' heads, rows,
  holes from neighbours), bearing loads, tool frames (what measuring a row takes besides the loads and the
  figures), expected figures, the map's store, map.csv, figures and report, and the rest (``other``: the command
  line, reading the study, budget checks, the grid, summary.json, the folder);
* ``million``: a 10^6-target (1000 × 1000) × ``--cycles`` map on 2 workers: ``computed_s``, the time of
  ``run_study`` in a child process, after its imports (reading the study and the robot, IK, loads, figures, the
  store, holes from neighbours), and ``command_s``, the whole command with its outputs;
* ``memory``: how far the resident memory of a child process rises while it computes and writes (results, map.csv,
  heat maps, light report; 1 worker) a map of 10^4, 10^6 and 2·10^6 targets (the kernel's recorded peak, and
  samples every 10 ms; Linux): per-target results go to the map's store on disk, tables are written block by block,
  heat maps and the scene show at most a bounded number of targets; the growth per target from 10^6 to 2·10^6
  (the caps are reached by 10^6) is what grows with the map;
* ``goals``: which of the issue's goals this run meets.

tribokin's sources are compiled to bytecode first (``compileall``, into ``src/**/__pycache__``), as installing a
package does: where ``PYTHONDONTWRITEBYTECODE`` is set (this machine sets it) a checkout's modules would otherwise be
compiled again by every command (about 0.06 s of its serial start).

Timings are wall clock on whatever machine runs this, which may be shared (``machine.load_average`` before and after
the run says how busy it was): read them as orders of magnitude, and compare ratios measured in the same run.
``machine.cpu`` names the processor (its model, and the vector extensions /proc/cpuinfo lists on Linux or ``sysctl``
on macOS), the SIMD extensions NumPy was built for and dispatches to there, and the CPU and vector features numba
compiles the kernels for: the FK loop and the kernels gain from them differently (AVX-512 against AVX2 only).
"""

from __future__ import annotations

import argparse
import builtins
import compileall
import csv
import importlib
import json
import os
import platform
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import dataclass
from pathlib import Path

START = time.perf_counter()

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results" / "map.json"
#: Where ``--directional-only`` writes, and its goal: the directional figures cost at most this ratio of the map.
DIRECTIONAL_RESULTS, GOAL_DIRECTIONAL_COST = ROOT / "benchmarks" / "results" / "map_directional.json", 1.5
STUDY = ROOT / "studies" / "ur5-map-horizontal.toml"
#: Goals of the issue: the command on 2 workers over the FK loop, a 10^6-target map's computation and command [s],
#: and the memory growth per target from 10^6 to 2·10^6 targets [B].
GOAL_FK_RATIO, GOAL_MILLION_COMPUTED_S, GOAL_MILLION_COMMAND_S, GOAL_GROWTH_B = 100, 10.0, 20.0, 1.0
#: The approach series of a map target's test under each ``study.approach``: what the FK loop's equivalent counts
#: (reachable targets x cycles x series; vAP_p's and RP_l_multi's series are not counted).
APPROACH_SERIES = {"unidirectional": 1, "bidirectional": 2, "random": 2}
#: Runs of each command on the big plane, the best kept (as the FK loop's best of 3): one run moves by 10-20 % with
#: whatever else the machine does.
PLANE_REPEATS = 3


def study_text(side_u: int, side_v: int, cycles: int, statistic: str = "expected",
               directional: bool | None = None) -> str:
    """The shipped study's text with ``map.resolution = [side_u, side_v]``, ``study.cycles`` and, unless
    ``"expected"`` (the default), ``map.statistic``; ``map.directional`` set unless ``None`` (the study's own)."""
    import tomlkit

    study = tomlkit.parse(STUDY.read_text())
    study["study"]["cycles"] = cycles
    study["map"]["resolution"] = [side_u, side_v]
    if statistic != "expected":
        study["map"]["statistic"] = statistic
    if directional is not None:
        study["map"]["directional"] = directional
    return tomlkit.dumps(study)


def write_study(folder: Path, side_u: int, side_v: int, cycles: int, statistic: str = "expected",
                directional: bool | None = None) -> Path:
    kind = "" if directional is None else "-directional" if directional else "-plain"
    path = folder / f"map-{side_u}x{side_v}-{cycles}-{statistic}{kind}.toml"
    path.write_text(study_text(side_u, side_v, cycles, statistic, directional))
    return path


#: numba's cache of compiled kernels for every child process of one run (empty at first: the cold compile), made by
#: the run's first process (:func:`main`, which deletes it at the end) and passed on to its children in this variable.
NUMBA_CACHE_VARIABLE = "TRIBOKIN_BENCHMARK_NUMBA_CACHE"


def numba_cache() -> Path:
    """This run's numba cache (:data:`NUMBA_CACHE_VARIABLE`)."""
    return Path(os.environ[NUMBA_CACHE_VARIABLE])


def child_env(kernels: str = "compiled") -> dict:
    """The environment of a child process: this checkout's sources, the run's numba cache, ``TRIBOKIN_KERNELS``."""
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT / "src"), *filter(None, [env.get("PYTHONPATH")])])
    env["NUMBA_CACHE_DIR"] = str(numba_cache())
    env["TRIBOKIN_KERNELS"] = kernels
    return env


def child(*arguments) -> dict:
    """The JSON line this script prints last when run in a child process with ``arguments``."""
    done = subprocess.run([sys.executable, __file__, *map(str, arguments)], capture_output=True, text=True,
                          check=True, env=child_env())
    return json.loads(done.stdout.strip().splitlines()[-1])


def children_cpu_seconds() -> float | None:
    """User and system time [s] of this process's finished children (and theirs, where they waited for them), or
    ``None`` without the ``resource`` module (Windows)."""
    try:
        import resource
    except ImportError:
        return None
    used = resource.getrusage(resource.RUSAGE_CHILDREN)
    return used.ru_utime + used.ru_stime


def command(study: Path, out: Path, workers: int = 1, kernels: str = "compiled", repeats: int = 1,
            loop_samples: int | None = None) -> dict:
    """Wall time of ``tribokin run study --out out --report light --workers N`` in a child process (``kernels``: the
    kernels' path, ``TRIBOKIN_KERNELS``): the best of ``repeats`` runs (``runs_s``: each run's), and the map's targets
    and reachable targets (its summary.json). With ``loop_samples``, the FK loop is timed right after each run
    (:func:`fk_loop_seconds_per_sample`, ``loop_s``: each run's), so that each run has a loop time taken while the
    machine ran at the same speed. ``cpu_s``: each run's processor time (user and system, its workers' and views'
    processes included; where ``resource`` exists), which moves less than the wall time with a shared machine's
    load."""
    runs, loops, cpu = [], [], []
    for _ in range(repeats):
        shutil.rmtree(out, ignore_errors=True)
        used = children_cpu_seconds()
        start = time.perf_counter()
        subprocess.run([sys.executable, "-m", "tribokin", "run", str(study), "--out", str(out), "--report", "light",
                        "--workers", str(workers)], check=True, env=child_env(kernels), stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL)
        runs.append(time.perf_counter() - start)
        cpu.append(None if used is None else children_cpu_seconds() - used)
        if loop_samples is not None:
            loops.append(fk_loop_seconds_per_sample(loop_samples))
    summary = json.loads((out / "summary.json").read_text())
    assert summary["reproduce"]["kernels"].startswith(kernels), summary["reproduce"]["kernels"]
    return {"workers": workers, "kernels": kernels, "seconds": min(runs), "runs_s": runs, "cpu_s": cpu,
            "targets": summary["map"]["count"], "reachable": summary["map"]["reachable"],
            "directional": summary["map"].get("directional", False),
            "series": APPROACH_SERIES[summary["study"]["approach"]]} | ({"loop_s": loops} if loops else {})


def compile_times(study: Path, folder: Path) -> dict:
    """The compiled kernels' cost on a tiny map (``study``): the command with numba's cache empty (compiling every
    kernel the map uses), then filled (loading them), and on the NumPy path; cold and warm compile times as the
    differences."""
    for stale in numba_cache().iterdir():
        shutil.rmtree(stale) if stale.is_dir() else stale.unlink()
    cold = command(study, folder / "cold")["seconds"]
    warm = min(command(study, folder / "warm")["seconds"] for _ in range(3))
    plain = min(command(study, folder / "numpy", kernels="numpy")["seconds"] for _ in range(3))
    return {"how": "tribokin run on a 3 x 3 plane: numba's cache empty (cold), then filled (warm, best of 3), and "
                   "the NumPy path (best of 3); differences to the NumPy path",
            "cold_command_s": cold, "warm_command_s": warm, "numpy_command_s": plain,
            "cold_compile_s": cold - plain, "warm_load_s": warm - plain}


def paired_ratios(run: dict, cycles: int) -> dict:
    """Each run of ``run`` (:func:`command` with ``loop_samples``) over the FK loop timed right after it, and their
    median: unlike the best run over the best loop, timed minutes apart, this ratio does not move with the speed of
    a shared machine between the two."""
    ratios = [run["reachable"] * cycles * run["series"] * loop / seconds
              for seconds, loop in zip(run["runs_s"], run["loop_s"], strict=True)]
    return {"how": "each 2-worker run's loop-equivalent time (reachable targets x cycles x the test's approach "
                   "series x the loop's time per sample, the loop timed right after that run, best of 3) over its "
                   "wall time; the goal is judged on the median",
            "runs": [{"command_s": seconds, "loop_s_per_sample": loop, "ratio": ratio}
                     for seconds, loop, ratio in zip(run["runs_s"], run["loop_s"], ratios, strict=True)],
            "median_ratio": float(statistics.median(ratios))}


def directional_cost(folder: Path, side: int, cycles: int, repeats: int, loop_samples: int) -> dict:
    """The ``side`` x ``side`` plane on 2 workers with ``map.directional = true`` and ``false``, in turn ``repeats``
    times (each run followed by the FK loop: :func:`command` with ``loop_samples``): the map's ratio to the FK loop
    with the directional figures on and off (each run over its own loop, the median), and what they cost (each
    run with them over the run without them just before it, the median)."""
    runs = {True: [], False: []}
    studies = {on: write_study(folder, side, side, cycles, directional=on) for on in runs}
    for _ in range(repeats):
        for on in (False, True):
            runs[on].append(command(studies[on], folder / f"directional-{on}", workers=2, loop_samples=loop_samples))
    merged = {on: {**done[0], "seconds": min(r["seconds"] for r in done),
                   **{key: [r[key][0] for r in done] for key in ("runs_s", "cpu_s", "loop_s")}}
              for on, done in runs.items()}
    for run in merged.values():
        run["paired"] = paired_ratios(run, cycles)
    costs = [on / off for on, off in zip(merged[True]["runs_s"], merged[False]["runs_s"], strict=True)]
    cpu_costs = [on / off for on, off in zip(merged[True]["cpu_s"], merged[False]["cpu_s"], strict=True)
                 if on is not None]
    return {"how": "the plane on 2 workers with map.directional = false, then true, in turn; the FK loop timed right "
                   "after each run; its equivalent: reachable targets x cycles x the test's approach series (vAP_p's "
                   "and RP_l_multi's series not counted)",
            "resolution": [side, side], "cycles": cycles, "series": merged[True]["series"],
            "on": merged[True], "off": merged[False],
            "on_over_loop": merged[True]["paired"]["median_ratio"],
            "off_over_loop": merged[False]["paired"]["median_ratio"],
            "cost_ratio": {"runs": costs, "median": float(statistics.median(costs))},
            "cpu_cost_ratio": {"runs": cpu_costs, "median": float(statistics.median(cpu_costs)) if cpu_costs else None}}


def rates(run: dict, cycles: int) -> dict:
    """``run`` with its target-cycles/s and µs per target."""
    return {**run, "target_cycles_per_s": run["reachable"] * cycles / run["seconds"],
            "us_per_target": run["seconds"] / run["targets"] * 1e6}


def fk_loop_seconds_per_sample(samples: int, repeats: int = 3) -> float:
    """Seconds per sample of a loop of Pinocchio frame forward kinematics (``forwardKinematics`` and
    ``updateFramePlacement``, the tool frame's translation kept) at UR5 configurations a few µrad apart (best of
    ``repeats``)."""
    import numpy as np
    import pinocchio as pin

    from tribokin.kinematics.robot import load_example_robot

    robot = load_example_robot("ur5")
    model, data, frame = robot.model, robot.data, robot.tool_frame_id
    qs = robot.reference_q + 1e-5 * np.random.default_rng(0).standard_normal((samples, model.nq))
    out = np.empty((samples, 3))
    best = float("inf")
    for _ in range(repeats):
        start = time.perf_counter()
        for j, q in enumerate(qs):
            pin.forwardKinematics(model, data, q)
            out[j] = pin.updateFramePlacement(model, data, frame).translation
        best = min(best, (time.perf_counter() - start) / samples)
    return best


# --- the machine's processor -----------------------------------------------------------------------------------

#: The flags of /proc/cpuinfo (x86: ``flags``; ARM: ``Features``) that name vector extensions: SSE to AVX-512 and
#: AMX, FMA and F16C on x86 (``pni`` is SSE3), NEON (``asimd``) and SVE on ARM, VSX / AltiVec on POWER.
VECTOR_FLAG = re.compile(r"^(sse|ssse3|pni|avx|fma|f16c|amx|asimd|sve|neon|vsx|altivec)")


def cpu() -> dict:
    """The processor the benchmark ran on: its model and vector extensions as the operating system reports them
    (/proc/cpuinfo on Linux, ``sysctl`` on macOS; elsewhere ``platform.processor()`` and no flags), NumPy's view
    (``numpy.show_config(mode="dicts")``: the SIMD baseline it was built for and the extensions it dispatches to
    here) and numba's (the host CPU llvmlite compiles the kernels for, and the vector features it enables)."""
    model, flags = platform.processor() or None, None
    if sys.platform.startswith("linux") and Path("/proc/cpuinfo").is_file():
        fields = {}
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            key, _, value = line.partition(":")
            fields.setdefault(key.strip(), value.strip())
        model = fields.get("model name") or fields.get("Hardware") or fields.get("cpu") or model
        flags = (fields.get("flags") or fields.get("Features") or "").split()
    elif sys.platform == "darwin":
        def sysctl(name):
            done = subprocess.run(["sysctl", "-n", name], capture_output=True, text=True)
            return done.stdout.strip() if done.returncode == 0 else ""
        model = sysctl("machdep.cpu.brand_string") or model
        flags = " ".join(sysctl(f"machdep.cpu.{name}") for name in ("features", "leaf7_features")).lower().split()
    import numpy as np

    try:
        numpy_simd = np.show_config(mode="dicts").get("SIMD Extensions")
    except TypeError:  # NumPy before 1.26 prints only
        numpy_simd = None
    try:
        import llvmlite.binding as llvm

        features = llvm.get_host_cpu_features()
        numba = {"cpu": llvm.get_host_cpu_name(),
                 "vector_features": sorted(name for name, on in features.items() if on and VECTOR_FLAG.match(name))}
    except (ImportError, RuntimeError):
        numba = None
    return {"model": model, "cores": os.cpu_count(),
            "vector_extensions": None if flags is None else sorted({flag for flag in flags if VECTOR_FLAG.match(flag)}),
            "numpy_simd": numpy_simd, "numba_host": numba}


# --- stages: one in-process run of the command, timed by hooks --------------------------------------------------

class StageClock:
    """Exclusive wall time per named stage: time spent in a stage entered from another counts for the inner one."""

    def __init__(self):
        self.seconds, self.stack = {}, []

    def enter(self, name: str) -> None:
        self.stack.append([name, time.perf_counter(), 0.0])

    def leave(self) -> None:
        name, start, inner = self.stack.pop()
        spent = time.perf_counter() - start
        self.seconds[name] = self.seconds.get(name, 0.0) + spent - inner
        if self.stack:
            self.stack[-1][2] += spent

    def wrap(self, name: str, function):
        def timed(*arguments, **keywords):
            self.enter(name)
            try:
                return function(*arguments, **keywords)
            finally:
                self.leave()
        return timed

    def wrap_imports(self) -> None:
        """Count every import (the outermost one of nested imports) as the stage ``imports``."""
        plain = builtins.__import__

        def timed_import(*arguments, **keywords):
            if self.stack and self.stack[-1][0] == "imports":
                return plain(*arguments, **keywords)
            self.enter("imports")
            try:
                return plain(*arguments, **keywords)
            finally:
                self.leave()

        builtins.__import__ = timed_import
        importlib.import_module = self.wrap("imports", importlib.import_module)


#: (module, attribute, stage): the functions each stage's time is measured around, where the code calls them.
STAGE_HOOKS = (
    ("tribokin.run", "load_robot", "robot"),
    ("tribokin.maps.mapping", "solve_row_starts", "IK: rows' heads"),
    ("tribokin.maps.mapping", "solve_rows", "IK: rows"),
    ("tribokin.maps.mapping", "fill_from_neighbours", "IK: holes from neighbours"),
    ("tribokin.simulation.pose_test", "PoseRunner.normal_forces_at", "loads"),
    ("tribokin.maps.mapping", "measure_into", "tool frames"),  # the rest of measuring a row: its tool frames
    ("tribokin.maps.mapping", "expected_targets", "expected figures"),
    ("tribokin.maps.mapping", "measure_targets", "one-test figures"),
    ("tribokin.maps.store", "ChunkStore.save", "store"),
    ("tribokin.maps.store", "ChunkStore.write", "store"),
    ("tribokin.output.writers", "write_map_tables", "map.csv"),
    ("tribokin.viz.contents", "write_views", "figures and report"),
)


def stages_child(study: str, out: str) -> None:
    """In a child process: ``tribokin run study --out out --report light`` (1 worker) in this process, its stages
    timed (:data:`STAGE_HOOKS`), the views drawn here too (not by the views' process the command forks: its time would
    be missing); print the seconds per stage as one JSON line."""
    clock = StageClock()
    clock.wrap_imports()
    clock.enter("other")
    from tribokin.cli import main
    from tribokin.output.views_process import ViewsProcess

    ViewsProcess.start = classmethod(lambda cls, *arguments: None)

    for module, attribute, stage in STAGE_HOOKS:
        owner = importlib.import_module(module)
        *path, name = attribute.split(".")
        for part in path:
            owner = getattr(owner, part)
        setattr(owner, name, clock.wrap(stage, getattr(owner, name)))
    status = main(["run", study, "--out", out, "--report", "light"])
    clock.leave()
    assert status == 0, status
    print(json.dumps({"seconds": clock.seconds, "process_seconds": time.perf_counter() - START,
                      "cpu_seconds": time.process_time()}))


def stages(study: Path, out: Path) -> dict:
    shutil.rmtree(out, ignore_errors=True)
    timed = child("--stages-child", study, out)
    targets = json.loads((out / "summary.json").read_text())["map"]["count"]
    seconds = dict(sorted(timed["seconds"].items(), key=lambda item: -item[1]))
    return {"targets": targets, "process_seconds": timed["process_seconds"], "cpu_seconds": timed["cpu_seconds"],
            "seconds": seconds, "us_per_target": {name: s / targets * 1e6 for name, s in seconds.items()}}


# --- where a directional map spends its time: cProfile of one in-process run ---------------------------------------

def profiled(stats, function: str, caller: str | None = None) -> float:
    """Cumulative seconds in ``function`` (a function's name, in any module, or a built-in method's whose name holds
    it), in all or (``caller``, a function of maps/expected_figures.py) from that caller only, from ``pstats``
    ``stats``."""
    def ours(key, name):
        return key[0].replace(os.sep, "/").endswith("maps/expected_figures.py") and key[2] == name
    total = 0.0
    for key, (_, _, _, cumulative, callers) in stats.stats.items():
        if not (key[2] == function or (key[0] == "~" and function in key[2])):
            continue
        if caller is None:
            total += cumulative
        else:
            total += sum(entry[3] for who, entry in callers.items() if ours(who, caller))
    return total


def profile_child(study: str, out: str) -> None:
    """In a child process: ``tribokin run study --out out --report light --workers 1`` in this process under
    cProfile; print where its directional figures' time went as one JSON line (seconds)."""
    import cProfile
    import pstats

    from tribokin.cli import main

    profiler = cProfile.Profile()
    start = time.perf_counter()
    profiler.enable()
    status = main(["run", study, "--out", out, "--report", "light", "--workers", "1"])
    profiler.disable()
    seconds = time.perf_counter() - start
    assert status == 0, status
    stats = pstats.Stats(profiler)
    multi = {"sign mixture's moments (_multi_moments)": profiled(stats, "_multi_moments", "_multi"),
             "cycles sampled (sampled_tests)": profiled(stats, "sampled_tests", "_multi"),
             "random numbers (numbers)": profiled(stats, "numbers", "_multi"),
             "RP_l from the cycles (cycle_moments)": profiled(stats, "repeatability", "_multi"),
             "sampled tests' RP_l (tests_rp_l)": profiled(stats, "tests_rp_l", "_multi"),
             "fast-engine fallbacks (engine_tests)": profiled(stats, "engine_tests", "_multi"),
             "first-order model (linear_model)": profiled(stats, "linear_model", "_multi")}
    multi["other"] = profiled(stats, "_multi") - sum(multi.values())
    vap_total = profiled(stats, "_vap")
    vap = {"expected distances (_vap_expected)": profiled(stats, "_vap_expected", "_vap"),
           "approach signs (approach_signs_from_jacobians)": profiled(stats, "approach_signs_from_jacobians", "_vap"),
           "fast-engine fallbacks (_vap_tests)": profiled(stats, "_vap_tests", "_vap")}
    vap["other (the barycentres through the mixed model; each direction's own models where it does not serve)"] = (
        vap_total - sum(vap.values()))
    expected = profiled(stats, "expected_targets")
    mixed = profiled(stats, "linear_model", "expected_targets")  # the test's model and the mixed (directional) one
    print(json.dumps({"command_s": seconds, "expected_figures_s": expected,
                      "first_order_models_in_expected_targets_s": mixed,
                      "RP_l_multi_s": profiled(stats, "_multi"), "RP_l_multi": multi,
                      "vAP_p_s": vap_total, "vAP_p": vap,
                      "rest_of_expected_figures_s": expected - profiled(stats, "_multi") - vap_total,
                      "rest_of_command_s": seconds - expected}))


def profile(study: Path, out: Path) -> dict:
    """Where a directional map's time goes (:func:`profile_child`), with shares of the whole command."""
    shutil.rmtree(out, ignore_errors=True)
    timed = child("--profile-child", study, out)
    summary = json.loads((out / "summary.json").read_text())["map"]
    shares = {name: timed[name] / timed["command_s"] for name in
              ("expected_figures_s", "RP_l_multi_s", "vAP_p_s", "rest_of_expected_figures_s", "rest_of_command_s")}
    return {"how": "cProfile of tribokin run --workers 1 --report light in one process (the views drawn by their own "
                   "process, waited for in the rest of the command); cumulative seconds of maps/expected_figures.py's "
                   "functions, RP_l_multi's and vAP_p's parts by caller",
            "resolution": summary["shape"][1:], "cycles": summary["cycles"], "targets": summary["count"],
            "reachable": summary["reachable"], "directional": summary["directional"], **timed,
            "shares_of_command": shares}


# --- a 10^6-target map's computation on 2 workers ----------------------------------------------------------------

def computed_child(study: str, workers: int) -> None:
    """In a child process: ``run_study`` of ``study`` on ``workers`` local processes, timed after the imports (the
    robot read once before, as the command's imports do); print its seconds as one JSON line."""
    from tribokin import run_study
    from tribokin.execution import executor_for
    from tribokin.study.assembly import load_robot
    from tribokin.study.reading import load_study

    load_robot(load_study(study))  # imports done, meshes read (as the command's first steps)
    with executor_for(workers) as executor:
        start = time.perf_counter()
        result = run_study(study, executor=executor)
        seconds = time.perf_counter() - start
    print(json.dumps({"seconds": seconds, "targets": result.map.grid.size,
                      "reachable": int(result.map.reachable.sum())}))


# --- memory -----------------------------------------------------------------------------------------------------

def status_mib(field: str) -> float:
    """``field`` of /proc/self/status (``VmRSS``: resident memory now, ``VmHWM``: its peak) [MiB] (Linux)."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith(field + ":"):
            return int(line.split()[1]) / 1024
    raise KeyError(field)


def memory_child(study: str) -> None:
    """In a child process: run and write ``study`` as ``tribokin run`` does (results, tables, heat maps and the light
    report; 1 worker) and print how far the resident memory rose above its level before [MiB]: the peak the kernel
    recorded (VmHWM), and sampled every 10 ms."""
    from tribokin import run_study
    from tribokin.maps.store import chunk_folder
    from tribokin.output.writers import write_results
    from tribokin.study.assembly import load_robot
    from tribokin.study.reading import load_study

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
    shutil.rmtree(out.parent, ignore_errors=True)
    print(json.dumps({"targets": summary["count"], "reachable": summary["reachable"], "csv_rows": csv_rows,
                      "cycles": summary["cycles"], "seconds": seconds, "rss_before_MiB": baseline,
                      "peak_rss_growth_MiB": max(peak[0], status_mib("VmHWM")) - baseline,
                      "sampled_peak_growth_MiB": peak[0] - baseline}))


# --- the run ----------------------------------------------------------------------------------------------------

def same_table(a: Path, b: Path) -> bool:
    return (a / "map.csv").read_bytes() == (b / "map.csv").read_bytes()


#: Configurations [rad] that differ by more than this are taken to be other IK solutions (the IK's tolerance).
SAME_CONFIGURATION_RAD = 1e-9
#: The map figures compared between the kernel paths.
COMPARED_FIGURES = ("RP_l_um", "RP_l_lo_um", "RP_l_hi_um", "AP_p_um", "RP_a_mdeg", "RP_b_mdeg", "RP_c_mdeg",
                    "largest_semi_axis_um", "dominant_share")


def path_agreement(compiled: Path, numpy_path: Path, row_length: int) -> dict:
    """How the map.csv of the compiled path (folder ``compiled``) and the NumPy path's differ: targets reachable on
    one path only, reachable targets whose configurations differ by more than ``SAME_CONFIGURATION_RAD`` (another
    IK solution) and the grid rows they lie in, and elsewhere the largest configuration difference [rad] and
    relative difference of a figure (``COMPARED_FIGURES``) and whether any dominant joint differs."""
    def rows(folder):
        with open(folder / "map.csv", newline="") as handle:
            yield from csv.DictReader(line for line in handle if not line.startswith("#"))
    reach_differs, moved, moved_rows, dominant_differs, q_max, figure_max = 0, 0, set(), 0, 0.0, 0.0
    for index, (a, b) in enumerate(zip(rows(compiled), rows(numpy_path), strict=True)):
        if a["reachable"] != b["reachable"]:
            reach_differs += 1
        if a["reachable"] != "true" or b["reachable"] != "true":
            continue
        q_difference = max(abs(float(a[k]) - float(b[k])) for k in a if k.startswith("q_"))
        if q_difference > SAME_CONFIGURATION_RAD:
            moved += 1
            moved_rows.add(index // row_length)
            continue
        q_max = max(q_max, q_difference)
        dominant_differs += a["dominant_joint"] != b["dominant_joint"]
        figure_max = max([figure_max] + [abs(float(a[f]) / float(b[f]) - 1) for f in COMPARED_FIGURES
                                          if float(b[f]) != 0])
    return {"reachable_on_one_path_only": reach_differs, "other_configurations": moved,
            "rows_with_other_configurations": len(moved_rows), "largest_configuration_difference_rad": q_max,
            "largest_relative_figure_difference": figure_max, "dominant_joint_differs": dominant_differs}


@dataclass(frozen=True)
class Sizes:
    """The maps of one run: sides of the big plane, the one-test plane, the 10^6-target plane, the directional runs'
    plane (their repeats) and the profiled plane; cycles; the memory runs' planes; the FK loop's samples."""

    side: int
    cycles: int
    one_test_side: int
    million_side: int
    memory_sides: list[tuple[int, int]]
    fk_samples: int
    directional_side: int
    directional_repeats: int
    profile_side: int


def directional_only(side: int, cycles: int, repeats: int, profile_side: int) -> dict:
    """The directional section alone (:func:`directional_cost` and :func:`profile`), with the machine's processor and
    load: what deliverable 6's goal (the directional figures at most 1.5x the map without them) is judged on."""
    folder = Path(tempfile.mkdtemp(prefix="tribokin-bench-"))
    try:
        load_before = os.getloadavg()
        command(write_study(folder, 3, 3, cycles), folder / "warm-up")  # files read and kernels compiled once
        directional = directional_cost(folder, side, cycles, repeats, 200_000)
        directional["profile"] = profile(write_study(folder, profile_side, profile_side, cycles, directional=True),
                                         folder / "profile")
        return {"machine": {"python": platform.python_version(), "cpus": os.cpu_count(), "cpu": cpu(),
                            "load_average": {"before": load_before[0], "after": os.getloadavg()[0]}},
                "directional": directional,
                "goal_cost_at_most_1_5": directional["cost_ratio"]["median"] <= GOAL_DIRECTIONAL_COST,
                "benchmark_seconds": time.perf_counter() - START}
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def benchmark(sizes: Sizes, quick: bool) -> dict:
    folder = Path(tempfile.mkdtemp(prefix="tribokin-bench-"))
    try:
        return measure(folder, sizes, quick)
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def measure(folder: Path, sizes: Sizes, quick: bool) -> dict:
    side, cycles, one_test_side, million_side = sizes.side, sizes.cycles, sizes.one_test_side, sizes.million_side
    memory_sides, fk_samples = sizes.memory_sides, sizes.fk_samples
    load_before = os.getloadavg()
    tiny = write_study(folder, 3, 3, cycles)
    command(tiny, folder / "warm-up", kernels="numpy")  # the files read once, into the page cache
    kernels = compile_times(tiny, folder)
    big = write_study(folder, side, side, cycles)
    serial = rates(command(big, folder / "one-worker", repeats=PLANE_REPEATS), cycles)
    two = rates(command(big, folder / "two-workers", workers=2, repeats=PLANE_REPEATS, loop_samples=fk_samples), cycles)
    identical = same_table(folder / "one-worker", folder / "two-workers")
    two_numpy = rates(command(big, folder / "two-workers-numpy", workers=2, kernels="numpy", repeats=PLANE_REPEATS),
                      cycles)
    kernels.update({"numpy_two_workers": two_numpy,
                    "compiled_over_numpy_two_workers": two_numpy["seconds"] / two["seconds"],
                    "map_csv_against_numpy": path_agreement(folder / "two-workers", folder / "two-workers-numpy",
                                                            side)})
    loop_s = fk_loop_seconds_per_sample(fk_samples)
    loop_rate = 1 / loop_s

    small = write_study(folder, one_test_side, one_test_side, cycles)
    one_test = rates(command(write_study(folder, one_test_side, one_test_side, cycles, "one-test"),
                             folder / "one-test", workers=2), cycles)
    expected_small = rates(command(small, folder / "expected-small", workers=2), cycles)
    one_test_scaled_s = one_test["seconds"] / one_test["reachable"] * two["reachable"]

    stage_run = stages(big, folder / "stages")
    million_study = write_study(folder, million_side, million_side, cycles)
    million_computed = child("--computed-child", million_study, 2)
    million_command = command(million_study, folder / "million", workers=2)
    million_numpy = command(million_study, folder / "million-numpy", workers=2, kernels="numpy")
    kernels.update({"numpy_million_command_s": million_numpy["seconds"],
                    "compiled_over_numpy_million": million_numpy["seconds"] / million_command["seconds"]})
    directional = directional_cost(folder, sizes.directional_side, cycles, sizes.directional_repeats, fk_samples)
    directional["profile"] = profile(write_study(folder, sizes.profile_side, sizes.profile_side, cycles,
                                                 directional=True), folder / "profile")
    memory = [child("--memory-child", write_study(folder, u, v, cycles)) for u, v in memory_sides]
    growth = ((memory[-1]["peak_rss_growth_MiB"] - memory[-2]["peak_rss_growth_MiB"]) * 2**20
              / (memory[-1]["targets"] - memory[-2]["targets"]))

    results = {
        "machine": {"python": platform.python_version(), "cpus": os.cpu_count(), "platform": platform.platform(),
                    "cpu": cpu(),
                    "OPENBLAS_NUM_THREADS": os.environ.get("OPENBLAS_NUM_THREADS"),
                    "load_average": {"before": load_before[0], "after": os.getloadavg()[0]}},
        "quick": quick,
        "map": {"study": str(STUDY.relative_to(ROOT)), "statistic": "expected", "resolution": [side, side],
                "cycles": cycles, "targets": serial["targets"], "reachable": serial["reachable"],
                "report": "light"},
        "command": {"one_worker": serial, "two_workers": two, "speed_up": serial["seconds"] / two["seconds"],
                    "identical_map_csv": identical},
        "kernels": kernels,
        "fk_loop": {"seconds_per_sample": loop_s, "samples_per_s": loop_rate,
                    "series": two["series"], "equivalent_seconds": two["reachable"] * cycles * two["series"] * loop_s,
                    "one_worker_over_loop": serial["target_cycles_per_s"] * serial["series"] / loop_rate,
                    "two_workers_over_loop": two["target_cycles_per_s"] * two["series"] / loop_rate,
                    "paired": paired_ratios(two, cycles)},
        "one_test": {"resolution": [one_test_side, one_test_side], "workers": 2, "run": one_test,
                     "expected_same_plane": expected_small,
                     "one_test_over_expected_same_plane": one_test["seconds"] / expected_small["seconds"],
                     "scaled": {"how": f"one-test seconds per reachable target on {one_test_side} x {one_test_side} "
                                       f"times the {side} x {side} plane's reachable targets (not run there: it "
                                       f"would take minutes)",
                                "one_test_seconds": one_test_scaled_s,
                                "one_test_over_expected": one_test_scaled_s / two["seconds"]}},
        "directional": directional,
        "stages": stage_run,
        "million": {"resolution": [million_side, million_side], "cycles": cycles, "workers": 2,
                    "targets": million_command["targets"], "reachable": million_command["reachable"],
                    "computed_s": million_computed["seconds"], "command_s": million_command["seconds"]},
        "memory": memory,
        "memory_growth_per_target_B": growth,
    }
    million_measured = million_command["targets"] >= 10**6
    results["goals"] = {
        "100x_fk_loop_two_workers": results["fk_loop"]["paired"]["median_ratio"] >= GOAL_FK_RATIO,
        "100x_fk_loop_two_workers_directional": directional["on_over_loop"] >= GOAL_FK_RATIO,
        "million_computed_under_10_s": million_computed["seconds"] < GOAL_MILLION_COMPUTED_S if million_measured
        else None,
        "million_command_under_20_s": million_command["seconds"] < GOAL_MILLION_COMMAND_S if million_measured else None,
        "memory_independent_of_targets": growth < GOAL_GROWTH_B,
        "two_workers_same_map_csv": identical,
        "compiled_kernels_double_the_plane_command": kernels["compiled_over_numpy_two_workers"] >= 2,
        "compiled_kernels_double_the_million_command": kernels["compiled_over_numpy_million"] >= 2,
    }
    return results


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--side", type=int, default=600, help="targets per side of the plane (default 600)")
    parser.add_argument("--cycles", type=int, default=1000, help="cycles per target (default 1000)")
    parser.add_argument("--one-test-side", type=int, default=200,
                        help="targets per side of the one-test map's plane (default 200)")
    parser.add_argument("--directional-side", type=int,
                        help="targets per side of the plane run with and without directional figures (default "
                             "--side)")
    parser.add_argument("--directional-repeats", type=int, default=2,
                        help="runs with and without directional figures, in turn (default 2)")
    parser.add_argument("--profile-side", type=int, default=150,
                        help="targets per side of the directional map profiled (default 150)")
    parser.add_argument("--quick", action="store_true",
                        help="a small run (120 x 120, one-test 60 x 60, 10^5 targets for the million, memory at "
                             "10^4, 4·10^4 and 8·10^4 targets, directional 60 x 60 once, profiled 40 x 40); printed, "
                             "written only with --results")
    parser.add_argument("--directional-only", action="store_true",
                        help="only the directional runs and their profile (the --directional-side plane, default "
                             "--side), written to --results or " + str(DIRECTIONAL_RESULTS.relative_to(ROOT)))
    parser.add_argument("--results", type=Path, help=f"where to write the JSON (default {RESULTS.relative_to(ROOT)})")
    parser.add_argument("--memory-child", help=argparse.SUPPRESS)
    parser.add_argument("--stages-child", nargs=2, help=argparse.SUPPRESS)
    parser.add_argument("--computed-child", nargs=2, help=argparse.SUPPRESS)
    parser.add_argument("--profile-child", nargs=2, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.memory_child:
        return memory_child(args.memory_child)
    if args.stages_child:
        return stages_child(*args.stages_child)
    if args.computed_child:
        return computed_child(args.computed_child[0], int(args.computed_child[1]))
    if args.profile_child:
        return profile_child(*args.profile_child)

    compileall.compile_dir(ROOT / "src", quiet=1)  # as installing tribokin does: see the module's last paragraph
    os.environ[NUMBA_CACHE_VARIABLE] = tempfile.mkdtemp(prefix="tribokin-bench-numba-")
    try:
        if args.directional_only:
            results = directional_only(args.directional_side or args.side, args.cycles, args.directional_repeats,
                                       args.profile_side)
            path = args.results or DIRECTIONAL_RESULTS
            path.write_text(json.dumps(results, indent=2) + "\n")
            print(json.dumps(results, indent=2))
            return
        if args.quick:
            sizes = Sizes(120, args.cycles, 60, 316, [(100, 100), (200, 200), (200, 400)], 20_000, 60, 1, 40)
        else:
            sizes = Sizes(args.side, args.cycles, args.one_test_side, 1000, [(100, 100), (1000, 1000), (1000, 2000)],
                          200_000, args.directional_side or args.side, args.directional_repeats, args.profile_side)
        results = benchmark(sizes, quick=args.quick)
    finally:
        shutil.rmtree(numba_cache(), ignore_errors=True)
    results["benchmark_seconds"] = time.perf_counter() - START
    path = args.results or (None if args.quick else RESULTS)
    if path is not None:
        path.parent.mkdir(exist_ok=True)
        path.write_text(json.dumps(results, indent=2) + "\n")
    print(json.dumps(results, indent=2))


if __name__ == "__main__":
    main()
