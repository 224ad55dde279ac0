"""The measurement file (issue 21's contract), read into frozen structures in SI units.

CSV, ``#`` lines are comments, one row per measured cycle; the unit is in each name:

- ``pose`` (text), ``cycle`` (1, 2, ... within the pose and direction),
  ``direction`` (optional approach label, default ``+``);
- ``x, y, z`` in ``_m`` or ``_mm``: measured tool position;
- ``a, b, c`` in ``_deg`` or ``_rad``: optional measured orientation (about x, y, z);
- ``cx, cy, cz`` in ``_m`` or ``_mm``: optional commanded position of the row;
- ``sx, sy, sz`` in ``_m`` or ``_mm``: optional standard deviation the instrument reports;
- ``q_<joint>``: optional joint coordinate of the row, [rad] (or [m] for the joints the
  caller names prismatic: the file does not say which joints are);
- ``t_s``: optional time of the reading [s].

A raw stream (``t_s`` and positions, no ``pose``) is read by :func:`read_stream`.
"""

from __future__ import annotations

import csv
from collections.abc import Collection
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from tribokin.checks import finite_cell
from tribokin.confinement import regular_file
from tribokin.errors import InputError, closest_hint
from tribokin.tribology.columns import csv_refusal

LENGTH_UNITS = {"m": 1.0, "mm": 1e-3}
ANGLE_UNITS = {"deg": np.pi / 180, "rad": 1.0}

#: The column triples: key -> (names without unit, accepted units -> factor to SI).
TRIPLES = {
    "position": (("x", "y", "z"), LENGTH_UNITS),
    "orientation": (("a", "b", "c"), ANGLE_UNITS),
    "commanded": (("cx", "cy", "cz"), LENGTH_UNITS),
    "std": (("sx", "sy", "sz"), LENGTH_UNITS),
}
#: Physical ranges in SI of each triple and of the q_ columns: (low, high, unit, why a value outside is refused).
_DISTANCE = "no instrument measures a robot a kilometre away; check the unit in the column's name (_m or _mm)"
RANGES = {
    "position": (-1e3, 1e3, "m", _DISTANCE),
    "commanded": (-1e3, 1e3, "m", _DISTANCE),
    "orientation": (-2 * np.pi, 2 * np.pi, "rad", "write each angle within one turn either way"),
    "std": (0.0, 1.0, "m", "an instrument reading a metre astray measures nothing of a robot's repeatability"),
    "q": (-1e3, 1e3, "rad or m", "no joint travels a kilometre or turns 160 times"),
}

DEFAULT_DIRECTION = "+"
#: Largest cycle number: a study's largest ``cycles`` (and whole numbers as floats are exact up to 2**53).
MAX_CYCLE = 10 ** 15
#: Bytes reading a measurement file holds, per byte of it (its text, its lines), per line and per cell (each a
#: Python string in a list), and per row read into arrays: measured (``tracemalloc``: about 12 bytes per byte of
#: a file of nine columns) and rounded up about twofold.
READ_BYTES_PER_BYTE, READ_BYTES_PER_LINE, READ_BYTES_PER_CELL, KEPT_BYTES_PER_ROW = 4, 300, 150, 400
#: Largest spread of one joint's coordinate between the rows of a pose: [rad], and [m] for prismatic joints.
Q_SPREAD_LIMIT_RAD = 0.01
Q_SPREAD_LIMIT_M = 1e-3


def _frozen(array: np.ndarray) -> np.ndarray:
    """``array``, made read-only."""
    array.setflags(write=False)
    return array


