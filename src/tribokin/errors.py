"""Errors: one base class, :class:`TribokinError`, that library users can catch.

The physics (robots, configurations, friction laws, joint ranges) raises plain, specific errors that
say what is wrong and name the argument at fault, never a file. The study layer knows the file and the
key a value came from: :func:`located` turns those errors into an :class:`InputError`, which names the
file, the key inside it and what to do; the command line prints it as one line and exits with status 2.
"""

from __future__ import annotations

import contextlib
import difflib
import importlib
from collections.abc import Callable, Iterator
from pathlib import Path


class TribokinError(Exception):
    """Base class of every error tribokin raises on purpose.

    Args:
        message: what is wrong and what to do about it.
    """

    def __init__(self, message: str):
        self.message = message
        super().__init__(message)

    def __reduce__(self):
        """Pickled with its attributes (a map's worker raises it in another process), whatever its arguments."""
        return _restored, (type(self), self.args, self.__dict__)


def _restored(cls: type, args: tuple, state: dict) -> TribokinError:
    """The error ``cls`` with ``args`` and attributes ``state``, its ``__init__`` not called (unpickling)."""
    error = cls.__new__(cls)
    error.args = args
    error.__dict__.update(state)
    return error


class InputError(TribokinError, ValueError):
    """Bad input: a file, a key in it, and what to fix.

    Args:
        message: what is wrong and what to do about it.
        source: the file (or ``"<mapping>"``, ``"command line"``) at fault.
        key: dotted key inside the source, e.g. ``"joints.stiffness"``.
    """

    def __init__(self, message: str, source: str | Path | None = None, key: str | None = None):
        self.source = str(source) if source is not None else None
        self.key = key
        super().__init__(message)
        self.args = (self.one_line(),)

    def one_line(self) -> str:
        """The message as ``source: key: message`` on a single line."""
        parts = [p for p in (self.source, self.key) if p]
        text = ": ".join(parts + [self.message])
        return " ".join(text.split())


class ConfigurationError(TribokinError, ValueError):
    """A joint configuration of the wrong size, not finite, or outside the joint limits."""


class ArgumentError(TribokinError, ValueError):
    """A bad argument of a library function, named by ``argument``.

    Args:
        message: what is wrong and what to do about it.
        argument: the argument at fault, or ``None`` for no one argument.
    """

    def __init__(self, message: str, argument: str | None = None):
        self.argument = argument
        super().__init__(message)


class RobotDescriptionError(ArgumentError):
    """A robot that cannot be loaded: an unknown name, a missing or malformed URDF, a mesh outside the package
    folders, an unknown tool frame, a joint tribokin cannot model; ``argument``: the loader's argument at fault
    (``"name"``, ``"path"``, ``"tool_frame"``, ``"package_dirs"``, ``"reference_q"``), or ``None`` for the robot as a
    whole."""


class LawError(TribokinError, ValueError):
    """Bad parameters of a friction law, or an unknown law or preset.

    Args:
        message: what is wrong and what to do about it.
        parameter: the parameter at fault (``"mean"``, ``"low"``, ``"values"``, ``"preset"``...).
    """

    def __init__(self, message: str, parameter: str | None = None):
        self.parameter = parameter
        super().__init__(message)


class JointRangeError(TribokinError, ValueError):
    """A joint's deviation that could exceed its range.

    Args:
        message: the joint, the figures and what to change.
        joint: the joint's name.
        part: the part of the deviation that is largest, named as the joint error model's field
            (``"stiffness"``, ``"backlash"``, ``"offset"``, ``"noise_std"``).
    """

    def __init__(self, message: str, joint: str, part: str):
        self.joint, self.part = joint, part
        super().__init__(message)


class SettingsError(ArgumentError):
    """A test's or a map's setting out of its range (cycles, seed, approach, engine, payload, approach directions);
    ``argument``: the setting at fault (``"cycles"``...)."""


class JointModelError(TribokinError, ValueError):
    """A joint error model that cannot be made: an unknown joint, a missing or bad stiffness or friction.

    Args:
        message: what is wrong and what to do about it.
        joint: the joint's name (``None``: every joint's shared value).
        part: the value at fault, named as the joint error model's field (``"stiffness"``, ``"friction"``...), or
            ``None`` for the joint itself (unknown).
    """

    def __init__(self, message: str, joint: str | None, part: str | None):
        self.joint, self.part = joint, part
        super().__init__(message)


class MissingExtraError(TribokinError, ImportError):
    """A library of an optional extra (``pip install 'tribokin[data]'``: pandas, xarray, pyarrow) that is not
    installed.

    Args:
        message: the library, what needs it and the install command.
        library: the missing library's module name (``"pandas"``, ``"xarray"``, ``"pyarrow"``).
    """

    def __init__(self, message: str, library: str):
        self.library = library
        super().__init__(message)


#: The optional extra each library comes with (pyproject.toml's ``[project.optional-dependencies]``).
EXTRAS = {"pandas": "data", "xarray": "data", "pyarrow": "data"}


def import_extra(library: str, purpose: str):
    """Import module ``library`` of an optional extra (:data:`EXTRAS`), for ``purpose`` (``"to_pandas()"``,
    ``"--table-format parquet"``); a :class:`MissingExtraError` naming the install command if it is missing."""
    package = library.partition(".")[0]
    try:
        return importlib.import_module(library)
    except ImportError:
        raise MissingExtraError(f"{purpose} needs {package}, which is not installed; install it with "
                                f"pip install 'tribokin[{EXTRAS[package]}]'", package) from None


@contextlib.contextmanager
def located(source: str | Path | None, key: str | Callable[[TribokinError], str]) -> Iterator[None]:
    """Turn a :class:`TribokinError` raised inside the block into an :class:`InputError` naming ``source`` and
    ``key`` (a key, or a function of the error giving one); an ``InputError`` passes unchanged."""
    try:
        yield
    except InputError:
        raise
    except TribokinError as error:
        raise InputError(error.message, source, key(error) if callable(key) else key) from None


def closest_hint(word: str, valid: list[str] | tuple[str, ...]) -> str:
    """`` (did you mean 'x'?)`` when a valid name is close to ``word``, else ``""``."""
    match = difflib.get_close_matches(word, list(valid), n=1)
    return f" (did you mean '{match[0]}'?)" if match else ""
