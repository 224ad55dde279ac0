"""Write the docs' study-file key reference (docs/reference/study-file.md) from the schema's own tables.

Each key's default comes from its table in ``tribokin.study.spec``, its range, unit and the reason of that range
from its check (``tribokin.checks.within`` keeps them as ``bounds``; ``one_of`` its ``choices``), its meaning from
``tribokin.study.key_docs.KEY_DOCS``. A key without a line there, or a line naming no key, stops the script.

    python tools/study_reference.py            # writes docs/reference/study-file.md
    python tools/study_reference.py --check    # exit 1 if the committed page is not what it would write
"""

from __future__ import annotations

import argparse
import math
import sys
from functools import partial
from pathlib import Path
from types import CodeType, FunctionType

from tribokin.study import series_spec, spec
from tribokin.study.key_docs import KEY_DOCS

PAGE = Path(__file__).resolve().parent.parent / "docs" / "reference" / "study-file.md"

#: The sections of a study file with a table of keys, in the file's order; ``[[scenarios]]`` has none of its own.
SECTIONS = {
    "study": ("[study]", spec.STUDY_KEYS),
    "robot": ("[robot]", spec.ROBOT_KEYS),
    "joints": ("[joints], [joints.<joint>]", spec.JOINT_KEYS),
    "friction": ("friction = { ..., <time keys> }", series_spec.SERIES_KEYS),
    "friction.run_in": ("run_in = { start, tau_cycles }", series_spec.RUN_IN_KEYS),
    "friction.thermal": ("thermal = { ... }", series_spec.THERMAL_KEYS),
    "poses": ("[[poses]]", spec.POSE_KEYS),
    "iso_cube": ("[iso_cube]", spec.ISO_CUBE_KEYS),
    "map": ("[map]", None),
    "map.state": ("state, compare = { age_cycles, after_s } (or \"cold\", \"warm\")", series_spec.STATE_KEYS),
    "calibration": ("[calibration]", spec.CALIBRATION_KEYS),
    "placement": ("[placement]", spec.PLACEMENT_KEYS),
    "drift": ("[drift]", spec.DRIFT_KEYS),
}
#: Sections without a table here: their text in the page says what they hold.
UNTABLED = ("scenarios",)
#: Units read off a key's name where its check holds none (the SI suffixes of the schema).
SUFFIX_UNITS = {"_m": "m", "_deg": "deg", "_N": "N", "_Nm": "N·m", "_kg": "kg"}

HEADER = """# Study-file keys

<!-- Written by tools/study_reference.py from the schema (tribokin/study/spec.py, key_docs.py): do not edit;
     tests/tools/test_study_reference.py fails when this page is stale. -->

Every key of a study file, section by section: its unit, its default (**required** where it has none; – where it is
unset unless given), the range a value must lie in and why, and what it means. An unknown key, or a value outside
its range, stops the command before anything runs, with one line naming the file and the key
([errors](../errors.md)). A joint's keys may also be given for one joint, `[joints.<joint>]`; a pose's, per
`[[poses]]` entry. How the keys work together: [study files](../study-files.md).
"""

SCENARIOS = """## `[[scenarios]]`

A map's what-if variants, each with a `name` (letters, digits, `-`, `_`, `.`, at most 100 characters, no leading
`.`; it names files, `map_<name>.csv`, `map_RP_l_<name>.png`, ..., and no two scenarios may write the same file:
`b` and `ratio_b` both would write `map_RP_l_ratio_b.png`) and overrides of the `[study]`, `[robot]` and `[joints]`
keys above, written as `section.key = value` (`joints.friction = { preset = "42CD4-treated" }`,
`robot.name = "ur10"`), merged key by key and checked as those sections' keys are. The first scenario is the
reference. See [scenarios](../maps.md#scenarios).
"""


def bounds_of(check, seen=None):
    """``(low, high, unit, why)`` of the range ``check`` holds: its own, or that of a check it is built on (a
    partial's arguments, a closure's cells, the functions its code names); ``None`` without one."""
    seen = set() if seen is None else seen
    if id(check) in seen:
        return None
    seen.add(id(check))
    if getattr(check, "bounds", None):
        return check.bounds
    if isinstance(check, partial):
        parts = [*check.keywords.values(), *check.args, check.func]
    elif isinstance(check, FunctionType):
        parts = [cell.cell_contents for cell in check.__closure__ or ()]
        parts += [check.__globals__.get(name) for name in names_in(check.__code__)]
    else:
        return None
    return next((found for part in parts if callable(part) and (found := bounds_of(part, seen))), None)


def names_in(code: CodeType) -> list[str]:
    """The global names a function's code uses, its comprehensions' and inner functions' included."""
    inner = (name for const in code.co_consts if isinstance(const, CodeType) for name in names_in(const))
    return [*code.co_names, *inner]


