"""Writing a map table (``map.csv``): the writer before issue 22 against the vectorised one, and candidates.

Run from the repository root: ``PYTHONPATH=src python benchmarks/map_csv.py`` (``--side 200`` for a
quicker run). Writes ``benchmarks/results/map_csv.json`` and prints it. The table is synthetic, shaped as a
UR5 plane's ``map_<scenario>.csv``: per target position, reachable, the figures, the dominant joint, ratio and
difference to the reference, grid coordinates, six ``q`` and six normal forces, the reason (26 float columns, NaN
where a target is unreachable, one boolean, two text columns), written block by block as the writer does.
Figures:

* ``whole_table``: seconds and ns per cell to write the whole file, before (``repr`` per cell, ``csv.writer``)
  and now (:func:`~tribokin.output.writers.table_lines`), and whether the bytes are identical;
* ``worst_case``: the same with every float in 1e-9 <= |x| < 1e-4, where the writer falls back to ``repr``
  (a third of the side);
* ``float_formatting``: ns per float to turn one block's float columns into text: cells by ``repr`` or numpy's
  ``astype(str)`` (Dragon4, no lines joined), orjson (``OPT_SERIALIZE_NUMPY``) a column at a time joined into lines
  by ``csv.writer`` or by ``",".join``, and :func:`~tribokin.output.writers.float_lines` (orjson on the columns
  stacked, a line per row, ``repr`` on rows where the styles differ), what the writer does.

Timings are wall clock on whatever machine runs this: compare ratios measured in the same run.
"""

from __future__ import annotations

import argparse
import csv
import io
import json
import os
import platform
import tempfile
import time
from pathlib import Path

import numpy as np
import orjson

from tribokin.maps.streaming import blocks
from tribokin.output.writers import float_lines, header_line, table_lines

RESULTS = Path(__file__).resolve().parent / "results" / "map_csv.json"
JOINTS = ("shoulder_pan", "shoulder_lift", "elbow", "wrist_1", "wrist_2", "wrist_3")
REASONS = np.array(["", "no inverse kinematics solution, closest 12.5 mm, 3.2 deg",
                    "beyond joint limits (wrist_2, \"hard\" stop)"], dtype=object)


