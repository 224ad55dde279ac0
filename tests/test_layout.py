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
#: path, and four modules of ``output`` every stage may use: its folders (temporary siblings renamed in; the map's
#: store makes its own), the provenance a result records, the folder's lock and the dispatch through which a result
#: writes its folder and shows its figures and scene (``write``, ``figures``, ``_repr_html_``: the writers and views
#: above register themselves there). Figures (``viz``) sit below ``output``, which draws them into the folder.
STAGES = (
    ("errors", "checks", "units", "confinement", "streams", "compiled", "output.folder", "output.provenance",
     "output.lock", "output.dispatch"),
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


IMPORTS = {name: imported_modules(name) for name in MODULES}


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
