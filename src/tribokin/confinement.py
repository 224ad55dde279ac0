"""Files read on a user's behalf: resolved (symlinks followed) and checked before anything opens them.

A file a study names (a law file, a tribometer log, a surface profile) must resolve inside one of the folders
allowed to it: the study file's folder and those its ``study.data_dirs`` lists (:func:`confined_file`). A file
given on the command line may lie anywhere, as the user chose it (:func:`regular_file`). Either way it must be a
regular file outside the kernel's pseudo-file systems: ``/proc``, ``/sys`` and ``/dev``, folders, FIFOs, sockets
and devices are refused, so that nothing reads a process's environment, blocks on a pipe or reads without end.
The errors name the path, never what the file holds.
"""

from __future__ import annotations

import os
import stat
from collections.abc import Iterable
from pathlib import Path

from tribokin.errors import InputError

#: Pseudo-file systems: files whose content is the machine's state (a process's environment, memory, devices).
SYSTEM_ROOTS = (Path("/proc"), Path("/sys"), Path("/dev"))
#: What a path that is not a regular file is, by ``stat``'s test.
_KINDS = ((stat.S_ISDIR, "a folder"), (stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISSOCK, "a socket"),
          (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"))


def _resolved(path: Path, source, key) -> Path:
    """``path`` made absolute with every symlink followed (a missing tail kept as written)."""
    try:
        return Path(os.path.realpath(path))
    except (OSError, ValueError) as error:  # a path with a NUL, or too long
        raise InputError(f"'{path}' is not a path that can be read ({type(error).__name__})", source, key) from None


def _shown(given: Path, real: Path) -> str:
    """The path as given, and where it resolves when elsewhere."""
    return f"'{given}'" if real == given else f"'{given}' (resolved: {real})"


def regular_file(path, source, key: str | None = None, missing: str = "file not found; check the path") -> Path:
    """``path`` resolved (symlinks followed): a regular file outside :data:`SYSTEM_ROOTS`.

    Args:
        path: the file as given.
        source: what names it, for the error: the file itself, a study file, ``"command line"``; ``None`` for the
            caller to locate.
        key: the key or option that names it, for the error.
        missing: the message when nothing is there.

    Returns:
        The resolved path, to be opened.

    Raises:
        InputError: naming ``source`` and ``key`` (and ``path`` unless it is the source): missing, a system file or
            not a regular file.
    """
    given = Path(path)
    real = _resolved(given, source, key)
    shown = _shown(given, real)
    if any(real.is_relative_to(root) for root in SYSTEM_ROOTS):
        raise InputError(f"{shown} is a system file under {', '.join(map(str, SYSTEM_ROOTS))}, not a data file; "
                         "name a file of your own", source, key)
    try:
        mode = real.stat().st_mode
    except FileNotFoundError:
        raise InputError(missing if str(source) == str(given) else f"{shown}: {missing}", source, key) from None
    except OSError as error:
        raise InputError(f"{shown} cannot be read: {error.strerror}", source, key) from None
    kind = next((name for test, name in _KINDS if test(mode)), None if stat.S_ISREG(mode) else "not a regular file")
    if kind is not None:
        raise InputError(f"{shown} is {kind}, not a data file; name a regular file", source, key)
    return real


def confined_file(path, roots: Iterable[str | Path], source, key: str | None,
                  missing: str = "file not found; check the path") -> Path:
    """``path`` resolved (symlinks followed), inside one of ``roots`` (resolved too), then a :func:`regular_file`.

    The place is checked first: a file outside the roots is refused before it is looked at, whether it exists or not.

    Args:
        path: the file as the study names it, joined to the folder it is relative to.
        roots: the folders allowed (the study file's folder first, then its ``study.data_dirs``).
        source: the file that names ``path``, for the error.
        key: the key that names it, for the error.
        missing: the message when nothing is there.

    Returns:
        The resolved path, to be opened.

    Raises:
        InputError: naming ``source`` and ``key``: outside the roots, missing, a system file or not a regular file.
    """
    real = _resolved(Path(path), source, key)
    folders = [_resolved(Path(root), source, key) for root in roots]
    if not any(real.is_relative_to(folder) for folder in folders):
        allowed = ", ".join(map(str, folders))
        raise InputError(f"{_shown(Path(path), real)} lies outside the folders a study may read ({allowed}): move it "
                         "under the study's folder or list its folder in study.data_dirs", source, key)
    return regular_file(path, source, key, missing)
