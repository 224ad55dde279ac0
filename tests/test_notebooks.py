"""The notebooks in examples/ run top to bottom on a Jupyter kernel (nbclient) from their own folder, as Jupyter runs
them, show what they say (the 3-D scene as HTML, figures as PNG) and print figures that an independent computation
gives: a study file's run of the same pose; the ISO formula applied to the measurement file's rows."""

from __future__ import annotations

import html
import re

import nbformat
import numpy as np
import pandas as pd
import pytest
from nbclient import NotebookClient

import tribokin
from conftest import ROOT
from tribokin.viz.static import viewer_js

EXAMPLES = ROOT / "examples"


def executed(name: str) -> list[dict]:
    """The outputs of every code cell of ``examples/<name>`` run on a fresh kernel in ``examples/`` (the notebooks
    are kept without outputs)."""
    notebook = nbformat.read(EXAMPLES / name, as_version=4)
    assert all(not cell.get("outputs") and cell.get("execution_count") is None
               for cell in notebook.cells if cell.cell_type == "code")
    NotebookClient(notebook, timeout=120, kernel_name="python3",
                   resources={"metadata": {"path": str(EXAMPLES)}}).execute()
    return [output for cell in notebook.cells if cell.cell_type == "code" for output in cell.outputs]


def printed(outputs: list[dict]) -> str:
    return "".join(output["text"] for output in outputs if output["output_type"] == "stream")


def shown(outputs: list[dict], mime: str) -> list[str]:
    return [output["data"][mime] for output in outputs if mime in output.get("data", {})]


@pytest.fixture(scope="module")
def pose_and_map():
    return executed("pose_and_map.ipynb")


def test_the_pose_notebook_prints_the_figures_a_study_file_gives(pose_and_map):
    study = {"study": {"name": "pose", "cycles": 30, "seed": 7, "approach": "bidirectional"},
             "robot": {"urdf": str(ROOT / "urdf" / "cartesian_xyz.urdf"), "tool_frame": "tool", "payload_kg": 5.0},
             "joints": {"friction": {"preset": "42CD4-raw"}, "stiffness": 2.0e7, "bearing_span_m": 0.2,
                        "z": {"friction": {"preset": "42CD4-treated"}}},
             "poses": [{"name": "P", "q": [0.3, 0.2, 0.1]}]}
    directions = tribokin.run_study(study, meshes=False).poses[0].report_row()["directions"]
    found = re.findall(r"approach (\S+): RP_l = ([\d.]+) um, AP_p = ([\d.]+) um", printed(pose_and_map))
    assert {label: (float(rp), float(ap)) for label, rp, ap in found} == {
        label: (round(d["RP_l_um"], 3), round(d["AP_p_um"], 3)) for label, d in directions.items()}


def test_the_pose_notebook_shows_the_scenes_inline_and_the_figures_as_png(pose_and_map):
    scenes = [html for html in shown(pose_and_map, "text/html") if html.startswith('<iframe title="3-D scene"')]
    assert len(scenes) == 2  # the pose's and the map's
    for scene in scenes:  # the page inside the frame, meshcat's viewer in it: nothing to fetch, no server
        page = html.unescape(re.fullmatch(r'<iframe [^>]*srcdoc="([^"]*)"></iframe>', scene)[1])
        assert page.startswith("<!DOCTYPE html>") and viewer_js() in page
    assert len(shown(pose_and_map, "image/png")) == 2  # the pose's field, the map's ratio
    medians = dict(re.findall(r"(raw|treated): median RP_l = ([\d.]+) um", printed(pose_and_map)))
    assert 0 < float(medians["treated"]) < float(medians["raw"])


def test_the_tracker_notebook_prints_the_iso_figures_of_the_file_s_rows_and_a_fit_bracketing_the_truth():
    outputs = executed("tracker_calibration.ipynb")
    text = printed(outputs)
    rows = pd.read_csv(ROOT / "studies" / "data" / "ur5-tracker.csv", comment="#")
    found = [(line.split(":")[0], direction, value) for line in text.splitlines() if re.match(r"P\d: ", line)
             for direction, value in re.findall(r"(\S+) RP_l = ([\d.]+) um", line)]
    assert len(found) == 15  # 5 poses x 3 directions
    for pose, direction, value in found:
        points = rows.loc[(rows["pose"] == pose) & (rows["direction"] == direction), ["x_m", "y_m", "z_m"]].to_numpy()
        distances = np.linalg.norm(points - points.mean(axis=0), axis=1)  # a rotation and shift keep them
        assert abs(float(value) - 1e6 * (distances.mean() + 3 * distances.std(ddof=1))) < 1.5e-3, (pose, direction)
    truth = {"shoulder_pan_joint": 6e4, "shoulder_lift_joint": 3.5e4, "elbow_joint": 5e4, "wrist_1_joint": 1.2e4}
    fitted = {name: (float(low), float(high)) for name, low, high in
              re.findall(r"joints\.(\w+)\.stiffness: \S+ \S+, 95 % \[(\S+), (\S+)\]", text)}
    assert set(truth) <= set(fitted)
    assert all(fitted[name][0] <= value <= fitted[name][1] for name, value in truth.items())
    assert len(shown(outputs, "image/png")) == 1
