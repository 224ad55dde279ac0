"""The ``tribokin`` command run in a subprocess, as a user runs it, or its ``main`` in this process."""

from __future__ import annotations

import io
import os
import subprocess
import sys
from contextlib import redirect_stderr, redirect_stdout


def tribokin(*args, cwd=None, env=None) -> subprocess.CompletedProcess:
    """``python -m tribokin *args`` (each argument as ``str``) in ``cwd``, its output captured as text; ``env``: the
    environment variables to set beside this process's."""
    return subprocess.run([sys.executable, "-m", "tribokin", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, env=None if env is None else {**os.environ, **env})


def in_process(*args) -> subprocess.CompletedProcess:
    """What :func:`tribokin` gives, from the command's ``main`` in this process (each argument as ``str``), its output
    captured as text: no new interpreter's imports and first calls (2-3 s of CPU a run of calibrate or run)."""
    from tribokin.cli import main

    out, err = io.StringIO(), io.StringIO()
    with redirect_stdout(out), redirect_stderr(err):
        try:
            status = main([str(arg) for arg in args])
        except SystemExit as exit_:  # the argument parser's refusals
            status = exit_.code
    return subprocess.CompletedProcess(["tribokin", *map(str, args)], status, out.getvalue(), err.getvalue())
