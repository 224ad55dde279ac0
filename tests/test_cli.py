"""The `tribokin` command: outputs, overrides, and one-line errors with nothing written."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from conftest import AXIS_URDF, STUDIES

STUDY = """
[study]
name = "cli"
cycles = 12
seed = 3

[robot]
urdf = "{urdf}"
tool_frame = "tool"

[joints]
friction = {{ preset = "42CD4-raw" }}
normal_force_N = 150.0
stiffness = 2.0e6

[[poses]]
name = "P1"
q = [0.25]
"""


def tribokin(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "tribokin", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd)


@pytest.fixture
def study_file(tmp_path):
    path = tmp_path / "study.toml"
    path.write_text(STUDY.format(urdf=AXIS_URDF))
    return path


def test_run_writes_every_output(study_file, tmp_path):
    out = tmp_path / "out"
    done = tribokin("run", study_file, "--out", out, "--cycles", 20, "--seed", 5)
    assert done.returncode == 0, done.stderr
    summary = json.loads((out / "summary.json").read_text())
    pose = summary["poses"][0]
    for key in ("name", "q", "cycles", "commanded_position_m", "barycenter_m", "AP_p_um", "RP_l_um", "AP_a_mdeg",
                "AP_b_mdeg", "AP_c_mdeg", "RP_a_mdeg", "RP_b_mdeg", "RP_c_mdeg", "vAP_p_um"):
        assert key in pose
    assert pose["cycles"] == 20 and summary["study"]["seed"] == 5
    assert pose["vAP_p_um"] is None
    samples = np.load(out / "samples.npz")
    assert samples["P1/positions_m"].shape == (20, 3)
    assert (out / "poses.csv").read_text().splitlines()[0].startswith("name,")
    assert (out / "field_P1.png").stat().st_size > 10_000
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temporary folder left


def test_existing_output_is_kept_without_force(study_file, tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "mine.txt").write_text("precious")
    done = tribokin("run", study_file, "--out", out)
    assert done.returncode == 2
    assert "--force" in done.stderr
    assert (out / "mine.txt").read_text() == "precious"
    assert tribokin("run", study_file, "--out", out, "--force").returncode == 0
    assert (out / "summary.json").exists() and not (out / "mine.txt").exists()


@pytest.mark.parametrize("edit, expected", [
    (lambda s: s.replace("stiffness = 2.0e6", "stiffness = -2.0e6"), "joints.stiffness"),
    (lambda s: s.replace('{ preset = "42CD4-raw" }', '{ law = "gaussian", mean = 0.1, std = -0.1 }'),
     "joints.friction.std"),
    (lambda s: s.replace('{ preset = "42CD4-raw" }', '{ law = "uniform", low = 0.2, high = 0.1 }'),
     "joints.friction.low"),
    (lambda s: s.replace('"42CD4-raw"', '"42CD4-rw"'), "joints.friction.preset"),
    (lambda s: s.replace("seed = 3", "seed = 3\nsede = 4"), "study.sede"),
    (lambda s: s.replace("q = [0.25]", "q = [0.25, 0.1]"), "poses[0].q"),
    (lambda s: s.replace("q = [0.25]", "q = [0.75]"), "poses[0].q"),
    (lambda s: s.replace("[study]", "[study"), "not valid TOML"),
])
def test_bad_study_one_line_exit_2_nothing_written(study_file, tmp_path, edit, expected):
    study_file.write_text(edit(study_file.read_text()))
    out = tmp_path / "out"
    done = tribokin("run", study_file, "--out", out)
    assert done.returncode == 2
    assert expected in done.stderr and str(study_file) in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 and "Traceback" not in done.stderr
    assert not out.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["study.toml"]


def test_missing_study_file(tmp_path):
    done = tribokin("run", tmp_path / "nope.toml", "--out", tmp_path / "out")
    assert done.returncode == 2 and "nope.toml" in done.stderr and "not found" in done.stderr
    assert not (tmp_path / "out").exists()


def test_bad_command_line_is_one_line():
    done = tribokin("run")
    assert done.returncode == 2 and len(done.stderr.strip().splitlines()) == 1


def test_shipped_paper_studies_run(tmp_path):
    for study in sorted(STUDIES.glob("paper-fig1*.toml")):
        done = tribokin("run", study, "--out", tmp_path / study.stem)
        assert done.returncode == 0, done.stderr
        summary = json.loads((tmp_path / study.stem / "summary.json").read_text())
        assert [p["name"] for p in summary["poses"]] == ["40N", "150N"]
