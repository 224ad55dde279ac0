"""The ``tribokin`` command run in a subprocess, as a user runs it."""

from __future__ import annotations

import subprocess
import sys


def tribokin(*args, cwd=None) -> subprocess.CompletedProcess:
    """``python -m tribokin *args`` (each argument as ``str``) in ``cwd``, its output captured as text."""
    return subprocess.run([sys.executable, "-m", "tribokin", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd)
