"""Errors that tell the user what to fix.

Every error raised on bad input is an :class:`InputError`: it names the file,
the key inside it and what to do, and the command line prints it as one line
and exits with status 2.
"""

from __future__ import annotations

import difflib
from pathlib import Path


class InputError(ValueError):
    """Bad input: a file, a key in it, and what to fix.

    Args:
        message: what is wrong and what to do about it.
        source: the file (or ``"<mapping>"``, ``"command line"``) at fault.
        key: dotted key inside the source, e.g. ``"joints.stiffness"``.
    """

    def __init__(self, message: str, source: str | Path | None = None, key: str | None = None):
        self.message = message
        self.source = str(source) if source is not None else None
        self.key = key
        super().__init__(self.one_line())

    def one_line(self) -> str:
        """The message as ``source: key: message`` on a single line."""
        parts = [p for p in (self.source, self.key) if p]
        text = ": ".join(parts + [self.message])
        return " ".join(text.split())


def closest_hint(word: str, valid: list[str] | tuple[str, ...]) -> str:
    """`` (did you mean 'x'?)`` when a valid name is close to ``word``, else ``""``."""
    match = difflib.get_close_matches(word, list(valid), n=1)
    return f" (did you mean '{match[0]}'?)" if match else ""
