"""``calibrated.toml``: the user's study file with the fitted values written in, runnable by ``tribokin run``.

The study's own text is kept (its comments and layout, through ``tomlkit``), with:

- a header of comment lines saying where the values come from;
- each fitted value set in its joint's table (``[joints.<joint>]``, made when missing), with a comment
  giving its interval; a value the data cannot determine is left as the study gives it, and a comment says so;
- when asked (``calibrate --fit-ar1``), a friction group's fitted ``ar1`` set in its friction table (``[joints]``'s
  or a joint's), the comment on that table's line;
  Where the study's ``[joints]`` cannot carry a comment on each value (given as root-level dotted keys
  ``joints.stiffness = ...``, a root inline table ``joints = { ... }``, or a joint's inline table), ``[joints]`` is
  written anew as tables (its values kept, its comments not) and the header says so;
- ``[[poses]]`` for the measured poses (their configurations and approach directions), so that ``run`` predicts
  there too, approached as they were measured;
- relative paths (``robot.urdf``, ``robot.package_dirs``, law files ``file``, ``log``, ``surface``,
  ``study.data_dirs``) rewritten relative to the output folder, so that they name the same files from there; a study
  naming law files lists its own folder in ``study.data_dirs``, where they may still be read from
  (:func:`~tribokin.confinement.confined_file`).
"""

from __future__ import annotations

import os
import sys
from dataclasses import dataclass
from pathlib import Path

import tomlkit
from tomlkit.items import AoT, InlineTable, Table

from tribokin.study.spec import JOINT_KEYS

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

#: Keys of friction-law tables that name files.
LAW_FILE_KEYS = ("file", "log", "surface")


@dataclass(frozen=True)
class WrittenValue:
    """A joint key to set: ``joints.<joint>.<key> = value  # comment``."""

    joint: str
    key: str
    value: float
    comment: str


@dataclass(frozen=True)
class WrittenFrictionKey:
    """A key of a friction table to set: ``joints.<friction>.<key>`` (``joint`` ``None``) or
    ``joints.<joint>.<friction>.<key> = value``, ``comment`` on the table's line (an inline table's) or the key's."""

    joint: str | None
    friction: str
    key: str
    value: float
    comment: str

    def table(self, joints):
        """The friction table in ``joints`` (a mapping of ``[joints]``)."""
        return (joints if self.joint is None else joints[self.joint])[self.friction]


def _moved(path: str, source_dir: Path, out: Path) -> str:
    """``path`` (relative to ``source_dir`` unless absolute) relative to ``out``."""
    if Path(path).is_absolute():
        return path
    return Path(os.path.relpath((source_dir / path).absolute(), out.absolute())).as_posix()


def _move_law_files(item, source_dir: Path, out: Path) -> bool:
    """Rewrite the file keys of every law table inside ``item`` (tables and arrays of tables, recursively); whether
    there were any."""
    found = False
    if isinstance(item, (dict, Table)):
        for key, value in item.items():
            if key in LAW_FILE_KEYS and isinstance(value, str):
                item[key] = _moved(value, source_dir, out)
                found = True
            else:
                found = _move_law_files(value, source_dir, out) or found
    elif isinstance(item, (list, AoT)):
        for value in item:
            found = _move_law_files(value, source_dir, out) or found
    return found


def _move_paths(document, source_dir: Path, out: Path) -> None:
    robot = document.get("robot", {})
    if isinstance(robot.get("urdf"), str):
        robot["urdf"] = _moved(robot["urdf"], source_dir, out)
    if "package_dirs" in robot:
        robot["package_dirs"] = [_moved(p, source_dir, out) for p in robot["package_dirs"]]
    names_files = False
    for section in ("joints", "poses", "scenarios"):
        if section in document:
            names_files = _move_law_files(document[section], source_dir, out) or names_files
    own = [_moved(".", source_dir, out)] if names_files else []
    if own or "data_dirs" in document.get("study", {}):
        if "study" not in document:
            document.add("study", tomlkit.table())
        _move_data_dirs(document["study"], own, source_dir, out)
    for scenario in document.get("scenarios", []):
        if isinstance(scenario.get("study"), (dict, Table)) and "data_dirs" in scenario["study"]:
            _move_data_dirs(scenario["study"], own, source_dir, out)


def _move_data_dirs(study, own: list[str], source_dir: Path, out: Path) -> None:
    """``study.data_dirs`` named from ``out``, after the folders ``own`` (the study's own, when it names files)."""
    folders = own + [_moved(folder, source_dir, out) for folder in study.get("data_dirs", [])]
    study["data_dirs"] = list(dict.fromkeys(folders))


