"""Output folders made whole or not at all, never over a user's folder unasked.

A folder is built as ``.<name>.<kind>-XXXX`` beside its final place (a temporary sibling) and renamed into
place at the end; an existing folder is replaced only with ``force``, by exchanging the two folders in one step
where the system can. A run killed meanwhile leaves only such temporary folders, which the next run clears
(:func:`remove_leftovers`). The primitives (temporary siblings, exchange, a full disk as one line) serve the map's
store too.
"""

from __future__ import annotations

import ctypes
import errno
import glob
import os
import shutil
import tempfile
from contextlib import contextmanager
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


def check_output_folder(out, force: bool = False) -> Path:
    """Refuse, before any work, an output folder that exists (without ``force``) or cannot be created, a
    symbolic link, and the current folder or one of its parents."""
    out = Path(out)
    if out.is_symlink():
        raise InputError(f"is a symbolic link (to '{os.readlink(out)}'); give a folder's own path as --out",
                         out, "--out")
    here = Path.cwd().resolve()
    if out.resolve() in (here, *here.parents):
        raise InputError("is the current folder or one of its parents, which a run never replaces; choose a new "
                         "folder as --out", out, "--out")
    if out.exists() and not force:
        raise InputError("output folder exists; choose another --out or pass --force to replace it",
                         out, "--out")
    if out.exists() and not out.is_dir():
        raise InputError("is a file, not a folder; choose another --out", out, "--out")
    parent = out.absolute().parent
    if not parent.is_dir():
        raise InputError(f"parent folder '{parent}' does not exist; create it first", out, "--out")
    os.rmdir(_temporary_folder(out, "probe"))  # can we write there? (asking os.access is wrong for root)
    return out


def _temporary_folder(out: Path, kind: str) -> Path:
    """A new empty folder ``.<out>.<kind>-XXXX`` beside ``out``, or an :class:`InputError` if none can be made."""
    try:
        return temporary_sibling(out, kind)
    except OSError as error:
        raise InputError(f"cannot write into parent folder '{out.absolute().parent}' ({error.strerror}); choose "
                         "another --out", out, "--out") from None


def remove_leftovers(out) -> Path | None:
    """Delete the temporary folders a killed run left beside ``out`` (call it while holding ``out``'s lock).

    A ``--force`` run killed after moving the old ``out`` aside and before renaming the new one in
    (only where folders cannot be exchanged in one step) left the old one in ``.<out>.old-*``: it is
    moved back, and the folder it was in is returned."""
    out = Path(out)
    restored = None
    for retired in temporary_siblings(out, "old"):
        if not out.exists() and (retired / out.name).exists():
            os.replace(retired / out.name, out)
            restored = retired
        remove(retired)
    for kind in ("partial", "probe"):
        for leftover in temporary_siblings(out, kind):
            remove(leftover)
    return restored


def _move_in(folder: Path, out: Path) -> None:
    """Rename ``folder`` to ``out``, replacing an existing ``out`` in one step where the system can."""
    if not out.exists():
        os.replace(folder, out)
    elif exchange(folder, out):
        remove(folder)  # the old out, exchanged into folder's place
    else:
        retired = _temporary_folder(out, "old")
        os.replace(out, retired / out.name)  # killed before the next line: the next run moves it back
        os.replace(folder, out)
        remove(retired)


@contextmanager
def atomic_folder(out, force: bool = False):
    """Yield a temporary folder; on success it replaces ``out``, on failure it is removed. A full disk
    is an :class:`InputError` naming the folder."""
    out = check_output_folder(out, force)
    temporary = _temporary_folder(out, "partial")
    umask = os.umask(0)
    os.umask(umask)
    temporary.chmod(0o777 & ~umask)  # mkdtemp makes it private; the result is an ordinary folder
    try:
        try:
            yield temporary
        except OSError as error:
            if error.errno in DISK_FULL:
                raise disk_full(error, out, f"more than the {gib(size_of(temporary))} written") from None
            raise
        if out.exists() and not force:
            raise InputError("output folder appeared while this run was computing; choose another --out or pass "
                             "--force to replace it", out, "--out")
        _move_in(temporary, out)
    except BaseException:
        remove(temporary)
        raise