def synthetic_columns(rng: np.random.Generator, part: slice, side: int, tiny: bool = False) -> dict[str, np.ndarray]:
    """One block of a UR5-like scenario table; ``tiny``: every float in 1e-9 <= |x| < 1e-4."""
    n = part.stop - part.start
    index = np.arange(part.start, part.stop)
    u, v = -0.4 + 0.8 * (index % side) / (side - 1), 0.3 * (index // side) / (side - 1)
    reachable = rng.random(n) > 0.15

    def figure(scale: float) -> np.ndarray:
        return rng.lognormal(np.log(scale), 0.5, n) * np.where(reachable, 1.0, np.nan)

    columns = {"x_m": u, "y_m": v - 0.55, "z_m": np.full(n, 0.1), "reachable": reachable}
    columns.update({name: figure(scale) for name, scale in
                    (("RP_l_um", 20.0), ("AP_p_um", 5.0), ("RP_a_mdeg", 2.0), ("RP_b_mdeg", 2.0),
                     ("RP_c_mdeg", 3.0), ("largest_semi_axis_um", 9.0))})
    columns["dominant_joint"] = np.array([*JOINTS, ""], dtype=object)[np.where(reachable, rng.integers(0, 6, n), 6)]
    columns["dominant_share"] = rng.random(n) * np.where(reachable, 1.0, np.nan)
    columns["RP_l_ratio"], columns["RP_l_diff_um"] = figure(1.0), figure(3.0) - 3.0
    columns["u_m"], columns["v_m"] = u, v
    columns.update({f"q_{joint}": np.where(reachable, rng.uniform(-np.pi, np.pi, n), np.nan)
                    for joint in JOINTS})
    columns.update({f"normal_force_{joint}_N": figure(80.0) for joint in JOINTS})
    columns["reason"] = REASONS[np.where(reachable, 0, rng.integers(1, 3, n))]
    if tiny:
        columns.update({name: np.copysign(10.0 ** rng.uniform(-9, -4, n), values) for name, values in columns.items()
                        if values.dtype.kind == "f"})
    return columns


def before_cell(value) -> str:
    """A cell as the writer before issue 22 wrote it: floats by ``repr``, NaN empty, booleans true/false."""
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    if isinstance(value, (float, np.floating)):
        return "" if np.isnan(value) else repr(float(value))
    return str(value)


def write_before(handle, columns: dict) -> None:
    text = io.StringIO(newline="")
    csv.writer(text).writerows([before_cell(v) for v in row] for row in zip(*columns.values(), strict=True))
    handle.write(text.getvalue().encode())


def write_now(handle, columns: dict) -> None:
    handle.writelines(table_lines(columns))


def write_table(path: Path, side: int, write_block, tiny: bool) -> float:
    """Seconds to write the table at ``path`` block by block (building the blocks not counted)."""
    rng, seconds = np.random.default_rng(7), 0.0
    with open(path, "wb") as handle:
        for part in blocks(side * side):
            columns = synthetic_columns(rng, part, side, tiny)
            start = time.perf_counter()
            if part.start == 0:
                handle.write(header_line(columns))
            write_block(handle, columns)
            seconds += time.perf_counter() - start
    return seconds


def compare_writers(side: int, tiny: bool = False) -> dict:
    cells = side * side * len(synthetic_columns(np.random.default_rng(0), slice(0, 2), side))
    with tempfile.TemporaryDirectory() as folder:
        before, now = Path(folder) / "before.csv", Path(folder) / "now.csv"
        before_s = write_table(before, side, write_before, tiny)
        now_s = write_table(now, side, write_now, tiny)
        identical = before.read_bytes() == now.read_bytes()
        size = now.stat().st_size
    return {"rows": side * side, "cells": cells, "MB": size / 1e6, "identical_bytes": identical,
            "before": {"seconds": before_s, "ns_per_cell": before_s / cells * 1e9},
            "now": {"seconds": now_s, "ns_per_cell": now_s / cells * 1e9}, "speed_up": before_s / now_s}


def orjson_columns(columns: list[np.ndarray]) -> list[list[str]]:
    """Candidate: each float column's cells from orjson alone (``1e-9`` where ``repr`` writes ``1e-09``)."""
    return [orjson.dumps(values, option=orjson.OPT_SERIALIZE_NUMPY)[1:-1].decode().replace("null", "").split(",")
            for values in columns]


def float_formatting(side: int, rows: int = 4096) -> dict:
    """ns per float of each way to turn one block's float columns into CSV text, ``rows`` lines at a time as
    ``table_lines`` does (the whole block at once for ``repr`` and numpy)."""
    columns = synthetic_columns(np.random.default_rng(1), next(iter(blocks(side * side))), side)
    floats = [values for values in columns.values() if values.dtype.kind == "f"]
    count = sum(values.size for values in floats)

    def ns(text_of) -> float:
        best = np.inf
        for _ in range(3):
            start = time.perf_counter()
            for part in blocks(floats[0].size, rows):
                text_of([values[part] for values in floats])
            best = min(best, time.perf_counter() - start)
        return best / count * 1e9

    return {
        "floats": count,
        "repr_cells_ns": ns(lambda part: [[repr(x) for x in values.tolist()] for values in part]),
        "numpy_astype_str_cells_ns": ns(lambda part: [values.astype(str) for values in part]),
        "orjson_per_column_csv_writer_ns": ns(lambda part: csv.writer(io.StringIO()).writerows(
            zip(*orjson_columns(part), strict=True))),
        "orjson_per_column_join_ns": ns(
            lambda part: "\r\n".join(map(",".join, zip(*orjson_columns(part), strict=True)))),
        "float_lines_ns": ns(lambda part: b"\r\n".join(float_lines(np.column_stack(part)))),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--side", type=int, default=600, help="targets per side of the plane (default 600)")
    args = parser.parse_args()
    results = {
        "machine": {"python": platform.python_version(), "cpus": os.cpu_count(), "platform": platform.platform(),
                    "numpy": np.__version__, "orjson": orjson.__version__},
        "table": {"side": args.side, "float_columns": 26, "bool_columns": 1, "text_columns": 2},
        "float_formatting": float_formatting(args.side),
        "whole_table": compare_writers(args.side),
        "worst_case": compare_writers(args.side // 3, tiny=True),
    }
    RESULTS.parent.mkdir(exist_ok=True)
    RESULTS.write_text(json.dumps(results, indent=2) + "\n")
    print(json.dumps(results, indent=2))


if __name__ == "__main__":
    main()
