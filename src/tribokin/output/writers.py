"""Writing a study's results into an output folder: ``summary.json``, ``poses.csv``, ``samples.npz``,
the map's tables, the placement's table and best study, the figures, the report and the scene."""

from __future__ import annotations

import csv
import io
import re
import shutil
from collections.abc import Callable, Iterator
from concurrent.futures import Executor
from contextlib import ExitStack
from itertools import groupby
from pathlib import Path

import numpy as np
import orjson

from tribokin.errors import import_extra
from tribokin.execution import local_pool, run_chunks
from tribokin.maps.result import MapResult, ScenarioMap
from tribokin.maps.streaming import blocks
from tribokin.maps.table import map_table_columns, map_table_name
from tribokin.output.dispatch import folder_writer
from tribokin.output.folder import atomic_folder
from tribokin.output.json_files import write_json
from tribokin.output.placed_study import BEST_STUDY, best_study_text
from tribokin.output.views_process import ViewsProcess
from tribokin.placement.result import PlacementResult
from tribokin.run import StudyResult
from tribokin.simulation.pose_result import pose_table_row
from tribokin.study.names import TABLE_FORMATS


def write_summary(result: StudyResult, folder: Path) -> None:
    """``summary.json``: settings and per-pose figures."""
    write_json(result.summary(), folder / "summary.json")


def write_rows(rows: list[dict], joints: list[str], path: Path) -> None:
    """A ``poses.csv``-shaped table at ``path``: report rows flattened as :func:`~tribokin.simulation.pose_result.
    pose_table_row` does, the
    columns in order of first appearance (used by ``run`` and ``measure``)."""
    flat = [pose_table_row(row, joints) for row in rows]
    columns = list(dict.fromkeys(key for row in flat for key in row))
    with open(path, "w", newline="", encoding="utf-8") as handle:
        writer = csv.DictWriter(handle, fieldnames=columns)
        writer.writeheader()
        writer.writerows(flat)


def write_pose_table(result: StudyResult, folder: Path) -> None:
    """``poses.csv``: one row per pose and approach direction
    (:meth:`~tribokin.simulation.pose_result.PoseResult.direction_rows`),
    the scalar figures (µm, mdeg) and positions (m) flattened."""
    write_rows([row for pose in result.poses for row in pose.direction_rows()], result.settings["joints"],
               folder / "poses.csv")


def write_samples(result: StudyResult, folder: Path) -> None:
    """``samples.npz``: per pose ``<pose>/positions_m`` (n, 3), ``angles_rad``, ``dq``, ``mu`` (every direction's
    cycles), ``approach`` (n,) each cycle's index into ``directions``, the approach directions' labels."""
    arrays = {}
    for pose in result.poses:
        arrays.update({f"{pose.name}/{name}": values for name, values in pose.samples().items()})
        arrays[f"{pose.name}/directions"] = np.array(pose.directions)
    np.savez_compressed(folder / "samples.npz", **arrays)


#: A float column whose cells ``repr`` must write (:func:`float_lines`) make up more than this share of its rows is
#: formatted as a column of cells (its rows joined to the others' after), not by splitting each of those rows.
REPR_COLUMN_SHARE = 1 / 64


def float_lines(values: np.ndarray) -> list[bytes]:
    """Each row of an (n, k) float array as CSV cells (UTF-8) joined by commas, every float as ``repr`` writes it, NaN
    empty: orjson's shortest round-trip digits, or ``repr`` for the cells whose styles differ (±inf, and
    1e-9 <= |value| < 1e-4, which orjson writes ``1e-9``, ``0.00001``). A column where such cells are common (more than
    ``REPR_COLUMN_SHARE`` of its rows: a map's small relative errors) is formatted on its own (:func:`_float_cells`)
    and joined to its neighbours' lines; elsewhere only the rows holding such cells are split into their cells, those
    cells written by ``repr``, and joined again."""
    values = np.ascontiguousarray(values, dtype=np.float64)
    magnitude = np.abs(values)
    styled = np.isinf(values) | ((magnitude >= 1e-9) & (magnitude < 1e-4))
    apart = np.flatnonzero(styled.sum(axis=0) > REPR_COLUMN_SHARE * len(values))
    if not len(apart):
        return _float_rows(values, styled)
    pieces, start = [], 0
    for column in [*apart.tolist(), values.shape[1]]:
        if column > start:
            pieces.append(_float_rows(values[:, start:column], styled[:, start:column]))
        if column < values.shape[1]:
            pieces.append(_float_cells(values[:, column]))
        start = column + 1
    return list(map(b",".join, zip(*pieces, strict=True)))


