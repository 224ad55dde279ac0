"""The scripts in examples/ run (each as ``__main__`` in this process, from an empty folder) and print honest numbers:
each printed figure is checked against the same computation made another way (a study file's run, a closed form, the
file the script wrote)."""

from __future__ import annotations

import io
import re
import runpy
from contextlib import redirect_stdout

import numpy as np
import pandas as pd
import pytest

import tribokin
from conftest import ROOT
from tribokin.tribology import laws

EXAMPLES = ROOT / "examples"
URDF = str(ROOT / "urdf" / "cartesian_xyz.urdf")
GANTRY = {"robot": {"urdf": URDF, "tool_frame": "tool", "payload_kg": 5.0},
          "joints": {"friction": {"preset": "42CD4-raw"}, "stiffness": 2.0e7, "bearing_span_m": 0.2}}


def run_example(name: str, folder) -> str:
    """The printed output of ``examples/<name>``, run as ``__main__`` with ``folder`` as its current folder (in this
    process: a new interpreter's imports would cost more than most examples). The registry of friction laws is the
    example's own copy: a law it defines (custom_friction_law.py's) is gone after it, as after a process of its own."""
    printed = io.StringIO()
    with pytest.MonkeyPatch.context() as patch, redirect_stdout(printed):
        patch.chdir(folder)
        patch.setattr(laws, "LAWS", dict(laws.LAWS))
        runpy.run_path(str(EXAMPLES / name), run_name="__main__")
    return printed.getvalue()


def numbers(pattern: str, text: str) -> list[tuple[str, ...]]:
    """Every match of ``pattern`` in ``text`` (its groups), at least one."""
    found = re.findall(pattern, text)
    assert found, f"{pattern!r} not in {text!r}"
    return found


def test_every_example_is_run_here():
    tested = set(re.findall(r'run_example\("([\w.]+)"', (ROOT / "tests" / "test_examples.py").read_text()))
    assert tested == {path.name for path in EXAMPLES.glob("*.py")}


def test_a_pose_from_python_prints_the_figures_a_study_file_gives(tmp_path):
    printed = run_example("pose_iso_test.py", tmp_path)
    study = {"study": {"name": "pose", "cycles": 30, "seed": 7, "approach": "bidirectional"}, **GANTRY,
             "joints": {**GANTRY["joints"], "z": {"friction": {"preset": "42CD4-treated"}}},
             "poses": [{"name": "P", "q": [0.3, 0.2, 0.1]}]}
    row = tribokin.run_study(study, meshes=False).poses[0].report_row()
    shown = {label: (float(rp), float(ap)) for label, rp, ap in
             numbers(r"approach (\S+): RP_l = ([\d.]+) um, AP_p = ([\d.]+) um", printed)}
    assert shown == {label: (round(d["RP_l_um"], 3), round(d["AP_p_um"], 3)) for label, d in row["directions"].items()}
    assert float(numbers(r"both directions: ([\d.]+) um", printed)[0]) == round(row["RP_l_all_directions_um"], 3)


def test_a_map_with_scenarios_prints_the_medians_a_study_file_gives_and_rp_l_scales_as_one_over_stiffness(tmp_path):
    printed = run_example("workspace_map.py", tmp_path)
    study = {"study": {"name": "map", "cycles": 30, "seed": 1}, **GANTRY,
             "map": {"kind": "box", "min_m": [0.2, 0.0, 0.2], "max_m": [0.8, 0.6, 0.7], "resolution": [4, 4, 2]},
             "scenarios": [{"name": "raw"}, {"name": "treated", "joints": {"friction": {"preset": "42CD4-treated"}}},
                           {"name": "stiff", "joints": {"stiffness": 2.0e8}}]}
    summary = tribokin.run_study(study, meshes=False).map.summary()
    medians = {s["name"]: round(s["RP_l_um"]["median"], 3) for s in summary["scenarios"]}
    assert {name: float(m) for name, m in numbers(r"(\w+): median RP_l = ([\d.]+) um", printed)} == medians
    low, high = numbers(r"stiff / raw: RP_l ratio ([\d.]+) to ([\d.]+)", printed)[0]
    assert float(low) == float(high) == 0.1  # the lost motion τ/k: ten times k, a tenth of it