@dataclass(frozen=True)
class Series:
    """The cycles of one pose approached from one direction, in cycle order (arrays read-only).

    Attributes:
        direction: approach label.
        cycles: (n,) cycle numbers, increasing.
        lines: (n,) line numbers of the rows in the file.
        positions_m: (n, 3) measured tool positions [m].
        angles_rad: (n, 3) measured orientation a, b, c [rad], or None.
        commanded_m: (n, 3) commanded positions [m], or None.
        std_m: (n, 3) the instrument's standard deviation of each reading [m], or None.
        times_s: (n,) times of the readings [s], or None.
    """

    direction: str
    cycles: np.ndarray
    lines: np.ndarray
    positions_m: np.ndarray
    angles_rad: np.ndarray | None
    commanded_m: np.ndarray | None
    std_m: np.ndarray | None
    times_s: np.ndarray | None

    @property
    def too_short(self) -> bool:
        """Fewer than two cycles: no RP of its own (its cycles still count in the pose's pooled cloud)."""
        return len(self.cycles) < 2


@dataclass(frozen=True)
class Pose:
    """One measured pose.

    Attributes:
        name: pose label.
        series: its unidirectional series, in order of first appearance in the file.
        q: (n_joints,) mean joint coordinates of its rows [rad or m] (circular mean for continuous
            joints), or None without ``q_`` columns.
        q_spread: largest spread (max - min) of one joint coordinate between its rows [rad or m], or None.
    """

    name: str
    series: tuple[Series, ...]
    q: np.ndarray | None
    q_spread: float | None

    def pooled(self, field: str) -> np.ndarray | None:
        """``field`` (e.g. ``"positions_m"``) of all its series stacked, in series order, or None."""
        parts = [getattr(s, field) for s in self.series]
        return None if parts[0] is None else np.concatenate(parts)


@dataclass(frozen=True)
class Measurements:
    """A measurement file: its poses in order of first appearance.

    Attributes:
        source: the file read.
        poses: the poses.
        joints: joint names of the ``q_`` columns, in file order.
        columns: the file's column names, in file order (empty when not read from a file).
    """

    source: str
    poses: tuple[Pose, ...]
    joints: tuple[str, ...]
    columns: tuple[str, ...] = ()


@dataclass(frozen=True)
class Rows:
    """Columns of the data rows, before grouping (SI; arrays over rows; None for absent columns).

    Attributes:
        lines: (n,) line numbers in the file (for messages).
        poses, directions: (n,) labels.
        cycles: (n,) cycle numbers.
        positions_m: (n, 3) [m].
        angles_rad, commanded_m, std_m: (n, 3) or None.
        times_s: (n,) [s] or None.
        q: (n, n_joints) or None, with ``joints`` naming the columns.
    """

    lines: np.ndarray
    poses: tuple[str, ...]
    directions: tuple[str, ...]
    cycles: np.ndarray
    positions_m: np.ndarray
    angles_rad: np.ndarray | None = None
    commanded_m: np.ndarray | None = None
    std_m: np.ndarray | None = None
    times_s: np.ndarray | None = None
    q: np.ndarray | None = None
    joints: tuple[str, ...] = ()


@dataclass(frozen=True)
class Stream:
    """Readings over time (a raw stream, or the instrument standing still).

    Attributes:
        source: the file read.
        lines: (n,) line numbers of the readings in the file.
        times_s: (n,) increasing times [s], or None when the file has no ``t_s``.
        positions_m: (n, 3) positions [m].
    """

    source: str
    lines: np.ndarray
    times_s: np.ndarray | None
    positions_m: np.ndarray


@dataclass(frozen=True)
class FileSize:
    """What reading a measurement file takes, counted before it is read.

    Attributes:
        bytes: its size [bytes].
        lines: its lines (every row at most one).
        cells: its cells (commas and lines).
    """

    bytes: int
    lines: int
    cells: int

    @property
    def reading_bytes(self) -> int:
        """Bytes reading it holds at once [bytes] (the constants above)."""
        return (READ_BYTES_PER_BYTE * self.bytes + READ_BYTES_PER_LINE * self.lines + READ_BYTES_PER_CELL * self.cells
                + KEPT_BYTES_PER_ROW * self.lines)


