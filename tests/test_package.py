"""The package's names: each of ``__all__`` resolves, and ``tribokin --version`` does not load the physics chain."""

import subprocess
import sys

import pytest

import tribokin
from conftest import ROOT

FRESH = """
import sys, runpy
sys.argv = ["tribokin", "--version"]
try:
    runpy.run_module("tribokin", run_name="__main__")
except SystemExit as end:
    assert end.code in (0, None), end.code
loaded = [name for name in ("tribokin.maps", "tribokin.run", "pinocchio", "numba", "matplotlib") if name in sys.modules]
assert not loaded, loaded
"""


MAP_COMMAND = """
import sys
from tribokin.cli import build_parser, kernels_to_compile
build_parser()
kernels_to_compile()
import tribokin.run, tribokin.output.writers, tribokin.viz.contents
loaded = [name for name in sys.modules if name.split(".")[:2] in
          (["scipy", "spatial"], ["scipy", "special"], ["scipy", "linalg"], ["scipy", "stats"], ["scipy", "sparse"])]
assert not loaded, loaded
from tribokin.measurement.registration import register_measurements
"""


def test_the_modules_of_a_map_command_import_none_of_scipys_heavy_subpackages():
    """scipy.spatial, .special and .linalg take about 0.15 s to import (they share scipy._lib's array API layer),
    scipy.stats 0.3 s: the parser, the run's modules and its views import none of them. A run still imports
    scipy.linalg through numba (which looks for BLAS when it loads its first kernel) on the compiled path, and
    scipy.special for Carlson's integrals on the NumPy path; the measurement commands import scipy.spatial when they
    register a frame."""
    done = subprocess.run([sys.executable, "-c", MAP_COMMAND], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr


def test_every_public_name_resolves_to_its_module():
    for name in tribokin.__all__:
        value = getattr(tribokin, name)
        assert getattr(value, "__module__", "tribokin").startswith("tribokin") or name == "__version__", name
    assert set(tribokin.__all__) <= set(dir(tribokin))
    assert tribokin.run_study.__module__ == "tribokin.run" and tribokin.MapResult.__module__ == "tribokin.maps.result"


def test_an_unknown_name_is_an_attribute_error():
    with pytest.raises(AttributeError, match="no_such_name"):
        _ = tribokin.no_such_name


def test_the_version_is_printed_without_loading_the_physics_chain():
    done = subprocess.run([sys.executable, "-c", FRESH], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == f"tribokin {tribokin.__version__}"