def _float_rows(values: np.ndarray, styled: np.ndarray) -> list[bytes]:
    """:func:`float_lines` of ``values`` (n, k), ``styled`` (n, k) the cells ``repr`` writes: a row of NaN only is
    commas, and only rows with some NaN are searched for orjson's ``null``."""
    values = np.ascontiguousarray(values)
    lines = orjson.dumps(values, option=orjson.OPT_SERIALIZE_NUMPY)[2:-2].split(b"],[")
    missing = np.isnan(values)
    empty = missing.all(axis=1)
    for i in np.flatnonzero(empty).tolist():
        lines[i] = b"," * (values.shape[1] - 1)
    for i in np.flatnonzero(missing.any(axis=1) & ~empty).tolist():
        lines[i] = lines[i].replace(b"null", b"")
    rows, columns = np.nonzero(styled)
    cells = {}  # the rows holding such cells, split into their cells
    for i, j, value in zip(rows.tolist(), columns.tolist(), values[rows, columns].tolist(), strict=True):
        if i not in cells:
            cells[i] = lines[i].split(b",")
        cells[i][j] = repr(value).encode()
    for i, row in cells.items():
        lines[i] = b",".join(row)
    return lines[:len(values)]  # no rows: "[]" splits into one empty line


#: orjson's styles that ``repr`` writes otherwise, in a column's text: one-digit negative exponents (``1e-9``:
#: ``1e-09``), and positional values below 1e-4 (``0.000015``: ``1.5e-05``), one digit or more.
_ONE_DIGIT_EXPONENT = re.compile(rb"e-(\d)(?=[,\]])")
_POSITIONAL_DIGIT = re.compile(rb"(?<=[\[,-])0\.0000(\d)(?=[,\]])")
_POSITIONAL_DIGITS = re.compile(rb"(?<=[\[,-])0\.0000(\d)(\d+)")


def _float_cells(values: np.ndarray) -> list[bytes]:
    """The cells of a float column ``values`` (n,) as :func:`float_lines` writes them: orjson's text with its styles
    turned into ``repr``'s (the same shortest digits) in three passes over the whole column; ±inf by ``repr``, NaN
    empty."""
    values = np.ascontiguousarray(values)
    text = orjson.dumps(values, option=orjson.OPT_SERIALIZE_NUMPY)
    text = _ONE_DIGIT_EXPONENT.sub(rb"e-0\1", text)
    text = _POSITIONAL_DIGITS.sub(rb"\1.\2e-05", _POSITIONAL_DIGIT.sub(rb"\1e-05", text))
    cells = text[1:-1].split(b",")[:len(values)]
    for i, value in zip(np.flatnonzero(np.isinf(values)).tolist(), values[np.isinf(values)].tolist(), strict=True):
        cells[i] = repr(value).encode()
    for i in np.flatnonzero(np.isnan(values)).tolist():
        cells[i] = b""
    return cells


def header_line(names) -> bytes:
    r"""The CSV header line (UTF-8, ``\r\n``-terminated) of columns ``names``, as ``csv.writer`` writes it."""
    text = io.StringIO(newline="")
    csv.writer(text).writerow(names)
    return text.getvalue().encode()


def text_cell(text: str) -> str:
    """A CSV cell of text, quoted as ``csv.writer`` (default dialect) quotes it: when it holds a comma, a quote
    (doubled) or a line break."""
    return '"' + text.replace('"', '""') + '"' if any(c in text for c in ',"\r\n') else text


def column_cells(values: np.ndarray) -> list[bytes]:
    """CSV cells (UTF-8) of a column of booleans (true/false) or of text (:func:`text_cell`)."""
    if values.dtype.kind == "b":
        return np.array([b"false", b"true"], dtype=object)[values.astype(np.intp)].tolist()
    cells = [str(value) for value in values.tolist()]
    quoted = {text: text_cell(text).encode() for text in set(cells)}
    return [quoted[text] for text in cells]


def table_lines(columns: dict[str, np.ndarray], rows: int = 4096) -> Iterator[bytes]:
    r"""The CSV lines (UTF-8, ``\r\n``-terminated, as ``csv.writer``) of equally long ``columns``, ``rows`` lines at
    a time: consecutive float columns together (:func:`float_lines`), the others a column at a time
    (:func:`column_cells`)."""
    runs = [(floating, list(run)) for floating, run in groupby(columns.values(), key=lambda v: v.dtype.kind == "f")]
    for part in blocks(len(next(iter(columns.values()))), rows):
        pieces = []
        for floating, run in runs:
            if floating:
                pieces.append(float_lines(np.column_stack([values[part] for values in run])))
            else:
                pieces.extend(column_cells(values[part]) for values in run)
        yield b"\r\n".join(map(b",".join, zip(*pieces, strict=True))) + b"\r\n"


