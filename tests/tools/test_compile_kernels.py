"""tools/compile_kernels.py, which make runs after installing tribokin: its studies are valid, it runs each on the
compiled path and none on the NumPy path, the last from ASYMPTOTIC_CYCLES cycles on (RP_l_multi's sign mixture; that
it fills numba's cache is what make test's first runs then load)."""

from conftest import load_tool
from tribokin.compiled import VARIABLE
from tribokin.iso9283.gaussian_tests import ASYMPTOTIC_CYCLES
from tribokin.study.reading import load_study

tool = load_tool("compile_kernels")


def test_its_studies_are_valid_and_it_runs_each_on_the_compiled_path_only(monkeypatch):
    ran = []
    monkeypatch.setattr(tool, "run_study", lambda study, **options: ran.append((study, options)))
    monkeypatch.setenv(VARIABLE, "numpy")
    assert tool.main() == 0 and ran == []
    monkeypatch.setenv(VARIABLE, "compiled")
    assert tool.main() == 0
    assert [(study["study"]["approach"], study["study"]["engine"], study["study"]["cycles"]) for study, _ in ran] == [
        ("unidirectional", "fast", 10), ("bidirectional", "fast", 10), ("unidirectional", "exact", 10),
        ("unidirectional", "fast", ASYMPTOTIC_CYCLES)]
    for study, options in ran:
        loaded = load_study(study)
        assert loaded.map is not None and loaded.map.directional and len(loaded.poses) == 1
        assert options == {"meshes": False}
