"""The `tribokin` command: outputs, overrides, an existing output folder kept (bad input: test_bad_input.py)."""

import hashlib
import json
import platform
import re
from importlib import metadata

import numpy as np
import pinocchio
import pytest
import scipy

from conftest import AXIS_STUDY_TOML, STUDIES
from helpers.command import in_process, tribokin
from tribokin import __version__ as tribokin_version
from tribokin.compiled import kernels_used


@pytest.fixture
def study_file(tmp_path):
    path = tmp_path / "study.toml"
    path.write_text(AXIS_STUDY_TOML)
    return path


def test_run_writes_every_output(study_file, tmp_path):
    out = tmp_path / "out"
    done = tribokin("run", study_file, "--out", out, "--cycles", 20, "--seed", 5)
    assert done.returncode == 0, done.stderr
    table = done.stdout.splitlines()
    assert table[0].split()[:2] == ["pose", "direction"] and table[1].split()[:2] == ["P1", "+"]
    summary = json.loads((out / "summary.json").read_text())
    pose = summary["poses"][0]
    for key in ("name", "q", "cycles", "commanded_position_m", "vAP_p_um", "RP_l_all_directions_um"):
        assert key in pose
    for key in ("cycles", "barycenter_m", "AP_p_um", "RP_l_um", "AP_a_mdeg", "AP_b_mdeg", "AP_c_mdeg", "RP_a_mdeg",
                "RP_b_mdeg", "RP_c_mdeg"):
        assert key in pose["directions"]["+"]
    assert pose["cycles"] == 20 and summary["study"]["seed"] == 5
    reproduce = summary["reproduce"]
    assert reproduce["seed"] == 5 and reproduce["study_sha256"] == hashlib.sha256(study_file.read_bytes()).hexdigest()
    assert reproduce["command"] == ["tribokin", "run", str(study_file), "--out", str(out), "--cycles", "20",
                                    "--seed", "5"]
    assert reproduce["kernels"] == kernels_used()  # this environment's TRIBOKIN_KERNELS, passed on
    versions = reproduce["versions"]
    assert versions["tribokin"] == tribokin_version and versions["python"] == platform.python_version()
    assert versions["numpy"] == np.__version__ and versions["scipy"] == scipy.__version__
    assert versions["pinocchio"] == pinocchio.__version__ and versions["example-robot-data"]
    assert pose["vAP_p_um"] is None
    samples = np.load(out / "samples.npz")
    assert samples["P1/positions_m"].shape == (20, 3)
    assert (out / "poses.csv").read_text().splitlines()[0].startswith("name,direction,")
    assert "tool frame: tool (robot.tool_frame), moved by x\n" in done.stdout
    assert (out / "field_P1.png").stat().st_size > 10_000
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temporary folder left


def test_existing_output_is_kept_without_force(study_file, tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "mine.txt").write_text("precious")
    done = in_process("run", study_file, "--out", out)
    assert done.returncode == 2
    assert "--force" in done.stderr
    assert (out / "mine.txt").read_text() == "precious"
    assert in_process("run", study_file, "--out", out, "--force").returncode == 0
    assert (out / "summary.json").exists() and not (out / "mine.txt").exists()


def test_shipped_paper_studies_run(tmp_path):
    for study in sorted(STUDIES.glob("paper-fig1*.toml")):
        done = in_process("run", study, "--out", tmp_path / study.stem)
        assert done.returncode == 0, done.stderr
        summary = json.loads((tmp_path / study.stem / "summary.json").read_text())
        assert [p["name"] for p in summary["poses"]] == ["40N", "150N"]


def test_version_is_the_installed_distributions():
    done = tribokin("--version")
    assert done.returncode == 0 and done.stdout == f"tribokin {metadata.version('tribokin')}\n"
    assert tribokin_version == metadata.version("tribokin")


def test_bare_command_prints_usage_and_the_commands():
    done = tribokin()
    assert done.returncode == 2 and done.stdout == ""
    assert done.stderr.startswith("usage: tribokin ")
    for command in ("run", "view", "fit-friction", "surface", "robots"):
        assert re.search(rf"^    {command}\s", done.stderr, re.MULTILINE)


def test_robots_lists_a_robots_candidate_tool_frames_default_first():
    kinova = in_process("robots", "--frames", "kinova")
    assert kinova.returncode == 0, kinova.stderr
    lines = kinova.stdout.splitlines()
    assert lines[0].startswith("tool frames of kinova, with the joints that move each (* the default")
    assert lines[1].split() == ["*", "j2s6s200_end_effector", "6", "joints"]
    assert all(line.startswith("  ") for line in lines[2:]) and len(lines) > 3
    anymal = in_process("robots", "--frames", "anymal")
    assert anymal.returncode == 0 and anymal.stdout.startswith("no default tool frame: anymal has a floating base")
    assert "\n  LF_FOOT     3 joints\n" in anymal.stdout and "*" not in anymal.stdout
    unknown = in_process("robots", "--frames", "ur55")
    assert unknown.returncode == 2 and unknown.stdout == ""
    assert unknown.stderr.startswith("tribokin: error: command line: --frames: unknown robot 'ur55' (did you mean "
                                     "'ur5'?)") and unknown.stderr.count("\n") == 1


def test_run_of_a_map_comparing_two_states_prints_and_draws_the_changes(tmp_path):
    """A map whose joint's friction runs in, from new to 5 000 cycles of age: the changes printed (signed: run in,
    the lost motion falls), their columns in map.csv and their heat maps."""
    study = tmp_path / "study.toml"
    friction = '{ preset = "42CD4-raw", ar1 = 0.5, run_in = { start = 0.3, tau_cycles = 20 } }'
    study.write_text(AXIS_STUDY_TOML.replace('{ preset = "42CD4-raw" }', friction) + '\n[map]\nkind = "joint"\n'
                     'joints = ["x"]\nranges = [[0.1, 0.3]]\ncounts = [3]\ndirectional = false\n'
                     'state = { age_cycles = 0 }\ncompare = { age_cycles = 5000 }\n')
    done = in_process("run", study, "--out", tmp_path / "out", "--report", "none")
    assert done.returncode == 0, done.stderr
    line = next(line for line in done.stdout.splitlines() if line.startswith("change from map.state"))
    parts = line.split("RP_l ")[1].split("AP_p ")
    rp_l, ap_p = (np.array(part.split(",")[0].split(" / "), dtype=float) for part in parts)
    assert np.all(rp_l < 0) and np.all(ap_p < 0)
    rests_on = done.stdout.splitlines()[done.stdout.splitlines().index(line) + 1]  # what the changes rest on
    (computed,) = json.loads((tmp_path / "out" / "summary.json").read_text())["map"]["computed"].values()
    assert rests_on == ("  largest Monte Carlo standard error / engine bound [µm]: " + ", ".join(
        f"{stem} {computed[f'{stem}_change_max_mc_error_um']:.3g} / "
        f"{computed[f'{stem}_change_max_engine_bound_um']:.3g}" for stem in ("RP_l", "AP_p")))
    assert computed["RP_l_change_max_mc_error_um"] > 0
    header = (tmp_path / "out" / "map.csv").read_text().splitlines()[0].split(",")
    assert {"RP_l_change_um", "AP_p_change_um", "RP_l_change_mc_error_um", "AP_p_change_mc_error_um"} <= set(header)
    assert (tmp_path / "out" / "map_RP_l_change.png").stat().st_size > 10_000
    assert (tmp_path / "out" / "map_AP_p_change.png").stat().st_size > 10_000
