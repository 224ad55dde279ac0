"""Robot descriptions written in xacro (``robot.urdf.xacro``): expanded to URDF text with the PyPI ``xacro``
package, without ROS.

:func:`urdf_text` gives the XML of a robot description file: a URDF's bytes as they are, a ``.xacro`` file
expanded with its arguments. While xacro expands it,

- ``$(find pkg)`` (and ``$(eval find('pkg'))``) is the folder named ``pkg`` in the first of the package folders
  that has one, as ``package://pkg/...`` mesh paths resolve; ROS's package index is never asked;
- every file xacro opens (the xacro, its includes, YAML files of ``xacro.load_yaml``) must resolve (symlinks
  followed) inside the xacro's own folder or a package folder, and be a regular file; one outside is refused before
  it is read, and its size counts towards the expansion's limit; an include's wildcards list only those folders;
- every ``${...}`` and ``$(eval ...)`` expression is checked against an allow-list before it runs, and the whole
  expansion is held within a time and a size limit (:mod:`tribokin.kinematics.xacro_guard`: why that holds);
  ``$(env)`` is refused, ``$(optenv)`` gives its default;
- xacro's warnings are kept from the terminal.

xacro keeps its state in module globals (the file stack, the arguments, its ``find``, its ``eval``); an expansion
holds a lock and puts back every global it touches, so other users of xacro in this process see it as it was.
"""

from __future__ import annotations

import contextlib
import glob
import io
import math
import os
import threading
import time
from collections.abc import Callable
from functools import partial
from pathlib import Path
from types import SimpleNamespace
from typing import NoReturn

from tribokin.confinement import regular_file
from tribokin.errors import InputError, RobotDescriptionError, closest_hint
from tribokin.kinematics.xacro_guard import Budget, Guard, XacroLimits, replace_node

#: The ending of a file expanded by xacro.
XACRO_SUFFIX = ".xacro"

_lock = threading.Lock()


def is_xacro(path) -> bool:
    """Whether ``path`` names a xacro file (its name ends with ``.xacro``)."""
    return str(path).endswith(XACRO_SUFFIX)


class _Refused(Exception):
    """A file, package or expression the expansion may not use, or a limit passed; raised through xacro, reported by
    :func:`expand_xacro`."""

    def __init__(self, error: RobotDescriptionError):
        super().__init__(error.message)
        self.error = error


class _Stopped(RobotDescriptionError):
    """An expansion stopped at its time or size limit: no argument is blamed (each try would take as long)."""


def _refuser(refusals: list) -> Callable[[RobotDescriptionError], NoReturn]:
    """Records ``error`` in ``refusals`` (xacro may wrap or swallow what is raised through it) and raises it."""

    def refuse(error: RobotDescriptionError) -> NoReturn:
        refusals.append(error)
        raise _Refused(error)

    return refuse


class _RecordedArguments(dict):
    """xacro's argument table (``mappings``), recording every name the xacro declares (``<xacro:arg>``) or reads
    (``$(arg name)``)."""

    def __init__(self, values: dict[str, str]):
        super().__init__(values)
        self.names: set[str] = set()

    def __contains__(self, name) -> bool:
        self.names.add(name)
        return super().__contains__(name)

    def __getitem__(self, name):
        value = super().__getitem__(name)
        self.names.add(name)
        return value


def _package_finder(package_dirs: list[Path], refuse):
    """xacro's ``find``: the folder ``pkg`` in the first of ``package_dirs`` that has it."""

    def find(package: str) -> str:
        candidates = [Path(folder) / package for folder in package_dirs]
        found = next((c for c in candidates if c.is_dir()), None)
        if package in ("", ".", "..") or "/" in package or found is None:
            refuse(RobotDescriptionError(
                f"$(find {package}): no folder '{package}' in the package folders "
                f"({', '.join(map(str, package_dirs))}); list the folder that holds it in robot.package_dirs",
                "path"))
        return str(found.resolve())

    return find


