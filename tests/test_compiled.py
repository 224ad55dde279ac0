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
from tribokin.maps.expected_figures_kernels import covariances
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


#: In a fresh process: a kernel module imported and its cache's index read (as a run's start does), then its kernel
#: called twice, its result against NumPy's; the CacheWarnings it gave printed, one per line.
CACHE_SCRIPT = """
import warnings
import numpy as np
from tribokin.compiled import CacheWarning, cache_is_empty
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    import tribokin.maps.expected_figures_kernels as kernels
    from tribokin.maps.expected_figures_kernels import covariances
    cache_is_empty([kernels])
    jacobian, variance = np.arange(24.0).reshape(1, 6, 4), np.array([[1.0, 2.0, 3.0, 4.0]])
    for _ in range(2):
        found = covariances(jacobian, variance, 0)
        expected = np.einsum("kin,kn,kjn->kij", jacobian[:, :3], variance, jacobian[:, :3])
        assert np.allclose(found, expected, rtol=1e-14), (found, expected)
for warning in caught:
    assert issubclass(warning.category, CacheWarning), warning
    print(warning.message)
"""


def _cache_run(tmp_path, prelude: str = "") -> list[str]:
    environment = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache"), "PYTHONPATH": str(ROOT / "src"),
                   compiled.VARIABLE: "compiled"}
    done = subprocess.run([sys.executable, "-c", prelude + CACHE_SCRIPT], env=environment, capture_output=True,
                          text=True)
    assert done.returncode == 0, done.stderr
    return done.stdout.splitlines()


def test_a_corrupted_cache_compiles_in_memory_and_says_so_once(tmp_path):
    assert _cache_run(tmp_path) == []  # compiled and cached
    indexes = list((tmp_path / "cache").rglob("*.nbi"))
    assert indexes
    for index in indexes:  # garbage where numba's pickled index was
        index.write_bytes(b"\x80\x04garbage" + bytes(range(256)))
    notes = _cache_run(tmp_path)
    assert len(notes) == 1 and "cannot be used" in notes[0] and "cannot be read" in notes[0], notes


def test_a_cache_no_folder_of_which_is_writable_compiles_in_memory_and_says_so_once(tmp_path):
    """Every location numba tries (NUMBA_CACHE_DIR, __pycache__ beside the source, the user's) refused as an
    unwritable folder refuses it (as root every folder is writable, so the refusal is simulated)."""
    refuse = ("import numba.core.caching as caching\n"
              "def refuse(locator):\n"
              "    raise PermissionError(13, 'Permission denied', locator.get_cache_path())\n"
              "caching._CacheLocator.ensure_cache_path = refuse\n")
    notes = _cache_run(tmp_path, refuse)
    assert len(notes) == 1 and "no folder it can write" in notes[0], notes
    assert not (tmp_path / "cache").exists()


def test_the_command_prints_the_cache_warning_as_one_note(capsys):
    from tribokin.cli import _show_warning

    _show_warning(compiled.CacheWarning("numba's cache cannot be used"), compiled.CacheWarning, "kernels.py", 1)
    assert capsys.readouterr().err == "tribokin: note: numba's cache cannot be used\n"


#: Two kernel modules of a package: the first's kernel calls the second's (compiled into it).
CALLER = """
from fakepkg.inner.value_kernels import value
from tribokin.compiled import kernel


@kernel
def twice():
    return 2.0 * value()
"""
CALLEE = """
from tribokin.compiled import kernel


@kernel
def value():
    return {value}
"""


def test_a_kernel_is_compiled_again_when_a_kernel_module_it_calls_changes(tmp_path):
    """numba keys a kernel's cache on its own file; tribokin's key adds every kernel module of its package, so a
    caller whose file did not change is not loaded from the cache with the old code of the kernel it calls."""
    package = tmp_path / "fakepkg"
    (package / "inner").mkdir(parents=True)
    (package / "__init__.py").write_text("")
    (package / "inner" / "__init__.py").write_text("")
    (package / "caller_kernels.py").write_text(CALLER)
    environment = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache"),
                   "PYTHONPATH": os.pathsep.join([str(tmp_path), str(ROOT / "src")]), compiled.VARIABLE: "compiled"}
    results = []
    for value in (1.0, 5.0):
        (package / "inner" / "value_kernels.py").write_text(CALLEE.format(value=value))
        done = subprocess.run([sys.executable, "-c", "from fakepkg.caller_kernels import twice; print(twice())"],
                              env=environment, capture_output=True, text=True)
        assert done.returncode == 0, done.stderr
        results.append(float(done.stdout))
    assert results == [2.0, 10.0]
    assert list((tmp_path / "cache").rglob("*caller_kernels.twice*.nbi"))  # cached, not compiled in memory