def choices_of(check):
    """The values a ``one_of`` check allows, else ``None``."""
    return getattr(check, "choices", None)


def number(value) -> str:
    """A range's end for people: ``2``, ``0.02``, a power of ten from 10⁴ up or below 10⁻³ as one (``10^15``),
    2⁶⁴ − 1 (the seeds') as that."""
    if value == 2 ** 64 - 1:
        return "2<sup>64</sup> − 1"
    exponent = round(math.log10(abs(value))) if value else 0
    if value and (abs(value) >= 1e4 or abs(value) < 1e-3) and math.isclose(abs(value), 10.0 ** exponent):
        return f"{'−' if value < 0 else ''}10<sup>{exponent}</sup>".replace("-", "−")
    return f"{value:g}".replace("-", "−")


def shown_default(default) -> str:
    if default is spec.REQUIRED:
        return "**required**"
    if default is None:
        return "–"
    if isinstance(default, bool):
        return f"`{str(default).lower()}`"
    if isinstance(default, str):
        return f'`"{default}"`'
    if isinstance(default, list):
        return f"`{default}`" if default else "`[]`"
    return f"`{default}`"


def unit_of(key: str, bounds) -> str:
    if bounds and bounds[2] and not bounds[2].startswith(("candidates", "rows")):
        return bounds[2]
    return next((unit for suffix, unit in SUFFIX_UNITS.items() if key.endswith(suffix)), "–")


def range_of(check, bounds) -> str:
    if choices_of(check):
        return "one of " + ", ".join(f"`{c}`" for c in choices_of(check))
    if not bounds:
        return "–"
    low, high, _, why = bounds
    return f"{number(low)} to {number(high)}: {why}"


def section_rows(name: str, table: dict, kinds: dict | None = None) -> list[tuple[str, str]]:
    """(key as written, the table row) of every key of a section's table (a map's: every kind's)."""
    prefix = "poses[]" if name == "poses" else name
    rows = []
    for key, (check, default) in table.items():
        full = f"{prefix}.{key}"
        bounds = bounds_of(check)
        kind = f" ({', '.join(kinds[key])})" if kinds and key in kinds else ""
        rows.append((full, f"| `{full}`{kind} | {unit_of(key, bounds)} | {shown_default(default)} | "
                           f"{range_of(check, bounds)} | {KEY_DOCS.get(full, '')} |"))
    return rows


def map_table() -> tuple[dict, dict]:
    """The ``[map]`` keys of every kind, each once (the common ones first), and the kinds that have each."""
    table = dict(spec.MAP_COMMON_KEYS)
    kinds: dict[str, list[str]] = {}
    for kind, keys in spec.MAP_KINDS.items():
        for key, entry in keys.items():
            table.setdefault(key, entry)
            kinds.setdefault(key, []).append(kind)
    return table, kinds


def schema_keys() -> list[str]:
    """Every key of the schema, as KEY_DOCS names it."""
    return [key for name, (_, table) in SECTIONS.items()
            for key, _ in section_rows(name, table if table is not None else map_table()[0])]


def problems() -> list[str]:
    """What stops the page from being written: keys without a line in KEY_DOCS, lines naming no key, sections of
    the study file the page does not cover."""
    keys = schema_keys()
    found = [f"{key}: no description in tribokin/study/key_docs.py KEY_DOCS" for key in keys if key not in KEY_DOCS]
    found += [f"{key}: described in KEY_DOCS but no such key in the schema" for key in KEY_DOCS if key not in keys]
    found += [f"[{section}]: a section of the study file the page does not cover" for section in spec.TOP_KEYS
              if section not in SECTIONS and section not in UNTABLED]
    return found


def render() -> str:
    """The page's text."""
    parts = [HEADER]
    for name, (title, table) in SECTIONS.items():
        kinds = None
        if table is None:
            table, kinds = map_table()
        parts.append(f"## `{title}`\n\n| key | unit | default | range | meaning |\n|---|---|---|---|---|\n"
                     + "\n".join(row for _, row in section_rows(name, table, kinds)) + "\n")
        if name == "map":
            parts.append(SCENARIOS)
    return "\n".join(parts)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="exit 1 if the committed page is stale")
    args = parser.parse_args(argv)
    found = problems()
    if found:
        print("\n".join(found), file=sys.stderr)
        return 1
    text = render()
    if args.check:
        if not PAGE.is_file() or PAGE.read_text(encoding="utf-8") != text:
            print(f"{PAGE} is stale: run python tools/study_reference.py", file=sys.stderr)
            return 1
        return 0
    PAGE.write_text(text, encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
