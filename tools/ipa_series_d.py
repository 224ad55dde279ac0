"""Convert Series D of the IPA UR10 laser-tracker data into tribokin's measurement CSV (issue 21).

    python tools/ipa_series_d.py studies/data/ipa-ur10 --out ipa-ur10-series-d.csv [--force]

``studies/data/ipa-ur10`` holds the upstream Series D files with their licence and provenance; what this
script writes from them is committed as ``studies/data/ipa-ur10-series-d.csv`` (a test keeps the two equal).

Reads ``raw/Series_D/measurements_iso_cubes.csv`` (``;`` separators, decimal commas) and
``raw/Series_D/Trafo_TM_F_init.txt`` of the data folder and writes one row per measurement of every
pose that has a unidirectional series of at least two cycles, in the file's row order:

- **Poses**: rows whose commanded positions agree within 0.5 mm and commanded orientations (as
  rotations) within 0.1° are one pose (connected groups, each checked to span less than both);
  a pose is named ``rowNNN`` after the 0-based data row of its first measurement.
- **Directions**: time order is the row order, and the robot is taken to have moved straight from
  the preceding row's commanded pose (the data record no waypoints). The label of a row is the
  direction of that move, the unit vector from the preceding row's commanded position to its own in
  the robot base frame, written with two decimals (``+0.58+0.58+0.58``); data row 0 has no
  predecessor and is labelled ``start``. Visits of one pose whose moves point within 1° of each other
  share the label of the first of them, whatever the move's length: a cube centre's later visits come
  along the same diagonal from the (-,-,-) corner of a 400, 250 or 100 mm cube, its first visit from
  the previous location, so that one is a series of one.
- Poses without a series of two cycles are dropped and listed; those kept keep all their rows (a
  one-cycle series still counts in the pooled cloud).
- Columns: measured T-Mac position ``x_m, y_m, z_m`` in the laser tracker's frame (not the robot base
  frame); ``a_deg, b_deg, c_deg``: rotation vector, about the tracker's x, y, z axes, taking the
  pose's mean measured orientation (``Rotation.mean``) to the row's: the deviations ISO 9283's a, b, c
  stand for, as ``tribokin.iso9283.metrics`` defines them (the raw angles are intrinsic X-Y-Z Euler angles
  whose second angle is near -79° and whose third wraps at ±180°, and fixed-axis x-y-z angles of
  these orientations sit at the gimbal lock, b ≈ -90°: differences of either are not rotations about
  x, y, z); commanded TCP position ``cx_m, cy_m, cz_m`` of the row itself in the robot base frame;
  ``q_<joint>`` [rad]; the tracker's per-reading standard deviation ``sx_mm, sy_mm, sz_mm``. No
  ``t_s``: Series D stores one rounded timestamp for all rows.

The probe's offset on the flange (the inverse of ``Trafo_TM_F_init.txt``) is printed and written
as ``robot.tool_offset_m`` / ``robot.tool_offset_rpy_deg`` comment lines; it is not applied.
Bad input: one line ``ipa_series_d: error: <file>: <key>: <what to fix>``, exit status 2, no file written.
"""

from __future__ import annotations

import argparse
import csv
import sys
from collections import Counter
from pathlib import Path
from typing import NamedTuple

import numpy as np
from output_file import check_out, write_atomically
from scipy.sparse.csgraph import connected_components
from scipy.spatial.transform import Rotation

from tribokin.errors import InputError

MEASUREMENTS = Path("raw/Series_D/measurements_iso_cubes.csv")
TOOL_TRAFO = Path("raw/Series_D/Trafo_TM_F_init.txt")
LICENCE = "MIT, Copyright (c) 2021 Christian Landgraf"
JOINTS = ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint",
          "wrist_3_joint")
GOAL = ("Goal x", "Goal y", "Goal z")
GOAL_RPY = ("Goal roll", "Goal pitch", "Goal yaw")
MEASURED = ("measurement_x", "measurement_y", "measurement_z")
MEASURED_XYZ_DEG = ("measurement_rx", "measurement_ry", "measurement_rz")
MEASURED_STD = ("measurement_std_x", "measurement_std_y", "measurement_std_z")
COLUMNS = GOAL + GOAL_RPY + JOINTS + MEASURED + MEASURED_XYZ_DEG + MEASURED_STD
POSITION_TOL_M = 0.5e-3
ORIENTATION_TOL_DEG = 0.1
DIRECTION_TOL_DEG = 1.0