def _confined_open(roots: list[Path], refuse, budget: Budget):
    """``open`` for xacro: a file that resolves outside every folder of ``roots``, or is no regular file, is refused
    before it is read; its size counts towards ``budget``."""

    def confined(file, *args, **kwargs):
        real = Path(file).resolve()
        if not any(real.is_relative_to(root) for root in roots):
            resolved = "" if str(real) == str(file) else f", which resolves to '{real}',"
            refuse(RobotDescriptionError(
                f"xacro opens '{file}'{resolved} outside the xacro's folder and the package folders "
                f"({', '.join(map(str, roots))}); move it under one of them or list its folder in robot.package_dirs",
                "package_dirs"))
        if real.exists() and not real.is_file():
            refuse(RobotDescriptionError(f"xacro opens '{file}', which is not a regular file", "path"))
        budget.file(real.stat().st_size if real.exists() else 0)
        return open(real, *args, **kwargs)

    return confined


def _confined_glob(roots: list[Path], refuse) -> SimpleNamespace:
    """``glob`` for xacro's includes (``filename="$(find pkg)/urdf/*.xacro"``): a pattern whose folder before its
    first wildcard resolves outside every folder of ``roots``, or that climbs (``..``) after one, is refused before
    any folder is listed."""

    def confined(pattern: str) -> list[str]:
        fixed = pattern[:min(pattern.find(c) for c in "*?[" if c in pattern)]
        folder = Path(fixed if fixed.endswith("/") else Path(fixed).parent).resolve()
        if not any(folder.is_relative_to(root) for root in roots) or ".." in Path(pattern[len(fixed):]).parts:
            refuse(RobotDescriptionError(
                f"xacro includes '{pattern}', which lists folders outside the xacro's folder and the package folders "
                f"({', '.join(map(str, roots))}); move the files under one of them or list their folder in "
                "robot.package_dirs", "package_dirs"))
        return glob.glob(pattern)

    return SimpleNamespace(glob=confined)


@contextlib.contextmanager
def _hooked_xacro(find, opener, lister, guard: Guard):
    """xacro with ``find``, ``opener`` and ``lister`` (its ``glob``) in place of its own, its expressions evaluated
    by ``guard`` and its elements and texts counted, its messages kept from the terminal; every global touched is put
    back on leaving."""
    import xacro
    from xacro import substitution_args

    with _lock:
        saved = (substitution_args._eval_find, substitution_args._eval_dict["find"], substitution_args._eval,
                 substitution_args._eval_env, substitution_args._eval_optenv, xacro.safe_eval, xacro.eval_all,
                 xacro.eval_text, xacro.replace_node, xacro.glob, xacro.filestack, xacro.macrostack,
                 dict(xacro.substitution_args_context), len(xacro.all_includes))
        substitution_args._eval_find = substitution_args._eval_dict["find"] = find
        substitution_args._eval, xacro.safe_eval = guard.substitution_eval, guard.safe_eval
        substitution_args._eval_env, substitution_args._eval_optenv = guard.environment, guard.optional_environment
        xacro.eval_all, xacro.eval_text = guard.counted(xacro.eval_all, xacro.eval_text)
        xacro.replace_node, xacro.glob = replace_node, lister
        xacro.open = opener  # a module global: xacro's parse() and load_yaml() open files through it
        try:
            with contextlib.redirect_stderr(io.StringIO()), contextlib.redirect_stdout(io.StringIO()):
                yield
        finally:
            del xacro.open
            (substitution_args._eval_find, substitution_args._eval_dict["find"], substitution_args._eval,
             substitution_args._eval_env, substitution_args._eval_optenv, xacro.safe_eval, xacro.eval_all,
             xacro.eval_text, xacro.replace_node, xacro.glob, xacro.filestack, xacro.macrostack) = saved[:12]
            xacro.substitution_args_context.clear()
            xacro.substitution_args_context.update(saved[12])
            del xacro.all_includes[saved[13]:]