def calibrated_study_text(study_text: str, source_dir: Path, out: Path, header: list[str],
                          values: list[WrittenValue], poses: list[tuple[str, list[float], list[str]]],
                          frictions: tuple[WrittenFrictionKey, ...] = ()) -> str:
    """The calibrated study (module docstring).

    Args:
        study_text: the study file's text.
        source_dir: the folder its relative paths resolve against.
        out: the folder ``calibrated.toml`` is written to.
        header: comment lines (without ``#``) put first.
        values: the joint keys to set.
        poses: (name, configuration, approach directions) of the poses to append as ``[[poses]]``.
        frictions: the friction tables' keys to set (each table given by the study).
    """
    document = moved_study_document(study_text, source_dir, out)
    expected = document.unwrap()
    for value in values:
        expected["joints"].setdefault(value.joint, {})[value.key] = value.value
    for friction in frictions:
        friction.table(expected["joints"])[friction.key] = friction.value
    try:
        _set_values(document["joints"], values, frictions)
        rewritten = not _carried(tomlkit.dumps(document), expected, [*values, *frictions])
    except (AttributeError, KeyError, TypeError, ValueError):  # tomlkit cannot edit this layout in place
        rewritten = True
    if rewritten:
        document = moved_study_document(study_text, source_dir, out)
        _set_values(_joints_as_tables(document), values, frictions)
        header = [*header, REWRITTEN]
    if poses:
        entries = document["poses"] if "poses" in document else tomlkit.aot()
        for name, q, directions in poses:
            entry = tomlkit.table()
            entry["name"] = name
            entry["q"] = q
            entry["q"].comment("measured pose [rad or m]")
            entry["directions"] = directions
            entry["directions"].comment("its measured approaches")
            entries.append(entry)
        document["poses"] = entries
    return with_header(document, header)


#: The header's line when ``[joints]`` is written anew.
REWRITTEN = ("[joints] is written as tables below (the study gave it as dotted keys or inline tables, which cannot "
             "carry a comment on each value): its values are the study's, its comments are not kept.")


def _set_values(joints, values: list[WrittenValue], frictions: tuple[WrittenFrictionKey, ...] = ()) -> None:
    """Set each of ``values`` in its joint's table of ``joints``, and each of ``frictions`` in its friction table,
    with its comment."""
    for value in values:
        if value.joint not in joints:
            joints[value.joint] = tomlkit.table()
        item = tomlkit.item(value.value)
        item.comment(value.comment)
        joints[value.joint][value.key] = item
    for friction in frictions:
        table = friction.table(joints)
        item = tomlkit.item(friction.value)
        if isinstance(table, InlineTable):
            table.comment(friction.comment)
        else:
            item.comment(friction.comment)
        table[friction.key] = item


def _carried(text: str, expected: dict, values: list[WrittenValue | WrittenFrictionKey]) -> bool:
    """Whether ``text`` parses into ``expected`` (a key tomlkit put in the wrong table would not) with the comment of
    each of ``values`` written (an inline table drops it)."""
    return tomllib.loads(text) == expected and all(f"# {v.comment}" in text for v in values)


def _inline(value):
    """A law table (``{ law = ... }``) as an inline table; any other value as it is."""
    if not isinstance(value, dict):
        return value
    table = tomlkit.inline_table()
    table.update(value)
    return table


def _joints_as_tables(document: tomlkit.TOMLDocument) -> Table:
    """``document``'s ``[joints]`` (in whatever layout) replaced by a ``[joints]`` table of its shared keys and a
    ``[joints.<joint>]`` table per joint (:data:`REWRITTEN`), put last; returned."""
    plain = document["joints"].unwrap()
    del document["joints"]
    joints = tomlkit.table()
    per_joint = {key: value for key, value in plain.items() if key not in JOINT_KEYS and isinstance(value, dict)}
    for key, value in plain.items():
        if key not in per_joint:
            joints[key] = _inline(value)
    for joint, entries in per_joint.items():
        table = tomlkit.table()
        for key, value in entries.items():
            table[key] = _inline(value)
        joints[joint] = table
    document["joints"] = joints
    return document["joints"]


def moved_study_document(study_text: str, source_dir: Path, out: Path) -> tomlkit.TOMLDocument:
    """The study's text as a ``tomlkit`` document (comments and layout kept), its relative paths rewritten to name the
    same files from ``out``."""
    document = tomlkit.parse(study_text)
    _move_paths(document, source_dir, out)
    return document


def with_header(document: tomlkit.TOMLDocument, header: list[str]) -> str:
    """``document``'s text after the comment lines ``header`` (without ``#``) and a blank line."""
    lines = "".join(f"# {line}\n" if line else "#\n" for line in header)
    return lines + "\n" + tomlkit.dumps(document)
