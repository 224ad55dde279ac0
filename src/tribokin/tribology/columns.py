"""Numeric columns from a CSV measurement file, with errors naming file and column.

Lines starting with ``#`` are comments (provenance headers); the first other
line holds the column names.
"""

from __future__ import annotations

import csv
import warnings
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from tribokin.checks import finite_cell
from tribokin.errors import InputError


def read_columns(path, layouts: tuple[tuple[str, ...], ...], min_rows: int,
                 optional: tuple[str, ...] = ()) -> dict[str, np.ndarray]:
    """The columns of the first layout whose names all appear in the header of ``path``.

    Args:
        path: CSV file.
        layouts: accepted sets of column names, in order of preference.
        min_rows: fewest data rows accepted.
        optional: further columns read when present.

    Returns:
        column name -> float array, for the matching layout and the optional columns present.
    """
    path = Path(path)
    if not path.is_file():
        raise InputError("file not found; check the path", path)
    try:
        with open(path, newline="", encoding="utf-8") as handle:
            rows = [row for row in csv.reader(line for line in handle if not line.lstrip().startswith("#"))
                    if any(cell.strip() for cell in row)]
    except UnicodeDecodeError:
        raise InputError("not a text CSV file", path) from None
    header = [name.strip() for name in rows[0]] if rows else []
    layout = next((names for names in layouts if all(name in header for name in names)), None)
    if layout is None:
        wanted = " or ".join(f"'{', '.join(names)}'" for names in layouts)
        raise InputError(f"needs the columns {wanted} in its header line (found: {', '.join(header) or 'nothing'})",
                         path, layouts[0][next((i for i, n in enumerate(layouts[0]) if n not in header), 0)])
    data = rows[1:]
    if len(data) < min_rows:
        raise InputError(f"has {len(data)} data rows; at least {min_rows} are needed", path, layout[0])
    columns = {}
    for name in layout + tuple(name for name in optional if name in header):
        index = header.index(name)
        columns[name] = np.array([finite_cell(row[index] if index < len(row) else "", f"data row {line + 1}", path,
                                              name) for line, row in enumerate(data)])
    return columns


@contextmanager
def quiet_numerics():
    """NumPy floating-point warnings and ``RuntimeWarning`` silenced inside the block (an error is one line):
    the caller checks that what it computed is finite."""
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        yield
