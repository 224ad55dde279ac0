"""The study-file key reference (docs/reference/study-file.md) is what tools/study_reference.py writes from the
schema, every schema key has a one-line description in tribokin.study.key_docs, and the ranges the page prints are
the ones the checks enforce."""

from __future__ import annotations

import pytest

from conftest import ROOT, load_tool
from tribokin.errors import InputError
from tribokin.study import spec
from tribokin.study.key_docs import KEY_DOCS

reference = load_tool("study_reference")


def test_the_committed_page_is_what_the_schema_gives():
    page = ROOT / "docs" / "reference" / "study-file.md"
    assert page.read_text(encoding="utf-8") == reference.render(), \
        "docs/reference/study-file.md is stale: run python tools/study_reference.py and commit the page"


def test_every_schema_key_has_a_description_and_every_description_a_key():
    assert reference.problems() == []
    keys = reference.schema_keys()
    assert len(keys) == len(set(keys)) >= 60
    assert set(keys) == set(KEY_DOCS)
    assert all(KEY_DOCS[key].strip() and "\n" not in KEY_DOCS[key] for key in keys)


def test_a_key_added_to_the_schema_without_a_description_is_named(monkeypatch):
    monkeypatch.setitem(spec.STUDY_KEYS, "new_key", (spec.text, None))
    monkeypatch.setitem(spec.MAP_KINDS["box"], "table_format", (spec.one_of("csv", "parquet"), "csv"))
    assert reference.problems() == ["study.new_key: no description in tribokin/study/key_docs.py KEY_DOCS",
                                    "map.table_format: no description in tribokin/study/key_docs.py KEY_DOCS"]
    assert reference.main(["--check"]) == 1


def test_a_description_of_no_key_and_a_section_without_a_table_are_named(monkeypatch):
    monkeypatch.setitem(KEY_DOCS, "study.cycels", "a misspelt key")
    monkeypatch.setattr(spec, "TOP_KEYS", (*spec.TOP_KEYS, "fixtures"))
    assert reference.problems() == ["study.cycels: described in KEY_DOCS but no such key in the schema",
                                    "[fixtures]: a section of the study file the page does not cover"]


@pytest.mark.parametrize("table, key, inside", [
    (spec.STUDY_KEYS, "cycles", lambda v: v), (spec.STUDY_KEYS, "seed", lambda v: v),
    (spec.JOINT_KEYS, "stiffness", lambda v: v), (spec.JOINT_KEYS, "backlash", lambda v: v),
    (spec.ROBOT_KEYS, "payload_kg", lambda v: v), (spec.ROBOT_KEYS, "tool_offset_m", lambda v: [0.0, 0.0, v]),
    (spec.JOINT_KEYS, "friction_torque_Nm", lambda v: {"law": "constant", "value": v}),
    (spec.MAP_KINDS["plane"], "resolution", lambda v: [1, v]), (spec.PLACEMENT_KEYS, "yaw_deg", lambda v: [v]),
    (spec.CALIBRATION_KEYS, "noise_floor_m", lambda v: v), (spec.PLACEMENT_KEYS, "min_reachable", lambda v: v),
])
def test_the_range_printed_is_the_one_the_check_enforces(table, key, inside):
    """bounds_of finds the range through a partial's arguments, a closure's cells and a comprehension's names; the
    check accepts both ends and refuses beyond each (above the range with the reason the page prints; below zero,
    for a quantity that cannot be negative, as negative)."""
    check = table[key][0]
    low, high, _, why = reference.bounds_of(check)
    for value in (low, high):
        check(inside(value), "study.toml", key)
    beyond = [high * 2 if high else 1, low - 1 if low <= 0 else low / 2]
    for value in beyond:
        if isinstance(low, int) and not float(value).is_integer():
            continue
        with pytest.raises(InputError) as error:
            check(inside(type(low)(value)), "study.toml", key)
        assert why in error.value.message or (value < 0 and ">= 0" in error.value.message)
    assert f"{reference.number(low)} to {reference.number(high)}: {why}" in reference.render()


def test_choices_and_defaults_come_from_the_schema():
    page = reference.render()
    assert "| `study.approach` | – | `\"unidirectional\"` | one of `unidirectional`, `bidirectional`, `random` |" \
        in page
    assert "| `poses[].q` | m or rad | **required** |" in page
    assert "| `map.resolution` (plane, box) | – | **required** | 1 to 10<sup>7</sup>:" in page
    assert "| `joints.friction_radius_m` | m | `0.02` | 10<sup>−4</sup> to 10:" in page