def read_table(path: Path) -> dict[str, np.ndarray]:
    """The :data:`COLUMNS` of a ``;``-separated file with decimal commas, as float arrays (one per column)."""
    try:
        with open(path, newline="", encoding="utf-8") as stream:
            lines = list(csv.reader(stream, delimiter=";"))
    except (OSError, UnicodeDecodeError) as error:
        raise InputError(f"cannot read it ({error.__class__.__name__}); give the ipa-ur10 data folder", path) from error
    header = lines[0] if lines else []
    missing = [name for name in COLUMNS if name not in header]
    if missing:
        raise InputError(f"missing column(s) {', '.join(missing)}; expected Series D's header", path)
    where = [header.index(name) for name in COLUMNS]
    values = np.empty((len(lines) - 1, len(COLUMNS)))
    for row, fields in enumerate(lines[1:]):
        if len(fields) != len(header):
            raise InputError(f"{len(fields)} fields, the header has {len(header)}; fix the row", path,
                             f"line {row + 2}")
        for k, index in enumerate(where):
            try:
                values[row, k] = float(fields[index].replace(",", "."))
            except ValueError:
                values[row, k] = np.nan
            if not np.isfinite(values[row, k]):
                raise InputError(f"'{fields[index]}' is not a finite number", path, f"line {row + 2}: {COLUMNS[k]}")
    if len(values) == 0:
        raise InputError("no data rows", path)
    return dict(zip(COLUMNS, values.T, strict=True))


