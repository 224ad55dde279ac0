"""A measurement file written from rows, for the measurement tests."""

from __future__ import annotations

from pathlib import Path


def write_csv(folder: Path, header: str, rows: list[str], name: str = "tracker.csv",
              comments: tuple[str, ...] = ("# synthetic tracker data",)) -> Path:
    """``folder/name`` holding the comment lines, the header and the rows."""
    path = folder / name
    path.write_text("\n".join([*comments, header, *rows]) + "\n", encoding="utf-8")
    return path