def file_size(path) -> FileSize:
    """Size, lines and cells of the file ``path``, counted in blocks of 1 MiB (nothing else is read); the file is
    first resolved and checked as reading it checks it (:func:`~tribokin.confinement.regular_file`)."""
    size = lines = commas = 0
    with open(regular_file(path, path), "rb") as handle:
        for block in iter(lambda: handle.read(1 << 20), b""):
            size, lines, commas = size + len(block), lines + block.count(b"\n"), commas + block.count(b",")
    return FileSize(size, lines + 1, commas + lines + 1)


class _Table:
    """Header and data rows of a CSV file, with errors naming the file, column and line."""

    def __init__(self, path):
        self.path = Path(path)
        real = regular_file(self.path, self.path)
        try:
            text = real.read_text(encoding="utf-8-sig")  # a spreadsheet's byte-order mark is not a name
        except UnicodeDecodeError:
            raise InputError("not a text CSV file", self.path) from None
        records = []
        for number, line in enumerate(text.splitlines(), start=1):
            if line.strip() and not line.lstrip().startswith("#"):
                try:
                    records.append((number, [cell.strip() for cell in next(csv.reader([line]))]))
                except csv.Error as error:
                    raise csv_refusal(error, self.path, number) from None
        if len(records) < 2:
            raise InputError("needs a header line and at least one data row", self.path)
        self.header_line, self.header = records[0]
        self.records = records[1:]
        self.lines = np.array([number for number, _ in self.records])
        if len(self.header) == 1 and ";" in self.header[0]:
            raise InputError("columns are separated by ';'; separate them by commas (decimal points, not commas)",
                             self.path)
        for index, name in enumerate(self.header):
            if self.header.count(name) > 1:
                again = self.header.index(name, index + 1)
                raise InputError(f"line {self.header_line}: columns {index + 1} and {again + 1} have the same name, "
                                 "given twice; keep one", self.path)
        for number, row in self.records:
            if len(row) != len(self.header):
                raise InputError(f"line {number} has {len(row)} cells, the header {len(self.header)}; "
                                 "give one cell per column (decimal points, not commas)", self.path)

    def texts(self, name: str) -> list[str]:
        """The cells of column ``name``, refusing empty ones."""
        index = self.header.index(name)
        cells = []
        for number, row in self.records:
            cell = row[index]
            if not cell:
                raise InputError(f"line {number} is empty here; fill it in or remove the row", self.path, name)
            cells.append(cell)
        return cells

    def labels(self, name: str) -> list[str]:
        """The cells of column ``name`` (:meth:`texts`), refusing characters that are not printable (NUL, escape,
        tab...): labels are written into tables and figures' titles, and shown on terminals."""
        cells = self.texts(name)
        for number, cell in zip(self.lines, cells, strict=True):
            if not cell.isprintable():
                raise InputError(f"line {number} holds {cell[:40]!r}, with a character that is not printable (such as "
                                 "NUL, escape or a tab); write the label in printable characters", self.path, name)
        return cells

    def numbers(self, name: str, factor: float = 1.0, bounds: str | None = None) -> np.ndarray:
        """Column ``name`` as finite floats times ``factor``, within ``RANGES[bounds]`` (in SI) if given."""
        column = self.header.index(name) + 1
        values = np.array([finite_cell(cell, f"line {number}, column {column}", self.path, name)
                           for number, cell in zip(self.lines, self.texts(name), strict=True)]) * factor
        if bounds is not None:
            low, high, unit, why = RANGES[bounds]
            outside = np.flatnonzero((values < low) | (values > high))
            if outside.size:
                raise InputError(f"line {self.lines[outside[0]]} holds {values[outside[0]]:g} {unit}, outside "
                                 f"[{low:g}, {high:g}] {unit}: {why}", self.path, name)
        return values

    def triple(self, key: str, required: bool = False) -> tuple[np.ndarray | None, tuple[str, ...]]:
        """The (n, 3) SI values of triple ``key`` of :data:`TRIPLES` (None when absent) and its column names."""
        names, units = TRIPLES[key]
        found = {}
        for name in names:
            hits = [f"{name}_{unit}" for unit in units if f"{name}_{unit}" in self.header]
            if len(hits) > 1:
                raise InputError(f"given in two units ({' and '.join(hits)}); keep one", self.path, hits[1])
            if hits:
                found[name] = hits[0]
        example = " or ".join(", ".join(f"{n}_{u}" for n in names) for u in units)
        if not found and not required:
            return None, ()
        missing = [name for name in names if name not in found]
        if missing:
            raise InputError(f"missing column: the {key} needs three columns, {example}", self.path,
                             f"{missing[0]}_{next(iter(units))}")
        columns = tuple(found[name] for name in names)
        used = {column.rsplit("_", 1)[1] for column in columns}
        if len(used) > 1:
            raise InputError(f"mixed units in {', '.join(columns)}; give all three in one unit ({example})",
                             self.path, columns[0])
        factor = units[used.pop()]
        return np.column_stack([self.numbers(column, factor, key) for column in columns]), columns

    def refuse_unknown(self, known: set[str]) -> None:
        """Refuse a column that is not in ``known`` and is not a ``q_<joint>``."""
        for index, name in enumerate(self.header):
            if name not in known and not (name.startswith("q_") and len(name) > 2):
                raise InputError(f"line {self.header_line}, column {index + 1}: unknown column"
                                 f"{closest_hint(name, sorted(known))}; rename or remove it (units go in the name: _m, "
                                 "_mm, _deg, _rad, _s)", self.path)


