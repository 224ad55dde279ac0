"""A result's folder, figures and notebook scene, each by the function registered for the result's type (ground floor).

The results sit low in the chain (``simulation.pose_result``, ``maps.result``, ``run``, ``tribology``,
``measured``); what writes their folders (``output``) and draws their figures and scenes (``viz``) sits above and
takes them. So a result's ``write``, ``figures`` and ``_repr_html_`` call :func:`write_folder`,
:func:`result_figures` and :func:`result_scene` here (an import down the chain), and each implementation registers
itself for its result's type where it is defined (``@folder_writer.register(StudyResult)``:
:mod:`~tribokin.output.writers`, :mod:`~tribokin.output.measured`, :mod:`~tribokin.output.tribology`;
``@result_figures.register``, ``@result_scene.register``: :mod:`~tribokin.viz.contents`,
:mod:`~tribokin.viz.notebook`). The package's ``__init__``, which Python runs before any of the package's modules,
names the functions that import those modules (:func:`registered_by`), the writers first; they run in turn when a type
is first dispatched, until its implementation is registered, so ``import tribokin`` loads none of them
(matplotlib, the writers) until a result is written or shown, and a result loads only the modules up to its own.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import singledispatch
from pathlib import Path

from tribokin.output.lock import write_claimed

#: The functions that import the modules registering implementations here, in the order they run (the package's
#: ``__init__``'s).
_registrars: list[Callable[[], object]] = []


def registered_by(registrar: Callable[[], object]) -> Callable[[], object]:
    """Have ``registrar`` (it imports a module that registers implementations here) run, after those named before it,
    when a type without an implementation is dispatched; returns it (a decorator)."""
    _registrars.append(registrar)
    return registrar


def _implementation(generic, result) -> Callable:
    """``generic``'s implementation for ``result``'s type, the registrars run in turn until it is registered: a
    :class:`TypeError` if none registers it."""
    registrars = iter(_registrars)
    while (implementation := generic.dispatch(type(result))) is generic.dispatch(object):
        registrar = next(registrars, None)
        if registrar is None:
            raise TypeError(f"{generic.__name__}: no implementation for a {type(result).__name__}")
        registrar()
    return implementation


@singledispatch
def folder_writer(result, out, force: bool = False, **options) -> Path:
    """Write ``result``'s command's folder to ``out``, all at once (the writer registered for its type)."""
    return _implementation(folder_writer, result)(result, out, force, **options)


@singledispatch
def result_figures(result, **options) -> dict:
    """``result``'s figures as matplotlib Figures by file name (the function registered for its type)."""
    return _implementation(result_figures, result)(result, **options)


@singledispatch
def result_scene(result) -> str | None:
    """``result``'s 3-D scene as a notebook's HTML, ``None`` without a robot (the function registered for its
    type)."""
    return _implementation(result_scene, result)(result)


def write_folder(result, folder, force: bool = False, **options) -> Path:
    """``result``'s folder written by its :func:`folder_writer` as the commands write it, its lock held
    (:func:`~tribokin.output.lock.write_claimed`): a result's ``write`` method.

    Returns:
        the folder written.
    """
    return write_claimed(folder_writer, result, folder, force, **options)
