"""Writing results to an output folder: all or nothing, never over a user's folder unasked.

Files are written into a temporary sibling folder, which is renamed into
place at the end; an existing folder is replaced only with ``force``, by
exchanging the two folders in one step where the system can.
"""

from __future__ import annotations

import os
from contextlib import contextmanager
from pathlib import Path

from tribokin.errors import InputError
from tribokin.folders import DISK_FULL, disk_full, exchange, remove, size_of, temporary_sibling, temporary_siblings
from tribokin.units import gib


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
