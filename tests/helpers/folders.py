"""Output folders compared: a library result's ``write`` against its command's folder."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest


def assert_same_files(written, command) -> None:
    """The two folders hold the same files, byte for byte."""
    names = sorted(p.relative_to(written).as_posix() for p in written.rglob("*") if p.is_file())
    assert names == sorted(p.relative_to(command).as_posix() for p in command.rglob("*") if p.is_file())
    assert names, "no file written"
    for name in names:
        assert (written / name).read_bytes() == (command / name).read_bytes(), name


def assert_frozen(result) -> None:
    """``result`` is a frozen dataclass: setting any of its fields is refused."""
    field = dataclasses.fields(result)[0].name
    with pytest.raises(dataclasses.FrozenInstanceError):
        setattr(result, field, None)


def _cell(value):
    """A table's cell compared: ``None`` for a missing one (NaN, an empty text), else a float or the text."""
    if value is None or (isinstance(value, float) and np.isnan(value)) or value == "":
        return None
    try:
        return float(value)
    except (TypeError, ValueError):
        return str(value)


def assert_frame_matches_csv(frame, path) -> None:
    """``frame`` (a result's ``to_pandas()``) holds the CSV's columns, in order, and the same numbers (NaN where the
    file's cell is empty) and texts."""
    pandas = pytest.importorskip("pandas")
    table = pandas.read_csv(path, keep_default_na=False, na_values=[""])
    assert list(frame.columns) == list(table.columns)
    assert len(frame) == len(table) > 0
    for column in table.columns:
        assert [_cell(v) for v in frame[column]] == [_cell(v) for v in table[column]], column
