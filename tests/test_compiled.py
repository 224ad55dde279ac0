"""The switch between compiled and NumPy kernels."""

import pytest

from conftest import AXIS_STUDY_TOML
from tribokin import compiled
from tribokin.cli import main
from tribokin.errors import InputError


def test_the_variable_chooses_the_path(monkeypatch):
    monkeypatch.setenv(compiled.VARIABLE, "numpy")
    assert not compiled.use_compiled() and compiled.kernels_used() == "numpy"
    monkeypatch.setenv(compiled.VARIABLE, "compiled")
    assert compiled.use_compiled() and compiled.kernels_used().startswith("compiled (numba ")
    monkeypatch.delenv(compiled.VARIABLE)
    assert compiled.use_compiled()


def test_an_unknown_path_is_refused_in_one_line(monkeypatch):
    monkeypatch.setenv(compiled.VARIABLE, "fortran")
    with pytest.raises(InputError, match="environment: TRIBOKIN_KERNELS: 'fortran' is not a kernel path"):
        compiled.use_compiled()


def test_the_command_refuses_an_unknown_path_before_any_work(monkeypatch, tmp_path, capsys):
    study = tmp_path / "study.toml"
    study.write_text(AXIS_STUDY_TOML)
    monkeypatch.setenv(compiled.VARIABLE, "gpu")
    assert main(["run", str(study), "--out", str(tmp_path / "out")]) == 2
    error = capsys.readouterr().err
    assert error.count("\n") == 1 and "TRIBOKIN_KERNELS: 'gpu' is not a kernel path" in error
    assert sorted(p.name for p in tmp_path.iterdir()) == ["study.toml"]
