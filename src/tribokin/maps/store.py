"""A map's per-target results on disk: written as chunks finish, read back block by block.

The store is a folder holding ``manifest.json`` (a fingerprint of the settings that determine the
numbers), one ``<column>.npy`` per result column over all targets, a marker ``done/<k>`` per finished
chunk (written once the chunk's rows are flushed to disk, by the process that computed them: a local worker or
this one), and records of later steps
(``<name>.npz``, each written under a temporary name and renamed, so complete or absent). A run
killed at any point leaves only finished work marked, which ``--resume`` keeps.

A temporary store (a map's without ``--resume``: a placement's candidates, a calibration's map) lives in
``$TMPDIR/tribokin-map-XXXX``, deleted with its store object; its run holds an ``flock`` on the folder's
``owner.lock`` (its process id inside) while it lives, which the system releases when the run ends however it ends.
A run killed before deleting its folder leaves it unlocked, and the next temporary store removes it
(:func:`remove_stale_stores`); another live run's store stays locked, and is never touched.

Columns are read through a memory map opened for each read and closed after it, so reading a
large map never holds more of it in memory than the block asked for; a few scattered targets (hole filling's
neighbours) are read with one ``pread`` each. Each column file's header is parsed once.
"""

from __future__ import annotations

import fcntl
import hashlib
import json
import math
import os
import shutil
import stat
import tempfile
import weakref
from contextlib import contextmanager
from pathlib import Path

import numpy as np
from numpy.lib.format import open_memmap, read_array_header_1_0, read_array_header_2_0, read_magic

from tribokin.errors import InputError
from tribokin.output.folder import DISK_FULL, disk_full, remove, temporary_sibling, temporary_siblings
from tribokin.units import gib

#: Temporary stores' folders under ``$TMPDIR``: this prefix, then random characters.
TEMPORARY_PREFIX = "tribokin-map-"
#: The file of a temporary store's folder its run holds locked while it lives.
OWNER_FILE = "owner.lock"
#: Rows of a column file a scattered read maps at once.
READ_ROWS = 1 << 16
#: Scattered reads of at most this many targets read each with ``pread`` instead of a memory map.
PREAD_TARGETS = 64


def chunk_folder(out) -> Path:
    """The chunk folder of output folder ``out``: ``<out>.chunks`` beside it."""
    out = Path(out)
    return out.with_name(out.name + ".chunks")


def check_chunk_folder(folder, resume: bool) -> None:
    """Refuse, without ``resume``, a chunk folder an interrupted run left (nothing is deleted unasked)."""
    if Path(folder).exists() and not resume:
        raise InputError("an interrupted run left its finished chunks here; pass --resume to finish it or --force "
                         "to start over", folder, "--resume")


def discard(folder) -> None:
    """Delete a chunk folder (once the results are written, or to start over), and the temporary folders
    a killed run left beside it. It is renamed aside first: a run killed meanwhile leaves it whole or gone."""
    folder = Path(folder)
    for leftover in temporary_siblings(folder, "new") + temporary_siblings(folder, "old"):
        remove(leftover)
    if folder.exists():
        retired = temporary_sibling(folder, "old")
        os.replace(folder, retired / folder.name)
        remove(retired)


def fingerprint(settings: dict) -> str:
    """SHA-256 of ``settings`` as canonical JSON."""
    return hashlib.sha256(json.dumps(settings, sort_keys=True, default=str).encode()).hexdigest()


def row_bytes(columns: dict[str, tuple[tuple, str]]) -> int:
    """Bytes one target takes in columns ``name -> (shape of one target's value, dtype)``."""
    return sum(math.prod(shape) * np.dtype(dtype).itemsize for shape, dtype in columns.values())


def _column_path(folder: Path, name: str) -> Path:
    return folder / f"{name}.npy"


def _reserve(path: Path) -> None:
    """Allocate the disk space of file ``path`` now, so that writing into it through a memory map cannot
    fail for lack of space later (the process would get SIGBUS, not an error)."""
    if hasattr(os, "posix_fallocate"):
        with open(path, "r+b") as handle:
            os.posix_fallocate(handle.fileno(), 0, os.fstat(handle.fileno()).st_size)


