"""What the commands share around a computation: the output folder claimed (checked, locked, a killed run's leftovers
cleared) and a library's error told in the command's words (its options)."""

from __future__ import annotations

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
