"""The ``tribokin`` command run in a subprocess, as a user runs it."""

from __future__ import annotations

import os
import subprocess
import sys


def tribokin(*args, cwd=None, env=None) -> subprocess.CompletedProcess:
    """``python -m tribokin *args`` (each argument as ``str``) in ``cwd``, its output captured as text; ``env``: the
    environment variables to set beside this process's."""
    return subprocess.run([sys.executable, "-m", "tribokin", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, env=None if env is None else {**os.environ, **env})