#: Bytes a part file of a map table is copied into its table at a time.
PART_COPY_BYTES = 1 << 20
#: Targets of a map table read from the store at once (their columns and reasons in memory together), a block
#: formatted by one worker.
TABLE_TARGETS = 1 << 14


def map_table_text(workspace_map: MapResult, scenario: ScenarioMap, targets: slice) -> bytes:
    """The lines (UTF-8) of ``scenario``'s map table at ``targets``, without the header (:func:`table_lines`)."""
    return b"".join(table_lines(map_table_columns(workspace_map, scenario, targets)))


def write_map_table_part(workspace_map: MapResult, scenario: ScenarioMap, targets: slice, path: Path) -> None:
    """:func:`map_table_text` written to file ``path`` (by a worker: the text stays out of the pipes)."""
    path.write_bytes(map_table_text(workspace_map, scenario, targets))


def write_map_tables(workspace_map: MapResult, tables: list[tuple[ScenarioMap, Path]],
                     executor: Executor | None = None, meanwhile: Callable[[], None] | None = None,
                     table_format: str = "csv") -> None:
    """Each scenario's map as CSV (``tables``: scenario and path), one row per target in index order, the columns of
    :func:`~tribokin.maps.table.map_table_columns`; or, in ``table_format`` ``"parquet"``, as Parquet
    (:func:`write_parquet_table`, here, after ``meanwhile()``).

    ``TABLE_TARGETS`` targets are read at a time. When ``executor`` is a pool of this machine's processes
    (:func:`~tribokin.execution.local_pool`: they read the map's store), its workers format the blocks, each into a
    part file beside its table (``.<table>.<block>.part``), which is appended to the table and deleted in order while
    ``meanwhile()`` runs here; else the blocks are formatted here (:func:`map_table_text`), after ``meanwhile()``."""
    if table_format == "parquet":
        if meanwhile is not None:
            meanwhile()
        for scenario, path in tables:
            write_parquet_table(workspace_map, scenario, path)
        return
    parts = list(workspace_map.blocks(TABLE_TARGETS))
    pool = local_pool(executor)

    def part_path(t: int, k: int) -> Path:
        return tables[t][1].with_name(f".{tables[t][1].name}.{k}.part")

    todo = {(t, k): (workspace_map, scenario, part) + ((part_path(t, k),) if pool is not None else ())
            for t, (scenario, _) in enumerate(tables) for k, part in enumerate(parts)}
    function = map_table_text if pool is None else write_map_table_part
    with run_chunks(function, todo, pool) as texts, ExitStack() as files:
        if meanwhile is not None:
            meanwhile()
        handles = []
        for scenario, path in tables:
            handles.append(files.enter_context(open(path, "wb")))
            handles[-1].write(header_line(map_table_columns(workspace_map, scenario, slice(0, 0))))
        written, waiting = [0] * len(tables), {}
        for key, text in texts:
            waiting[key] = text
            for t, handle in enumerate(handles):
                while (t, written[t]) in waiting:
                    text = waiting.pop((t, written[t]))
                    if text is None:
                        with open(part_path(t, written[t]), "rb") as part:
                            shutil.copyfileobj(part, handle, PART_COPY_BYTES)
                        part_path(t, written[t]).unlink()
                    else:
                        handle.write(text)
                    written[t] += 1


def write_map_table(workspace_map: MapResult, scenario: ScenarioMap, path: Path, table_format: str = "csv") -> None:
    """One scenario's map as CSV (or Parquet: ``table_format``), written here (:func:`write_map_tables`)."""
    write_map_tables(workspace_map, [(scenario, path)], table_format=table_format)


#: Parquet's compression of a map table's columns (pyarrow's default, named here: the bytes depend on it).
PARQUET_COMPRESSION = "snappy"


def arrow_table(columns: dict[str, np.ndarray]):
    """A ``pyarrow.Table`` of a map table's ``columns`` (:func:`~tribokin.maps.table.map_table_columns`): float64
    (NaN as NaN, not null), bool, or string (the object columns)."""
    pa = import_extra("pyarrow", "--table-format parquet")
    return pa.table({name: pa.array(values, type=pa.string()) if values.dtype == object else pa.array(values)
                     for name, values in columns.items()})