def test_a_friction_law_of_one_s_own_has_the_triangular_law_s_moments(tmp_path):
    printed = run_example("custom_friction_law.py", tmp_path)
    low, mode, high = 0.08, 0.10, 0.16
    mean = (low + mode + high) / 3
    std = np.sqrt((low**2 + mode**2 + high**2 - low * mode - low * high - mode * high) / 18)
    law_mean, law_std = numbers(r"mean mu = ([\d.]+), std = ([\d.]+)", printed)[0]
    assert (float(law_mean), float(law_std)) == (round(mean, 4), round(std, 4))
    drawn_mean, drawn_std = numbers(r"cycles: mean ([\d.]+), std ([\d.]+)", printed)[0]
    assert abs(float(drawn_mean) - mean) < 4 * std / np.sqrt(200)  # 200 draws
    assert abs(float(drawn_std) / std - 1) < 0.2
    rp_l = dict(numbers(r"x guide (\w+): RP_l = ([\d.]+) um", printed))
    assert float(rp_l["triangular"]) != float(rp_l["preset"]) > 0


def test_a_calibration_from_arrays_brackets_the_truth(tmp_path):
    printed = run_example("calibration_from_arrays.py", tmp_path)
    assert "converged: True" in printed and "not identifiable" not in printed
    truth = {"shoulder.stiffness": 4.0e4, "elbow.stiffness": 2.0e4, "wrist.stiffness": 8.0e3,
             "shoulder.backlash": 2e-5, "elbow.backlash": 3e-5, "wrist.backlash": 4e-5}
    shown = {name: tuple(map(float, values)) for name, *values in
             numbers(r"joints\.(\w+\.\w+): (\S+) \S+, 95 % interval \[(\S+), (\S+)\]", printed)}
    assert set(shown) == set(truth)
    for name, (value, low, high) in shown.items():
        assert low <= truth[name] <= high and low <= value <= high, name
    for joint in ("shoulder", "elbow", "wrist"):  # the stiffnesses within 10 %
        assert abs(shown[f"{joint}.stiffness"][0] / truth[f"{joint}.stiffness"] - 1) < 0.1


def test_a_map_to_xarray_and_parquet_prints_the_numbers_of_the_file_it_wrote(tmp_path):
    printed = run_example("map_to_xarray_parquet.py", tmp_path)
    table = pd.read_parquet(tmp_path / "map.parquet")
    assert numbers(r"dims \('scenario', 'v', 'u'\), shape \((\d+), (\d+), (\d+)\)", printed) == [("2", "4", "6")]
    medians = dict(numbers(r"(raw|treated) ([\d.]+) um", printed))
    for name, median in medians.items():
        assert float(median) == round(float(np.nanmedian(table.loc[table["scenario"] == name, "RP_l_um"])), 3)
    raw = table[table["scenario"] == "raw"]
    by_v = raw.groupby(raw["v_m"].round(6))["RP_l_um"].mean()
    assert [float(v) for _, v in numbers(r"v = ([\d.]+) m: ([\d.]+)", printed)] == [round(x, 3) for x in by_v]
    assert "same numbers as the Dataset: True" in printed


def test_placement_prints_the_ranking_and_the_best_base_s_p95_is_that_of_the_tray_mapped_from_it(tmp_path):
    """The best candidate's p95 RP_l equals numpy's percentile of a plain map of the tray with the base set there."""
    printed = run_example("placement.py", tmp_path)
    ranked = [(tuple(map(float, xyz.split(", "))), float(yaw), float(p95)) for xyz, yaw, p95 in
              numbers(r"#\d: base at \(([^)]*)\) m, yaw (\S+) deg: p95 RP_l = ([\d.]+) um over 9 targets", printed)]
    assert len(ranked) == 3 and [r[2] for r in ranked] == sorted(r[2] for r in ranked)
    (x, y, z), yaw, p95 = ranked[0]
    study = {"study": {"name": "tray", "cycles": 30, "seed": 9283},
             "robot": {**GANTRY["robot"], "base_xyz_m": [x, y, z], "base_rpy_deg": [0.0, 0.0, yaw]},
             "joints": GANTRY["joints"],
             "map": {"kind": "plane", "origin_m": [0.5, 0.3, 0.4], "axis_u": [1, 0, 0], "axis_v": [0, 1, 0],
                     "extent_u_m": [0.0, 0.2], "extent_v_m": [0.0, 0.2], "resolution": [3, 3]}}
    rp_l = next(iter(tribokin.run_study(study, meshes=False).map.scenarios.values())).figure("RP_l_um")
    assert np.isfinite(rp_l).all() and p95 == round(float(np.percentile(rp_l, 95)), 3)
