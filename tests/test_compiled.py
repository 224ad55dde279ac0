"""The switch between compiled and NumPy kernels."""

import pytest

from tribokin import compiled
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
