"""The switch between compiled and NumPy kernels."""

import os
import subprocess
import sys

import pytest

from conftest import AXIS_STUDY_TOML, ROOT
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


def test_a_run_compiles_its_kernels_when_numbas_cache_holds_none_of_them(tmp_path):
    """In a fresh process with an empty numba cache: every kernel to compile; once one is compiled (and cached),
    not; on the NumPy path, none."""
    script = """
import numpy as np
from tribokin.cli import kernels_to_compile
assert kernels_to_compile()
from tribokin.maps.expected_kernels import covariances
covariances(np.ones((1, 6, 2)), np.ones((1, 2)), 0)
assert not kernels_to_compile()
"""
    environment = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache"), "PYTHONPATH": str(ROOT / "src")}
    done = subprocess.run([sys.executable, "-c", script], env=environment, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert any((tmp_path / "cache").rglob("*.nbi"))  # numba's index, where the variable put it
    numpy_path = subprocess.run([sys.executable, "-c", "from tribokin.cli import kernels_to_compile\n"
                                 "assert not kernels_to_compile()"], env={**environment, compiled.VARIABLE: "numpy"},
                                capture_output=True, text=True)
    assert numpy_path.returncode == 0, numpy_path.stderr
