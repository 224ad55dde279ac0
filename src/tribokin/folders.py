"""Folders made whole or not at all: temporary folders beside a folder, swapped in by a rename.

A folder is built as ``.<name>.<kind>-XXXX`` beside its final place and renamed (or exchanged) into
it; a run killed meanwhile leaves only such temporary folders, which the next run clears.
"""

from __future__ import annotations

import ctypes
import errno
import glob
import os
import shutil
import tempfile
from pathlib import Path

from tribokin.errors import InputError
from tribokin.units import gib

#: ``renameat2`` flag: exchange the two paths atomically (Linux).
_RENAME_EXCHANGE = 2
_AT_FDCWD = -100
#: A full disk, or a user's quota reached.
DISK_FULL = (errno.ENOSPC, errno.EDQUOT)


def temporary_sibling(folder: Path, kind: str) -> Path:
    """A new empty folder ``.<name>.<kind>-XXXX`` beside ``folder`` (an ``OSError`` if none can be made)."""
    return Path(tempfile.mkdtemp(prefix=f".{folder.name}.{kind}-", dir=folder.absolute().parent))


def temporary_siblings(folder: Path, kind: str) -> list[Path]:
    """The folders :func:`temporary_sibling` made beside ``folder`` for ``kind``, oldest name first."""
    return sorted(folder.absolute().parent.glob(f".{glob.escape(folder.name)}.{kind}-*"))


def remove(path: Path) -> None:
    """Delete ``path``, a folder with its content or a symbolic link, if it is there."""
    if path.is_symlink():
        path.unlink()
    else:
        shutil.rmtree(path, ignore_errors=True)


def exchange(first: Path, second: Path) -> bool:
    """Swap two existing paths in one step (Linux ``renameat2``); ``False``, and nothing moved, where the
    system or the file system cannot."""
    libc = ctypes.CDLL(None, use_errno=True)
    if not hasattr(libc, "renameat2"):
        return False
    if libc.renameat2(_AT_FDCWD, os.fsencode(first), _AT_FDCWD, os.fsencode(second), _RENAME_EXCHANGE) == 0:
        return True
    code = ctypes.get_errno()
    if code in (errno.EINVAL, errno.ENOSYS, errno.ENOTSUP):
        return False
    raise OSError(code, os.strerror(code), str(first), None, str(second))


def size_of(folder: Path) -> int:
    """Bytes in the files below ``folder`` [bytes]."""
    return sum(path.stat().st_size for path in folder.rglob("*") if path.is_file() and not path.is_symlink())


def disk_full(error: OSError, folder: Path, needed: str) -> InputError:
    """The one-line error for a disk that filled up (or a quota reached) while writing into ``folder``;
    ``needed`` says how much the writing needed (e.g. ``"more than 12 MiB"``)."""
    existing = folder.absolute()
    while not existing.exists():
        existing = existing.parent
    written = f" writing '{error.filename}'" if error.filename else ""
    return InputError(f"the disk is full ({error.strerror}){written}: it needed {needed}, and "
                      f"{gib(shutil.disk_usage(existing).free)} is free there; free some space or choose another "
                      "--out", folder, "--out")