def _all_triple_columns() -> set[str]:
    return {f"{name}_{unit}" for names, units in TRIPLES.values() for name in names for unit in units}


def read_measurements(path, prismatic: Collection[str] = (), continuous: Collection[str] = ()) -> Measurements:
    """Read and check a measurement file.

    Args:
        path: CSV file of the contract (module docstring).
        prismatic: joints (names after ``q_``) whose coordinates are lengths [m]; the others are angles [rad].
        continuous: joints whose mean is circular (angles wrap at ±pi).
    """
    table = _Table(path)
    table.refuse_unknown({"pose", "cycle", "direction", "t_s"} | _all_triple_columns())
    for name in ("pose", "cycle"):
        if name not in table.header:
            raise InputError("missing column (one row per measured cycle: pose, cycle, [direction,] x_m, y_m, z_m"
                             " or x_mm, ...)", table.path, name)
    cycles = table.numbers("cycle")
    for number, cycle in zip(table.lines, cycles, strict=True):
        if cycle < 1 or cycle != int(cycle) or cycle > MAX_CYCLE:
            raise InputError(f"line {number} holds {cycle:g}; cycles are whole numbers from 1 to {MAX_CYCLE:g} (1e15 "
                             "cycles at one a second would take 30 million years)", table.path, "cycle")
    positions, _ = table.triple("position", required=True)
    joints = tuple(name[2:] for name in table.header if name.startswith("q_"))
    rows = Rows(
        lines=table.lines,
        poses=tuple(table.labels("pose")),
        directions=tuple(table.labels("direction")) if "direction" in table.header
        else (DEFAULT_DIRECTION,) * len(table.lines),
        cycles=cycles.astype(int),
        positions_m=positions,
        angles_rad=table.triple("orientation")[0],
        commanded_m=table.triple("commanded")[0],
        std_m=table.triple("std")[0],
        times_s=table.numbers("t_s") if "t_s" in table.header else None,
        q=np.column_stack([table.numbers(f"q_{j}", bounds="q") for j in joints]) if joints else None,
        joints=joints,
    )
    return replace(assemble(str(table.path), rows, prismatic, continuous), columns=tuple(table.header))