class ChunkStore:
    """Per-target result columns of a map, in ``folder``.

    The folder is built beside its place and renamed into it once its columns (their disk space
    reserved) and manifest are written, so it is whole or absent. A folder deleted or damaged while a
    run uses it, or a full disk, is an :class:`InputError`.

    Args:
        folder: the store's folder.
        key: fingerprint of the settings the results are computed with.
        columns: ``name -> (shape of one target's value, dtype)``, e.g. ``{"q": ((6,), "f8")}``.
        size: number of targets.
        resume: keep the chunks of an earlier, interrupted run with the same ``key``; without it an
            existing folder is an error.
    """

    def __init__(self, folder, key: str, columns: dict[str, tuple[tuple, str]], size: int, resume: bool = False):
        self.folder = Path(folder)
        self.size = size
        self._layouts = {}  # column name -> (dtype, shape, data offset) of its file
        check_chunk_folder(self.folder, resume)
        if self.folder.exists():
            self._check_resumable(key, columns)
        else:
            self._create(key, columns)

    def _check_resumable(self, key: str, columns: dict) -> None:
        manifest = self.folder / "manifest.json"
        saved = json.loads(manifest.read_text()).get("key") if manifest.is_file() else None
        if saved is not None and saved != key:
            raise InputError("these chunks were computed with other settings (study file, cycles, seed, "
                             "chunk size or kernel path, TRIBOKIN_KERNELS); rerun with the same ones, or pass "
                             "--force without --resume to start over", self.folder, "--resume")
        parts = [manifest, self.folder / "done", *(_column_path(self.folder, name) for name in columns)]
        missing = [path.name for path in parts if not path.exists()]
        if missing:
            raise InputError(f"this chunk folder lacks {', '.join(missing)} (damaged or partly deleted); pass "
                             "--force without --resume to start over", self.folder, "--resume")

    def _create(self, key: str, columns: dict) -> None:
        discard(self.folder)  # the temporary folders of a killed creation
        building = temporary_sibling(self.folder, "new")
        try:
            (building / "done").mkdir()
            for name, (shape, dtype) in columns.items():
                path = _column_path(building, name)
                open_memmap(path, mode="w+", dtype=dtype, shape=(self.size, *shape))  # sparse until written
                _reserve(path)
            (building / "manifest.json").write_text(json.dumps({"key": key}) + "\n")
            os.rename(building, self.folder)
        except OSError as error:
            if error.errno in DISK_FULL:
                needed = self.size * row_bytes(columns)
                raise disk_full(error, self.folder, f"about {gib(needed)} for the map's store") from None
            raise
        finally:
            remove(building)

    @contextmanager
    def _intact(self):
        """Turn a file of the store gone missing, or a full disk, into an :class:`InputError`."""
        try:
            yield
        except FileNotFoundError as error:
            raise InputError(f"{os.path.relpath(error.filename, self.folder)} is gone: the chunk folder was deleted "
                             "or damaged while this run used it; run again (with --force to start over)",
                             self.folder) from None
        except OSError as error:
            if error.errno in DISK_FULL:
                raise disk_full(error, self.folder, "more than the space reserved for the map's store") from None
            raise

    def _path(self, name: str) -> Path:
        return _column_path(self.folder, name)

    def finished(self) -> list[int]:
        """Indices of the chunks already saved."""
        with self._intact():
            return sorted(int(p.name) for p in (self.folder / "done").iterdir())

    def write(self, index, arrays: dict[str, np.ndarray]) -> None:
        """Write ``arrays`` (column name -> values) at targets ``index`` (a slice or indices), flushed to disk."""
        with self._intact():
            for name, values in arrays.items():
                column = open_memmap(self._path(name), mode="r+")
                column[index] = values
                column.flush()
                del column

    def save(self, chunk: int, first: int, arrays: dict[str, np.ndarray]) -> None:
        """Write chunk ``chunk``'s arrays (targets ``first`` on), then mark it finished."""
        self.write(slice(first, first + len(next(iter(arrays.values())))), arrays)
        with self._intact():
            (self.folder / "done" / str(chunk)).touch()

    def _layout(self, name: str) -> tuple[np.dtype, tuple, int]:
        """(dtype, shape, offset of the data) of column ``name``'s file, from its header, parsed once."""
        if name not in self._layouts:
            with self._intact(), open(self._path(name), "rb") as handle:
                version = read_magic(handle)
                header = read_array_header_1_0 if version == (1, 0) else read_array_header_2_0
                shape, _, dtype = header(handle)
                self._layouts[name] = dtype, shape, handle.tell()
        return self._layouts[name]

    def _mapped(self, name: str, take) -> np.ndarray:
        """``take(column)`` of column ``name``, copied out of a memory map closed before returning, so
        the column's pages it touched do not stay in this process's memory."""
        dtype, shape, offset = self._layout(name)
        with self._intact():
            column = np.memmap(self._path(name), dtype=dtype, mode="r", offset=offset, shape=shape)
        values = np.array(take(column))
        del column
        return values

    def _pread(self, name: str, index: np.ndarray) -> np.ndarray:
        """Column ``name`` at the targets ``index`` (k,), each read with one ``pread``."""
        dtype, shape, offset = self._layout(name)
        index = np.where(index < 0, index + shape[0], index)  # from the end, as NumPy's indexing
        if np.any((index < 0) | (index >= shape[0])):
            raise IndexError(f"targets {index.tolist()} are not all within the {shape[0]} of column {name}")
        size = math.prod(shape[1:]) * dtype.itemsize
        with self._intact(), open(self._path(name), "rb", buffering=0) as handle:
            data = b"".join(os.pread(handle.fileno(), size, offset + int(i) * size) for i in index)
        return np.frombuffer(data, dtype=dtype).reshape(len(index), *shape[1:]).copy()

    def read(self, name: str, index=slice(None), item: int | None = None) -> np.ndarray:
        """Column ``name`` at targets ``index`` (a slice, an index, or indices), in memory; with ``item``, only that
        element of each target's value (one figure of a row of figures), the rest not copied. Scattered
        indices are read ``READ_ROWS`` rows of the file at a time (up to ``PREAD_TARGETS`` of them, one ``pread``
        each), so the pages a read touches stay bounded."""
        def take(rows):
            return (lambda column: column[rows]) if item is None else (lambda column: column[rows, item])

        if isinstance(index, slice):
            return self._mapped(name, take(index))
        if np.ndim(index) == 0:
            value = self._pread(name, np.array([index], dtype=np.intp))[0].reshape(self._layout(name)[1][1:])
            return value if item is None else value[item]
        index = np.asarray(index, dtype=np.intp)
        if len(index) <= PREAD_TARGETS:
            values = self._pread(name, index)
            return values if item is None else values[:, item]
        order = np.argsort(index, kind="stable")
        ordered = index[order]
        bounds = np.searchsorted(ordered, np.arange(0, self.size + READ_ROWS, READ_ROWS))
        pieces = [(lo, hi) for lo, hi in zip(bounds[:-1], bounds[1:], strict=True) if hi > lo]
        if not pieces:
            return self._mapped(name, take(index))
        values = None
        for lo, hi in pieces:
            part = self._mapped(name, take(ordered[lo:hi]))
            if values is None:
                values = np.empty((len(index), *part.shape[1:]), dtype=part.dtype)
            values[order[lo:hi]] = part
        return values

    def save_record(self, name: str, arrays: dict[str, np.ndarray]) -> None:
        """Keep ``arrays`` as record ``name``, atomically."""
        temporary = self.folder / f".{name}.tmp.npz"
        with self._intact():
            np.savez(temporary, **arrays)
            os.replace(temporary, self.folder / f"{name}.npz")

    def load_record(self, name: str) -> dict[str, np.ndarray] | None:
        """Record ``name``, or ``None`` if it was never saved."""
        path = self.folder / f"{name}.npz"
        if not path.is_file():
            return None
        with self._intact(), np.load(path) as saved:
            return {key: saved[key] for key in saved.files}


