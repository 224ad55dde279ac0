"""`tribokin fit-friction` and `tribokin surface`: outputs (bad input: test_bad_input.py)."""

import json

import pytest

from conftest import ROOT
from helpers.command import in_process, tribokin

LOG = ROOT / "studies/data/tribometer-42CD4-treated-150N.csv"
PROFILE = ROOT / "src/tribokin/data/profiles/intermediate.csv"


def test_fit_friction_writes_law_usable_by_a_study(tmp_path):
    out = tmp_path / "fit"
    done = tribokin("fit-friction", LOG, "--out", out)
    assert done.returncode == 0, done.stderr
    assert 'chosen: friction = { law = "gaussian"' in done.stdout
    report = json.loads((out / "fit.json").read_text())
    assert report["chosen"] == "gaussian" and {f["law"] for f in report["fits"]} == {"gaussian", "lognormal", "uniform"}
    assert report["mean"] == pytest.approx(0.1375, abs=0.001)
    # the shipped log's cycles are independent (Ljung-Box) after a running-in from 0.1375 + 0.04·e^(−1/60) over 60
    assert "consistent with independent cycles" in done.stdout and report["ljung_box"]["independent"]
    assert set(report["time_keys"]) == {"run_in"} and "run_in = { start = 0.17" in report["inline"]
    assert report["run_in_fit"]["tau_cycles"]["low"] <= 60 <= report["run_in_fit"]["tau_cycles"]["high"]
    for png in ("mu_cycles.png", "mu_histogram.png"):
        assert (out / png).stat().st_size > 10_000
    study = tmp_path / "study.toml"
    text = (ROOT / "studies/tribology-log.toml").read_text()
    study.write_text(text.replace('{ log = "data/tribometer-42CD4-treated-150N.csv" }', '{ file = "fit/law.toml" }')
                     .replace("../urdf", str(ROOT / "urdf")))
    done = in_process("run", study, "--out", tmp_path / "run")
    assert done.returncode == 0, done.stderr
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert summary["study"]["friction"]["x"]["law"] == "gaussian"


def test_running_in_override_and_force(tmp_path):
    out = tmp_path / "fit"
    assert in_process("fit-friction", LOG, "--out", out, "--running-in", 300).returncode == 0
    assert json.loads((out / "fit.json").read_text())["running_in_cycles"] == 300
    assert in_process("fit-friction", LOG, "--out", out).returncode == 2
    assert in_process("fit-friction", LOG, "--out", out, "--force").returncode == 0


def test_surface_writes_summary_and_figures(tmp_path):
    out = tmp_path / "s"
    done = in_process("surface", PROFILE, "--out", out, "--z-range-m", 0, 1e-5)
    assert done.returncode == 0, done.stderr
    report = json.loads((out / "surface.json").read_text())
    assert report["summit_density_m2"] == pytest.approx(1.2 / report["AR_m"] ** 2)
    assert 0 < report["asperity_count"]["count"] < report["summit_density_m2"] * 1e-6
    for png in ("profile.png", "p_z_R.png"):
        assert (out / png).stat().st_size > 10_000