def write_parquet_table(workspace_map: MapResult, scenario: ScenarioMap, path: Path) -> None:
    """``scenario``'s map table as a Parquet file at ``path``: the columns of
    :func:`~tribokin.maps.table.map_table_columns`, typed (:func:`arrow_table`), one row group per ``TABLE_TARGETS``
    targets, ``PARQUET_COMPRESSION``; no time or host in it, so the same map gives the same bytes (with the same
    pyarrow, whose version the file records)."""
    parquet = import_extra("pyarrow.parquet", "--table-format parquet")
    with ExitStack() as stack:
        writer = None
        for part in workspace_map.blocks(TABLE_TARGETS):
            table = arrow_table(map_table_columns(workspace_map, scenario, part))
            if writer is None:
                writer = stack.enter_context(parquet.ParquetWriter(path, table.schema,
                                                                   compression=PARQUET_COMPRESSION))
            writer.write_table(table, row_group_size=TABLE_TARGETS)


def write_placement(placement: PlacementResult, folder: Path, out: Path) -> None:
    """``placement.csv`` (one row per candidate, best first: :meth:`~tribokin.placement.result.PlacementResult.columns`)
    and ``best.toml`` (:func:`~tribokin.output.placed_study.best_study_text`, its paths relative to ``out``)."""
    columns = placement.columns()
    with open(folder / "placement.csv", "wb") as handle:
        handle.write(header_line(columns))
        handle.writelines(table_lines(columns))
    (folder / BEST_STUDY).write_text(best_study_text(placement, Path(out)), encoding="utf-8")


def import_views() -> None:
    """Import what :func:`write_results` draws with (matplotlib, meshcat: about half a second) ahead of it, for a
    process that has the time now: one waiting for a map's workers (:func:`~tribokin.run.run_study`'s
    ``meanwhile``) and that draws the views itself (no :class:`~tribokin.output.views_process.ViewsProcess`)."""
    import tribokin.viz.contents  # noqa: F401


@folder_writer.register(StudyResult)
def write_results(result: StudyResult, out, force: bool = False, report: str = "full", map_layers=None,
                  cube=None, executor: Executor | None = None, views: ViewsProcess | None = None,
                  table_format: str = "csv") -> Path:
    """Write summary.json, the pose files (poses.csv, samples.npz), the map tables (map*.csv, or map*.parquet in
    ``table_format`` ``"parquet"``) or the placement's files (placement.csv, best.toml) to ``out``, atomically, with
    the figures and, unless ``report`` is ``"none"``, ``report.html`` and ``scene.npz``, as
    :func:`~tribokin.viz.contents.write_views` decides (``report``, ``map_layers``, ``cube``: see there).

    The views are drawn by ``views`` (:class:`~tribokin.output.views_process.ViewsProcess`; closed here) while this
    process writes the rest, else here; the map's tables' blocks (:func:`write_map_tables`) and its statistics
    (:meth:`~tribokin.maps.result.MapResult.summarise_on`, sent on to ``views`` for the report) are computed on
    ``executor``'s local workers meanwhile (without them, by ``views``, or here).
    """
    if table_format not in TABLE_FORMATS:
        raise ValueError(f"table_format {table_format!r}: choose one of {', '.join(TABLE_FORMATS)}")
    if table_format == "parquet" and result.map is not None:
        import_extra("pyarrow.parquet", "--table-format parquet")  # before anything is written
    with atomic_folder(out, force) as folder:
        try:
            pool = local_pool(executor) if result.map is not None else None
            if pool is not None:
                result.map.summarise_on(pool)  # the map's statistics meanwhile, on a worker
            drawing = views is not None and views.draw(result, folder, report, map_layers, cube, pool is not None)

            def the_rest() -> None:
                if result.poses:
                    write_pose_table(result, folder)
                    write_samples(result, folder)
                if result.placement is not None:
                    write_placement(result.placement, folder, Path(out))
                if not drawing:
                    _write_views(result, folder, report, map_layers, cube)
                elif pool is not None:
                    views.send_statistics(result.map.statistics())

            if result.map is None:
                the_rest()
            else:
                write_map_tables(result.map, [(scenario, folder / map_table_name(result.map, scenario, table_format))
                                              for scenario in result.map.scenarios.values()], executor, the_rest,
                                 table_format)
            if drawing:
                drawn, statistics = views.wait()
                if not drawn:  # the views' process was lost, or declined: drawn here instead
                    _write_views(result, folder, report, map_layers, cube)
                elif statistics is not None:
                    result.map.use_statistics(statistics)
            write_summary(result, folder)
        finally:
            if views is not None:
                views.close()
    return Path(out)


def _write_views(result: StudyResult, folder: Path, report: str, map_layers, cube) -> None:
    from tribokin.viz.contents import write_views  # matplotlib and meshcat: imported when first drawn here

    write_views(result, folder, report, map_layers, cube)
