"""The ``tribokin`` command: the parser assembled from one module per command (arguments and printing), ``main`` and
the console script's ``entry``.

Bad input prints one line, ``tribokin: error: <file>: <key>: <what to fix>``,
and exits with status 2; nothing is written.
"""

from __future__ import annotations

import argparse
import gc
import sys
import warnings

from tribokin.cli.progress import COMPILING, ETA_SAMPLES, ProgressBar, kernels_to_compile, map_progress
from tribokin.errors import InputError

__all__ = ["main", "entry", "build_parser", "ProgressBar", "map_progress", "kernels_to_compile", "COMPILING",
           "ETA_SAMPLES"]


class _Parser(argparse.ArgumentParser):
    """argparse, with usage errors on one line and exit status 2."""

    def error(self, message):
        raise InputError(message, "command line")


def build_parser() -> argparse.ArgumentParser:
    from tribokin import __version__
    from tribokin.cli import calibrate, fit_friction, measure, robots, run, surface, view

    parser = _Parser(prog="tribokin", description="Friction-induced pose repeatability (ISO 9283) of robots.")
    parser.add_argument("--version", action="version", version=f"tribokin {__version__}")
    commands = parser.add_subparsers(dest="command", required=True, parser_class=_Parser, title="commands",
                                     metavar="COMMAND")
    for command in (run, measure, calibrate, view, fit_friction, surface, robots):
        command.add_parser(commands)
    return parser


def entry() -> int:
    """The ``tribokin`` command (``python -m tribokin``): :func:`main`, then every object it leaves frozen
    (:func:`gc.freeze`), so that the interpreter's exit does not search them for garbage before the process ends
    (docs/benchmarks.md); its exit handlers still run."""
    status = main()
    gc.freeze()
    return status


def _show_warning(message, category, filename, lineno, file=None, line=None, shown=warnings.showwarning):
    """A :class:`~tribokin.compiled.CacheWarning` as one line, ``tribokin: note: ...``; other warnings as Python
    shows them."""
    from tribokin.compiled import CacheWarning

    if issubclass(category, CacheWarning):
        print(f"tribokin: note: {message}", file=sys.stderr if file is None else file)
    else:
        shown(message, category, filename, lineno, file, line)


def main(argv=None) -> int:
    """Entry point of the ``tribokin`` command; returns the exit status (2 for a bare ``tribokin``, which
    prints the help: a command is missing, a usage error as for argparse)."""
    warnings.showwarning = _show_warning
    try:
        argv = sys.argv[1:] if argv is None else [str(arg) for arg in argv]
        parser = build_parser()
        if not argv:
            parser.print_help(sys.stderr)
            return 2
        args = parser.parse_args(argv)
        args.argv = argv
        args.handler(args)
    except InputError as error:
        print(f"tribokin: error: {error.one_line()}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("tribokin: interrupted; nothing was written", file=sys.stderr)
        return 130
    return 0
