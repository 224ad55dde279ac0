"""A result's ``write``, ``figures`` and ``_repr_html_`` reach the writers and views above it through
``output.dispatch``: each public result's type has its implementation, registered when first used (the package's
``__init__`` imports the modules that register them, in turn until the type is registered), whatever module the
result was imported from."""

from __future__ import annotations

import subprocess
import sys

import pytest

import tribokin
from conftest import ROOT
from tribokin.output.dispatch import folder_writer, result_figures, result_scene

#: A surface written from its own module's import: its writer is loaded when it is written, the others' never.
FRESH = """
import sys
from tribokin.tribology.surface_result import analyse_surface
result = analyse_surface(sys.argv[1], z_range_m=(0.0, 1e-5))
assert "tribokin.output.tribology" not in sys.modules, "loaded before the write"
assert result.write(sys.argv[2]) is not None
assert "tribokin.output.tribology" in sys.modules, "not loaded by the write"
others = ("tribokin.output.writers", "tribokin.output.measured", "tribokin.viz.notebook", "tribokin.run")
assert not [name for name in others if name in sys.modules], [name for name in others if name in sys.modules]
"""


@pytest.mark.parametrize(("method", "generic", "arguments"), [("write", folder_writer, ("out",)),
                                                              ("figures", result_figures, ()),
                                                              ("_repr_html_", result_scene, ())])
def test_every_public_result_has_the_implementation_of_its_methods(method, generic, arguments):
    public = [getattr(tribokin, name) for name in tribokin.__all__]
    results = [value for value in public if isinstance(value, type) and callable(getattr(value, method, None))]
    assert tribokin.StudyResult in results
    with pytest.raises(TypeError, match="no implementation for a object"):
        generic(object(), *arguments)  # the registrars have run: every module that registers is imported
    assert [result.__name__ for result in results if generic.dispatch(result) is generic.dispatch(object)] == []


def test_a_result_imported_from_its_module_writes_its_folder_and_loads_the_writers_then(tmp_path):
    profile = ROOT / "src/tribokin/data/profiles/intermediate.csv"
    done = subprocess.run([sys.executable, "-c", FRESH, str(profile), str(tmp_path / "out")], cwd=ROOT,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert sorted(path.name for path in (tmp_path / "out").iterdir()) == ["p_z_R.png", "profile.png", "surface.json"]