def read_stream(path, require_time: bool = True) -> Stream:
    """Read a raw stream: ``t_s`` (increasing; optional unless ``require_time``) and positions, no poses."""
    table = _Table(path)
    table.refuse_unknown({"t_s"} | {f"{n}_{u}" for n in TRIPLES["position"][0] for u in LENGTH_UNITS})
    if require_time and "t_s" not in table.header:
        raise InputError("missing column: a raw stream needs the time of each reading", table.path, "t_s")
    positions, _ = table.triple("position", required=True)
    times = table.numbers("t_s") if "t_s" in table.header else None
    if times is not None:
        step = np.flatnonzero(np.diff(times) <= 0)
        if step.size:
            raise InputError(f"line {table.lines[step[0] + 1]}: times must increase from row to row",
                             table.path, "t_s")
    return Stream(str(table.path), _frozen(table.lines), times if times is None else _frozen(times),
                  _frozen(positions))


def _refuse_duplicates(source: str, rows: Rows) -> None:
    seen: dict[tuple[str, str, int], int] = {}
    for line, key in zip(rows.lines, zip(rows.poses, rows.directions, rows.cycles.tolist(), strict=True), strict=True):
        if key in seen:
            raise InputError(f"lines {seen[key]} and {line} both hold pose '{key[0]}', direction '{key[1]}', "
                             f"cycle {key[2]}; remove or renumber one", source, "cycle")
        seen[key] = int(line)


def _joint_configuration(source: str, pose: str, q: np.ndarray, joints: tuple[str, ...],
                         prismatic: Collection[str], continuous: Collection[str]) -> tuple[np.ndarray, float]:
    """Mean (circular for ``continuous`` joints) and largest spread of a pose's (n, n_joints) coordinates."""
    means, spreads = [], []
    for column, joint in zip(q.T, joints, strict=True):
        if joint in continuous:
            mean = float(np.arctan2(np.sin(column).mean(), np.cos(column).mean()))
            deviations = (column - mean + np.pi) % (2 * np.pi) - np.pi
        else:
            mean = float(column.mean())
            deviations = column - mean
        spread = float(np.ptp(deviations))
        limit, unit = (Q_SPREAD_LIMIT_M, "m") if joint in prismatic else (Q_SPREAD_LIMIT_RAD, "rad")
        if spread > limit:
            raise InputError(f"pose '{pose}': its rows differ by {spread:.3g} {unit} in this joint (limit {limit:g}"
                             f" {unit}); one pose is one joint configuration: split it or check the data",
                             source, f"q_{joint}")
        means.append(mean)
        spreads.append(spread)
    return _frozen(np.array(means)), max(spreads)


def assemble(source: str, rows: Rows, prismatic: Collection[str] = (),
             continuous: Collection[str] = ()) -> Measurements:
    """Group checked rows into poses and series; refuse duplicates, poses without a series of two
    cycles and joint spreads above :data:`Q_SPREAD_LIMIT_RAD` (:data:`Q_SPREAD_LIMIT_M` for prismatic)."""
    _refuse_duplicates(source, rows)
    labels = np.array(rows.poses, dtype=object)
    directions = np.array(rows.directions, dtype=object)
    poses = []
    for name in dict.fromkeys(rows.poses):
        mine = labels == name
        series = []
        for direction in dict.fromkeys(directions[mine]):
            picked = np.flatnonzero(mine & (directions == direction))
            picked = picked[np.argsort(rows.cycles[picked], kind="stable")]
            series.append(Series(direction, _frozen(rows.cycles[picked]), _frozen(rows.lines[picked]),
                                 *(None if a is None else _frozen(a[picked]) for a in
                                   (rows.positions_m, rows.angles_rad, rows.commanded_m, rows.std_m,
                                    rows.times_s))))
        if all(s.too_short for s in series):
            found = ", ".join(f"'{s.direction}' {len(s.cycles)} cycle" for s in series)
            raise InputError(f"pose '{name}' has no series of two or more cycles (found: {found}); measure at "
                             "least two cycles from one direction, or remove the pose", source, "pose")
        q, spread = (None, None) if rows.q is None else _joint_configuration(
            source, name, rows.q[mine], rows.joints, prismatic, continuous)
        poses.append(Pose(name, tuple(series), q, spread))
    return Measurements(source, tuple(poses), rows.joints)
