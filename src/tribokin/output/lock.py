"""One run at a time per output folder: an exclusive lock on ``<out>.lock`` beside the folder.

The lock is a ``flock`` on that file, held for the whole run (computation, chunks, writing) and
removed when the run ends. The kernel releases a ``flock`` when its process ends, however it ends,
so a file left behind by a killed run locks nothing: the next run takes it over. A process forked
while the lock is held (a local worker) closes its copy of the lock's descriptor at once, so the
lock ends with the run, not with its longest-lived child. ``flock`` is local to one machine: on a
network file system, do not run two machines into one folder.
"""

from __future__ import annotations

import fcntl
import os
from contextlib import contextmanager, suppress
from pathlib import Path

from tribokin.errors import InputError
from tribokin.output.folder import DISK_FULL, check_output_folder, disk_full, remove_leftovers

#: Descriptors of the lock files this process holds.
_held: set[int] = set()


def _close_held() -> None:
    """In a forked child: close the inherited lock descriptors (closing, unlike unlocking, leaves the
    parent's lock in place)."""
    for fd in _held:
        with suppress(OSError):
            os.close(fd)
    _held.clear()


os.register_at_fork(after_in_child=_close_held)


def lock_path(out) -> Path:
    """The lock file of output folder ``out``: ``<out>.lock`` beside it."""
    out = Path(out)
    return out.with_name(out.name + ".lock")


def _holder(fd: int) -> str:
    """`` (pid 1234 on host)`` as the holder wrote it in the lock file, or ``""``."""
    os.lseek(fd, 0, os.SEEK_SET)
    words = os.read(fd, 200).decode(errors="replace").split()
    return f" (pid {words[0]} on {words[1]})" if len(words) >= 2 else ""


def _is_the_file_at(fd: int, path: Path) -> bool:
    """Whether ``fd`` is still the file at ``path`` (a finishing run may have removed it meanwhile)."""
    try:
        return os.stat(path).st_ino == os.fstat(fd).st_ino
    except FileNotFoundError:
        return False


def _acquire(out: Path) -> int:
    """Open and lock ``<out>.lock``; an :class:`InputError` if another process holds it."""
    path = lock_path(out)
    while True:
        try:
            fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as error:
            raise InputError(f"cannot create the lock file '{path}' ({error.strerror}); choose another --out",
                             out, "--out") from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = _holder(fd)
            os.close(fd)
            raise InputError(f"another tribokin run{holder} is writing this output folder (lock file '{path}'); "
                             "wait until it ends or choose another --out (a lock left by a killed run is taken "
                             "over by the next run)", out, "--out") from None
        if _is_the_file_at(fd, path):
            return fd
        os.close(fd)  # locked a file its holder had just removed: lock the one at the path now


@contextmanager
def output_lock(out):
    """Hold ``<out>.lock`` while the block runs; refuse (``InputError``, ``--out``) if another run holds it."""
    out = Path(out)
    fd = _acquire(out)
    _held.add(fd)
    try:
        os.ftruncate(fd, 0)
        try:
            os.write(fd, f"{os.getpid()} {os.uname().nodename}\n".encode())
        except OSError as error:
            if error.errno in DISK_FULL:
                raise disk_full(error, out, "a few bytes for the lock file") from None
            raise
        yield lock_path(out)
    finally:
        with suppress(FileNotFoundError):
            os.unlink(lock_path(out))  # still locked: no other run can have taken it meanwhile
        _held.discard(fd)
        os.close(fd)


@contextmanager
def claimed_folder(out, force: bool = False):
    """Check output folder ``out`` (:func:`~tribokin.output.folder.check_output_folder`), hold its lock while the block
    runs, and first delete the temporary folders a killed run left beside it; yields the folder from which an output
    folder a killed ``--force`` run had moved aside was moved back (``None``: none was)."""
    check_output_folder(out, force)
    with output_lock(out):
        yield remove_leftovers(out)


def write_claimed(write, result, out, force: bool = False, **options) -> Path:
    """``write(result, out, force, **options)`` (a writer of the whole folder, all at once) as the commands write:
    ``out``'s lock held (:func:`claimed_folder`), the temporary folders a killed run left beside it deleted first
    (a result's ``write`` method, through :func:`tribokin.output.dispatch.write_folder`)."""
    with claimed_folder(out, force):
        return write(result, out, force, **options)