def read_tool_offset(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """Probe TCP in the flange frame: translation [m] (to 0.1 µm) and fixed-axis x-y-z angles [deg] (to 1e-6°),
    from the 4x4 pose of the flange in the T-Mac frame [mm] (TCP = flange · inverse(matrix))."""
    try:
        matrix = np.loadtxt(path)
    except (OSError, ValueError) as error:
        raise InputError(f"cannot read a 4x4 matrix ({error.__class__.__name__})", path) from error
    if matrix.shape != (4, 4) or not np.isfinite(matrix).all():
        raise InputError(f"expected a 4x4 homogeneous matrix, found shape {matrix.shape}", path)
    tcp = np.linalg.inv(matrix)
    rpy_deg = Rotation.from_matrix(tcp[:3, :3]).as_euler("xyz", degrees=True)
    return np.round(tcp[:3, 3] / 1000.0, 7) + 0.0, np.round(rpy_deg, 6) + 0.0


def group_poses(commanded_m: np.ndarray, rotations: Rotation, source: Path) -> np.ndarray:
    """Pose index per row: rows joined when within :data:`POSITION_TOL_M` and :data:`ORIENTATION_TOL_DEG`,
    numbered in order of first appearance; an error when a group spans more than either."""
    n = len(commanded_m)
    distance = np.linalg.norm(commanded_m[:, None] - commanded_m[None], axis=2)
    angle = np.degrees(np.array([(rotations[i].inv() * rotations).magnitude() for i in range(n)]))
    close = (distance < POSITION_TOL_M) & (angle < ORIENTATION_TOL_DEG)
    labels = connected_components(close, directed=False)[1]
    for group in np.unique(labels):
        rows = np.flatnonzero(labels == group)
        inside = np.ix_(rows, rows)
        if distance[inside].max() >= POSITION_TOL_M or angle[inside].max() >= ORIENTATION_TOL_DEG:
            raise InputError(f"data rows {', '.join(map(str, rows))} chain into one pose spanning "
                             f"{distance[inside].max() * 1e3:.3f} mm, {angle[inside].max():.3f} deg: the tolerances "
                             f"({POSITION_TOL_M * 1e3} mm, {ORIENTATION_TOL_DEG} deg) do not separate the poses",
                             source)
    _, first, order = np.unique(labels, return_index=True, return_inverse=True)
    return np.argsort(np.argsort(first))[order]


def approach_labels(commanded_m: np.ndarray, poses: np.ndarray, source: Path) -> list[str]:
    """Direction label per row: its move from the preceding row's commanded position (see the module's docstring)."""
    moves = np.diff(commanded_m, axis=0)
    still = np.flatnonzero(np.linalg.norm(moves, axis=1) < POSITION_TOL_M)
    if still.size:
        raise InputError(f"data rows {still[0]} and {still[0] + 1} are commanded within {POSITION_TOL_M * 1e3:g} mm "
                         "of each other: the second has no approach direction", source)
    units = np.vstack([np.full(3, np.nan), moves / np.linalg.norm(moves, axis=1, keepdims=True)])
    labels = ["start"] + ["".join(f"{v:+.2f}" for v in u) for u in units[1:]]
    for pose in np.unique(poses):
        references: list[int] = []
        for row in np.flatnonzero(poses == pose):
            if row == 0:
                continue
            angles_deg = [np.degrees(np.arccos(min(1.0, units[r] @ units[row]))) for r in references]
            same = [r for r, angle in zip(references, angles_deg, strict=True) if angle < DIRECTION_TOL_DEG]
            if same:
                labels[row] = labels[same[0]]
            else:
                references.append(row)
    return labels


def _ranges(rows) -> str:
    """``1-3, 7`` for rows 1, 2, 3, 7."""
    rows = list(rows)
    starts = [r for i, r in enumerate(rows) if i == 0 or rows[i - 1] != r - 1]
    ends = [r for i, r in enumerate(rows) if i == len(rows) - 1 or rows[i + 1] != r + 1]
    return ", ".join(str(a) if a == b else f"{a}-{b}" for a, b in zip(starts, ends, strict=True))


class Conversion(NamedTuple):
    """Series D as measurement rows.

    Attributes:
        rows_read: data rows in the raw file.
        kept: pose name -> its 0-based data rows, for the poses written.
        dropped: pose name -> its data rows, for the poses without a series of two cycles.
        notes: the comment lines on the tool offset, the kept and the dropped poses (printed by :func:`main`).
        text: the CSV file's content (comment lines, header, rows).
    """

    rows_read: int
    kept: dict[str, list[int]]
    dropped: dict[str, list[int]]
    notes: list[str]
    text: str


def _number(value: float) -> str:
    return format(float(value), ".12g")


def convert(folder: Path) -> Conversion:
    """Read Series D from the ipa-ur10 data ``folder`` and build the measurement file (nothing written)."""
    source = folder / MEASUREMENTS
    table = read_table(source)
    offset_m, offset_rpy_deg = read_tool_offset(folder / TOOL_TRAFO)
    commanded_m = np.column_stack([table[k] for k in GOAL])
    rotations = Rotation.from_euler("xyz", np.column_stack([table[k] for k in GOAL_RPY]))
    poses = group_poses(commanded_m, rotations, source)
    directions = approach_labels(commanded_m, poses, source)
    names = {p: f"row{np.flatnonzero(poses == p)[0]:03d}" for p in np.unique(poses)}
    members = {names[p]: np.flatnonzero(poses == p).tolist() for p in np.unique(poses)}
    series: Counter = Counter()
    cycles = []
    for pose, label in zip(poses, directions, strict=True):
        series[names[pose], label] += 1
        cycles.append(series[names[pose], label])
    longest = {name: max(count for (n, _), count in series.items() if n == name) for name in members}
    kept = {n: rows for n, rows in members.items() if longest[n] >= 2}
    dropped = {n: rows for n, rows in members.items() if longest[n] < 2}
    if not kept:
        raise InputError("no pose was measured twice from one direction; nothing to convert", source)

    measured = Rotation.from_euler("XYZ", np.column_stack([table[k] for k in MEASURED_XYZ_DEG]), degrees=True)
    abc_deg = np.zeros((len(poses), 3))
    for rows in kept.values():
        abc_deg[rows] = np.degrees((measured[rows] * measured[rows].mean().inv()).as_rotvec())
    columns = {"x_m": table["measurement_x"] / 1000, "y_m": table["measurement_y"] / 1000,
               "z_m": table["measurement_z"] / 1000, "a_deg": abc_deg[:, 0], "b_deg": abc_deg[:, 1],
               "c_deg": abc_deg[:, 2], "cx_m": table["Goal x"], "cy_m": table["Goal y"], "cz_m": table["Goal z"],
               **{f"q_{j}": table[j] for j in JOINTS},
               "sx_mm": table["measurement_std_x"], "sy_mm": table["measurement_std_y"],
               "sz_mm": table["measurement_std_z"]}
    out_rows = sorted(r for rows in kept.values() for r in rows)
    body = [",".join(["pose", "cycle", "direction", *columns])]
    body += [",".join([names[poses[r]], str(cycles[r]), directions[r], *(_number(c[r]) for c in columns.values())])
             for r in out_rows]
    notes = _notes(kept, dropped, series, directions, (offset_m, offset_rpy_deg))
    comments = _provenance(kept, commanded_m, len(members), len(poses)) + notes
    return Conversion(len(poses), kept, dropped, notes,
                      "".join(f"# {line}\n" for line in comments) + "\n".join(body) + "\n")


def _provenance(kept, commanded_m, poses: int, rows: int) -> list[str]:
    """Source, licence, frames, columns and rules of the file."""
    spread_mm = 1e3 * max(np.linalg.norm(commanded_m[rows][:, None] - commanded_m[rows][None], axis=2).max()
                          for rows in kept.values())
    return [
        "IPA UR10 laser-tracker measurements, Series D (nested ISO-style cubes), as a tribokin measurement file.",
        "Source: GitHub christianlandgraf/ipa-robot-accuracy, commit 507fba69bdaf6c43c2faf306e70a7e37c5e39b89,",
        "file Series_D/measurements_iso_cubes.csv.",
        f"Licence: {LICENCE}.",
        "Converted by tools/ipa_series_d.py (tribokin); see studies/data/ipa-ur10/README.md in tribokin for the data.",
        "Frames: x_m, y_m, z_m = measured T-Mac probe origin in the LASER TRACKER frame (not the robot base",
        "frame: register it); cx_m, cy_m, cz_m = commanded probe TCP of the row in the robot base frame (ROS",
        "base_link, the maker's base turned 180 deg about z); q_<joint> [rad]; sx_mm, sy_mm, sz_mm = the",
        "tracker's standard deviation per reading. a_deg, b_deg, c_deg = rotation vector about the tracker's",
        "x, y, z taking the pose's mean measured orientation (raw: intrinsic X-Y-Z Euler angles) to the row's:",
        "orientation deviations, so their mean is 0 and AP_a, AP_b, AP_c cannot be read from them.",
        "No t_s: Series D stores one rounded timestamp for all rows; the row order is the time order.",
        f"Poses: rows whose commanded positions agree within {POSITION_TOL_M * 1e3:g} mm and orientations within "
        f"{ORIENTATION_TOL_DEG:g} deg;",
        f"{poses} poses in {rows} rows, each named after its first data row (0-based).",
        f"Commanded positions of one kept pose differ by up to {spread_mm:.3f} mm between its rows (re-taught",
        "cube centres): each row keeps its own.",
        "Directions: the unit vector of the move from the preceding row's commanded position (robot base frame),",
        "assuming a straight move (no waypoints are recorded); row 0 is 'start'. Visits of a pose whose moves",
        f"point within {DIRECTION_TOL_DEG:g} deg share the label of the first, whatever the move's length.",
        "A cube centre's first visit at a location comes from elsewhere: it is a one-cycle series beside the others.",
    ]


def _notes(kept, dropped, series: Counter, directions, tool_offset) -> list[str]:
    """The tool offset to use, the kept poses with their series and the dropped poses."""
    repeated = {name: rows for name, rows in dropped.items() if len(rows) > 1}
    singles = sorted(rows[0] for rows in dropped.values() if len(rows) == 1)
    return [
        "Probe TCP in the flange (tool0) frame, the inverse of Trafo_TM_F_init.txt; NOT applied to any column:",
        f"  robot.tool_offset_m = [{', '.join(map(repr, tool_offset[0].tolist()))}]",
        f"  robot.tool_offset_rpy_deg = [{', '.join(map(repr, tool_offset[1].tolist()))}]  (fixed-axis x-y-z)",
        f"Kept {len(kept)} poses (pose: data rows; direction x cycles):",
        *(f"  {name}: rows {', '.join(map(str, rows))}; "
          + "; ".join(f"{label} x{series[name, label]}" for label in dict.fromkeys(directions[r] for r in rows))
          for name, rows in kept.items()),
        f"Dropped {len(dropped)} poses without a series of two cycles: {len(repeated)} measured more than once, "
        "each time from a different direction:",
        *(f"  {name}: rows {', '.join(map(str, rows))}; " + "; ".join(directions[r] for r in rows)
          for name, rows in repeated.items()),
        f"  and {len(singles)} measured once, at rows {_ranges(singles)}.",
    ]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder", type=Path, help="the ipa-ur10 data folder (holding raw/Series_D)")
    parser.add_argument("--out", type=Path, required=True, help="the measurement CSV to write")
    parser.add_argument("--force", action="store_true", help="replace --out if it exists")
    args = parser.parse_args(argv)
    try:
        check_out(args.out, args.force)
        result = convert(args.folder)
        write_atomically(args.out, result.text)
    except InputError as error:
        print(f"ipa_series_d: error: {error.one_line()}", file=sys.stderr)
        return 2
    print(f"read {result.rows_read} rows; kept {len(result.kept)} poses "
          f"({sum(map(len, result.kept.values()))} rows), dropped {len(result.dropped)}")
    print("\n".join(result.notes))
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
