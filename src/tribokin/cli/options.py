"""What the commands share around a computation: the output folder claimed (checked, locked, a killed run's leftovers
cleared) and a library's error told in the command's words (its options)."""

from __future__ import annotations

import sys
import warnings
from contextlib import contextmanager

from tribokin.errors import InputError, SettingsError


@contextmanager
def claimed(out, force: bool):
    """Check the output folder, hold its lock (``<out>.lock``) while the block runs, and first delete the
    temporary folders a killed run left beside it (or move back an output folder it had moved aside)."""
    from tribokin.output.folder import check_output_folder
    from tribokin.output.lock import claimed_folder

    with claimed_folder(out, force) as restored:
        if restored is not None:
            print(f"note: moved '{out}' back from '{restored}', where a killed --force run had left it")
            check_output_folder(out, force)
        yield


@contextmanager
def option_named(argument: str, instead: str):
    """Within the block, an :class:`InputError` whose remedy is the library's ``argument`` (``meshes=False reads no
    mesh``) gives the command's remedy ``instead`` (``--report none reads no mesh``)."""
    try:
        yield
    except InputError as error:
        if argument not in error.message:
            raise
        raise InputError(error.message.replace(argument, instead), error.source, error.key) from None



@contextmanager
def options_located(options: dict[str, str]):
    """Within the block, a library's :class:`~tribokin.errors.SettingsError` naming one of ``options``' arguments
    (``"seed"``, or ``"z_range_m[0]"`` for ``"z_range_m"``) is an :class:`~tribokin.errors.InputError` naming the
    command line and the option instead (``--seed``, ``--z-range-m[0]``); any other error passes unchanged."""
    try:
        yield
    except SettingsError as error:
        name, bracket, index = (error.argument or "").partition("[")
        if name not in options:
            raise
        raise InputError(error.message, "command line", options[name] + bracket + index) from None


def add_registration_options(parser) -> None:
    """``--registration`` and ``--transform`` of ``measure`` and ``calibrate`` (the measuring frame)."""
    from tribokin.measurement.registration import AUTO_MIN_POSES, CHOICES

    parser.add_argument("--registration", choices=CHOICES,
                        help="the measuring frame: auto (default) registers it by a best fit of the barycentres to "
                             f"the commanded positions only where that is harmless ({AUTO_MIN_POSES} or more "
                             "well-spread poses), none keeps it as measured, best-fit registers it")
    parser.add_argument("--transform", metavar="FILE",
                        help="apply this transform to the measuring frame instead: a TOML file with rotation (3 rows) "
                             "or rpy_deg, and translation_m (p_world = rotation · p + translation_m)")


def registration_choice(args):
    """``--registration`` (default ``auto``), or the transform ``--transform`` names, read and checked; both given
    are refused."""
    if args.transform is None:
        return args.registration or "auto"
    if args.registration is not None:
        raise InputError("gives the measuring frame's transform, which --registration would choose otherwise; leave "
                         "out one of them", "command line", "--transform")
    from tribokin.measurement.registration import read_transform

    return read_transform(args.transform)


@contextmanager
def registration_noted():
    """Within the block, the library's registration warnings are held back (:func:`warn_registration` prints the
    result's once) and its refusal of ``registration 'best-fit'`` names ``--registration best-fit``."""
    from tribokin.measurement.registration import RegistrationWarning

    with warnings.catch_warnings(), option_named("registration 'best-fit'", "--registration best-fit"):
        warnings.simplefilter("ignore", RegistrationWarning)
        yield


def warn_registration(frame) -> None:
    """The frame's warning (a best fit that absorbs accuracy) as one line on stderr, if it has one."""
    if frame.warning is not None:
        print(f"tribokin: warning: {frame.warning}", file=sys.stderr)
