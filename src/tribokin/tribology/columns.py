"""Numeric columns from a CSV measurement file, with errors naming the file, the line and the column.

Lines starting with ``#`` are comments (provenance headers); the first other
line holds the column names.
"""

from __future__ import annotations

import csv
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from tribokin.checks import finite_cell
from tribokin.confinement import regular_file
from tribokin.errors import InputError


def csv_refusal(error: csv.Error, path, line: int) -> InputError:
    """A line of the CSV file ``path`` the reader refuses (a cell beyond its field limit, a NUL) as one line naming
    the line, never quoting it."""
    return InputError(f"not a CSV file: {error}", path, f"line {line}")


def _records(handle, path) -> Iterator[tuple[int, list[str]]]:
    """(line number, cells) of each CSV record of ``handle`` (the file ``path``) that is neither a comment nor
    blank."""
    reader = csv.reader("\n" if line.lstrip().startswith("#") else line for line in handle)
    try:
        for row in reader:
            if any(cell.strip() for cell in row):
                yield reader.line_num, row
    except csv.Error as error:
        raise csv_refusal(error, path, reader.line_num) from None


def read_columns(path, layouts: tuple[tuple[str, ...], ...], min_rows: int,
                 optional: tuple[str, ...] = ()) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """The columns of the first layout whose names all appear in the header of ``path``, and each row's line.

    The file must be a regular file (:func:`~tribokin.confinement.regular_file`); errors name its lines and columns,
    never what they hold.

    Args:
        path: CSV file.
        layouts: accepted sets of column names, in order of preference.
        min_rows: fewest data rows accepted.
        optional: further columns read when present.

    Returns:
        column name -> float array, for the matching layout and the optional columns present; and the line number of
        each data row in the file (comments and blank lines counted), for messages.
    """
    path = Path(path)
    real = regular_file(path, path)
    try:
        with open(real, newline="", encoding="utf-8") as handle:
            records = list(_records(handle, path))
    except UnicodeDecodeError:
        raise InputError("not a text CSV file", path) from None
    header = [name.strip() for name in records[0][1]] if records else []
    layout = next((names for names in layouts if all(name in header for name in names)), None)
    if layout is None:
        wanted = " or ".join(f"'{', '.join(names)}'" for names in layouts)
        where = f"line {records[0][0]}: expected a header" if records else "no header line: expected one"
        raise InputError(f"{where} naming the columns {wanted}", path,
                         layouts[0][next((i for i, n in enumerate(layouts[0]) if n not in header), 0)])
    data = records[1:]
    if len(data) < min_rows:
        raise InputError(f"has {len(data)} data rows; at least {min_rows} are needed", path, layout[0])
    columns = {}
    for name in layout + tuple(name for name in optional if name in header):
        index = header.index(name)
        columns[name] = np.array([finite_cell(row[index] if index < len(row) else "",
                                              f"line {line}, column {index + 1}", path, name) for line, row in data])
    return columns, np.array([line for line, _ in data])


@contextmanager
def quiet_numerics():
    """NumPy floating-point warnings and ``RuntimeWarning`` silenced inside the block (an error is one line):
    the caller checks that what it computed is finite."""
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        yield