def _expand(path: Path, arguments: dict[str, str], package_dirs: list[Path], limits: XacroLimits, deadline: float
            ) -> tuple[str, set[str]]:
    """The URDF text of the xacro ``path`` and the argument names it declares or reads, stopped past ``limits`` or
    the ``deadline`` (a ``time.monotonic()``).

    Raises:
        RobotDescriptionError: a file or package refused (:func:`_confined_open`, :func:`_package_finder`), an
            expression refused or a limit passed (:mod:`~tribokin.kinematics.xacro_guard`; :class:`_Stopped`), or
            xacro's own error (``argument`` ``"path"``; :func:`expand_xacro` finds the argument at fault).
    """
    import xacro

    refusals: list[RobotDescriptionError] = []
    refuse = _refuser(refusals)

    def stop(what: str, limited: bool) -> NoReturn:
        refuse((_Stopped if limited else RobotDescriptionError)(f"xacro '{path}'{_where(xacro.filestack, path)}: "
                                                                f"{what}", "path"))

    roots = list(dict.fromkeys([path.parent, *(Path(folder).resolve() for folder in package_dirs)]))
    recorded = _RecordedArguments(arguments)
    budget = Budget(limits, stop, deadline)
    find = _package_finder(package_dirs, refuse)
    with _hooked_xacro(find, _confined_open(roots, refuse, budget), _confined_glob(roots, refuse),
                       Guard(xacro, budget, find)):
        try:
            document = xacro.process_file(str(path), mappings=recorded)
            budget.tick()
            text = document.toxml()
            failure = None
        except Exception as error:  # noqa: BLE001 - xacro raises many kinds for a bad file; all are input errors
            failure = _xacro_message(error, xacro.filestack, path)
    if refusals:
        raise refusals[0]
    if failure is not None:
        raise failure
    return text, recorded.names


def _where(filestack, path: Path) -> str:
    """`` (in <file>)`` naming the file xacro is expanding (the last of its ``filestack``) when not ``path``."""
    current = next((f for f in reversed(filestack or []) if f), None)
    return "" if current is None or Path(current).resolve() == path else f" (in {current})"


def _xacro_message(error: Exception, filestack, path: Path) -> RobotDescriptionError:
    """xacro's ``error`` as one error naming the xacro (and the file being expanded, when another), the key
    ``robot.xacro_args.<name>`` for an argument it lacks, else ``robot.urdf``."""
    from xacro.substitution_args import ArgException

    cause = getattr(error, "exc", None)
    text = f"{cause.strerror}: {cause.filename}" if isinstance(cause, OSError) else str(error) or type(error).__name__
    message = " ".join(text.split())
    where = _where(filestack, path)
    if isinstance(cause, ArgException):
        name = str(cause)
        return RobotDescriptionError(f"xacro '{path}'{where}: {message}: set robot.xacro_args.{name} = \"...\"",
                                     f"xacro_args.{name}")
    return RobotDescriptionError(f"cannot expand xacro '{path}'{where}: {message}", "path")


def expand_xacro(path, xacro_args: dict[str, str] | None = None, package_dirs=(),
                 limits: XacroLimits = XacroLimits()) -> str:
    """The URDF text of the xacro file ``path`` expanded with the arguments ``xacro_args`` (strings).

    Args:
        path: the ``.xacro`` file (symlinks followed; includes resolve from its real folder).
        xacro_args: the xacro's ``<xacro:arg>`` values by name; each must be one the xacro declares or reads.
        package_dirs: folders that ``$(find pkg)`` resolves against (each holding package folders), and with the
            xacro's folder the only folders xacro may read files from.
        limits: when the expansion is stopped (:class:`~tribokin.kinematics.xacro_guard.XacroLimits`).

    Raises:
        RobotDescriptionError: with ``argument`` ``"path"`` (robot.urdf: a missing or malformed file or include,
            an unknown package, an expression refused, a limit passed, another xacro error), ``"xacro_args.<name>"``
            (an argument the xacro lacks, does not know, whose value is a number no double holds, or whose value
            makes the expansion fail) or ``"package_dirs"`` (a file outside the folders).
    """
    real = description_file(path, "xacro")
    arguments = dict(xacro_args or {})
    for name, value in arguments.items():
        _check_finite(value, path, name)
    dirs = [Path(folder) for folder in package_dirs]
    expansion = partial(_expand, real, package_dirs=dirs, limits=limits, deadline=time.monotonic() + limits.seconds)
    try:
        text, names = expansion(arguments)
    except RobotDescriptionError as error:
        raise _blamed(error, real, arguments, expansion) from None
    for name in arguments:
        if name not in names:
            known = sorted(names)
            raise RobotDescriptionError(f"xacro '{path}' has no argument '{name}'{closest_hint(name, known)}; its "
                                        f"arguments: {', '.join(known) or 'none'}", f"xacro_args.{name}")
    return text