def _hold(folder: Path) -> int:
    """A descriptor of ``folder``'s :data:`OWNER_FILE`, locked by this process (its id written in): made under another
    name, locked, then renamed, so that a sweep never finds it unlocked while this process lives."""
    making = folder / f".{OWNER_FILE}.new"
    descriptor = os.open(making, os.O_RDWR | os.O_CREAT | os.O_EXCL | os.O_CLOEXEC, 0o600)
    fcntl.flock(descriptor, fcntl.LOCK_EX)
    os.write(descriptor, f"{os.getpid()}\n".encode())
    os.rename(making, folder / OWNER_FILE)
    return descriptor


def _release(folder: Path, descriptor: int) -> None:
    shutil.rmtree(folder, True)
    os.close(descriptor)


def remove_stale_stores(parent=None) -> list[Path]:
    """Delete the temporary stores killed runs left under ``parent`` (default ``$TMPDIR``): the folders
    ``tribokin-map-*`` of this user whose :data:`OWNER_FILE` no process holds locked. Symbolic links, other users'
    folders and folders without that file (being made, or left by an earlier tribokin) are left alone.

    Returns:
        the folders removed.
    """
    removed = []
    for folder in sorted(Path(parent or tempfile.gettempdir()).glob(f"{TEMPORARY_PREFIX}*")):
        try:
            info = os.lstat(folder)
            if not stat.S_ISDIR(info.st_mode) or info.st_uid != os.getuid():
                continue
            descriptor = os.open(folder / OWNER_FILE, os.O_RDONLY | os.O_NOFOLLOW | os.O_CLOEXEC)
        except OSError:
            continue
        try:
            fcntl.flock(descriptor, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:  # its run lives
            os.close(descriptor)
            continue
        shutil.rmtree(folder, True)
        os.close(descriptor)
        removed.append(folder)
    return removed


def temporary_store(key: str, columns: dict[str, tuple[tuple, str]], size: int) -> ChunkStore:
    """A :class:`ChunkStore` in a new temporary folder (under ``$TMPDIR``), held by this process and deleted with the
    store object; the stores killed runs left there are removed first (:func:`remove_stale_stores`)."""
    remove_stale_stores()
    folder = Path(tempfile.mkdtemp(prefix=TEMPORARY_PREFIX))
    descriptor = _hold(folder)
    try:
        store = ChunkStore(folder / "store", key, columns, size)
    except BaseException:
        _release(folder, descriptor)
        raise
    weakref.finalize(store, _release, folder, descriptor)
    return store
