"""Where the time of ``tribokin calibrate`` goes, stage by stage, on the shipped examples.

Run from the repository root: ``OPENBLAS_NUM_THREADS=1 PYTHONPATH=src python benchmarks/calibrate.py``
(the examples: the synthetic UR5 data and Series D of the IPA UR10 data, both in ``studies/data``).
Writes ``benchmarks/results/calibrate.json`` and prints a table: seconds of each stage (reading and
assembling the inputs, the fit, the profile intervals, the predictions at the measured poses, the
leave-one-pose-out refits) and of the whole command with ``--report none``. One run each: the figures
are seconds of wall time on a possibly shared machine, and ratios between stages are what to read.
"""

from __future__ import annotations

import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from tribokin.calibration.cross_validation import leave_one_pose_out, predict_pose
from tribokin.calibration.fit import fit, profile_interval
from tribokin.measurement.contract import read_measurements
from tribokin.study.assembly import joint_models, load_robot
from tribokin.study.calibration_data import calibration_input
from tribokin.study.reading import read_study_file

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "benchmarks" / "results" / "calibrate.json"


def stages(study_path: Path, data_path: Path) -> dict:
    """Seconds of each stage of a calibration, and what was fitted."""
    seconds, start = {}, time.perf_counter()
    study = read_study_file(study_path)
    robot = load_robot(study)
    models = joint_models(study, robot)
    inputs = calibration_input(study, robot, models, read_measurements(data_path))
    seconds["inputs"] = time.perf_counter() - start
    frame = "registered" if inputs.registration is not None else "unknown"
    start = time.perf_counter()
    calibration = fit(inputs.model, inputs.poses, frame=frame)
    seconds["fit"] = time.perf_counter() - start
    start = time.perf_counter()
    for estimate in calibration.parameters:
        if estimate.identifiable:
            profile_interval(calibration, inputs.poses, estimate.name)
    seconds["profile intervals"] = time.perf_counter() - start
    start = time.perf_counter()
    for i, pose in enumerate(inputs.poses):
        predict_pose(calibration, pose, np.random.default_rng(i))
    seconds["predictions"] = time.perf_counter() - start
    start = time.perf_counter()
    leave_one_pose_out(inputs.model, inputs.poses, frame=frame)
    seconds["leave-one-pose-out"] = time.perf_counter() - start
    return {"poses": len(inputs.poses), "series": sum(len(p.series) for p in inputs.poses),
            "free_parameters": len(calibration.parameters),
            "identifiable": sum(e.identifiable for e in calibration.parameters), "seconds": seconds}


def whole_command(study_path: Path, data_path: Path, folder: Path) -> float:
    """Wall time [s] of ``tribokin calibrate ... --report none`` in a new process."""
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "tribokin", "calibrate", str(study_path), "--measurements", str(data_path),
                    "--out", str(folder / "fit"), "--report", "none"], check=True, capture_output=True)
    return time.perf_counter() - start


def main() -> None:
    results = {"machine": {"python": platform.python_version(), "processor": platform.machine(),
                           "cpus": os.cpu_count(), "load_average_1min": os.getloadavg()[0],
                           "OPENBLAS_NUM_THREADS": os.environ.get("OPENBLAS_NUM_THREADS")}, "examples": {}}
    with tempfile.TemporaryDirectory() as scratch:
        scratch = Path(scratch)
        examples = {"ur5-synthetic": (ROOT / "studies" / "ur5-calibrate.toml", ROOT / "studies" / "data" /
                                      "ur5-tracker.csv"),
                    "ipa-ur10": (ROOT / "studies" / "ur10-ipa-calibrate.toml", ROOT / "studies" / "data" /
                                 "ipa-ur10-series-d.csv")}
        for name, (study, data) in examples.items():
            entry = stages(study, data)
            (scratch / name).mkdir()
            entry["seconds"]["whole command (with the study's map, --report none)"] = whole_command(
                study, data, scratch / name)
            results["examples"][name] = entry
    RESULTS.write_text(json.dumps(results, indent=2) + "\n", encoding="utf-8")
    for name, entry in results["examples"].items():
        print(f"{name}: {entry['poses']} poses, {entry['series']} series, {entry['identifiable']} of "
              f"{entry['free_parameters']} parameters identifiable")
        for stage, value in entry["seconds"].items():
            print(f"  {stage:<55} {value:8.2f} s")


if __name__ == "__main__":
    main()
