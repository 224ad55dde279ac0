"""Friction laws from files in study specs: law files, tribometer logs, surface profiles."""

import numpy as np
import pytest

from conftest import ROOT, axis_study
from tribokin.errors import InputError
from tribokin.run import run_study
from tribokin.tribology import Empirical, Gaussian, law_from_spec

PROFILES = ROOT / "src/tribokin/data/profiles"
SURFACE = {"normal_force_N": 150.0, "contact_area_m2": 1e-6, "film_thickness_m": 1.2e-6, "cycles": 300}


def test_file_kind_reads_a_law_relative_to_the_study(tmp_path):
    (tmp_path / "law.toml").write_text('# comment\nlaw = "gaussian"\nmean = 0.13\nstd = 0.01\n')
    law = law_from_spec({"file": "law.toml"}, "study.toml", "joints.friction", tmp_path)
    assert isinstance(law, Gaussian) and law.mean() == pytest.approx(0.13) and "law.toml" in law.provenance


def test_errors_inside_a_law_file_name_that_file(tmp_path):
    (tmp_path / "law.toml").write_text('law = "gaussian"\nmean = 0.13\nstd = -0.01\n')
    with pytest.raises(InputError) as error:
        law_from_spec({"file": "law.toml"}, "study.toml", "joints.friction", tmp_path)
    assert error.value.source.endswith("law.toml") and error.value.key == "std"
    with pytest.raises(InputError, match="joints.friction.file"):
        law_from_spec({"file": "nope.toml"}, "study.toml", "joints.friction", tmp_path)


def test_a_law_file_that_is_not_toml_is_located_not_quoted(tmp_path):
    (tmp_path / "law.toml").write_text('law = "constant"\nsecret_7f3a = 1\nsecret_7f3a = 2\n')
    with pytest.raises(InputError) as error:
        law_from_spec({"file": "law.toml"}, "study.toml", "joints.friction", tmp_path)
    assert "at line 3, column" in error.value.message and "secret_7f3a" not in error.value.one_line()


def test_files_out_of_the_roots_are_refused_and_roots_admit_them(tmp_path):
    study, logs = tmp_path / "study", tmp_path / "logs"
    study.mkdir()
    logs.mkdir()
    mu = np.full(40, 0.12) + np.linspace(0, 1e-3, 40)
    (logs / "log.csv").write_text("mu\n" + "\n".join(map(str, mu)) + "\n")
    (study / "law.toml").write_text('log = "../logs/log.csv"\nrunning_in = 0\n')
    with pytest.raises(InputError, match="joints.friction.log: .*outside the folders"):
        law_from_spec({"log": "../logs/log.csv"}, "s.toml", "joints.friction", study)
    with pytest.raises(InputError, match="law.toml: log: .*outside the folders"):  # a law file's own: the same roots
        law_from_spec({"file": "law.toml"}, "s.toml", "joints.friction", study)
    for spec in ({"log": "../logs/log.csv", "running_in": 0}, {"file": "law.toml"}):
        law = law_from_spec(spec, "s.toml", "joints.friction", study, (study, logs))
        assert isinstance(law, Empirical) and law.mean() == pytest.approx(mu.mean())


def test_log_kind_trims_running_in(tmp_path):
    mu = np.concatenate([np.full(10, 0.3), np.full(40, 0.12)]) + np.linspace(0, 1e-3, 50)
    (tmp_path / "log.csv").write_text("mu\n" + "\n".join(map(str, mu)) + "\n")
    law = law_from_spec({"log": "log.csv", "running_in": 10}, "s.toml", "joints.friction", tmp_path)
    assert isinstance(law, Empirical) and law.values.size == 40 and law.support()[1] < 0.13


def test_surface_kind_gives_a_law_between_film_and_boundary_friction():
    law = law_from_spec({"surface": "ground.csv", **SURFACE}, "s.toml", "joints.friction", PROFILES)
    assert 0.09 < law.mean() < 0.16 and law.std() > 0
    assert "ground.csv" in law.provenance


def test_smoother_turned_surface_carries_less_asperity_load_than_ground():
    mu = {name: law_from_spec({"surface": f"{name}.csv", **SURFACE}, "s", "f", PROFILES).mean()
          for name in ("turned", "ground")}
    assert mu["turned"] < mu["ground"]


@pytest.mark.parametrize("edit, key", [
    ({"film_thickness_m": -1.0}, "joints.friction.film_thickness_m"),
    ({"cycles": 2.5}, "joints.friction.cycles"),
    ({"filmthickness_m": 1e-6}, "joints.friction.filmthickness_m"),
])
def test_surface_kind_errors_name_the_key(edit, key):
    with pytest.raises(InputError, match=key.replace(".", r"\.")):
        law_from_spec({"surface": "ground.csv", **SURFACE, **edit}, "s.toml", "joints.friction", PROFILES)


def test_surface_study_runs(tmp_path):
    study = axis_study(friction={"surface": str(PROFILES / "turned.csv"), **SURFACE})
    study["study"]["data_dirs"] = [str(PROFILES)]  # a study reads only its folder's files and those it lists
    result = run_study(study)
    assert 0.09 <= result.poses[0].mu.min() and result.poses[0].mu.max() <= 0.16


@pytest.mark.parametrize("spec", [{"law": "uniform", "low": 0.12, "high": 0.12},
                                  {"law": "gaussian", "mean": 0.12, "std": 0.0},
                                  {"law": "lognormal", "mean": 0.12, "std": 0.0}], ids=lambda spec: spec["law"])
def test_zero_width_laws_are_constants_and_give_no_dispersion(spec):
    law = law_from_spec(spec)
    assert law.support() == (0.12, 0.12) and law.std() == 0.0
    pose = run_study(axis_study(friction=spec)).poses[0]
    assert np.all(pose.mu == 0.12)
    # constant mu, one approach direction: every cycle stops mu N / k short, RP_l = 0 and AP = mu N / k
    figures = pose.metrics.directions["+"]
    assert figures.RP_l_m == 0.0 and figures.AP_p_m == pytest.approx(0.12 * 100.0 / 1.0e6, rel=1e-9)
