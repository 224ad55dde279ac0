"""Writing one output file of a script in ``tools/``: refuse to replace it unless asked, and never leave it half
written.

Imported by the scripts beside it (``from output_file import check_out, write_atomically``): a script run as
``python tools/<name>.py`` has ``tools/`` on its path.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from tribokin.errors import InputError


def check_out(path: Path, force: bool) -> None:
    """Refuse an output file that exists (without ``force``) or whose folder does not."""
    if path.exists() and not force:
        raise InputError("exists; give another --out or add --force", path)
    if not path.parent.is_dir():
        raise InputError("its folder does not exist", path)


def write_atomically(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` through a temporary file in the same folder (no half-written file)."""
    handle, temporary = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(handle, "w", encoding="utf-8", newline="\n") as stream:
            stream.write(text)
        os.replace(temporary, path)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise
