"""The ``tribokin`` command as a user runs it: in a subprocess, or in this process (no interpreter start-up)."""

from __future__ import annotations

import contextlib
import io
import subprocess
import sys


def tribokin(*args, cwd=None) -> subprocess.CompletedProcess:
    """``python -m tribokin *args`` (each argument as ``str``) in ``cwd``, its output captured as text."""
    return subprocess.run([sys.executable, "-m", "tribokin", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd)


def tribokin_here(*args) -> subprocess.CompletedProcess:
    """``tribokin *args`` through :func:`tribokin.cli.main` in this process, its exit status and output captured
    as text, as :func:`tribokin` gives them (for the long commands, whose import time a subprocess would add)."""
    from tribokin.cli import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        status = main([str(arg) for arg in args])
    return subprocess.CompletedProcess(list(args), status, out.getvalue(), err.getvalue())
