"""What the commands share around a computation: the output folder claimed (checked, locked, a killed run's leftovers
cleared) and a library's error told in the command's words (its options)."""

from __future__ import annotations

from contextlib import contextmanager

from tribokin.errors import InputError, TribokinError, located


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



def options_located(renamed: dict[str, str] | None = None):
    """Within the block, a library's error naming its argument (``SettingsError.argument``: ``"area_m2"``) names the
    command-line option instead (``--area-m2``, or as ``renamed`` gives it) and the command line as its source, as
    any :class:`~tribokin.errors.InputError` does (:func:`~tribokin.errors.located`)."""
    def key(error: TribokinError) -> str | None:
        name = getattr(error, "argument", None)
        return None if name is None else (renamed or {}).get(name, "--" + name.replace("_", "-"))

    return located("command line", key)
