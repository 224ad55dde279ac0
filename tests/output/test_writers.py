"""The pose files' layout: poses.csv, summary.json and samples.npz agree."""

import csv
import json

import numpy as np

from conftest import axis_study
from tribokin import run_study
from tribokin.output.writers import write_results


def test_pose_files_hold_one_row_per_pose_and_approach_direction(tmp_path):
    """poses.csv: a row per pose and direction, joints by name, no bracketed columns, the figures across
    directions repeated on each row of a pose; summary.json: the same figures under ``directions``;
    samples.npz: every cycle with its direction."""
    study = axis_study(friction={"law": "uniform", "low": 0.1, "high": 0.2})
    study["study"]["approach"] = "bidirectional"
    study["poses"].append({"name": "P2", "q": [0.3]})
    result = run_study(study, cycles=10)
    out = write_results(result, tmp_path / "out", report="none")
    with open(out / "poses.csv", newline="", encoding="utf-8") as handle:
        rows = list(csv.DictReader(handle))
    joint = result.settings["joints"][0]
    assert [(row["name"], row["direction"], row["cycles"]) for row in rows] == [
        ("P1", "+", "10"), ("P1", "-", "10"), ("P2", "+", "10"), ("P2", "-", "10")]
    header = list(rows[0])
    assert not [column for column in header if "[" in column]
    for column in (f"q_{joint}", f"normal_force_{joint}_N", "barycenter_x_m", "RP_l_um", "AP_p_um", "RP_a_mdeg",
                   "vAP_p_um", "RP_l_all_directions_um", "RP_l_95_low_um", "RP_l_95_high_um",
                   "ellipsoid_semi_axis_1_um", f"contribution_{joint}"):
        assert column in header, column
    summary = json.loads((out / "summary.json").read_text())
    for row in rows:
        pose = next(p for p in summary["poses"] if p["name"] == row["name"])
        figures = pose["directions"][row["direction"]]
        assert float(row["RP_l_um"]) == figures["RP_l_um"] and float(row["AP_p_um"]) == figures["AP_p_um"]
        assert [float(row["RP_l_95_low_um"]), float(row["RP_l_95_high_um"])] == figures["RP_l_95_um"]
        assert float(row["vAP_p_um"]) == pose["vAP_p_um"]
        assert float(row["RP_l_all_directions_um"]) == pose["RP_l_all_directions_um"]
        assert float(row[f"q_{joint}"]) == pose["q"][0]
    with np.load(out / "samples.npz") as samples:
        assert samples["P1/positions_m"].shape == (20, 3)
        assert samples["P1/directions"].tolist() == ["+", "-"] and samples["P1/approach"].tolist() == [0, 1] * 10
