"""The package's layout: imports point down the chain of stages and never go round in a circle.

Every ``import`` of every module counts, those inside functions and under ``TYPE_CHECKING``
included; importing a package's module does not count as importing the package's ``__init__``.
"""

from __future__ import annotations

import ast
from pathlib import Path

from conftest import ROOT

PACKAGE = ROOT / "src" / "tribokin"

#: The stages, lowest first: a module may import from its own stage or a lower one. A stage is
#: named by the first part of its modules' names below ``tribokin`` (or by a dotted module name, which places that
#: module apart from the rest of its package); ``tribokin`` itself (the package's ``__init__``) is the top. Ground
#: floor: errors, value checks, units, files confined before they are read, random streams, the compiled kernels'
#: path, and two modules of ``output`` every stage may use: its folders (temporary siblings renamed in; the map's
#: store makes its own) and the provenance a result records. Figures (``viz``) sit below ``output``, which draws them
#: into the folder.
STAGES = (
    ("errors", "checks", "units", "confinement", "streams", "compiled", "output.folder", "output.provenance"),
    ("tribology",),
    ("kinematics",),
    ("propagation",),
    ("iso9283",),
    ("measurement",),
    ("calibration",),
    ("simulation",),
    ("study",),
    ("execution",),
    ("maps",),
    ("placement",),
    ("run",),
    ("measured",),
    ("viz",),
    ("output",),
    ("cli", "__main__", ""),
)
LEVEL = {part: level for level, parts in enumerate(STAGES) for part in parts}
#: The imports that point up, each inside the named methods only
#: (:func:`test_the_upward_import_is_inside_the_write_method_only`): a result writes itself (``StudyResult.write``,
#: ``MeasurementResult.write``...) through its writer, which takes the result's class, and the lock the commands hold;
#: a result shows itself in a notebook (``_repr_html_``: the report's 3-D scene) and gives its figures (``figures``)
#: through the views, which take the result's class. The stages and the cycles are checked without them.
WRITE_METHODS = {**{(result, writer): ("write",) for result, writers in (
    ("tribokin.run", ("tribokin.output.writers", "tribokin.output.lock")),
    ("tribokin.tribology.friction_fit", ("tribokin.output.tribology", "tribokin.output.lock")),
    ("tribokin.tribology.surface_result", ("tribokin.output.tribology", "tribokin.output.lock")),
    ("tribokin.measured.written", ("tribokin.output.measured", "tribokin.output.lock"))) for writer in writers},
                 ("tribokin.run", "tribokin.viz.contents"): ("figures",),
                 ("tribokin.run", "tribokin.viz.notebook"): ("_repr_html_",),
                 ("tribokin.maps.result", "tribokin.viz.notebook"): ("figures", "_repr_html_"),
                 ("tribokin.simulation.pose_result", "tribokin.viz.notebook"): ("figures", "_repr_html_")}


def module_name(path: Path) -> str:
    """``tribokin.maps.mapping`` for ``src/tribokin/maps/mapping.py``; ``tribokin.maps`` for its ``__init__.py``."""
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {module_name(path): path for path in sorted(PACKAGE.rglob("*.py"))}


def imported_modules(name: str) -> set[str]:
    """The package's modules that module ``name`` imports anywhere in its source."""
    found = set()
    for node in ast.walk(ast.parse(MODULES[name].read_text(), str(MODULES[name]))):
        if isinstance(node, ast.Import):
            found |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom):
            assert node.level == 0, f"{name}: relative import"
            found |= {f"{node.module}.{alias.name}" if f"{node.module}.{alias.name}" in MODULES else node.module
                      for alias in node.names}
    return {module for module in found if module in MODULES and module != name}


IMPORTS = {name: imported_modules(name) - {other for (module, other) in WRITE_METHODS if module == name}
           for name in MODULES}


def stage(name: str) -> int:
    """The level of module ``name``'s stage in :data:`STAGES`: its own dotted name's (below ``tribokin``) if listed,
    else its first part's."""
    parts = name.split(".")[1:]
    return LEVEL[".".join(parts)] if ".".join(parts) in LEVEL else LEVEL[parts[0] if parts else ""]


def test_every_module_has_a_stage():
    assert {name.split(".")[1] for name in MODULES if "." in name} <= set(LEVEL)


def test_every_dotted_stage_is_a_module():
    assert {part for part in LEVEL if "." in part} <= {name.removeprefix("tribokin.") for name in MODULES}


def test_at_most_eight_modules_sit_flat_in_the_package():
    flat = sorted(path.stem for path in PACKAGE.glob("*.py") if path.stem not in ("__init__", "__main__"))
    assert len(flat) <= 8, flat


def test_no_module_imports_from_a_stage_above_its_own():
    upward = sorted(f"{name} imports {other}" for name, others in IMPORTS.items() for other in others
                    if stage(other) > stage(name))
    assert upward == []


def test_no_import_cycle():
    cycles, state = [], {}

    def visit(name: str, path: list[str]) -> None:
        state[name] = "open"
        for other in sorted(IMPORTS[name]):
            if state.get(other) == "open":
                cycles.append(" -> ".join(path[path.index(other):] + [other]))
            elif other not in state:
                visit(other, path + [other])
        state[name] = "done"

    for name in sorted(MODULES):
        if name not in state:
            visit(name, [name])
    assert cycles == []


def test_the_walk_sees_imports_inside_functions():
    assert "tribokin.kinematics.robot" in IMPORTS["tribokin.cli.robots"]  # imported in a function only


def test_the_upward_import_is_inside_the_write_method_only():
    for (name, other), methods in WRITE_METHODS.items():
        tree = ast.parse(MODULES[name].read_text(), str(MODULES[name]))
        inside = {id(node) for function in ast.walk(tree) if isinstance(function, ast.FunctionDef)
                  and function.name in methods for node in ast.walk(function)}
        imports = [node for node in ast.walk(tree) if isinstance(node, ast.ImportFrom) and node.module == other]
        assert imports and all(id(node) in inside for node in imports)
        assert other not in {alias.name for node in ast.walk(tree) if isinstance(node, ast.Import)
                             for alias in node.names}