def _check_finite(value: str, path, name: str) -> None:
    """Refuse an argument written as a finite number that no double holds (xacro would write it as ``inf``); a
    value spelling ``inf`` or ``nan`` is the user's word and passes."""
    try:
        number = float(value)
    except ValueError:
        return
    if not math.isfinite(number) and value.strip().lstrip("+-").lower() not in ("inf", "infinity", "nan"):
        raise RobotDescriptionError(f"xacro '{path}': argument {name} ({len(value)} characters) reads as {number}, "
                                    "not a finite number; give a value within +-1.8e308", f"xacro_args.{name}")


def _blamed(error: RobotDescriptionError, path: Path, arguments: dict[str, str], expansion):
    """``error`` of expanding ``path`` with ``arguments``, keyed by the first argument without which ``expansion``
    fails otherwise (its value is at fault); unchanged when it names an argument already, none is at fault, or the
    expansion stopped at a limit (each try would take as long; the tries share the first's deadline)."""
    if error.argument != "path" or not arguments or isinstance(error, _Stopped):
        return error
    for name in arguments:
        others = {key: value for key, value in arguments.items() if key != name}
        try:
            expansion(others)
        except _Stopped:
            return error
        except RobotDescriptionError as without:
            if without.message == error.message:
                continue
        message = error.message.replace(f"cannot expand xacro '{path}'", f"xacro '{path}'", 1).replace(
            f"xacro '{path}'", f"xacro '{path}' with {name} = {arguments[name]!r}", 1)
        return RobotDescriptionError(message, f"xacro_args.{name}")
    return error


#: The largest URDF read [bytes] (a xacro's files are held to :class:`XacroLimits` instead).
MAX_URDF_BYTES = XacroLimits().characters // 5


def description_file(path, kind: str = "URDF") -> Path:
    """``path`` resolved (symlinks followed): a regular file outside the kernel's pseudo-file systems
    (:func:`~tribokin.confinement.regular_file`).

    Raises:
        RobotDescriptionError: (``"path"``) missing, under ``/proc``, ``/sys`` or ``/dev``, or not a regular file.
    """
    if not os.path.lexists(path):
        raise RobotDescriptionError(f"{kind} file '{path}' not found", "path")
    try:
        return regular_file(path, None, None, f"{kind} file not found")
    except InputError as error:
        raise RobotDescriptionError(error.message, "path") from None


def urdf_text(path: Path, package_dirs: list[Path], xacro_args: dict[str, str] | None = None) -> bytes | str:
    """The XML of the robot description ``path``: a URDF's bytes (at most :data:`MAX_URDF_BYTES`), or a xacro
    expanded (:func:`expand_xacro`).

    Raises:
        RobotDescriptionError: ``path`` refused by :func:`description_file` or too large, ``xacro_args`` given for a
            file that is not a xacro, or as :func:`expand_xacro`.
    """
    if is_xacro(path):
        return expand_xacro(path, xacro_args, package_dirs)
    if xacro_args:
        raise RobotDescriptionError(f"'{path}' is not a xacro file (its name does not end with {XACRO_SUFFIX}): "
                                    "it takes no arguments; remove robot.xacro_args", "xacro_args")
    real = description_file(path)
    if real.stat().st_size > MAX_URDF_BYTES:
        raise RobotDescriptionError(f"URDF file '{path}' is larger than {MAX_URDF_BYTES:,} bytes, the largest read",
                                    "path")
    return real.read_bytes()
